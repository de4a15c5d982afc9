//! `bake(&Scene, &BakeConfig)`: the stage order of a bake, its timings and report.
//!
//! Stages, in order (each a function of plain data in its own crate):
//! 1. `segment` — parts (drafter-segment);
//! 2. `bounds` — per part, an oriented box of its world-space vertices, the projector derived from
//!    it and the gradient parameters, then per-part overrides from the config (drafter-bounds);
//! 3. `normals` — per unique mesh, crease-aware vertex normals on a new vertex layout and the
//!    Cignoni et al. 2005 enhanced normals (drafter-normals); then every primitive that would write
//!    more than 65,535 vertices is split into consecutive primitives that fit 16-bit indices
//!    ([`split`]: it counts the layout's vertices, and the stages after it work per chunk);
//! 4. `lines` — per unique mesh, edge classes on the welded topology (creases, boundaries, part
//!    borders, silhouette candidates), their EXT_mesh_primitive_edge_visibility encoding per
//!    primitive, and the silhouette hierarchies (drafter-lines);
//! 5. `textures` — the NPR lookup textures the scene uses (γ, cel, cool-to-warm, hatching, metal),
//!    baked by drafter-textures and encoded as PNG (what is baked when: [`textures`]);
//! 6. `write` — the extended glTF (drafter-format), the PNGs embedded as glTF images.
//!
//! Invariant: this is the only crate that knows the order. The output bytes depend only on the
//! scene and the config, never on timings or the thread count (parts are processed in parallel and
//! collected in part order).

mod config;
pub mod heap;
mod reorder;
pub mod split;
pub mod textures;

use std::borrow::Cow;
use std::time::{Duration, Instant};

use drafter_bounds::{Obb, ObbOptions, Projector, box_with_axes, oriented_box};
use drafter_core::{Diagnostic, DiagnosticKind, PartId, Scene, Topology, TriangleGroup, Weld};
use drafter_format::{
    BakeOutput, BoxRecord, Container, FORMAT_VERSION, GENERATOR, GradientRecord, HardEdgeClass, InputInfo,
    MeshSilhouettes, NormalsInfo, ObbMethod, PartRecord, PartStyle, PrimitiveEdges, ProjectorRecord, RootExtension,
    StoredNormals, TextureImage, VertexData, Written,
};
use drafter_lines::{EdgeClass, HierarchyChoice, SilhouetteIndex, SilhouetteOptions};
use drafter_segment::{MeshLabels, Parts};
use glam::{DMat4, DVec3};
use rayon::prelude::*;
use serde::Serialize;

pub use config::{
    BakeConfig, Compression, DEFAULT_METALLIC_THRESHOLD, DEFAULT_TEXTURE_STYLES, GradientOptions, LinesStage,
    NormalsStage, OutputOptions, PartOverride, PartSelector, TexturesStage,
};
pub use split::SplitSummary;
pub use textures::{TextureReport, TexturesSummary};

