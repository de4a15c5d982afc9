//! Crease-aware vertex normals: the vertex/index layout that keeps hard edges hard.
//!
//! Around each welded vertex, its faces are grouped into *smooth fans*: two faces join when they share
//! an edge at the vertex, that edge has exactly two faces with a normal, and their normals differ by at
//! most the crease angle. Each fan becomes one output vertex whose normal is the weighted average of
//! the fan's face normals. Every other pair of corners must stay apart (their averages differ), so the
//! layout has the minimum number of vertices for this rule: a closed smooth surface keeps one vertex
//! per welded position, a cube gets 3 per corner, and an unwelded CAD export is smoothed across its
//! patch seams because the grouping runs on welded vertices.
//!
//! Non-manifold edges (3 or more faces) are treated as sharp. A degenerate face (no normal) is bridged:
//! faces on either side of it at the vertex join if their normals are within the angle, and its own
//! corner joins the first of them (or the vertex's first face). This covers one sliver between two
//! faces; a chain of several degenerate faces around one vertex is not bridged.

use drafter_core::{EDGE_NONE, Mesh, Topology};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde::Serialize;

use crate::face::{FACE_CHUNK, FaceGeometry};

/// Default crease angle in degrees: edges whose faces' normals differ by more stay hard.
pub const DEFAULT_CREASE_ANGLE_DEG: f32 = 30.0;

/// How face normals are weighted in a vertex's average.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexWeighting {
    /// By the face's angle at the corner (Thürmer and Wüthrich 1998): independent of how a surface
    /// patch is cut into triangles, so a fan of CAD slivers does not outvote one large triangle.
    #[default]
    Angle,
    /// By face area: large faces dominate.
    Area,
    /// Every face counts once.
    Uniform,
}

/// Options of the crease-aware layout.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CreaseOptions {
    /// Faces whose normals differ by more than this many degrees do not share a vertex normal.
    /// Default [`DEFAULT_CREASE_ANGLE_DEG`]; range 0–180 (0 gives flat shading, 180 smooths across
    /// every manifold edge).
    pub crease_angle_deg: f32,
    /// Weighting of the face normals in a vertex normal. Default [`VertexWeighting::Angle`].
    pub weighting: VertexWeighting,
    /// Keep the input's own vertex splits (UV or material seams): corners that are different input
    /// vertices never share an output vertex. Default `false`: group on welded vertices only, which
    /// smooths unwelded CAD exports and gives the fewest vertices.
    pub keep_input_seams: bool,
}

impl Default for CreaseOptions {
    fn default() -> Self {
        Self {
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
            weighting: VertexWeighting::default(),
            keep_input_seams: false,
        }
    }
}

/// The output vertex/index layout: which input vertex each output vertex copies, the new triangles,
/// and which corners each output vertex averages.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VertexLayout {
    /// For each output vertex, the input (`Mesh::positions`) vertex whose attributes it copies: the
    /// lowest-numbered input vertex among its corners.
    pub source_vertex: Vec<u32>,
    /// For each output vertex, its welded vertex in the topology.
    pub welded_vertex: Vec<u32>,
    /// The triangles in output vertex ids, same order and winding as the input triangles.
    pub triangles: Vec<[u32; 3]>,
    /// CSR offsets into `corners`, `vertex_count + 1` entries.
    pub corner_offsets: Vec<u32>,
    /// Corners (`3 * face + k`) of each output vertex, in increasing order.
    pub corners: Vec<u32>,
    /// Weight of each input corner (`3 * face + k`) in its vertex normal; 0 for degenerate faces.
    pub corner_weights: Vec<f32>,
}

