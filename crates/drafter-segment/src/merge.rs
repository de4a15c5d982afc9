//! Merging small parts of one mesh's segmentation into their largest touching neighbour.

use drafter_core::{Aabb, Topology};
use glam::DVec3;
use rayon::prelude::*;

use crate::geometry::triangles_within;
use crate::union_find::UnionFind;

/// Thresholds of a merge, already turned into absolute units of the mesh.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MergeLimits {
    /// A part is small when it has fewer triangles than this...
    pub(crate) max_triangles: f64,
    /// ...and its bounding-box diagonal is below this.
    pub(crate) max_diagonal: f64,
    /// Two triangles touch when they come within this distance.
    pub(crate) touch_distance: f64,
}

/// What a merge did.
#[derive(Clone, Debug, Default)]
pub(crate) struct MergeOutcome {
    pub(crate) labels: Vec<u32>,
    pub(crate) count: u32,
    /// Parts that were small and found a neighbour to join.
    pub(crate) merged: usize,
    /// Small parts that touch nothing and stay alone.
    pub(crate) isolated: usize,
}

#[derive(Clone, Copy)]
struct Group {
    triangles: u64,
    bounds: Aabb,
}

fn triangle_points(topo: &Topology, f: usize) -> [DVec3; 3] {
    topo.faces[f].map(|v| topo.welded_positions[v as usize].as_dvec3())
}

fn triangle_bounds(t: &[DVec3; 3]) -> Aabb {
    Aabb { min: t[0].min(t[1]).min(t[2]), max: t[0].max(t[1]).max(t[2]) }
}

fn overlaps(a: &Aabb, b: &Aabb, margin: f64) -> bool {
    (a.min - margin).cmple(b.max).all() && (b.min - margin).cmple(a.max).all()
}

/// A closed label is a solid when its enclosed volume exceeds this fraction of its box diagonal
/// cubed (a cube has 0.19; two coincident triangles facing apart have 0).
const SOLID_VOLUME_FRACTION: f64 = 1e-6;

/// Merges small labels of `labels` (dense, `0..count`) into their largest touching neighbour.
pub(crate) fn merge_small(topo: &Topology, labels: &[u32], count: u32, open: &[bool], limits: &MergeLimits) -> MergeOutcome {
    let k = count as usize;
    let unchanged = || MergeOutcome { labels: labels.to_vec(), count, merged: 0, isolated: 0 };
    if k < 2 {
        return unchanged();
    }
    let mut groups = vec![Group { triangles: 0, bounds: Aabb::EMPTY }; k];
    for (f, &l) in labels.iter().enumerate() {
        let g = &mut groups[l as usize];
        g.triangles += 1;
        for p in triangle_points(topo, f) {
            g.bounds.extend(p);
        }
    }
    let is_small = |g: &Group| (g.triangles as f64) < limits.max_triangles && g.bounds.diagonal() < limits.max_diagonal;
    // Closed surfaces that enclose a volume are solids: parts in their own right, whatever their size.
    let mut volume = vec![0.0f64; k];
    for (f, &l) in labels.iter().enumerate() {
        let g = &groups[l as usize];
        let centre = (g.bounds.min + g.bounds.max) * 0.5;
        let [a, b, c] = triangle_points(topo, f).map(|p| p - centre);
        volume[l as usize] += a.dot(b.cross(c)) / 6.0;
    }
    let solid = |c: usize| !open[c] && volume[c].abs() > SOLID_VOLUME_FRACTION * groups[c].bounds.diagonal().powi(3);
    let small: Vec<bool> = (0..k).map(|c| is_small(&groups[c]) && !solid(c)).collect();
    if !small.iter().any(|&s| s) {
        return unchanged();
    }
    let vertex_contacts = vertex_contacts(topo, labels, &small);
    let spatial_contacts = spatial_contacts(topo, labels, &small, &groups, limits.touch_distance);

    let mut order: Vec<u32> = (0..count).filter(|&c| small[c as usize]).collect();
    order.sort_by_key(|&c| (groups[c as usize].triangles, c));
    let mut uf = UnionFind::new(k);
    let (mut merged, mut isolated) = (0, 0);
    for c in order {
        let root = uf.find(c);
        if !is_small(&groups[root as usize]) || !small[c as usize] {
            continue;
        }
        let mut best: Option<(u64, u32)> = None;
        for contacts in [&vertex_contacts, &spatial_contacts] {
            for &other in neighbours(contacts, c) {
                let r = uf.find(other);
                if r == root {
                    continue;
                }
                let size = groups[r as usize].triangles;
                // Largest neighbour; ties go to the smaller id.
                if best.is_none_or(|(s, id)| size > s || (size == s && r < id)) {
                    best = Some((size, r));
                }
            }
            if best.is_some() {
                break;
            }
        }
        match best {
            Some((_, target)) => {
                let joined = Group {
                    triangles: groups[root as usize].triangles + groups[target as usize].triangles,
                    bounds: groups[root as usize].bounds.union(&groups[target as usize].bounds),
                };
                let new_root = uf.union(root, target);
                groups[new_root as usize] = joined;
                merged += 1;
            }
            None => isolated += 1,
        }
    }
    // Renumber in order of first triangle.
    let mut label_of_root = vec![u32::MAX; k];
    let mut next = 0u32;
    let mut out = vec![0u32; labels.len()];
    for (f, &l) in labels.iter().enumerate() {
        let r = uf.find(l) as usize;
        if label_of_root[r] == u32::MAX {
            label_of_root[r] = next;
            next += 1;
        }
        out[f] = label_of_root[r];
    }
    MergeOutcome { labels: out, count: next, merged, isolated }
}

