//! Measuring uneven tessellation, and the optional, bounded refinement of §4.1.
//!
//! The paper warns that the filter "works only if the starting mesh is rather densely and uniformly
//! tessellated" and offers two remedies: split faces larger than a threshold, or weight the averaging by
//! triangle size. [`TessellationStats::measure`] quantifies the problem; [`refine`] is the first remedy,
//! opt-in and capped by a triangle budget; `Weighting::ScaleDependent` is the second, and the default
//! (see the crate docs for the measurements on the CAD corpus behind that choice).

use drafter_core::{Mesh, Topology, Weld};
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

use crate::face::FACE_CHUNK;

/// Default of [`RefineOptions::max_edge_factor`]: split edges longer than 4× the median edge.
pub const DEFAULT_MAX_EDGE_FACTOR: f32 = 4.0;
/// Default of [`RefineOptions::max_added_ratio`]: add at most as many triangles as the mesh had.
pub const DEFAULT_MAX_ADDED_RATIO: f32 = 1.0;
/// Default of [`RefineOptions::max_passes`].
pub const DEFAULT_MAX_PASSES: u32 = 8;

/// How uneven a tessellation is. Percentiles are over non-degenerate faces (or interior manifold edges
/// for the neighbour ratio).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct TessellationStats {
    pub faces: usize,
    /// Median edge length (each face's three edges counted).
    pub median_edge_length: f32,
    /// Longest edge of the mesh over its median edge.
    pub max_edge_over_median: f32,
    /// Median and 99th percentile of each face's longest/shortest edge ratio (1 = equilateral-ish).
    pub aspect_p50: f32,
    pub aspect_p99: f32,
    /// Median and 99th percentile, over interior edges, of the larger/smaller area of the two faces:
    /// abrupt size changes are what make a per-face filter uneven.
    pub neighbor_area_ratio_p50: f32,
    pub neighbor_area_ratio_p99: f32,
    /// 99th over 1st percentile of face area.
    pub area_p99_over_p1: f32,
    /// Share of the surface area in faces whose longest edge exceeds 4× the median edge.
    pub long_face_area_share: f32,
}

impl TessellationStats {
    /// Measures `topology`'s faces over its welded positions.
    pub fn measure(topology: &Topology) -> TessellationStats {
        let positions = &topology.welded_positions;
        let per_face: Vec<Option<([f64; 3], f64)>> = topology
            .faces
            .par_iter()
            .zip(topology.face_degenerate.par_iter())
            .with_min_len(FACE_CHUNK)
            .map(|(&face, &degenerate)| {
                if degenerate {
                    return None;
                }
                let p = face.map(|v| positions[v as usize].as_dvec3());
                let lengths = [p[0].distance(p[1]), p[1].distance(p[2]), p[2].distance(p[0])];
                let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                Some((lengths, area))
            })
            .collect();
        let valid: Vec<([f64; 3], f64)> = per_face.iter().flatten().copied().collect();
        if valid.is_empty() {
            return TessellationStats { faces: topology.faces.len(), ..Default::default() };
        }
        let mut edges: Vec<f64> = valid.iter().flat_map(|(l, _)| *l).collect();
        let median_edge = percentile(&mut edges, 0.5);
        let max_edge = edges.iter().copied().fold(0.0, f64::max);
        let mut aspects: Vec<f64> = valid
            .iter()
            .map(|(l, _)| {
                let longest = l[0].max(l[1]).max(l[2]);
                let shortest = l[0].min(l[1]).min(l[2]);
                if shortest > 0.0 { longest / shortest } else { f64::INFINITY }
            })
            .collect();
        let mut areas: Vec<f64> = valid.iter().map(|(_, a)| *a).collect();
        let total_area: f64 = areas.iter().sum();
        let long_area: f64 =
            valid.iter().filter(|(l, _)| l[0].max(l[1]).max(l[2]) > 4.0 * median_edge).map(|(_, a)| *a).sum();
        let mut neighbor_ratios: Vec<f64> = (0..topology.edges.len())
            .filter_map(|e| match topology.faces_of_edge(e) {
                &[f, g] => {
                    let (a, b) = (per_face[f as usize]?.1, per_face[g as usize]?.1);
                    (a.min(b) > 0.0).then(|| a.max(b) / a.min(b))
                }
                _ => None,
            })
            .collect();
        let p1 = percentile(&mut areas, 0.01);
        let p99 = percentile(&mut areas, 0.99);
        TessellationStats {
            faces: topology.faces.len(),
            median_edge_length: median_edge as f32,
            max_edge_over_median: (max_edge / median_edge) as f32,
            aspect_p50: percentile(&mut aspects, 0.5) as f32,
            aspect_p99: percentile(&mut aspects, 0.99) as f32,
            neighbor_area_ratio_p50: percentile(&mut neighbor_ratios, 0.5) as f32,
            neighbor_area_ratio_p99: percentile(&mut neighbor_ratios, 0.99) as f32,
            area_p99_over_p1: if p1 > 0.0 { (p99 / p1) as f32 } else { f32::INFINITY },
            long_face_area_share: if total_area > 0.0 { (long_area / total_area) as f32 } else { 0.0 },
        }
    }
}

