//! Welded connectivity of one mesh.
//!
//! CAD exporters write every face of a B-rep as its own patch, so a cube arrives as 24 vertices with
//! every edge a "boundary". [`Topology::build`] first welds positions (exactly, or within a tolerance
//! relative to the bounding diagonal), then derives everything else on the welded vertices:
//!
//! * undirected edges with their incident faces (CSR): 1 face = boundary, 2 = manifold, ≥ 3 =
//!   non-manifold;
//! * for each face the ids of its three edges, `v0:v1, v1:v2, v2:v0` (so face↔face adjacency is
//!   `face_edges` then `edge_faces`);
//! * vertex→face adjacency (CSR);
//! * vertex-connected components (faces sharing only a vertex are in one component, as trimesh and
//!   MeshLab count them), numbered in order of their first face;
//! * degenerate triangles: a repeated welded vertex or an exactly zero area.
//!
//! How it is built, and why by hand (this runs on every mesh before every stage, and on a
//! 871k-triangle scan it was slower than the normal enhancement it feeds): welding is one pass in
//! vertex order over an open-addressing hash table of cluster ids; a counting sort lists the
//! corners around each welded vertex (the vertex→face CSR); one walk over the vertices in order
//! then collects each vertex's edges to larger neighbours, a handful, sorts them with a small
//! sorting network and emits them. Nothing is sorted globally and no hash map is touched per edge,
//! so the cost is linear, and the result (edge order included) depends only on the input, never on
//! the hash or the thread count. The degenerate flags and the components (a union-find) run beside
//! the edge walk when rayon has a second thread.
//!
//! Degenerate faces with a repeated welded vertex contribute no edges: their collapsed edge has no
//! direction and their other two edges would only double an existing one. Zero-area faces with three
//! distinct vertices do contribute edges (they still close the surface topologically).

use glam::{DVec3, Vec3};

use crate::Mesh;

/// Marks an edge slot of a face that collapsed to a point after welding.
pub const EDGE_NONE: u32 = u32::MAX;

/// Default grid of [`Weld::Snap`], as a fraction of the bounding diagonal.
pub const DEFAULT_SNAP_FRACTION: f64 = 1e-9;

/// How positions are merged before connectivity is derived.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Weld {
    /// Merge vertices whose coordinates are bit-identical (after mapping -0.0 to 0.0).
    Exact,
    /// Merge vertices whose coordinates round to the same point of a grid with this spacing, as a
    /// fraction of the bounding diagonal (default [`DEFAULT_SNAP_FRACTION`]; a few vertices far
    /// outside the rest do not count, see `snap_scale`). This is "identical
    /// positions" up to float noise: CAD exporters write `2.4e-18` where a neighbouring facet has
    /// `0.0`, and trimesh's `merge_vertices` welds those by rounding too. At 1e-9 the grid is
    /// finer than f32 resolution for every coordinate above 1/60 of the diagonal, so distinct
    /// vertices of a real model never merge. Same cost as `Exact`.
    Snap(f64),
    /// Merge vertices closer than this fraction of the mesh's bounding diagonal (e.g. `1e-6`).
    /// Clustering is greedy in vertex order: a vertex joins the first earlier cluster
    /// representative within the distance, so the result is deterministic.
    Relative(f64),
}

/// Welded connectivity of a mesh. See the module docs.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// For each vertex of the mesh, its welded vertex.
    pub welded_of_vertex: Vec<u32>,
    /// Positions of the welded vertices (the first original vertex of each cluster).
    pub welded_positions: Vec<Vec3>,
    /// The mesh's triangles in welded vertex ids, same order as `Mesh::triangles`.
    pub faces: Vec<[u32; 3]>,
    /// Undirected edges as `[a, b]` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// CSR offsets into `edge_faces`, `edges.len() + 1` entries.
    pub edge_face_offsets: Vec<u32>,
    /// Faces incident to each edge, in increasing face order.
    pub edge_faces: Vec<u32>,
    /// For each face, the edge ids of `v0:v1, v1:v2, v2:v0`; [`EDGE_NONE`] for collapsed edges.
    pub face_edges: Vec<[u32; 3]>,
    /// CSR offsets into `vertex_faces`, `welded_positions.len() + 1` entries.
    pub vertex_face_offsets: Vec<u32>,
    /// Faces around each welded vertex, in increasing face order.
    pub vertex_faces: Vec<u32>,
    /// Vertex-connected component of each face.
    pub face_component: Vec<u32>,
    pub component_count: usize,
    /// Per face: a repeated welded vertex or zero area.
    pub face_degenerate: Vec<bool>,
}

impl Topology {
    /// Welds `mesh` and derives its connectivity.
    pub fn build(mesh: &Mesh, weld: Weld) -> Topology {
        Self::from_triangles(&mesh.positions, &mesh.triangles, weld)
    }

    /// Same as [`Topology::build`] on raw arrays. Indices must be `< positions.len()`.
    pub fn from_triangles(positions: &[Vec3], triangles: &[[u32; 3]], weld: Weld) -> Topology {
        let Welded { of_vertex: welded_of_vertex, positions: welded_positions } = match weld {
            Weld::Exact => weld_exact(positions),
            Weld::Snap(fraction) => weld_snap(positions, fraction),
            Weld::Relative(fraction) => weld_tolerance(positions, fraction),
        };
        let welded_count = welded_positions.len();
        let WeldedFaces { faces, corner_counts, collapsed_faces } =
            weld_faces(triangles, &welded_of_vertex, welded_count);
        // Two independent halves: the degenerate flags and components read only `faces`, the
        // adjacency tables are one chain. Each half is sequential, so the result does not depend on
        // the thread count; with one thread `join` just runs them in turn.
        let ((face_degenerate, (face_component, component_count)), adjacency) = rayon::join(
            || {
                let degenerate = faces.iter().map(|&face| is_degenerate(face, &welded_positions)).collect();
                (degenerate, build_components(welded_count, &faces))
            },
            || build_adjacency(&faces, corner_counts, collapsed_faces),
        );
        let Adjacency { edges, edge_face_offsets, edge_faces, face_edges, vertex_face_offsets, vertex_faces } =
            adjacency;

        Topology {
            welded_of_vertex,
            welded_positions,
            faces,
            edges,
            edge_face_offsets,
            edge_faces,
            face_edges,
            vertex_face_offsets,
            vertex_faces,
            face_component,
            component_count,
            face_degenerate,
        }
    }

    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Faces incident to edge `e`.
    #[inline]
    pub fn faces_of_edge(&self, e: usize) -> &[u32] {
        &self.edge_faces[self.edge_face_offsets[e] as usize..self.edge_face_offsets[e + 1] as usize]
    }

