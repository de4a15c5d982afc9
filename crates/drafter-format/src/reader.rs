//! Reads a baked file back into the extension's types (the viewer and `drafter inspect` use it).
//! [`read`] gives the extension's records (the root's `textures` holds the glTF texture indices of
//! the baked lookups); [`read_textures`] gives those textures' PNG bytes.

use serde::Deserialize;
use serde_json::Value;

use crate::FormatError;
use crate::accessor::{self, ComponentType, Layout, LayoutError};
use crate::gltf::{EdgeVisibility, Extensible, Root};

/// `bytes`, or the plain GLB they decode to when they use `EXT_meshopt_compression` (see
/// `crate::meshopt`): every reader here takes compressed and plain files alike.
fn plain(bytes: &[u8]) -> Result<std::borrow::Cow<'_, [u8]>, FormatError> {
    if crate::glb::is_glb(bytes)
        && let Some(decoded) = crate::meshopt::decompress_glb(bytes).map_err(|e| FormatError::Invalid(e.to_string()))?
    {
        return Ok(std::borrow::Cow::Owned(decoded));
    }
    Ok(std::borrow::Cow::Borrowed(bytes))
}
use crate::ext::{
    EDGE_VISIBILITY_EXTENSION, EXTENSION, FORMAT_VERSION, MeshExtension, NodeExtension, PartRecord, PrimitiveExtension,
    RootExtension, TexturesRecord,
};
use crate::writer::{MeshSilhouettes, PrimitiveEdges, StoredNormals};
use drafter_core::hierarchy::{ConeBvhArrays, GaussMapArrays};

/// What a baked file carries in `DRAFTER_illustration`.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedFile {
    pub root: RootExtension,
    /// (node index, its parts), in node order.
    pub nodes: Vec<(u32, NodeExtension)>,
    /// (mesh index, primitive index, part label per triangle), in mesh then primitive order.
    pub primitive_labels: Vec<(u32, u32, Vec<u32>)>,
    /// (mesh index, primitive index, its edges): `EXT_mesh_primitive_edge_visibility` plus our
    /// `hardEdgeClasses`, in mesh then primitive order. The same type the writer takes.
    pub primitive_edges: Vec<(u32, u32, PrimitiveEdges)>,
    /// (mesh index, its silhouette candidates and hierarchies), in mesh order. The same type the
    /// writer takes; drafter-lines' `SilhouetteIndex::from_arrays` loads the arrays.
    pub mesh_silhouettes: Vec<(u32, MeshSilhouettes)>,
}

impl BakedFile {
    /// Every part, ordered by id.
    pub fn parts(&self) -> Vec<&PartRecord> {
        let mut parts: Vec<&PartRecord> = self.nodes.iter().flat_map(|(_, n)| n.parts.iter()).collect();
        parts.sort_by_key(|p| p.id);
        parts
    }
}

/// Splits a .glb into its JSON and BIN chunks, or returns a .gltf's JSON as is. The container is
/// framed by [`crate::glb`], the workspace's one GLB reader.
pub fn split_container(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), FormatError> {
    if !crate::glb::is_glb(bytes) {
        return Ok((bytes, None));
    }
    let chunks = crate::glb::split(bytes)?;
    Ok((chunks.json, chunks.bin))
}

