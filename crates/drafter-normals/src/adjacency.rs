//! The compact, weighted face→face adjacency the low-pass filter iterates over.
//!
//! Built once from [`Topology`] (edge→faces or vertex→faces CSR) in parallel, in face order, so the
//! result depends only on the input. Each row lists a face's neighbours in increasing face order with
//! their weights; degenerate neighbours (no normal) are left out, so the inner loop never tests for
//! them. Edge neighbourhoods (at most three neighbours per face: only manifold edges count) are stored as
//! three padded face ids per face (plus three dampings only if some pair is damped); anything else as
//! CSR. The low-pass is memory-bound, so bytes per face and where they lie are what set its speed:
//! where a large mesh's face order scatters neighbours, its packed rows are stored and iterated in a
//! breadth-first order of the faces, which keeps every row's neighbours close to it in memory (see
//! [`FaceAdjacency`]).

use std::sync::atomic::{AtomicBool, Ordering};

use drafter_core::{EDGE_NONE, Topology};
use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use serde::Serialize;

use crate::face::{FACE_CHUNK, FaceGeometry};

/// `h` of [`Weighting::ScaleDependent`] as a multiple of the median centroid distance between
/// neighbours. 2 leaves ordinary size variation alone (a uniform mesh is filtered exactly as with area
/// weights) and damps only neighbours more than twice as far as usual; chosen by the tessellation survey
/// (crate docs), where of the factors tried it deviated least from refine-then-filter (figures in
/// `bench/normals/README.md`).
pub const SCALE_REFERENCE_FACTOR: f32 = 2.0;

/// Which faces count as neighbours of a face in the low-pass filter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Neighborhood {
    /// Faces sharing a manifold edge (3 on a closed manifold; none across a boundary or a
    /// non-manifold edge, one with more than two non-degenerate faces). The paper's and MeshLab's choice; the cheapest per iteration. A
    /// non-manifold edge bounds the filter like a boundary: the sheets that meet there are separate
    /// surfaces (a CAD T-junction, a fin), and averaging across all of them is ill-posed. Evenly
    /// spread wings sum to about zero, so their low-pass normal would point wherever rounding sends
    /// it (the stability suite's rotated 3- and 6-wing fans moved by 11–22° before this rule).
    /// MeshLab takes one arbitrary wing across such an edge.
    #[default]
    Edge,
    /// Faces sharing at least one vertex (about 12 on a regular mesh): smooths about twice as far per
    /// iteration, at about four times the cost, and sees across vertices where only a corner touches.
    Vertex,
}

/// How much each neighbour counts in the average.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Weighting {
    /// Every face counts once, whatever its size.
    Uniform,
    /// Each face counts with its area: the paper's "area-weighted average" (§4 step 1) and MeshLab's
    /// `FaceNormalLaplacianFF`. One iteration spreads the signal by one face, so how far the filter
    /// reaches depends on the local triangle size.
    Area,
    /// Scale-dependent (§4.1, after Desbrun et al. 1999): area weight times `min(1, (h / d)²)`, where
    /// `d` is the distance between the two centroids and `h` is [`SCALE_REFERENCE_FACTOR`] times the
    /// median of that distance over the mesh. One iteration then diffuses over at most about `h`,
    /// instead of over one face however large: a long CAD triangle neither drags its small neighbours
    /// nor spreads the filter over its whole length. On a uniform mesh it equals [`Weighting::Area`].
    #[default]
    ScaleDependent,
}

