//! What the renderer draws, prepared on the CPU: one draw batch per mesh, its instances, and the
//! per-part parameters the shaders index by part id.
//!
//! # From a baked file
//! A mesh stores one part label per triangle (the primitive's `partLabels`); the node that draws
//! the mesh lists its parts, indexed by label. So the part of a fragment is
//! `label_to_part[instance.label_base + label]`, where each instance owns a slice of
//! `label_to_part` holding its node's part ids. Labels are per triangle and vertices are shared
//! between triangles, so a vertex used by triangles of two labels (or two materials) is split in
//! two: the label then travels as a flat vertex attribute and the whole mesh is still one draw,
//! however many parts it holds.
//!
//! # From any other file
//! A file without the extension still renders: each instance is one part, its projector laid along
//! the longest side of its world-space bounding box (facing away from the scene centre, as the
//! bake's heuristic does) with the default gradient, and a notice says so.
//!
//! # Normals
//! A baked file carries two normal sets per primitive: the crease-aware `NORMAL` and the enhanced
//! normals of Cignoni et al. 2005 (`_ENHANCED_NORMAL`; swapped when the bake put the enhanced ones in
//! `NORMAL`). Both are read ([`drafter_format::read_normal_sets`]) and split with the vertices, so a
//! batch can be drawn with either (the viewer's `RenderOptions::enhanced_normals`); other files keep their
//! imported normals.
//!
//! # Lookup textures
//! A baked file's NPR lookup textures (`DRAFTER_illustration.textures`) are decoded on load into
//! [`Model::lookups`] ([`crate::lookups`]); where the file has none, or one does not fit, the
//! G-buffer computes that lookup procedurally, and a notice says which source is used.
//!
//! Positions are moved into *render space*, the world translated so that the centre of the
//! scene's bounds is the origin: the transforms are composed in f64 and rounded once, so CAD
//! coordinates far from the world origin keep their precision in f32.

use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;

use drafter_core::gradient::{DEFAULT_FADE_STEP, DEFAULT_POWER, DEFAULT_QUANTIZATION, TransferCurve};
use drafter_core::{Aabb, Diagnostic, Scene};
use drafter_format::{BakedFile, FormatError, PartRecord, PrimitiveNormals};
use glam::{DMat3, DMat4, DVec3, DVec4};
use rayon::prelude::*;

use crate::edges::Hierarchies;
use crate::layout::{InstanceGpu, MaterialGpu, NO_STYLE, NOT_FLAT, PartGpu, Vertex};
use crate::lookups::BakedLookups;
use crate::style::{Style, transfer_index};

/// Colour of triangles without a material (display values).
pub const DEFAULT_BASE_COLOR: [f32; 4] = [0.8, 0.8, 0.8, 1.0];

/// Why a file cannot be loaded for rendering.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file cannot be read or parsed as a model (the input's fault).
    #[error(transparent)]
    Import(#[from] drafter_io::ImportError),
    /// The file carries `DRAFTER_illustration` data that cannot be read (the input's fault).
    #[error("{path}: {source}")]
    Baked { path: String, source: FormatError },
    /// Nothing to draw.
    #[error("{0}: the scene has no triangles to render")]
    Empty(String),
}

/// One draw: a mesh with split vertices, drawn once per instance in `instances`.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub name: String,
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
    /// The enhanced normals (Cignoni et al. 2005) of `vertices`, one each, when the file carries them
    /// (`_ENHANCED_NORMAL`): what the viewer's `RenderOptions::enhanced_normals` draws instead of
    /// `Vertex::normal_in_object`.
    pub enhanced_normals: Option<Vec<[f32; 3]>>,
    /// Range of [`Model::instances`] that draws this batch.
    pub instances: Range<u32>,
}

/// A part as the viewer knows it: what picking reports and what the shaders read.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub id: u32,
    pub name: String,
    /// The baked style hint, if any.
    pub style: Option<Style>,
    /// The baked record; `None` for parts the viewer made up for an unbaked file.
    pub record: Option<PartRecord>,
    pub gpu: PartGpu,
}

