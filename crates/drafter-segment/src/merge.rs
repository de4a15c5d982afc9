//! Merging small parts of one mesh's segmentation into a touching neighbour. The rule is in the
//! crate docs ("What is merged, and why").

use drafter_core::{Aabb, EDGE_NONE, Topology};
use glam::{DVec3, UVec3};
use rayon::prelude::*;

use crate::connect::Labelling;
use crate::geometry::closest_point_on_triangle;
use crate::union_find::UnionFind;

/// Thresholds of a merge, in absolute units of the mesh.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MergeLimits {
    /// A part is small when it has fewer triangles than this...
    pub(crate) max_triangles: f64,
    /// ...and its bounding-box diagonal is below this.
    pub(crate) max_diagonal: f64,
    /// Two parts touch where a free-boundary vertex of one is within this distance of a triangle
    /// of the other.
    pub(crate) touch_distance: f64,
    /// Through near-only contacts, a part takes in at most this fraction of its core component.
    pub(crate) max_absorbed: f64,
}

/// What a merge did.
#[derive(Clone, Debug, Default)]
pub(crate) struct MergeOutcome {
    pub(crate) labels: Vec<u32>,
    pub(crate) count: u32,
    /// Small parts that joined a neighbour.
    pub(crate) merged: usize,
    /// Small parts that touch nothing.
    pub(crate) untouched: usize,
    /// Small parts that touch only neighbours too small (or too full) to take them.
    pub(crate) kept: usize,
}

/// A set of labels being merged, stored at its union-find root.
#[derive(Clone, Copy)]
struct Group {
    triangles: u64,
    bounds: Aabb,
    /// Triangles of the label the group grew from (its largest).
    core: u64,
}

impl Group {
    fn absorbed(&self) -> u64 {
        self.triangles - self.core
    }
}

/// A closed label is a solid when its enclosed volume exceeds this fraction of its box diagonal
/// cubed (a cube has 0.19; two coincident triangles facing apart have 0).
const SOLID_VOLUME_FRACTION: f64 = 1e-6;

fn triangle_points(topo: &Topology, f: usize) -> [DVec3; 3] {
    topo.faces[f].map(|v| topo.welded_positions[v as usize].as_dvec3())
}

/// Merges the small labels of `labelling` into touching neighbours; see the crate docs.
pub(crate) fn merge_small(topo: &Topology, labelling: &Labelling, limits: &MergeLimits) -> MergeOutcome {
    let labels = &labelling.labels[..];
    let k = labelling.count as usize;
    let unchanged = || MergeOutcome { labels: labels.to_vec(), count: labelling.count, ..MergeOutcome::default() };
    if k < 2 {
        return unchanged();
    }
    let mut groups = vec![Group { triangles: 0, bounds: Aabb::EMPTY, core: 0 }; k];
    for (f, &l) in labels.iter().enumerate() {
        let g = &mut groups[l as usize];
        g.triangles += 1;
        g.core += 1;
        for p in triangle_points(topo, f) {
            g.bounds.extend(p);
        }
    }
    let is_small = |g: &Group| (g.triangles as f64) < limits.max_triangles && g.bounds.diagonal() < limits.max_diagonal;
    // Closed surfaces that enclose a volume are solids, parts in their own right whatever their
    // size. Volumes are summed about each label's box centre to keep the sums small.
    let mut volume = vec![0.0f64; k];
    for (f, &l) in labels.iter().enumerate() {
        let b = &groups[l as usize].bounds;
        let centre = (b.min + b.max) * 0.5;
        let [p, q, r] = triangle_points(topo, f).map(|p| p - centre);
        volume[l as usize] += p.dot(q.cross(r)) / 6.0;
    }
    let solid =
        |c: usize| !labelling.open[c] && volume[c].abs() > SOLID_VOLUME_FRACTION * groups[c].bounds.diagonal().powi(3);
    let small: Vec<bool> = (0..k).map(|c| is_small(&groups[c]) && !solid(c)).collect();
    if !small.iter().any(|&s| s) {
        return unchanged();
    }
    let probes = boundary_probes(topo, labelling, &small);
    let (shared, near) = probe_contacts(topo, labels, &probes, limits.touch_distance);
    // Probes are sorted by label: those of label c are probe_offsets[c]..probe_offsets[c + 1].
    let mut probe_offsets = vec![0u32; k + 1];
    for &(c, _) in &probes {
        probe_offsets[c as usize + 1] += 1;
    }
    for c in 0..k {
        probe_offsets[c + 1] += probe_offsets[c];
    }

    let mut order: Vec<u32> = (0..k as u32).filter(|&c| small[c as usize]).collect();
    order.sort_by_key(|&c| (groups[c as usize].triangles, c));
    let mut uf = UnionFind::new(k);
    let mut outcome = MergeOutcome::default();
    let mut votes = Vec::new();
    for c in order {
        let root = uf.find(c);
        let group = groups[root as usize];
        if !is_small(&group) {
            continue;
        }
        let probe_range = probe_offsets[c as usize]..probe_offsets[c as usize + 1];
        // A shared welded vertex is strong evidence of one surface: join without a cap.
        tally(&shared, probe_range.clone(), &mut uf, root, &mut votes);
        let mut best = choose(&votes, &groups, |_| true);
        if best.is_none() {
            // Only near: join a neighbour that stays within its absorption cap.
            tally(&near, probe_range, &mut uf, root, &mut votes);
            if votes.is_empty() {
                outcome.untouched += 1;
                continue;
            }
            best = choose(&votes, &groups, |target| {
                (target.absorbed() + group.triangles) as f64 <= limits.max_absorbed * target.core as f64
            });
        }
        let Some(target) = best else {
            outcome.kept += 1;
            continue;
        };
        let t = groups[target as usize];
        let joined = Group {
            triangles: t.triangles + group.triangles,
            bounds: t.bounds.union(&group.bounds),
            core: t.core.max(group.core),
        };
        let new_root = uf.union(root, target);
        groups[new_root as usize] = joined;
        outcome.merged += 1;
    }
    // Renumber in order of first triangle.
    let (new_of, count) = uf.relabel_by_first(labels);
    outcome.labels = labels.iter().map(|&l| new_of[l as usize]).collect();
    outcome.count = count;
    outcome
}