impl VertexLayout {
    /// Groups the corners of `mesh` into smooth fans (see the module docs). `topology` must have been
    /// built from `mesh`, and `geometry` from `topology`.
    pub fn build(mesh: &Mesh, topology: &Topology, geometry: &FaceGeometry, options: &CreaseOptions) -> VertexLayout {
        let cos_crease = (options.crease_angle_deg.clamp(0.0, 180.0) as f64).to_radians().cos() as f32;
        let vertex_count = topology.welded_positions.len();
        let chunk_count = vertex_count.div_ceil(FACE_CHUNK);
        let smooth_pairs = smooth_pairs(topology, geometry, cos_crease);
        let grouping =
            Grouping { mesh, topology, geometry, smooth_pairs, cos_crease, keep_input_seams: options.keep_input_seams };
        let chunks: Vec<ChunkGroups> = (0..chunk_count)
            .into_par_iter()
            .map(|chunk| {
                let start = chunk * FACE_CHUNK;
                grouping.group_vertices(start..(start + FACE_CHUNK).min(vertex_count))
            })
            .collect();

        let output_count: usize = chunks.iter().map(|c| c.group_sizes.len()).sum();
        let mut layout = VertexLayout {
            source_vertex: Vec::with_capacity(output_count),
            welded_vertex: Vec::with_capacity(output_count),
            triangles: vec![[0; 3]; mesh.triangles.len()],
            corner_offsets: Vec::with_capacity(output_count + 1),
            corners: Vec::with_capacity(mesh.triangles.len() * 3),
            corner_weights: corner_weights(topology, geometry, options.weighting),
        };
        layout.corner_offsets.push(0);
        for chunk in chunks {
            layout.source_vertex.extend_from_slice(&chunk.sources);
            layout.welded_vertex.extend_from_slice(&chunk.welded);
            for size in chunk.group_sizes {
                let last = layout.corner_offsets.last().copied().unwrap_or(0);
                layout.corner_offsets.push(last + size);
            }
            layout.corners.extend_from_slice(&chunk.corners);
        }
        for vertex in 0..output_count {
            let range = layout.corner_offsets[vertex] as usize..layout.corner_offsets[vertex + 1] as usize;
            for &corner in &layout.corners[range] {
                layout.triangles[corner as usize / 3][corner as usize % 3] = vertex as u32;
            }
        }
        layout
    }

    /// Number of output vertices.
    pub fn vertex_count(&self) -> usize {
        self.source_vertex.len()
    }

    /// Corners of output vertex `v`.
    #[inline]
    pub fn corners_of(&self, v: usize) -> &[u32] {
        &self.corners[self.corner_offsets[v] as usize..self.corner_offsets[v + 1] as usize]
    }

    /// Vertex normals from per-face normals (the face normals, or the enhanced ones): for each output
    /// vertex, the normalised weighted sum of its corners' face normals. Where that sum is zero (only
    /// degenerate faces, or normals that cancel) the unweighted sum is used, and where that is zero too,
    /// `+Z`. Returns the normals and how many vertices fell back to `+Z`.
    pub fn vertex_normals(&self, face_normals: &[Vec3]) -> (Vec<Vec3>, usize) {
        let normals: Vec<(Vec3, bool)> = (0..self.vertex_count())
            .into_par_iter()
            .with_min_len(FACE_CHUNK)
            .map(|v| {
                let corners = self.corners_of(v);
                let mut weighted = Vec3::ZERO;
                for &corner in corners {
                    weighted += face_normals[corner as usize / 3] * self.corner_weights[corner as usize];
                }
                if let Some(n) = weighted.try_normalize() {
                    return (n, false);
                }
                let mut plain = Vec3::ZERO;
                for &corner in corners {
                    plain += face_normals[corner as usize / 3];
                }
                match plain.try_normalize() {
                    Some(n) => (n, false),
                    None => (Vec3::Z, true),
                }
            })
            .collect();
        let fallbacks = normals.iter().filter(|(_, fallback)| *fallback).count();
        (normals.into_iter().map(|(n, _)| n).collect(), fallbacks)
    }
}

/// Output of one chunk of welded vertices: its groups in order.
struct ChunkGroups {
    group_sizes: Vec<u32>,
    corners: Vec<u32>,
    sources: Vec<u32>,
    welded: Vec<u32>,
}