/// A scene ready for upload.
#[derive(Clone, Debug)]
pub struct Model {
    pub batches: Vec<Batch>,
    /// Every instance, grouped by batch.
    pub instances: Vec<InstanceGpu>,
    /// Per instance, the scene mesh it draws.
    pub instance_mesh: Vec<u32>,
    /// Per instance, its world transform in f64 (the silhouette query takes the eye into object
    /// space with its inverse).
    pub instance_world_from_object: Vec<DMat4>,
    /// The baked edges the lines pass draws (empty for an unbaked file).
    pub lines: crate::edges::ModelLines,
    /// Per instance, its part ids by label (see the module docs).
    pub label_to_part: Vec<u32>,
    /// Indexed by part id.
    pub parts: Vec<Part>,
    /// Index 0 is the default material; scene material `m` is at `m + 1`.
    pub materials: Vec<MaterialGpu>,
    /// World-space bounds of every drawn vertex.
    pub bounds: Aabb,
    /// World position of the render-space origin.
    pub origin: DVec3,
    /// Corners of every instance's bounding box, in render space: they contain every drawn
    /// vertex (the soft shadow's ground map covers their shadow).
    pub fit_points: Vec<glam::Vec3>,
    /// Vertices of the drawn geometry's convex hull, in render space: what the camera frames
    /// (tighter than [`Self::fit_points`]: a gear's or a shaft's box corners stick out of it):
    /// each mesh's [`crate::camera::hull_sample`] placed by every instance, sampled again.
    pub frame_points: Vec<glam::Vec3>,
    /// Whether the file carried `DRAFTER_illustration` data.
    pub baked: bool,
    /// The file's lookup textures (see [`Self::set_lookups`]).
    lookups: BakedLookups,
    /// What the viewer substituted or could not use, and where its lookup textures come from (one
    /// line each).
    pub notices: Vec<String>,
    /// The importer's diagnostics.
    pub diagnostics: Vec<Diagnostic>,
}

impl Model {
    /// Reads `path` (any format drafter-io imports) and its `DRAFTER_illustration` data, if any.
    pub fn load(path: &Path) -> Result<Model, LoadError> {
        Self::load_within(path, &drafter_io::Limits::default())
    }

    /// As [`Self::load`], refusing a file that lists more than `limits` allows.
    pub fn load_within(path: &Path, limits: &drafter_io::Limits) -> Result<Model, LoadError> {
        let bytes =
            std::fs::read(path).map_err(|source| drafter_io::ImportError::Io { path: path.to_path_buf(), source })?;
        Self::load_bytes_within(path, &bytes, limits)
    }

    /// As [`Self::load`], for bytes already read from `path` (which names the file and resolves a
    /// glTF's external buffers).
    pub fn load_bytes(path: &Path, bytes: &[u8]) -> Result<Model, LoadError> {
        Self::load_bytes_within(path, bytes, &drafter_io::Limits::default())
    }

    /// As [`Self::load_bytes`], refusing a file that lists more than `limits` allows.
    pub fn load_bytes_within(path: &Path, bytes: &[u8], limits: &drafter_io::Limits) -> Result<Model, LoadError> {
        Self::load_bytes_with(path, bytes, limits, Hierarchies::AtLoad)
    }

    /// [`Self::load_bytes_within`], building the silhouette hierarchies when `hierarchies` says (the
    /// browser's page defers them past its first frame: [`Hierarchies::Deferred`]).
    pub fn load_bytes_with(
        path: &Path,
        bytes: &[u8],
        limits: &drafter_io::Limits,
        hierarchies: Hierarchies,
    ) -> Result<Model, LoadError> {
        Self::load_bytes_inner(path, bytes, limits, hierarchies, true)
    }

    /// What a line drawing reads: [`Self::load_bytes_within`] with no silhouette hierarchies built
    /// ([`Hierarchies::Never`]) and no lookup textures decoded (a drawing shades nothing with them,
    /// so it neither pays for their PNGs nor notes where they came from).
    pub fn load_bytes_for_drawing(path: &Path, bytes: &[u8], limits: &drafter_io::Limits) -> Result<Model, LoadError> {
        Self::load_bytes_inner(path, bytes, limits, Hierarchies::Never, false)
    }