/// Why a bake failed.
#[derive(Debug, thiserror::Error)]
pub enum BakeError {
    /// The config (file or options) is invalid: the user's fault.
    #[error("config: {0}")]
    Config(String),
    /// The scene cannot be baked (e.g. it has no triangles): the input's fault.
    #[error("{0}")]
    Input(String),
    /// A stage failed where it should not: a bug.
    #[error("internal error in stage {stage}: {message}")]
    Internal { stage: &'static str, message: String },
}

/// A finished bake: the file's bytes and the report.
#[derive(Debug)]
pub struct Baked {
    pub written: Written,
    pub report: BakeReport,
    /// The embedded textures' PNGs (exactly the bytes in the file), in the file's image order; what
    /// `drafter bake --textures-out` writes.
    pub textures: Vec<TextureImage>,
}

/// What `--report FILE.json` contains.
#[derive(Clone, Debug, Serialize)]
pub struct BakeReport {
    pub input: InputInfo,
    pub triangles: usize,
    pub parts: Vec<PartReport>,
    pub stages: Vec<StageTiming>,
    /// Bytes of the written file(s).
    pub output_bytes: u64,
    /// The same bytes by what they hold (geometry, normals, Khronos edges, hierarchies, ...),
    /// before compression.
    pub sections: drafter_format::ByteSections,
    /// What `--compress` did (absent without it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compression: Option<drafter_format::meshopt::CompressionStats>,
    /// What the normal stage did, summed over unique meshes (absent when it was off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub normals: Option<NormalsSummary>,
    /// What the line stage found, summed over unique meshes (absent when it was off).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lines: Option<LinesSummary>,
    /// The primitives split for 16-bit indices (absent when none was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub split: Option<SplitSummary>,
    /// The embedded textures and their PNG bytes (absent when none were baked).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub textures: Option<TexturesSummary>,
    pub diagnostics: Vec<Diagnostic>,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct LinesSummary {
    pub meshes: usize,
    pub edges: drafter_lines::EdgeClassCounts,
    pub silhouette_candidates: usize,
    /// Meshes whose orthographic / perspective queries use a stored hierarchy.
    pub gauss_maps: usize,
    pub cone_bvhs: usize,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct NormalsSummary {
    pub meshes: usize,
    pub input_vertices: usize,
    pub output_vertices: usize,
    /// Output vertices beyond one per welded vertex: the splits hard edges need.
    pub split_vertices: usize,
    pub degenerate_faces: usize,
    pub face_iterations: u64,
}

#[derive(Clone, Debug, Serialize)]
pub struct PartReport {
    pub id: u32,
    pub name: String,
    pub triangles: u32,
    pub obb: ObbReport,
    pub projector: ProjectorReport,
    pub gradient: GradientRecord,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub style: Option<PartStyle>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObbReport {
    pub center: [f64; 3],
    pub axes: [[f64; 3]; 3],
    pub half_extents: [f64; 3],
    pub volume: f64,
    pub method: ObbMethod,
}

#[derive(Clone, Debug, Serialize)]
pub struct ProjectorReport {
    pub anchor: [f64; 3],
    pub direction: [f64; 3],
    pub scale: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct StageTiming {
    pub name: &'static str,
    pub ms: f64,
}

/// The stages of a bake in the order they run, as [`bake_observed`] announces them; `Done` is
/// announced when the bake has finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    Topology,
    Segment,
    Bounds,
    Normals,
    Lines,
    Textures,
    Write,
    Done,
}

impl Stage {
    /// Every stage, in the order a bake announces them.
    pub const ALL: [Stage; 8] = [
        Stage::Topology,
        Stage::Segment,
        Stage::Bounds,
        Stage::Normals,
        Stage::Lines,
        Stage::Textures,
        Stage::Write,
        Stage::Done,
    ];

    /// The stage's name in progress lines and the report's timings.
    pub const fn name(self) -> &'static str {
        match self {
            Stage::Topology => "topology",
            Stage::Segment => "segment",
            Stage::Bounds => "bounds",
            Stage::Normals => "normals",
            Stage::Lines => "lines",
            Stage::Textures => "textures",
            Stage::Write => "write",
            Stage::Done => "done",
        }
    }

    /// The stage's place in [`Stage::ALL`].
    pub const fn index(self) -> usize {
        self as usize
    }
}

/// The names of [`Stage::ALL`], in order.
pub const STAGE_NAMES: [&str; 8] = {
    let mut names = [""; 8];
    let mut i = 0;
    while i < names.len() {
        names[i] = Stage::ALL[i].name();
        i += 1;
    }
    names
};

/// Runs every stage on `scene` and writes the extended glTF in memory.
pub fn bake(scene: &Scene, config: &BakeConfig) -> Result<Baked, BakeError> {
    bake_observed(scene, config, &mut |_| {})
}

/// [`bake`], calling `on_stage(stage)` as each [`Stage`] starts (and with [`Stage::Done`] when the
/// bake is done), so a caller can show progress. The observer cannot change the output.
pub fn bake_observed(scene: &Scene, config: &BakeConfig, on_stage: &mut dyn FnMut(Stage)) -> Result<Baked, BakeError> {
    if scene.instanced_triangle_count() == 0 {
        return Err(BakeError::Input("the scene has no triangles to bake".into()));
    }
    // Compressed output: triangles and vertices in the orders the codecs compress best, before
    // any stage, so that everything is computed on what the file holds (`reorder.rs`).
    let reordered;
    let scene = if config.output.compress == Compression::Meshopt && config.container == Container::Glb {
        reordered = reorder::for_compression(scene);
        &reordered
    } else {
        scene
    };
    let mut stages = Vec::new();
    let mut timed =
        |stage: Stage, time: Duration| stages.push(StageTiming { name: stage.name(), ms: time.as_secs_f64() * 1e3 });
    let mut begin = |stage: Stage| {
        on_stage(stage);
        Instant::now()
    };

    // Welded topology of every mesh used by an instance, built once and shared by the stages.
    let start = begin(Stage::Topology);
    let mut topologies = build_topologies(scene, config.segment.weld);
    timed(Stage::Topology, start.elapsed());

    let start = begin(Stage::Segment);
    let (parts, mut diagnostics) = drafter_segment::segment_with_topologies(scene, &topologies, &config.segment);
    // Meshes that repeat an earlier one's geometry and parts share its normals and lines.
    let canonical = canonical_meshes(scene, &parts);
    timed(Stage::Segment, start.elapsed());

    // Bounds and normals read only the scene, the topologies and the parts: they run side by side.
    // Bounds is one task per part, so a single-part mesh's hull and box search would hold one core
    // while the others wait; beside the normals' many small tasks they do not.
    // Their timings overlap in the report.
    begin(Stage::Bounds);
    let bounds_start = Instant::now();
    let (records, normals_result) = rayon::join(
        || bound_parts(scene, &parts, config).map(|records| (records, bounds_start.elapsed())),
        || {
            let start = Instant::now();
            let result = normals_and_split(scene, &mut topologies, &canonical, config);
            (result, start.elapsed())
        },
    );
    let (records, bounds_time) = records?;
    let (normals, normals_time) = normals_result;
    let NormalsAndSplit {
        vertex_data,
        summary: normals_summary,
        diagnostics: normal_diagnostics,
        splits,
        split_summary,
        written_scene,
    } = normals;
    diagnostics.extend(normal_diagnostics);
    timed(Stage::Bounds, bounds_time);
    timed(Stage::Normals, normals_time);
    begin(Stage::Normals);

    let start = begin(Stage::Lines);
    let (primitive_edges, mesh_silhouettes, lines_summary) = if config.lines.enabled {
        let lines = compute_lines(&written_scene, &splits, topologies, &parts, &canonical, &vertex_data, &config.lines);
        diagnostics.extend(lines.diagnostics);
        (lines.primitive_edges, lines.mesh_silhouettes, Some(lines.summary))
    } else {
        (vec![Vec::new(); scene.meshes.len()], vec![None; scene.meshes.len()], None)
    };
    timed(Stage::Lines, start.elapsed());

    let start = begin(Stage::Textures);
    let metal_parts = textures::metal_parts(scene, &parts, &records, config.textures.metallic_threshold);
    let request = textures::request(&records, &metal_parts, &config.textures);
    let baked_textures = if request.is_empty() {
        None
    } else {
        Some(textures::bake_memoized(&request, metal_parts, config.textures.metallic_threshold)?)
    };
    timed(Stage::Textures, start.elapsed());

    let start = begin(Stage::Write);
    let root = root_record(scene, config, parts.len() as u32);
    let (instance_parts, mesh_labels) = part_records_and_labels(scene, &parts, &records);
    let (textures_summary, embedded) = match baked_textures {
        Some(b) => (Some(b.summary), Some(b.embedded)),
        None => (None, None),
    };
    let output = BakeOutput {
        scene: &written_scene,
        root,
        instance_parts,
        mesh_labels,
        vertex_data,
        primitive_edges,
        mesh_silhouettes,
        textures: embedded,
        quantized_normals: config.output.compress == Compression::Meshopt && config.container == Container::Glb,
    };
    let written = drafter_format::write(&output, &config.container).map_err(|e| match e {
        // The input's own JSON that cannot be carried over (a number beyond f64, nesting deeper
        // than the JSON parser's limit of 128): the input's fault, reported as such.
        drafter_format::FormatError::Source(message) => {
            BakeError::Input(format!("the glTF document cannot be passed through: {message}"))
        }
        e => BakeError::Internal { stage: "write", message: e.to_string() },
    })?;
    let texture_images = output.textures.map(|t| t.images).unwrap_or_default();
    for note in &written.notes {
        diagnostics.push(Diagnostic { kind: DiagnosticKind::Output, count: 1, first_example: note.clone() });
    }

    let sections = written.sections;
    let mut written = written;
    let compression = compress(config, &mut written)?;
    timed(Stage::Write, start.elapsed());
    let output_bytes = (written.main.len() + written.bin.as_ref().map_or(0, Vec::len)) as u64;
    diagnostics.sort_by_key(|d| d.kind);
    let report = BakeReport {
        input: config.input.clone(),
        triangles: scene.instanced_triangle_count(),
        parts: records.iter().map(part_report).collect(),
        stages,
        output_bytes,
        sections,
        compression,
        normals: normals_summary,
        lines: lines_summary,
        split: (split_summary.split_primitives > 0).then_some(split_summary),
        textures: textures_summary,
        diagnostics,
    };
    begin(Stage::Done);
    Ok(Baked { written, report, textures: texture_images })
}

/// The root record of the file: provenance, settings, scene centre and the normal stage's
/// parameters (the embedded textures' indices are added by the writer).
fn root_record(scene: &Scene, config: &BakeConfig, part_count: u32) -> RootExtension {
    let bounds = scene.world_bounds();
    let center = if bounds.is_empty() { DVec3::ZERO } else { (bounds.min + bounds.max) * 0.5 };
    RootExtension {
        version: FORMAT_VERSION.to_owned(),
        generator: GENERATOR.to_owned(),
        input: config.input.clone(),
        settings: settings_echo(config),
        scene_center: center.to_array(),
        part_count,
        normals: config.normals.enabled.then(|| NormalsInfo {
            strength: f64::from(config.normals.strength),
            iterations: config.normals.iterations,
            crease_angle_deg: f64::from(config.normals.crease_angle_deg),
            enhanced_in_normal: config.normals.enhanced_in_normal,
        }),
        textures: None,
    }
}

/// Each instance's part records, and each mesh's per-triangle part labels (from the first
/// instance that has them; instances of one mesh share its labels).
fn part_records_and_labels(
    scene: &Scene,
    parts: &Parts,
    records: &[PartRecord],
) -> (Vec<Vec<PartRecord>>, Vec<Option<Vec<u32>>>) {
    let instance_parts = parts
        .instances
        .iter()
        .map(|ip| records[ip.first_part.index()..ip.first_part.index() + ip.part_count as usize].to_vec())
        .collect();
    let mut mesh_labels: Vec<Option<Vec<u32>>> = vec![None; scene.meshes.len()];
    for (inst, ip) in scene.instances.iter().zip(&parts.instances) {
        if let MeshLabels::PerTriangle(table) = &ip.labels {
            mesh_labels[inst.mesh.index()].get_or_insert_with(|| table.labels().to_vec());
        }
    }
    (instance_parts, mesh_labels)
}

/// Compresses the written .glb in place when the configuration asks for it.
fn compress(
    config: &BakeConfig,
    written: &mut Written,
) -> Result<Option<drafter_format::meshopt::CompressionStats>, BakeError> {
    match (config.output.compress, &config.container) {
        (Compression::None, _) => Ok(None),
        (Compression::Meshopt, Container::Glb) => {
            let (main, stats) = drafter_format::meshopt::compress_glb(&written.main)
                .map_err(|e| BakeError::Internal { stage: "write", message: format!("compression: {e}") })?;
            written.main = main;
            Ok(Some(stats))
        }
        (Compression::Meshopt, Container::Gltf { .. }) => {
            Err(BakeError::Config("compression (meshopt) writes .glb files only".into()))
        }
    }
}

/// What the normals stage hands on: per-mesh vertex data, the primitives split within 16-bit
/// indices, and the scene as it will be written.
struct NormalsAndSplit<'a> {
    vertex_data: Vec<Option<VertexData>>,
    summary: Option<NormalsSummary>,
    diagnostics: Vec<Diagnostic>,
    splits: Vec<Option<split::SplitGroups>>,
    split_summary: split::SplitSummary,
    written_scene: Cow<'a, Scene>,
}

/// The normals stage, then the primitives' split within 16-bit indices (and, when compressing, each
/// triangle's rotation).
fn normals_and_split<'a>(
    scene: &'a Scene,
    topologies: &mut [Topology],
    canonical: &[usize],
    config: &BakeConfig,
) -> NormalsAndSplit<'a> {
    let (vertex_data, summary, diagnostics) = if config.normals.enabled {
        let (data, summary, diagnostics) = compute_normals(scene, topologies, canonical, &config.normals);
        (data, Some(summary), diagnostics)
    } else {
        (vec![None; scene.meshes.len()], None, Vec::new())
    };
    // Primitives within 16-bit indices: groups split by the vertices the writer will write, before
    // the lines stage so that its per-primitive data is per chunk. Triangles keep their order. (Timed
    // with the normals: a pass over the triangles, not a stage of its own in the progress line.)
    let (splits, split_summary) = split::split_scene(scene, &vertex_data);
    let compressing = config.output.compress == Compression::Meshopt && config.container == Container::Glb;
    let mut vertex_data = vertex_data;
    let written_scene: Cow<Scene> = if splits.iter().all(Option::is_none) && !compressing {
        Cow::Borrowed(scene)
    } else {
        let mut copy = scene.clone();
        for (mesh, split) in copy.meshes.iter_mut().zip(&splits) {
            if let Some(split) = split {
                mesh.groups = split.groups.clone();
            }
        }
        if compressing {
            // Each triangle starts at the corner the index codec keeps (`reorder.rs`).
            for ((mesh, layout), topology) in copy.meshes.iter_mut().zip(&mut vertex_data).zip(topologies.iter_mut()) {
                if let Some(layout) = layout {
                    let groups = mesh.groups.clone();
                    reorder::settle_rotations(mesh, layout, topology, &groups);
                }
            }
        }
        Cow::Owned(copy)
    };
    NormalsAndSplit { vertex_data, summary, diagnostics, splits, split_summary, written_scene }
}

