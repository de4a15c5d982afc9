//! Axis-aligned and oriented bounding boxes of a part's world-space points.
//!
//! # Methods ([`ObbMethod`])
//! * `Aabb` — the world axis-aligned box.
//! * `Pca` — axes are the eigenvectors of the covariance of *all points* (Jolliffe; the classic
//!   "covariance box"). O(n), no hull. Sensitive to point density (a densely tessellated fillet pulls the
//!   axes) and undefined on symmetric shapes; there the degenerate eigenspace is snapped to the world
//!   axes (see below), so a cube or an upright cylinder still gets a deterministic box.
//! * `Hull` — axes are the eigenvectors of the covariance of the *convex-hull surface*, each triangle
//!   weighted by its area (Gottschalk 2000, PhD thesis, §3 "OBB fitting", the continuous-surface
//!   covariance `C = Σ A_k/12 (9 m_k m_kᵀ + p pᵀ + q qᵀ + r rᵀ) / A − μ μᵀ`). Independent of tessellation
//!   density, still not minimal.
//! * `Default` — fast and tight: the hull, then the exact minimum-area rectangle (rotating calipers) under
//!   the [`ObbOptions::default_face_normals`] largest hull faces (coplanar triangles merged) and under
//!   the PCA and hull-covariance axes, then a short pattern search on SO(3) from the two best (below).
//! * `Optimal` — the minimum-volume box within the limits stated below.
//!
//! # Optimal: what is enumerated and what is guaranteed
//! O'Rourke (1985, "Finding minimal enclosing boxes", Int. J. Comput. Inf. Sci. 14) proved that a
//! minimum-volume box of a convex polyhedron has two adjacent faces each flush with a hull edge. The
//! remaining one-parameter family is pinned by a third contact; Jylänki (2015, "An exact algorithm for
//! finding minimum oriented bounding boxes") enumerates the configurations where it is pinned and
//! conjectures, with computer search finding no counter-example, that the minimum is always one of
//! them. `Optimal` enumerates each exactly (in f64), on the hull (see `hull`):
//! 1. **a box face flush with a hull face**: every distinct hull face normal `n` (coplanar triangles
//!    merged), completed by the exact minimum-area rectangle of the hull projected along `n` (rotating
//!    calipers over the silhouette). This is what trimesh's `bounds.oriented_bounds` does, so `Optimal` is
//!    never larger than trimesh's box (up to rounding);
//! 2. **two hull edges flush with opposite box faces**: every antipodal pair of crease edges (edge `i`
//!    supports the hull in direction `n = e_i × e_j`, edge `j` in `−n`), completed as in 1;
//! 3. **three hull edges flush with three mutually adjacent box faces**: every triple of crease edges
//!    whose Gauss arcs can hold three perpendicular normals, solved in closed form
//!    (`A cos 2t + B sin 2t = C`, at most two boxes per triple); a triple is skipped unsolved when lower
//!    bounds of its three widths already exceed the best box of cases 1–2.
//!
//! The PCA and hull-covariance boxes are candidates too, so `Optimal ≤ Pca` and `Optimal ≤ Hull` always.
//! The best four candidates are then polished by a pattern search on SO(3) down to 1e-8 rad, and the
//! leaders re-measured over all hull vertices.
//!
//! So: when [`ObbStats::face_search`] and [`ObbStats::edge_search`] are both [`Coverage::Exhaustive`],
//! the box is the global minimum under Jylänki's conjecture (O'Rourke's theorem alone guarantees a
//! local minimum; the enumeration covers every pinned configuration); when `face_search` is exhaustive
//! it is never larger than the best face-flush box. Both searches are bounded by
//! [`ObbOptions::optimal_budget`]: a hull with more faces than the budget affords is searched over its
//! largest faces only, and when the edge configurations would take more steps than the budget they are
//! skipped ([`Coverage::OverBudget`]) and the refinement from the best face-flush boxes stands in. On the
//! parts of ../shared/models the edge configurations improve on faces + refinement by a tiny fraction of
//! the volume, and few parts hit the budget, so it is a cheap trade. Edges between coplanar hull
//! triangles are not creases and never enter cases 2–3 (such contacts are face contacts, case 1).
//! Against trimesh's `oriented_bounds` on the same points it is never larger, and smaller on many parts
//! (docs/bench.md#oriented-boxes-over-the-corpus).
//!
//! # Default
//! The same machinery with fixed small effort: the PCA and hull-covariance frames, the exact rectangle
//! under their six axes and under the [`ObbOptions::default_face_normals`] largest distinct hull faces,
//! then the pattern search (from 0.05 rad down to 2e-5 rad) from the two best. Its volume against
//! `Optimal` over the parts of ../shared/models is in docs/bench.md#oriented-boxes-over-the-corpus;
//! `examples/obb_bench.rs` times both.
//!
//! DiTO (Larsson & Källberg 2011, "Fast computation of tight-fitting oriented bounding boxes") was not
//! needed: its strength is speed without a hull, but the hull is needed anyway for `Default`'s
//! exact rectangles, and on these parts `Default` is already within a fraction of a percent of
//! `Optimal` at a small part of its cost.
//!
//! # Precision, degenerate input, determinism
//! * All computation is in f64 relative to the centre of the points' axis-aligned box, so a part far from
//!   the origin (10⁶) loses nothing; the hull uses an exact orientation predicate.
//! * The final extents of every method are taken over **all** input points (not only hull vertices), so
//!   every box contains every point up to the rounding of one dot product.
//! * Degenerate input gives a valid box: coincident points → zero extents and world axes; collinear →
//!   the segment's direction first, zero extent across; coplanar → the exact minimum-area rectangle in
//!   the plane (for `Default` and `Optimal`) with a zero or `ε` extent along the normal. No NaN ever.
//!   Empty input and non-finite coordinates are errors ([`BoundsError`]); filter NaN points out first.
//! * Canonical form, so that equal inputs give identical boxes and symmetric shapes give a stable one:
//!   axes are sorted by half extent, longest first (the projector uses `axes[0]`); axes within 1e-9 of
//!   ties are ordered by the world axis they are closest to; each of the first two axes points along the
//!   positive direction of its largest world component; the third is their cross product (right-handed).
//!   Frames within 1e-9 rad of the world axes snap to them exactly. No randomness anywhere; parallel loops
//!   reduce by `(volume, index)`, so results do not depend on the thread count.