    /// Faces around welded vertex `v`.
    #[inline]
    pub fn faces_of_vertex(&self, v: usize) -> &[u32] {
        &self.vertex_faces[self.vertex_face_offsets[v] as usize..self.vertex_face_offsets[v + 1] as usize]
    }

    /// Number of faces on edge `e`.
    #[inline]
    pub fn edge_valence(&self, e: usize) -> u32 {
        self.edge_face_offsets[e + 1] - self.edge_face_offsets[e]
    }

    /// Faces sharing an edge with face `f` (each neighbour once per shared edge).
    pub fn face_neighbors(&self, f: usize) -> impl Iterator<Item = u32> + '_ {
        self.face_edges[f]
            .into_iter()
            .filter(|&e| e != EDGE_NONE)
            .flat_map(move |e| self.faces_of_edge(e as usize).iter().copied().filter(move |&g| g as usize != f))
    }

    /// Edges with exactly one incident face.
    pub fn boundary_edge_count(&self) -> usize {
        (0..self.edges.len()).filter(|&e| self.edge_valence(e) == 1).count()
    }

    /// Edges with three or more incident faces.
    pub fn nonmanifold_edge_count(&self) -> usize {
        (0..self.edges.len()).filter(|&e| self.edge_valence(e) >= 3).count()
    }

    /// Boundary and non-manifold edge counts in the *incidence* convention of trimesh and MeshLab:
    /// every face corner contributes its edge, collapsed faces included, so a face `(a, a, b)` adds a
    /// self-edge `{a, a}` (seen once: boundary) and two more uses of `{a, b}`. [`Topology::edges`]
    /// leaves collapsed faces out, which is what the geometry stages want; this count is what
    /// other tools report for the same file.
    pub fn incidence_edge_counts(&self) -> (usize, usize) {
        let mut extra: std::collections::BTreeMap<[u32; 2], u32> = Default::default();
        for &[a, b, c] in &self.faces {
            if a == b || b == c || c == a {
                for (u, w) in [(a, b), (b, c), (c, a)] {
                    *extra.entry([u.min(w), u.max(w)]).or_default() += 1;
                }
            }
        }
        let (mut boundary, mut nonmanifold) = (self.boundary_edge_count(), self.nonmanifold_edge_count());
        for (edge, added) in extra {
            let before = self.edges.binary_search(&edge).map_or(0, |e| self.edge_valence(e));
            let after = before + added;
            boundary = boundary + usize::from(after == 1) - usize::from(before == 1);
            nonmanifold = nonmanifold + usize::from(after >= 3) - usize::from(before >= 3);
        }
        (boundary, nonmanifold)
    }

    pub fn degenerate_triangle_count(&self) -> usize {
        self.face_degenerate.iter().filter(|&&d| d).count()
    }

    /// Number of welded vertices referenced by at least one face.
    pub fn referenced_vertex_count(&self) -> usize {
        (0..self.welded_positions.len())
            .filter(|&v| self.vertex_face_offsets[v] != self.vertex_face_offsets[v + 1])
            .count()
    }
}

/// A triangle whose welded vertices repeat, which therefore contributes no edges.
#[inline]
fn is_collapsed([a, b, c]: [u32; 3]) -> bool {
    a == b || b == c || c == a
}

/// A repeated welded vertex or an exactly zero area (in f64, from the welded positions).
#[inline]
fn is_degenerate(face: [u32; 3], welded_positions: &[Vec3]) -> bool {
    if is_collapsed(face) {
        return true;
    }
    let [pa, pb, pc] = face.map(|v| welded_positions[v as usize].as_dvec3());
    (pb - pa).cross(pc - pa) == DVec3::ZERO
}

/// Coordinate bits with -0.0 folded onto 0.0, so that the two zeros weld.
#[inline]
fn weld_key(p: Vec3) -> [u32; 3] {
    p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() })
}

impl Default for Weld {
    fn default() -> Self {
        Weld::Snap(DEFAULT_SNAP_FRACTION)
    }
}

/// Result of a weld: the cluster of each vertex, numbered in order of first occurrence, and the
/// position of each cluster's first vertex.
struct Welded {
    of_vertex: Vec<u32>,
    positions: Vec<Vec3>,
}

fn weld_exact(positions: &[Vec3]) -> Welded {
    weld_by_keys(positions, weld_key, |k| hash_words(k.map(u64::from)))
}

fn weld_snap(positions: &[Vec3], fraction: f64) -> Welded {
    let cell = snap_scale(positions) * fraction.abs();
    if !(cell.is_finite() && cell > 0.0) {
        return weld_exact(positions);
    }
    // Rounding the coordinate itself (not relative to the box) keeps 0.0 at a cell centre, so noise
    // around zero welds.
    weld_by_keys(positions, |p| p.as_dvec3().to_array().map(|c| snap_key(c, cell)), hash_words)
}

/// The cell `c` falls in on a grid of `cell`, as the bits of the rounded quotient (-0.0 folded onto
/// 0.0). Not an integer conversion: a grid fine against the coordinates (a tiny robust diagonal
/// beside far vertices) gives quotients beyond `i64`, where a saturating conversion would put
/// vertices whole units apart in one cell. Distinct `f32` coordinates give distinct quotients on
/// any grid, since `f64` division keeps their relative spacing.
#[inline]
fn snap_key(c: f64, cell: f64) -> u64 {
    let q = (c / cell).round();
    if q == 0.0 || q.is_nan() { 0 } else { q.to_bits() }
}

/// How far the core of a model may be outgrown by its outliers before they stop setting the weld
/// grid (see [`snap_scale`]).
const SNAP_CORE_FACTOR: f64 = 64.0;

/// Vertices sampled (evenly, by index) for the core box of [`snap_scale`].
const SNAP_SAMPLE: usize = 4096;

/// The length the snap grid is a fraction of: the bounding diagonal, unless a few vertices lie far
/// outside the rest. Then the diagonal of the *core* (the box from the 1st to the 99th percentile of
/// each coordinate, at least one value trimmed at each end, over an even sample of at most 4,096
/// vertices), times 64, is used instead. A finer grid never merges what a coarser one kept apart, so
/// this can only leave float noise on the outliers themselves unwelded. One
/// vertex moved to 1e19 would otherwise make the grid 1e10 wide and weld the whole model into a
/// point, and every later stage would pay for that collapse. For a model
/// without such outliers the core spans more than 1/64 of the box and nothing changes.
fn snap_scale(positions: &[Vec3]) -> f64 {
    robust_diagonal(positions)
}