/// Normals of every mesh used by an instance, in mesh order. UV seams are kept where the mesh has
/// texture coordinates (a vertex copies one source vertex's UV); otherwise coincident vertices of an
/// unwelded CAD export are merged within a smooth fan, which is what smooths them correctly.
fn compute_normals(
    scene: &Scene,
    topologies: &[Topology],
    canonical: &[usize],
    stage: &NormalsStage,
) -> (Vec<Option<VertexData>>, NormalsSummary, Vec<Diagnostic>) {
    let used = used_meshes(scene);
    let mut results: Vec<Option<(VertexData, drafter_normals::NormalsReport, Vec<Diagnostic>)>> = scene
        .meshes
        .par_iter()
        .enumerate()
        .map(|(m, mesh)| {
            if !used[m] || mesh.triangles.is_empty() || canonical[m] != m {
                return None;
            }
            let topology = &topologies[m];
            let mut options = stage.options();
            options.crease.keep_input_seams = mesh.uvs.is_some();
            let (normals, diagnostics) = drafter_normals::compute_normals(mesh, topology, &options);
            let (plain, enhanced) = if stage.enhanced_in_normal {
                (&normals.enhanced_normals, &normals.normals)
            } else {
                (&normals.normals, &normals.enhanced_normals)
            };
            let (normals_out, enhanced_out) =
                (plain.iter().map(|n| n.to_array()).collect(), enhanced.iter().map(|n| n.to_array()).collect());
            let data = VertexData {
                source_vertex: normals.layout.source_vertex,
                triangles: normals.layout.triangles,
                normals: normals_out,
                enhanced: enhanced_out,
            };
            Some((data, normals.report, diagnostics))
        })
        .collect();
    copy_to_repeats(&mut results, canonical);
    let mut summary = NormalsSummary::default();
    let mut diagnostics = Vec::new();
    let data = results
        .into_iter()
        .map(|r| {
            r.map(|(data, report, d)| {
                summary.meshes += 1;
                summary.input_vertices += report.input_vertices;
                summary.output_vertices += report.output_vertices;
                summary.split_vertices += report.split_vertices;
                summary.degenerate_faces += report.degenerate_faces;
                summary.face_iterations += report.face_iterations;
                diagnostics.extend(d);
                data
            })
        })
        .collect();
    (data, summary, diagnostics)
}

