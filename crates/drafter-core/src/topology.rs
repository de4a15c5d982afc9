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
//! How it is built, and why by hand: exact welding sorts vertex indices by their coordinate bits;
//! edges are bucketed by their smaller vertex (a counting sort) and each bucket, a handful of
//! entries, is sorted by the other vertex. No hash map is touched per edge, so the cost is linear
//! apart from the weld sort, and the result (edge order included) depends only on the input.
//!
//! Degenerate faces with a repeated welded vertex contribute no edges: their collapsed edge has no
//! direction and their other two edges would only double an existing one. Zero-area faces with three
//! distinct vertices do contribute edges (they still close the surface topologically).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::Mesh;

/// Marks an edge slot of a face that collapsed to a point after welding.
pub const EDGE_NONE: u32 = u32::MAX;

/// Default grid of [`Weld::Snap`], as a fraction of the bounding diagonal.
pub const DEFAULT_SNAP_FRACTION: f64 = 1e-9;

/// How positions are merged before connectivity is derived.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Weld {
    /// Merge vertices whose coordinates are bit-identical (after mapping -0.0 to 0.0).
    Exact,
    /// Merge vertices whose coordinates round to the same point of a grid with this spacing, as a
    /// fraction of the bounding diagonal (default [`DEFAULT_SNAP_FRACTION`]). This is "identical
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
        let welded_of_vertex = match weld {
            Weld::Exact => weld_exact(positions),
            Weld::Snap(fraction) => weld_snap(positions, fraction),
            Weld::Relative(fraction) => weld_tolerance(positions, fraction),
        };
        let welded_count = welded_of_vertex.iter().map(|&w| w as usize + 1).max().unwrap_or(0);
        let mut welded_positions = vec![Vec3::ZERO; welded_count];
        // Walk backwards so the first original vertex of each cluster wins.
        for (v, &w) in welded_of_vertex.iter().enumerate().rev() {
            welded_positions[w as usize] = positions[v];
        }
        let faces: Vec<[u32; 3]> = triangles.par_iter().map(|t| t.map(|v| welded_of_vertex[v as usize])).collect();
        let face_degenerate: Vec<bool> = faces
            .par_iter()
            .map(|&[a, b, c]| {
                if a == b || b == c || c == a {
                    return true;
                }
                let pa = welded_positions[a as usize].as_dvec3();
                let pb = welded_positions[b as usize].as_dvec3();
                let pc = welded_positions[c as usize].as_dvec3();
                (pb - pa).cross(pc - pa) == DVec3::ZERO
            })
            .collect();

        let (edges, edge_face_offsets, edge_faces, face_edges) = build_edges(welded_count, &faces);
        let (vertex_face_offsets, vertex_faces) = build_vertex_faces(welded_count, &faces);
        let (face_component, component_count) = build_components(welded_count, &faces);

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

fn weld_exact(positions: &[Vec3]) -> Vec<u32> {
    let keys: Vec<[u32; 3]> = positions.par_iter().map(|&p| weld_key(p)).collect();
    weld_by_keys(&keys)
}

fn weld_snap(positions: &[Vec3], fraction: f64) -> Vec<u32> {
    let (lo, hi) =
        positions.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
            (lo.min(p.as_dvec3()), hi.max(p.as_dvec3()))
        });
    let cell = if positions.is_empty() { 0.0 } else { (hi - lo).length() * fraction.abs() };
    if !(cell.is_finite() && cell > 0.0) {
        return weld_exact(positions);
    }
    // Rounding the coordinate itself (not relative to the box) keeps 0.0 at a cell centre, so noise
    // around zero welds.
    let keys: Vec<[i64; 3]> =
        positions.par_iter().map(|p| p.as_dvec3().to_array().map(|c| (c / cell).round() as i64)).collect();
    weld_by_keys(&keys)
}

/// Welds vertices with equal keys; ids in order of first occurrence.
fn weld_by_keys<K: Ord + Copy + Send + Sync>(keys: &[K]) -> Vec<u32> {
    let n = keys.len();
    let mut order: Vec<(K, u32)> = keys.par_iter().enumerate().map(|(i, &k)| (k, i as u32)).collect();
    // Unique (key, index) pairs: the unstable sort is deterministic.
    order.par_sort_unstable();
    let mut representative = vec![0u32; n];
    let mut start = 0;
    while start < n {
        let key = order[start].0;
        let first = order[start].1;
        let mut end = start;
        while end < n && order[end].0 == key {
            representative[order[end].1 as usize] = first;
            end += 1;
        }
        start = end;
    }
    number_clusters(&representative)
}

/// Turns "representative original vertex" into dense welded ids in order of first occurrence.
/// Requires `representative[v] <= v`.
fn number_clusters(representative: &[u32]) -> Vec<u32> {
    let mut id = vec![0u32; representative.len()];
    let mut next = 0u32;
    for v in 0..representative.len() {
        let r = representative[v] as usize;
        if r == v {
            id[v] = next;
            next += 1;
        } else {
            id[v] = id[r];
        }
    }
    id
}

fn weld_tolerance(positions: &[Vec3], fraction: f64) -> Vec<u32> {
    // Greedy clustering over a hash grid: a vertex joins the lowest-numbered earlier representative
    // within the distance. Slower than the sort-based welds; for explicit tolerances only.
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
    number_clusters(&representative)
}