use drafter_core::Aabb;
pub use drafter_core::ObbMethod;
use glam::{DMat3, DMat4, DVec3, Vec3};
use serde::{Deserialize, Serialize};

use crate::BoundsError;
use crate::hull::{DEFAULT_HULL_TOLERANCE, HullDimension, LocalHull, LocalPoints};
use crate::linalg::{canonical_sign, dominant_component, frame_from_direction, orthonormalize, symmetric_eigen};
use crate::search::{self, Candidate, Frame};

/// Default of [`ObbOptions::method`].
pub const DEFAULT_OBB_METHOD: ObbMethod = ObbMethod::Default;
/// Default of [`ObbOptions::default_face_normals`].
pub const DEFAULT_FACE_NORMALS: usize = 48;
/// `Default` runs the exhaustive `Optimal` search on hulls with at most this many triangles.
pub const DEFAULT_EXHAUSTIVE_HULL_FACES: usize = 64;
/// Default of [`ObbOptions::optimal_budget`].
pub const DEFAULT_OPTIMAL_BUDGET: u64 = 100_000_000;

/// Options of [`oriented_box`]. serde reads `method`, the choice a user makes (a bake config's `[obb]`
/// table, any other key refused); the other fields are tuning that reading leaves at its default, and
/// all are written.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ObbOptions {
    /// Which method orients the box. Default [`DEFAULT_OBB_METHOD`] (`default`).
    pub method: ObbMethod,
    /// Relative hull tolerance (see [`crate::HullOptions::tolerance`]). Default
    /// [`DEFAULT_HULL_TOLERANCE`] (1e-10); range [0, 1e-3].
    #[serde(skip_deserializing)]
    pub hull_tolerance: f64,
    /// `Default` method: how many of the largest distinct hull faces are tried as box face normals.
    /// Default [`DEFAULT_FACE_NORMALS`] (48); range 1..=100 000 (more = slower and tighter; `Optimal`
    /// tries all).
    #[serde(skip_deserializing)]
    pub default_face_normals: usize,
    /// `Optimal` method: the most elementary steps (a few nanoseconds each) that each of its searches
    /// may take: face normals × hull triangles for the face search (beyond it only the largest faces are
    /// tried), edge pairs and edge-triple candidates for the edge searches (beyond it they are skipped).
    /// See [`ObbStats::face_search`] and [`ObbStats::edge_search`]. Default [`DEFAULT_OPTIMAL_BUDGET`]
    /// (1e8: at most about half a second per search on one core); 0 keeps only the refinement and the
    /// [`DEFAULT_FACE_NORMALS`] largest faces.
    #[serde(skip_deserializing)]
    pub optimal_budget: u64,
}

