//! Normal enhancement and crease-aware vertex normals.
//!
//! CAD tessellations shade flat and ambiguous. Cignoni, Scopigno and Tarini, "A simple normal
//! enhancement technique for interactive non-photorealistic renderings", Computers & Graphics 29(1),
//! 2005 (`../shared/papers/004_5602abd1f4ef4d91.txt`) sharpen the perceived shape by changing only the
//! normals, in a preprocessing step: any renderer benefits and the silhouette stays exact.
//!
//! # How it works
//!
//! 1. **Face normals** `n` and areas in f64 from the welded positions of [`drafter_core::Topology`]
//!    ([`FaceGeometry`]). A degenerate face (zero area, or collapsed by welding) gets a zero normal and
//!    zero weight: it never votes.
//! 2. **Low-pass** `n_L` (§4 step 1, the paper's Laplacian kernel): `iterations` Jacobi steps of
//!    `n_f ← normalize(w_ff·n_f + Σ_g w_fg·n_g)` over a compact CSR face adjacency built once
//!    ([`FaceAdjacency`]): edge- or vertex-adjacent faces ([`Neighborhood`]), weighted uniformly, by
//!    area (the paper, MeshLab) or scale-dependently ([`Weighting`], §4.1). Rows are read in a fixed
//!    order from the previous iteration's buffer, so the output is bit-identical at any thread count.
//! 3. **Enhancement** `n_E = normalize(n + k·(n − n_L))` (§4 step 2) per face ([`enhance`]).
//! 4. **Crease-aware vertex normals** (end of §4): around each welded vertex, faces are grouped into
//!    smooth fans (joined across manifold edges whose dihedral angle is within the crease angle); one
//!    output vertex per fan ([`VertexLayout`]), which is the fewest vertices that keep hard edges hard.
//!    Both the original and the enhanced face normals are averaged over the same fans, so a viewer can
//!    toggle between them on one index buffer (the paper's toggle). Because grouping runs on welded
//!    vertices, unwelded CAD exports are smoothed across their patch seams.
//!
//! [`compute_normals`] runs all of it on one mesh and returns a [`MeshNormals`] (layout, `NORMAL`,
//! enhanced normals, per-face `n`/`n_L`/`n_E`, report) and diagnostics.
//!
//! # Defaults and their effect
//!
//! | option | default | effect |
//! |---|---|---|
//! | [`EnhanceOptions::strength`] `k` | [`DEFAULT_STRENGTH`] = 0.5 | paper: 0.2–0.7. Higher: more contrast at features, and flat faces next to features look slightly concave (§5.1). |
//! | [`EnhanceOptions::iterations`] | [`DEFAULT_ITERATIONS`] = 20 | paper: 10–30. More: a wider shaded band along features; small features fade out of `n_L` and lose their own contrast (Fig. 6). |
//! | [`EnhanceOptions::neighborhood`] | [`Neighborhood::Edge`] | as the paper and MeshLab; `Vertex` reaches about twice as far per iteration at several times the cost. |
//! | [`EnhanceOptions::weighting`] | [`Weighting::ScaleDependent`] | area weights, damped by `(h/d)²` for neighbours farther than `h` = 2× the median centroid distance; equals area weighting on uniform meshes. |
//! | [`CreaseOptions::crease_angle_deg`] | [`DEFAULT_CREASE_ANGLE_DEG`] = 30 | edges with a larger dihedral angle stay hard. |
//! | [`CreaseOptions::weighting`] | [`VertexWeighting::Angle`] | corner-angle weights: a fan of slivers does not outvote one large triangle. |
//! | [`CreaseOptions::keep_input_seams`] | `false` | `true` never merges different input vertices (keeps UV seams). |
//!
//! # Uneven tessellation (§4.1): scale-dependent weights by default, refinement opt-in
//!
//! The paper's filter assumes small, uniform triangles; it offers two remedies: split faces larger than
//! a threshold, or weight by size. `examples/tessellation_survey.rs` measures both on the CAD models of
//! `../shared/models` (its figures, with the command, are in `bench/normals/README.md`):
//!
//! * Most CAD exports are uneven: a large share of their surface lies in triangles whose longest edge
//!   exceeds 4× the median edge, and neighbouring faces differ in area by orders of magnitude. The
//!   remeshed research sets (fandisk, block, joint, partLp, casting, ...) are uniform.
//! * Refining to edges ≤ 4× the median edge ([`refine`]) multiplies the triangles of such models, on
//!   some by far more than ten: the paper's own warning ("even by a factor of ten or more", §4.2).
//!   Every triangle is carried into the baked file.
//! * Taking refine-then-filter (area weights) as the reference, the filter on the *unrefined* mesh
//!   lands closest to it with scale-dependent weights (`h` = 2× median, the best of the factors
//!   tried), closer than with area or uniform weights, while staying identical to area weights on the
//!   uniform models.
//!
//! So the default is [`Weighting::ScaleDependent`] with no refinement; [`refine`] stays available,
//! opt-in and bounded ([`RefineOptions::max_added_ratio`], default: at most doubling), and its
//! [`RefineReport`] says how many triangles it added and whether the budget stopped it.
//!
//! # Against MeshLab
//!
//! MeshLab's "UnSharp Mask Normals" (`FP_UNSHARP_NORMAL`; pymeshlab
//! `apply_normal_unsharp_mask_per_vertex`) is the same paper with edge neighbours and area weights; with
//! [`Weighting::Area`] our per-face `n_E` agree with MeshLab's to a small fraction of a degree on
//! average (`bench/normals/compare_meshlab.py`, figures in `bench/normals/README.md`). Remaining
//! differences, all deliberate: MeshLab does not weld (the dragon
//! has 2,100 duplicate positions, which we weld), counts a face itself once more across each boundary
//! edge, and takes one neighbour across a non-manifold edge (we take none: such an edge bounds the
//! filter, see [`Neighborhood::Edge`]); it leaves `n_E` unnormalised
//! (same direction).
//!
//! # Limits
//!
//! * One iteration moves the signal by at most one face: in regions finer than the median the filter
//!   reaches less far than `h·√iterations`, whatever the weighting.
//! * Non-manifold edges are always sharp. A chain of several degenerate faces around one vertex is not
//!   bridged (a single sliver is). Vertices touched only by degenerate faces get `+Z` (reported).
//! * [`refine`] returns a welded mesh without normals or UVs, and groups with widened vertex ranges.
//! * Normals are iterated in f32 (4 to ~13 terms per sum); face normals and angles are computed in f64.
//! * §4.2 (resampling enhanced normals of a refined mesh into a normal map) is not implemented.