/// Nearest-rank percentile `q` in [0, 1] of `values` (reordered); 0 when empty.
fn percentile(values: &mut [f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let rank = ((values.len() - 1) as f64 * q).round() as usize;
    let (_, value, _) = values.select_nth_unstable_by(rank, f64::total_cmp);
    *value
}

/// Options of [`refine`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RefineOptions {
    /// Edges longer than this multiple of the mesh's median edge are split at their midpoint. Default
    /// [`DEFAULT_MAX_EDGE_FACTOR`]; range > 1 (smaller gives a more uniform mesh and more triangles).
    pub max_edge_factor: f32,
    /// Stop once this fraction of the input's triangle count has been added; the longest edges are
    /// split first. Default [`DEFAULT_MAX_ADDED_RATIO`] (at most doubling the mesh).
    pub max_added_ratio: f32,
    /// At most this many split passes (each pass at most halves the longest edges). Default
    /// [`DEFAULT_MAX_PASSES`].
    pub max_passes: u32,
}

impl Default for RefineOptions {
    fn default() -> Self {
        Self {
            max_edge_factor: DEFAULT_MAX_EDGE_FACTOR,
            max_added_ratio: DEFAULT_MAX_ADDED_RATIO,
            max_passes: DEFAULT_MAX_PASSES,
        }
    }
}

/// What refinement did and what it cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct RefineReport {
    pub triangles_before: usize,
    pub triangles_added: usize,
    pub vertices_added: usize,
    pub passes: u32,
    /// Edges still longer than the threshold when refinement stopped (budget or pass limit).
    pub long_edges_left: usize,
    /// True when the triangle budget stopped refinement early.
    pub budget_exhausted: bool,
}

/// A refined mesh and where each of its triangles came from.
#[derive(Clone, Debug, Default)]
pub struct Refined {
    /// The refined mesh over the welded positions of the input plus the new midpoints. Normals and UVs
    /// are not carried (recompute them from this mesh); groups are remapped to the children, and their
    /// vertex ranges widened to the whole (welded) mesh.
    pub mesh: Mesh,
    /// For each refined triangle, the input triangle it lies in. Children follow their parent's order.
    pub parent_face: Vec<u32>,
    pub report: RefineReport,
}