impl Default for ObbOptions {
    fn default() -> Self {
        Self {
            method: DEFAULT_OBB_METHOD,
            hull_tolerance: DEFAULT_HULL_TOLERANCE,
            default_face_normals: DEFAULT_FACE_NORMALS,
            optimal_budget: DEFAULT_OPTIMAL_BUDGET,
        }
    }
}

impl ObbOptions {
    /// The default options with another method.
    pub fn with_method(method: ObbMethod) -> Self {
        Self { method, ..Self::default() }
    }
}

/// An oriented box: `center + Σ_k s_k · half_extents[k] · axes[k]` for `s_k ∈ [−1, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Obb {
    /// Centre in world space.
    pub center: DVec3,
    /// Orthonormal, right-handed axes, sorted by half extent (longest first).
    pub axes: [DVec3; 3],
    /// Half the box's size along each axis (≥ 0; zero across flat, linear or point-like input).
    pub half_extents: DVec3,
    /// `8 · hx · hy · hz`.
    pub volume: f64,
    /// The method that oriented the box.
    pub method: ObbMethod,
}

impl Obb {
    /// Whether `p` is inside the box, allowing `eps` (world units) outside each face.
    pub fn contains(&self, p: DVec3, eps: f64) -> bool {
        let d = p - self.center;
        (0..3).all(|k| self.axes[k].dot(d).abs() <= self.half_extents[k] + eps)
    }

    /// The eight corners (bit k of the index selects the sign along `axes[k]`).
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            let s = |k: usize| if i >> k & 1 == 1 { 1.0 } else { -1.0 };
            self.center + (0..3).map(|k| self.axes[k] * (s(k) * self.half_extents[k])).sum::<DVec3>()
        })
    }

    /// Maps the unit cube [−1, 1]³ onto the box (columns: scaled axes, then the centre).
    pub fn world_from_unit_cube(&self) -> DMat4 {
        DMat4::from_cols(
            (self.axes[0] * self.half_extents.x).extend(0.0),
            (self.axes[1] * self.half_extents.y).extend(0.0),
            (self.axes[2] * self.half_extents.z).extend(0.0),
            self.center.extend(1.0),
        )
    }

    /// Surface area of the box.
    pub fn surface_area(&self) -> f64 {
        let h = self.half_extents;
        8.0 * (h.x * h.y + h.y * h.z + h.z * h.x)
    }
}

/// Whether a search of `Optimal` covered every configuration of its kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// Not part of the method (or the hull is not a solid).
    NotRun,
    /// Every configuration was solved.
    Exhaustive,
    /// The hull was too large for [`ObbOptions::optimal_budget`]: only part was searched (the largest
    /// faces) or none (edges), and refinement stood in.
    OverBudget,
}

