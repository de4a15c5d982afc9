//! Parameter sweeps of every stage on one scene: time against accuracy, in one process, so the
//! figures of one run compare with each other (the machines are shared and noisy).
//!
//! * **Oriented boxes** ([`sweep_obb`]): every part, every method, one thread; time per part and
//!   volume over the best box any method found for that part.
//! * **Normal enhancement** ([`sweep_normals`]): the face filter of Cignoni et al. 2005 over its
//!   iteration count and its strength `k`, timed over every unique mesh; accuracy as the mean angle
//!   to the result at [`CONVERGED_ITERATIONS`] and as the fraction of crease edges (dihedral above
//!   30°) whose shading contrast grew — contrast being the angle between the two faces' normals,
//!   the largest difference in Lambertian shade that any light can make across the edge.
//! * **Silhouettes** ([`sweep_silhouettes`]): on the mesh with the most silhouette candidates, time
//!   per view of brute force, the Gauss map (overlapping and strict bins, by depth) and the
//!   perspective cone BVH, on evenly strided subsets of its candidates (edge count axis) and at
//!   every depth; every answer is checked against brute force; the configuration the bake would
//!   store is reported.
//! * **Segmentation** ([`sweep_segmentation`]): parts and time over the region-growing angle
//!   (`regions` mode) and the small-part merge threshold (`auto` mode on each unique mesh alone).
//! * **Bake** ([`sweep_bake`]): stage timings of a default bake, and output bytes per stage from
//!   bakes with stages switched off one by one.
//!
//! Timing: minimum over repeats for anything under 20 ms, one run otherwise; boxes on one thread
//! (comparable with single-threaded peers), everything else on the global rayon pool as in a bake.

use std::time::Instant;

use drafter_bake::BakeConfig;
use drafter_bounds::{ObbMethod, ObbOptions, oriented_box};
use drafter_core::{PartId, Scene, Topology, Weld};
use drafter_lines::{
    Bins, BruteForce, BruteForceReason, ConeBvh, ConeBvhOptions, CostModel, EdgeSet, GaussMapHierarchy,
    GaussMapOptions, HierarchyChoice, LineOptions, SilhouetteIndex, SilhouetteOptions, View, classify_edges,
    depth_for_count,
};
use drafter_normals::{EnhanceOptions, enhance_faces};
use drafter_segment::{FanPairing, SegmentMode, SegmentOptions, segment, segment_with_topologies};
use glam::Vec3;
use serde::{Deserialize, Serialize};

use drafter_testkit::Rng;
use drafter_testkit::generate::TriMesh;

/// The reference of the normals accuracy: the filter run this many iterations.
pub const CONVERGED_ITERATIONS: u32 = 160;
/// Iteration counts of the normals sweep.
pub const ITERATIONS: [u32; 8] = [1, 2, 5, 10, 20, 40, 80, CONVERGED_ITERATIONS];
/// Strengths `k` of the normals sweep.
pub const STRENGTHS: [f32; 8] = [0.0, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.5];
/// Region angles (degrees) of the segmentation sweep.
pub const REGION_ANGLES: [f64; 8] = [5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 90.0];
/// Merge thresholds (fraction of a mesh's triangles) of the segmentation sweep.
pub const MERGE_FRACTIONS: [f64; 7] = [0.0, 0.001, 0.003, 0.01, 0.03, 0.1, 0.3];
/// Dihedral angle above which an edge counts as a crease for the contrast measure.
pub const CREASE_DEG: f64 = 30.0;

/// What to sweep and how hard.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepOptions {
    /// Views per silhouette measurement (each orthographic and perspective). Default 200.
    pub views: usize,
    /// At most this many parts get boxes (evenly spaced by id); default 400.
    pub max_obb_parts: usize,
    /// Seed of the random views. Default 1.
    pub seed: u64,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self { views: 200, max_obb_parts: 400, seed: 1 }
    }
}