/// The bounding diagonal of `positions`, unless a few lie far outside the rest: then 64 times the
/// diagonal of their core (see [`snap_scale`], which is this). Tolerances that are a fraction of a
/// mesh's size should use it, so that one stray vertex cannot make them huge.
pub fn robust_diagonal(positions: &[Vec3]) -> f64 {
    if positions.is_empty() {
        return 0.0;
    }
    let (lo, hi) =
        positions.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
        });
    let diagonal = (hi - lo).length();
    let step = positions.len().div_ceil(SNAP_SAMPLE).max(1);
    let mut core = DVec3::ZERO;
    for axis in 0..3 {
        let mut values: Vec<f64> = positions.iter().step_by(step).map(|p| p[axis] as f64).collect();
        values.sort_unstable_by(f64::total_cmp);
        // At least one value is trimmed at each end, so that a small mesh has a core too.
        let last = values.len() - 1;
        let trim = (last / 100).max(1).min(last / 2);
        core[axis] = values[last - trim] - values[trim];
    }
    let core = core.length();
    if core.is_finite() && core > 0.0 { diagonal.min(core * SNAP_CORE_FACTOR) } else { diagonal }
}

/// Welds vertices with equal keys; ids in order of first occurrence.
///
/// Written by hand for speed (it was a sort of (key, index) pairs, a quarter of the whole build on
/// large meshes): one pass in vertex order over an open-addressing table (linear probing). A slot
/// holds a cluster id and, in its spare high bits, a tag from the key's hash, so a probe compares
/// keys (recomputed from the cluster's first position) only when the tags agree. A general hash
/// map would store every key again and hash it with a slower general-purpose hasher. The result
/// depends only on the input, not on the hash: a vertex joins the cluster of the first earlier
/// vertex with an equal key, or opens the next cluster. From [`PARTITIONED_WELD_MIN`] vertices,
/// with more than one thread, [`weld_partitioned`] gives the same result on the pool.
fn weld_by_keys<K: Copy + PartialEq + Send + Sync>(
    positions: &[Vec3],
    key_of: impl Fn(Vec3) -> K + Sync,
    hash_of: impl Fn(K) -> u64 + Sync,
) -> Welded {
    if positions.len() >= PARTITIONED_WELD_MIN && rayon::current_num_threads() > 1 {
        return weld_partitioned(positions, &key_of, &hash_of, PARTITION_BITS);
    }
    let n = positions.len();
    // Load factor at most 1/2. A slot is 0 when empty, else `cluster id + 1` in the low `id_bits`
    // and the tag above them (the hash's top bits pick the slot, its low bits make the tag).
    let bits = (2 * n).next_power_of_two().max(16).trailing_zeros();
    let mask = (1usize << bits) - 1;
    let id_bits = u32::BITS - (n as u32).leading_zeros();
    let id_mask = if id_bits >= 32 { u32::MAX } else { (1u32 << id_bits) - 1 };
    let mut table = vec![0u32; 1 << bits];
    let mut cluster_positions: Vec<Vec3> = Vec::with_capacity(n);
    let mut of_vertex = Vec::with_capacity(n);
    for &p in positions {
        let key = key_of(p);
        let hash = hash_of(key);
        let tag = hash as u32 & !id_mask;
        let mut slot = (hash >> (64 - bits)) as usize;
        let id = loop {
            let stored = table[slot];
            if stored == 0 {
                let id = cluster_positions.len() as u32;
                table[slot] = tag | (id + 1);
                cluster_positions.push(p);
                break id;
            }
            let id = (stored & id_mask).wrapping_sub(1);
            if stored & !id_mask == tag && key_of(cluster_positions[id as usize]) == key {
                break id;
            }
            slot = (slot + 1) & mask;
        };
        of_vertex.push(id);
    }
    cluster_positions.shrink_to_fit();
    Welded { of_vertex, positions: cluster_positions }
}

/// From this many vertices, and with more than one thread, [`weld_by_keys`] runs
/// [`weld_partitioned`].
const PARTITIONED_WELD_MIN: usize = 1 << 16;

/// Buckets of [`weld_partitioned`]: `2^bits`.
const PARTITION_BITS: u32 = 8;

/// A vertex of [`weld_partitioned`] with its key's hash and its key.
type Entry<K> = (u32, u64, K);

/// [`weld_by_keys`] on the thread pool, with the same result. Equal keys have equal hashes, so
/// the vertices are first sorted by their hash's top `bits` ([`crate::scatter_in_parallel`]:
/// vertex order within a bucket), then each bucket finds, for each of its vertices, the first
/// earlier vertex with an equal key, over a table of its own that stays in cache; a last pass in
/// vertex order numbers the clusters ([`number_clusters`]). The serial pass probes one table of
/// twice the vertex count at random, which misses the cache more as the mesh grows; here every
/// probe stays in a bucket's small table (docs/bench.md#scaling). It holds each vertex's hash and
/// key twice while it sorts (80 bytes a vertex with the snapped key, against the serial table's 8
/// to 16), which stays far below the peak of the later lines stage.
fn weld_partitioned<K: Copy + PartialEq + Send + Sync>(
    positions: &[Vec3],
    key_of: &(impl Fn(Vec3) -> K + Sync),
    hash_of: &(impl Fn(K) -> u64 + Sync),
    bits: u32,
) -> Welded {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicU32, Ordering};
    let n = positions.len();
    let Some(&first) = positions.first() else { return Welded { of_vertex: Vec::new(), positions: Vec::new() } };
    let buckets = 1usize << bits;
    let bucket_of = |h: u64| (h >> (64 - bits)) as usize;
    // Each key once (the snapped key divides and rounds every coordinate), then the vertices with
    // their hashes and keys in bucket order, vertex order within a bucket.
    let entries: Vec<Entry<K>> = positions
        .par_iter()
        .enumerate()
        .map(|(v, &p)| {
            let key = key_of(p);
            (v as u32, hash_of(key), key)
        })
        .collect();
    let mut sorted = vec![(0u32, 0u64, key_of(first)); n];
    let mut starts = vec![0usize; buckets + 1];
    let chunk = n.div_ceil(4 * rayon::current_num_threads());
    crate::scatter_in_parallel(&entries, |i| bucket_of(entries[i].1), chunk, &mut sorted, &mut starts);
    drop(entries);
    let bucket_slices: Vec<std::ops::Range<usize>> = starts.windows(2).map(|w| w[0]..w[1]).collect();
    // Each vertex's first earlier vertex with an equal key (itself if none), bucket by bucket.
    let representative: Vec<AtomicU32> = (0..n as u32).into_par_iter().map(AtomicU32::new).collect();
    bucket_slices.into_par_iter().for_each(|range| {
        let entries = &sorted[range];
        let table_bits = (2 * entries.len()).next_power_of_two().max(16).trailing_zeros();
        let mask = (1usize << table_bits) - 1;
        // A slot holds an entry's index + 1, 0 when empty; the slot comes from the hash's low bits.
        let mut table = vec![0u32; 1 << table_bits];
        for (i, &(v, h, key)) in entries.iter().enumerate() {
            let mut slot = h as usize & mask;
            loop {
                let stored = table[slot];
                if stored == 0 {
                    table[slot] = i as u32 + 1;
                    break;
                }
                let (first, first_hash, first_key) = entries[stored as usize - 1];
                if first_hash == h && first_key == key {
                    representative[v as usize].store(first, Ordering::Relaxed);
                    break;
                }
                slot = (slot + 1) & mask;
            }
        }
    });
    let representative: Vec<u32> = representative.into_iter().map(AtomicU32::into_inner).collect();
    number_clusters(&representative, positions)
}