/// What the lines stage gives the writer, indexed by mesh: the two arrays are the ones
/// `drafter_format::BakeOutput` takes, an unused or empty mesh holding no edges and no silhouettes.
struct LinesResult {
    /// Per mesh, per group (primitive): its edge visibility, hard edge classes and silhouette normals;
    /// `None` for a primitive with no visible edge.
    primitive_edges: Vec<Vec<Option<PrimitiveEdges>>>,
    /// Per mesh: the silhouette candidates and the hierarchies stored over them.
    mesh_silhouettes: Vec<Option<MeshSilhouettes>>,
    summary: LinesSummary,
    diagnostics: Vec<Diagnostic>,
}

/// The lines of one unique mesh, before they are gathered into a [`LinesResult`].
#[derive(Clone)]
struct MeshLines {
    /// Per group of the mesh, as [`LinesResult::primitive_edges`].
    edges: Vec<Option<PrimitiveEdges>>,
    silhouettes: Option<MeshSilhouettes>,
    counts: drafter_lines::EdgeClassCounts,
    diagnostics: Vec<Diagnostic>,
}

/// Edges of every mesh used by an instance: classes (with part borders from the segmentation),
/// the per-primitive encoding and the silhouette index. `splits` gives, for meshes whose groups were
/// split, the source group of each: a silhouette candidate is encoded once over the chunks of one
/// source group (hard edges once per chunk, as the encode-once rules are per primitive).
fn compute_lines(
    scene: &Scene,
    splits: &[Option<split::SplitGroups>],
    topologies: Vec<Topology>,
    parts: &Parts,
    canonical: &[usize],
    vertex_data: &[Option<VertexData>],
    stage: &LinesStage,
) -> LinesResult {
    let used = used_meshes(scene);
    // Per-triangle part labels of each mesh (shared by its instances), if it was split.
    let mut labels: Vec<Option<&[u32]>> = vec![None; scene.meshes.len()];
    for (inst, ip) in scene.instances.iter().zip(&parts.instances) {
        if let MeshLabels::PerTriangle(table) = &ip.labels {
            labels[inst.mesh.index()] = Some(table.labels());
        }
    }
    let options = stage.line_options();
    let mut results: Vec<_> = scene
        .meshes
        .par_iter()
        .zip(topologies)
        .enumerate()
        .map(|(m, (mesh, owned_topology))| {
            if !used[m] || mesh.triangles.is_empty() || canonical[m] != m {
                return None;
            }
            let topology = &owned_topology;
            let face_parts: Option<Vec<PartId>> = labels[m].map(|l| l.iter().map(|&x| PartId(x)).collect());
            let input_faces = input_faces(mesh);
            let labels =
                drafter_lines::FaceLabels { parts: face_parts.as_deref(), input_faces: input_faces.as_deref() };
            // Without the candidates' normals and points (47 MB on the dragon): the encoder does not
            // read them, and the hierarchies are built from what the file holds.
            let feature = match drafter_lines::classify_edges_for_encoding(topology, labels, &options) {
                Ok(f) => f,
                Err(e) => {
                    let d = Diagnostic {
                        kind: DiagnosticKind::LinesSkipped,
                        count: 1,
                        first_example: format!("mesh {m}: lines skipped: {e}"),
                    };
                    return Some(MeshLines {
                        edges: Vec::new(),
                        silhouettes: None,
                        counts: drafter_lines::EdgeClassCounts::default(),
                        diagnostics: vec![d],
                    });
                }
            };
            let mut diagnostics = feature.diagnostics();
            let mut encoded = drafter_lines::SilhouettesEncoded::default();
            let edges: Vec<Option<PrimitiveEdges>> = mesh
                .groups
                .iter()
                .enumerate()
                .map(|(i, g)| {
                    let source = |i: usize| splits[m].as_ref().map_or(i as u32, |s| s.source[i]);
                    if i > 0 && source(i) != source(i - 1) {
                        encoded = drafter_lines::SilhouettesEncoded::default();
                    }
                    let triangles = &mesh.triangles[g.start as usize..(g.start + g.count) as usize];
                    let first_face = g.start as usize;
                    match drafter_lines::encode_faces_continuing(
                        triangles,
                        first_face,
                        topology,
                        &feature,
                        &mut encoded,
                    ) {
                        Ok(v) if v.has_visible_edges() => Some(PrimitiveEdges {
                            hard_edge_classes: v
                                .hard_edges
                                .iter()
                                .map(|&e| hard_edge_code(feature.classes[e as usize]))
                                .collect(),
                            visibility: v.visibility,
                            silhouette_normals: StoredNormals::Byte(v.silhouette_normals),
                        }),
                        Ok(_) => None,
                        Err(e) => {
                            diagnostics.push(Diagnostic {
                                kind: DiagnosticKind::EdgesNotWritten,
                                count: 1,
                                first_example: format!("mesh {m}: edge visibility not written: {e}"),
                            });
                            None
                        }
                    }
                })
                .collect();
            // The classes, face normals and candidate arrays (85 MB on the dragon) are not needed
            // by the hierarchies, which are built from what the file holds: freed before them.
            let counts = feature.counts;
            drop(feature);
            // Nor the topology (53 MB on the dragon), which no later stage reads.
            drop(owned_topology);
            let silhouettes = silhouettes_of(mesh, &edges, vertex_data[m].as_ref(), stage.hierarchies);
            Some(MeshLines { edges, silhouettes, counts, diagnostics })
        })
        .collect();
    copy_to_repeats(&mut results, canonical);
    let mut summary = LinesSummary::default();
    let mut all_edges = Vec::with_capacity(results.len());
    let mut all_silhouettes = Vec::with_capacity(results.len());
    let mut diagnostics = Vec::new();
    for r in results {
        match r {
            Some(MeshLines { edges, silhouettes, counts, diagnostics: d }) => {
                summary.meshes += 1;
                let e = &mut summary.edges;
                e.boundary += counts.boundary;
                e.non_manifold += counts.non_manifold;
                e.part_border += counts.part_border;
                e.crease += counts.crease;
                e.silhouette_candidate += counts.silhouette_candidate;
                e.coplanar += counts.coplanar;
                e.degenerate += counts.degenerate;
                e.tangent += counts.tangent;
                e.continued += counts.continued;
                e.inconsistent_orientation += counts.inconsistent_orientation;
                if let Some(s) = &silhouettes {
                    summary.silhouette_candidates += s.candidate_corners.len();
                    summary.gauss_maps += usize::from(s.gauss_map.is_some());
                    summary.cone_bvhs += usize::from(s.cone_bvh.is_some());
                }
                all_edges.push(edges);
                all_silhouettes.push(silhouettes);
                diagnostics.extend(d);
            }
            None => {
                all_edges.push(Vec::new());
                all_silhouettes.push(None);
            }
        }
    }
    LinesResult { primitive_edges: all_edges, mesh_silhouettes: all_silhouettes, summary, diagnostics }
}