    fn load_bytes_inner(
        path: &Path,
        bytes: &[u8],
        limits: &drafter_io::Limits,
        hierarchies: Hierarchies,
        lookups: bool,
    ) -> Result<Model, LoadError> {
        // A compressed GLB (EXT_meshopt_compression) is decoded once, and everything below reads
        // the plain bytes; a stream that does not decode is reported by the import.
        let plain = drafter_format::meshopt::decompress_glb(bytes).ok().flatten();
        let bytes = plain.as_deref().unwrap_or(bytes);
        let imported = drafter_io::import_bytes_within(path, bytes, limits)?;
        let baked = read_baked(path, bytes)?;
        let normal_sets = match &baked {
            Some(_) => read_normal_sets(path, bytes)?,
            None => Vec::new(),
        };
        let mut model = Model::build(&imported.scene, baked.as_ref(), &normal_sets, hierarchies)
            .ok_or_else(|| LoadError::Empty(path.display().to_string()))?;
        model.diagnostics = imported.diagnostics;
        if let Some(record) = baked.as_ref().and_then(|b| b.root.textures.as_ref()).filter(|_| lookups) {
            let external = drafter_format::external_buffers(path);
            let (lookups, notices) = BakedLookups::read(Some(record), bytes, &external);
            model.notices.extend(notices);
            model.set_lookups(lookups);
        }
        if !lookups {
            // The procedural fallbacks `build` noted are not the drawing's business either.
            model.notices.retain(|n| !n.starts_with(crate::lookups::NOTICE_PREFIX));
        }
        Ok(model)
    }

    /// Prepares `scene` with its baked data (`None` for an unbaked file). `None` when the scene
    /// draws no triangles.
    pub fn from_scene(scene: &Scene, baked: Option<&BakedFile>) -> Option<Model> {
        Self::from_scene_with_normals(scene, baked, &[])
    }

    /// As [`Self::from_scene`], with the baked normal sets of the file's primitives
    /// ([`drafter_format::read_normal_sets`]): the batches then carry both the crease-aware and the
    /// enhanced normals, for the toggle.
    pub fn from_scene_with_normals(
        scene: &Scene,
        baked: Option<&BakedFile>,
        normal_sets: &[PrimitiveNormals],
    ) -> Option<Model> {
        Self::build(scene, baked, normal_sets, Hierarchies::AtLoad)
    }