/// Multiply-rotate mixing of three key words (FxHash's step, plus a final fold so that the low
/// half, used as a tag, also depends on every input bit).
#[inline]
fn hash_words(words: [u64; 3]) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut h = 0u64;
    for word in words {
        h = (h.rotate_left(23) ^ word).wrapping_mul(K);
    }
    h ^ (h >> 32)
}

/// Turns "representative original vertex" into dense welded ids in order of first occurrence, and
/// the representatives' positions. Requires `representative[v] <= v`.
fn number_clusters(representative: &[u32], positions: &[Vec3]) -> Welded {
    let mut of_vertex = vec![0u32; representative.len()];
    let mut cluster_positions = Vec::new();
    for v in 0..representative.len() {
        let r = representative[v] as usize;
        if r == v {
            of_vertex[v] = cluster_positions.len() as u32;
            cluster_positions.push(positions[v]);
        } else {
            of_vertex[v] = of_vertex[r];
        }
    }
    Welded { of_vertex, positions: cluster_positions }
}

fn weld_tolerance(positions: &[Vec3], fraction: f64) -> Welded {
    // Greedy clustering over a hash grid: a vertex joins the lowest-numbered earlier representative
    // within the distance. Slower than the key-based welds; for explicit tolerances only.
    let mut bounds_min = DVec3::splat(f64::INFINITY);
    let mut bounds_max = DVec3::splat(f64::NEG_INFINITY);
    for p in positions {
        bounds_min = bounds_min.min(p.as_dvec3());
        bounds_max = bounds_max.max(p.as_dvec3());
    }
    let diagonal = if positions.is_empty() { 0.0 } else { (bounds_max - bounds_min).length() };
    let tolerance = fraction.abs() * diagonal;
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return weld_exact(positions);
    }
    let cell_of = |p: DVec3| -> [i64; 3] { ((p - bounds_min) / tolerance).floor().to_array().map(|c| c as i64) };
    let mut grid: std::collections::HashMap<[i64; 3], Vec<u32>> = std::collections::HashMap::new();
    let mut representative = vec![0u32; positions.len()];
    let tolerance_sq = tolerance * tolerance;
    for (v, p) in positions.iter().enumerate() {
        let p = p.as_dvec3();
        let cell = cell_of(p);
        let mut found: Option<u32> = None;
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = grid.get(&[cell[0] + dx, cell[1] + dy, cell[2] + dz]) else { continue };
                    for &r in list {
                        if positions[r as usize].as_dvec3().distance_squared(p) <= tolerance_sq
                            && found.is_none_or(|f| r < f)
                        {
                            found = Some(r);
                        }
                    }
                }
            }
        }
        match found {
            Some(r) => representative[v] = r,
            None => {
                representative[v] = v as u32;
                grid.entry(cell).or_default().push(v as u32);
            }
        }
    }
    number_clusters(&representative, positions)
}

/// The CSR tables of [`Topology`] derived from the welded faces.
struct Adjacency {
    edges: Vec<[u32; 2]>,
    edge_face_offsets: Vec<u32>,
    edge_faces: Vec<u32>,
    face_edges: Vec<[u32; 3]>,
    vertex_face_offsets: Vec<u32>,
    vertex_faces: Vec<u32>,
}

/// The welded faces, and the number of faces around each welded vertex (each face counted once
/// per distinct vertex) in `corner_counts[v + 2]`, the layout [`build_adjacency`] wants.
struct WeldedFaces {
    faces: Vec<[u32; 3]>,
    corner_counts: Vec<u32>,
    collapsed_faces: usize,
}

fn weld_faces(triangles: &[[u32; 3]], welded_of_vertex: &[u32], welded_count: usize) -> WeldedFaces {
    let mut corner_counts = vec![0u32; welded_count + 2];
    let mut collapsed_faces = 0usize;
    let faces = triangles
        .iter()
        .map(|t| {
            let face = t.map(|v| welded_of_vertex[v as usize]);
            let [a, b, c] = face;
            corner_counts[a as usize + 2] += 1;
            if is_collapsed(face) {
                collapsed_faces += 1;
                // A vertex repeated within a collapsed face is listed once.
                corner_counts[b as usize + 2] += u32::from(b != a);
                corner_counts[c as usize + 2] += u32::from(c != a && c != b);
            } else {
                corner_counts[b as usize + 2] += 1;
                corner_counts[c as usize + 2] += 1;
            }
            face
        })
        .collect();
    WeldedFaces { faces, corner_counts, collapsed_faces }
}