/// Face→face adjacency with weights. See the module docs.
///
/// The weight of neighbour `g` in face `f`'s average factors as `w_g · d_fg`: the face weight `w_g`
/// (1 or the relative area) times a damping `d_fg` (1 except for distant neighbours under
/// [`Weighting::ScaleDependent`]). The iteration therefore keeps `w_g·n_g` premultiplied, and a row
/// needs only neighbour ids, plus dampings when some pair is damped.
///
/// The packed rows of a large mesh whose face order scatters neighbours ([`SWEEP_ORDER_MIN_FACES`],
/// [`scattered`]) are stored in *sweep order*, a breadth-first order of the faces ([`SweepOrder`]),
/// so that the neighbours a row reads lie within a short window around it, where a scan's input
/// order can put them tens of thousands of faces away (docs/bench.md#normals).
/// Each row keeps its neighbours in the sequence of the face's own row, so every sum has the same
/// terms in the same order as in face order, and the result does not depend on the order.
#[derive(Clone, Debug, Default)]
pub struct FaceAdjacency {
    /// `w_f` per row (0 for a degenerate face), in sweep order.
    weights: Vec<f32>,
    rows: Rows,
    /// Sweep order of the rows; the identity for CSR rows (vertex neighbourhoods reach too far for an
    /// order to keep them close).
    order: SweepOrder,
    /// The reference length `h` of [`Weighting::ScaleDependent`].
    reference_length: f32,
}

/// The rows, in one of two layouts with the same content and the same summation order.
#[derive(Clone, Debug)]
enum Rows {
    /// At most three neighbours per face (edge neighbourhoods), as positions in sweep order, padded with
    /// the position one past the last row, whose premultiplied normal is always zero. `dampings` is
    /// empty when no pair is damped.
    Packed { neighbors: Vec<[u32; 3]>, dampings: Vec<[f32; 3]> },
    /// Any number of neighbours (vertex neighbourhoods; edge neighbourhoods of duplicated faces):
    /// CSR, in face order.
    General { offsets: Vec<u32>, neighbors: Vec<u32>, dampings: Vec<f32> },
}

impl Default for Rows {
    fn default() -> Self {
        Rows::Packed { neighbors: Vec::new(), dampings: Vec::new() }
    }
}

/// Where each face's row is iterated: `face[i]` is the face at position `i`, `position[f]` the position
/// of face `f`. Both empty for the identity.
#[derive(Clone, Debug, Default)]
struct SweepOrder {
    face: Vec<u32>,
    position: Vec<u32>,
}

impl SweepOrder {
    #[inline]
    fn position(&self, f: usize) -> usize {
        if self.position.is_empty() { f } else { self.position[f] as usize }
    }

    #[inline]
    fn face(&self, i: usize) -> usize {
        if self.face.is_empty() { i } else { self.face[i] as usize }
    }
}

impl FaceAdjacency {
    /// Builds the weighted adjacency of `topology`'s faces; `geometry` must come from `topology`.
    pub fn build(
        topology: &Topology,
        geometry: &FaceGeometry,
        neighborhood: Neighborhood,
        weighting: Weighting,
    ) -> FaceAdjacency {
        Self::build_in(topology, geometry, neighborhood, weighting, None)
    }