/// Progress of a sweep, for a progress bar.
pub trait Progress {
    /// A stage begins with `items` steps.
    fn stage(&mut self, name: &str, items: u64);
    /// One step is done.
    fn tick(&mut self);
}

/// No progress display.
#[derive(Debug, Default)]
pub struct Silent;

impl Progress for Silent {
    fn stage(&mut self, _: &str, _: u64) {}
    fn tick(&mut self) {}
}

/// Everything measured on one scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SweepReport {
    pub model: ModelInfo,
    /// Threads of the global pool (boxes use one).
    pub threads: usize,
    pub obb: ObbSweep,
    pub normals: NormalsSweep,
    pub silhouettes: Option<SilhouetteSweep>,
    pub segmentation: SegmentSweep,
    pub bake: BakeSweep,
    /// Bytes against accuracy of the silhouette normals.
    #[serde(default)]
    pub quantization: Option<crate::quantization::QuantizationSweep>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ModelInfo {
    pub name: String,
    pub meshes: usize,
    pub instances: usize,
    /// Triangles of all instances.
    pub triangles: usize,
    /// Triangles of the unique meshes used.
    pub unique_triangles: usize,
}

/// Runs every sweep.
pub fn run(scene: &Scene, name: &str, options: &SweepOptions, progress: &mut dyn Progress) -> SweepReport {
    let used = used_meshes(scene);
    let model = ModelInfo {
        name: name.to_owned(),
        meshes: used.iter().filter(|&&u| u).count(),
        instances: scene.instances.len(),
        triangles: scene.instanced_triangle_count(),
        unique_triangles: scene.meshes.iter().zip(&used).filter(|(_, u)| **u).map(|(m, _)| m.triangles.len()).sum(),
    };
    let topologies = topologies(scene, &used);
    let obb = sweep_obb(scene, options, progress);
    let normals = sweep_normals(&topologies, progress);
    let silhouettes = sweep_silhouettes(&topologies, options, progress);
    progress.stage("quantization", 1);
    let quantization = crate::quantization::sweep_quantization(&topologies, options.views, options.seed);
    progress.tick();
    let segmentation = sweep_segmentation(scene, &topologies, progress);
    let bake = sweep_bake(scene, progress);
    SweepReport {
        model,
        threads: rayon::current_num_threads(),
        obb,
        normals,
        silhouettes,
        segmentation,
        bake,
        quantization,
    }
}

fn used_meshes(scene: &Scene) -> Vec<bool> {
    let mut used = vec![false; scene.meshes.len()];
    for i in &scene.instances {
        used[i.mesh.index()] = true;
    }
    used
}

/// Welded topology of each used mesh (empty for unused ones), as the bake builds it.
fn topologies(scene: &Scene, used: &[bool]) -> Vec<Topology> {
    scene
        .meshes
        .iter()
        .zip(used)
        .map(|(m, &u)| if u { Topology::build(m, Weld::default()) } else { Topology::default() })
        .collect()
}

/// Milliseconds of `f`: the minimum of up to 5 runs while runs take under 20 ms.
fn time_ms<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let start = Instant::now();
    let mut out = f();
    let mut best = start.elapsed().as_secs_f64() * 1e3;
    let mut runs = 1;
    while best < 20.0 && runs < 5 {
        let start = Instant::now();
        out = f();
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
        runs += 1;
    }
    (best, out)
}

// ---------------------------------------------------------------------------------------------
// Oriented boxes