/// Splits edges longer than `max_edge_factor × median edge` at their midpoints, conformingly (a face
/// with 1, 2 or 3 split edges becomes 2, 3 or 4 triangles), pass after pass, longest edges first, until
/// none is too long, the budget of added triangles is spent, or `max_passes` is reached. Geometry is
/// unchanged: every new vertex lies on an input edge. Works on the welded mesh, so the result is welded.
pub fn refine(mesh: &Mesh, options: &RefineOptions) -> Refined {
    let topology = Topology::build(mesh, Weld::Exact);
    let stats = TessellationStats::measure(&topology);
    let threshold = stats.median_edge_length as f64 * options.max_edge_factor.max(1.0) as f64;
    let budget = (mesh.triangles.len() as f64 * options.max_added_ratio.max(0.0) as f64) as usize;
    let mut positions: Vec<Vec3> = topology.welded_positions.clone();
    let mut triangles: Vec<[u32; 3]> = topology.faces.clone();
    let mut parent_face: Vec<u32> = (0..triangles.len() as u32).collect();
    let mut report = RefineReport { triangles_before: mesh.triangles.len(), ..Default::default() };
    let mut current = topology;

    while threshold > 0.0 && report.passes < options.max_passes {
        let long: Vec<(f64, u32)> = current
            .edges
            .iter()
            .enumerate()
            .filter_map(|(e, &[a, b])| {
                let length = positions[a as usize].as_dvec3().distance(positions[b as usize].as_dvec3());
                (length > threshold).then_some((length, e as u32))
            })
            .collect();
        if long.is_empty() {
            break;
        }
        let mut order = long;
        // Longest first; ties by edge id so the choice is deterministic.
        order.sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
        let mut split = vec![u32::MAX; current.edges.len()];
        let mut added = 0usize;
        for &(_, e) in &order {
            let cost = current.edge_valence(e as usize) as usize;
            if report.triangles_added + added + cost > budget {
                report.budget_exhausted = true;
                break;
            }
            let [a, b] = current.edges[e as usize];
            let midpoint = ((positions[a as usize].as_dvec3() + positions[b as usize].as_dvec3()) * 0.5).as_vec3();
            split[e as usize] = positions.len() as u32;
            positions.push(midpoint);
            report.vertices_added += 1;
            added += cost;
        }
        if added == 0 {
            break;
        }
        let mut next_triangles = Vec::with_capacity(triangles.len() + added);
        let mut next_parent = Vec::with_capacity(triangles.len() + added);
        for (f, &tri) in triangles.iter().enumerate() {
            let edges = current.face_edges[f];
            let mids = edges.map(|e| if e == drafter_core::EDGE_NONE { u32::MAX } else { split[e as usize] });
            let before = next_triangles.len();
            split_triangle(tri, mids, &positions, &mut next_triangles);
            next_parent.extend(std::iter::repeat_n(parent_face[f], next_triangles.len() - before));
        }
        report.triangles_added += next_triangles.len() - triangles.len();
        triangles = next_triangles;
        parent_face = next_parent;
        report.passes += 1;
        current = Topology::from_triangles(&positions, &triangles, Weld::Exact);
        // A midpoint can land on an existing vertex (a T-junction of the input): continue on the
        // re-welded ids, which are the ones `current`'s edges use.
        if current.welded_positions.len() != positions.len() {
            report.vertices_added -= positions.len() - current.welded_positions.len();
            positions = current.welded_positions.clone();
            triangles = current.faces.clone();
        }
        if report.budget_exhausted {
            break;
        }
    }
    report.long_edges_left = current
        .edges
        .iter()
        .filter(|&&[a, b]| positions[a as usize].as_dvec3().distance(positions[b as usize].as_dvec3()) > threshold)
        .count();

    let groups = remap_groups(mesh, &parent_face, positions.len());
    Refined {
        mesh: Mesh { name: mesh.name.clone(), positions, triangles, normals: None, uvs: None, groups },
        parent_face,
        report,
    }
}

/// Appends the children of triangle `tri` whose edges `v0:v1, v1:v2, v2:v0` have midpoints `mids`
/// (`u32::MAX` = not split), keeping the winding.
fn split_triangle(tri: [u32; 3], mids: [u32; 3], positions: &[Vec3], out: &mut Vec<[u32; 3]>) {
    let count = mids.iter().filter(|&&m| m != u32::MAX).count();
    match count {
        0 => out.push(tri),
        1 => {
            let k = mids.iter().position(|&m| m != u32::MAX).unwrap_or(0);
            let (a, b, c, m) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3], mids[k]);
            out.push([a, m, c]);
            out.push([m, b, c]);
        }
        2 => {
            // Rotate so the unsplit edge is c:a; split edges are a:b (m1) and b:c (m2).
            let k = mids.iter().position(|&m| m == u32::MAX).unwrap_or(0);
            let (c, a, b) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let (m1, m2) = (mids[(k + 1) % 3], mids[(k + 2) % 3]);
            out.push([m1, b, m2]);
            // The quad a, m1, m2, c: cut along its shorter diagonal.
            let p = |v: u32| positions[v as usize].as_dvec3();
            if p(a).distance_squared(p(m2)) <= p(m1).distance_squared(p(c)) {
                out.push([a, m1, m2]);
                out.push([a, m2, c]);
            } else {
                out.push([a, m1, c]);
                out.push([m1, m2, c]);
            }
        }
        _ => {
            let [a, b, c] = tri;
            let [mab, mbc, mca] = mids;
            out.push([a, mab, mca]);
            out.push([mab, b, mbc]);
            out.push([mca, mbc, c]);
            out.push([mab, mbc, mca]);
        }
    }
}

fn remap_groups(mesh: &Mesh, parent_face: &[u32], vertex_count: usize) -> Vec<drafter_core::TriangleGroup> {
    mesh.groups
        .iter()
        .map(|g| {
            let start = parent_face.partition_point(|&p| p < g.start);
            let end = parent_face.partition_point(|&p| p < g.start + g.count);
            let mut group = g.clone();
            group.start = start as u32;
            group.count = (end - start) as u32;
            // The refined mesh is welded: a group's vertices may lie anywhere in it.
            group.first_vertex = 0;
            group.vertex_count = vertex_count as u32;
            group
        })
        .collect()
}
