//! Writes a baked scene as glTF 2.0 plus the `DRAFTER_illustration` extension.
//!
//! glTF input is passed through: the source JSON is kept whole (nodes, names, transforms,
//! materials, textures, cameras, extras, unknown extensions, `_` attributes), its buffers are merged
//! into one, and our data is added next to it. Other input (OBJ, STL, OFF, PLY) gets a fresh
//! document with one node per part instance. Either way the extension is listed in
//! `extensionsUsed` only, so every viewer still opens the file as a plain model.

use drafter_core::hierarchy::{ConeBvhArrays, GaussMapArrays};
use drafter_core::{Mesh, Scene, TriangleGroup};
use rayon::prelude::*;
use serde_json::Value;

use crate::FormatError;
use crate::accessor::{ComponentType, ELEMENT_ARRAY_BUFFER};
use crate::doc::Doc;
use crate::ext::{
    ConeBvhRecord, EDGE_VISIBILITY_EXTENSION, ENHANCED_NORMAL_ATTRIBUTE, EXTENSION, GaussMapRecord, MeshExtension,
    NodeExtensionRef, PartRecord, PrimitiveExtension, RootExtension, SilhouettesRecord, TexturesRecord,
};
use crate::gltf::{self, Extensible};

/// The most vertices a primitive may have for 16-bit indices: glTF forbids the index 65535 (the
/// primitive-restart value of UNSIGNED_SHORT), so indices run 0..=65534. The bake splits every
/// triangle primitive that would write more into consecutive primitives of at most this many
/// vertices; the writer renumbers such a group's vertices in order of first use.
pub const MAX_PRIMITIVE_VERTICES: u32 = 65_535;

/// Everything a bake produced, ready to write.
#[derive(Clone, Debug)]
pub struct BakeOutput<'a> {
    pub scene: &'a Scene,
    pub root: RootExtension,
    /// For each scene instance, its parts, indexed by the mesh's triangle labels.
    pub instance_parts: Vec<Vec<PartRecord>>,
    /// For each scene mesh, the part label of each triangle (`None`: the whole mesh is label 0).
    pub mesh_labels: Vec<Option<Vec<u32>>>,
    /// For each scene mesh, a new vertex layout with normals (`None`: keep the mesh's own).
    pub vertex_data: Vec<Option<VertexData>>,
    /// For each scene mesh, for each triangle group (primitive), its encoded edges.
    pub primitive_edges: Vec<Vec<Option<PrimitiveEdges>>>,
    /// For each scene mesh, its silhouette candidates and hierarchies.
    pub mesh_silhouettes: Vec<Option<MeshSilhouettes>>,
    /// The NPR lookup textures to embed (`None`: none).
    pub textures: Option<EmbeddedTextures>,
    /// Write the new layouts' `NORMAL` as normalized bytes (`KHR_mesh_quantization`, then listed
    /// as required), each within the validator's unit tolerance
    /// (`drafter_core::snorm8_encode_unit`); for compressed files, whose readers need an
    /// extension anyway. `false`: FLOAT.
    pub quantized_normals: bool,
}

/// The extension that allows normalized-integer `NORMAL`s.
pub const MESH_QUANTIZATION_EXTENSION: &str = "KHR_mesh_quantization";

/// PNG images to embed and the extension's record of them. The record's indices are positions in
/// `images`; the writer appends the images after the input's own `images`/`textures` and rewrites
/// the indices to the glTF texture indices. Every image must be referenced exactly once (an
/// unreferenced texture would be an unused object).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EmbeddedTextures {
    pub record: TexturesRecord,
    pub images: Vec<TextureImage>,
}

/// One PNG image with the sampler it is read with.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    /// Written as the image's and the texture's `name`.
    pub name: String,
    /// The PNG file's bytes.
    pub png: Vec<u8>,
    pub sampler: SamplerDesc,
}

/// How a texture is sampled; written as a glTF `sampler` (identical ones are shared).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SamplerDesc {
    /// `true`: `REPEAT` in u; `false`: `CLAMP_TO_EDGE`.
    pub repeat_u: bool,
    /// The same in v.
    pub repeat_v: bool,
    /// `true`: `LINEAR` magnification; `false`: `NEAREST`.
    pub linear: bool,
    /// `true`: minification filters between mip levels (`LINEAR_MIPMAP_LINEAR` or
    /// `NEAREST_MIPMAP_NEAREST`); `false`: within the image only.
    pub mipmaps: bool,
}

impl SamplerDesc {
    /// The glTF sampler object.
    fn to_gltf(self) -> gltf::Sampler {
        const NEAREST: u64 = 9728;
        const LINEAR: u64 = 9729;
        const NEAREST_MIPMAP_NEAREST: u64 = 9984;
        const LINEAR_MIPMAP_LINEAR: u64 = 9987;
        const CLAMP_TO_EDGE: u64 = 33071;
        const REPEAT: u64 = 10497;
        let wrap = |repeat: bool| if repeat { REPEAT } else { CLAMP_TO_EDGE };
        let (mag, min) = match (self.linear, self.mipmaps) {
            (true, true) => (LINEAR, LINEAR_MIPMAP_LINEAR),
            (true, false) => (LINEAR, LINEAR),
            (false, true) => (NEAREST, NEAREST_MIPMAP_NEAREST),
            (false, false) => (NEAREST, NEAREST),
        };
        gltf::Sampler {
            mag_filter: Some(mag),
            min_filter: Some(min),
            wrap_s: Some(wrap(self.repeat_u)),
            wrap_t: Some(wrap(self.repeat_v)),
            ..gltf::Sampler::default()
        }
    }
}

/// One primitive's edges: `EXT_mesh_primitive_edge_visibility` data plus the class of each hard
/// edge.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PrimitiveEdges {
    /// 2 bits per triangle edge (the draft's `visibility`).
    pub visibility: Vec<u8>,
    /// The draft's `silhouetteNormals`: two VEC3 normals per edge encoded as 1, in encoding order,
    /// in the component type stored (the bake writes BYTE normalized).
    pub silhouette_normals: StoredNormals,
    /// [`crate::ext::HardEdgeClass`] code of each edge encoded as 2, in encoding order.
    pub hard_edge_classes: Vec<u8>,
}