/// Methods compared by the box sweep (cheapest first).
pub const OBB_METHODS: [ObbMethod; 5] =
    [ObbMethod::Aabb, ObbMethod::Pca, ObbMethod::Hull, ObbMethod::Default, ObbMethod::Optimal];

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ObbSweep {
    /// Parts in the scene (default segmentation) and parts measured.
    pub parts: usize,
    pub measured_parts: usize,
    pub methods: Vec<ObbMethodSummary>,
    /// Per measured part: points, and per method (in `methods` order) milliseconds and volume over
    /// the smallest volume found.
    pub per_part: Vec<ObbPart>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ObbMethodSummary {
    pub method: String,
    pub mean_ms: f64,
    pub median_ms: f64,
    pub total_ms: f64,
    /// Mean and worst of volume / best volume (parts with a positive best volume).
    pub mean_relative_volume: f64,
    pub max_relative_volume: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ObbPart {
    pub part: u32,
    pub points: usize,
    pub ms: Vec<f64>,
    pub relative_volume: Vec<f64>,
}

pub fn sweep_obb(scene: &Scene, options: &SweepOptions, progress: &mut dyn Progress) -> ObbSweep {
    let (parts, _) = segment(scene, &SegmentOptions::default());
    let n = parts.len();
    let take = n.min(options.max_obb_parts.max(1));
    let ids: Vec<usize> = (0..take).map(|i| i * n / take).collect();
    progress.stage("oriented boxes", ids.len() as u64);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().ok();
    let mut per_part = Vec::new();
    for &p in &ids {
        let points = drafter_bake::part_points(scene, &parts, PartId::from(p));
        let mut ms = Vec::new();
        let mut volumes = Vec::new();
        for method in OBB_METHODS {
            let run = || oriented_box(&points, &ObbOptions::with_method(method));
            let (t, obb) = match &pool {
                Some(pool) => pool.install(|| time_ms(run)),
                None => time_ms(run),
            };
            ms.push(t);
            volumes.push(obb.map_or(f64::NAN, |b| b.volume));
        }
        let best = volumes.iter().copied().filter(|v| v.is_finite()).fold(f64::INFINITY, f64::min);
        let relative_volume =
            volumes.iter().map(|&v| if best > 0.0 && best.is_finite() { v / best } else { 1.0 }).collect();
        per_part.push(ObbPart { part: p as u32, points: points.len(), ms, relative_volume });
        progress.tick();
    }
    let methods = OBB_METHODS
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let mut ms: Vec<f64> = per_part.iter().map(|p| p.ms[k]).collect();
            ms.sort_by(f64::total_cmp);
            let rel: Vec<f64> = per_part.iter().map(|p| p.relative_volume[k]).filter(|r| r.is_finite()).collect();
            let total: f64 = ms.iter().sum();
            ObbMethodSummary {
                method: m.name().to_owned(),
                mean_ms: total / ms.len().max(1) as f64,
                median_ms: ms.get(ms.len() / 2).copied().unwrap_or(0.0),
                total_ms: total,
                mean_relative_volume: rel.iter().sum::<f64>() / rel.len().max(1) as f64,
                max_relative_volume: rel.iter().copied().fold(1.0, f64::max),
            }
        })
        .collect();
    ObbSweep { parts: n, measured_parts: per_part.len(), methods, per_part }
}