    fn build(
        scene: &Scene,
        baked: Option<&BakedFile>,
        normal_sets: &[PrimitiveNormals],
        hierarchies: Hierarchies,
    ) -> Option<Model> {
        let bounds = scene.world_bounds();
        if bounds.is_empty() || scene.instanced_triangle_count() == 0 {
            return None;
        }
        let origin = (bounds.min + bounds.max) * 0.5;
        let mut notices = Vec::new();
        if baked.is_none() {
            notices.push(
                "no DRAFTER_illustration data: each instance is one part with a projector along its bounding \
                 box (bake the file for parts, oriented boxes and gradients)"
                    .to_owned(),
            );
        }

        let triangle_labels = mesh_labels(scene, baked, &mut notices);
        let mesh_normals = mesh_normal_sets(scene, normal_sets, &mut notices);
        let node_parts: HashMap<u32, &[PartRecord]> = baked
            .map(|b| b.nodes.iter().map(|(node, ext)| (*node, ext.parts.as_slice())).collect())
            .unwrap_or_default();
        let baked_part_count = baked_part_count(baked, &mut notices);

        let mut parts: Vec<Option<Part>> = vec![None; baked_part_count as usize];
        let mut fallback_parts = Vec::new();
        let mut instances = Vec::new();
        let mut instance_mesh = Vec::new();
        let mut instance_world_from_object = Vec::new();
        let mut label_to_part = Vec::new();
        let mut batches = Vec::new();
        let mut fit_points = Vec::new();
        let mut hull_candidates = Vec::new();
        let mut faults = RecordFaults::default();

        // Each mesh's hull sample on its own: independent, so on the thread pool (in mesh order).
        let supports: Vec<Vec<DVec3>> = scene
            .meshes
            .par_iter()
            .map(|mesh| {
                crate::camera::hull_sample(&mesh.positions).into_iter().map(|i| mesh.positions[i].as_dvec3()).collect()
            })
            .collect();
        for (mesh_index, (mesh, support)) in scene.meshes.iter().zip(supports).enumerate() {
            let labels = &triangle_labels[mesh_index];
            let label_count = labels.iter().copied().max().map_or(1, |m| m + 1);
            let first_instance = instances.len() as u32;
            for instance in scene.instances.iter().filter(|i| i.mesh.index() == mesh_index) {
                let label_base = label_to_part.len() as u32;
                let records = instance.node.and_then(|n| node_parts.get(&n.0).copied()).filter(|r| !r.is_empty());
                match records {
                    Some(records) => {
                        if (records.len() as u32) < label_count {
                            faults.short_part_lists += 1;
                        }
                        for label in 0..label_count as usize {
                            let record = records.get(label).unwrap_or(&records[0]);
                            if record.id >= baked_part_count {
                                faults.bad_ids += 1;
                                label_to_part.push(u32::MAX); // patched below to a fallback part
                                continue;
                            }
                            label_to_part.push(record.id);
                            let slot = &mut parts[record.id as usize];
                            if slot.is_none() {
                                *slot = Some(baked_part(record, origin));
                            }
                        }
                    }
                    None => {
                        if baked.is_some() {
                            faults.missing_node_parts += 1;
                        }
                        let id = baked_part_count + fallback_parts.len() as u32;
                        let world = mesh.bounds().transformed(&instance.world_from_object);
                        fallback_parts.push(fallback_part(id, &instance.name, &world, origin));
                        label_to_part.extend(std::iter::repeat_n(id, label_count as usize));
                    }
                }
                if label_to_part[label_base as usize..].contains(&u32::MAX) {
                    let id = baked_part_count + fallback_parts.len() as u32;
                    let world = mesh.bounds().transformed(&instance.world_from_object);
                    fallback_parts.push(fallback_part(id, &instance.name, &world, origin));
                    for slot in &mut label_to_part[label_base as usize..] {
                        if *slot == u32::MAX {
                            *slot = id;
                        }
                    }
                }
                instances.push(instance_gpu(&instance.world_from_object, origin, label_base, label_count));
                instance_mesh.push(mesh_index as u32);
                instance_world_from_object.push(instance.world_from_object);
                let object = mesh.bounds();
                if !object.is_empty() {
                    let render_from_object = DMat4::from_translation(-origin) * instance.world_from_object;
                    fit_points.extend(object.corners().map(|c| render_from_object.transform_point3(c).as_vec3()));
                    hull_candidates.extend(support.iter().map(|&p| render_from_object.transform_point3(p).as_vec3()));
                }
            }
            let last_instance = instances.len() as u32;
            if last_instance > first_instance && !mesh.triangles.is_empty() {
                let (vertices, indices, enhanced_normals) =
                    split_vertices_with(mesh, labels, mesh_normals[mesh_index].as_ref());
                batches.push(Batch {
                    name: mesh.name.clone(),
                    vertices,
                    indices,
                    enhanced_normals,
                    instances: first_instance..last_instance,
                });
            }
        }

        faults.report(&mut notices);

        let parts = dense_parts(parts, fallback_parts, &bounds, origin);

        let materials = material_table(scene);

        let lines = baked
            .map(|b| {
                crate::edges::ModelLines::from_scene_with(
                    scene,
                    b,
                    &instance_mesh,
                    &instance_world_from_object,
                    hierarchies,
                )
            })
            .unwrap_or_default();
        notices.extend(lines.notices.iter().cloned());

        let frame_points =
            crate::camera::hull_sample(&hull_candidates).into_iter().map(|i| hull_candidates[i]).collect();

        let mut model = Model {
            batches,
            instances,
            instance_mesh,
            instance_world_from_object,
            lines,
            label_to_part,
            parts,
            materials,
            bounds,
            origin,
            fit_points,
            frame_points,
            baked: baked.is_some(),
            lookups: BakedLookups::default(),
            notices,
            diagnostics: Vec::new(),
        };
        // Procedural until the caller reads the file's textures ([`Self::load_bytes`]).
        model.set_lookups(BakedLookups::default());
        Some(model)
    }

    /// The lookup textures the G-buffer binds (what [`Self::load`] read from the file).
    pub fn lookups(&self) -> &BakedLookups {
        &self.lookups
    }

    /// Replaces the lookup textures (for a file read by other means, or a test's altered images).
    /// A γ atlas that lacks some part's curve is dropped (procedural tables instead); the notices
    /// say so and which source each lookup has.
    pub fn set_lookups(&mut self, mut lookups: BakedLookups) {
        // The curves of the parts drawn (ids no node uses get a placeholder that is never drawn).
        let mut drawn = vec![false; self.parts.len()];
        for &id in &self.label_to_part {
            if let Some(d) = drawn.get_mut(id as usize) {
                *d = true;
            }
        }
        let curves = self.parts.iter().zip(drawn).filter(|(_, d)| *d).map(|(p, _)| part_curve(&p.gpu));
        let dropped = lookups.require_curves(curves);
        self.notices.retain(|n| !n.starts_with(crate::lookups::NOTICE_PREFIX));
        self.notices.extend(dropped);
        self.notices.push(lookups.notice());
        self.lookups = lookups;
    }

    /// Whether some batch carries enhanced normals (the file was baked with them).
    pub fn has_enhanced_normals(&self) -> bool {
        self.batches.iter().any(|b| b.enhanced_normals.is_some())
    }