/// The groups (other than `root`) touched by the probes in `probes`, one vote per probe and group,
/// sorted.
fn tally(contacts: &Contacts, probes: std::ops::Range<u32>, uf: &mut UnionFind, root: u32, votes: &mut Vec<u32>) {
    votes.clear();
    let mut touched = Vec::new();
    for p in probes {
        touched.clear();
        touched.extend(contacts_of(contacts, p).iter().map(|&m| uf.find(m)).filter(|&r| r != root));
        touched.sort_unstable();
        touched.dedup();
        votes.extend_from_slice(&touched);
    }
    votes.sort_unstable();
}

/// Among the voted groups that `allowed` accepts: the most votes, then the most triangles, then
/// the lowest root.
fn choose(votes: &[u32], groups: &[Group], allowed: impl Fn(&Group) -> bool) -> Option<u32> {
    let mut best: Option<(usize, u64, u32)> = None;
    for run in votes.chunk_by(|a, b| a == b) {
        let r = run[0];
        let target = &groups[r as usize];
        if !allowed(target) {
            continue;
        }
        let key = (run.len(), target.triangles);
        if best.is_none_or(|(n, size, _)| key > (n, size)) {
            best = Some((key.0, key.1, r));
        }
    }
    best.map(|b| b.2)
}

/// Points that probe where each small label touches its neighbours: the welded vertices on its
/// free edges (boundary edges and unpaired non-manifold edges), or all its vertices when it has
/// none. Sorted `(label, vertex)` pairs.
fn boundary_probes(topo: &Topology, labelling: &Labelling, small: &[bool]) -> Vec<(u32, u32)> {
    let mut probes = Vec::new();
    let mut has_free = vec![false; small.len()];
    for (f, &l) in labelling.labels.iter().enumerate() {
        if !small[l as usize] {
            continue;
        }
        let tri = topo.faces[f];
        for (i, &e) in topo.face_edges[f].iter().enumerate() {
            if e == EDGE_NONE {
                continue;
            }
            if topo.edge_valence(e as usize) == 1
                || labelling.unpaired_edges.binary_search(&e).is_ok()
                || labelling.partial_edges.binary_search(&e).is_ok()
            {
                probes.push((l, tri[i]));
                probes.push((l, tri[(i + 1) % 3]));
                has_free[l as usize] = true;
            }
        }
    }
    for (f, &l) in labelling.labels.iter().enumerate() {
        if small[l as usize] && !has_free[l as usize] {
            probes.extend(topo.faces[f].iter().map(|&v| (l, v)));
        }
    }
    probes.par_sort_unstable();
    probes.dedup();
    probes
}

/// Contact lists as CSR: `offsets[c]..offsets[c + 1]` into `targets`.
struct Contacts {
    offsets: Vec<u32>,
    targets: Vec<u32>,
}

fn contacts_of(contacts: &Contacts, c: u32) -> &[u32] {
    &contacts.targets[contacts.offsets[c as usize] as usize..contacts.offsets[c as usize + 1] as usize]
}

fn contacts_from_pairs(k: usize, mut pairs: Vec<(u32, u32)>) -> Contacts {
    pairs.par_sort_unstable();
    pairs.dedup();
    let mut offsets = vec![0u32; k + 1];
    for &(a, _) in &pairs {
        offsets[a as usize + 1] += 1;
    }
    for i in 0..k {
        offsets[i + 1] += offsets[i];
    }
    Contacts { offsets, targets: pairs.into_iter().map(|(_, b)| b).collect() }
}