// ---------------------------------------------------------------------------------------------
// Normals

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NormalsSweep {
    pub faces: usize,
    /// Edges whose dihedral angle exceeds [`CREASE_DEG`].
    pub crease_edges: usize,
    pub default_iterations: u32,
    pub default_strength: f32,
    pub converged_iterations: u32,
    /// Over [`ITERATIONS`] at the default strength.
    pub by_iterations: Vec<NormalsPoint>,
    /// Over [`STRENGTHS`] at the default iteration count.
    pub by_strength: Vec<NormalsPoint>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NormalsPoint {
    pub iterations: u32,
    pub strength: f32,
    /// The face filter (adjacency, low-pass, enhancement) over every unique mesh.
    pub ms: f64,
    /// Mean angle between the enhanced face normals and those at [`CONVERGED_ITERATIONS`] (same
    /// strength), degrees.
    pub mean_deg_from_converged: f64,
    /// Fraction of crease edges whose contrast (angle between the two faces' normals) grew.
    pub crease_contrast_increased: f64,
    /// Mean change of that contrast over the crease edges, degrees.
    pub mean_crease_contrast_gain_deg: f64,
}

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Crease edges (two non-degenerate faces, dihedral above [`CREASE_DEG`]) as face pairs.
fn crease_pairs(topology: &Topology, normals: &[Vec3]) -> Vec<(u32, u32)> {
    (0..topology.edges.len())
        .filter_map(|e| match topology.faces_of_edge(e) {
            &[f, g] => {
                let (a, b) = (normals[f as usize], normals[g as usize]);
                (a != Vec3::ZERO && b != Vec3::ZERO && angle_deg(a, b) > CREASE_DEG).then_some((f, g))
            }
            _ => None,
        })
        .collect()
}

pub fn sweep_normals(topologies: &[Topology], progress: &mut dyn Progress) -> NormalsSweep {
    let defaults = EnhanceOptions::default();
    let meshes: Vec<&Topology> = topologies.iter().filter(|t| !t.faces.is_empty()).collect();
    progress.stage("normal enhancement", (ITERATIONS.len() + STRENGTHS.len() + 1) as u64);
    // Per mesh: original face normals, crease pairs, and the converged result.
    let run = |options: &EnhanceOptions| -> (f64, Vec<drafter_normals::EnhancedFaces>) {
        time_ms(|| meshes.iter().map(|t| enhance_faces(t, options)).collect::<Vec<_>>())
    };
    let reference = run(&EnhanceOptions { iterations: CONVERGED_ITERATIONS, ..defaults }).1;
    progress.tick();
    let creases: Vec<Vec<(u32, u32)>> =
        meshes.iter().zip(&reference).map(|(t, r)| crease_pairs(t, &r.geometry.normals)).collect();
    let measure = |options: EnhanceOptions, reference: &[drafter_normals::EnhancedFaces]| {
        let (ms, out) = run(&options);
        let (mut angle, mut faces) = (0.0, 0usize);
        let (mut grew, mut gain, mut creases_n) = (0usize, 0.0, 0usize);
        for ((o, r), pairs) in out.iter().zip(reference).zip(&creases) {
            for (f, (a, b)) in o.enhanced.iter().zip(&r.enhanced).enumerate() {
                if !o.geometry.is_degenerate(f) {
                    angle += angle_deg(*a, *b);
                    faces += 1;
                }
            }
            for &(f, g) in pairs {
                let n = &o.geometry.normals;
                let before = angle_deg(n[f as usize], n[g as usize]);
                let after = angle_deg(o.enhanced[f as usize], o.enhanced[g as usize]);
                grew += usize::from(after > before + 1e-6);
                gain += after - before;
                creases_n += 1;
            }
        }
        NormalsPoint {
            iterations: options.iterations,
            strength: options.strength,
            ms,
            mean_deg_from_converged: angle / faces.max(1) as f64,
            crease_contrast_increased: grew as f64 / creases_n.max(1) as f64,
            mean_crease_contrast_gain_deg: gain / creases_n.max(1) as f64,
        }
    };
    let mut by_iterations = Vec::new();
    for iterations in ITERATIONS {
        by_iterations.push(measure(EnhanceOptions { iterations, ..defaults }, &reference));
        progress.tick();
    }
    let mut by_strength = Vec::new();
    for strength in STRENGTHS {
        // The converged reference at this strength: the converged low-pass does not depend on k.
        let reference_k: Vec<drafter_normals::EnhancedFaces> = reference
            .iter()
            .map(|r| drafter_normals::EnhancedFaces {
                enhanced: drafter_normals::enhance(&r.geometry.normals, &r.low_pass, strength),
                ..r.clone()
            })
            .collect();
        by_strength.push(measure(EnhanceOptions { strength, ..defaults }, &reference_k));
        progress.tick();
    }
    NormalsSweep {
        faces: meshes.iter().map(|t| t.faces.len()).sum(),
        crease_edges: creases.iter().map(Vec::len).sum(),
        default_iterations: defaults.iterations,
        default_strength: defaults.strength,
        converged_iterations: CONVERGED_ITERATIONS,
        by_iterations,
        by_strength,
    }
}

// ---------------------------------------------------------------------------------------------
// Silhouettes

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SilhouetteSweep {
    /// The measured mesh (the one with the most candidates) and its counts.
    pub mesh: usize,
    pub edges: usize,
    pub candidates: usize,
    pub views: usize,
    /// Time per view over candidate subsets (every `stride`-th candidate).
    pub by_size: Vec<SilhouetteSize>,
    /// Gauss map over depths on all candidates, overlapping and strict bins.
    pub by_depth: Vec<SilhouetteDepth>,
    /// Brute force on all candidates, µs per orthographic view (the baseline of `by_depth`).
    pub brute_ortho_us: f64,
    /// What [`SilhouetteIndex::build`] with the defaults stores for the whole mesh.
    pub chosen_orthographic: String,
    pub chosen_perspective: String,
    /// Depth of the stored Gauss map, if one is stored.
    pub chosen_depth: Option<u8>,
    /// Views on which a hierarchy's set differed from brute force (must be 0).
    pub mismatches: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SilhouetteSize {
    pub stride: usize,
    pub candidates: usize,
    /// Microseconds per view (one thread).
    pub brute_ortho_us: f64,
    pub brute_perspective_us: f64,
    pub gauss_overlapping_us: f64,
    pub gauss_strict_us: f64,
    pub cone_bvh_us: f64,
    /// Depth picked by [`depth_for_count`].
    pub auto_depth: u8,
    pub mean_silhouettes: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SilhouetteDepth {
    pub depth: u8,
    pub overlapping_us: f64,
    pub strict_us: f64,
}

/// Microseconds per view of `query` over `views`: three passes, the fastest counts.
fn us_per_view(views: &[View], mut query: impl FnMut(View)) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let start = Instant::now();
        for &v in views {
            query(v);
        }
        best = best.min(start.elapsed().as_secs_f64() * 1e6 / views.len().max(1) as f64);
    }
    best
}

fn choice_name(c: HierarchyChoice) -> String {
    match c {
        HierarchyChoice::GaussMap { max_depth, predicted_speedup, .. } => {
            format!("gauss map, depth {max_depth} (predicted {predicted_speedup:.1}x)")
        }
        HierarchyChoice::ConeBvh { leaf_size, predicted_speedup, .. } => {
            format!("cone BVH, leaves of {leaf_size} (predicted {predicted_speedup:.1}x)")
        }
        HierarchyChoice::BruteForce(BruteForceReason::TooFewCandidates { candidates, minimum }) => {
            format!("brute force ({candidates} < {minimum} candidates)")
        }
        HierarchyChoice::BruteForce(BruteForceReason::NotFaster { predicted_speedup }) => {
            format!("brute force (hierarchy predicted {predicted_speedup:.1}x only)")
        }
        HierarchyChoice::BruteForce(reason) => format!("brute force ({reason:?})"),
    }
}

pub fn sweep_silhouettes(
    topologies: &[Topology],
    options: &SweepOptions,
    progress: &mut dyn Progress,
) -> Option<SilhouetteSweep> {
    // Classify every used mesh; measure the one with the most candidates.
    let (mesh, topology, lines) = topologies
        .iter()
        .enumerate()
        .filter(|(_, t)| !t.faces.is_empty())
        .filter_map(|(m, t)| classify_edges(t, None, &LineOptions::default()).ok().map(|l| (m, t, l)))
        .max_by_key(|(m, _, l)| (l.candidates.len(), usize::MAX - m))?;
    let n = lines.candidates.len();
    if n == 0 {
        return None;
    }
    let cost = CostModel::default();
    let full_depth = depth_for_count(n, GaussMapOptions::default().base);
    let depths: Vec<u8> = (0..=(full_depth + 1).min(10)).collect();
    let strides: Vec<usize> = [256usize, 64, 16, 4, 1].into_iter().filter(|&s| n / s >= 64 || s == 1).collect();
    progress.stage("silhouettes", (strides.len() + depths.len() + 1) as u64);

    let mut rng = Rng::new(options.seed);
    let (lo, hi) =
        lines.candidate_points.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo) * 0.5).length().max(1e-6);
    let ortho: Vec<View> =
        (0..options.views).map(|_| View::Orthographic { direction: rng.direction().as_vec3() }).collect();
    let persp: Vec<View> = (0..options.views)
        .map(|_| View::Perspective {
            eye: center + rng.direction().as_vec3() * radius * (1.05 + 3.0 * rng.unit_f64() as f32),
        })
        .collect();
    let direction = |v: View| match v {
        View::Orthographic { direction } => direction,
        View::Perspective { .. } => Vec3::ZERO,
    };
    let eye = |v: View| match v {
        View::Perspective { eye } => eye,
        View::Orthographic { .. } => Vec3::ZERO,
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().ok();
    let one_thread = |f: &mut (dyn FnMut() + Send)| match &pool {
        Some(p) => p.install(f),
        None => f(),
    };

    let chosen = SilhouetteIndex::build(&lines, &SilhouetteOptions::default());
    let chosen_depth = chosen.gauss_map().map(|g| g.max_depth());
    progress.tick();

    let mut mismatches = 0usize;
    let (mut a, mut b) = (EdgeSet::default(), EdgeSet::default());
    let mut by_size = Vec::new();
    for &stride in &strides {
        let normals: Vec<[Vec3; 2]> = lines.candidate_normals.iter().step_by(stride).copied().collect();
        let points: Vec<Vec3> = lines.candidate_points.iter().step_by(stride).copied().collect();
        let brute = BruteForce::new(&normals, &points);
        let auto_depth = depth_for_count(normals.len(), GaussMapOptions::default().base);
        let overlapping = GaussMapHierarchy::build(&normals, &GaussMapOptions::default(), &cost);
        let strict =
            GaussMapHierarchy::build(&normals, &GaussMapOptions { bins: Bins::Strict, ..Default::default() }, &cost);
        let bvh = ConeBvh::build(&normals, &points, &ConeBvhOptions::default(), &cost);
        let mut silhouettes = 0usize;
        for &v in &ortho {
            brute.query_serial(v, &mut a);
            silhouettes += a.count();
            for g in [&overlapping, &strict] {
                g.query(direction(v), &mut b);
                mismatches += usize::from(a != b);
            }
        }
        for &v in &persp {
            brute.query_serial(v, &mut a);
            bvh.query(eye(v), &mut b);
            mismatches += usize::from(a != b);
        }
        let mut row = SilhouetteSize {
            stride,
            candidates: normals.len(),
            brute_ortho_us: 0.0,
            brute_perspective_us: 0.0,
            gauss_overlapping_us: 0.0,
            gauss_strict_us: 0.0,
            cone_bvh_us: 0.0,
            auto_depth,
            mean_silhouettes: silhouettes as f64 / ortho.len().max(1) as f64,
        };
        one_thread(&mut || {
            row.brute_ortho_us = us_per_view(&ortho, |v| brute.query_serial(v, &mut a));
            row.brute_perspective_us = us_per_view(&persp, |v| brute.query_serial(v, &mut a));
            row.gauss_overlapping_us = us_per_view(&ortho, |v| overlapping.query(direction(v), &mut b));
            row.gauss_strict_us = us_per_view(&ortho, |v| strict.query(direction(v), &mut b));
            row.cone_bvh_us = us_per_view(&persp, |v| bvh.query(eye(v), &mut b));
        });
        by_size.push(row);
        progress.tick();
    }
    let brute_ortho_us = by_size.last().map_or(0.0, |r| r.brute_ortho_us);
    let normals = &lines.candidate_normals;
    let brute = BruteForce::new(normals, &lines.candidate_points);
    let mut by_depth = Vec::new();
    for &depth in &depths {
        let mut us = [0.0; 2];
        for (k, bins) in
            [Bins::Overlapping { factor: drafter_lines::DEFAULT_OVERLAP }, Bins::Strict].into_iter().enumerate()
        {
            let g = GaussMapHierarchy::build(
                normals,
                &GaussMapOptions { bins, max_depth: Some(depth), ..Default::default() },
                &cost,
            );
            for &v in ortho.iter().take(32) {
                brute.query_serial(v, &mut a);
                g.query(direction(v), &mut b);
                mismatches += usize::from(a != b);
            }
            one_thread(&mut || us[k] = us_per_view(&ortho, |v| g.query(direction(v), &mut b)));
        }
        by_depth.push(SilhouetteDepth { depth, overlapping_us: us[0], strict_us: us[1] });
        progress.tick();
    }
    Some(SilhouetteSweep {
        mesh,
        edges: topology.edges.len(),
        candidates: n,
        views: options.views,
        by_size,
        by_depth,
        brute_ortho_us,
        chosen_orthographic: choice_name(chosen.orthographic_choice()),
        chosen_perspective: choice_name(chosen.perspective_choice()),
        chosen_depth,
        mismatches,
    })
}