/// The input face of each triangle of `mesh`: the glTF primitive its group was read from (the
/// chunks of a primitive split for 16-bit indices keep their source primitive, so they are one
/// face). `None` where the mesh says nothing of its faces (no group names a primitive: STL, OBJ,
/// a synthesized mesh) or names one alone.
pub fn input_faces(mesh: &drafter_core::Mesh) -> Option<Vec<u32>> {
    let mut primitives = mesh.groups.iter().filter_map(|g| g.primitive);
    let first = primitives.next()?;
    if primitives.all(|p| p == first) {
        return None;
    }
    let mut faces = vec![u32::MAX; mesh.triangles.len()];
    for g in &mesh.groups {
        let range = g.start as usize..(g.start as usize + g.count as usize).min(faces.len());
        faces[range].fill(g.primitive.unwrap_or(u32::MAX));
    }
    Some(faces)
}

fn hard_edge_code(class: EdgeClass) -> u8 {
    match class {
        EdgeClass::Tangent => HardEdgeClass::Tangent as u8,
        EdgeClass::Crease => HardEdgeClass::Crease as u8,
        EdgeClass::Boundary => HardEdgeClass::Boundary as u8,
        EdgeClass::PartBorder => HardEdgeClass::PartBorder as u8,
        EdgeClass::NonManifold => HardEdgeClass::NonManifold as u8,
        _ => 0,
    }
}

/// `data` cut into consecutive slices of `per_item · count` elements, one per count, so that each
/// primitive fills its own slice on the thread pool.
fn split_by_counts<'a, T>(mut data: &'a mut [T], counts: &[usize], per_item: usize) -> Vec<&'a mut [T]> {
    let mut slices = Vec::with_capacity(counts.len());
    for &count in counts {
        let (slice, rest) = data.split_at_mut(per_item * count);
        slices.push(slice);
        data = rest;
    }
    slices
}

/// The mesh's silhouette candidates as every reader of the file sees them (format 0.2): the edges
/// its primitives' `EXT_mesh_primitive_edge_visibility` encodes as 1, primitive by primitive in
/// encoding order, with the decoded `silhouetteNormals` and, as the perspective test's point, the
/// written position of the edge's first vertex. The hierarchies are built on exactly these values,
/// so that they answer as brute force over the file's data, bit for bit; nothing per candidate is
/// stored twice. `None` when no primitive has a candidate.
fn silhouettes_of(
    mesh: &drafter_core::Mesh,
    edges: &[Option<PrimitiveEdges>],
    layout: Option<&VertexData>,
    hierarchies: bool,
) -> Option<MeshSilhouettes> {
    // Candidates per primitive, counted first so that each primitive fills its own slice of the
    // arrays on the thread pool, rather than pushing a million candidates one by one into growing
    // vectors on one core.
    let counts: Vec<usize> = edges.par_iter().map(|e| e.as_ref().map_or(0, |e| e.silhouette_slots().count())).collect();
    let total: usize = counts.iter().sum();
    if total == 0 {
        return None;
    }
    let mut corners = drafter_core::filled_in_parallel(total, 0u32);
    let mut normals = drafter_core::filled_in_parallel(total, [glam::Vec3::ZERO; 2]);
    let mut points = drafter_core::filled_in_parallel(total, glam::Vec3::ZERO);
    let slices = split_by_counts(&mut corners, &counts, 1)
        .into_iter()
        .zip(split_by_counts(&mut normals, &counts, 1))
        .zip(split_by_counts(&mut points, &counts, 1))
        .map(|((c, n), p)| (c, n, p));
    mesh.groups.par_iter().zip(edges).zip(slices.collect::<Vec<_>>()).for_each(
        |((group, primitive_edges), (corners, normals, points))| {
            let Some(e) = primitive_edges else { return };
            let range = group.start as usize..(group.start + group.count) as usize;
            // The position the writer gives each corner: with a new vertex layout, an output vertex
            // takes the mesh vertex of its first corner in this primitive (as `write_vertex_data` does).
            // Output vertex → the mesh vertex of its first corner here (u32::MAX: not in this primitive).
            let written: Option<Vec<u32>> = layout.map(|vd| {
                let mut first = vec![u32::MAX; vd.source_vertex.len()];
                for (t, mesh_triangle) in vd.triangles[range.clone()].iter().zip(&mesh.triangles[range.clone()]) {
                    for (&o, &v) in t.iter().zip(mesh_triangle) {
                        if let Some(slot) = first.get_mut(o as usize).filter(|s| **s == u32::MAX) {
                            *slot = v;
                        }
                    }
                }
                first
            });
            for (i, slot) in e.silhouette_slots().enumerate() {
                let t = group.start as usize + slot as usize / 3;
                let k = slot as usize % 3;
                let vertex = match (&written, layout) {
                    (Some(first), Some(vd)) => first[vd.triangles[t][k] as usize],
                    _ => mesh.triangles[t][k],
                };
                corners[i] = 3 * t as u32 + k as u32;
                let decoded = |j: usize| e.silhouette_normals.decoded(j).unwrap_or(glam::Vec3::ZERO);
                normals[i] = [decoded(2 * i), decoded(2 * i + 1)];
                points[i] = mesh.positions[vertex as usize];
            }
        },
    );
    let options =
        SilhouetteOptions { orthographic: hierarchies, perspective: hierarchies, ..SilhouetteOptions::default() };
    // The hierarchies store no candidate order (format 0.2): a reader derives it from the
    // candidates in the Khronos order, as the index was built from them here. Built for storage:
    // the bake never queries them.
    let arrays = SilhouetteIndex::stored_hierarchies(normals, points, &options);
    // The normals as the writer lists them, decoded again rather than copied before the index
    // consumed its own (31 MB less at the bake's peak on the dragon).
    // Per primitive on the thread pool, each into its own slice (as the gather above).
    let mut candidate_normals = vec![0.0f32; 6 * total];
    let slices = split_by_counts(&mut candidate_normals, &counts, 6);
    edges.par_iter().zip(slices).for_each(|(e, out)| {
        let Some(e) = e else { return };
        for (j, xyz) in out.chunks_exact_mut(3).enumerate() {
            xyz.copy_from_slice(&e.silhouette_normals.decoded(j).unwrap_or(glam::Vec3::ZERO).to_array());
        }
    });
    use drafter_format::{OrthographicHierarchy as Ortho, PerspectiveHierarchy as Persp};
    let orthographic = match arrays.orthographic {
        HierarchyChoice::GaussMap { .. } => Ortho::GaussMap,
        _ => Ortho::BruteForce,
    };
    let perspective = match arrays.perspective {
        HierarchyChoice::ConeBvh { .. } => Persp::ConeBvh,
        _ => Persp::BruteForce,
    };
    Some(MeshSilhouettes {
        candidate_normals,
        candidate_corners: corners,
        orthographic,
        perspective,
        gauss_map: arrays.gauss_map,
        cone_bvh: arrays.cone_bvh,
    })
}