    /// [`Self::build`]; `force_sweep` `Some(true)` or `Some(false)` stores packed rows in sweep order or
    /// in face order whatever the mesh (for tests), `None` decides as `build` does
    /// ([`SWEEP_ORDER_MIN_FACES`], [`scattered`]).
    fn build_in(
        topology: &Topology,
        geometry: &FaceGeometry,
        neighborhood: Neighborhood,
        weighting: Weighting,
        force_sweep: Option<bool>,
    ) -> FaceAdjacency {
        // Areas are divided by the mean non-degenerate area so weights stay near 1 whatever the units.
        let (area_sum, area_count) =
            geometry.areas.iter().filter(|&&a| a > 0.0).fold((0.0f64, 0usize), |(s, n), &a| (s + a as f64, n + 1));
        let mean_area = if area_count > 0 { (area_sum / area_count as f64) as f32 } else { 1.0 };
        let face_weight = |area: f32| match weighting {
            _ if area == 0.0 => 0.0,
            Weighting::Uniform => 1.0,
            Weighting::Area | Weighting::ScaleDependent => area / mean_area,
        };
        let face_weights = || geometry.areas.par_iter().with_min_len(FACE_CHUNK).map(|&a| face_weight(a)).collect();
        let packed = match neighborhood {
            Neighborhood::Edge => build_packed(topology, geometry, weighting == Weighting::ScaleDependent),
            Neighborhood::Vertex => None,
        };
        match packed {
            Some((neighbors, mut distances)) => {
                let reference_length = if weighting == Weighting::ScaleDependent {
                    let stride = distances.len().div_ceil(SAMPLE_SIZE).max(1);
                    let sample = distances.iter().step_by(stride).flatten().copied().filter(|&d| d > 0.0).collect();
                    SCALE_REFERENCE_FACTOR * median(sample)
                } else {
                    0.0
                };
                let damped = weighting == Weighting::ScaleDependent
                    && distances.par_iter().flatten().any(|&d| d > reference_length);
                let to_dampings = |distances: &mut Vec<[f32; 3]>| {
                    distances.par_iter_mut().with_min_len(FACE_CHUNK).for_each(|row| {
                        *row = row.map(|d| damping(d, reference_length));
                    });
                };
                let sweep_order =
                    force_sweep.unwrap_or_else(|| neighbors.len() >= SWEEP_ORDER_MIN_FACES && scattered(&neighbors));
                if !sweep_order {
                    let dampings = if damped {
                        to_dampings(&mut distances);
                        distances
                    } else {
                        Vec::new()
                    };
                    let rows = Rows::Packed { neighbors, dampings };
                    return FaceAdjacency {
                        weights: face_weights(),
                        rows,
                        order: SweepOrder::default(),
                        reference_length,
                    };
                }
                // The order is serial: the other threads turn distances into dampings meanwhile.
                let (order, ()) = rayon::join(
                    || breadth_first_order(&neighbors),
                    || {
                        if damped {
                            to_dampings(&mut distances);
                        }
                    },
                );
                let dampings = if damped { drafter_core::gather(&distances, &order.face) } else { Vec::new() };
                drop(distances);
                let padding = neighbors.len() as u32;
                let mut rows = Vec::new();
                order
                    .face
                    .par_iter()
                    .with_min_len(FACE_CHUNK)
                    .map(|&f| neighbors[f as usize].map(|g| if g == padding { g } else { order.position[g as usize] }))
                    .collect_into_vec(&mut rows);
                let weights = order
                    .face
                    .par_iter()
                    .with_min_len(FACE_CHUNK)
                    .map(|&f| face_weight(geometry.areas[f as usize]))
                    .collect();
                FaceAdjacency { weights, rows: Rows::Packed { neighbors: rows, dampings }, order, reference_length }
            }
            None => {
                let (rows, reference_length) = build_general(topology, geometry, neighborhood, weighting);
                FaceAdjacency { weights: face_weights(), rows, order: SweepOrder::default(), reference_length }
            }
        }
    }

    /// Number of faces (rows).
    pub fn face_count(&self) -> usize {
        self.weights.len()
    }

    /// Number of neighbour entries over all rows.
    pub fn entry_count(&self) -> usize {
        let padding = self.face_count() as u32;
        match &self.rows {
            Rows::Packed { neighbors, .. } => neighbors.iter().flatten().filter(|&&g| g != padding).count(),
            Rows::General { neighbors, .. } => neighbors.len(),
        }
    }

    /// The reference length `h` of [`Weighting::ScaleDependent`] ([`SCALE_REFERENCE_FACTOR`] × the
    /// median centroid distance between neighbours); 0 for other weightings or without neighbour pairs.
    pub fn reference_length(&self) -> f32 {
        self.reference_length
    }

    /// Weight of face `f`'s own normal in its average (0 for a degenerate face).
    pub fn self_weight(&self, f: usize) -> f32 {
        self.weights[self.order.position(f)]
    }