mod adjacency;
mod enhance;
mod face;
mod tessellation;
mod vertex;

pub use adjacency::{FaceAdjacency, Neighborhood, SCALE_REFERENCE_FACTOR, Weighting};
pub use enhance::{
    DEFAULT_ITERATIONS, DEFAULT_STRENGTH, EnhanceOptions, EnhancedFaces, enhance, enhance_faces, low_pass,
};
pub use face::FaceGeometry;
pub use tessellation::{
    DEFAULT_MAX_ADDED_RATIO, DEFAULT_MAX_EDGE_FACTOR, DEFAULT_MAX_PASSES, RefineOptions, RefineReport, Refined,
    TessellationStats, refine,
};
pub use vertex::{CreaseOptions, DEFAULT_CREASE_ANGLE_DEG, VertexLayout, VertexWeighting};

use drafter_core::{Diagnostic, DiagnosticKind, Diagnostics, Mesh, Topology};
use glam::Vec3;
use serde::Serialize;

/// Options of the normals stage: the enhancement filter and the crease-aware layout.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct NormalsOptions {
    /// The enhancement filter (strength, iterations, neighbourhood, weighting).
    pub enhance: EnhanceOptions,
    /// Crease angle, vertex weighting and seam policy of the vertex layout.
    pub crease: CreaseOptions,
}