type EdgeTables = (Vec<[u32; 2]>, Vec<u32>, Vec<u32>, Vec<[u32; 3]>);

fn build_edges(vertex_count: usize, faces: &[[u32; 3]]) -> EdgeTables {
    // Counting sort of corners (f*3+k) by the smaller vertex of their edge.
    let mut bucket_offsets = vec![0u32; vertex_count + 1];
    let collapsed = |a: u32, b: u32, c: u32| a == b || b == c || c == a;
    for &[a, b, c] in faces {
        if collapsed(a, b, c) {
            continue;
        }
        bucket_offsets[a.min(b) as usize + 1] += 1;
        bucket_offsets[b.min(c) as usize + 1] += 1;
        bucket_offsets[c.min(a) as usize + 1] += 1;
    }
    for v in 0..vertex_count {
        bucket_offsets[v + 1] += bucket_offsets[v];
    }
    let corner_total = bucket_offsets[vertex_count] as usize;
    // Each entry: (larger vertex, corner).
    let mut entries = vec![(0u32, 0u32); corner_total];
    let mut cursor = bucket_offsets.clone();
    for (f, &[a, b, c]) in faces.iter().enumerate() {
        if collapsed(a, b, c) {
            continue;
        }
        for (k, (u, w)) in [(a, b), (b, c), (c, a)].into_iter().enumerate() {
            let slot = &mut cursor[u.min(w) as usize];
            entries[*slot as usize] = (u.max(w), (f * 3 + k) as u32);
            *slot += 1;
        }
    }
    // Sort within each bucket (tiny) by (other vertex, corner): corners ascend, so faces ascend.
    let bucket_ranges: Vec<(usize, usize)> =
        (0..vertex_count).map(|v| (bucket_offsets[v] as usize, bucket_offsets[v + 1] as usize)).collect();
    {
        let mut rest: &mut [(u32, u32)] = &mut entries;
        let mut slices: Vec<&mut [(u32, u32)]> = Vec::with_capacity(vertex_count);
        for &(s, e) in &bucket_ranges {
            let (head, tail) = rest.split_at_mut(e - s);
            slices.push(head);
            rest = tail;
        }
        slices.par_iter_mut().with_min_len(4096).for_each(|s| s.sort_unstable());
    }
    let mut edges = Vec::with_capacity(corner_total / 2 + 1);
    let mut edge_face_offsets = Vec::with_capacity(corner_total / 2 + 2);
    let mut edge_faces = Vec::with_capacity(corner_total);
    let mut face_edges = vec![[EDGE_NONE; 3]; faces.len()];
    edge_face_offsets.push(0u32);
    for (v, &(s, e)) in bucket_ranges.iter().enumerate() {
        let mut i = s;
        while i < e {
            let other = entries[i].0;
            let edge_id = edges.len() as u32;
            edges.push([v as u32, other]);
            while i < e && entries[i].0 == other {
                let corner = entries[i].1 as usize;
                let face = (corner / 3) as u32;
                face_edges[corner / 3][corner % 3] = edge_id;
                // A face appears at most once per edge unless it is collapsed (excluded above).
                edge_faces.push(face);
                i += 1;
            }
            edge_face_offsets.push(edge_faces.len() as u32);
        }
    }
    (edges, edge_face_offsets, edge_faces, face_edges)
}

fn build_vertex_faces(vertex_count: usize, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; vertex_count + 1];
    for tri in faces {
        for (k, &v) in tri.iter().enumerate() {
            // A vertex repeated within a degenerate face is listed once.
            if tri[..k].contains(&v) {
                continue;
            }
            offsets[v as usize + 1] += 1;
        }
    }
    for v in 0..vertex_count {
        offsets[v + 1] += offsets[v];
    }
    let mut cursor = offsets.clone();
    let mut list = vec![0u32; offsets[vertex_count] as usize];
    for (f, tri) in faces.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            if tri[..k].contains(&v) {
                continue;
            }
            list[cursor[v as usize] as usize] = f as u32;
            cursor[v as usize] += 1;
        }
    }
    (offsets, list)
}

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
        let ra = find(&mut parent, a);
        for v in [b, c] {
            let rv = find(&mut parent, v);
            if rv != ra {
                // Union towards the smaller root keeps the structure deterministic.
                let (lo, hi) = if ra < rv { (ra, rv) } else { (rv, ra) };
                parent[hi as usize] = lo;
            }
        }
    }
    let mut label = vec![u32::MAX; vertex_count];
    let mut count = 0u32;
    let mut face_component = Vec::with_capacity(faces.len());
    for &[a, _, _] in faces {
        let root = find(&mut parent, a) as usize;
        if label[root] == u32::MAX {
            label[root] = count;
            count += 1;
        }
        face_component.push(label[root]);
    }
    (face_component, count as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube exported the CAD way: 4 vertices per face, nothing shared.
    fn unwelded_cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for axis in 0..3 {
            for side in [0.0f32, 1.0] {
                let base = positions.len() as u32;
                for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                    let mut p = [0.0f32; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    positions.push(Vec3::from(p));
                }
                if side == 0.0 {
                    triangles.push([base, base + 2, base + 1]);
                    triangles.push([base, base + 3, base + 2]);
                } else {
                    triangles.push([base, base + 1, base + 2]);
                    triangles.push([base, base + 2, base + 3]);
                }
            }
        }
        (positions, triangles)
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
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = |m: u32| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % m as u64) as u32
        };
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
}