/// What a box fit looked at, for benchmarks and reports.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObbStats {
    /// Points given.
    pub input_points: usize,
    /// Hull vertices (0 for `Aabb` and `Pca`, which need no hull).
    pub hull_vertices: usize,
    /// Hull triangles (0 unless the hull is a solid).
    pub hull_triangles: usize,
    /// The hull's dimension (`None` for `Aabb` and `Pca`).
    pub hull_dimension: Option<HullDimension>,
    /// Face normals, antipodal edge pairs and PCA/covariance axes tried with the exact rectangle.
    pub normals_tried: usize,
    /// Valid three-edge configurations evaluated.
    pub edge_triples: u64,
    /// `Optimal`: whether every distinct hull face normal was tried (case 1).
    pub face_search: Coverage,
    /// `Optimal`: whether every antipodal edge pair and edge triple was solved (cases 2 and 3).
    pub edge_search: Coverage,
}

/// The axis-aligned box of `points` ([`Aabb::EMPTY`] for no points; non-finite points are skipped).
pub fn aabb(points: &[DVec3]) -> Aabb {
    let mut b = Aabb::EMPTY;
    for p in points.iter().filter(|p| p.is_finite()) {
        b.extend(*p);
    }
    b
}

/// The oriented box of `points` (world space) by `options.method`.
pub fn oriented_box(points: &[DVec3], options: &ObbOptions) -> Result<Obb, BoundsError> {
    oriented_box_with_stats(points, options).map(|(obb, _)| obb)
}

/// [`oriented_box`] for f32 points (converted exactly to f64 first).
pub fn oriented_box_f32(points: &[Vec3], options: &ObbOptions) -> Result<Obb, BoundsError> {
    oriented_box(&points.iter().map(|p| p.as_dvec3()).collect::<Vec<_>>(), options)
}

/// The box of `points` along `axes` (orthonormalised, snapped to the world axes and ordered as
/// every method's box is), recording `method`: where the orientation was found on other points,
/// such as one mesh's for each of its instances ([`Obb`]'s extents and centre always come from
/// `points` themselves, so the box holds them whatever `axes` are).
pub fn box_with_axes(points: &[DVec3], axes: [DVec3; 3], method: ObbMethod) -> Result<Obb, BoundsError> {
    let local = LocalPoints::new(points)?;
    Ok(finish(&local, axes, method))
}

/// Object-space positions moved to world space in f64 (`world_from_object · p`).
pub fn world_points(positions_in_object: &[Vec3], world_from_object: &DMat4) -> Vec<DVec3> {
    positions_in_object.iter().map(|p| world_from_object.transform_point3(p.as_dvec3())).collect()
}

/// [`oriented_box`] plus what the fit looked at.
pub fn oriented_box_with_stats(points: &[DVec3], options: &ObbOptions) -> Result<(Obb, ObbStats), BoundsError> {
    let local = LocalPoints::new(points)?;
    let method = options.method;
    let mut stats = ObbStats {
        input_points: points.len(),
        hull_vertices: 0,
        hull_triangles: 0,
        hull_dimension: None,
        normals_tried: 0,
        edge_triples: 0,
        face_search: Coverage::NotRun,
        edge_search: Coverage::NotRun,
    };
    match method {
        ObbMethod::Aabb => return Ok((finish(&local, [DVec3::X, DVec3::Y, DVec3::Z], method), stats)),
        ObbMethod::Pca => return Ok((finish(&local, pca_axes(&local.points), method), stats)),
        _ => {}
    }
    let hull = LocalHull::build(&local, options.hull_tolerance);
    stats.hull_vertices = hull.vertices.len();
    stats.hull_triangles = hull.triangles.len();
    stats.hull_dimension = Some(hull.dimension);
    let axes = match hull.dimension {
        HullDimension::Point => [DVec3::X, DVec3::Y, DVec3::Z],
        HullDimension::Segment => {
            let d = (hull.vertices[hull.vertices.len() - 1] - hull.vertices[0]).normalize_or(DVec3::X);
            frame_from_direction(d)
        }
        HullDimension::Polygon => match method {
            ObbMethod::Hull => hull_covariance_axes(&hull),
            _ => {
                stats.normals_tried = 1;
                let mut scratch = Vec::new();
                let all: Vec<u32> = (0..hull.vertices.len() as u32).collect();
                search::fit_with_normal(&hull.vertices, &all, hull.polygon_normal, &mut scratch).axes
            }
        },
        HullDimension::Solid => match method {
            ObbMethod::Hull => hull_covariance_axes(&hull),
            // Tiny hulls: the exhaustive search costs about what the heuristic does (a few hundred
            // microseconds at most) and catches edge-flush minima the face heuristic misses, e.g.
            // on a tetrahedron.
            ObbMethod::Default if hull.triangles.len() <= DEFAULT_EXHAUSTIVE_HULL_FACES => {
                optimal_axes(&local, &hull, options, &mut stats)
            }
            ObbMethod::Default => default_axes(&local, &hull, options, &mut stats),
            _ => optimal_axes(&local, &hull, options, &mut stats),
        },
    };
    Ok((finish(&local, axes, method), stats))
}