/// The extension's records of the file at `path` (its bytes), or `None` when it is not a baked
/// glTF: not a glTF container, or no `DRAFTER_illustration` in its JSON. The one answer to "is this
/// file baked?" for the viewer and inspect; a .gltf's buffer is loaded by [`crate::external_buffers`].
pub fn read_if_baked(path: &std::path::Path, bytes: &[u8]) -> Result<Option<BakedFile>, FormatError> {
    let Ok((json, _)) = split_container(bytes) else { return Ok(None) };
    let marker = EXTENSION.as_bytes();
    if !json.windows(marker.len()).any(|w| w == marker) {
        return Ok(None);
    }
    match read(bytes, &crate::external_buffers(path)) {
        Ok(baked) => Ok(Some(baked)),
        Err(FormatError::NotBaked(_)) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The PNG bytes of one texture the extension refers to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EmbeddedPng {
    /// glTF texture index (as in `root.textures`).
    pub texture: u32,
    /// The image's `name`.
    pub name: String,
    /// The PNG file's bytes.
    pub png: Vec<u8>,
}

/// The PNG images of every texture `root.extensions.DRAFTER_illustration.textures` refers to, in the
/// record's order (gradient, cel, cool-to-warm, hatching levels, metal bands, metal highlights);
/// empty when the file has no textures. `external` loads a .gltf's buffer, as for [`read`].
pub fn read_textures(
    bytes: &[u8],
    external: &dyn Fn(&str) -> Option<Vec<u8>>,
) -> Result<Vec<EmbeddedPng>, FormatError> {
    let decoded = plain(bytes)?;
    let bytes = &*decoded;
    let (json, bin) = split_container(bytes)?;
    let doc = Root::from_slice(json)?;
    /// The root extension's `textures` alone, whatever the rest holds.
    #[derive(Deserialize)]
    struct Textures {
        #[serde(default)]
        textures: Option<TexturesRecord>,
    }
    let Some(record) = doc.extension::<Textures>(EXTENSION).transpose()?.and_then(|t| t.textures) else {
        return Ok(Vec::new());
    };
    let buffer = load_buffer(&doc, bin, external)?;
    record
        .indices()
        .into_iter()
        .map(|texture| {
            let bad = |what: &str| FormatError::Invalid(format!("/textures/{texture}: {what}"));
            let source = doc
                .textures()
                .get(texture as usize)
                .and_then(|t| t.source)
                .ok_or_else(|| bad("missing, or no source"))?;
            let image = doc.images().get(at(source)).ok_or_else(|| bad("image missing"))?;
            if image.mime_type.as_deref() != Some("image/png") {
                return Err(bad("image is not image/png"));
            }
            let view = image.buffer_view.ok_or_else(|| bad("image has no bufferView"))?;
            let view = doc.buffer_views().get(at(view)).ok_or_else(|| bad("bufferView missing"))?;
            let start = view.byte_offset.unwrap_or(0) as usize;
            let length = view.byte_length.ok_or_else(|| bad("no byteLength"))? as usize;
            let png = buffer
                .as_deref()
                .and_then(|b| b.get(start..start.checked_add(length)?))
                .ok_or_else(|| bad("image bytes outside the buffer"))?
                .to_vec();
            let name = image.name.clone().unwrap_or_default();
            Ok(EmbeddedPng { texture, name, png })
        })
        .collect()
}

/// The bytes of the single buffer: the .glb's BIN chunk or the .gltf's external file.
fn load_buffer(
    doc: &Root,
    bin: Option<&[u8]>,
    external: &dyn Fn(&str) -> Option<Vec<u8>>,
) -> Result<Option<Vec<u8>>, FormatError> {
    Ok(match doc.buffers().first() {
        Some(b) => match b.uri.as_deref() {
            Some(uri) => Some(external_buffer(uri, external)?),
            None => bin.map(<[u8]>::to_vec),
        },
        None => None,
    })
}

/// A glTF index as a position in its array (`usize::MAX`, found nowhere, when it does not fit).
fn at(index: u64) -> usize {
    usize::try_from(index).unwrap_or(usize::MAX)
}

/// The bytes of the buffer file `uri`, loaded by `external`.
fn external_buffer(uri: &str, external: &dyn Fn(&str) -> Option<Vec<u8>>) -> Result<Vec<u8>, FormatError> {
    external(uri).ok_or_else(|| FormatError::Invalid(format!("cannot load buffer {uri:?}")))
}

/// The root object of the extension, refused unless its `version` is the one this crate reads
/// (layouts change between versions; an older file is baked again, not guessed at).
fn root_extension(doc: &Root) -> Result<RootExtension, FormatError> {
    /// The extension's `version` alone (any JSON), read before its layout.
    #[derive(Deserialize)]
    struct Versioned {
        #[serde(default)]
        version: Value,
    }
    let not_baked = || FormatError::NotBaked(format!("no {EXTENSION} extension on the root"));
    let found = doc.extension::<Versioned>(EXTENSION).ok_or_else(not_baked)?.map(|v| v.version);
    match found.as_ref().ok().and_then(Value::as_str) {
        Some(FORMAT_VERSION) => Ok(doc.extension(EXTENSION).ok_or_else(not_baked)??),
        found => Err(FormatError::Version(found.unwrap_or("(none)").to_owned())),
    }
}

/// Reads a baked .glb, or a .gltf whose buffer `external` returns (given the buffer's URI).
pub fn read(bytes: &[u8], external: &dyn Fn(&str) -> Option<Vec<u8>>) -> Result<BakedFile, FormatError> {
    let decoded = plain(bytes)?;
    let bytes = &*decoded;
    let (json, bin) = split_container(bytes)?;
    let doc = Root::from_slice(json)?;
    let root = root_extension(&doc)?;
    let buffer = load_buffer(&doc, bin, external)?;
    let mut nodes = Vec::new();
    for (i, node) in doc.nodes().iter().enumerate() {
        if let Some(ext) = node.extension::<NodeExtension>(EXTENSION) {
            nodes.push((i as u32, ext?));
        }
    }
    let data = || buffer.as_deref().ok_or_else(|| FormatError::Invalid("accessors but no buffer".into()));
    let mut primitive_labels = Vec::new();
    let mut primitive_edges = Vec::new();
    let mut mesh_silhouettes = Vec::new();
    for (m, mesh) in doc.meshes().iter().enumerate() {
        // Mesh-wide number of each primitive's first triangle, and the edges of this mesh.
        let mut first_triangle = 0u64;
        let mut mesh_edges: Vec<(u64, usize)> = Vec::new();
        for (p, prim) in mesh.primitives().iter().enumerate() {
            let triangles = prim.triangle_count(&doc);
            let ours = prim.extension::<PrimitiveExtension>(EXTENSION).transpose()?;
            if let Some(accessor) = ours.as_ref().and_then(|e| e.part_labels) {
                primitive_labels.push((m as u32, p as u32, scalars(&doc, accessor as usize, data()?)?));
            }
            if let Some(edges) = prim.extension::<EdgeVisibility>(EDGE_VISIBILITY_EXTENSION).transpose()? {
                let bad = |what: &str| FormatError::Invalid(format!("/meshes/{m}/primitives/{p}: {what}"));
                let visibility = edges.visibility.ok_or_else(|| bad("edge visibility without `visibility`"))?;
                let narrow = |values: Vec<u32>, what: &str| -> Result<Vec<u8>, FormatError> {
                    values.into_iter().map(|v| u8::try_from(v).map_err(|_| bad(what))).collect()
                };
                let silhouette_normals = match edges.silhouette_normals {
                    Some(a) => read_unit_vec3s(&doc, at(a), data()?)?,
                    None => StoredNormals::default(),
                };
                let hard_edge_classes = match ours.as_ref().and_then(|e| e.hard_edge_classes) {
                    Some(a) => narrow(scalars(&doc, a as usize, data()?)?, "hardEdgeClasses above 8 bits")?,
                    None => Vec::new(),
                };
                mesh_edges.push((first_triangle, primitive_edges.len()));
                primitive_edges.push((
                    m as u32,
                    p as u32,
                    PrimitiveEdges {
                        visibility: narrow(scalars(&doc, at(visibility), data()?)?, "visibility above 8 bits")?,
                        silhouette_normals,
                        hard_edge_classes,
                    },
                ));
            }
            first_triangle += triangles;
        }
        let Some(ext) = mesh.extension::<MeshExtension>(EXTENSION) else { continue };
        if let Some(s) = ext?.silhouettes {
            let data = data()?;
            let u32s = |a: u32| scalars(&doc, a as usize, data);
            let f32s = |a: u32| floats(&doc, a as usize, data);
            let (candidate_corners, candidate_normals) = derived_candidates(&mesh_edges, &primitive_edges)
                .map_err(|what| FormatError::Invalid(format!("/meshes/{m}: {what}")))?;
            let silhouettes = MeshSilhouettes {
                candidate_corners,
                candidate_normals,
                orthographic: s.orthographic,
                perspective: s.perspective,
                gauss_map: match s.gauss_map {
                    Some(g) => Some(GaussMapArrays {
                        base: g.base,
                        max_depth: g.max_depth,
                        overlap: g.overlap,
                        node_caps: f32s(g.node_caps)?,
                        nodes: u32s(g.nodes)?,
                    }),
                    None => None,
                },
                cone_bvh: match s.cone_bvh {
                    Some(b) => Some(ConeBvhArrays {
                        normal_level: b.normal_level,
                        leaf_size: b.leaf_size,
                        node_boxes: f32s(b.node_boxes)?,
                        node_cones: f32s(b.node_cones)?,
                        nodes: u32s(b.nodes)?,
                        splits: b
                            .splits
                            .map(u32s)
                            .transpose()?
                            .unwrap_or_default()
                            .into_iter()
                            .map(|v| {
                                u8::try_from(v)
                                    .map_err(|_| FormatError::Invalid(format!("/meshes/{m}: splits above 8 bits")))
                            })
                            .collect::<Result<_, _>>()?,
                        split_starts: u32s(b.split_starts)?,
                    }),
                    None => None,
                },
            };
            if silhouettes.candidate_corners.len() != s.candidates as usize {
                return Err(FormatError::Invalid(format!(
                    "/meshes/{m}: {} silhouette candidates, but the primitives encode {} edges as 1",
                    s.candidates,
                    silhouettes.candidate_corners.len()
                )));
            }
            mesh_silhouettes.push((m as u32, silhouettes));
        }
    }
    Ok(BakedFile { root, nodes, primitive_labels, primitive_edges, mesh_silhouettes })
}

/// Reads a FLOAT SCALAR accessor of the document `doc` (its JSON, parsed) from the single buffer.
pub fn read_floats(doc: &Value, accessor: usize, buffer: &[u8]) -> Result<Vec<f32>, FormatError> {
    floats(&Root::deserialize(doc)?, accessor, buffer)
}

/// Reads an unsigned SCALAR accessor of the document `doc` (its JSON, parsed) from the single
/// buffer.
pub fn read_scalars(doc: &Value, accessor: usize, buffer: &[u8]) -> Result<Vec<u32>, FormatError> {
    scalars(&Root::deserialize(doc)?, accessor, buffer)
}

/// Reads a FLOAT SCALAR accessor from the single buffer.
fn floats(doc: &Root, accessor: usize, buffer: &[u8]) -> Result<Vec<f32>, FormatError> {
    let (a, view, layout) = accessor_in(doc, accessor, buffer, "SCALAR")?;
    if a.component != ComponentType::F32 {
        return Err(FormatError::Invalid(format!("/accessors/{accessor}: not a FLOAT accessor")));
    }
    Ok(accessor::read_vectors::<1>(view, &layout, a.component, false).into_iter().map(|[v]| v).collect())
}

/// Reads an unsigned SCALAR accessor from the single buffer.
fn scalars(doc: &Root, accessor: usize, buffer: &[u8]) -> Result<Vec<u32>, FormatError> {
    let (a, view, layout) = accessor_in(doc, accessor, buffer, "SCALAR")?;
    accessor::read_indices(view, &layout, a.component)
        .ok_or_else(|| FormatError::Invalid(format!("/accessors/{accessor}: not an unsigned integer type")))
}

/// The two sets of vertex normals of one primitive of a baked file (the paper's toggle, Cignoni et
/// al. 2005): one entry per vertex of the primitive, in its vertex order.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveNormals {
    pub mesh: u32,
    pub primitive: u32,
    /// The crease-aware normals of the original shading.
    pub normals: Vec<[f32; 3]>,
    /// The enhanced normals.
    pub enhanced: Vec<[f32; 3]>,
}

/// Both normal sets of every primitive that declares an enhanced-normal attribute
/// (`DRAFTER_illustration.enhancedNormal`, normally `_ENHANCED_NORMAL`), in mesh then primitive
/// order, sorted out by the root's `normals.enhancedInNormal` (when true, `NORMAL` holds the enhanced
/// set and the attribute the crease-aware one). Empty for a file baked without normals.
/// `external` loads a .gltf's buffer, as for [`read`].
pub fn read_normal_sets(
    bytes: &[u8],
    external: &dyn Fn(&str) -> Option<Vec<u8>>,
) -> Result<Vec<PrimitiveNormals>, FormatError> {
    let decoded = plain(bytes)?;
    let bytes = &*decoded;
    let (json, bin) = split_container(bytes)?;
    let doc = Root::from_slice(json)?;
    let root = root_extension(&doc)?;
    let swapped = root.normals.as_ref().is_some_and(|n| n.enhanced_in_normal);
    let mut buffer = None;
    let mut sets = Vec::new();
    for (m, mesh) in doc.meshes().iter().enumerate() {
        for (p, prim) in mesh.primitives().iter().enumerate() {
            let Some(ext) = prim.extension::<PrimitiveExtension>(EXTENSION) else { continue };
            let Some(name) = ext?.enhanced_normal else { continue };
            let bad = |what: &str| FormatError::Invalid(format!("/meshes/{m}/primitives/{p}: {what}"));
            let attribute = |key: &str| {
                prim.attribute(key)
                    .ok_or_else(|| bad(&format!("enhancedNormal names {name}, but the primitive has no {key}")))
            };
            let (normal_accessor, other_accessor) = (attribute("NORMAL")?, attribute(&name)?);
            if buffer.is_none() {
                buffer = Some(
                    load_buffer(&doc, bin, external)?
                        .ok_or_else(|| FormatError::Invalid("accessors but no buffer".into()))?,
                );
            }
            let data = buffer.as_deref().unwrap_or_default();
            let normal = read_vec3s(&doc, at(normal_accessor), data)?;
            let other = read_vec3s(&doc, at(other_accessor), data)?;
            if normal.len() != other.len() {
                return Err(bad(&format!("NORMAL has {} entries but {name} has {}", normal.len(), other.len())));
            }
            let (normals, enhanced) = if swapped { (other, normal) } else { (normal, other) };
            sets.push(PrimitiveNormals { mesh: m as u32, primitive: p as u32, normals, enhanced });
        }
    }
    Ok(sets)
}

/// `v` at unit length (+Z when it has none).
fn unit(v: glam::Vec3) -> [f32; 3] {
    v.try_normalize().unwrap_or(glam::Vec3::Z).to_array()
}

/// A mesh's silhouette candidates as format 0.2 defines them: the edges its primitives encode as 1,
/// primitive by primitive in encoding order, as corners `3·t + k` counted through the mesh's
/// triangles, with the two decoded normals of each. `edges` lists each primitive with edges as (its
/// first mesh triangle, its index in `all`).
fn derived_candidates(
    edges: &[(u64, usize)],
    all: &[(u32, u32, PrimitiveEdges)],
) -> Result<(Vec<u32>, Vec<f32>), String> {
    let mut corners = Vec::new();
    let mut normals = Vec::new();
    for &(first, i) in edges {
        let e = &all[i].2;
        let slots: Vec<u32> = e.silhouette_slots().collect();
        if e.silhouette_normals.len() != 2 * slots.len() {
            return Err(format!(
                "primitive {}: {} edges encoded 1 but {} silhouetteNormals",
                all[i].1,
                slots.len(),
                e.silhouette_normals.len()
            ));
        }
        for (k, slot) in slots.into_iter().enumerate() {
            let corner = (3 * first + u64::from(slot))
                .try_into()
                .map_err(|_| format!("primitive {}: triangle numbers beyond 32 bits", all[i].1))?;
            corners.push(corner);
            for n in [2 * k, 2 * k + 1].into_iter().filter_map(|i| e.silhouette_normals.decoded(i)) {
                normals.extend(n.to_array());
            }
        }
    }
    Ok((corners, normals))
}

/// What the readers need of an accessor's JSON.
struct AccessorInfo {
    component: ComponentType,
    normalized: bool,
}

/// An accessor of `kind` (`"SCALAR"`, `"VEC3"`) in the single buffer: its type, its buffer view's
/// bytes and its elements' layout there, every offset checked with checked arithmetic (the numbers
/// come from the file).
fn accessor_in<'a>(
    doc: &Root,
    accessor: usize,
    buffer: &'a [u8],
    kind: &str,
) -> Result<(AccessorInfo, &'a [u8], Layout), FormatError> {
    let bad = |what: &str| FormatError::Invalid(format!("/accessors/{accessor}: {what}"));
    let a = doc.accessors().get(accessor).ok_or_else(|| bad("missing"))?;
    if a.kind.as_deref() != Some(kind) {
        return Err(bad(&format!("not a {kind} accessor")));
    }
    let component = a.component_type.and_then(ComponentType::from_code).ok_or_else(|| bad("no valid componentType"))?;
    let normalized = a.normalized.unwrap_or(false);
    let view_index = at(a.buffer_view.ok_or_else(|| bad("no bufferView"))?);
    let view = doc.buffer_views().get(view_index).ok_or_else(|| bad("bufferView missing"))?;
    let count = a.count.ok_or_else(|| bad("no count"))?;
    let view_length = view.byte_length.ok_or_else(|| bad("bufferView has no byteLength"))?;
    let view_bytes = usize::try_from(view.byte_offset.unwrap_or(0))
        .ok()
        .zip(usize::try_from(view_length).ok())
        .and_then(|(start, length)| buffer.get(start..start.checked_add(length)?))
        .ok_or_else(|| bad("data outside the buffer"))?;
    let components = if kind == "VEC3" { 3 } else { 1 };
    let as_usize = |v: u64| usize::try_from(v).map_err(|_| bad("data outside its buffer view"));
    let layout = Layout::new(
        view_bytes.len(),
        Some(as_usize(view.byte_stride.unwrap_or(0))?),
        as_usize(a.byte_offset.unwrap_or(0))?,
        as_usize(count)?,
        components * component.size(),
    )
    .map_err(|e| match e {
        LayoutError::StrideTooSmall => bad("byteStride smaller than an element"),
        LayoutError::OutsideView => bad("data outside its buffer view"),
    })?;
    Ok((AccessorInfo { component, normalized }, view_bytes, layout))
}