// ---------------------------------------------------------------------------------------------
// Segmentation

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SegmentSweep {
    pub default_parts: usize,
    pub default_region_angle_deg: f64,
    pub default_merge_fraction: f64,
    /// `regions` mode over [`REGION_ANGLES`].
    pub by_region_angle: Vec<SegmentPoint>,
    /// `auto` mode on each unique mesh alone over [`MERGE_FRACTIONS`] (parts summed).
    pub by_merge_fraction: Vec<SegmentPoint>,
    /// `auto` mode on the generated contact family ([`drafter_testkit::assemblies::contact_assemblies`]),
    /// with fans paired whole only (the earlier rule), in part, and in part with cracks glued (the
    /// defaults).
    #[serde(default)]
    pub contacts: Vec<ContactPoint>,
}

/// Accuracy of `auto` on one generated contact assembly under each fan-pairing rule.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ContactPoint {
    pub name: String,
    pub triangles: usize,
    pub truth_parts: usize,
    /// [`FanPairing::Whole`]: fraction of triangles in a matching part, and parts found.
    pub whole: (f64, usize),
    /// [`FanPairing::Partial`], without gluing cracks.
    pub partial: (f64, usize),
    /// The defaults: fans paired in part and open pieces glued across cracks.
    #[serde(default)]
    pub stitched: (f64, usize),
}