/// What the stage did, for the bake report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct NormalsReport {
    pub faces: usize,
    /// Faces with zero area or collapsed by welding: no normal, no vote.
    pub degenerate_faces: usize,
    pub input_vertices: usize,
    /// Welded vertices referenced by a face.
    pub welded_vertices: usize,
    /// Vertices of the output layout.
    pub output_vertices: usize,
    /// Output vertices beyond one per referenced welded vertex (the crease splits).
    pub split_vertices: usize,
    /// Output vertices whose faces give no normal at all; they got `+Z`.
    pub fallback_normals: usize,
    /// Edges with three or more faces (treated as sharp).
    pub nonmanifold_edges: usize,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Face-iterations of the low-pass filter (faces × iterations).
    pub face_iterations: u64,
}

/// The stage's result for one mesh.
#[derive(Clone, Debug, Default)]
pub struct MeshNormals {
    /// The output vertex/index layout (a remap of the input vertices and new triangles).
    pub layout: VertexLayout,
    /// Crease-aware vertex normals of the original shading, one per output vertex: the `NORMAL`.
    pub normals: Vec<Vec3>,
    /// Crease-aware vertex normals of the enhanced face normals, one per output vertex, grouped by the
    /// same fans as `normals` so the two can be toggled on one index buffer.
    pub enhanced_normals: Vec<Vec3>,
    /// Per-face normals `n`, `n_L`, `n_E`.
    pub faces: EnhancedFaces,
    pub report: NormalsReport,
}

/// The normals stage: enhances the face normals of `mesh` and builds the crease-aware layout with both
/// the original and the enhanced vertex normals. `topology` must have been built from `mesh`.
/// Recoverable problems (degenerate faces, normals that fell back to `+Z`) are returned as diagnostics.
pub fn compute_normals(mesh: &Mesh, topology: &Topology, options: &NormalsOptions) -> (MeshNormals, Vec<Diagnostic>) {
    // The filter and the layout need only the face geometry; run side by side, each fills the other's
    // serial stretches (the filter's sweep order, the layout's assembly).
    let geometry = FaceGeometry::compute(topology);
    let (layout, filtered) = rayon::join(
        || VertexLayout::build(mesh, topology, &geometry, &options.crease),
        || enhance::filter(topology, &geometry, &options.enhance),
    );
    let faces = filtered.with_geometry(geometry, &options.enhance);
    let (normals, fallback_original) = layout.vertex_normals(&faces.geometry.normals);
    let (enhanced_normals, _) = layout.vertex_normals(&faces.enhanced);
    let welded_vertices = topology.referenced_vertex_count();
    let report = NormalsReport {
        faces: mesh.triangles.len(),
        degenerate_faces: faces.geometry.degenerate_count(),
        input_vertices: mesh.positions.len(),
        welded_vertices,
        output_vertices: layout.vertex_count(),
        split_vertices: layout.vertex_count().saturating_sub(welded_vertices),
        fallback_normals: fallback_original,
        nonmanifold_edges: topology.nonmanifold_edge_count(),
        boundary_edges: topology.boundary_edge_count(),
        face_iterations: faces.face_iterations,
    };
    let mut diagnostics = Diagnostics::new();
    diagnostics.push(DiagnosticKind::DegenerateTriangle, report.degenerate_faces, || {
        let first = (0..faces.geometry.len()).find(|&f| faces.geometry.is_degenerate(f)).unwrap_or(0);
        format!("mesh '{}' triangle {first} (zero area: no normal of its own)", mesh.name)
    });
    diagnostics.push(DiagnosticKind::FallbackNormal, report.fallback_normals, || {
        format!("mesh '{}' (touched only by degenerate triangles: normal +Z)", mesh.name)
    });
    (MeshNormals { layout, normals, enhanced_normals, faces, report }, diagnostics.into_vec())
}