/// Unit vectors in one of the component types the merged `EXT_mesh_primitive_edge_visibility`
/// allows for `silhouetteNormals`, as stored; [`StoredNormals::decoded`] is what a glTF reader
/// computes from them (`drafter_core::snorm`), the values our hierarchies are exact for.
#[derive(Clone, Debug, PartialEq)]
pub enum StoredNormals {
    /// BYTE normalized (what the bake writes).
    Byte(Vec<[i8; 3]>),
    /// SHORT normalized.
    Short(Vec<[i16; 3]>),
    /// FLOAT.
    Float(Vec<[f32; 3]>),
}

impl Default for StoredNormals {
    fn default() -> Self {
        StoredNormals::Byte(Vec::new())
    }
}

impl StoredNormals {
    pub fn len(&self) -> usize {
        match self {
            StoredNormals::Byte(v) => v.len(),
            StoredNormals::Short(v) => v.len(),
            StoredNormals::Float(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Vector `i` as a glTF reader decodes it (not renormalised); `None` past the end.
    pub fn decoded(&self, i: usize) -> Option<glam::Vec3> {
        match self {
            StoredNormals::Byte(v) => v.get(i).map(|&c| drafter_core::snorm8_decode(c)),
            StoredNormals::Short(v) => v.get(i).map(|&c| drafter_core::snorm16_decode(c)),
            StoredNormals::Float(v) => v.get(i).map(|&c| glam::Vec3::from(c)),
        }
    }

    /// Every vector decoded (see [`StoredNormals::decoded`]).
    pub fn decoded_all(&self) -> Vec<glam::Vec3> {
        (0..self.len()).filter_map(|i| self.decoded(i)).collect()
    }
}

impl PrimitiveEdges {
    /// The 2-bit value of triangle edge `slot` (`3·t + k`: edge v_k → v_(k+1) of the primitive's
    /// triangle t), packed from the least significant bits; 0 past the end.
    pub fn value(&self, slot: usize) -> u8 {
        self.visibility.get(slot / 4).map_or(0, |b| (b >> (2 * (slot % 4))) & 3)
    }

    /// Every hard edge once: the slot encoded 2 and its class code (from `hard_edge_classes`, in
    /// encoding order; 0 where the list is short). Slots encoded 3 repeat an edge and are skipped.
    pub fn hard_edges(&self) -> impl Iterator<Item = (u32, u8)> + '_ {
        (0..self.visibility.len() * 4)
            .filter(|&slot| self.value(slot) == 2)
            .enumerate()
            .map(|(n, slot)| (slot as u32, self.hard_edge_classes.get(n).copied().unwrap_or(0)))
    }

    /// The slots encoded 1 (silhouette candidates), in encoding order: candidate i has the
    /// normals `silhouette_normals[2i..2i + 2]`.
    pub fn silhouette_slots(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.visibility.len() * 4).filter(|&slot| self.value(slot) == 1).map(|slot| slot as u32)
    }
}

/// A mesh's silhouette candidates and hierarchies, as flat arrays.
///
/// Format 0.2 stores no per-candidate data of its own: the candidates are the edges the mesh's
/// primitives encode as 1 in `EXT_mesh_primitive_edge_visibility`, primitive by primitive in
/// encoding order. `candidate_corners` and `candidate_normals` are what a reader derives from
/// those (and what the writer checks them against); the hierarchies' `order` arrays map storage
/// positions to candidates in that order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshSilhouettes {
    /// `3·t + k` of each candidate (edge k of mesh triangle t, triangles counted through the
    /// primitives in order). Derived, not stored.
    pub candidate_corners: Vec<u32>,
    /// 6 floats per candidate: both face normals as decoded from `silhouetteNormals`. Derived, not
    /// stored.
    pub candidate_normals: Vec<f32>,
    /// What answers orthographic views.
    pub orthographic: crate::OrthographicHierarchy,
    /// What answers perspective views.
    pub perspective: crate::PerspectiveHierarchy,
    /// The Gauss-map hierarchy as stored: no candidate order, a reader assigns the arcs to their
    /// cells again.
    pub gauss_map: Option<GaussMapArrays>,
    /// The cone BVH as stored: no candidate order, a reader replays the recorded splits.
    pub cone_bvh: Option<ConeBvhArrays>,
}

/// A mesh's vertices re-laid out by the normal stage: every output vertex copies the attributes of
/// one mesh vertex and carries two normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexData {
    /// For each output vertex, a mesh vertex (index into `Mesh::positions`) it copies. Where an
    /// output vertex spans several glTF primitives, the writer takes each primitive's own corner.
    pub source_vertex: Vec<u32>,
    /// The mesh's triangles in output vertex ids, same order and winding as `Mesh::triangles`.
    pub triangles: Vec<[u32; 3]>,
    /// Written as `NORMAL`; unit length.
    pub normals: Vec<[f32; 3]>,
    /// Written as [`ENHANCED_NORMAL_ATTRIBUTE`]; unit length.
    pub enhanced: Vec<[f32; 3]>,
}

/// The file layout to write.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Container {
    /// One self-contained .glb.
    Glb,
    /// A .gltf whose buffer is the file `bin_uri` beside it.
    Gltf { bin_uri: String },
}

/// The bytes of the written file(s).
#[derive(Clone, Debug)]
pub struct Written {
    /// The .glb or .gltf.
    pub main: Vec<u8>,
    /// The .bin of a .gltf container.
    pub bin: Option<Vec<u8>>,
    /// Things the writer could not do as asked (e.g. primitives whose vertices it could not re-lay
    /// out), one line each.
    pub notes: Vec<String>,
    /// What the bytes hold, as [`crate::byte_sections`] reads them from the written file (before
    /// any compression).
    pub sections: crate::ByteSections,
}