    /// Triangles drawn (every instance counted).
    pub fn triangle_count(&self) -> usize {
        self.batches.iter().map(|b| b.indices.len() / 3 * b.instances.len()).sum()
    }

    /// The part with scene-wide id `id`.
    pub fn part(&self, id: u32) -> Option<&Part> {
        self.parts.get(id as usize)
    }

    /// Replaces the baked record of part `record.id` (an edit) and its GPU record with it; the
    /// selection flags stay. False when there is no such baked part.
    pub fn set_part_record(&mut self, record: &PartRecord) -> bool {
        let origin = self.origin;
        let Some(part) = self.parts.get_mut(record.id as usize).filter(|p| p.record.is_some()) else { return false };
        let flags = part.gpu.flags;
        *part = baked_part(record, origin);
        part.gpu.flags = flags;
        true
    }

    /// Marks the selected parts and the reference part for the G-buffer's highlight (see
    /// [`crate::layout::PART_SELECTED`]).
    pub fn set_selection(&mut self, selected: &[u32], reference: Option<u32>) {
        for part in &mut self.parts {
            part.gpu.flags = 0;
        }
        for &id in selected {
            if let Some(part) = self.parts.get_mut(id as usize) {
                part.gpu.flags |= crate::layout::PART_SELECTED;
            }
        }
        if let Some(part) = reference.and_then(|id| self.parts.get_mut(id as usize)) {
            part.gpu.flags |= crate::layout::PART_SELECTED | crate::layout::PART_REFERENCE;
        }
    }

    /// Per-part GPU records, indexed by part id, each with the row of its transfer curve in the γ
    /// atlas the G-buffer binds (the file's when [`Self::lookups`] has one, else the procedural
    /// atlas, whose rows are [`TransferCurve::ALL`]).
    pub fn part_table(&self) -> Vec<PartGpu> {
        self.parts
            .iter()
            .map(|p| {
                let mut gpu = p.gpu;
                if let Some(gamma) = &self.lookups.gamma {
                    gpu.gradient[3] = gamma.row(part_curve(&p.gpu)).unwrap_or(0) as f32;
                }
                gpu
            })
            .collect()
    }
}

/// The baked part ids in use: `partCount`, but never more than the part records present. Ids are
/// dense `0..partCount`, one per record: a count beyond the records is a broken (or hostile) file,
/// and is never used to size an allocation.
fn baked_part_count(baked: Option<&BakedFile>, notices: &mut Vec<String>) -> u32 {
    let records = baked.map_or(0, |b| b.nodes.iter().map(|(_, ext)| ext.parts.len()).sum::<usize>());
    let declared = baked.map_or(0, |b| b.root.part_count);
    let count = declared.min(u32::try_from(records).unwrap_or(u32::MAX));
    if declared > count {
        notices.push(format!(
            "partCount {declared} but {records} part records: ids from {count} on are drawn as unbaked parts"
        ));
    }
    count
}

/// What was wrong with a file's part records, counted while the instances are mapped to parts.
#[derive(Default)]
struct RecordFaults {
    bad_ids: usize,
    missing_node_parts: usize,
    short_part_lists: usize,
}

impl RecordFaults {
    fn report(&self, notices: &mut Vec<String>) {
        let RecordFaults { bad_ids, missing_node_parts, short_part_lists } = *self;
        if bad_ids > 0 {
            notices.push(format!("{bad_ids} part references with an id ≥ partCount: drawn as unbaked parts"));
        }
        if missing_node_parts > 0 {
            notices.push(format!(
                "{missing_node_parts} instances have no baked parts: each drawn as one part with a bounding-box projector"
            ));
        }
        if short_part_lists > 0 {
            notices.push(format!(
                "{short_part_lists} instances have fewer parts than their mesh has labels: extra labels use part 0 of the node"
            ));
        }
    }
}

/// The baked parts by id, then the fallback parts: ids the file declares but no node uses get a
/// neutral placeholder so indexing stays dense.
fn dense_parts(baked: Vec<Option<Part>>, fallback: Vec<Part>, bounds: &Aabb, origin: DVec3) -> Vec<Part> {
    baked
        .into_iter()
        .enumerate()
        .map(|(id, p)| p.unwrap_or_else(|| fallback_part(id as u32, "", bounds, origin)))
        .chain(fallback)
        .collect()
}