    /// Neighbours of face `f` (increasing, degenerate faces left out) with their full weights
    /// `w_g · d_fg`. For inspection; the iteration does not use it.
    pub fn row(&self, f: usize) -> Vec<(u32, f32)> {
        let padding = self.face_count() as u32;
        let i = self.order.position(f);
        match &self.rows {
            Rows::Packed { neighbors, dampings } => (0..3)
                .filter(|&k| neighbors[i][k] != padding)
                .map(|k| {
                    let g = neighbors[i][k] as usize;
                    let d = dampings.get(i).map_or(1.0, |row| row[k]);
                    (self.order.face(g) as u32, self.weights[g] * d)
                })
                .collect(),
            Rows::General { offsets, neighbors, dampings } => (offsets[i] as usize..offsets[i + 1] as usize)
                .map(|e| (neighbors[e], self.weights[neighbors[e] as usize] * dampings[e]))
                .collect(),
        }
    }

    /// `iterations` Jacobi steps from `normals`: `n_f ← normalize(w_f·n_f + Σ_g w_g·d_fg·n_g)`, zero
    /// where the sum is zero. Every output depends only on the previous iteration, summed in row order,
    /// so the result is the same at any thread count and in any sweep order.
    pub fn smooth(&self, normals: &[Vec3], iterations: u32) -> Vec<Vec3> {
        let n = self.face_count();
        if iterations == 0 {
            return normals.to_vec();
        }
        // Premultiplied `w_f·n_f` in 16-byte SIMD vectors, in sweep order, with one extra zero entry
        // that the padding of packed rows points to.
        let mut current: Vec<Vec3A> = Vec::with_capacity(n + 1);
        self.weights
            .par_iter()
            .enumerate()
            .with_min_len(FACE_CHUNK)
            .map(|(i, &w)| Vec3A::from(normals[self.order.face(i)]) * w)
            .collect_into_vec(&mut current);
        current.push(Vec3A::ZERO);
        let mut next = vec![Vec3A::ZERO; n + 1];
        for iteration in 0..iterations {
            // The last step stores the unit normals themselves, which degenerate faces need too.
            let unit = iteration + 1 == iterations;
            next[..n].par_chunks_mut(FACE_CHUNK).enumerate().for_each(|(chunk, out)| {
                let start = chunk * FACE_CHUNK;
                self.sweep(&current, start..start + out.len(), out, unit);
            });
            std::mem::swap(&mut current, &mut next);
        }
        (0..n).into_par_iter().with_min_len(FACE_CHUNK).map(|f| Vec3::from(current[self.order.position(f)])).collect()
    }

    /// One Jacobi step of the rows `rows`, reading the previous step from `source` (its last entry zero,
    /// for padding) and writing `out` (row `rows.start` first): `normalize(sum)·w_i`, or the unit normal
    /// when `unit`; zero for a zero sum.
    fn sweep(&self, source: &[Vec3A], rows: std::ops::Range<usize>, out: &mut [Vec3A], unit: bool) {
        let weights = &self.weights[rows.clone()];
        let finish = |sum: Vec3A, weight: f32| -> Vec3A {
            let length = sum.length();
            if length > 0.0 { sum * ((if unit { 1.0 } else { weight }) / length) } else { Vec3A::ZERO }
        };
        let at = |g: u32| source[g as usize];
        let own = |i: usize| source[i];
        match &self.rows {
            Rows::Packed { neighbors, dampings } if dampings.is_empty() => {
                for ((out, &[a, b, c]), (i, &w)) in out.iter_mut().zip(&neighbors[rows.clone()]).zip(rows.zip(weights))
                {
                    *out = finish(own(i) + at(a) + at(b) + at(c), w);
                }
            }
            Rows::Packed { neighbors, dampings } => {
                let packed = neighbors[rows.clone()].iter().zip(&dampings[rows.clone()]);
                for ((out, (&[a, b, c], &[da, db, dc])), (i, &w)) in out.iter_mut().zip(packed).zip(rows.zip(weights)) {
                    *out = finish(own(i) + at(a) * da + at(b) * db + at(c) * dc, w);
                }
            }
            Rows::General { offsets, neighbors, dampings } => {
                for ((out, i), &w) in out.iter_mut().zip(rows).zip(weights) {
                    let range = offsets[i] as usize..offsets[i + 1] as usize;
                    let mut sum = own(i);
                    for (&g, &d) in neighbors[range.clone()].iter().zip(&dampings[range]) {
                        sum += source[g as usize] * d;
                    }
                    *out = finish(sum, w);
                }
            }
        }
    }
}

