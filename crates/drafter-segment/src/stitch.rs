//! Gluing the open pieces of one part across cracks. The rule is in the crate docs
//! ("Cracks"); this is how it is computed.
//!
//! A *free segment* is an edge of a face that no other face of its label shares (a boundary edge,
//! or a face left over at a non-manifold fan). A free segment of label `a` is *covered* by label
//! `b` when both its ends and its midpoint lie within the tolerance of free segments of `b`
//! (distance from a point to a segment, in f64). A T-junction crack gives exactly this: the
//! vertices of each side lie on the edges of the other, whatever the two tessellations.
//!
//! The search is a sorted list of (grid cell, segment) entries: each segment is registered in
//! every cell that its tolerance-grown box touches, split into pieces no longer than a cell so
//! that a long segment touches a number of cells proportional to its length, not to its box's
//! volume. A point is then tested only against the segments of its own cell. Nothing iterates a
//! hash map and every list is sorted, so the result does not depend on the thread count.
//!
//! Hostile input stays linear: the tolerance is a fraction of the mesh's robust diagonal (a stray
//! vertex far away does not count), the cells double until all pieces fit a budget of 4 per
//! segment plus 2^16 (each piece touches at most 27 cells), the cells are never finer than 2^-30
//! of the free edges' extent, and a cell with more than [`MAX_CELL_ENTRIES`] segments is not
//! searched.

use drafter_core::{Aabb, EDGE_NONE, Topology};
use glam::DVec3;
use rayon::prelude::*;

use crate::connect::Labelling;
use crate::union_find::UnionFind;

/// Thresholds of the gluing, in absolute units of the mesh.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StitchLimits {
    /// A point lies on a segment when it is within this distance of it.
    pub(crate) tolerance: f64,
    /// A label is sealed when at least this fraction of its free length is covered by other labels.
    pub(crate) sealed_fraction: f64,
    /// A sealed label is glued to each label that covers at least this fraction of its free length.
    pub(crate) share_fraction: f64,
}

/// What the gluing did.
pub(crate) struct StitchOutcome {
    pub(crate) labels: Vec<u32>,
    pub(crate) count: u32,
    /// Per new label: true when some of its free length is not covered by its own pieces.
    pub(crate) open: Vec<bool>,
    /// Labels glued to another (the number of unions that joined two sets).
    pub(crate) glued: usize,
}

/// A free segment: its label and its two welded end vertices.
#[derive(Clone, Copy)]
struct Segment {
    label: u32,
    a: u32,
    b: u32,
}

/// Cells per axis at most (the cell is at least the free edges' box diagonal over this), so that
/// cell coordinates stay far inside `u32`.
const MAX_CELLS_PER_AXIS: f64 = (1u64 << 30) as f64;

/// Cells holding more segments than this are not searched: many free edges through one small
/// region (a fan of thousands of open slivers around a point) would make the search quadratic.
/// Their points count as uncovered, so what meets there is not glued.
const MAX_CELL_ENTRIES: usize = 256;

/// Glues the open labels of `labelling` across cracks; `None` when nothing could be glued (fewer
/// than two open labels, or no sealed one).
pub(crate) fn stitch_cracks(topo: &Topology, labelling: &Labelling, limits: &StitchLimits) -> Option<StitchOutcome> {
    let labels = &labelling.labels[..];
    if labelling.open.iter().filter(|&&o| o).count() < 2 {
        return None;
    }
    let segments = free_segments(topo, labelling);
    let point = |v: u32| topo.welded_positions[v as usize].as_dvec3();
    let lengths: Vec<f64> = segments.iter().map(|s| point(s.a).distance(point(s.b))).collect();
    let grid = SegmentGrid::new(topo, &segments, &lengths, limits.tolerance.max(0.0))?;
    let cover = covering_labels(topo, &segments, &grid);
    let (mut uf, glued) = glue(labelling.count as usize, &segments, &lengths, &cover, limits);
    if glued == 0 {
        return None;
    }
    // New labels in order of first face.
    let (new_of, count) = uf.relabel_by_first(labels);
    let new_labels: Vec<u32> = labels.iter().map(|&l| new_of[l as usize]).collect();
    let group_of = |l: u32| new_of[l as usize];
    // A glued set stays open where one of its free segments is not covered by its own pieces;
    // a label that was closed stays closed.
    let mut open = vec![false; count as usize];
    let mut c = 0;
    for (i, s) in segments.iter().enumerate() {
        let own = group_of(s.label);
        let mut sealed = false;
        while c < cover.len() && (cover[c].0 as usize) < i {
            c += 1;
        }
        while c < cover.len() && cover[c].0 as usize == i {
            sealed |= group_of(cover[c].1) == own;
            c += 1;
        }
        if !sealed {
            open[own as usize] = true;
        }
    }
    Some(StitchOutcome { labels: new_labels, count, open, glued })
}