/// PCA and hull-covariance frames, and the candidates they seed (the frames themselves and the exact
/// rectangle under each of their axes).
fn covariance_candidates(local: &LocalPoints, hull: &LocalHull) -> (Vec<Frame>, Vec<DVec3>) {
    let pca = pca_axes(&local.points);
    let cov = hull_covariance_axes(hull);
    let mut normals = Vec::with_capacity(6);
    normals.extend_from_slice(&pca);
    normals.extend_from_slice(&cov);
    (vec![pca, cov], normals)
}

fn default_axes(local: &LocalPoints, hull: &LocalHull, options: &ObbOptions, stats: &mut ObbStats) -> Frame {
    let verts = &hull.vertices;
    let edges = search::mesh_edges(&hull.triangles);
    let (_, areas) = search::triangle_normals(verts, &hull.triangles);
    let tri_normals = search::resolve_slivers(verts, &hull.triangles, &edges, hull.eps);
    let faces = search::distinct_normals(&tri_normals, &areas);
    let (frames, mut normals) = covariance_candidates(local, hull);
    normals.extend(faces.iter().take(options.default_face_normals.max(1)).map(|(n, _)| *n));
    let normals = search::dedupe_directions(&normals);
    stats.normals_tried = normals.len();
    let mut candidates: Vec<Candidate> = frames.iter().map(|f| Candidate::of(verts, *f)).collect();
    let silhouettes = search::Silhouettes::new(verts, &tri_normals, &edges);
    candidates.extend(search::fit_normals(verts, Some(&silhouettes), &normals));
    let graph = search::HullGraph::new(verts, &hull.triangles, &tri_normals);
    let refined: Vec<Candidate> = search::best_distinct(&candidates, 2)
        .into_iter()
        .map(|c| search::refine(&graph, c, 0.05, 2e-5, 1500))
        .collect();
    candidates.extend(refined);
    pick_final(local, verts, &candidates, &frames)
}