/// Reads a VEC3 accessor of unit vectors as stored: BYTE or SHORT normalized, or FLOAT, the three
/// component types the merged `EXT_mesh_primitive_edge_visibility` allows for `silhouetteNormals`.
fn read_unit_vec3s(doc: &Root, accessor: usize, buffer: &[u8]) -> Result<StoredNormals, FormatError> {
    let (a, view, layout) = accessor_in(doc, accessor, buffer, "VEC3")?;
    match (a.component, a.normalized) {
        (ComponentType::I8, true) => {
            Ok(StoredNormals::Byte(layout.elements(view).map(|c| [c[0] as i8, c[1] as i8, c[2] as i8]).collect()))
        }
        (ComponentType::I16, true) => Ok(StoredNormals::Short(
            layout
                .elements(view)
                .map(|c| std::array::from_fn(|k| i16::from_le_bytes([c[2 * k], c[2 * k + 1]])))
                .collect(),
        )),
        (ComponentType::F32, false) => {
            Ok(StoredNormals::Float(accessor::read_vectors(view, &layout, a.component, false)))
        }
        _ => Err(FormatError::Invalid(format!(
            "/accessors/{accessor}: silhouetteNormals must be FLOAT, or BYTE or SHORT normalized"
        ))),
    }
}

/// Reads a VEC3 accessor of FLOAT, or of BYTE / SHORT normalized (decoded as glTF defines, then
/// renormalised: these are shading normals), from the single buffer, tightly packed or strided.
fn read_vec3s(doc: &Root, accessor: usize, buffer: &[u8]) -> Result<Vec<[f32; 3]>, FormatError> {
    let (a, view, layout) = accessor_in(doc, accessor, buffer, "VEC3")?;
    match (a.component, a.normalized) {
        (ComponentType::F32, _) => Ok(accessor::read_vectors(view, &layout, a.component, false)),
        (ComponentType::I8 | ComponentType::I16, true) => {
            Ok(accessor::read_vectors::<3>(view, &layout, a.component, true)
                .into_iter()
                .map(|v| unit(glam::Vec3::from(v)))
                .collect())
        }
        _ => Err(FormatError::Invalid(format!(
            "/accessors/{accessor}: not a FLOAT, or BYTE or SHORT normalized, VEC3 accessor"
        ))),
    }
}