/// A fold of the contact search deduplicates its pairs from this many on (2^20, 8 MB).
const DEDUP_FROM: usize = 1 << 20;

/// Largest number of grid cells per axis of the contact search.
const GRID_CELLS_PER_AXIS: f64 = 64.0;

/// For each probe `(label, vertex)`, the other labels that touch its vertex: those that use the
/// same welded vertex, and those with a triangle within `tol` of it (found by testing every
/// triangle against a uniform grid of the probes, at most 64 cells per axis).
fn probe_contacts(topo: &Topology, labels: &[u32], probes: &[(u32, u32)], tol: f64) -> (Contacts, Contacts) {
    let mut shared: Vec<(u32, u32)> = Vec::new();
    for (i, &(l, v)) in probes.iter().enumerate() {
        for &g in topo.faces_of_vertex(v as usize) {
            let m = labels[g as usize];
            if m != l {
                shared.push((i as u32, m));
            }
        }
    }
    let mut pairs = Vec::new();
    let point = |i: usize| topo.welded_positions[probes[i].1 as usize].as_dvec3();
    let mut region = Aabb::EMPTY;
    for i in 0..probes.len() {
        region.extend(point(i));
    }
    if !region.is_empty() {
        region.min -= tol;
        region.max += tol;
        let size = region.max - region.min;
        let cell = (size.max_element() / GRID_CELLS_PER_AXIS).max(tol).max(f64::MIN_POSITIVE);
        let dims = (size / cell).ceil().max(DVec3::ONE).as_uvec3();
        let cell_count = (dims.x * dims.y * dims.z) as usize;
        let cell_of = |p: DVec3| ((p - region.min) / cell).floor().max(DVec3::ZERO).as_uvec3().min(dims - 1);
        let index = |c: UVec3| ((c.z * dims.y + c.y) * dims.x + c.x) as usize;
        // Counting sort of the probes into cells.
        let mut offsets = vec![0u32; cell_count + 1];
        for i in 0..probes.len() {
            offsets[index(cell_of(point(i))) + 1] += 1;
        }
        for c in 0..cell_count {
            offsets[c + 1] += offsets[c];
        }
        let mut cursor = offsets.clone();
        let mut entries = vec![0u32; probes.len()];
        for i in 0..probes.len() {
            let c = index(cell_of(point(i)));
            entries[cursor[c] as usize] = i as u32;
            cursor[c] += 1;
        }
        let tol2 = tol * tol;
        // Each fold's pairs are sorted and deduplicated whenever they have doubled since the last
        // time (from 2^20 on): every triangle of a label near a probe finds it again, and a dense
        // cluster (probes within the tolerance of thousands of triangles of a few hundred labels)
        // would otherwise hold one pair per probe and triangle, gigabytes for an input of a few
        // hundred kilobytes (`tests/regressions/obj/dense-cluster-of-strips.obj`).
        let spatial: Vec<(u32, u32)> = (0..labels.len())
            .into_par_iter()
            .with_min_len(4096)
            .fold(
                || (Vec::new(), DEDUP_FROM),
                |(mut out, mut dedup_at): (Vec<(u32, u32)>, usize), f| {
                    if out.len() >= dedup_at {
                        out.sort_unstable();
                        out.dedup();
                        dedup_at = (2 * out.len()).max(DEDUP_FROM);
                    }
                    let t = triangle_points(topo, f);
                    let grown = Aabb { min: t[0].min(t[1]).min(t[2]) - tol, max: t[0].max(t[1]).max(t[2]) + tol };
                    if !(grown.min.cmple(region.max).all() && region.min.cmple(grown.max).all()) {
                        return (out, dedup_at);
                    }
                    let (lo, hi) = (cell_of(grown.min), cell_of(grown.max));
                    let lf = labels[f];
                    for z in lo.z..=hi.z {
                        for y in lo.y..=hi.y {
                            for x in lo.x..=hi.x {
                                let c = index(UVec3::new(x, y, z));
                                for &i in &entries[offsets[c] as usize..offsets[c + 1] as usize] {
                                    if probes[i as usize].0 == lf {
                                        continue;
                                    }
                                    let p = point(i as usize);
                                    if grown.min.cmple(p).all()
                                        && p.cmple(grown.max).all()
                                        && closest_point_on_triangle(p, t[0], t[1], t[2]).distance_squared(p) <= tol2
                                    {
                                        out.push((i, lf));
                                    }
                                }
                            }
                        }
                    }
                    (out, dedup_at)
                },
            )
            .map(|(out, _)| out)
            .reduce(Vec::new, |mut a, mut b| {
                a.append(&mut b);
                a
            });
        pairs = spatial;
    }
    (contacts_from_pairs(probes.len(), shared), contacts_from_pairs(probes.len(), pairs))
}