/// Serialises `out`. Deterministic: the same input gives the same bytes.
pub fn write(out: &BakeOutput, container: &Container) -> Result<Written, FormatError> {
    let scene = out.scene;
    if out.instance_parts.len() != scene.instances.len()
        || out.mesh_labels.len() != scene.meshes.len()
        || out.vertex_data.len() != scene.meshes.len()
        || out.primitive_edges.len() != scene.meshes.len()
        || out.mesh_silhouettes.len() != scene.meshes.len()
    {
        return Err(FormatError::Inconsistent(
            "instance_parts / mesh_labels / vertex_data do not match the scene".into(),
        ));
    }
    let from_source = scene.source.is_some();
    let mut doc = match &scene.source {
        Some(source) => Doc::from_source(&source.json, &source.buffers)?,
        None => synthesize(scene),
    };
    if from_source {
        keep_node_tree(&mut doc);
        drop_earlier_records(&mut doc);
    }
    let mut notes = Vec::new();
    // Node index of each instance: the source node, or the synthesized node i.
    let node_of = |i: usize| scene.instances[i].node.map_or(i, |n| n.index());
    // The part records join their nodes only as the document is serialised, one node at a time
    // (`node_extension` below): as a JSON tree beside the rest they were most of the writer's
    // memory and time on assemblies of many parts (20,000 one-triangle objects: a 435 MB peak,
    // 328 MB this way; docs/bench.md, "Many parts").
    let mut node_parts: Vec<Option<&[PartRecord]>> = vec![None; doc.root.nodes().len()];
    for (i, parts) in out.instance_parts.iter().enumerate() {
        let slot = node_parts
            .get_mut(node_of(i))
            .ok_or_else(|| FormatError::Inconsistent(format!("instance {i} has no node")))?;
        *slot = Some(parts);
    }
    let node_extension =
        |n: usize| node_parts.get(n).copied().flatten().map(|parts| serde_json::to_value(NodeExtensionRef { parts }));
    let mut edge_material: Option<usize> = None;
    // Every primitive's new layout at once, on the thread pool (the layouts do not depend on the
    // document); the document is then written in order.
    let layouts: Vec<Vec<Relaid>> = scene
        .meshes
        .par_iter()
        .zip(&out.vertex_data)
        .map(|(mesh, vd)| match vd {
            Some(vd) => {
                mesh.groups.par_iter().map(|g| relay(mesh, g, vd, (from_source, out.quantized_normals))).collect()
            }
            None => Vec::new(),
        })
        .collect();
    // Source primitives that lost every face (all their positions non-finite), per mesh.
    let mut emptied: Vec<Vec<usize>> = vec![Vec::new(); scene.meshes.len()];
    for (m, mesh) in scene.meshes.iter().enumerate() {
        let primitive_of = arrange_primitives(&mut doc, mesh, m, from_source)?;
        for (g, group) in mesh.groups.iter().enumerate() {
            let primitive = primitive_of[g];
            if from_source && group.count == 0 {
                emptied[m].push(primitive);
                continue;
            }
            let mut enhanced_normal = None;
            let relaid = match layouts[m].get(g) {
                Some(relaid) => match write_vertex_data(&mut doc, (m, primitive), relaid, from_source) {
                    Ok(()) => {
                        if out.quantized_normals {
                            doc.require_extension(MESH_QUANTIZATION_EXTENSION);
                        }
                        enhanced_normal = Some(ENHANCED_NORMAL_ATTRIBUTE.to_owned());
                        true
                    }
                    Err(reason) => {
                        notes.push(format!("mesh {m} primitive {primitive}: normals not written ({reason})"));
                        false
                    }
                },
                None => false,
            };
            if !relaid {
                if !from_source {
                    write_mesh_vertices(&mut doc, mesh, m, primitive, group)?;
                } else if group.vertex_count <= MAX_PRIMITIVE_VERTICES {
                    rewrite_if_faces_dropped(&mut doc, mesh, m, primitive, group)?;
                } else if let Err(reason) = gather_source_vertices(&mut doc, mesh, m, primitive, group) {
                    // Still valid glTF: the whole source vertex range, 32-bit indices.
                    notes.push(format!("mesh {m} primitive {primitive}: not written with 16-bit indices ({reason})"));
                    rewrite_if_faces_dropped(&mut doc, mesh, m, primitive, group)?;
                }
            }
            let part_labels = match &out.mesh_labels[m] {
                Some(labels) => {
                    let range = group.start as usize..(group.start + group.count) as usize;
                    let slice = labels
                        .get(range)
                        .ok_or_else(|| FormatError::Inconsistent(format!("mesh {m}: too few labels")))?;
                    Some(doc.push_scalars(slice, None) as u32)
                }
                None => None,
            };
            // The draft requires a non-zero value in the bitfield (CesiumJS stops rendering on an
            // all-zero one): a primitive with nothing to draw gets no extension, whatever the caller
            // passed (drafter-bake passes none; `tests/edge_extension.rs` there checks both).
            let edges =
                out.primitive_edges[m].get(g).and_then(Option::as_ref).filter(|e| e.visibility.iter().any(|&b| b != 0));
            let hard_edge_classes = match edges {
                Some(edges) => write_edges(&mut doc, (m, primitive), edges, &mut edge_material)?,
                None => None,
            };
            if part_labels.is_none() && enhanced_normal.is_none() && hard_edge_classes.is_none() {
                continue;
            }
            let ext = serde_json::to_value(PrimitiveExtension { part_labels, enhanced_normal, hard_edge_classes })?;
            primitive_mut(&mut doc, m, primitive)?.set_extension(EXTENSION, ext);
        }
        if let Some(sil) = &out.mesh_silhouettes[m] {
            write_silhouettes(&mut doc, m, sil, &out.primitive_edges[m])?;
        }
    }
    write_root(&mut doc, out)?;
    if emptied.iter().any(|e| !e.is_empty()) {
        drop_emptied(&mut doc, &emptied, &mut notes);
    }
    if from_source && let Err(why) = doc.compact(EXTENSION) {
        notes.push(format!("{why}; replaced vertex data is kept in the buffer"));
    }
    match container {
        Container::Glb => {
            let (main, sections) = doc.into_glb(EXTENSION, &node_extension)?;
            Ok(Written { main, bin: None, notes, sections })
        }
        Container::Gltf { bin_uri } => {
            let (main, bin, sections) = doc.into_gltf(bin_uri, EXTENSION, &node_extension)?;
            Ok(Written { main, bin: Some(bin), notes, sections })
        }
    }
}