struct Grouping<'a> {
    mesh: &'a Mesh,
    topology: &'a Topology,
    geometry: &'a FaceGeometry,
    /// Per edge, its two faces when they may join ([`smooth_pairs`]).
    smooth_pairs: Vec<[u32; 2]>,
    cos_crease: f32,
    keep_input_seams: bool,
}

/// For each edge, its two faces (in increasing order) when it has exactly two non-degenerate faces
/// whose normals are within the crease angle: the edges along which step 1 of the grouping joins
/// faces; `[EDGE_NONE; 2]` for every other edge.
///
/// Each edge is decided once here, in edge order, instead of four times (from both faces, at both
/// ends) with three random reads each inside the per-vertex loop. On its own this saves little; the
/// corner angles below are the larger cost.
fn smooth_pairs(topology: &Topology, geometry: &FaceGeometry, cos_crease: f32) -> Vec<[u32; 2]> {
    let mut pairs = Vec::new();
    (0..topology.edge_count())
        .into_par_iter()
        .with_min_len(FACE_CHUNK)
        .map(|e| {
            if e + LAYOUT_PREFETCH_AHEAD < topology.edge_count() {
                for &g in topology.faces_of_edge(e + LAYOUT_PREFETCH_AHEAD) {
                    drafter_core::prefetch(&geometry.areas[g as usize]);
                    drafter_core::prefetch(&geometry.normals[g as usize]);
                }
            }
            let mut pair = [EDGE_NONE; 2];
            let mut count = 0;
            for &g in topology.faces_of_edge(e) {
                if geometry.is_degenerate(g as usize) {
                    continue;
                }
                if count == 2 {
                    // Stop at the third: a fan of n faces on one edge costs n, not more.
                    return [EDGE_NONE; 2];
                }
                pair[count] = g;
                count += 1;
            }
            let [f, g] = pair;
            if count == 2 && geometry.normals[f as usize].dot(geometry.normals[g as usize]) >= cos_crease {
                pair
            } else {
                [EDGE_NONE; 2]
            }
        })
        .collect_into_vec(&mut pairs);
    pairs
}