/// Vertex→face CSR, then edges by walking it.
///
/// Written by hand for speed (the edge tables were half of the whole build): a counting sort lists
/// the corners `3f + k` around each vertex in face order, once per distinct vertex of a face. Then
/// one walk over the vertices in order collects, for vertex `v`, the face edges `{v, w}` with
/// `w > v` (at most two per corner), sorts that handful by `(w, edge slot)` and emits the edges of
/// `v`, while turning the corners back into face ids. So edges come out sorted by `(a, b)`, faces
/// of an edge ascend, and nothing but the output is allocated per edge.
fn build_adjacency(faces: &[[u32; 3]], corner_counts: Vec<u32>, collapsed_faces: usize) -> Adjacency {
    // Counts are in `offsets[v + 2]`, so that after the prefix sum `offsets[v + 1]` is the start
    // of `v`, used as its fill cursor; after filling it is the end of `v`, i.e. the CSR offset of
    // `v + 1`. The extra entry is dropped.
    let mut offsets = corner_counts;
    let vertex_count = offsets.len() - 2;
    for v in 2..offsets.len() {
        offsets[v] += offsets[v - 1];
    }
    let mut vertex_faces = vec![0u32; offsets[vertex_count + 1] as usize];
    for (f, &face) in faces.iter().enumerate() {
        let [a, b, c] = face;
        let corner = 3 * f as u32;
        let mut put = |v: u32, k: u32| {
            let cursor = &mut offsets[v as usize + 1];
            vertex_faces[*cursor as usize] = corner + k;
            *cursor += 1;
        };
        put(a, 0);
        if !is_collapsed(face) {
            put(b, 1);
            put(c, 2);
        } else {
            if b != a {
                put(b, 1);
            }
            if c != a && c != b {
                put(c, 2);
            }
        }
    }
    offsets.pop();

    // Every corner of a face that is not collapsed is one edge use, so `edge_faces` has exactly
    // `corner_total` entries and there are at most that many edges. The tables are zeroed (pages
    // untouched until written) and written by index, so the loop below has no data-dependent
    // branches, which on a mesh are coin flips.
    let corner_total = 3 * (faces.len() - collapsed_faces);
    let mut edges = vec![[0u32; 2]; corner_total];
    let mut edge_face_offsets = vec![0u32; corner_total + 1];
    let mut edge_faces = vec![0u32; corner_total];
    // Every slot is written: edges below, EDGE_NONE for collapsed faces.
    let mut face_edges = vec![[0u32; 3]; faces.len()];
    // The keys around a vertex: on the stack for all but the rare vertex with more faces.
    let mut small = [u64::MAX; SMALL_KEYS];
    let mut large: Vec<u64> = Vec::new();
    let mut edge_count = 0usize;
    let mut uses = 0usize;
    let mut start = 0usize;
    for (v, &end) in offsets[1..].iter().enumerate() {
        // The faces of a vertex a few steps ahead, read and written below, start loading now.
        if let (Some(&a), Some(&b)) = (offsets.get(v + WALK_PREFETCH_AHEAD), offsets.get(v + WALK_PREFETCH_AHEAD + 1)) {
            for &corner in &vertex_faces[a as usize..b as usize] {
                let f = corner as usize / 3;
                crate::prefetch(&faces[f]);
                crate::prefetch(&face_edges[f]);
            }
        }
        let corners = &mut vertex_faces[start..end as usize];
        start = end as usize;
        let keys: &[u64] = if corners.len() < SMALL_KEYS / 2 {
            small[..8].fill(u64::MAX);
            let len = gather_keys(v as u32, corners, faces, &mut face_edges, &mut small);
            sort_small(&mut small, len);
            &small[..len]
        } else {
            large.clear();
            large.resize((2 * corners.len() + 1).next_power_of_two(), u64::MAX);
            let len = gather_keys(v as u32, corners, faces, &mut face_edges, &mut large);
            large.truncate(len);
            large.sort_unstable();
            &large
        };
        // A new edge starts wherever the other end changes; `edge_face_offsets[edge_count]` is
        // rewritten after every use, so it ends up at the end of the edge.
        let mut last = u32::MAX;
        for (&key, edge_face) in keys.iter().zip(&mut edge_faces[uses..uses + keys.len()]) {
            let other = (key >> 32) as u32;
            let slot = key as u32 as usize;
            edge_count += usize::from(other != last);
            last = other;
            edges[edge_count - 1] = [v as u32, other];
            face_edges[slot / 3][slot % 3] = (edge_count - 1) as u32;
            *edge_face = (slot / 3) as u32;
            uses += 1;
            edge_face_offsets[edge_count] = uses as u32;
        }
    }
    edges.truncate(edge_count);
    edges.shrink_to_fit();
    edge_face_offsets.truncate(edge_count + 1);
    edge_face_offsets.shrink_to_fit();
    Adjacency { edges, edge_face_offsets, edge_faces, face_edges, vertex_face_offsets: offsets, vertex_faces }
}

/// How many vertices ahead the walk of [`build_adjacency`] prefetches the faces (and their edge
/// slots) around a vertex. Where the vertex order scatters a vertex's faces over the face array
/// (the scaling benchmark's subdivision order), every face read would miss the cache; fetched this
/// far ahead, the reads have arrived by the time the walk needs them, and in first-use order the
/// prefetches cost next to nothing (docs/bench.md#scaling). Half the distance did as well.
const WALK_PREFETCH_AHEAD: usize = 16;

/// Room for the keys of a vertex with fewer than `SMALL_KEYS / 2` faces (two keys per face and a
/// spare slot). A power of two, so that masked indices need no bounds checks.
const SMALL_KEYS: usize = 64;

/// Writes `w << 32 | edge slot 3f + k` into `keys` for the edges `{v, w}`, `w > v`, of the faces
/// at the corners around `v`, turns those corners into face ids and returns the number of keys.
/// Collapsed faces contribute nothing and get [`EDGE_NONE`] edges. `keys.len()` must be a power of
/// two above twice the number of corners.
#[inline(always)]
fn gather_keys(
    v: u32,
    corners: &mut [u32],
    faces: &[[u32; 3]],
    face_edges: &mut [[u32; 3]],
    keys: &mut [u64],
) -> usize {
    const NEXT: [usize; 3] = [1, 2, 0];
    const PREV: [usize; 3] = [2, 0, 1];
    let mask = keys.len() - 1;
    let mut len = 0;
    for corner in corners {
        let (f, k) = (*corner as usize / 3, *corner as usize % 3);
        *corner = f as u32;
        let face = faces[f];
        if is_collapsed(face) {
            face_edges[f] = [EDGE_NONE; 3];
            continue;
        }
        // Edge slot k is (v, next), slot k + 2 is (prev, v). Every key is written, and kept
        // (`len` moves past it) only if the other end is larger.
        let (next, prev) = (face[NEXT[k]], face[PREV[k]]);
        keys[len & mask] = u64::from(next) << 32 | (3 * f + k) as u64;
        len += usize::from(next > v);
        keys[len & mask] = u64::from(prev) << 32 | (3 * f + PREV[k]) as u64;
        len += usize::from(prev > v);
    }
    // The slot after the last key may hold a rejected one; the sorting networks need MAX there.
    keys[len & mask] = u64::MAX;
    len
}

/// Sorts `keys[..len]`, the few edges around one vertex (typically 4 to 8); `keys[len..8]` must
/// be `u64::MAX`. Up to 8 keys go through a fixed sorting network of branch-free min/max (Knuth's
/// optimal ones for 4 and 8 inputs): the keys of a mesh are in no useful order, so the branches
/// of an insertion sort would be mispredicted about once per key. (A 16-input network for the
/// rarer longer lists measured no faster than the library sort.)
#[inline]
fn sort_small(keys: &mut [u64], len: usize) {
    // One comparator, written out for every pair so that the network stays in registers.
    macro_rules! network {
        ($n:literal: $(($i:literal, $j:literal)),*) => {{
            let Some(head) = keys.first_chunk_mut::<$n>() else { return };
            let mut a = *head;
            $(
                let (x, y) = (a[$i], a[$j]);
                a[$i] = x.min(y);
                a[$j] = x.max(y);
            )*
            *head = a;
        }};
    }
    match len {
        0..=1 => {}
        2..=4 => network!(4: (0, 1), (2, 3), (0, 2), (1, 3), (1, 2)),
        5..=8 => network!(8: (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7), (0, 1), (2, 3),
                             (4, 5), (6, 7), (2, 4), (3, 5), (1, 4), (3, 6), (1, 2), (3, 4), (5, 6)),
        _ => keys[..len].sort_unstable(),
    }
}