/// Writes one primitive's `EXT_mesh_primitive_edge_visibility` (its edge material created on
/// first use) and returns the accessor of its hard-edge classes, if it has any.
fn write_edges(
    doc: &mut Doc,
    (m, primitive): (usize, usize),
    edges: &PrimitiveEdges,
    edge_material: &mut Option<usize>,
) -> Result<Option<u32>, FormatError> {
    let visibility = doc.push_typed_scalars(ComponentType::U8, &edges.visibility, edges.visibility.len());
    let material = *edge_material.get_or_insert_with(|| doc.push_material(edges_material()));
    let silhouette_normals =
        (!edges.silhouette_normals.is_empty()).then(|| doc.push_unit_vec3(&edges.silhouette_normals) as u64);
    let ext = gltf::EdgeVisibility {
        material: Some(material as u64),
        silhouette_normals,
        visibility: Some(visibility as u64),
        ..gltf::EdgeVisibility::default()
    };
    let hard_edge_classes = (!edges.hard_edge_classes.is_empty()).then(|| {
        doc.push_typed_scalars(ComponentType::U8, &edges.hard_edge_classes, edges.hard_edge_classes.len()) as u32
    });
    primitive_mut(doc, m, primitive)?.set_extension(EDGE_VISIBILITY_EXTENSION, Value::from(ext));
    doc.use_extension(EDGE_VISIBILITY_EXTENSION);
    Ok(hard_edge_classes)
}

/// Writes mesh `m`'s silhouette record, after checking it against the edges its primitives encode.
fn write_silhouettes(
    doc: &mut Doc,
    m: usize,
    sil: &MeshSilhouettes,
    edges: &[Option<PrimitiveEdges>],
) -> Result<(), FormatError> {
    let encoded: usize = edges.iter().flatten().map(|e| e.silhouette_normals.len() / 2).sum();
    if encoded != sil.candidate_corners.len() || 6 * encoded != sil.candidate_normals.len() {
        return Err(FormatError::Inconsistent(format!(
            "mesh {m}: {} silhouette candidates, but its primitives encode {encoded} edges as 1",
            sil.candidate_corners.len()
        )));
    }
    let record = silhouettes_record(doc, sil);
    let ext = serde_json::to_value(MeshExtension { silhouettes: Some(record) })?;
    mesh_mut(doc, m)?.set_extension(EXTENSION, ext);
    Ok(())
}

/// Writes the root record (with the embedded textures' indices) into the document's extensions.
fn write_root(doc: &mut Doc, out: &BakeOutput) -> Result<(), FormatError> {
    let mut root = out.root.clone();
    if let Some(textures) = &out.textures {
        root.textures = Some(write_textures(doc, textures)?);
    }
    // A source whose `extensions` was `null` reads as one without (the typed document takes a
    // null as absent), so the root record always has an object to go into.
    doc.root.set_extension(EXTENSION, serde_json::to_value(&root)?);
    doc.use_extension(EXTENSION);
    Ok(())
}

/// Appends the PNG images (buffer views), their samplers and textures after the document's own,
/// and returns the record with glTF texture indices.
fn write_textures(doc: &mut Doc, textures: &EmbeddedTextures) -> Result<TexturesRecord, FormatError> {
    let mut record = textures.record.clone();
    let mut referenced = vec![0usize; textures.images.len()];
    for &i in &record.indices() {
        let slot = referenced
            .get_mut(i as usize)
            .ok_or_else(|| FormatError::Inconsistent(format!("texture record refers to missing image {i}")))?;
        *slot += 1;
    }
    if let Some(i) = referenced.iter().position(|&n| n != 1) {
        return Err(FormatError::Inconsistent(format!(
            "embedded image {i} is referenced {} times, not once",
            referenced[i]
        )));
    }
    let image_base = doc.root.images().len();
    let texture_base = doc.root.textures().len();
    let sampler_base = doc.root.samplers.as_ref().map_or(0, Vec::len);
    let mut samplers: Vec<SamplerDesc> = Vec::new();
    for (i, image) in textures.images.iter().enumerate() {
        let view = doc.push_view(&image.png, None, None);
        doc.root.images.get_or_insert_default().push(gltf::Image {
            buffer_view: Some(view as u64),
            mime_type: Some("image/png".into()),
            name: Some(image.name.clone()),
            ..gltf::Image::default()
        });
        let sampler = match samplers.iter().position(|s| *s == image.sampler) {
            Some(s) => s,
            None => {
                samplers.push(image.sampler);
                doc.root.samplers.get_or_insert_default().push(image.sampler.to_gltf());
                samplers.len() - 1
            }
        };
        doc.root.textures.get_or_insert_default().push(gltf::Texture {
            sampler: Some((sampler_base + sampler) as u64),
            source: Some((image_base + i) as u64),
            name: Some(image.name.clone()),
            ..gltf::Texture::default()
        });
    }
    for index in record.indices_mut() {
        *index += texture_base as u32;
    }
    Ok(record)
}

/// A primitive's new vertex layout ([`relay`]): everything [`write_vertex_data`] writes that does
/// not depend on the document, so that it is computed for every primitive at once on the thread
/// pool before the document is written in order.
struct Relaid {
    /// The primitive's triangles in its own vertex numbers (order of first use).
    triangles: Vec<u32>,
    /// For each of its vertices, the mesh vertex it copies, less the group's first vertex.
    source_local: Vec<u32>,
    positions: Vec<[f32; 3]>,
    normals: RelaidNormals,
    /// The enhanced normals as normalized bytes.
    enhanced: Vec<[i8; 3]>,
    /// `TEXCOORD_0`, for a scene without a source document (otherwise gathered from the source).
    uvs: Option<Vec<[f32; 2]>>,
}

enum RelaidNormals {
    Float(Vec<[f32; 3]>),
    /// `KHR_mesh_quantization` bytes.
    Quantized(Vec<[i8; 3]>),
}

/// The new layout of `vd` restricted to `group`'s triangles and renumbered in order of first use.
fn relay(
    mesh: &Mesh,
    group: &TriangleGroup,
    vd: &VertexData,
    (from_source, quantized_normals): (bool, bool),
) -> Relaid {
    let range = group.start as usize..(group.start + group.count) as usize;
    let mut local_of = vec![u32::MAX; vd.source_vertex.len()];
    // Output vertex and the mesh vertex it copies here: the corner where it is first used in this
    // primitive (an output vertex may merge corners of several primitives; each keeps its own).
    let mut picks: Vec<(u32, u32)> = Vec::new();
    let mut triangles: Vec<u32> = Vec::with_capacity(range.len() * 3);
    for (t, mesh_triangle) in vd.triangles[range.clone()].iter().zip(&mesh.triangles[range]) {
        for (&o, &v) in t.iter().zip(mesh_triangle) {
            if local_of[o as usize] == u32::MAX {
                local_of[o as usize] = picks.len() as u32;
                picks.push((o, v));
            }
            triangles.push(local_of[o as usize]);
        }
    }
    let normals = if quantized_normals {
        RelaidNormals::Quantized(
            picks.iter().map(|&(o, _)| drafter_core::snorm8_encode_unit(vd.normals[o as usize].into())).collect(),
        )
    } else {
        RelaidNormals::Float(picks.iter().map(|&(o, _)| vd.normals[o as usize]).collect())
    };
    Relaid {
        triangles,
        source_local: picks.iter().map(|&(_, v)| v - group.first_vertex).collect(),
        positions: picks.iter().map(|&(_, v)| mesh.positions[v as usize].to_array()).collect(),
        normals,
        // Normalized bytes (stride 4): a quarter of FLOAT, within 0.4° (what gltfpack gives NORMAL).
        enhanced: picks.iter().map(|&(o, _)| drafter_core::snorm8_encode(vd.enhanced[o as usize].into())).collect(),
        uvs: match (&mesh.uvs, from_source) {
            (Some(uvs), false) => Some(picks.iter().map(|&(_, v)| uvs[v as usize].to_array()).collect()),
            _ => None,
        },
    }
}