/// The material table the G-buffer indexes: entry 0 the default material, then the scene's.
fn material_table(scene: &Scene) -> Vec<MaterialGpu> {
    let mut materials =
        vec![MaterialGpu { base_color: DEFAULT_BASE_COLOR, metallic: 0.0, roughness: 1.0, _pad: [0.0; 2] }];
    materials.extend(scene.materials.iter().map(|m| MaterialGpu {
        base_color: m.base_color,
        metallic: m.metallic,
        roughness: m.roughness,
        _pad: [0.0; 2],
    }));
    materials
}

/// The transfer curve of a part record (`gradient.w` is its index in [`TransferCurve::ALL`]).
fn part_curve(gpu: &PartGpu) -> TransferCurve {
    TransferCurve::ALL.get(gpu.gradient[3] as usize).copied().unwrap_or_default()
}

/// Reads the `DRAFTER_illustration` data of a glTF/GLB; `None` for other formats and plain glTF.
fn read_baked(path: &Path, bytes: &[u8]) -> Result<Option<BakedFile>, LoadError> {
    drafter_format::read_if_baked(path, bytes)
        .map_err(|source| LoadError::Baked { path: path.display().to_string(), source })
}

/// Reads both normal sets of a baked glTF/GLB (see [`read_baked`] for the buffer resolution).
fn read_normal_sets(path: &Path, bytes: &[u8]) -> Result<Vec<PrimitiveNormals>, LoadError> {
    drafter_format::read_normal_sets(bytes, &drafter_format::external_buffers(path))
        .map_err(|source| LoadError::Baked { path: path.display().to_string(), source })
}

/// Both normal sets of a mesh, one entry per mesh vertex.
#[derive(Clone, Debug)]
struct MeshNormalSets {
    normals: Vec<[f32; 3]>,
    enhanced: Vec<[f32; 3]>,
}

/// Per mesh, its crease-aware and enhanced normals from the primitives' baked sets (a glTF primitive
/// is the mesh's vertex range `first_vertex..first_vertex + vertex_count`); `None` for a mesh without
/// any. Vertices of primitives without a set keep the imported normal in both.
fn mesh_normal_sets(
    scene: &Scene,
    sets: &[PrimitiveNormals],
    notices: &mut Vec<String>,
) -> Vec<Option<MeshNormalSets>> {
    let mut out: Vec<Option<MeshNormalSets>> = vec![None; scene.meshes.len()];
    let mut mismatched = 0usize;
    for set in sets {
        let Some(mesh) = scene.meshes.get(set.mesh as usize) else {
            mismatched += 1;
            continue;
        };
        let group = mesh.groups.iter().find(|g| g.primitive == Some(set.primitive));
        let Some(g) = group.filter(|g| g.vertex_count as usize == set.normals.len()) else {
            mismatched += 1;
            continue;
        };
        let slot = out[set.mesh as usize].get_or_insert_with(|| {
            let imported: Vec<[f32; 3]> = match &mesh.normals {
                Some(n) => n.iter().map(|n| n.to_array()).collect(),
                None => vec![[0.0; 3]; mesh.positions.len()],
            };
            MeshNormalSets { normals: imported.clone(), enhanced: imported }
        });
        let range = g.first_vertex as usize..(g.first_vertex + g.vertex_count) as usize;
        slot.normals[range.clone()].copy_from_slice(&set.normals);
        slot.enhanced[range].copy_from_slice(&set.enhanced);
    }
    if mismatched > 0 {
        notices.push(format!(
            "{mismatched} primitives' enhanced normals do not match their vertices: imported normals used for them"
        ));
    }
    out
}

/// Part label of every triangle of every mesh (0 where the file has none).
fn mesh_labels(scene: &Scene, baked: Option<&BakedFile>, notices: &mut Vec<String>) -> Vec<Vec<u32>> {
    let mut labels: Vec<Vec<u32>> = scene.meshes.iter().map(|m| vec![0; m.triangles.len()]).collect();
    let Some(baked) = baked else { return labels };
    let mut mismatched = 0usize;
    for (mesh, primitive, values) in &baked.primitive_labels {
        let Some(mesh_labels) = labels.get_mut(*mesh as usize) else {
            mismatched += 1;
            continue;
        };
        let group = scene.meshes[*mesh as usize].groups.iter().find(|g| g.primitive == Some(*primitive));
        match group {
            Some(g) if g.count as usize == values.len() => {
                mesh_labels[g.start as usize..(g.start + g.count) as usize].copy_from_slice(values);
            }
            _ => mismatched += 1,
        }
    }
    if mismatched > 0 {
        notices
            .push(format!("{mismatched} primitives' part labels do not match their triangles: label 0 used for them"));
    }
    labels
}