/// Contact lists as CSR: `offsets[c]..offsets[c + 1]` into `targets`.
struct Contacts {
    offsets: Vec<u32>,
    targets: Vec<u32>,
}

fn neighbours(contacts: &Contacts, c: u32) -> &[u32] {
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

/// Labels sharing a welded vertex with each small label.
fn vertex_contacts(topo: &Topology, labels: &[u32], small: &[bool]) -> Contacts {
    let mut pairs = Vec::new();
    for (f, &l) in labels.iter().enumerate() {
        if !small[l as usize] {
            continue;
        }
        for v in topo.faces[f] {
            for &g in topo.faces_of_vertex(v as usize) {
                let m = labels[g as usize];
                if m != l {
                    pairs.push((l, m));
                }
            }
        }
    }
    contacts_from_pairs(small.len(), pairs)
}

/// Largest number of grid cells per axis of the contact search.
const GRID_CELLS_PER_AXIS: f64 = 64.0;

/// Labels with a triangle within `tol` of a triangle of each small label, found with a uniform
/// grid over the small labels' triangles that every triangle of the mesh is tested against.
fn spatial_contacts(topo: &Topology, labels: &[u32], small: &[bool], groups: &[Group], tol: f64) -> Contacts {
    let k = small.len();
    let queries: Vec<u32> = (0..labels.len() as u32).filter(|&f| small[labels[f as usize] as usize]).collect();
    let mut region = Aabb::EMPTY;
    let mut extent_sum = 0.0;
    for (c, g) in groups.iter().enumerate() {
        if small[c] {
            region = region.union(&g.bounds);
        }
    }
    for &q in &queries {
        let b = triangle_bounds(&triangle_points(topo, q as usize));
        extent_sum += (b.max - b.min).max_element();
    }
    if queries.is_empty() || region.is_empty() {
        return contacts_from_pairs(k, Vec::new());
    }
    region.min -= tol;
    region.max += tol;
    let size = region.max - region.min;
    let cell = (extent_sum / queries.len() as f64).max(size.max_element() / GRID_CELLS_PER_AXIS).max(tol).max(f64::MIN_POSITIVE);
    let dims = (size / cell).ceil().max(DVec3::ONE).as_uvec3();
    let cell_count = (dims.x * dims.y * dims.z) as usize;
    let for_each_cell = |b: &Aabb, visit: &mut dyn FnMut(usize)| {
        if !overlaps(b, &region, 0.0) {
            return;
        }
        let lo = ((b.min - region.min) / cell).floor().max(DVec3::ZERO).as_uvec3().min(dims - 1);
        let hi = ((b.max - region.min) / cell).floor().max(DVec3::ZERO).as_uvec3().min(dims - 1);
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    visit(((z * dims.y + y) * dims.x + x) as usize);
                }
            }
        }
    };
    let expanded: Vec<Aabb> = queries
        .iter()
        .map(|&q| {
            let b = triangle_bounds(&triangle_points(topo, q as usize));
            Aabb { min: b.min - tol, max: b.max + tol }
        })
        .collect();
    // Counting sort of (cell, query) into CSR.
    let mut offsets = vec![0u32; cell_count + 1];
    for b in &expanded {
        for_each_cell(b, &mut |c| offsets[c + 1] += 1);
    }
    for c in 0..cell_count {
        offsets[c + 1] += offsets[c];
    }
    let mut cursor = offsets.clone();
    let mut entries = vec![0u32; offsets[cell_count] as usize];
    for (i, b) in expanded.iter().enumerate() {
        for_each_cell(b, &mut |c| {
            entries[cursor[c] as usize] = i as u32;
            cursor[c] += 1;
        });
    }
    let pairs: Vec<(u32, u32)> = (0..labels.len())
        .into_par_iter()
        .with_min_len(4096)
        .fold(Vec::new, |mut out, f| {
            let t = triangle_points(topo, f);
            let b = triangle_bounds(&t);
            let lf = labels[f];
            let mut found: Vec<u32> = Vec::new();
            for_each_cell(&b, &mut |c| {
                for &i in &entries[offsets[c] as usize..offsets[c + 1] as usize] {
                    let q = queries[i as usize] as usize;
                    let lq = labels[q];
                    if lq == lf || found.contains(&lq) || !overlaps(&expanded[i as usize], &b, 0.0) {
                        continue;
                    }
                    if triangles_within(&triangle_points(topo, q), &t, tol) {
                        found.push(lq);
                        out.push((lq, lf));
                    }
                }
            });
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    contacts_from_pairs(k, pairs)
}