/// Replaces a primitive's vertex attributes and indices by its new layout `relaid` ([`relay`]).
/// Attributes the scene model does not hold (colours, tangents, `_` attributes, more texture
/// coordinates) are gathered from the source bytes. Fails, changing nothing, for primitives with
/// morph targets or sparse attributes.
fn write_vertex_data(
    doc: &mut Doc,
    (m, primitive): (usize, usize),
    relaid: &Relaid,
    from_source: bool,
) -> Result<(), String> {
    let prim = primitive_mut(doc, m, primitive).map_err(|e| e.to_string())?;
    if prim.targets.is_some() {
        return Err("the primitive has morph targets".into());
    }
    let source = prim.attributes.clone().unwrap_or_default();
    let mut attributes = Attributes::new();
    if from_source {
        for (name, &accessor) in &source {
            if matches!(name.as_str(), "POSITION" | "NORMAL") || name == ENHANCED_NORMAL_ATTRIBUTE {
                continue;
            }
            let gathered = doc.gather_attribute(accessor as usize, &relaid.source_local).map_err(|e| e.to_string())?;
            attributes.insert(name.clone(), gathered as u64);
        }
    } else if let Some(uv) = &relaid.uvs {
        attributes.insert("TEXCOORD_0".into(), doc.push_vec2(uv) as u64);
    }
    attributes.insert("POSITION".into(), doc.push_vec3(&relaid.positions, true) as u64);
    let normal = match &relaid.normals {
        RelaidNormals::Quantized(bytes) => doc.push_snorm8_attribute(bytes),
        RelaidNormals::Float(normals) => doc.push_vec3(normals, false),
    };
    attributes.insert("NORMAL".into(), normal as u64);
    attributes.insert(ENHANCED_NORMAL_ATTRIBUTE.into(), doc.push_snorm8_attribute(&relaid.enhanced) as u64);
    set_triangle_list(doc, m, primitive, attributes, &relaid.triangles).map_err(|e| e.to_string())
}

/// Gives a primitive new attributes and a triangle list (indices in the smallest type that fits;
/// any `mode` removed: the default is triangles).
fn set_triangle_list(
    doc: &mut Doc,
    m: usize,
    primitive: usize,
    attributes: Attributes,
    triangles: &[u32],
) -> Result<(), FormatError> {
    let indices = doc.push_scalars(triangles, Some(ELEMENT_ARRAY_BUFFER));
    let prim = primitive_mut(doc, m, primitive)?;
    prim.attributes = Some(attributes);
    prim.indices = Some(indices as u64);
    prim.mode = None;
    Ok(())
}

/// The mesh's own vertices for a synthesized primitive (no new layout).
fn write_mesh_vertices(
    doc: &mut Doc,
    mesh: &Mesh,
    m: usize,
    primitive: usize,
    group: &TriangleGroup,
) -> Result<(), FormatError> {
    let range = group.start as usize..(group.start + group.count) as usize;
    // The group's vertex range; over the 16-bit limit (a chunk of a split group), the vertices its
    // triangles use, in order of first use.
    let (vertices, local): (Vec<u32>, Vec<u32>) = if group.vertex_count <= MAX_PRIMITIVE_VERTICES {
        let vertices = (group.first_vertex..group.first_vertex + group.vertex_count).collect();
        (vertices, mesh.triangles[range].iter().flatten().map(|&v| v - group.first_vertex).collect())
    } else {
        first_use(&mesh.triangles[range], group.first_vertex, group.vertex_count)
            .map(|(picks, local)| (picks.iter().map(|&l| l + group.first_vertex).collect(), local))
            .ok_or_else(|| FormatError::Inconsistent(format!("mesh {m}: a triangle outside its group's vertices")))?
    };
    let positions: Vec<[f32; 3]> = vertices.iter().map(|&v| mesh.positions[v as usize].to_array()).collect();
    let mut attributes = Attributes::from([("POSITION".to_owned(), doc.push_vec3(&positions, true) as u64)]);
    if let Some(normals) = &mesh.normals {
        // The spec requires unit normals; skip the attribute if any cannot be normalised.
        let unit: Option<Vec<[f32; 3]>> =
            vertices.iter().map(|&v| normals[v as usize].try_normalize().map(|n| n.to_array())).collect();
        if let Some(unit) = unit {
            attributes.insert("NORMAL".into(), doc.push_vec3(&unit, false) as u64);
        }
    }
    if let Some(uvs) = &mesh.uvs {
        let uv: Vec<[f32; 2]> = vertices.iter().map(|&v| uvs[v as usize].to_array()).collect();
        attributes.insert("TEXCOORD_0".into(), doc.push_vec2(&uv) as u64);
    }
    let indices = doc.push_scalars(&local, Some(ELEMENT_ARRAY_BUFFER));
    let prim = primitive_mut(doc, m, primitive)?;
    prim.attributes = Some(attributes);
    prim.indices = Some(indices as u64);
    Ok(())
}

/// The vertices of `triangles` within the range of `count` vertices from `first` (source-local
/// numbers, in order of first use) and the triangles' corners renumbered onto them; `None` when a
/// corner is outside the range. Also the index stream `bake --compress` settles its triangles'
/// rotations on (drafter-bake's `reorder.rs`), so that both number vertices the same way.
pub fn first_use(triangles: &[[u32; 3]], first: u32, count: u32) -> Option<(Vec<u32>, Vec<u32>)> {
    let mut local_of = vec![u32::MAX; count as usize];
    let mut picks = Vec::new();
    let mut local = Vec::with_capacity(3 * triangles.len());
    for &v in triangles.iter().flatten() {
        let slot = local_of.get_mut(v.checked_sub(first)? as usize)?;
        if *slot == u32::MAX {
            *slot = picks.len() as u32;
            picks.push(v - first);
        }
        local.push(*slot);
    }
    Some((picks, local))
}