impl Grouping<'_> {
    /// Position of welded vertex `v` in face `f` (its first corner there).
    #[inline]
    fn corner_of(&self, f: usize, v: u32) -> usize {
        let face = self.topology.faces[f];
        if face[0] == v {
            0
        } else if face[1] == v {
            1
        } else {
            2
        }
    }

    /// The two edges of face `f` that meet at its corner `c`: `c→c+1` and `c-1→c`.
    #[inline]
    fn edges_at(&self, f: usize, c: usize) -> [u32; 2] {
        let edges = self.topology.face_edges[f];
        [edges[c], edges[(c + 2) % 3]]
    }

    /// True when corners of `f` and `g` at `v` may share an output vertex as far as input seams go.
    #[inline]
    fn same_input_vertex(&self, f: usize, g: usize, v: u32) -> bool {
        !self.keep_input_seams
            || self.mesh.triangles[f][self.corner_of(f, v)] == self.mesh.triangles[g][self.corner_of(g, v)]
    }

    #[inline]
    fn smooth(&self, f: usize, g: usize, v: u32) -> bool {
        self.geometry.normals[f].dot(self.geometry.normals[g]) >= self.cos_crease && self.same_input_vertex(f, g, v)
    }

    fn group_vertices(&self, vertices: std::ops::Range<usize>) -> ChunkGroups {
        let mut out =
            ChunkGroups { group_sizes: Vec::new(), corners: Vec::new(), sources: Vec::new(), welded: Vec::new() };
        let mut parent: Vec<u32> = Vec::new();
        let mut linked: Vec<u32> = Vec::new();
        let mut group_of_root: Vec<u32> = Vec::new();
        let mut members: Vec<(u32, u32)> = Vec::new();
        let mut corner_at: Vec<u8> = Vec::new();
        let end = vertices.end;
        for v in vertices {
            // What the fans of a vertex a few steps ahead read, loading now (`LAYOUT_PREFETCH_AHEAD`).
            if v + LAYOUT_PREFETCH_AHEAD < end {
                for &f in self.topology.faces_of_vertex(v + LAYOUT_PREFETCH_AHEAD) {
                    let f = f as usize;
                    drafter_core::prefetch(&self.topology.faces[f]);
                    drafter_core::prefetch(&self.topology.face_edges[f]);
                    drafter_core::prefetch(&self.geometry.areas[f]);
                }
            }
            let faces = self.topology.faces_of_vertex(v);
            if faces.is_empty() {
                continue;
            }
            let v32 = v as u32;
            let local = |g: u32| faces.binary_search(&g).ok();
            parent.clear();
            parent.extend(0..faces.len() as u32);

            // 1. Smooth manifold edges join non-degenerate faces.
            corner_at.clear();
            let mut any_degenerate = false;
            for (i, &f) in faces.iter().enumerate() {
                if self.geometry.is_degenerate(f as usize) {
                    any_degenerate = true;
                    corner_at.push(0);
                    continue;
                }
                let c = self.corner_of(f as usize, v32);
                corner_at.push(c as u8);
                for e in self.edges_at(f as usize, c) {
                    if e == EDGE_NONE {
                        continue;
                    }
                    let [a, b] = self.smooth_pairs[e as usize];
                    // The pair holds `f` itself (a non-degenerate face of the edge) or nothing.
                    let g = if a == f { b } else { a };
                    if g != EDGE_NONE
                        && g > f
                        && self.same_input_vertex(f as usize, g as usize, v32)
                        && let Some(j) = local(g)
                    {
                        union(&mut parent, i, j);
                    }
                }
            }
            // The common case: no degenerate face (a face then holds `v` at one corner only) and
            // one smooth fan. Its corners in face order are what step 3 emits after its sort, so
            // the sort and step 3's second read of every face are skipped. Nearly every vertex of a
            // smooth mesh takes this path, so it is most of the grouping's time (`normals_bench`).
            if !any_degenerate && (1..faces.len()).all(|i| find(&mut parent, i) == 0) {
                let mut source = u32::MAX;
                for (&f, &c) in faces.iter().zip(&corner_at) {
                    source = source.min(self.mesh.triangles[f as usize][usize::from(c)]);
                    out.corners.push(f * 3 + u32::from(c));
                }
                out.group_sizes.push(faces.len() as u32);
                out.sources.push(source);
                out.welded.push(v32);
                continue;
            }
            // 2. Degenerate faces: bridge their neighbours, then join the first of them.
            self.bridge_degenerate(faces, v32, &mut parent, &mut linked);
            // 3. Number the groups in order of their first face and emit their corners.
            self.emit_groups(faces, v32, &mut parent, (&mut group_of_root, &mut members), &mut out);
        }
        out
    }

    /// Step 2 of [`Self::group_vertices`]: each degenerate face around `v` bridges its neighbours
    /// (smooth pairs that share no edge are joined) and joins the first face it shares the input
    /// vertex with.
    #[inline]
    fn bridge_degenerate(&self, faces: &[u32], v32: u32, parent: &mut [u32], linked: &mut Vec<u32>) {
        let local = |g: u32| faces.binary_search(&g).ok();
        for (i, &d) in faces.iter().enumerate() {
            if !self.geometry.is_degenerate(d as usize) {
                continue;
            }
            linked.clear();
            let c = self.corner_of(d as usize, v32);
            for e in self.edges_at(d as usize, c) {
                if e == EDGE_NONE {
                    continue;
                }
                for &g in self.topology.faces_of_edge(e as usize) {
                    if !self.geometry.is_degenerate(g as usize) && !linked.contains(&g) {
                        linked.push(g);
                    }
                }
            }
            for a in 0..linked.len() {
                for b in a + 1..linked.len() {
                    let (f, g) = (linked[a], linked[b]);
                    let shares_edge = self.topology.face_edges[f as usize]
                        .iter()
                        .any(|&e| e != EDGE_NONE && self.topology.faces_of_edge(e as usize).contains(&g));
                    // Faces that already share an edge were decided in step 1.
                    if !shares_edge
                        && self.smooth(f as usize, g as usize, v32)
                        && let (Some(x), Some(y)) = (local(f), local(g))
                    {
                        union(parent, x, y);
                    }
                }
            }
            let target = linked
                .iter()
                .copied()
                .find(|&g| self.same_input_vertex(d as usize, g as usize, v32))
                .or_else(|| {
                    faces.iter().copied().find(|&g| {
                        g != d
                            && !self.geometry.is_degenerate(g as usize)
                            && self.same_input_vertex(d as usize, g as usize, v32)
                    })
                })
                .or_else(|| {
                    faces.iter().copied().find(|&g| g != d && self.same_input_vertex(d as usize, g as usize, v32))
                });
            if let Some(j) = target.and_then(local) {
                union(parent, i, j);
            }
        }
    }

    /// Step 3 of [`Self::group_vertices`]: numbers the groups around `v` in order of their first
    /// face and emits their corners, sources and welded vertex into `out`.
    #[inline]
    fn emit_groups(
        &self,
        faces: &[u32],
        v32: u32,
        parent: &mut [u32],
        (group_of_root, members): (&mut Vec<u32>, &mut Vec<(u32, u32)>),
        out: &mut ChunkGroups,
    ) {
        group_of_root.clear();
        group_of_root.resize(faces.len(), u32::MAX);
        members.clear();
        let mut group_count = 0u32;
        for (i, &f) in faces.iter().enumerate() {
            let root = find(parent, i) as usize;
            if group_of_root[root] == u32::MAX {
                group_of_root[root] = group_count;
                group_count += 1;
            }
            let face = self.topology.faces[f as usize];
            for (k, &w) in face.iter().enumerate() {
                if w == v32 {
                    members.push((group_of_root[root], f * 3 + k as u32));
                }
            }
        }
        members.sort_unstable();
        let mut start = 0;
        while start < members.len() {
            let group = members[start].0;
            let mut end = start;
            let mut source = u32::MAX;
            while end < members.len() && members[end].0 == group {
                let corner = members[end].1 as usize;
                source = source.min(self.mesh.triangles[corner / 3][corner % 3]);
                out.corners.push(members[end].1);
                end += 1;
            }
            out.group_sizes.push((end - start) as u32);
            out.sources.push(source);
            out.welded.push(v32);
            start = end;
        }
    }
}