/// The free segments registered in a uniform grid of cells, for "which labels' free segments pass
/// within the tolerance of this point".
struct SegmentGrid {
    min: DVec3,
    cell: f64,
    tol: f64,
    /// (cell, segment) pairs, sorted.
    entries: Vec<((u32, u32, u32), u32)>,
}

impl SegmentGrid {
    /// `None` when the segments span nothing or an infinite region.
    fn new(topo: &Topology, segments: &[Segment], lengths: &[f64], tol: f64) -> Option<Self> {
        let point = |v: u32| topo.welded_positions[v as usize].as_dvec3();
        // Cells about twice the median free segment, never below the tolerance.
        let median = {
            let mut sorted = lengths.to_vec();
            let mid = sorted.len() / 2;
            if sorted.is_empty() { 0.0 } else { *sorted.select_nth_unstable_by(mid, f64::total_cmp).1 }
        };
        let mut region = Aabb::EMPTY;
        for s in segments {
            region.extend(point(s.a));
            region.extend(point(s.b));
        }
        if region.is_empty() {
            return None;
        }
        region.min -= tol;
        region.max += tol;
        // A segment is registered piece by piece, each piece at most a cell long, so that with the
        // tolerance at most a quarter cell a piece touches at most 3 cells per axis. The cells double
        // until the pieces fit a budget linear in the segments (a few very long edges among short ones
        // would otherwise be cut into millions of pieces), so the entries are at most 27 times that.
        let extent = region.diagonal();
        if !extent.is_finite() {
            return None;
        }
        let mut cell = (2.0 * median).max(4.0 * tol).max(extent / MAX_CELLS_PER_AXIS).max(f64::MIN_POSITIVE);
        let budget = (4 * segments.len() + (1 << 16)) as f64;
        while lengths.iter().map(|&l| (l / cell).ceil().max(1.0)).sum::<f64>() > budget {
            cell *= 2.0;
        }
        let mut grid = SegmentGrid { min: region.min, cell, tol, entries: Vec::new() };
        let mut entries: Vec<((u32, u32, u32), u32)> = segments
            .par_iter()
            .enumerate()
            .with_min_len(1024)
            .fold(Vec::new, |mut out, (i, s)| {
                let (p, q) = (point(s.a), point(s.b));
                let pieces = (p.distance(q) / cell).ceil().max(1.0);
                let n = pieces as u32;
                for k in 0..n {
                    let (x, y) = (p.lerp(q, f64::from(k) / pieces), p.lerp(q, f64::from(k + 1) / pieces));
                    let (lo, hi) = (grid.cell_of(x.min(y) - tol), grid.cell_of(x.max(y) + tol));
                    for cz in lo.2..=hi.2 {
                        for cy in lo.1..=hi.1 {
                            for cx in lo.0..=hi.0 {
                                out.push(((cx, cy, cz), i as u32));
                            }
                        }
                    }
                }
                out
            })
            .reduce(Vec::new, |mut a, mut b| {
                a.append(&mut b);
                a
            });
        entries.par_sort_unstable();
        entries.dedup();
        grid.entries = entries;
        Some(grid)
    }

    fn cell_of(&self, p: DVec3) -> (u32, u32, u32) {
        let max_coord = f64::from(u32::MAX - 1);
        let c = ((p - self.min) / self.cell).floor().clamp(DVec3::ZERO, DVec3::splat(max_coord));
        (c.x as u32, c.y as u32, c.z as u32)
    }