/// Without a new layout, a glTF primitive's vertices restricted to what `group`'s triangles use,
/// renumbered in order of first use: how each chunk of a primitive split for 16-bit indices gets its
/// own vertices. `POSITION` is written from the scene (with the bounds the spec requires), every
/// other attribute gathered from the source bytes; the indices become a triangle list. Fails,
/// leaving the primitive as it was, for primitives with morph targets or sparse attributes (what it
/// had appended is unreferenced, and compaction drops it).
fn gather_source_vertices(
    doc: &mut Doc,
    mesh: &Mesh,
    m: usize,
    primitive: usize,
    group: &TriangleGroup,
) -> Result<(), String> {
    let range = group.start as usize..(group.start + group.count) as usize;
    let (picks, local) = first_use(&mesh.triangles[range], group.first_vertex, group.vertex_count)
        .ok_or("a triangle outside the primitive's vertices")?;
    let prim = primitive_mut(doc, m, primitive).map_err(|e| e.to_string())?;
    if prim.targets.is_some() {
        return Err("the primitive has morph targets".into());
    }
    let source = prim.attributes.clone().unwrap_or_default();
    let mut attributes = Attributes::new();
    for (name, &accessor) in &source {
        if name == "POSITION" {
            let positions: Vec<[f32; 3]> =
                picks.iter().map(|&l| mesh.positions[(group.first_vertex + l) as usize].to_array()).collect();
            attributes.insert(name.clone(), doc.push_vec3(&positions, true) as u64);
            continue;
        }
        let gathered = doc.gather_attribute(accessor as usize, &picks).map_err(|e| e.to_string())?;
        attributes.insert(name.clone(), gathered as u64);
    }
    set_triangle_list(doc, m, primitive, attributes, &local).map_err(|e| e.to_string())
}

/// The glTF primitive each of `mesh`'s groups is written to. A group is its source primitive (glTF
/// input) or the synthesized primitive of its own; when several groups come from one source
/// primitive (the bake split it so that every primitive fits 16-bit indices), the mesh's
/// `primitives` array is rebuilt with one copy of that primitive's JSON per group, consecutive and
/// in group order, the other primitives (those of no group too) kept in their order. So the file's
/// triangle primitives are the groups in order, and a mesh triangle's number counted through the
/// primitives is its index in `mesh.triangles`.
fn arrange_primitives(doc: &mut Doc, mesh: &Mesh, m: usize, from_source: bool) -> Result<Vec<usize>, FormatError> {
    let sources: Vec<usize> = mesh
        .groups
        .iter()
        .enumerate()
        .map(|(g, group)| if from_source { group.primitive.map_or(g, |p| p as usize) } else { g })
        .collect();
    let mut distinct = sources.clone();
    distinct.sort_unstable();
    distinct.dedup();
    if distinct.len() == sources.len() {
        return Ok(sources);
    }
    if sources.windows(2).any(|w| w[0] > w[1]) {
        return Err(FormatError::Inconsistent(format!("mesh {m}: split groups are not in primitive order")));
    }
    let mesh_json = mesh_mut(doc, m)?;
    let old = mesh_json.primitives.take().unwrap_or_default();
    let mut primitives = Vec::with_capacity(old.len() + sources.len());
    let mut primitive_of = Vec::with_capacity(sources.len());
    let mut g = 0;
    for (p, primitive) in old.into_iter().enumerate() {
        let first = g;
        while sources.get(g) == Some(&p) {
            primitive_of.push(primitives.len());
            primitives.push(primitive.clone());
            g += 1;
        }
        if g == first {
            primitives.push(primitive);
        }
    }
    if g != sources.len() {
        return Err(FormatError::Inconsistent(format!("mesh {m} has no primitive {}", sources[g])));
    }
    mesh_json.primitives = Some(primitives);
    Ok(primitive_of)
}

/// The material `EXT_mesh_primitive_edge_visibility.material` names on every primitive: black and
/// matte, so that engines that draw the edges (CesiumJS colours them with it) set them apart from
/// their faces. Appended once after the input's materials, whose indices do not change.
pub const EDGE_MATERIAL_NAME: &str = "drafter edges";

fn edges_material() -> gltf::Material {
    material(EDGE_MATERIAL_NAME, [0.0, 0.0, 0.0, 1.0], 0.0, 1.0)
}

/// A material of this name and metallic-roughness factors (numbers written as `f32`s are, as the
/// `f64` they widen to).
fn material(name: &str, base_color: [f32; 4], metallic: f32, roughness: f32) -> gltf::Material {
    gltf::Material {
        name: Some(name.to_owned()),
        pbr_metallic_roughness: Some(gltf::PbrMetallicRoughness {
            base_color_factor: Some(Value::from(base_color.to_vec())),
            metallic_factor: Some(Value::from(metallic)),
            roughness_factor: Some(Value::from(roughness)),
            ..gltf::PbrMetallicRoughness::default()
        }),
        ..gltf::Material::default()
    }
}

/// The mesh's hierarchies: integer arrays in the smallest unsigned type that holds them, float
/// arrays as FLOAT, split bytes as UNSIGNED_BYTE.
fn silhouettes_record(doc: &mut Doc, sil: &MeshSilhouettes) -> SilhouettesRecord {
    let gauss_map = sil.gauss_map.as_ref().map(|g| GaussMapRecord {
        base: g.base,
        max_depth: g.max_depth,
        overlap: g.overlap,
        node_caps: doc.push_f32_scalars(&g.node_caps) as u32,
        nodes: doc.push_scalars(&g.nodes, None) as u32,
    });
    let cone_bvh = sil.cone_bvh.as_ref().map(|b| ConeBvhRecord {
        normal_level: b.normal_level,
        leaf_size: b.leaf_size,
        node_boxes: doc.push_f32_scalars(&b.node_boxes) as u32,
        node_cones: doc.push_f32_scalars(&b.node_cones) as u32,
        nodes: doc.push_scalars(&b.nodes, None) as u32,
        splits: (!b.splits.is_empty())
            .then(|| doc.push_typed_scalars(ComponentType::U8, &b.splits, b.splits.len()) as u32),
        split_starts: doc.push_scalars(&b.split_starts, None) as u32,
    });
    SilhouettesRecord {
        candidates: sil.candidate_corners.len() as u32,
        orthographic: sil.orthographic,
        perspective: sil.perspective,
        gauss_map,
        cone_bvh,
    }
}