/// How many welded vertices ahead the grouping prefetches the faces around a vertex (their
/// corners, edges and areas), and how many edges ahead [`smooth_pairs`] prefetches its faces'
/// areas and normals. Where the vertex order scatters a vertex's faces over the arrays (the scaling
/// benchmark's subdivision order), these reads would miss the cache; fetched this far ahead, they
/// have arrived when the grouping needs them (docs/bench.md#scaling). Prefetching the vertex
/// normals' face normals, the layout's triangle writes, the input triangles (the sources) or the
/// smooth pairs of the fans gained nothing measurable, so it is not done.
const LAYOUT_PREFETCH_AHEAD: usize = 16;

fn find(parent: &mut [u32], mut x: usize) -> u32 {
    while parent[x] as usize != x {
        let grand = parent[parent[x] as usize];
        parent[x] = grand;
        x = grand as usize;
    }
    x as u32
}

/// Union towards the smaller root, so the structure (and the group order) is deterministic.
fn union(parent: &mut [u32], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        parent[hi as usize] = lo;
    }
}

/// Weight of every corner (`3 * face + k`) under `weighting`; 0 for degenerate faces.
fn corner_weights(topology: &Topology, geometry: &FaceGeometry, weighting: VertexWeighting) -> Vec<f32> {
    let positions = &topology.welded_positions;
    let mut weights = vec![0.0f32; 3 * topology.faces.len()];
    // Written in place, a face's three corners at a time (a flattening collect of per-face arrays cost
    // as much as the angles).
    weights.par_chunks_mut(3 * FACE_CHUNK).enumerate().for_each(|(chunk, out)| {
        let base = chunk * FACE_CHUNK;
        for (i, corner) in out.chunks_exact_mut(3).enumerate() {
            let f = base + i;
            if geometry.is_degenerate(f) {
                continue;
            }
            let w = match weighting {
                VertexWeighting::Uniform => [1.0; 3],
                VertexWeighting::Area => [geometry.areas[f]; 3],
                VertexWeighting::Angle => corner_angles(topology.faces[f].map(|v| positions[v as usize].as_dvec3())),
            };
            corner.copy_from_slice(&w);
        }
    });
    weights
}