fn optimal_axes(local: &LocalPoints, hull: &LocalHull, options: &ObbOptions, stats: &mut ObbStats) -> Frame {
    let verts = &hull.vertices;
    let edges = search::mesh_edges(&hull.triangles);
    let (_, areas) = search::triangle_normals(verts, &hull.triangles);
    let tri_normals = search::resolve_slivers(verts, &hull.triangles, &edges, hull.eps);
    let faces = search::distinct_normals(&tri_normals, &areas);
    let budget = options.optimal_budget;
    let (frames, mut normals) = covariance_candidates(local, hull);
    // Each face normal costs a silhouette pass over the triangles.
    let affordable = (budget / hull.triangles.len().max(1) as u64).max(DEFAULT_FACE_NORMALS as u64) as usize;
    stats.face_search = if faces.len() <= affordable { Coverage::Exhaustive } else { Coverage::OverBudget };
    normals.extend(faces.iter().take(affordable).map(|(n, _)| *n));
    let silhouettes = search::Silhouettes::new(verts, &tri_normals, &edges);
    let mut arcs = search::edge_arcs(verts, &edges, &tri_normals);
    let graph = search::HullGraph::new(verts, &hull.triangles, &tri_normals);
    search::find_opposites(&graph, &mut arcs);
    // Cases 1 and 2 first: their best volume prunes the three-edge search.
    let pairs = search::edge_pairs(&arcs, budget);
    if let Some(pairs) = &pairs {
        normals.extend_from_slice(&pairs.antipodal);
    }
    let normals = search::dedupe_directions(&normals);
    stats.normals_tried = normals.len();
    let mut candidates: Vec<Candidate> = frames.iter().map(|f| Candidate::of(verts, *f)).collect();
    candidates.extend(search::fit_normals(verts, Some(&silhouettes), &normals));
    let limit = search::best_index(&candidates).map_or(f64::INFINITY, |i| candidates[i].volume);
    // The minimum width is attained at a face normal or an antipodal edge pair (both enumerated when
    // the pair scan ran), so it bounds every width from below.
    let complete = pairs.is_some() && stats.face_search == Coverage::Exhaustive;
    let min_width = if complete { search::min_width(verts, &normals) * (1.0 - 1e-9) } else { 0.0 };
    let triples = match pairs.as_ref().and_then(|p| p.partners.as_ref()) {
        Some(partners) => search::edge_triples(&graph, &arcs, partners, budget, limit, min_width),
        None => search::TripleSearch::default(),
    };
    stats.edge_search = if pairs.is_some() && triples.complete { Coverage::Exhaustive } else { Coverage::OverBudget };
    stats.edge_triples = triples.evaluated;
    if let Some((axes, volume)) = triples.best {
        candidates.push(Candidate { axes, volume });
    }
    let refined: Vec<Candidate> = search::best_distinct(&candidates, 4)
        .into_iter()
        .map(|c| search::refine(&graph, c, 0.02, 1e-8, 20_000))
        .collect();
    candidates.extend(refined);
    pick_final(local, verts, &candidates, &frames)
}

/// The best candidate by hull volume, then compared with the covariance frames by the volume over all
/// points (so `Default`/`Optimal` never lose to `Pca`/`Hull` through the hull tolerance).
fn pick_final(local: &LocalPoints, verts: &[DVec3], candidates: &[Candidate], frames: &[Frame]) -> Frame {
    // Re-measure the leaders by full scans: walk-based volumes are estimates.
    let leaders: Vec<Candidate> = search::best_distinct(candidates, 8)
        .into_iter()
        .map(|c| Candidate::of(verts, orthonormalize(c.axes)))
        .collect();
    let best = search::best_index(&leaders).map(|i| leaders[i].axes).unwrap_or([DVec3::X, DVec3::Y, DVec3::Z]);
    let mut choice = (snap_to_world(orthonormalize(best)), f64::INFINITY);
    choice.1 = search::frame_volume(&local.points, &choice.0);
    for f in frames {
        let f = snap_to_world(orthonormalize(*f));
        let v = search::frame_volume(&local.points, &f);
        if v < choice.1 {
            choice = (f, v);
        }
    }
    choice.0
}

/// Covariance of all points: eigenvectors, with degenerate eigenspaces snapped to the world axes.
pub(crate) fn pca_axes(points: &[DVec3]) -> Frame {
    // Sequential sums: the same rounding for any thread count.
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec3>() / n;
    let mut c = [0.0f64; 6];
    for p in points {
        let d = *p - mean;
        c[0] += d.x * d.x;
        c[1] += d.x * d.y;
        c[2] += d.x * d.z;
        c[3] += d.y * d.y;
        c[4] += d.y * d.z;
        c[5] += d.z * d.z;
    }
    let m = DMat3::from_cols_array(&[c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5]]) * (1.0 / n);
    eigen_frame(m)
}