/// Bytes of a baked file by what they hold. Each buffer view is counted once, under the first use
/// found (mesh attributes and indices, then the edge extensions, then our hierarchies, then
/// images); `json` is the JSON text, `other` everything else (padding, the GLB framing, buffer
/// views of the input that nothing above names).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct ByteSections {
    /// Indices, POSITION and every vertex attribute but the normals.
    pub geometry: u64,
    /// `NORMAL` and the enhanced normals (`_ENHANCED_NORMAL`).
    pub normals: u64,
    /// `EXT_mesh_primitive_edge_visibility`: `visibility` and `silhouetteNormals`.
    pub khronos_edges: u64,
    /// `DRAFTER_illustration` per primitive: part labels and hard-edge classes.
    pub labels: u64,
    /// `DRAFTER_illustration` silhouette hierarchies (nodes, bounds, split bytes).
    pub hierarchies: u64,
    /// Images (the input's and the baked lookup textures).
    pub textures: u64,
    pub json: u64,
    pub other: u64,
    pub total: u64,
}

/// [`ByteSections`] of a .glb, or of a .gltf whose buffer `external` returns. The JSON is read as
/// the typed document the writer holds, and counted by the writer's own `sections_of`, so that a
/// bake's report and `drafter inspect` count alike by construction.
pub fn byte_sections(bytes: &[u8], external: &dyn Fn(&str) -> Option<Vec<u8>>) -> Result<ByteSections, FormatError> {
    let decoded = plain(bytes)?;
    let bytes = &*decoded;
    let (json, _) = split_container(bytes)?;
    let doc = Root::from_slice(json)?;
    let external_bytes = match doc.buffers().first().and_then(|b| b.uri.as_deref()) {
        Some(uri) => external_buffer(uri, external)?.len() as u64,
        None => 0,
    };
    Ok(sections_of(&doc).sized(json.len() as u64, bytes.len() as u64 + external_bytes))
}