/// From this many faces, packed rows may be stored in sweep order. Below it the filter's arrays
/// (about 60 bytes a face per step) stay in cache in any order, and ordering would cost more than it
/// saves: an assembly of many meshes of a few tens of thousands of faces (GearboxAssy) spent more CPU
/// time with every mesh ordered.
const SWEEP_ORDER_MIN_FACES: usize = 1 << 16;

/// Whether the face order scatters neighbours: more than [`SCATTERED_SHARE`] of the neighbour pairs of
/// every 61st row lie more than [`NEAR_FACES`] faces apart. Ordering costs about 20 bytes a face at
/// the stage's peak and the serial breadth-first pass; it pays only where the face order is poor.
/// The threshold separates the dragon's scan order, whose filter the order speeds up, from the
/// scaling benchmark's subdivisions, whose filter it does not speed up while it raises their peak;
/// their shares are in docs/bench.md#normals.
fn scattered(rows: &[[u32; 3]]) -> bool {
    let padding = rows.len() as u32;
    let (mut far, mut pairs) = (0usize, 0usize);
    for (f, row) in rows.iter().enumerate().step_by(61) {
        for &g in row.iter().filter(|&&g| g != padding) {
            pairs += 1;
            far += usize::from((g as usize).abs_diff(f) > NEAR_FACES);
        }
    }
    far as f64 > SCATTERED_SHARE * pairs as f64
}

/// See [`scattered`]: 4,096 faces are 64 KB of the filter's 16-byte vectors.
const NEAR_FACES: usize = 4096;

/// See [`scattered`].
const SCATTERED_SHARE: f64 = 0.15;

/// A breadth-first order of the faces over packed rows: each connected piece from its lowest face,
/// pieces in the order of their lowest faces. Serial, and linear in the faces; neighbours are visited
/// in row order, so the order depends only on the rows.
fn breadth_first_order(rows: &[[u32; 3]]) -> SweepOrder {
    const UNSEEN: u32 = u32::MAX;
    let n = rows.len();
    let mut position = vec![UNSEEN; n];
    let mut face: Vec<u32> = Vec::with_capacity(n);
    for seed in 0..n {
        if position[seed] != UNSEEN {
            continue;
        }
        position[seed] = face.len() as u32;
        face.push(seed as u32);
        let mut next = face.len() - 1;
        while next < face.len() {
            // The queue says which rows come next: load them a few faces ahead.
            if let Some(&ahead) = face.get(next + BFS_PREFETCH_AHEAD) {
                drafter_core::prefetch(&rows[ahead as usize]);
            }
            for &g in &rows[face[next] as usize] {
                if (g as usize) < n && position[g as usize] == UNSEEN {
                    position[g as usize] = face.len() as u32;
                    face.push(g);
                }
            }
            next += 1;
        }
    }
    SweepOrder { face, position }
}

/// How many queued faces ahead the breadth-first order loads rows. The order is built serially, so
/// it must not wait on memory: the position array doubles as the visited flag, and each row is
/// requested this far ahead of its use.
const BFS_PREFETCH_AHEAD: usize = 8;

/// How many rows (or entries) the median of [`Weighting::ScaleDependent`] samples, evenly strided.
const SAMPLE_SIZE: usize = 1 << 16;

/// `min(1, (h / d)²)`.
#[inline]
fn damping(distance: f32, reference_length: f32) -> f32 {
    if distance > reference_length {
        let ratio = reference_length / distance;
        ratio * ratio
    } else {
        1.0
    }
}