/// Area-weighted covariance of the hull surface (Gottschalk 2000). Falls back to the PCA of the hull
/// vertices when the surface has no area.
pub(crate) fn hull_covariance_axes(hull: &LocalHull) -> Frame {
    let tris = hull.surface_triangles();
    let mut area_sum = 0.0;
    let mut mean = DVec3::ZERO;
    let mut second = DMat3::ZERO;
    for [p, q, r] in &tris {
        let area = 0.5 * (*q - *p).cross(*r - *p).length();
        if area == 0.0 {
            continue;
        }
        let m = (*p + *q + *r) / 3.0;
        area_sum += area;
        mean += m * area;
        let outer = |a: DVec3| DMat3::from_cols(a * a.x, a * a.y, a * a.z);
        second += (outer(m) * 9.0 + outer(*p) + outer(*q) + outer(*r)) * (area / 12.0);
    }
    if area_sum <= 0.0 {
        return pca_axes(&hull.vertices);
    }
    let mean = mean / area_sum;
    let cov = second * (1.0 / area_sum) - DMat3::from_cols(mean * mean.x, mean * mean.y, mean * mean.z);
    eigen_frame(cov)
}

/// Eigenvectors of a covariance matrix as a frame; eigenvalues equal to 1e-8 (relative) leave the
/// eigenvectors undefined, so that eigenspace is replaced by world-aligned directions.
fn eigen_frame(m: DMat3) -> Frame {
    let (values, vectors) = symmetric_eigen(m);
    let scale = values[0].abs().max(f64::MIN_POSITIVE);
    let tie = |a: f64, b: f64| (a - b).abs() <= 1e-8 * scale;
    if !values.iter().all(|v| v.is_finite()) || tie(values[0], values[2]) {
        return [DVec3::X, DVec3::Y, DVec3::Z];
    }
    if tie(values[0], values[1]) {
        // Only the smallest is distinct: its axis, and world-aligned directions in its plane.
        let w = vectors[2];
        let [w, u, v] = frame_from_direction(w);
        return [u, v, w];
    }
    if tie(values[1], values[2]) {
        return frame_from_direction(vectors[0]);
    }
    vectors
}

/// Snaps a frame within 1e-9 rad of the (signed, permuted) world axes to them exactly.
fn snap_to_world(axes: Frame) -> Frame {
    let mut out = axes;
    let mut used = [false; 3];
    for k in 0..3 {
        let c = dominant_component(axes[k]);
        let off_axis = (0..3).filter(|&i| i != c).map(|i| axes[k][i] * axes[k][i]).sum::<f64>().sqrt();
        if used[c] || off_axis > 1e-9 {
            return axes;
        }
        used[c] = true;
        let mut e = DVec3::ZERO;
        e[c] = axes[k][c].signum();
        out[k] = e;
    }
    if out[0].cross(out[1]).dot(out[2]) > 0.0 { out } else { axes }
}

/// Final box: extents over all points along `axes`, then the canonical order and signs.
fn finish(local: &LocalPoints, axes: Frame, method: ObbMethod) -> Obb {
    let axes = snap_to_world(orthonormalize(axes));
    let (lo, hi) = search::frame_extents(&local.points, &axes);
    let half = (hi - lo) * 0.5;
    let mid = (hi + lo) * 0.5;
    let center = local.origin + axes[0] * mid.x + axes[1] * mid.y + axes[2] * mid.z;
    // Order: half extent descending; near-ties by the world axis each is closest to.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| half[b].total_cmp(&half[a]).then(a.cmp(&b)));
    let tol = 1e-9 * half.max_element();
    let tie_key = |k: usize| (dominant_component(axes[k]), k);
    for (i, j) in [(0, 1), (1, 2), (0, 1)] {
        let (a, b) = (order[i], order[j]);
        if (half[a] - half[b]).abs() <= tol && tie_key(b) < tie_key(a) {
            order.swap(i, j);
        }
    }
    // `+ 0.0` turns −0.0 into +0.0, so that equal boxes serialise identically.
    let a0 = canonical_sign(axes[order[0]]) + DVec3::ZERO;
    let a1 = canonical_sign(axes[order[1]]) + DVec3::ZERO;
    let a2 = a0.cross(a1) + DVec3::ZERO;
    let half_extents = DVec3::new(half[order[0]], half[order[1]], half[order[2]]);
    Obb {
        center,
        axes: [a0, a1, a2],
        half_extents,
        volume: 8.0 * half_extents.x * half_extents.y * half_extents.z,
        method,
    }
}