/// Splits vertices shared by triangles of different labels or materials; returns the batch's
/// vertices and indices (triangle order kept).
#[cfg(test)]
fn split_vertices(mesh: &drafter_core::Mesh, labels: &[u32]) -> (Vec<Vertex>, Vec<u32>) {
    let (vertices, indices, _) = split_vertices_with(mesh, labels, None);
    (vertices, indices)
}

/// As `split_vertices`, with the normals taken from `sets` when given; the third result is then the
/// enhanced normal of every output vertex.
fn split_vertices_with(
    mesh: &drafter_core::Mesh,
    labels: &[u32],
    sets: Option<&MeshNormalSets>,
) -> (Vec<Vertex>, Vec<u32>, Option<Vec<[f32; 3]>>) {
    let mut enhanced = sets.map(|_| Vec::with_capacity(mesh.positions.len()));
    let mut material_of = vec![0u32; mesh.triangles.len()];
    for g in &mesh.groups {
        let m = g.material.map_or(0, |m| m.0 + 1);
        let end = (g.start as usize + g.count as usize).min(material_of.len());
        for slot in &mut material_of[(g.start as usize).min(end)..end] {
            *slot = m;
        }
    }
    // First (label, material) → new index per vertex; further combinations in a map.
    let mut first: Vec<Option<(u32, u32, u32)>> = vec![None; mesh.positions.len()];
    let mut extra: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let mut vertices = Vec::with_capacity(mesh.positions.len());
    let mut indices = Vec::with_capacity(mesh.triangles.len() * 3);
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let (label, material) = (labels.get(t).copied().unwrap_or(0), material_of[t]);
        for &v in tri {
            let make = |vertices: &mut Vec<Vertex>, enhanced: &mut Option<Vec<[f32; 3]>>| {
                let normal = match sets {
                    Some(s) => s.normals[v as usize],
                    None => mesh.normals.as_ref().map_or([0.0; 3], |n| n[v as usize].to_array()),
                };
                if let (Some(out), Some(s)) = (enhanced.as_mut(), sets) {
                    out.push(s.enhanced[v as usize]);
                }
                vertices.push(Vertex {
                    position_in_object: mesh.positions[v as usize].to_array(),
                    normal_in_object: normal,
                    label,
                    material,
                });
                vertices.len() as u32 - 1
            };
            let index = match first[v as usize] {
                None => {
                    let i = make(&mut vertices, &mut enhanced);
                    first[v as usize] = Some((label, material, i));
                    i
                }
                Some((l, m, i)) if l == label && m == material => i,
                Some(_) => *extra.entry((v, label, material)).or_insert_with(|| make(&mut vertices, &mut enhanced)),
            };
            indices.push(index);
        }
    }
    (vertices, indices, enhanced)
}

fn instance_gpu(world_from_object: &DMat4, origin: DVec3, label_base: u32, label_count: u32) -> InstanceGpu {
    let render_from_object = DMat4::from_translation(-origin) * *world_from_object;
    let linear = DMat3::from_mat4(*world_from_object);
    let normal = if linear.determinant().abs() > 1e-300 { linear.inverse().transpose() } else { DMat3::IDENTITY };
    let col = |c: glam::DVec3| [c.x as f32, c.y as f32, c.z as f32, 0.0];
    InstanceGpu {
        render_from_object: render_from_object.as_mat4().to_cols_array_2d(),
        normal_from_object: [col(normal.x_axis), col(normal.y_axis), col(normal.z_axis)],
        label_base,
        mirrored: u32::from(world_from_object.determinant() < 0.0),
        label_count,
        _pad: 0,
    }
}

/// Row 0 of a world-space projector matrix, rewritten for render-space positions.
fn render_row(world_row: DVec4, origin: DVec3) -> [f32; 4] {
    let w = world_row.w + world_row.truncate().dot(origin);
    [world_row.x as f32, world_row.y as f32, world_row.z as f32, w as f32]
}

/// The viewer's record of a baked part (its transfer curve and style arrive typed: drafter-format
/// refuses names outside the schema's enumerations when it reads the file).
fn baked_part(record: &PartRecord, origin: DVec3) -> Part {
    let m = &record.projector.matrix;
    // Column-major: row 0 is elements 0, 4, 8, 12.
    let row = DVec4::new(m[0], m[4], m[8], m[12]);
    let transfer = transfer_index(record.gradient.transfer);
    let style = record.style;
    let axes = record.obb.axes.map(|a| [a[0] as f32, a[1] as f32, a[2] as f32, 0.0]);
    let gpu = PartGpu {
        projector_row: render_row(row, origin),
        axes,
        gradient: [record.gradient.q as f32, record.gradient.f as f32, record.gradient.p as f32, transfer as f32],
        style_hint: style.map_or(NO_STYLE, crate::style::shader_index),
        flags: 0,
        flat: record.flat.map_or(NOT_FLAT, |g| g as f32),
        _pad: 0,
    };
    Part { id: record.id, name: record.name.clone(), style, record: Some(record.clone()), gpu }
}