/// Interior angles of the triangle `p` at its three corners, robust for tiny and obtuse angles:
/// `atan2(|u × w|, u · w)` of the two edges at each corner. `|u × w|` is twice the area at every corner,
/// so it is taken once. Edge vectors and products are in f64, the angle in f32 (the weights are f32).
fn corner_angles(p: [DVec3; 3]) -> [f32; 3] {
    let edges = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
    let double_area = edges[0].cross(edges[2]).length();
    // At corner k the edges are p[k+1] − p[k] = edges[k] and p[k+2] − p[k] = −edges[k+2].
    std::array::from_fn(|k| angle_of(double_area, -edges[k].dot(edges[(k + 2) % 3])))
}

/// `atan2(sine, cosine)` for `sine ≥ 0`, in [0, π], within 2e-7 rad (tested against f64 `atan2`).
///
/// Written here because libm's arctangent (f64 or f32) was a large share of the vertex layout's
/// time: three per triangle. Cephes' `atanf` reduction to |x| ≤ tan(π/8) and its degree-9 odd
/// polynomial (Moshier, *Methods and Programs for Mathematical Functions*, 1989), evaluated in f64.
#[inline]
fn angle_of(sine: f64, cosine: f64) -> f32 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    if sine == 0.0 && cosine == 0.0 {
        return 0.0;
    }
    // atan(sine / |cosine|), the ratio in [0, ∞] reduced as Cephes does (never dividing by zero:
    // the larger of the two is the denominator of the first branch).
    let (numerator, denominator) = (sine, cosine.abs());
    let (offset, x) = if numerator > 2.414_213_562_373_095 * denominator {
        (FRAC_PI_2, -denominator / numerator)
    } else if numerator > 0.414_213_562_373_095 * denominator {
        (FRAC_PI_4, (numerator - denominator) / (numerator + denominator))
    } else {
        (0.0, numerator / denominator)
    };
    let z = x * x;
    let atan = offset
        + (((8.053_744_495_38e-2 * z - 1.387_768_560_32e-1) * z + 1.997_771_064_78e-1) * z - 3.333_294_915_39e-1)
            * z
            * x
        + x;
    (if cosine < 0.0 { PI - atan } else { atan }) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polynomial arctangent against f64 `atan2` over 200,000 pseudo-random (sine, cosine) pairs
    /// spanning twelve decades, plus the axes and the zero pair.
    #[test]
    fn angle_matches_atan2() {
        let mut rng = drafter_core::rng::Rng::new(0x9e37_79b9_7f4a_7c15u64);
        let mut next = || rng.unit_f64();
        let mut worst = 0.0f64;
        for _ in 0..200_000 {
            let sine = next() * 10f64.powf(next() * 12.0 - 6.0);
            let cosine = (next() - 0.5) * 10f64.powf(next() * 12.0 - 6.0);
            let error = (f64::from(angle_of(sine, cosine)) - sine.atan2(cosine)).abs();
            worst = worst.max(error);
        }
        assert!(worst < 2e-7, "worst error {worst:e} rad");
        for (sine, cosine) in [(0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (0.0, 0.0), (1e-300, 1.0), (1.0, 1e-300)] {
            let error = (f64::from(angle_of(sine, cosine)) - f64::atan2(sine, cosine)).abs();
            assert!(error < 2e-7, "atan2({sine}, {cosine}): error {error:e}");
        }
    }
}