    /// The labels whose free segments pass within the tolerance of `p`, other than `own`, sorted.
    fn near_labels(&self, topo: &Topology, segments: &[Segment], p: DVec3, own: u32, out: &mut Vec<u32>) {
        let point = |v: u32| topo.welded_positions[v as usize].as_dvec3();
        out.clear();
        let key = self.cell_of(p);
        let start = self.entries.partition_point(|e| e.0 < key);
        let end = start + self.entries[start..].partition_point(|e| e.0 == key);
        if end - start > MAX_CELL_ENTRIES {
            return; // a crowded cell (many free edges through one point) is not searched
        }
        let tol2 = self.tol * self.tol;
        for &(_, i) in &self.entries[start..end] {
            let s = segments[i as usize];
            if s.label != own && point_segment_distance_squared(p, point(s.a), point(s.b)) <= tol2 {
                out.push(s.label);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// The labels that cover each segment, as sorted (segment, label) pairs: all three samples of the
/// segment (its ends and middle) lie near one of the label's free segments.
fn covering_labels(topo: &Topology, segments: &[Segment], grid: &SegmentGrid) -> Vec<(u32, u32)> {
    let point = |v: u32| topo.welded_positions[v as usize].as_dvec3();
    let mut cover: Vec<(u32, u32)> = segments
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .fold(Vec::new, |mut out, (i, s)| {
            let (p, q) = (point(s.a), point(s.b));
            let (mut x, mut y, mut z) = (Vec::new(), Vec::new(), Vec::new());
            grid.near_labels(topo, segments, p, s.label, &mut x);
            if x.is_empty() {
                return out;
            }
            grid.near_labels(topo, segments, q, s.label, &mut y);
            grid.near_labels(topo, segments, (p + q) * 0.5, s.label, &mut z);
            out.extend(
                x.iter().filter(|l| y.binary_search(l).is_ok() && z.binary_search(l).is_ok()).map(|&l| (i as u32, l)),
            );
            out
        })
        .reduce(Vec::new, |mut a, mut b| {
            a.append(&mut b);
            a
        });
    cover.par_sort_unstable();
    cover
}

/// Unites each label with the labels that cover enough of its free length (`limits`), when
/// enough of it is sealed at all; the union-find and the number of unions.
fn glue(
    k: usize,
    segments: &[Segment],
    lengths: &[f64],
    cover: &[(u32, u32)],
    limits: &StitchLimits,
) -> (UnionFind, usize) {
    let (mut free_length, mut sealed_length) = (vec![0.0f64; k], vec![0.0f64; k]);
    for (s, len) in segments.iter().zip(lengths) {
        free_length[s.label as usize] += len;
    }
    let mut shares: Vec<(u32, u32, f64)> = Vec::with_capacity(cover.len());
    for run in cover.chunk_by(|x, y| x.0 == y.0) {
        let i = run[0].0 as usize;
        let (a, len) = (segments[i].label, lengths[i]);
        sealed_length[a as usize] += len;
        shares.extend(run.iter().map(|&(_, b)| (a, b, len)));
    }
    // Summed per (label, coverer) in segment order, so the sums do not depend on the threads.
    shares.sort_by_key(|x| (x.0, x.1));
    let mut uf = UnionFind::new(k);
    let mut glued = 0;
    for run in shares.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1) {
        let (a, b) = (run[0].0, run[0].1);
        let shared: f64 = run.iter().map(|x| x.2).sum();
        let free = free_length[a as usize];
        if sealed_length[a as usize] >= limits.sealed_fraction * free
            && shared >= limits.share_fraction * free
            && uf.find(a) != uf.find(b)
        {
            uf.union(a, b);
            glued += 1;
        }
    }
    (uf, glued)
}

/// The free segments of the open labels, in face order.
fn free_segments(topo: &Topology, labelling: &Labelling) -> Vec<Segment> {
    let labels = &labelling.labels;
    let mut out = Vec::new();
    for (f, edges) in topo.face_edges.iter().enumerate() {
        let l = labels[f];
        if !labelling.open[l as usize] {
            continue;
        }
        let tri = topo.faces[f];
        for (i, &e) in edges.iter().enumerate() {
            if e == EDGE_NONE {
                continue;
            }
            let faces = topo.faces_of_edge(e as usize);
            if faces.iter().all(|&g| g == f as u32 || labels[g as usize] != l) {
                out.push(Segment { label: l, a: tri[i], b: tri[(i + 1) % 3] });
            }
        }
    }
    out
}

/// Squared distance from `p` to the segment `ab` (a point when `a == b`).
fn point_segment_distance_squared(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t).distance_squared(p)
}