/// A primitive's attributes: name → accessor index.
type Attributes = std::collections::BTreeMap<String, u64>;

fn mesh_mut(doc: &mut Doc, mesh: usize) -> Result<&mut gltf::Mesh, FormatError> {
    doc.root
        .meshes
        .as_mut()
        .and_then(|m| m.get_mut(mesh))
        .ok_or_else(|| FormatError::Inconsistent(format!("no mesh {mesh}")))
}

fn primitive_mut(doc: &mut Doc, mesh: usize, primitive: usize) -> Result<&mut gltf::Primitive, FormatError> {
    doc.root
        .meshes
        .as_mut()
        .and_then(|m| m.get_mut(mesh))
        .and_then(|m| m.primitives.as_mut())
        .and_then(|p| p.get_mut(primitive))
        .ok_or_else(|| FormatError::Inconsistent(format!("mesh {mesh} has no primitive {primitive}")))
}

/// The importer drops faces that use NaN positions; when it did, the source primitive's indices no
/// longer match our triangles (and the labels written per triangle), so the primitive gets a new
/// triangle-list index accessor with the surviving triangles.
fn rewrite_if_faces_dropped(
    doc: &mut Doc,
    mesh: &Mesh,
    m: usize,
    primitive: usize,
    group: &TriangleGroup,
) -> Result<(), FormatError> {
    let prim = primitive_mut(doc, m, primitive)?;
    let (indices, positions, mode) = (prim.indices, prim.attribute("POSITION"), prim.mode.unwrap_or(4));
    let count_of = |accessor: Option<u64>| accessor.and_then(|a| doc.root.accessor_count(a)).unwrap_or(0);
    let elements = match indices {
        Some(i) => count_of(Some(i)),
        None => count_of(positions),
    };
    let source_triangles = if mode == 4 { elements / 3 } else { elements.saturating_sub(2) };
    if source_triangles == u64::from(group.count) {
        return Ok(());
    }
    let range = group.start as usize..(group.start + group.count) as usize;
    let local: Vec<u32> = mesh.triangles[range].iter().flatten().map(|&v| v - group.first_vertex).collect();
    let accessor = doc.push_scalars(&local, Some(ELEMENT_ARRAY_BUFFER));
    let prim = primitive_mut(doc, m, primitive)?;
    prim.indices = Some(accessor as u64);
    prim.mode = None;
    Ok(())
}

/// Makes the source's node graph a forest again where it is not (a cycle, a node listed as the
/// child of two nodes, a scene root that is also some node's child): glTF forbids all three, and
/// the importer reports them and skips every repeat (`drafter_io`'s walk). The same walk here, from
/// the default scene's roots first (each in order, children in order, a node taken where it is
/// first reached), keeps the links the importer followed and drops the others from `children`
/// and from the scenes' `nodes`, so the written file describes the scene that was baked. A graph
/// that is already a forest is left untouched.
fn keep_node_tree(doc: &mut Doc) {
    let node_count = doc.root.nodes().len();
    let indices = |list: &Option<Vec<u64>>| -> Vec<Option<usize>> {
        list.iter().flatten().map(|&i| usize::try_from(i).ok()).collect()
    };
    let children: Vec<Vec<Option<usize>>> = doc.root.nodes().iter().map(|n| indices(&n.children)).collect();
    let scenes: Vec<Vec<Option<usize>>> = doc.root.scenes.iter().flatten().map(|s| indices(&s.nodes)).collect();
    let default = doc.root.scene.map_or(0, |s| s as usize);
    let scene_order = std::iter::once(default).chain((0..scenes.len()).filter(|&s| s != default));
    // Which entries of each `children` and scene `nodes` list lead to a node's first visit.
    let mut keep_child: Vec<Vec<bool>> = children.iter().map(|c| vec![false; c.len()]).collect();
    let mut keep_root: Vec<Vec<bool>> = scenes.iter().map(|r| vec![false; r.len()]).collect();
    let mut visited = vec![false; node_count];
    // Nodes to visit and where each was listed, popped in preorder.
    let mut stack: Vec<(usize, Listed)> = Vec::new();
    let starts = scene_order
        .filter(|&s| s < scenes.len())
        .flat_map(|s| scenes[s].iter().enumerate().map(move |(slot, &n)| (n, Listed::Root { scene: s, slot })))
        .chain((0..node_count).map(|n| (Some(n), Listed::Unlisted)))
        .collect::<Vec<_>>();
    for (start, listed) in starts {
        let Some(start) = start.filter(|&n| n < node_count) else { continue };
        if visited[start] {
            continue;
        }
        stack.push((start, listed));
        while let Some((id, listed)) = stack.pop() {
            if std::mem::replace(&mut visited[id], true) {
                continue;
            }
            match listed {
                Listed::Root { scene, slot } => keep_root[scene][slot] = true,
                Listed::Child { parent, slot } => keep_child[parent][slot] = true,
                Listed::Unlisted => {}
            }
            for (slot, &c) in children[id].iter().enumerate().rev() {
                if let Some(c) = c.filter(|&c| c < node_count) {
                    stack.push((c, Listed::Child { parent: id, slot }));
                }
            }
        }
    }
    // The list at `key` of `object` without its dropped entries; the key goes where none is left
    // (glTF forbids empty lists). Untouched where every entry is kept.
    let keep_listed = |list: &mut Option<Vec<u64>>, keep: &[bool]| {
        if keep.iter().all(|&k| k) {
            return;
        }
        let kept: Vec<u64> = list.iter().flatten().zip(keep).filter(|&(_, &k)| k).map(|(&i, _)| i).collect();
        *list = (!kept.is_empty()).then_some(kept);
    };
    for (n, node) in doc.root.nodes.iter_mut().flatten().enumerate() {
        keep_listed(&mut node.children, &keep_child[n]);
    }
    for (s, scene) in doc.root.scenes.iter_mut().flatten().enumerate() {
        keep_listed(&mut scene.nodes, &keep_root[s]);
    }
}