/// For each mesh, the first mesh used by an instance that has the same geometry and segmentation
/// (itself where there is none). CAD exports often write a mesh per instance, each listing the same
/// accessors: 10 of GearboxAssy's 42 meshes repeat another's, 39 % of its triangles. A repeat's
/// normals and lines are the first's, computed once ([`copy_to_repeats`]). Materials may differ:
/// they do not enter either stage, and each mesh keeps its own groups in the written scene.
fn canonical_meshes(scene: &Scene, parts: &Parts) -> Vec<usize> {
    let used = used_meshes(scene);
    let mut labels: Vec<Option<&MeshLabels>> = vec![None; scene.meshes.len()];
    for (inst, ip) in scene.instances.iter().zip(&parts.instances) {
        labels[inst.mesh.index()].get_or_insert(&ip.labels);
    }
    let same_labels = |a: Option<&MeshLabels>, b: Option<&MeshLabels>| match (a, b) {
        (Some(MeshLabels::Whole), Some(MeshLabels::Whole)) => true,
        (Some(MeshLabels::PerTriangle(x)), Some(MeshLabels::PerTriangle(y))) => x.labels() == y.labels(),
        _ => false,
    };
    let without_material = |g: &TriangleGroup| TriangleGroup { material: None, ..g.clone() };
    let same_geometry = |a: &drafter_core::Mesh, b: &drafter_core::Mesh| {
        a.positions == b.positions
            && a.triangles == b.triangles
            && a.normals == b.normals
            && a.uvs == b.uvs
            && a.groups.len() == b.groups.len()
            && a.groups.iter().zip(&b.groups).all(|(x, y)| without_material(x) == without_material(y))
    };
    // Meshes are compared only within a group of equal sizes and, where a size is shared, equal
    // content hashes: many different meshes of one size (an OBJ of thousands of equal groups) must
    // not be compared pairwise. A mesh whose size no other shares is not hashed at all.
    let size = |mesh: &drafter_core::Mesh| (mesh.positions.len(), mesh.triangles.len(), mesh.groups.len());
    let mut sizes: std::collections::BTreeMap<(usize, usize, usize), usize> = Default::default();
    for (m, mesh) in scene.meshes.iter().enumerate() {
        if used[m] {
            *sizes.entry(size(mesh)).or_default() += 1;
        }
    }
    let hashes: Vec<Option<u64>> = scene
        .meshes
        .par_iter()
        .enumerate()
        .map(|(m, mesh)| (used[m] && sizes[&size(mesh)] > 1).then(|| content_hash(mesh)))
        .collect();
    let mut canonical: Vec<usize> = (0..scene.meshes.len()).collect();
    let mut firsts: std::collections::BTreeMap<u64, Vec<usize>> = Default::default();
    for (m, mesh) in scene.meshes.iter().enumerate() {
        let Some(hash) = hashes[m] else { continue };
        let list = firsts.entry(hash).or_default();
        match list.iter().find(|&&c| same_labels(labels[c], labels[m]) && same_geometry(&scene.meshes[c], mesh)) {
            Some(&c) => canonical[m] = c,
            None => list.push(m),
        }
    }
    canonical
}

/// A hash of a mesh's positions and triangles (bit patterns), to find candidates for
/// [`canonical_meshes`]; equal meshes are then compared in full.
fn content_hash(mesh: &drafter_core::Mesh) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    for p in &mesh.positions {
        p.to_array().map(f32::to_bits).hash(&mut h);
    }
    mesh.triangles.hash(&mut h);
    h.finish()
}

/// Gives every repeated mesh (see [`canonical_meshes`]) a copy of its first's result.
fn copy_to_repeats<T: Clone>(results: &mut [Option<T>], canonical: &[usize]) {
    for m in 0..results.len() {
        if canonical[m] != m {
            results[m] = results[canonical[m]].clone();
        }
    }
}

fn used_meshes(scene: &Scene) -> Vec<bool> {
    let mut used = vec![false; scene.meshes.len()];
    for inst in &scene.instances {
        used[inst.mesh.index()] = true;
    }
    used
}

/// One topology per scene mesh (empty for meshes no instance uses), in mesh order.
fn build_topologies(scene: &Scene, weld: Weld) -> Vec<Topology> {
    let used = used_meshes(scene);
    scene
        .meshes
        .par_iter()
        .zip(used.par_iter())
        .map(|(mesh, &used)| if used { Topology::build(mesh, weld) } else { Topology::default() })
        .collect()
}

/// The options that shaped the file (never the thread count: output is identical at any).
fn settings_echo(config: &BakeConfig) -> serde_json::Value {
    serde_json::json!({
        "segment": {"mode": config.segment.mode, "regionAngleDeg": config.segment.region_angle_deg},
        "obb": {"method": config.obb.method.name()},
        "normals": {"enabled": config.normals.enabled},
        "lines": {"enabled": config.lines.enabled, "creaseAngleDeg": config.lines.crease_angle_deg, "creaseMinEdges": config.lines.crease_min_edges, "creaseMinLength": config.lines.crease_min_length, "strongCreaseDeg": config.lines.strong_crease_deg, "hierarchies": config.lines.hierarchies},
        "textures": {"enabled": config.textures.enabled, "styles": config.textures.styles, "metallicThreshold": config.textures.metallic_threshold},
        "gradient": {"q": config.gradient.q, "f": config.gradient.f, "p": config.gradient.p, "transfer": config.gradient.transfer},
        "partOverrides": config.overrides.len(),
    })
}