/// Vertex-connected components, numbered in order of their first face.
///
/// Union-find over the welded vertices with the union towards the smaller root, so every parent is
/// at most its child: after the unions, one pass in vertex order makes every vertex point at its
/// root, without further finds. Within a face the first vertex's root follows each union, so all
/// three vertex sets are joined.
fn build_components(vertex_count: usize, faces: &[[u32; 3]]) -> (Vec<u32>, usize) {
    let mut parent: Vec<u32> = (0..vertex_count as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            let grand = parent[parent[x as usize] as usize];
            parent[x as usize] = grand;
            x = grand;
        }
        x
    }
    for &[a, b, c] in faces {
        let mut ra = find(&mut parent, a);
        for v in [b, c] {
            let rv = find(&mut parent, v);
            if rv != ra {
                let (lo, hi) = if ra < rv { (ra, rv) } else { (rv, ra) };
                parent[hi as usize] = lo;
                ra = lo;
            }
        }
    }
    for v in 0..vertex_count {
        parent[v] = parent[parent[v] as usize];
    }
    let mut label = vec![u32::MAX; vertex_count];
    let mut count = 0u32;
    let face_component = faces
        .iter()
        .map(|&[a, _, _]| {
            let root = parent[a as usize] as usize;
            if label[root] == u32::MAX {
                label[root] = count;
                count += 1;
            }
            label[root]
        })
        .collect();
    (face_component, count as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube exported the CAD way: 4 vertices per face, nothing shared.
    fn unwelded_cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let cube = drafter_testkit::generate::unwelded_cube();
        (cube.positions, cube.triangles)
    }

    #[test]
    fn unwelded_cube_welds_to_closed_manifold() {
        let (p, t) = unwelded_cube();
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!(topo.welded_positions.len(), 8);
        assert_eq!(topo.edges.len(), 18);
        assert_eq!(topo.boundary_edge_count(), 0);
        assert_eq!(topo.nonmanifold_edge_count(), 0);
        assert_eq!(topo.component_count, 1);
        assert_eq!(topo.degenerate_triangle_count(), 0);
        // Euler characteristic of a sphere.
        assert_eq!(8 - 18 + 12, 2);
        for f in 0..12 {
            assert_eq!(topo.face_neighbors(f).count(), 3);
        }
    }

    #[test]
    fn negative_zero_welds_with_zero() {
        let p = vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(-0.0, 0.0, 0.0), Vec3::X];
        let topo = Topology::from_triangles(&p, &[], Weld::Exact);
        assert_eq!(topo.welded_of_vertex, vec![0, 0, 1]);
    }

    #[test]
    fn tolerance_weld_merges_near_vertices_only() {
        let p = vec![Vec3::ZERO, Vec3::new(1e-7, 0.0, 0.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.5, 0.0, 0.0)];
        let topo = Topology::from_triangles(&p, &[], Weld::Relative(1e-6));
        assert_eq!(topo.welded_of_vertex, vec![0, 0, 1, 2]);
        let exact = Topology::from_triangles(&p, &[], Weld::Exact);
        assert_eq!(exact.welded_positions.len(), 4);
    }

    #[test]
    fn snap_weld_merges_float_noise_only() {
        let p = vec![Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.5, 2.4e-18, 0.0), Vec3::new(0.5, 1e-4, 0.0), Vec3::ONE];
        let topo = Topology::from_triangles(&p, &[], Weld::default());
        assert_eq!(topo.welded_of_vertex, vec![0, 0, 1, 2]);
    }

    #[test]
    fn a_far_away_vertex_does_not_coarsen_the_snap_grid() {
        // An unwelded cube plus one triangle reaching 1e19 away: the grid follows the cube, so the
        // cube still welds to its 8 corners and the corners stay apart (a grid of 1e-9 of the full
        // diagonal, 1e10 wide, would merge all of them).
        let (mut p, mut t) = unwelded_cube();
        let n = p.len() as u32;
        p.extend([Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1e19, 0.0)]);
        t.push([n, n + 1, n + 2]);
        let topo = Topology::from_triangles(&p, &t, Weld::default());
        assert_eq!(topo.welded_positions.len(), 9);
        assert_eq!(topo.degenerate_triangle_count(), 0);
        // Without outliers the scale is the bounding diagonal.
        assert_eq!(snap_scale(&unwelded_cube().0), 3f64.sqrt());
    }

    #[test]
    fn incidence_counts_include_collapsed_faces() {
        // Two triangles sharing {0,1}, plus a collapsed face (0,0,1): {0,1} becomes non-manifold and
        // the self-edge {0,0} a boundary, as trimesh counts them.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_Y];
        let t = vec![[0, 1, 2], [1, 0, 3], [0, 0, 1]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!((topo.boundary_edge_count(), topo.nonmanifold_edge_count()), (4, 0));
        assert_eq!(topo.incidence_edge_counts(), (5, 1));
    }

    #[test]
    fn nonmanifold_fan_and_boundaries() {
        // Three triangles sharing the edge (0,1).
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::NEG_Y];
        let t = vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!(topo.edges.len(), 7);
        assert_eq!(topo.nonmanifold_edge_count(), 1);
        assert_eq!(topo.boundary_edge_count(), 6);
        assert_eq!(topo.faces_of_edge(0), &[0, 1, 2]);
    }

    #[test]
    fn degenerate_faces_are_counted_and_add_no_edges() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.0, 0.0, 0.0)];
        let t = vec![[0, 1, 2], [0, 0, 1], [0, 1, 3]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!(topo.degenerate_triangle_count(), 2);
        assert_eq!(topo.face_edges[1], [EDGE_NONE; 3]);
        // Face 2 is collinear (zero area) but still contributes edges.
        assert_eq!(topo.edges.len(), 5);
    }

    #[test]
    fn components_join_through_shared_vertices() {
        let p = vec![
            Vec3::ZERO,
            Vec3::X,
            Vec3::Y,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::NEG_Y,
            Vec3::splat(5.0),
            Vec3::splat(6.0),
            Vec3::new(5.0, 6.0, 5.0),
        ];
        let t = vec![[0, 1, 2], [0, 3, 4], [5, 6, 7]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!(topo.component_count, 2);
        assert_eq!(topo.face_component, vec![0, 0, 1]);
    }

    /// Independent recount with a hash map over many random meshes.
    #[test]
    fn edges_match_hashmap_reference() {
        let mut rng = crate::rng::Rng::new(0x2545_f491_4f6c_dd1du64);
        let mut rnd = |m: u32| rng.below(u64::from(m)) as u32;
        for _ in 0..200 {
            let nv = 3 + rnd(30);
            let p: Vec<Vec3> = (0..nv).map(|_| Vec3::new(rnd(4) as f32, rnd(4) as f32, rnd(4) as f32)).collect();
            let t: Vec<[u32; 3]> = (0..rnd(60)).map(|_| [rnd(nv), rnd(nv), rnd(nv)]).collect();
            let topo = Topology::from_triangles(&p, &t, Weld::Exact);
            let mut reference: std::collections::BTreeMap<[u32; 2], Vec<u32>> = Default::default();
            for (f, tri) in topo.faces.iter().enumerate() {
                let [a, b, c] = *tri;
                if a == b || b == c || c == a {
                    continue;
                }
                for (u, w) in [(a, b), (b, c), (c, a)] {
                    reference.entry([u.min(w), u.max(w)]).or_default().push(f as u32);
                }
            }
            assert_eq!(topo.edges, reference.keys().copied().collect::<Vec<_>>());
            for (e, faces) in reference.values().enumerate() {
                assert_eq!(topo.faces_of_edge(e), faces.as_slice());
            }
        }
    }

    /// The tables as a brute-force reading of the module docs would compute them, from given
    /// welded ids: maps instead of counting sorts, a flood fill instead of union-find.
    fn reference_tables(topo: &Topology, triangles: &[[u32; 3]]) {
        let welded_count = topo.welded_positions.len();
        let faces: Vec<[u32; 3]> = triangles.iter().map(|t| t.map(|v| topo.welded_of_vertex[v as usize])).collect();
        assert_eq!(topo.faces, faces);

        let collapsed = |&[a, b, c]: &[u32; 3]| a == b || b == c || c == a;
        let degenerate: Vec<bool> = faces
            .iter()
            .map(|face| {
                let [pa, pb, pc] = face.map(|v| topo.welded_positions[v as usize].as_dvec3());
                collapsed(face) || (pb - pa).cross(pc - pa) == DVec3::ZERO
            })
            .collect();
        assert_eq!(topo.face_degenerate, degenerate);

        let mut uses: std::collections::BTreeMap<[u32; 2], Vec<(usize, usize)>> = Default::default();
        for (f, face) in faces.iter().enumerate() {
            if collapsed(face) {
                continue;
            }
            for k in 0..3 {
                let (u, w) = (face[k], face[(k + 1) % 3]);
                uses.entry([u.min(w), u.max(w)]).or_default().push((f, k));
            }
        }
        assert_eq!(topo.edges, uses.keys().copied().collect::<Vec<_>>());
        let mut face_edges = vec![[EDGE_NONE; 3]; faces.len()];
        let mut edge_face_offsets = vec![0u32];
        let mut edge_faces = Vec::new();
        for (e, list) in uses.values().enumerate() {
            for &(f, k) in list {
                face_edges[f][k] = e as u32;
                edge_faces.push(f as u32);
            }
            edge_face_offsets.push(edge_faces.len() as u32);
        }
        assert_eq!(topo.face_edges, face_edges);
        assert_eq!(topo.edge_face_offsets, edge_face_offsets);
        assert_eq!(topo.edge_faces, edge_faces);

        let mut vertex_face_offsets = vec![0u32];
        let mut vertex_faces = Vec::new();
        for v in 0..welded_count as u32 {
            vertex_faces.extend((0..faces.len() as u32).filter(|&f| faces[f as usize].contains(&v)));
            vertex_face_offsets.push(vertex_faces.len() as u32);
        }
        assert_eq!(topo.vertex_face_offsets, vertex_face_offsets);
        assert_eq!(topo.vertex_faces, vertex_faces);

        // Flood fill over faces sharing a vertex, started from each unlabelled face in order.
        let mut face_component = vec![u32::MAX; faces.len()];
        let mut count = 0;
        for start in 0..faces.len() {
            if face_component[start] != u32::MAX {
                continue;
            }
            face_component[start] = count;
            let mut stack = vec![start];
            while let Some(f) = stack.pop() {
                for g in 0..faces.len() {
                    if face_component[g] == u32::MAX && faces[g].iter().any(|v| faces[f].contains(v)) {
                        face_component[g] = count;
                        stack.push(g);
                    }
                }
            }
            count += 1;
        }
        assert_eq!(topo.face_component, face_component);
        assert_eq!(topo.component_count, count as usize);
    }

    /// Welded ids in order of first occurrence by key, and the first position of each.
    fn reference_weld<K: Ord>(positions: &[Vec3], key: impl Fn(Vec3) -> [K; 3]) -> (Vec<u32>, Vec<Vec3>) {
        let mut ids: std::collections::BTreeMap<[K; 3], u32> = Default::default();
        let mut welded_positions = Vec::new();
        let of_vertex = positions
            .iter()
            .map(|&p| {
                *ids.entry(key(p)).or_insert_with(|| {
                    welded_positions.push(p);
                    welded_positions.len() as u32 - 1
                })
            })
            .collect();
        (of_vertex, welded_positions)
    }

    /// A seeded generator of integers below its argument.
    fn seeded_below(seed: u64) -> impl FnMut(u32) -> u32 {
        let mut rng = crate::rng::Rng::new(seed);
        move |m| rng.below(u64::from(m)) as u32
    }

    /// `count` positions on a grid of `grid` steps of `step` per axis, many repeated; one in eight
    /// with a negated x (so -0.0 against 0.0), one in eight with `noise` added to y.
    fn grid_positions(rnd: &mut impl FnMut(u32) -> u32, count: u32, grid: u32, step: f32, noise: f32) -> Vec<Vec3> {
        (0..count)
            .map(|_| {
                let mut c = [0.0f32; 3].map(|_| rnd(grid) as f32 * step);
                match rnd(8) {
                    0 => c[0] = -c[0],
                    1 => c[1] += noise,
                    _ => {}
                }
                Vec3::from(c)
            })
            .collect()
    }

    /// Random meshes with duplicated positions (also -0.0 against 0.0 and snap-sized noise),
    /// unreferenced vertices, repeated indices, zero-area and non-manifold faces, against
    /// [`reference_tables`] and [`reference_weld`], for every weld.
    #[test]
    fn every_table_matches_a_brute_force_reference() {
        let mut rnd = seeded_below(0x9e37_79b9_7f4a_7c15);
        for _ in 0..400 {
            let nv = 1 + rnd(40);
            let grid = 1 + rnd(4);
            let positions = grid_positions(&mut rnd, nv, grid, 1.0, 1e-12);
            let triangles: Vec<[u32; 3]> = (0..rnd(60)).map(|_| [rnd(nv), rnd(nv), rnd(nv)]).collect();

            let exact = Topology::from_triangles(&positions, &triangles, Weld::Exact);
            let expected = reference_weld(&positions, |p| weld_key(p).map(i64::from));
            assert_eq!((&exact.welded_of_vertex, &exact.welded_positions), (&expected.0, &expected.1));
            reference_tables(&exact, &triangles);

            let snap = Topology::from_triangles(&positions, &triangles, Weld::default());
            let cell = robust_diagonal(&positions) * DEFAULT_SNAP_FRACTION;
            let expected = if cell > 0.0 {
                // Cells as exact integers (`i128` holds every quotient of these coordinates).
                reference_weld(&positions, |p| p.as_dvec3().to_array().map(|c| (c / cell).round() as i128))
            } else {
                reference_weld(&positions, |p| weld_key(p).map(i128::from))
            };
            assert_eq!((&snap.welded_of_vertex, &snap.welded_positions), (&expected.0, &expected.1));
            reference_tables(&snap, &triangles);

            reference_tables(&Topology::from_triangles(&positions, &triangles, Weld::Relative(0.3)), &triangles);
        }
    }

    /// A grid fine against the coordinates: four vertices whose core spans 1e-12 (so the snap cell
    /// is 6.4e-20) two units apart in x. Their cells lie beyond `i64`; they must stay apart.
    #[test]
    fn a_grid_finer_than_the_coordinates_welds_nothing_apart() {
        let positions = [[2.0, 0.0, 0.0], [2.0, 0.0, 1.0], [3.0, 1e-12, 1.0], [1.0, 1e-12, 1.0]].map(Vec3::from_array);
        let topology = Topology::from_triangles(&positions, &[[0, 1, 2], [0, 2, 3]], Weld::default());
        assert_eq!(topology.welded_of_vertex, [0, 1, 2, 3]);
    }

    /// The partitioned weld against the serial reference, on random positions with many repeats
    /// (also -0.0 and snap-sized noise), with 1 to 10 bucket bits (many vertices per bucket, and
    /// more buckets than vertices), exact and snapped keys.
    #[test]
    fn partitioned_weld_is_the_serial_weld() {
        let mut rnd = seeded_below(0x2545_f491_4f6c_dd1d);
        for round in 0..60 {
            let nv = 1 + rnd(if round % 10 == 0 { 70_000 } else { 3000 });
            let grid = 1 + rnd(20);
            let positions = grid_positions(&mut rnd, nv, grid, 0.25, 1e-6);
            for bits in [1, 3, 10] {
                let exact = weld_partitioned(&positions, &weld_key, &|k: [u32; 3]| hash_words(k.map(u64::from)), bits);
                let expected = reference_weld(&positions, |p| weld_key(p).map(i64::from));
                assert_eq!((&exact.of_vertex, &exact.positions), (&expected.0, &expected.1), "exact, {nv} vertices");
                let key = |p: Vec3| p.as_dvec3().to_array().map(|c| snap_key(c, 0.01));
                let snapped = weld_partitioned(&positions, &key, &hash_words, bits);
                let expected =
                    reference_weld(&positions, |p| p.as_dvec3().to_array().map(|c| (c / 0.01).round() as i64));
                assert_eq!((&snapped.of_vertex, &snapped.positions), (&expected.0, &expected.1), "snapped");
            }
        }
    }

    /// By the 0-1 principle a comparator network sorts everything if it sorts every 0/1 input.
    #[test]
    fn sorting_networks_sort_every_zero_one_input() {
        for len in 0..=16 {
            for bits in 0u32..1 << len.min(12) {
                let mut keys = [u64::MAX; SMALL_KEYS];
                for (i, key) in keys[..len].iter_mut().enumerate() {
                    // Distinct keys, as in the walk: the 0/1 value on top, the index below.
                    *key = u64::from(bits >> i & 1) << 32 | i as u64;
                }
                let mut expected = keys[..len].to_vec();
                expected.sort_unstable();
                sort_small(&mut keys, len);
                assert_eq!(keys[..len], expected[..], "len {len}, input {bits:b}");
            }
        }
    }

    /// A face whose second vertex's set has a smaller root than the first's, and whose third's has
    /// a smaller one still, must join all three sets (an earlier union-find joined only two).
    #[test]
    fn components_join_all_three_vertex_sets_of_a_face() {
        let p: Vec<Vec3> = (0..8).map(|i| Vec3::new(i as f32, (i * i) as f32, 0.0)).collect();
        let t = vec![[7, 6, 0], [3, 4, 6], [0, 1, 7]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        assert_eq!(topo.component_count, 1);
        assert_eq!(topo.face_component, vec![0, 0, 0]);
    }

    /// The same tables whatever the thread count, also on a mesh large enough for rayon to split.
    #[test]
    fn result_does_not_depend_on_the_thread_count() {
        let n = 300u32;
        let positions: Vec<Vec3> =
            (0..n * n).map(|i| Vec3::new((i % n) as f32, (i / n) as f32, ((i * 7919) % 13) as f32)).collect();
        let mut triangles = Vec::new();
        for y in 0..n - 1 {
            for x in 0..n - 1 {
                let v = y * n + x;
                triangles.push([v, v + 1, v + n]);
                triangles.push([v + 1, v + n + 1, v + n]);
            }
        }
        // Duplicates of existing positions used by a face, a third face on an edge and a collapsed
        // face.
        let mut positions = positions;
        positions.extend_from_within(0..500);
        triangles.push([n * n, n * n + 1, n * n + 2]);
        triangles.push([1, n, 2 * n + 5]);
        triangles.push([5, 5, 6]);
        let build = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool");
            pool.install(|| Topology::from_triangles(&positions, &triangles, Weld::default()))
        };
        let one = build(1);
        reference_edges_only(&one);
        for threads in [2, 4] {
            let other = build(threads);
            assert_eq!(one.welded_of_vertex, other.welded_of_vertex);
            assert_eq!(one.edges, other.edges);
            assert_eq!(one.edge_face_offsets, other.edge_face_offsets);
            assert_eq!(one.edge_faces, other.edge_faces);
            assert_eq!(one.face_edges, other.face_edges);
            assert_eq!(one.vertex_face_offsets, other.vertex_face_offsets);
            assert_eq!(one.vertex_faces, other.vertex_faces);
            assert_eq!(one.face_component, other.face_component);
            assert_eq!(one.face_degenerate, other.face_degenerate);
        }
    }

    /// Edges sorted and each face's edges containing the face (a cheap check on a big mesh).
    fn reference_edges_only(topo: &Topology) {
        assert!(topo.edges.windows(2).all(|w| w[0] < w[1]));
        for (f, ids) in topo.face_edges.iter().enumerate() {
            for &e in ids.iter().filter(|&&e| e != EDGE_NONE) {
                assert!(topo.faces_of_edge(e as usize).contains(&(f as u32)));
            }
        }
    }
}