/// [`ByteSections`] of the document `doc`, its JSON and its total still 0 ([`ByteSections::sized`]
/// gives them). The writer calls this on the document it serialises, so the bake's report does not
/// parse the file back.
pub(crate) fn sections_of(doc: &Root) -> ByteSections {
    let views = doc.buffer_views();
    let mut counted = vec![false; views.len()];
    let mut count_view = |view: Option<u64>, into: &mut u64| {
        if let Some(v) = view.map(|v| v as usize).filter(|&v| v < views.len())
            && !std::mem::replace(&mut counted[v], true)
        {
            *into += views[v].byte_length.unwrap_or(0);
        }
    };
    let view_of = |accessor: u64| doc.accessors().get(accessor as usize)?.buffer_view;
    let mut s = ByteSections::default();
    let enhanced = crate::ext::ENHANCED_NORMAL_ATTRIBUTE;
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            for (name, &accessor) in prim.attributes.iter().flatten() {
                let into = if name == "NORMAL" || name == enhanced { &mut s.normals } else { &mut s.geometry };
                count_view(view_of(accessor), into);
            }
            if let Some(indices) = prim.indices {
                count_view(view_of(indices), &mut s.geometry);
            }
            let edge_keys = ["visibility", "silhouetteNormals"];
            prim.extension_indices(EDGE_VISIBILITY_EXTENSION, &edge_keys, &mut |a| {
                count_view(view_of(a), &mut s.khronos_edges)
            });
            prim.extension_indices(EXTENSION, &["partLabels", "hardEdgeClasses"], &mut |a| {
                count_view(view_of(a), &mut s.labels)
            });
        }
        let hierarchy_keys = ["nodeCaps", "nodes", "nodeBoxes", "nodeCones", "splits", "splitStarts"];
        mesh.extension_indices(EXTENSION, &hierarchy_keys, &mut |a| count_view(view_of(a), &mut s.hierarchies));
    }
    for image in doc.images() {
        count_view(image.buffer_view, &mut s.textures);
    }
    s
}

impl ByteSections {
    /// The sections with the JSON's bytes `json` and the file's (or the .glb's and its .bin's)
    /// `total`, and what no section names as `other`.
    pub(crate) fn sized(mut self, json: u64, total: u64) -> Self {
        let s = &mut self;
        s.json = json;
        s.total = total;
        let named = s.geometry + s.normals + s.khronos_edges + s.labels + s.hierarchies + s.textures + s.json;
        s.other = s.total.saturating_sub(named);
        self
    }
}
