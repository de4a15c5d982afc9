//! The normal-enhancement filter itself: low-pass by iterated averaging, then unsharp masking.

use drafter_core::Topology;
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::adjacency::{FaceAdjacency, Neighborhood, Weighting};
use crate::face::{FACE_CHUNK, FaceGeometry};

/// Default enhancement strength `k`: the middle of the paper's range [0.2, 0.7] (§5).
pub const DEFAULT_STRENGTH: f32 = 0.5;
/// Default number of averaging iterations: the middle of the paper's 10–30 (§5, Fig. 6).
pub const DEFAULT_ITERATIONS: u32 = 20;

/// Parameters of the enhancement `n_E = normalize(n + k·(n − n_L))`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EnhanceOptions {
    /// `k`, how strongly the normal is pushed away from its low-pass version. Default
    /// [`DEFAULT_STRENGTH`]; the paper finds 0.2–0.7 reasonable. 0 returns the face normals; larger
    /// values darken concave and brighten convex transitions more, and make flat faces next to
    /// features look slightly curved (§5.1).
    pub strength: f32,
    /// Averaging iterations that produce `n_L`. Default [`DEFAULT_ITERATIONS`]; the paper uses 10–30.
    /// More iterations widen the shaded band along features and let small features fade from `n_L`,
    /// so their own enhancement becomes uniform (Fig. 6). 0 returns the face normals.
    pub iterations: u32,
    /// Which faces are averaged. Default [`Neighborhood::Edge`].
    pub neighborhood: Neighborhood,
    /// How neighbours are weighted. Default [`Weighting::ScaleDependent`] (see the crate docs for the
    /// measurements behind this choice).
    pub weighting: Weighting,
}

impl Default for EnhanceOptions {
    fn default() -> Self {
        Self {
            strength: DEFAULT_STRENGTH,
            iterations: DEFAULT_ITERATIONS,
            neighborhood: Neighborhood::default(),
            weighting: Weighting::default(),
        }
    }
}

/// Per-face normals before and after enhancement, indexed like `Topology::faces`.
#[derive(Clone, Debug, Default)]
pub struct EnhancedFaces {
    /// Face geometry; its `normals` are `n` (zero for degenerate faces).
    pub geometry: FaceGeometry,
    /// `n_L`, the low-pass normals (unit, or zero for a face with no normal and no neighbour with one).
    pub low_pass: Vec<Vec3>,
    /// `n_E`, the enhanced normals (unit, or zero as `low_pass`).
    pub enhanced: Vec<Vec3>,
    /// Face-iterations performed (faces × iterations), for throughput figures.
    pub face_iterations: u64,
    /// The scale-dependent reference length `h` used (median centroid distance of neighbours).
    pub reference_length: f32,
}

/// Runs the whole filter on a mesh's welded topology: face geometry, adjacency, low-pass, enhancement.
pub fn enhance_faces(topology: &Topology, options: &EnhanceOptions) -> EnhancedFaces {
    let geometry = FaceGeometry::compute(topology);
    let filtered = filter(topology, &geometry, options);
    filtered.with_geometry(geometry, options)
}

/// The filter's results on face geometry computed from `topology`, before [`EnhancedFaces`] takes the
/// geometry.
pub(crate) struct Filtered {
    low_pass: Vec<Vec3>,
    enhanced: Vec<Vec3>,
    reference_length: f32,
}

impl Filtered {
    pub(crate) fn with_geometry(self, geometry: FaceGeometry, options: &EnhanceOptions) -> EnhancedFaces {
        EnhancedFaces {
            face_iterations: geometry.len() as u64 * options.iterations as u64,
            reference_length: self.reference_length,
            geometry,
            low_pass: self.low_pass,
            enhanced: self.enhanced,
        }
    }
}

/// Adjacency, low-pass and enhancement on `geometry`, which must come from `topology`.
pub(crate) fn filter(topology: &Topology, geometry: &FaceGeometry, options: &EnhanceOptions) -> Filtered {
    let adjacency = FaceAdjacency::build(topology, geometry, options.neighborhood, options.weighting);
    let low_pass = low_pass(&adjacency, &geometry.normals, options.iterations);
    let enhanced = enhance(&geometry.normals, &low_pass, options.strength);
    Filtered { low_pass, enhanced, reference_length: adjacency.reference_length() }
}

/// `n_L`: `iterations` Jacobi steps of re-normalised weighted averaging (the paper's Laplacian kernel),
/// starting from `normals`. A degenerate face (zero normal, zero self weight) receives its
/// neighbours' average but never contributes.
pub fn low_pass(adjacency: &FaceAdjacency, normals: &[Vec3], iterations: u32) -> Vec<Vec3> {
    adjacency.smooth(normals, iterations)
}

/// `n_E = normalize(n + k·(n − n_L))` per face. For unit `n`, `n_L` and `k ≥ 0` the sum has length at
/// least 1, so the result is always defined. A face with no normal of its own takes `n_L`.
pub fn enhance(normals: &[Vec3], low_pass: &[Vec3], strength: f32) -> Vec<Vec3> {
    normals
        .par_iter()
        .zip(low_pass.par_iter())
        .with_min_len(FACE_CHUNK)
        .map(|(&n, &l)| if n == Vec3::ZERO { l } else { (n + strength * (n - l)).normalize_or(n) })
        .collect()
}