/// Whether the filter averages across an edge with faces `faces`: unless more than two of them have a
/// normal (a non-manifold edge, see [`Neighborhood::Edge`]). Degenerate faces have no vote, so a
/// sliver lying on an edge does not make it a boundary.
#[inline]
fn filters_across(faces: &[u32], geometry: &FaceGeometry) -> bool {
    // `take(3)`: every face of a fan asks, so counting a long fan through would cost its length squared.
    faces.len() <= 2 || faces.iter().filter(|&&g| !geometry.is_degenerate(g as usize)).take(3).count() <= 2
}

/// Neighbour ids and centroid distances of packed rows.
type PackedRows = (Vec<[u32; 3]>, Vec<[f32; 3]>);

/// Edge neighbourhoods as packed rows (padded with the face count) and, `with_distances`, their
/// centroid distances (0 for padding); `None` when some face has more than three neighbours (which
/// only edges listed twice in a face could cause; kept as a guard).
fn build_packed(topology: &Topology, geometry: &FaceGeometry, with_distances: bool) -> Option<PackedRows> {
    let face_count = topology.faces.len();
    let padding = face_count as u32;
    let mut neighbors = vec![[padding; 3]; face_count];
    let mut distances = vec![[0.0f32; 3]; face_count];
    // Set when some face has a fourth neighbour; whether it is set does not depend on the schedule.
    let overflow = AtomicBool::new(false);
    neighbors.par_iter_mut().zip(distances.par_iter_mut()).enumerate().with_min_len(FACE_CHUNK).for_each(
        |(f, (row, row_distances))| {
            let mut len = 0usize;
            for e in topology.face_edges[f] {
                if e == EDGE_NONE {
                    continue;
                }
                let across = topology.faces_of_edge(e as usize);
                if !filters_across(across, geometry) {
                    continue;
                }
                for &g in across {
                    if g as usize == f || geometry.is_degenerate(g as usize) || row[..len].contains(&g) {
                        continue;
                    }
                    if len == 3 {
                        overflow.store(true, Ordering::Relaxed);
                        return;
                    }
                    // Insert in increasing order (the general layout's order).
                    let mut k = len;
                    while k > 0 && row[k - 1] > g {
                        row[k] = row[k - 1];
                        row_distances[k] = row_distances[k - 1];
                        k -= 1;
                    }
                    row[k] = g;
                    if with_distances {
                        row_distances[k] = geometry.centroids[f].distance(geometry.centroids[g as usize]);
                    }
                    len += 1;
                }
            }
        },
    );
    if overflow.into_inner() { None } else { Some((neighbors, distances)) }
}

fn build_general(
    topology: &Topology,
    geometry: &FaceGeometry,
    neighborhood: Neighborhood,
    weighting: Weighting,
) -> (Rows, f32) {
    let face_count = topology.faces.len();
    let chunk_count = face_count.div_ceil(FACE_CHUNK);
    // Rows by chunk, concatenated in face order: (row lengths, neighbours, centroid distances).
    let chunks: Vec<(Vec<u32>, Vec<u32>, Vec<f32>)> = (0..chunk_count)
        .into_par_iter()
        .map(|chunk| {
            let start = chunk * FACE_CHUNK;
            let end = (start + FACE_CHUNK).min(face_count);
            let mut lengths = Vec::with_capacity(end - start);
            let mut neighbors = Vec::with_capacity((end - start) * 3);
            let mut distances = Vec::with_capacity((end - start) * 3);
            let mut scratch: Vec<u32> = Vec::new();
            for f in start..end {
                scratch.clear();
                match neighborhood {
                    Neighborhood::Edge => {
                        for e in topology.face_edges[f] {
                            if e != EDGE_NONE && filters_across(topology.faces_of_edge(e as usize), geometry) {
                                scratch.extend_from_slice(topology.faces_of_edge(e as usize));
                            }
                        }
                    }
                    Neighborhood::Vertex => {
                        for v in topology.faces[f] {
                            scratch.extend_from_slice(topology.faces_of_vertex(v as usize));
                        }
                    }
                }
                scratch.sort_unstable();
                scratch.dedup();
                let before = neighbors.len();
                for &g in &scratch {
                    if g as usize == f || geometry.is_degenerate(g as usize) {
                        continue;
                    }
                    neighbors.push(g);
                    distances.push(geometry.centroids[f].distance(geometry.centroids[g as usize]));
                }
                lengths.push((neighbors.len() - before) as u32);
            }
            (lengths, neighbors, distances)
        })
        .collect();

    let mut offsets = Vec::with_capacity(face_count + 1);
    offsets.push(0u32);
    let total: usize = chunks.iter().map(|c| c.1.len()).sum();
    let mut neighbors = Vec::with_capacity(total);
    let mut dampings = Vec::with_capacity(total);
    for (lengths, chunk_neighbors, chunk_distances) in chunks {
        for length in lengths {
            let last = offsets.last().copied().unwrap_or(0);
            offsets.push(last + length);
        }
        neighbors.extend_from_slice(&chunk_neighbors);
        dampings.extend_from_slice(&chunk_distances);
    }

    let reference_length = if weighting == Weighting::ScaleDependent {
        let stride = dampings.len().div_ceil(SAMPLE_SIZE).max(1);
        SCALE_REFERENCE_FACTOR * median(dampings.iter().step_by(stride).copied().collect())
    } else {
        0.0
    };
    // The distances become dampings.
    dampings.par_iter_mut().with_min_len(FACE_CHUNK).for_each(|d| {
        *d = if weighting == Weighting::ScaleDependent { damping(*d, reference_length) } else { 1.0 };
    });
    (Rows::General { offsets, neighbors, dampings }, reference_length)
}