/// Box, projector and gradient of every part, in part order; overrides applied.
fn bound_parts(scene: &Scene, parts: &Parts, config: &BakeConfig) -> Result<Vec<PartRecord>, BakeError> {
    // Resolve overrides to part ids first, so a selector that matches nothing is reported.
    let mut per_part: Vec<Vec<&PartOverride>> = vec![Vec::new(); parts.len()];
    for o in &config.overrides {
        let matched: Vec<usize> = if match &o.selector() {
            PartSelector::Id(id) => (*id as usize) < parts.len(),
            PartSelector::Name(_) => true,
        } {
            {
                (0..parts.len())
                    .filter(|&p| match &o.selector() {
                        PartSelector::Id(id) => p == *id as usize,
                        PartSelector::Name(n) => &parts.parts[p].name == n,
                    })
                    .collect()
            }
        } else {
            Default::default()
        };
        if matched.is_empty() {
            let what = match &o.selector() {
                PartSelector::Id(id) => format!("id {id} (the scene has {} parts)", parts.len()),
                PartSelector::Name(n) => format!("name {n:?}"),
            };
            return Err(BakeError::Config(format!("part override with {what} matches no part")));
        }
        for p in matched {
            per_part[p].push(o);
        }
    }
    let bounds = scene.world_bounds();
    let center = if bounds.is_empty() { DVec3::ZERO } else { (bounds.min + bounds.max) * 0.5 };
    let methods: Vec<ObbMethod> = per_part
        .iter()
        .map(|overrides| overrides.iter().rev().find_map(|o| o.method).unwrap_or(config.obb.method))
        .collect();
    let shared = SharedOrientations::find(scene, parts, &methods, &config.obb);
    (0..parts.len())
        .into_par_iter()
        .map(|p| {
            let part = &parts.parts[p];
            let overrides = &per_part[p];
            let method = methods[p];
            let points = part_points(scene, parts, PartId::from(p));
            let obb = match shared.axes(scene, parts, p) {
                Some(axes) => box_with_axes(&points, axes, method),
                None => oriented_box(&points, &ObbOptions { method, ..config.obb }),
            }
            .map_err(|e| BakeError::Internal { stage: "bounds", message: format!("part {p} ({}): {e}", part.name) })?;
            let fitted = Projector::from_obb(&obb, center);
            let mut projector = fitted;
            let mut gradient = config.gradient.params();
            let mut transfer = config.gradient.transfer;
            let mut style = None;
            let mut flat = None;
            for o in overrides {
                if let Some(d) = o.direction {
                    // A direction that is already unit is kept bit for bit, so the overrides that
                    // `drafter view` exports re-bake to the records it saved.
                    let d = DVec3::from(d);
                    projector.direction =
                        if (d.length_squared() - 1.0).abs() <= 4.0 * f64::EPSILON { d } else { d.normalize() };
                }
                if let Some(a) = o.anchor {
                    projector.anchor = DVec3::from(a);
                }
                if let Some(s) = o.scale {
                    projector.scale = s;
                }
                gradient = o.gradient(&gradient);
                transfer = o.transfer.unwrap_or(transfer);
                style = o.style.or(style);
                flat = o.flat.map(f64::from).or(flat);
            }
            // Only where the override made it so: a point-like part's own projector is degenerate
            // and drawn flat, and `drafter view` exports every part's anchor and scale.
            if overrides.iter().any(|o| o.anchor.is_some() || o.scale.is_some())
                && projector.is_degenerate()
                && !fitted.is_degenerate()
            {
                return Err(BakeError::Config(format!(
                    "[[part]] for part {p} ({}): anchor {:?} with scale {} gives no gradient (the scale must \
                     exceed 1e-12 of the anchor's largest coordinate, and both must fit in f32)",
                    part.name,
                    projector.anchor.to_array(),
                    projector.scale
                )));
            }
            Ok(PartRecord {
                id: p as u32,
                name: part.name.clone(),
                triangles: part.triangles,
                obb: box_record(&obb),
                projector: ProjectorRecord {
                    anchor: projector.anchor.to_array(),
                    direction: projector.direction.to_array(),
                    scale: projector.scale,
                    matrix: projector.matrix().to_cols_array(),
                },
                gradient: GradientRecord {
                    q: f64::from(gradient.q),
                    f: f64::from(gradient.f),
                    p: f64::from(gradient.p),
                    transfer,
                },
                style,
                flat,
            })
        })
        .collect()
}

/// World-space positions of the vertices used by `part` (each mesh vertex once).
pub fn part_points(scene: &Scene, parts: &Parts, part: PartId) -> Vec<DVec3> {
    let instance = &scene.instances[parts.part(part).instance.index()];
    points_through(scene, parts, part, &instance.world_from_object)
}

/// The positions of the vertices used by `part` (each mesh vertex once) through `transform`.
fn points_through(scene: &Scene, parts: &Parts, part: PartId, transform: &DMat4) -> Vec<DVec3> {
    let mesh = scene.mesh(parts.part(part).mesh);
    let mut seen = vec![false; mesh.positions.len()];
    let mut points = Vec::new();
    for t in parts.triangles_of(part) {
        for v in mesh.triangles[t as usize] {
            if !std::mem::replace(&mut seen[v as usize], true) {
                points.push(transform.transform_point3(mesh.positions[v as usize].as_dvec3()));
            }
        }
    }
    if points.is_empty() {
        // A node whose mesh has no triangles (only line or point primitives, which the importer
        // skips): its part is the node's origin, a box of size zero, so that the node still gets
        // its record and the bake does not fail on valid glTF.
        points.push(transform.transform_point3(DVec3::ZERO));
    }
    points
}

/// The orientations of boxes that several parts share: the same triangles of one mesh (instances
/// of it, segmented alike), boxed by the same rotation-invariant method, each placed by a
/// rotation, a mirror and a uniform scale. Their box is oriented once, in the mesh's own frame,
/// and each part's box takes that orientation turned by its instance's transform, its extents and
/// centre from its own points ([`box_with_axes`]). The searches for a box are nearly all of the
/// bounds stage, and an assembly's repeated screws, washers and gears are where its parts come
/// from.
struct SharedOrientations {
    /// Per part: the index of its shared orientation in `axes`, if it has one.
    slot: Vec<Option<usize>>,
    /// Each shared orientation, in the mesh's frame.
    axes: Vec<[DVec3; 3]>,
}

/// How far a transform's linear part may be from a rotation (or mirror) times a uniform scale,
/// relative to the scale, for its parts to share an orientation: glTF's f32 matrices of a rotation
/// are orthogonal to about 1e-7. (The box is fitted to the part's own points whatever the
/// orientation, so this bounds how much larger than the part's best box it can be.)
const SIMILARITY_TOLERANCE: f64 = 1e-6;