/// [`ContactPoint`]s of the generated contact family.
pub fn contact_accuracy() -> Vec<ContactPoint> {
    drafter_testkit::assemblies::contact_assemblies()
        .iter()
        .map(|a| {
            let (scene, truth) = a.merged();
            let measure = |fan_pairing, stitch_fraction| {
                let options = SegmentOptions { fan_pairing, stitch_fraction, ..SegmentOptions::default() };
                let (parts, _) = segment(&scene, &options);
                let acc = drafter_testkit::assemblies::accuracy(&parts, &truth);
                (acc, (acc.matched, acc.parts))
            };
            let (acc, whole) = measure(FanPairing::Whole, 0.0);
            let (_, partial) = measure(FanPairing::Partial, 0.0);
            let (_, stitched) = measure(FanPairing::Partial, drafter_segment::DEFAULT_STITCH_FRACTION);
            ContactPoint {
                name: a.name.clone(),
                triangles: truth.len(),
                truth_parts: acc.truth_parts,
                whole,
                partial,
                stitched,
            }
        })
        .collect()
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SegmentPoint {
    pub value: f64,
    pub parts: usize,
    pub ms: f64,
}

pub fn sweep_segmentation(scene: &Scene, topologies: &[Topology], progress: &mut dyn Progress) -> SegmentSweep {
    progress.stage("segmentation", (REGION_ANGLES.len() + MERGE_FRACTIONS.len() + 2) as u64);
    let defaults = SegmentOptions::default();
    let (default_parts, _) = segment_with_topologies(scene, topologies, &defaults);
    progress.tick();
    let mut by_region_angle = Vec::new();
    for angle in REGION_ANGLES {
        let options = SegmentOptions { mode: SegmentMode::Regions, region_angle_deg: angle, ..defaults.clone() };
        let (ms, (parts, _)) = time_ms(|| segment_with_topologies(scene, topologies, &options));
        by_region_angle.push(SegmentPoint { value: angle, parts: parts.len(), ms });
        progress.tick();
    }
    // Each used mesh alone, once, as a single-instance scene (what `auto` merges).
    let used = used_meshes(scene);
    let singles: Vec<(Scene, Vec<Topology>)> = scene
        .meshes
        .iter()
        .zip(topologies)
        .zip(&used)
        .filter(|(_, u)| **u)
        .map(|((m, t), _)| {
            let tri = TriMesh { positions: m.positions.clone(), triangles: m.triangles.clone() };
            (tri.to_scene(&m.name), vec![t.clone()])
        })
        .collect();
    let mut by_merge_fraction = Vec::new();
    for fraction in MERGE_FRACTIONS {
        let options = SegmentOptions { merge_triangle_fraction: fraction, ..defaults.clone() };
        let (ms, parts) =
            time_ms(|| singles.iter().map(|(s, t)| segment_with_topologies(s, t, &options).0.len()).sum::<usize>());
        by_merge_fraction.push(SegmentPoint { value: fraction, parts, ms });
        progress.tick();
    }
    let contacts = contact_accuracy();
    progress.tick();
    SegmentSweep {
        contacts,
        default_parts: default_parts.len(),
        default_region_angle_deg: defaults.region_angle_deg,
        default_merge_fraction: defaults.merge_triangle_fraction,
        by_region_angle,
        by_merge_fraction,
    }
}

// ---------------------------------------------------------------------------------------------
// Bake

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BakeSweep {
    /// Stage timings of the default bake (ms), in stage order.
    pub stages: Vec<(String, f64)>,
    pub total_ms: f64,
    /// Output bytes: the scene with parts, boxes and projectors (textures, normals and lines off),
    /// then what textures, normals, edges and silhouette hierarchies each add (signed: alignment padding can make
    /// a step a few bytes negative).
    pub bytes: Vec<(String, i64)>,
    pub output_bytes: u64,
}

pub fn sweep_bake(scene: &Scene, progress: &mut dyn Progress) -> BakeSweep {
    progress.stage("bake", 5);
    let mut configs = Vec::new();
    let mut base = BakeConfig::default();
    base.normals.enabled = false;
    base.lines.enabled = false;
    base.textures.enabled = false;
    configs.push(base.clone());
    base.textures.enabled = true;
    configs.push(base.clone());
    base.normals.enabled = true;
    configs.push(base.clone());
    base.lines.enabled = true;
    base.lines.hierarchies = false;
    configs.push(base.clone());
    base.lines.hierarchies = true;
    configs.push(base);
    let mut sizes = Vec::new();
    let mut full = None;
    for config in &configs {
        let baked = drafter_bake::bake(scene, config);
        let bytes = baked.as_ref().map_or(0, |b| b.report.output_bytes);
        sizes.push(bytes);
        full = baked.ok().map(|b| b.report);
        progress.tick();
    }
    let stages: Vec<(String, f64)> =
        full.as_ref().map(|r| r.stages.iter().map(|s| (s.name.to_owned(), s.ms)).collect()).unwrap_or_default();
    let names = ["scene, parts, boxes", "textures", "normals", "edges", "silhouette hierarchies"];
    let mut bytes = Vec::new();
    let mut previous = 0i64;
    for (name, &size) in names.iter().zip(&sizes) {
        bytes.push(((*name).to_owned(), size as i64 - previous));
        previous = size as i64;
    }
    BakeSweep {
        total_ms: stages.iter().map(|s| s.1).sum(),
        stages,
        bytes,
        output_bytes: sizes.last().copied().unwrap_or(0),
    }
}