/// A part for an instance without baked data: the projector runs along the longest side of its
/// world bounding box, away from the scene centre (which is the render origin).
fn fallback_part(id: u32, name: &str, world: &Aabb, origin: DVec3) -> Part {
    let size = if world.is_empty() { DVec3::ZERO } else { world.max - world.min };
    let center = if world.is_empty() { origin } else { (world.min + world.max) * 0.5 };
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| size[b].total_cmp(&size[a]));
    let axis = |k: usize| {
        let mut v = DVec3::ZERO;
        v[k] = 1.0;
        v
    };
    let long = order[0];
    let direction = drafter_bounds::facing_away(axis(long), center - origin, size[long]);
    let scale = size[long];
    // p = 1/2 + d·(x − a)/s, in render coordinates (x_render = x_world − origin).
    let row = if scale > 1e-12 * (1.0 + center.length()) {
        let d = direction / scale;
        [d.x as f32, d.y as f32, d.z as f32, (0.5 - d.dot(center - origin)) as f32]
    } else {
        [0.0, 0.0, 0.0, 0.5]
    };
    let axes = order.map(|k| {
        let a = axis(k);
        [a.x as f32, a.y as f32, a.z as f32, 0.0]
    });
    Part {
        id,
        name: name.to_owned(),
        style: None,
        record: None,
        gpu: PartGpu {
            projector_row: row,
            axes,
            gradient: [DEFAULT_QUANTIZATION as f32, DEFAULT_FADE_STEP, DEFAULT_POWER, 0.0],
            style_hint: NO_STYLE,
            flags: 0,
            flat: NOT_FLAT,
            _pad: 0,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::{Instance, Mesh, MeshId, SourceFormat, TriangleGroup};
    use glam::Vec3;

    fn quad_scene() -> Scene {
        let mut scene = Scene::new(SourceFormat::Obj);
        scene.meshes.push(Mesh {
            name: "quad".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            normals: None,
            uvs: None,
            groups: vec![TriangleGroup { start: 0, count: 2, ..Default::default() }],
        });
        for x in [0.0, 10.0] {
            scene.instances.push(Instance {
                name: format!("q{x}"),
                mesh: MeshId(0),
                node: None,
                world_from_object: DMat4::from_translation(DVec3::new(x, 0.0, 0.0)),
            });
        }
        scene
    }

    #[test]
    fn unbaked_scene_gets_one_part_per_instance() {
        let model = Model::from_scene(&quad_scene(), None).unwrap();
        assert_eq!(model.batches.len(), 1);
        assert_eq!(model.instances.len(), 2);
        assert_eq!(model.parts.len(), 2);
        assert_eq!(model.label_to_part, vec![0, 1]);
        assert_eq!(model.triangle_count(), 4);
        assert!(!model.notices.is_empty());
        // The scene spans x ∈ [0, 11]: origin at 5.5; instance 0's projector runs along -x (away
        // from the centre), from p = 0 at x = 1 to p = 1 at x = 0.
        let row = model.parts[0].gpu.projector_row;
        let p = |x_world: f32| row[0] * (x_world - 5.5) + row[3];
        assert!((p(1.0) - 0.0).abs() < 1e-5, "{row:?}");
        assert!((p(0.0) - 1.0).abs() < 1e-5, "{row:?}");
    }

    #[test]
    fn labels_split_shared_vertices() {
        let scene = quad_scene();
        let (vertices, indices) = split_vertices(&scene.meshes[0], &[0, 1]);
        // Vertices 0 and 2 are shared by both triangles: split once each.
        assert_eq!(vertices.len(), 6);
        assert_eq!(indices.len(), 6);
        for (t, tri) in indices.chunks(3).enumerate() {
            assert!(tri.iter().all(|&i| vertices[i as usize].label == t as u32));
        }
        let (same, _) = split_vertices(&scene.meshes[0], &[3, 3]);
        assert_eq!(same.len(), 4);
    }

    #[test]
    fn empty_scene_is_none() {
        assert!(Model::from_scene(&Scene::new(SourceFormat::Obj), None).is_none());
    }
}