impl SharedOrientations {
    fn find(scene: &Scene, parts: &Parts, methods: &[ObbMethod], options: &ObbOptions) -> Self {
        let mut slot = vec![None; parts.len()];
        // The parts of each (mesh, segmentation, label, method): a per-triangle segmentation is
        // one table shared by every instance of its mesh, so its address tells the segmentations apart.
        let mut groups: std::collections::BTreeMap<(usize, usize, u32, u8), Vec<usize>> = Default::default();
        for (p, part) in parts.parts.iter().enumerate() {
            // The world's axis-aligned box is not turned with the part.
            if methods[p] == ObbMethod::Aabb
                || !is_similarity(&scene.instances[part.instance.index()].world_from_object)
            {
                continue;
            }
            let table = match &parts.instances[part.instance.index()].labels {
                MeshLabels::Whole => 0,
                MeshLabels::PerTriangle(table) => std::sync::Arc::as_ptr(table) as usize,
            };
            groups.entry((part.mesh.index(), table, part.label, methods[p] as u8)).or_default().push(p);
        }
        let shared: Vec<Vec<usize>> = groups.into_values().filter(|g| g.len() > 1).collect();
        let axes: Vec<Option<[DVec3; 3]>> = shared
            .par_iter()
            .map(|group| {
                let p = group[0];
                let points = points_through(scene, parts, PartId::from(p), &DMat4::IDENTITY);
                oriented_box(&points, &ObbOptions { method: methods[p], ..*options }).ok().map(|b| b.axes)
            })
            .collect();
        let mut kept = Vec::new();
        for (group, axes) in shared.iter().zip(axes) {
            let Some(axes) = axes else { continue };
            for &p in group {
                slot[p] = Some(kept.len());
            }
            kept.push(axes);
        }
        SharedOrientations { slot, axes: kept }
    }

    /// The world axes of part `p`'s box, if it shares an orientation.
    fn axes(&self, scene: &Scene, parts: &Parts, p: usize) -> Option<[DVec3; 3]> {
        let axes = self.axes[self.slot[p]?];
        let transform = &scene.instances[parts.parts[p].instance.index()].world_from_object;
        // A component within rounding of zero (the transform's own rounding, a few ulp of 1) is
        // zero, as it is where the search runs on the part's points: an axis in a world plane
        // stays in it, and its record does not carry the noise.
        Some(axes.map(|a| {
            let a = transform.transform_vector3(a).normalize_or_zero();
            let clean = |c: f64| if c.abs() <= 8.0 * f64::EPSILON { 0.0 } else { c };
            DVec3::new(clean(a.x), clean(a.y), clean(a.z))
        }))
    }
}

/// Whether the linear part of `m` is a rotation or mirror times a uniform scale (within
/// [`SIMILARITY_TOLERANCE`]), with finite entries and a scale that is not zero.
fn is_similarity(m: &DMat4) -> bool {
    let l = glam::DMat3::from_mat4(*m);
    let g = l.transpose() * l;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    if !(s2.is_finite() && s2 > 0.0) {
        return false;
    }
    let off = g - glam::DMat3::from_diagonal(DVec3::splat(s2));
    [off.x_axis, off.y_axis, off.z_axis].iter().all(|c| c.abs().max_element() <= SIMILARITY_TOLERANCE * s2)
}

fn box_record(obb: &Obb) -> BoxRecord {
    BoxRecord {
        center: obb.center.to_array(),
        axes: obb.axes.map(|a| a.to_array()),
        half_extents: obb.half_extents.to_array(),
        volume: obb.volume,
        method: obb.method,
    }
}

fn part_report(r: &PartRecord) -> PartReport {
    PartReport {
        id: r.id,
        name: r.name.clone(),
        triangles: r.triangles,
        obb: ObbReport {
            center: r.obb.center,
            axes: r.obb.axes,
            half_extents: r.obb.half_extents,
            volume: r.obb.volume,
            method: r.obb.method,
        },
        projector: ProjectorReport {
            anchor: r.projector.anchor,
            direction: r.projector.direction,
            scale: r.projector.scale,
        },
        gradient: r.gradient.clone(),
        style: r.style,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::{Instance, MaterialId, Mesh, MeshId, SourceFormat};
    use glam::Vec3;

    /// A closed tetrahedron whose apex is at height `top`.
    fn tetrahedron(material: u32, top: f32) -> Mesh {
        let positions =
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.2, 0.2, top]].map(Vec3::from_array).to_vec();
        let triangles = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let groups = vec![TriangleGroup {
            start: 0,
            count: 4,
            material: Some(MaterialId(material)),
            vertex_count: 4,
            ..Default::default()
        }];
        Mesh { name: format!("tetrahedron {material}"), positions, triangles, groups, ..Default::default() }
    }

    /// A bake announces every stage once, in the order of `Stage::ALL`, and times each but `Done`
    /// under its name.
    #[test]
    fn a_bake_announces_its_stages_in_order() {
        let mut scene = Scene::new(SourceFormat::Obj);
        scene.meshes = vec![tetrahedron(0, 1.0)];
        scene.instances.push(Instance {
            name: "i".into(),
            mesh: MeshId(0),
            node: None,
            world_from_object: DMat4::IDENTITY,
        });
        let mut seen = Vec::new();
        let baked = bake_observed(&scene, &BakeConfig::default(), &mut |stage| seen.push(stage)).expect("a bake");
        assert_eq!(seen, Stage::ALL);
        let timed: Vec<&str> = baked.report.stages.iter().map(|t| t.name).collect();
        assert_eq!(timed, STAGE_NAMES[..STAGE_NAMES.len() - 1]);
        assert!(Stage::ALL.iter().enumerate().all(|(i, s)| s.index() == i && STAGE_NAMES[i] == s.name()));
    }

    /// A mesh repeats the first used mesh with its geometry and parts, whatever its name and
    /// materials; a moved vertex, or a mesh no instance uses, does not.
    #[test]
    fn repeated_meshes_are_found() {
        let mut scene = Scene::new(SourceFormat::Obj);
        scene.meshes = vec![
            tetrahedron(0, 1.0),
            tetrahedron(1, 1.0),
            tetrahedron(0, 1.5),
            tetrahedron(2, 1.0),
            tetrahedron(3, 1.0),
        ];
        for m in [2, 0, 1, 0, 4] {
            let at = DMat4::from_translation(DVec3::new(3.0 * m as f64, 0.0, 0.0));
            scene.instances.push(Instance {
                name: format!("i{m}"),
                mesh: MeshId(m),
                node: None,
                world_from_object: at,
            });
        }
        let (parts, _) = drafter_segment::segment(&scene, &drafter_segment::SegmentOptions::default());
        assert_eq!(canonical_meshes(&scene, &parts), vec![0, 0, 2, 3, 0]);
        let baked = bake(&scene, &BakeConfig::default()).expect("bakes");
        let lines = baked.report.lines.expect("lines");
        assert_eq!(lines.meshes, 4, "each used mesh counts, repeated or not");
    }
}