/// A source baked before carries this format's records on its nodes, meshes and primitives, and
/// the Khronos edges on its primitives: they describe the earlier bake, so they go, and this bake
/// writes its own where it has them (the root's record is replaced whole anyway). Left in place, a
/// record this bake did not replace contradicted the file or was not read at all (as drafter-fuzz
/// found): a mesh without silhouette candidates now kept the earlier candidates' count over
/// primitives that encode none; a node that is no instance now (its parent lost its `children`)
/// kept the earlier part records, whatever they had become. Either file did not read back. The
/// accessors they named are then unreferenced, and the compaction drops them.
fn drop_earlier_records(doc: &mut Doc) {
    for node in doc.root.nodes.iter_mut().flatten() {
        node.remove_extension(EXTENSION);
    }
    for mesh in doc.root.meshes.iter_mut().flatten() {
        mesh.remove_extension(EXTENSION);
        for primitive in mesh.primitives.iter_mut().flatten() {
            primitive.remove_extension(EXTENSION);
            primitive.remove_extension(EDGE_VISIBILITY_EXTENSION);
        }
    }
}

/// Removes source primitives that lost every face on import (each position NaN or infinite), and
/// meshes left with none (nodes then keep no `mesh`, later meshes are renumbered): written as they
/// were, they would keep their non-finite positions and an empty index accessor, both invalid glTF.
/// Their accessors become unreferenced, so the compaction that follows drops them. An empty
/// primitive holds no triangles, so the triangle order the edges and hierarchies refer to, which
/// runs over a mesh's primitives in order, is unchanged.
fn drop_emptied(doc: &mut Doc, emptied: &[Vec<usize>], notes: &mut Vec<String>) {
    let mut removed_meshes = Vec::new();
    for (m, primitives) in emptied.iter().enumerate().filter(|(_, p)| !p.is_empty()) {
        let Some(list) = doc.root.meshes.as_mut().and_then(|meshes| meshes.get_mut(m)?.primitives.as_mut()) else {
            continue;
        };
        let mut drop: Vec<usize> = primitives.iter().copied().filter(|&p| p < list.len()).collect();
        drop.sort_unstable();
        drop.dedup();
        for &p in drop.iter().rev() {
            list.remove(p);
        }
        notes.push(format!("mesh {m}: {} primitive(s) without a finite face left out", drop.len()));
        if list.is_empty() {
            removed_meshes.push(m);
        }
    }
    if removed_meshes.is_empty() {
        return;
    }
    for node in doc.root.nodes.iter_mut().flatten() {
        let Some(mesh) = node.mesh.map(|m| m as usize) else { continue };
        node.mesh = match removed_meshes.binary_search(&mesh) {
            Ok(_) => None,
            Err(removed_before) => Some((mesh - removed_before) as u64),
        };
    }
    let meshes = doc.root.meshes.get_or_insert_default();
    for &m in removed_meshes.iter().rev() {
        meshes.remove(m);
    }
    if meshes.is_empty() {
        doc.root.meshes = None;
    }
    notes.push(format!("{} mesh(es) without a finite face left out", removed_meshes.len()));
}

/// Where [`keep_node_tree`]'s walk found a node: in a scene's `nodes`, in a parent's `children`,
/// or nowhere (a node outside every scene, walked last).
#[derive(Clone, Copy)]
enum Listed {
    Root { scene: usize, slot: usize },
    Child { parent: usize, slot: usize },
    Unlisted,
}

/// The material given to primitives of a mesh input (OBJ without `usemtl`, STL, OFF, PLY) that
/// name none: a neutral light grey dielectric. glTF's own default (white, fully metallic) renders
/// washed out or dark in plain viewers, which have no environment to reflect.
pub const DEFAULT_MATERIAL: drafter_core::Material =
    drafter_core::Material { name: String::new(), base_color: [0.8, 0.8, 0.8, 1.0], metallic: 0.0, roughness: 0.5 };
/// Its name in the output.
pub const DEFAULT_MATERIAL_NAME: &str = "drafter default";

/// A fresh document for input without one: materials (the input's, then [`DEFAULT_MATERIAL`] when
/// some primitive names none), one mesh per scene mesh (one primitive per triangle group), one node
/// per instance, one scene.
fn synthesize(scene: &Scene) -> Doc {
    let mut root = gltf::Root {
        asset: Some(gltf::Asset {
            version: Some("2.0".into()),
            generator: Some(crate::GENERATOR.into()),
            ..gltf::Asset::default()
        }),
        ..gltf::Root::default()
    };
    let material_of = |m: &drafter_core::Material, name: &str| material(name, m.base_color, m.metallic, m.roughness);
    let mut materials: Vec<gltf::Material> = scene.materials.iter().map(|m| material_of(m, &m.name)).collect();
    let needs_default = scene.meshes.iter().flat_map(|m| &m.groups).any(|g| g.material.is_none());
    let default_material = needs_default.then(|| {
        materials.push(material_of(&DEFAULT_MATERIAL, DEFAULT_MATERIAL_NAME));
        materials.len() - 1
    });
    root.materials = (!materials.is_empty()).then_some(materials);
    // Primitives get their attributes and indices from `write`, with or without a new layout.
    let meshes = scene.meshes.iter().map(|mesh| {
        let primitives = mesh.groups.iter().map(|group| gltf::Primitive {
            attributes: Some(Attributes::new()),
            material: group.material.map(|m| m.0 as usize).or(default_material).map(|m| m as u64),
            ..gltf::Primitive::default()
        });
        gltf::Mesh {
            primitives: Some(primitives.collect()),
            name: (!mesh.name.is_empty()).then(|| mesh.name.clone()),
            ..gltf::Mesh::default()
        }
    });
    root.meshes = Some(meshes.collect());
    let nodes: Vec<gltf::Node> = scene
        .instances
        .iter()
        .map(|inst| gltf::Node {
            name: Some(inst.name.clone()),
            mesh: Some(u64::from(inst.mesh.0)),
            matrix: (inst.world_from_object != glam::DMat4::IDENTITY)
                .then(|| Value::from(inst.world_from_object.to_cols_array().to_vec())),
            ..gltf::Node::default()
        })
        .collect();
    let roots: Vec<u64> = (0..nodes.len() as u64).collect();
    root.nodes = Some(nodes);
    root.scenes = Some(vec![gltf::Scene { nodes: Some(roots), ..gltf::Scene::default() }]);
    root.scene = Some(0);
    Doc::new(root)
}