/// Median of `sample` (the upper one for an even count); 0 when empty. The callers pass an evenly
/// strided sample of at most about [`SAMPLE_SIZE`] rows, so this costs nothing on large meshes.
fn median(mut sample: Vec<f32>) -> f32 {
    if sample.is_empty() {
        return 0.0;
    }
    let middle = sample.len() / 2;
    let (_, value, _) = sample.select_nth_unstable_by(middle, f32::total_cmp);
    *value
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::Weld;

    /// A bumpy grid in shuffled face order, with a far vertex (damped neighbours), a degenerate face,
    /// a boundary, and a second piece.
    fn shuffled_grid(side: u32, seed: u64) -> Topology {
        let mut rng = drafter_core::rng::Rng::new(seed);
        let mut next = move || rng.unit_f64() as f32;
        let id = |x: u32, y: u32| y * (side + 1) + x;
        let mut positions: Vec<glam::Vec3> = (0..=side)
            .flat_map(|y| (0..=side).map(move |x| (x, y)))
            .map(|(x, y)| glam::Vec3::new(x as f32, y as f32, 0.0))
            .collect();
        for p in &mut positions {
            p.z = 0.3 * next();
        }
        let mut triangles = Vec::new();
        for y in 0..side {
            for x in 0..side {
                triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
        // A far corner: two long faces, whose neighbours are damped.
        positions[id(side, side) as usize] += glam::Vec3::new(40.0, 40.0, 3.0);
        // A degenerate face (three times the same vertex) and a separate triangle.
        triangles.push([0, 0, 0]);
        let base = positions.len() as u32;
        positions.extend([
            glam::Vec3::new(-5.0, 0.0, 0.0),
            glam::Vec3::new(-5.0, 1.0, 0.0),
            glam::Vec3::new(-6.0, 0.0, 1.0),
        ]);
        triangles.push([base, base + 1, base + 2]);
        for i in (1..triangles.len()).rev() {
            let j = (next() * (i + 1) as f32) as usize % (i + 1);
            triangles.swap(i, j);
        }
        Topology::from_triangles(&positions, &triangles, Weld::Exact)
    }

    /// The breadth-first sweep order changes where rows are stored, never a sum: the low-pass equals
    /// that of the rows built in face order bit for bit, with and without dampings, on one thread and on four.
    #[test]
    fn the_sweep_order_gives_the_face_order_bits() {
        for (side, seed) in [(3, 1), (17, 2), (60, 3)] {
            let topology = shuffled_grid(side, seed);
            let geometry = FaceGeometry::compute(&topology);
            for weighting in [Weighting::ScaleDependent, Weighting::Area, Weighting::Uniform] {
                let adjacency =
                    FaceAdjacency::build_in(&topology, &geometry, Neighborhood::Edge, weighting, Some(true));
                let reference =
                    FaceAdjacency::build_in(&topology, &geometry, Neighborhood::Edge, weighting, Some(false));
                assert!(adjacency.order.face.iter().enumerate().any(|(i, &f)| i != f as usize), "not reordered");
                if weighting == Weighting::ScaleDependent {
                    let Rows::Packed { dampings, .. } = &adjacency.rows else { unreachable!() };
                    assert!(dampings.iter().flatten().any(|&d| d < 1.0), "side {side}: nothing damped");
                }
                for f in 0..adjacency.face_count() {
                    assert_eq!(adjacency.row(f), reference.row(f), "side {side} face {f}");
                }
                for threads in [1, 4] {
                    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                    for iterations in [1, 2, 9] {
                        let (ours, theirs) = pool.install(|| {
                            (
                                adjacency.smooth(&geometry.normals, iterations),
                                reference.smooth(&geometry.normals, iterations),
                            )
                        });
                        let bits =
                            |v: &[Vec3]| v.iter().flat_map(|n| n.to_array().map(f32::to_bits)).collect::<Vec<_>>();
                        assert_eq!(bits(&ours), bits(&theirs), "side {side} {weighting:?} {iterations} iterations");
                    }
                }
            }
        }
    }

    /// `scattered` on rows whose neighbours lie close, far, or are padding.
    #[test]
    fn scattered_tells_near_rows_from_far_ones() {
        let n = 200_000u32;
        let near: Vec<[u32; 3]> =
            (0..n).map(|f| [f.saturating_sub(1), (f + 1).min(n - 1), (f + 300).min(n - 1)]).collect();
        assert!(!scattered(&near));
        // One neighbour in three far away: a third of the pairs, above the share.
        let far: Vec<[u32; 3]> = (0..n).map(|f| [f.saturating_sub(1), (f + 1).min(n - 1), (f + n / 2) % n]).collect();
        assert!(scattered(&far));
        // One in ten far: below it.
        let some: Vec<[u32; 3]> = (0..n)
            .map(|f| [f.saturating_sub(1), if f % 10 == 0 { (f + n / 2) % n } else { n }, (f + 1).min(n - 1)])
            .collect();
        assert!(!scattered(&some));
        let padded: Vec<[u32; 3]> = (0..n).map(|_| [n; 3]).collect();
        assert!(!scattered(&padded));
    }

    /// Every face appears once in the order; each face is a seed (the lowest face not yet placed) or a
    /// neighbour of a face placed before it, so each piece's faces are contiguous.
    #[test]
    fn the_breadth_first_order_is_a_permutation() {
        let topology = shuffled_grid(20, 7);
        let geometry = FaceGeometry::compute(&topology);
        let (rows, _) = build_packed(&topology, &geometry, false).expect("packed");
        let order = breadth_first_order(&rows);
        let mut seen = vec![false; rows.len()];
        for (i, &f) in order.face.iter().enumerate() {
            assert!(!std::mem::replace(&mut seen[f as usize], true), "face {f} twice");
            assert_eq!(order.position[f as usize] as usize, i);
        }
        assert!(seen.iter().all(|&s| s));
        let n = rows.len() as u32;
        let mut seeds = 0;
        for (i, &f) in order.face.iter().enumerate() {
            let reached = rows[f as usize].iter().any(|&g| g < n && (order.position[g as usize] as usize) < i);
            let lowest_left = order.face[i..].iter().all(|&h| h >= f);
            assert!(reached || lowest_left, "face {f} at {i} is neither reached nor a seed");
            seeds += usize::from(!reached);
        }
        // The grid, the separate triangle and the degenerate face (no neighbours).
        assert_eq!(seeds, 3);
    }
}
