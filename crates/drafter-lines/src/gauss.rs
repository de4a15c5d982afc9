//! The Gauss-map arc hierarchy for orthographic silhouettes (Gooch et al. 1999, §5.1.2, Fig. 8,
//! Tables 1–2; ../shared/papers/001_*).
//!
//! # How it works
//!
//! On the sphere of orientations a candidate edge is the great-circle arc between its two face
//! normals. Under an orthographic view along `u` the faces with `n·u > 0` and `n·u < 0` are separated
//! by the great circle `n·u = 0`, and the edge is a silhouette iff its arc crosses that circle.
//!
//! Arcs are stored in a hierarchy of spherical triangles: the faces of an icosahedron (or
//! octahedron), each split 4:1 at its normalised edge midpoints, level after level. An arc goes
//! down from the root towards the cell containing its midpoint for as long as it fits that cell's
//! *bin*, and is stored at the deepest cell whose bin holds it:
//!
//! * [`Bins::Strict`]: the bin is the spherical triangle itself (the paper's first variant; arcs
//!   that straddle a cell boundary get stuck high up, Table 2 "No Overlap");
//! * [`Bins::Overlapping`] (default, the variant the paper recommends): the bin is the cap around
//!   the cell's centre with `factor` × the cell's circumradius, so neighbouring bins overlap and
//!   an arc near a boundary still goes down.
//!
//! Arcs that fit no base cell (longer than a base bin, or with antipodal normals) stay at the root.
//!
//! # Query and exactness
//!
//! Every node keeps a *data-dependent* bounding cap of all the arc endpoints in its subtree (centre
//! `c`, radius `r`, the smaller of the cap around the cell centre and the one around the mean
//! endpoint). A query walks the tree one level at a time (breadth-first, see `tree.rs` for why)
//! and enters a node only when the view's great circle meets its cap, `|c·u| ≤ sin r + ε`. Since
//! the predicate only looks at the two endpoints, a missed cap means both normals of every arc below
//! lie strictly on one side with a margin (`ε` = [`CULL_MARGIN`] = 1e-5 ≫ the ~1e-6 rounding of
//! the `f32` dot products), so the `f32` predicate would reject each of them: culling never drops
//! a silhouette. A cap of radius ≥ π/2 is never culled.
//!
//! Storage: the arcs are stored node after node (breadth-first), in blocks of 4 lanes. A query
//! first walks the caps and collects the block ranges of the nodes it enters, then tests the
//! ranges as one prefetched stream. On x86-64 a 16-bit copy of the normals decides almost every
//! lane with exact integer arithmetic and a proven error bound, and the few lanes within ~6·10⁻⁵
//! of the great circle are tested again with the brute-force arithmetic (same `u`, same `f32`
//! operations in the same order; see `brute::Quantized`); elsewhere every lane takes the `f32`
//! test. Either way the answer is bit-identical to [`crate::BruteForce`]. Blocks at the ends of
//! a range also hold a few arcs of neighbouring nodes; testing them too is harmless (the predicate
//! is exact for any arc, and an arc of a culled node is no silhouette). Up to 4 children's caps
//! are tested in one SIMD pass. A hierarchy built on its own answers in its input order, through
//! `order`; [`GaussMapHierarchy::into_storage_order`] renumbers the candidates by storage position
//! (what [`crate::SilhouetteIndex`] does), and then a block's hits are 4 bits ORed straight into
//! the answer.
//!
//! # How deep
//!
//! Cells are built down to [`depth_for_count`] levels. Then a bottom-up pass collapses every
//! subtree whose expected cost is lower as one node: for a uniformly random `u`, `c·u` is uniform on
//! `[-1, 1]`, so a cap is entered with probability `min(1, sin r + ε)` (capped by its parent's).
//! With the per-operation costs of [`CostModel`] this chooses the depth of every branch; the
//! expected time of the final hierarchy is then measured in operations over fixed directions and
//! priced with the same model, and [`crate::SilhouetteIndex`] compares it with brute force to
//! decide whether to keep the hierarchy at all.

use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::brute::{OrthoBlocks, unit_direction};
use crate::tree::{
    Purpose, breadth_first, check_breadth_first, depths, push_children, widest_level, with_levels, with_ranges,
};
use crate::{ArraysError, CostModel, EdgeSet};

/// Margin added to the sine of every cap radius (see the module docs).
pub const CULL_MARGIN: f64 = 1e-5;

/// Default bin size of [`Bins::Overlapping`], in cell circumradii.
pub const DEFAULT_OVERLAP: f32 = 1.5;

/// A threshold at or above which a cap is never culled.
const NEVER_CULL: f32 = 2.0;

/// The platonic solid whose faces are the level-0 cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BaseSolid {
    /// 8 faces.
    Octahedron,
    /// 20 faces (default; the paper's choice).
    Icosahedron,
}

impl BaseSolid {
    pub fn face_count(self) -> usize {
        match self {
            Self::Octahedron => 8,
            Self::Icosahedron => 20,
        }
    }

    fn code(self) -> u32 {
        match self {
            Self::Octahedron => 0,
            Self::Icosahedron => 1,
        }
    }
}

/// Which region of a cell an arc must fit to be stored there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Bins {
    /// The spherical triangle itself.
    Strict,
    /// The cap around the cell centre of `factor` circumradii (`factor` ≥ 1).
    Overlapping { factor: f32 },
}

/// Options of [`GaussMapHierarchy::build`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussMapOptions {
    /// Level-0 cells. Default [`BaseSolid::Icosahedron`].
    pub base: BaseSolid,
    /// Bin shape. Default `Overlapping { factor: DEFAULT_OVERLAP }`.
    pub bins: Bins,
    /// Deepest level built (0 = base faces only); `None` (default) picks [`depth_for_count`].
    /// Range 0..=12.
    pub max_depth: Option<u8>,
    /// Collapse subtrees that the cost model says are cheaper as one node. Default `true`.
    pub prune: bool,
}

impl Default for GaussMapOptions {
    fn default() -> Self {
        Self {
            base: BaseSolid::Icosahedron,
            bins: Bins::Overlapping { factor: DEFAULT_OVERLAP },
            max_depth: None,
            prune: true,
        }
    }
}

/// The deepest level worth building for `candidates` arcs: one level below about one arc per
/// cell if they were spread evenly (arcs crowd into a band of the sphere on most models; the
/// cost-model pruning then removes what does not pay), at most 10.
pub fn depth_for_count(candidates: usize, base: BaseSolid) -> u8 {
    let per_face = candidates as f64 / base.face_count() as f64;
    if per_face <= 1.0 {
        return 0;
    }
    (per_face.log(4.0).ceil() as u8 + 1).min(10)
}

/// Nodes and arcs at one level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelCount {
    pub nodes: usize,
    pub arcs: usize,
}

/// How many arcs are stored at each level (Gooch et al. 1999, Table 2).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelHistogram {
    /// The whole sphere: arcs that fit no base cell (or, after pruning, a collapsed hierarchy).
    pub root: LevelCount,
    /// `levels[k]`: cells after `k` 4:1 splits (level 0 = the base solid's faces).
    pub levels: Vec<LevelCount>,
}

impl LevelHistogram {
    /// From `(depth, own arc count)` per node (depth 0 = root, 1 = base face).
    fn from_nodes(nodes: impl Iterator<Item = (u32, usize)>) -> Self {
        let mut h = LevelHistogram::default();
        for (depth, arcs) in nodes {
            let slot = if depth == 0 {
                &mut h.root
            } else {
                let level = depth as usize - 1;
                if h.levels.len() <= level {
                    h.levels.resize(level + 1, LevelCount::default());
                }
                &mut h.levels[level]
            };
            slot.nodes += 1;
            slot.arcs += arcs;
        }
        h
    }
}

/// Work done by one query (for benchmarks and the cost model).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct QueryCounts {
    /// Nodes entered (their children's bounds tested, their own candidates tested).
    pub nodes_entered: usize,
    /// Bounds (caps, or boxes and cones) tested.
    pub bounds_tested: usize,
    /// Entered nodes with own candidates.
    pub ranges: usize,
    /// Blocks of 4 lanes tested.
    pub blocks_tested: usize,
    /// Candidates tested with the exact predicate (blocks minus padding).
    pub arcs_tested: usize,
}

impl std::ops::AddAssign for QueryCounts {
    fn add_assign(&mut self, o: Self) {
        self.nodes_entered += o.nodes_entered;
        self.bounds_tested += o.bounds_tested;
        self.ranges += o.ranges;
        self.blocks_tested += o.blocks_tested;
        self.arcs_tested += o.arcs_tested;
    }
}

impl QueryCounts {
    /// Priced with a cost model's Gauss-map (`gauss = true`) or cone-BVH costs, in ns.
    pub fn cost_ns(&self, cost: &CostModel, gauss: bool) -> f64 {
        let [enter, test, range, block] = if gauss {
            [cost.gauss_enter_ns, cost.gauss_test_ns, cost.gauss_range_ns, cost.gauss_block_ns]
        } else {
            [cost.bvh_enter_ns, cost.bvh_test_ns, cost.bvh_range_ns, cost.bvh_block_ns]
        };
        self.nodes_entered as f64 * f64::from(enter)
            + self.bounds_tested as f64 * f64::from(test)
            + self.ranges as f64 * f64::from(range)
            + self.blocks_tested as f64 * f64::from(block)
    }
}

/// The flat arrays of a [`GaussMapHierarchy`], ready for glTF buffer views.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GaussMapArrays {
    /// 0 octahedron, 1 icosahedron.
    pub base: u32,
    /// Deepest level that was built.
    pub max_depth: u32,
    /// 4 `f32` per node: cap centre x, y, z and the cull threshold `sin r + ε` (≥ 1: never culled).
    pub node_caps: Vec<f32>,
    /// The overlapping-bin factor ([`Bins::Overlapping`]); 0 for [`Bins::Strict`].
    pub overlap: f32,
    /// 4 `u32` per node, nodes breadth-first from the root (the whole sphere; depth 1 = level 0):
    /// first child, child count, first own arc and end of own arcs, positions in the storage
    /// order; own arcs of the nodes follow one another in node order.
    ///
    /// The storage order itself is not stored: which cell holds an arc is a function of its two
    /// normals (the bin rule), so [`GaussMapHierarchy::from_arrays`] assigns the arcs again with
    /// the builder's arithmetic and checks the result against these nodes.
    pub nodes: Vec<u32>,
}

/// See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussMapHierarchy {
    base: BaseSolid,
    bins: Bins,
    max_depth: u8,
    /// What a query reads about nodes, each with its cap, padded with 4 culled entries so that
    /// the up to 4 children of a node are tested in one SIMD pass.
    nodes: Vec<GaussNode>,
    /// The most nodes at one depth (sizes the walk's level buffers).
    widest: usize,
    /// The arcs in storage order, in blocks of 4.
    blocks: OrthoBlocks,
    /// Whether `order` is the identity, so that storage positions are candidate indices and hits
    /// go straight into the answer (see [`GaussMapHierarchy::into_storage_order`]).
    identity: bool,
    /// The serialised form: `[first_child, child_count, arc_start, arc_end]` per node.
    flat: Vec<[u32; 4]>,
    caps: Vec<[f32; 4]>,
    order: Vec<u32>,
    assigned: Option<LevelHistogram>,
    predicted_ns: f64,
}

/// A node as the query reads it: its cap next to its record, 32 bytes, so that testing a node's
/// children touches 2 cache lines (caps as 4 separate arrays touched 4 to 8, and the records
/// another 1 or 2 at the next level).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
struct GaussNode {
    /// Centre x, y, z and threshold `sin r + ε` (see the module docs).
    cap: Vec4,
    first_child: u32,
    child_count: u32,
    /// The blocks covering the own arcs (the partial blocks at both ends also hold arcs of
    /// neighbouring nodes, which are tested too: harmless, the predicate is exact for any arc).
    block_start: u32,
    block_end: u32,
}

/// What a query reads, built from the serialised form.
struct Assembled {
    nodes: Vec<GaussNode>,
    widest: usize,
    blocks: OrthoBlocks,
}

/// Query records, cap arrays and blocks of a breadth-first tree.
fn assemble(flat: &[[u32; 4]], caps: &[[f32; 4]], order: &[u32], normals: &[[Vec3; 2]], purpose: Purpose) -> Assembled {
    let mut nodes: Vec<GaussNode> = flat
        .iter()
        .zip(caps)
        .map(|(&[first_child, child_count, start, end], &cap)| GaussNode {
            cap: Vec4::from(cap),
            first_child,
            child_count,
            block_start: start / 4,
            block_end: if end > start { end.div_ceil(4) } else { start / 4 },
        })
        .collect();
    // Padding: threshold -1 is culled by any finite direction (and masked off anyway).
    let pad =
        GaussNode { cap: Vec4::new(0.0, 0.0, 0.0, -1.0), first_child: 0, child_count: 0, block_start: 0, block_end: 0 };
    nodes.extend(std::iter::repeat_n(pad, 4));
    let blocks = match purpose {
        Purpose::Query => OrthoBlocks::new(order, normals),
        Purpose::Storage => OrthoBlocks::default(),
    };
    Assembled { nodes, widest: widest_level(flat), blocks }
}

/// Fixed view directions for estimating a hierarchy's cost (a Fibonacci sphere).
fn sample_directions(count: u32) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / count as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * k as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// A spherical triangle, counter-clockwise seen from outside.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cell {
    v: [DVec3; 3],
    /// Unit normals of the planes through the origin and each edge, pointing inside.
    planes: [DVec3; 3],
    center: DVec3,
    /// Cosine of the circumradius.
    cos_radius: f64,
}

impl Cell {
    fn new(a: DVec3, b: DVec3, c: DVec3) -> Cell {
        let center = (a + b + c).normalize();
        let cos_radius = center.dot(a).min(center.dot(b)).min(center.dot(c));
        let planes = [a.cross(b).normalize(), b.cross(c).normalize(), c.cross(a).normalize()];
        Cell { v: [a, b, c], planes, center, cos_radius }
    }

    /// Signed inside-ness: ≥ 0 inside, the larger the deeper.
    #[inline]
    pub(crate) fn score(&self, p: DVec3) -> f64 {
        min(min(self.planes[0].dot(p), self.planes[1].dot(p)), self.planes[2].dot(p))
    }

    pub(crate) fn children(&self) -> [Cell; 4] {
        let [a, b, c] = self.v;
        let ab = (a + b).normalize();
        let bc = (b + c).normalize();
        let ca = (c + a).normalize();
        [Cell::new(a, ab, ca), Cell::new(ab, b, bc), Cell::new(ca, bc, c), Cell::new(ab, bc, ca)]
    }
}

pub(crate) fn base_cells(base: BaseSolid) -> Vec<Cell> {
    let (vertices, edge_len2): (Vec<DVec3>, f64) = match base {
        BaseSolid::Octahedron => (vec![DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z], 2.0),
        BaseSolid::Icosahedron => {
            let phi = (1.0 + 5f64.sqrt()) / 2.0;
            let mut v = Vec::new();
            for s1 in [-1.0, 1.0] {
                for s2 in [-1.0, 1.0] {
                    v.push(DVec3::new(0.0, s1, s2 * phi));
                    v.push(DVec3::new(s1, s2 * phi, 0.0));
                    v.push(DVec3::new(s2 * phi, 0.0, s1));
                }
            }
            (v, 4.0)
        }
    };
    let n = vertices.len();
    let adjacent = |i: usize, j: usize| (vertices[i].distance_squared(vertices[j]) - edge_len2).abs() < 1e-9;
    let mut cells = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if adjacent(i, j) && adjacent(j, k) && adjacent(k, i) {
                    let (a, mut b, mut c) = (vertices[i], vertices[j], vertices[k]);
                    if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                        std::mem::swap(&mut b, &mut c);
                    }
                    cells.push(Cell::new(a.normalize(), b.normalize(), c.normalize()));
                }
            }
        }
    }
    cells
}

/// Where the overlapping-bin rule stores the arc `n1`–`n2` (unit; zero for a degenerate face):
/// the cells containing its midpoint, level after level, for as long as both endpoints lie in the
/// cell's bin (the cap of `factor` circumradii around its centre), at most `level` splits below
/// the base. Returns `(digits, cells)`: `cells` is how many cells the arc went down (0: it fits
/// no base cell), `digits` the path as `base · 4^level + child digits` with unused digits 0.
/// The reference for [`arc_paths`], which computes it for many arcs at once.
#[cfg(test)]
pub(crate) fn arc_path(n1: DVec3, n2: DVec3, base: &[Cell], level: u8, factor: f64) -> (u32, u8) {
    let sum = n1 + n2;
    if n1 == DVec3::ZERO || n2 == DVec3::ZERO || sum.length() <= 1e-9 {
        return (0, 0);
    }
    let mid = sum.normalize();
    let fits = |c: &Cell| fits_bin(c, bin_cos(c, factor), [n1, n2]);
    let b = most_inside(base, mid);
    if !fits(&base[b]) {
        return (0, 0);
    }
    let (mut key, mut cells, mut cell) = (b as u32, 1u8, base[b]);
    for _ in 0..level {
        let children = cell.children();
        let k = most_inside(&children, mid);
        if !fits(&children[k]) {
            break;
        }
        key = key * 4 + k as u32;
        cells += 1;
        cell = children[k];
    }
    (key * 4u32.pow(u32::from(level + 1 - cells)), cells)
}

/// Where the overlapping-bin rule stores each arc `unit[i]` (unit normals; zero for a degenerate
/// face): the cells containing its midpoint, level after level, for as long as both endpoints lie
/// in the cell's bin (the cap of `factor` circumradii around its centre), at most `level` splits
/// below the base. Each path is `(digits, cells)`: `cells` is how many cells the arc went down
/// (0: it fits no base cell), `digits` the path as `base · 4^level + child digits` with unused
/// digits 0. Computed top-down over the cells instead of arc by arc:
/// each visited cell's children (and their bins) are built once for all the arcs that reach it,
/// rather than once per arc and level. Equal to `arc_path` on every arc (tested).
pub(crate) fn arc_paths(unit: &[[DVec3; 2]], base: &[Cell], level: u8, factor: f64) -> Vec<(u32, u8)> {
    let mids: Vec<Option<DVec3>> = unit.par_iter().map(|&u| arc_mid(u)).collect();
    let bins: Vec<f64> = base.iter().map(|c| bin_cos(c, factor)).collect();
    let mut groups: Vec<Vec<u32>> = vec![Vec::new(); base.len()];
    for (i, mid) in mids.iter().enumerate() {
        if let Some(m) = mid {
            let b = most_inside(base, *m);
            if fits_bin(&base[b], bins[b], unit[i]) {
                groups[b].push(i as u32);
            }
        }
    }
    let descend = PathDescent { unit, level, factor };
    let found: Vec<Vec<(u32, (u32, u8))>> = groups
        .into_par_iter()
        .enumerate()
        .map(|(b, ids)| {
            let mut out = Vec::with_capacity(ids.len());
            descend.cell(base[b], b as u32, 1, ids, &mut out);
            out
        })
        .collect();
    let mut paths = vec![(0u32, 0u8); unit.len()];
    for (i, path) in found.into_iter().flatten() {
        paths[i as usize] = path;
    }
    paths
}

/// Arcs per task of [`drafter_core::scatter_in_parallel`] (serial, the dragon's root level was
/// 30 ms of one core).
const SCATTER_CHUNK: usize = 1 << 16;

/// Sorts `items[r]` for every range `r` of `ranges`: on the thread pool where the ranges are
/// disjoint and in increasing order (as the outermost collapsed subtrees of a preorder are),
/// one after the other otherwise.
fn sort_ranges(items: &mut [u32], ranges: &[std::ops::Range<usize>]) {
    match drafter_core::disjoint_slices_mut(items, ranges) {
        Some(slices) => slices.into_par_iter().for_each(|s| s.sort_unstable()),
        None => {
            for r in ranges {
                if let Some(slice) = items.get_mut(r.clone()) {
                    slice.sort_unstable();
                }
            }
        }
    }
}

/// Cosine of the overlapping bin radius of `c` (`factor` circumradii, at most π).
fn bin_cos(c: &Cell, factor: f64) -> f64 {
    (c.cos_radius.clamp(-1.0, 1.0).acos() * factor.max(1.0)).min(std::f64::consts::PI).cos()
}

#[inline]
fn fits_bin(c: &Cell, cos_bin: f64, [n1, n2]: [DVec3; 2]) -> bool {
    c.center.dot(n1) >= cos_bin && c.center.dot(n2) >= cos_bin
}

/// The smaller of two scores. Scores are never NaN (finite planes and points), and for those this
/// is `f64::min` up to the sign of a zero, which no comparison of scores sees; it compiles to one
/// `minsd` where `f64::min` adds a NaN fix-up of four instructions.
#[inline(always)]
fn min(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// The cell whose inside-ness score of `p` is the largest (the first of equals).
fn most_inside(cells: &[Cell], p: DVec3) -> usize {
    cells
        .iter()
        .enumerate()
        .map(|(k, c)| (k, c.score(p)))
        .fold((0, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc })
        .0
}

/// The midpoint of the arc between unit normals `n1`, `n2`; `None` for a zero or antipodal arc.
fn arc_mid([n1, n2]: [DVec3; 2]) -> Option<DVec3> {
    let sum = n1 + n2;
    let length = sum.length();
    // `sum * (1 / length)` is glam's `normalize`, without taking the length a second time.
    (n1 != DVec3::ZERO && n2 != DVec3::ZERO && length > 1e-9).then(|| sum * (1.0 / length))
}

/// The cell with digits `key` ([`BuildNode::key`]) `cells` cells down from `base`.
fn cell_of(base: &[Cell], key: u32, cells: u8) -> Cell {
    let digit = |i: u8| (key >> (2 * u32::from(i))) as usize;
    let mut cell = base[digit(cells - 1)];
    for i in (0..cells - 1).rev() {
        cell = cell.children()[digit(i) & 3];
    }
    cell
}

struct PathDescent<'a> {
    unit: &'a [[DVec3; 2]],
    level: u8,
    factor: f64,
}

impl PathDescent<'_> {
    /// Paths of `ids`, all of which went down to `cell` (`cells` cells so far, digits `key`).
    fn cell(&self, cell: Cell, key: u32, cells: u8, ids: Vec<u32>, out: &mut Vec<(u32, (u32, u8))>) {
        let here = (key * 4u32.pow(u32::from(self.level + 1 - cells)), cells);
        if cells > self.level {
            out.extend(ids.into_iter().map(|i| (i, here)));
            return;
        }
        let children = cell.children();
        let bins = children.each_ref().map(|c| bin_cos(c, self.factor));
        let mut groups: [Vec<u32>; 4] = Default::default();
        for i in ids {
            let Some(m) = arc_mid(self.unit[i as usize]) else { continue };
            let k = most_inside(&children, m);
            if fits_bin(&children[k], bins[k], self.unit[i as usize]) {
                groups[k].push(i);
            } else {
                out.push((i, here));
            }
        }
        for (k, ids) in groups.into_iter().enumerate() {
            if !ids.is_empty() {
                self.cell(children[k], key * 4 + k as u32, cells + 1, ids, out);
            }
        }
    }
}

/// An arc as the builder moves it: its candidate and its unit endpoints (zero for a degenerate
/// face). The builder partitions these records in place, level after level, so that every pass
/// reads and writes memory in sequence (carrying indices into a shared array instead cost a cache
/// miss per arc and level on a million-arc mesh). The midpoint is recomputed where it is needed,
/// which is cheaper than moving it along.
#[derive(Clone, Copy, Debug, Default)]
struct Arc {
    n1: DVec3,
    n2: DVec3,
    id: u32,
    /// A lower bound on the visit probability of any node holding the arc ([`StopRule`]'s
    /// `p_a`), in the record's padding.
    p: f32,
}

impl Arc {
    /// The arc's midpoint; `None` for a zero or antipodal arc.
    fn mid(&self) -> Option<DVec3> {
        arc_mid([self.n1, self.n2])
    }
}

/// Where the bin rule left each arc as far as a Gauss map followed it, in the map's storage
/// order. The cone BVH splits its candidates by the same rule (icosahedron, default overlap) to
/// a shallower level, and reads the cells from here instead of assigning every arc again.
#[derive(Debug)]
pub(crate) struct ArcCells {
    base: BaseSolid,
    bins: Bins,
    /// Per arc: its cell's digits ([`BuildNode::key`]), how many cells it went down (0: the
    /// root), and whether the map stopped before offering it to that cell's children.
    cells: Vec<(u32, u8, bool)>,
}

impl ArcCells {
    /// Each arc's cell, by candidate, from the builder's `nodes` and preorder `arcs`.
    fn by_candidate(nodes: &[BuildNode], arcs: &[Arc]) -> Vec<(u32, u8, bool)> {
        use std::sync::atomic::{AtomicU64, Ordering};
        // On the thread pool, node by node: every arc is in one node's own range, so each slot is
        // written once (a relaxed atomic store is a plain store). The scatter by candidate misses
        // the cache for nearly every arc; done serially, the build's step around it took 17–26 ms
        // on the dragon's 1.3M arcs at two threads, 10–11 ms this way (temporary timers).
        let packed: Vec<AtomicU64> = (0..arcs.len()).into_par_iter().map(|_| AtomicU64::new(0)).collect();
        nodes.par_iter().with_min_len(64).for_each(|n| {
            let cell = u64::from(n.key) << 16 | u64::from(n.depth) << 8 | u64::from(!n.tried);
            for a in &arcs[n.own.0 as usize..n.own.1 as usize] {
                packed[a.id as usize].store(cell, Ordering::Relaxed);
            }
        });
        packed
            .into_par_iter()
            .map(|cell| {
                let cell = cell.into_inner();
                ((cell >> 16) as u32, (cell >> 8) as u8, cell & 1 == 1)
            })
            .collect()
    }

    /// The cells `by_id` ([`ArcCells::by_candidate`]) in storage order `order`.
    fn new(base: BaseSolid, bins: Bins, by_id: &[(u32, u8, bool)], order: &[u32]) -> Self {
        ArcCells { base, bins, cells: drafter_core::gather(by_id, order) }
    }

    /// The paths [`arc_paths`] gives for `unit` (the arcs in this order) at `level` and bin radius
    /// `factor`: each arc's cell cut to `level`, and where the map stopped above `level` (a
    /// collapsed subtree, its `max_depth`) the descent goes on from there. `None` where the map
    /// used another rule.
    pub(crate) fn paths(&self, unit: &[[DVec3; 2]], level: u8, factor: f64) -> Option<Vec<(u32, u8)>> {
        let same_rule = self.base == BaseSolid::Icosahedron
            && matches!(self.bins, Bins::Overlapping { factor: f } if f64::from(f) == factor);
        if !same_rule || self.cells.len() != unit.len() || self.cells.iter().any(|&(_, c, open)| c == 0 && open) {
            return None;
        }
        let full = level + 1;
        let mut paths: Vec<(u32, u8)> = self
            .cells
            .par_iter()
            .map(|&(key, cells, _)| match cells {
                c if c >= full => (key >> (2 * u32::from(c - full)), full),
                c => (key * 4u32.pow(u32::from(full - c)), c),
            })
            .collect();
        // Runs of arcs that may go further (a node's arcs are contiguous in storage order).
        let mut runs = Vec::new();
        let mut i = 0;
        while i < self.cells.len() {
            let (key, cells, open) = self.cells[i];
            let mut j = i + 1;
            while j < self.cells.len() && self.cells[j] == (key, cells, open) {
                j += 1;
            }
            if open && cells < full {
                runs.push((i, j));
            }
            i = j;
        }
        let base = base_cells(BaseSolid::Icosahedron);
        let descend = PathDescent { unit, level, factor };
        let found: Vec<Vec<(u32, (u32, u8))>> = runs
            .into_par_iter()
            .map(|(lo, hi)| {
                let (key, cells, _) = self.cells[lo];
                let mut out = Vec::with_capacity(hi - lo);
                descend.cell(cell_of(&base, key, cells), key, cells, (lo as u32..hi as u32).collect(), &mut out);
                out
            })
            .collect();
        for (i, path) in found.into_iter().flatten() {
            paths[i as usize] = path;
        }
        Some(paths)
    }
}

fn arc_records(normals: &[[Vec3; 2]]) -> Vec<Arc> {
    normals
        .par_iter()
        .enumerate()
        .map(|(id, &[a, b])| {
            let (n1, n2) = (a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero());
            // The visit probability bound of `StopRule`, rounded down.
            let p = ((n1 - n2).length() * 0.5 + CULL_MARGIN).min(1.0);
            let p32 = p as f32;
            Arc { n1, n2, id: id as u32, p: if f64::from(p32) > p { p32.next_down() } else { p32 } }
        })
        .collect()
}

struct BuildNode {
    depth: u8,
    /// The node's own arcs, positions in the final arc order.
    own: (u32, u32),
    /// End of the subtree's arcs in the final arc order.
    sub_end: u32,
    children: Vec<u32>,
    /// The cell's digits: base face, then one digit per 4:1 split (unpadded; 0 for the root).
    key: u32,
    /// Whether the arcs were offered to the children (false at `max_depth`, at a stored leaf and
    /// where the build stopped because collapsing is optimal, where the bin rule might have taken
    /// them further).
    tried: bool,
    /// The cap over the subtree's endpoints ([`cap_of`]); zero when the caller does not
    /// need caps (a reader's guided assignment).
    cap: [f32; 4],
}

/// Subtrees holding more arcs than this are built on the thread pool (one task per child cell)
/// and appended to their parent; smaller ones in the calling thread. The tree is the same either
/// way.
const PARALLEL_ARCS: usize = 32 * 1024;

/// A cell and the cosine of its bin radius (see [`Bins`]), computed once per cell rather than
/// once per arc tested against it.
#[derive(Clone, Copy)]
struct BinCell {
    cell: Cell,
    cos_bin: f64,
}

/// For each octant of the sphere, the base cells whose circumcap, widened by [`OCTANT_MARGIN`],
/// reaches into it: the only cells [`most_inside`] can pick for a point there. The root assigns
/// every arc to a base cell, and scoring all 20 icosahedron faces (60 dot products an arc) was
/// about 15 % of a one-thread profile of the dragon's assignment; each octant meets 10 of them.
///
/// Why skipping the others picks the same cell, bit for bit: the point lies in some cell, whose
/// computed score is within rounding (about 1e-15) of a non-negative one, and that cell's cap
/// holds the point, so it is listed. A cell that is not listed is at least the margin (0.01 rad)
/// away from the point, so one of its edge planes is violated by far more than rounding and its
/// score is below that cell's. The listed cells are scored in index order with the same
/// first-of-equals rule.
#[derive(Debug)]
struct BaseByOctant {
    cells: [Vec<u8>; 8],
}

/// Angle by which [`BaseByOctant`] widens each base cell's circumcap.
const OCTANT_MARGIN: f64 = 0.01;

impl BaseByOctant {
    fn new(base: &[Cell]) -> Self {
        let mut cells: [Vec<u8>; 8] = Default::default();
        for (o, list) in cells.iter_mut().enumerate() {
            let sign = |bit: usize| if o >> bit & 1 == 1 { -1.0 } else { 1.0 };
            let s = DVec3::new(sign(0), sign(1), sign(2));
            for (k, c) in base.iter().enumerate() {
                // max c·p over unit p in the closed octant is |c⁺|, c with the components of the
                // wrong sign zeroed (c·p ≤ c⁺·p there).
                let reach = (c.center * s).max(DVec3::ZERO).length();
                let radius = c.cos_radius.clamp(-1.0, 1.0).acos();
                if reach >= (radius + OCTANT_MARGIN).min(std::f64::consts::PI).cos() - 1e-9 {
                    list.push(k as u8);
                }
            }
        }
        BaseByOctant { cells }
    }

    /// [`most_inside`] over `base` for the unit point `p` (the first of equals).
    #[inline]
    fn most_inside(&self, base: &[Cell], p: DVec3) -> usize {
        let octant = usize::from(p.x < 0.0) | usize::from(p.y < 0.0) << 1 | usize::from(p.z < 0.0) << 2;
        let mut best = (usize::MAX, f64::NEG_INFINITY);
        for &k in &self.cells[octant] {
            let s = base[usize::from(k)].score(p);
            if s > best.1 {
                best = (usize::from(k), s);
            }
        }
        best.0
    }
}

struct Builder {
    bins: Bins,
    max_depth: u8,
    base: Vec<Cell>,
    /// The base cells that may hold a point of each octant ([`BaseByOctant`]).
    by_octant: BaseByOctant,
    /// Compute each node's cap (a build; a reader's guided assignment needs none).
    caps: bool,
    /// Stop descending where collapsing the subtree is provably the cheapest choice of the
    /// cost-model pruning (see [`StopRule`]); `None` builds to `max_depth`.
    stop: Option<StopRule>,
}

/// The pruning's costs (see [`GaussMapHierarchy::build_with_cells`]), used during the build to
/// stop where the pruning would collapse whatever was built below.
///
/// A node with visit probability `p` over `n` arcs costs `p · (enter + range + block · ⌈n/4⌉)`
/// collapsed. Let `p_a` be a lower bound on the visit probability of any node holding arc `a`: a
/// cap holding both endpoints has a radius of at least half the arc, so its threshold is at least
/// `sin(θ/2) + ε = |n1 − n2| / 2 + ε` (or the whole sphere, 1). Any split of the node then costs at
/// least
/// * `p · (enter + test)`: it is entered and tests at least one child;
/// * `min(p · range, (enter + range) · max p_a)`: the arc of largest `p_a` is tested either among
///   the node's own arcs or in a descendant that is entered;
/// * `block · max(max p_a, Σ p_a / 4)`: every arc is tested in some block of 4, and the arc of
///   largest `p_a` in a block of its own at worst.
///
/// Where the collapsed cost is not above that bound, the bottom-up pruning collapses the node
/// whatever its subtree, so the build does not make the subtree. On the dragon (1.3M arcs) the
/// build makes 201k nodes instead of 396k (of which the pruning kept 24k either way).
#[derive(Clone, Copy)]
struct StopRule {
    enter: f64,
    test: f64,
    range: f64,
    block: f64,
}

/// Chunk of arcs whose endpoint sum is one partial sum of [`subtree_cap`]: sums in fixed chunks,
/// added in order, give the same bits on any number of threads.
const CAP_CHUNK: usize = 4096;

/// What [`subtree_cap`] measures of a node's arcs.
struct Measured {
    cap: [f32; 4],
    /// `Σ p_a` and `max p_a` of [`StopRule`].
    p_sum: f64,
    p_max: f64,
}

/// [`cap_of`] over the endpoints of `arcs` (centred on the cell or on the endpoints' mean,
/// whichever is tighter), and the arcs' probability bounds of [`StopRule`]. Large nodes are
/// measured on the thread pool, with the same result: the mean is summed in fixed chunks and the
/// widest angle is an exact maximum.
fn subtree_cap(arcs: &[Arc], cell_center: Option<DVec3>) -> Measured {
    let partial = |chunk: &[Arc]| {
        let (mut sum, mut p_sum, mut p_max) = (DVec3::ZERO, 0.0f64, 0.0f64);
        for a in chunk {
            sum += a.n1;
            sum += a.n2;
            let p = f64::from(a.p);
            p_sum += p;
            p_max = p_max.max(p);
        }
        (sum, p_sum, p_max)
    };
    let parallel = arcs.len() > PARALLEL_ARCS;
    let (mut mean, mut p_sum, mut p_max) = (DVec3::ZERO, 0.0, 0.0f64);
    let add = |(s, ps, pm): (DVec3, f64, f64)| {
        mean += s;
        p_sum += ps;
        p_max = p_max.max(pm);
    };
    // The partial sums added in chunk order either way (a small node's in place: most nodes are).
    if parallel {
        arcs.par_chunks(CAP_CHUNK).map(partial).collect::<Vec<_>>().into_iter().for_each(add);
    } else {
        arcs.chunks(CAP_CHUNK).map(partial).for_each(add);
    }
    let widest = |c: &[DVec3]| {
        let of = |chunk: &[Arc]| widest_angles_of_arcs(c, chunk);
        let max = |a: [f64; 2], b: [f64; 2]| [a[0].max(b[0]), a[1].max(b[1])];
        if parallel { arcs.par_chunks(CAP_CHUNK).map(of).reduce(|| [0.0; 2], max) } else { of(arcs) }
    };
    // A bound below the true one (rounding of the norms and of `sin`) keeps the rule conservative.
    let shrink = 1.0 - 1e-9;
    Measured { cap: cap_of(cell_center, mean, widest), p_sum: p_sum * shrink, p_max: p_max * shrink }
}

/// A stored breadth-first tree and a node's index in it, which a reader's assignment follows.
type Guide<'a> = Option<(&'a [[u32; 4]], usize)>;

/// Where an arc goes at a node: it stays there.
const STAY: u8 = u8::MAX;

impl Builder {
    fn bin_cell(&self, cell: Cell) -> BinCell {
        let cos_bin = match self.bins {
            Bins::Strict => 0.0,
            Bins::Overlapping { factor } => bin_cos(&cell, f64::from(factor)),
        };
        BinCell { cell, cos_bin }
    }

    #[inline]
    fn fits(&self, bin: &BinCell, arc: &Arc) -> bool {
        match self.bins {
            Bins::Strict => bin.cell.score(arc.n1) >= 0.0 && bin.cell.score(arc.n2) >= 0.0,
            Bins::Overlapping { .. } => fits_bin(&bin.cell, bin.cos_bin, [arc.n1, arc.n2]),
        }
    }

    /// Appends to `out` the subtree, in preorder, for `cell` (`None`: the root) holding `arcs`,
    /// which start at position `offset` of the final order, and leaves the arcs in that order: the
    /// node's own arcs, then each child's subtree (stable: input order within each).
    ///
    /// The arcs move between two buffers, one scatter per level (ping-pong): `arcs` holds them on
    /// entry and `spare` is free, as long as `arcs`. `flipped` says that `arcs` is the caller's
    /// scratch buffer and `spare` its arc buffer, where the final order must end up.
    ///
    /// With `guide` (a stored breadth-first tree and this node's index in it) the descent follows
    /// the stored tree instead of going to `max_depth`: a stored leaf keeps all its arcs (in input
    /// order, as the build stores a collapsed subtree), and a stored inner node must split into
    /// exactly its stored children. Returns false where the arcs do not split as stored.
    #[allow(clippy::too_many_arguments)]
    fn node(
        &self,
        cell: Option<Cell>,
        depth: u8,
        arcs: &mut [Arc],
        spare: &mut [Arc],
        flipped: bool,
        offset: u32,
        out: &mut Vec<BuildNode>,
        (key, guide): (u32, Guide<'_>),
        parent_prob: f64,
    ) -> bool {
        let index = out.len();
        let (cap, prob, stop) = if self.caps {
            let m = subtree_cap(arcs, cell.map(|c| c.center));
            let prob = parent_prob.min(f64::from(m.cap[3]).min(1.0));
            let stop = self.stop.is_some_and(|r| {
                let n = arcs.len() as f64;
                let collapsed = prob * (r.enter + r.range + r.block * (n / 4.0).ceil());
                let split_at_least = prob * (r.enter + r.test)
                    + (prob * r.range).min((r.enter + r.range) * m.p_max)
                    + r.block * m.p_max.max(m.p_sum / 4.0);
                collapsed <= split_at_least * (1.0 - 1e-9)
            });
            (m.cap, prob, stop)
        } else {
            ([0.0; 4], parent_prob, false)
        };
        out.push(BuildNode {
            depth,
            own: (offset, offset),
            sub_end: offset + arcs.len() as u32,
            children: Vec::new(),
            key,
            tried: false,
            cap,
        });
        let stored_children = guide.map(|(tree, at)| tree[at][1]);
        let children: Vec<BinCell> = match cell {
            _ if stored_children == Some(0) || stop => Vec::new(),
            None => self.base.iter().map(|&c| self.bin_cell(c)).collect(),
            // Depth 1 is level 0; a cell at level `depth - 1` splits while that is below max_depth.
            Some(c) if depth <= self.max_depth => c.children().iter().map(|&c| self.bin_cell(c)).collect(),
            Some(_) => Vec::new(),
        };
        if children.is_empty() {
            out[index].own.1 = offset + arcs.len() as u32;
            if flipped {
                spare.copy_from_slice(arcs);
            }
            return stored_children.is_none_or(|c| c == 0);
        }
        out[index].tried = true;
        // Where each arc goes, then a stable counting scatter: own arcs first, then by child.
        let quad = (children.len() == 4).then(|| Quad::of(&children));
        let overlapping = matches!(self.bins, Bins::Overlapping { .. });
        // The general rule (the root's base cells, strict bins); `Quad::targets` for a 4:1 split
        // under overlapping bins, the bulk of the work.
        let target = |g: &Arc| {
            g.mid()
                .and_then(|m| {
                    let best = match &quad {
                        Some(q) => q.most_inside(m),
                        None => self.by_octant.most_inside(&self.base, m),
                    };
                    (best < children.len() && self.fits(&children[best], g)).then_some(best as u8)
                })
                .unwrap_or(STAY)
        };
        let targets: Vec<u8> = match &quad {
            Some(q) if overlapping => {
                let mut t = vec![0u8; arcs.len()];
                if arcs.len() > PARALLEL_ARCS {
                    t.par_chunks_mut(4096).zip(arcs.par_chunks(4096)).for_each(|(t, a)| q.targets(&children, a, t));
                } else {
                    q.targets(&children, arcs, &mut t);
                }
                t
            }
            _ if arcs.len() > PARALLEL_ARCS => arcs.par_iter().with_min_len(4096).map(target).collect(),
            _ => arcs.iter().map(target).collect(),
        };
        let bucket = |t: u8| if t == STAY { 0 } else { usize::from(t) + 1 };
        // At most the 20 base cells, the own arcs and an end: on the stack (one node per cell).
        let mut starts = [0usize; 22];
        let starts = &mut starts[..children.len() + 2];
        if arcs.len() > PARALLEL_ARCS {
            drafter_core::scatter_in_parallel(arcs, |i| bucket(targets[i]), SCATTER_CHUNK, spare, starts);
        } else {
            for &t in &targets {
                starts[bucket(t) + 1] += 1;
            }
            for k in 1..starts.len() {
                starts[k] += starts[k - 1];
            }
            let mut next = [0usize; 22];
            next[..starts.len()].copy_from_slice(starts);
            for (g, &t) in arcs.iter().zip(&targets) {
                let b = bucket(t);
                spare[next[b]] = *g;
                next[b] += 1;
            }
        }
        drop(targets);
        // The arcs are now in `spare`; the own ones stay there if that is the final buffer.
        if !flipped {
            arcs[..starts[1]].copy_from_slice(&spare[..starts[1]]);
        }
        out[index].own.1 = offset + starts[1] as u32;
        let filled = (0..children.len()).filter(|&k| starts[k + 2] > starts[k + 1]).count();
        if stored_children.is_some_and(|c| c as usize != filled) {
            return false;
        }

        // The children's ranges, split off the two buffers in order; the roles swap below.
        let parallel = arcs.len() > PARALLEL_ARCS;
        let mut work = Vec::new();
        let (mut rest, mut rest_spare) = (&mut spare[starts[1]..], &mut arcs[starts[1]..]);
        for k in 0..children.len() {
            let len = starts[k + 2] - starts[k + 1];
            let (these, tail) = rest.split_at_mut(len);
            let (these_spare, tail_spare) = rest_spare.split_at_mut(len);
            (rest, rest_spare) = (tail, tail_spare);
            if len > 0 {
                let child_guide = guide.map(|(tree, at)| (tree, tree[at][0] as usize + work.len()));
                let child_key = if cell.is_none() { k as u32 } else { key * 4 + k as u32 };
                work.push((
                    children[k].cell,
                    these,
                    these_spare,
                    offset + starts[k + 1] as u32,
                    (child_key, child_guide),
                ));
            }
        }
        if parallel {
            let subtrees: Vec<(Vec<BuildNode>, bool)> = work
                .into_par_iter()
                .map(|(cell, these, these_spare, at, g)| {
                    let mut sub = Vec::new();
                    let ok = self.node(Some(cell), depth + 1, these, these_spare, !flipped, at, &mut sub, g, prob);
                    (sub, ok)
                })
                .collect();
            let mut ok = true;
            for (sub, fine) in subtrees {
                ok &= fine;
                let node_offset = out.len() as u32;
                out[index].children.push(node_offset);
                out.extend(sub.into_iter().map(|mut n| {
                    n.children.iter_mut().for_each(|c| *c += node_offset);
                    n
                }));
            }
            ok
        } else {
            for (cell, these, these_spare, at, g) in work {
                let child = out.len() as u32;
                if !self.node(Some(cell), depth + 1, these, these_spare, !flipped, at, out, g, prob) {
                    return false;
                }
                out[index].children.push(child);
            }
            true
        }
    }
}

/// The four children of a cell ([`Cell::children`]: three corners, then the middle one) for
/// [`Quad::most_inside`]. Each corner shares one edge with the middle cell, and its edge plane
/// is the middle's plane negated, bit for bit (a cross product with its factors swapped, then
/// normalised), so the four scores need 9 dot products instead of 12.
struct Quad {
    /// Each corner's two planes not shared with the middle cell.
    outer: [[DVec3; 2]; 3],
    middle: [DVec3; 3],
}

impl Quad {
    fn of(children: &[BinCell]) -> Quad {
        let [c0, c1, c2, c3] = [0, 1, 2, 3].map(|k| children[k].cell.planes);
        debug_assert!(c0[1] == -c3[2] && c1[2] == -c3[0] && c2[0] == -c3[1]);
        Quad { outer: [[c0[0], c0[2]], [c1[0], c1[1]], [c2[1], c2[2]]], middle: c3 }
    }

    /// What `Cell::score` and the first-of-equals maximum give over the four children.
    #[inline(always)]
    fn most_inside(&self, p: DVec3) -> usize {
        let d = self.middle.map(|m| m.dot(p));
        let o = self.outer.map(|[a, b]| [a.dot(p), b.dot(p)]);
        // `Cell::score`'s order of minima (a minimum of non-NaN values does not depend on it).
        let scores = [
            min(min(o[0][0], -d[2]), o[0][1]),
            min(min(o[1][0], o[1][1]), -d[0]),
            min(min(-d[1], o[2][0]), o[2][1]),
            min(min(d[0], d[1]), d[2]),
        ];
        // The first of equals, without branches: which child wins is as good as random from one
        // arc to the next, so a branch on it would often be mispredicted.
        let (mut best, mut high) = (0, scores[0]);
        for (k, s) in scores.into_iter().enumerate().skip(1) {
            let higher = s > high;
            best = if higher { k } else { best };
            high = if higher { s } else { high };
        }
        best
    }

    /// [`Quad::target`] of every arc of `arcs` into `out`: four arcs at a time with AVX where the
    /// CPU has it (without FMA, so every lane rounds as the scalar code does and the result is
    /// the same bits on any machine).
    fn targets(&self, bins: &[BinCell], arcs: &[Arc], out: &mut [u8]) {
        #[cfg(target_arch = "x86_64")]
        #[allow(unsafe_code)]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX, the one feature the function is compiled with.
            return unsafe { self.targets_avx(bins, arcs, out) };
        }
        for (a, t) in arcs.iter().zip(out) {
            *t = self.target(bins, a);
        }
    }

    /// [`Quad::targets`] on 4 lanes: the same operations as [`Quad::target`] in the same order
    /// (glam's dot product is `(x·x' + y·y') + z·z'`; `_mm256_min_pd(a, b)` is `if a < b { a } else
    /// { b }`, as is [`min`]; negation flips the sign bit), so each lane gives that arc's target
    /// bit for bit (tested). Written with `std::arch` because no crate offers `f64` lanes with
    /// IEEE rounding that stays free of fused multiply-adds; the win is the dragon's level-by-level
    /// child choice, 8.5 million arc-levels.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    #[allow(unsafe_code)]
    fn targets_avx(&self, bins: &[BinCell], arcs: &[Arc], out: &mut [u8]) {
        use std::arch::x86_64::*;
        let splat = |x: f64| _mm256_set1_pd(x);
        let dot = |p: DVec3, x: __m256d, y: __m256d, z: __m256d| {
            _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(splat(p.x), x), _mm256_mul_pd(splat(p.y), y)),
                _mm256_mul_pd(splat(p.z), z),
            )
        };
        let neg = |x: __m256d| _mm256_xor_pd(x, splat(-0.0));
        let vmin = |a: __m256d, b: __m256d| _mm256_min_pd(a, b);
        let zero = _mm256_setzero_pd();
        let n = arcs.len() / 4 * 4;
        for (four, t) in arcs[..n].chunks_exact(4).zip(out[..n].chunks_exact_mut(4)) {
            let lanes = |f: fn(&Arc) -> f64| _mm256_setr_pd(f(&four[0]), f(&four[1]), f(&four[2]), f(&four[3]));
            let (ax, ay, az) = (lanes(|a| a.n1.x), lanes(|a| a.n1.y), lanes(|a| a.n1.z));
            let (bx, by, bz) = (lanes(|a| a.n2.x), lanes(|a| a.n2.y), lanes(|a| a.n2.z));
            let nonzero = |x: __m256d, y: __m256d, z: __m256d| {
                _mm256_or_pd(
                    _mm256_or_pd(_mm256_cmp_pd::<_CMP_NEQ_UQ>(x, zero), _mm256_cmp_pd::<_CMP_NEQ_UQ>(y, zero)),
                    _mm256_cmp_pd::<_CMP_NEQ_UQ>(z, zero),
                )
            };
            let (sx, sy, sz) = (_mm256_add_pd(ax, bx), _mm256_add_pd(ay, by), _mm256_add_pd(az, bz));
            let length = _mm256_sqrt_pd(_mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(sx, sx), _mm256_mul_pd(sy, sy)),
                _mm256_mul_pd(sz, sz),
            ));
            let real = _mm256_and_pd(
                _mm256_and_pd(nonzero(ax, ay, az), nonzero(bx, by, bz)),
                _mm256_cmp_pd::<_CMP_GT_OQ>(length, splat(1e-9)),
            );
            let inv = _mm256_div_pd(splat(1.0), length);
            let (mx, my, mz) = (_mm256_mul_pd(sx, inv), _mm256_mul_pd(sy, inv), _mm256_mul_pd(sz, inv));
            let d = self.middle.map(|p| dot(p, mx, my, mz));
            let o = self.outer.map(|[a, b]| [dot(a, mx, my, mz), dot(b, mx, my, mz)]);
            let scores = [
                vmin(vmin(o[0][0], neg(d[2])), o[0][1]),
                vmin(vmin(o[1][0], o[1][1]), neg(d[0])),
                vmin(vmin(neg(d[1]), o[2][0]), o[2][1]),
                vmin(vmin(d[0], d[1]), d[2]),
            ];
            let (mut best, mut high) = (zero, scores[0]);
            let (mut cx, mut cy, mut cz, mut cos) = {
                let c = &bins[0];
                (splat(c.cell.center.x), splat(c.cell.center.y), splat(c.cell.center.z), splat(c.cos_bin))
            };
            for (k, &score) in scores.iter().enumerate().skip(1) {
                let higher = _mm256_cmp_pd::<_CMP_GT_OQ>(score, high);
                let pick = |now: __m256d, x: f64| _mm256_blendv_pd(now, splat(x), higher);
                best = pick(best, k as f64);
                high = _mm256_blendv_pd(high, score, higher);
                let c = &bins[k];
                (cx, cy, cz, cos) = (
                    pick(cx, c.cell.center.x),
                    pick(cy, c.cell.center.y),
                    pick(cz, c.cell.center.z),
                    pick(cos, c.cos_bin),
                );
            }
            let center_dot = |x: __m256d, y: __m256d, z: __m256d| {
                _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(cx, x), _mm256_mul_pd(cy, y)), _mm256_mul_pd(cz, z))
            };
            let fits = _mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(center_dot(ax, ay, az), cos),
                _mm256_cmp_pd::<_CMP_GE_OQ>(center_dot(bx, by, bz), cos),
            );
            let stored = _mm256_movemask_pd(_mm256_and_pd(real, fits));
            let mut k = [0f64; 4];
            // SAFETY: `k` holds 4 f64s; the store is unaligned.
            unsafe { _mm256_storeu_pd(k.as_mut_ptr(), best) };
            for (lane, t) in t.iter_mut().enumerate() {
                *t = if stored >> lane & 1 == 1 { k[lane] as u8 } else { STAY };
            }
        }
        for (a, t) in arcs[n..].iter().zip(&mut out[n..]) {
            *t = self.target(bins, a);
        }
    }

    /// The child an arc goes to from this cell under overlapping bins: [`Quad::most_inside`] of its
    /// midpoint, if both endpoints lie in that child's bin; [`STAY`] otherwise, and for a zero or
    /// antipodal arc. What the builder's general rule gives (`arc_mid`, `most_inside`, `fits_bin`),
    /// with every step computed whatever the arc and the outcome selected at the end: the
    /// outcomes are as good as random from one arc to the next, so branches on them would often
    /// be mispredicted.
    #[inline(always)]
    fn target(&self, bins: &[BinCell], a: &Arc) -> u8 {
        let sum = a.n1 + a.n2;
        let length = sum.length();
        let real = (a.n1 != DVec3::ZERO) & (a.n2 != DVec3::ZERO) & (length > 1e-9);
        // `arc_mid`'s midpoint (NaN or infinite where `real` is false; then unused).
        let m = sum * (1.0 / length);
        let k = self.most_inside(m);
        let c = &bins[k];
        let fits = (c.cell.center.dot(a.n1) >= c.cos_bin) & (c.cell.center.dot(a.n2) >= c.cos_bin);
        if real & fits { k as u8 } else { STAY }
    }
}

/// The widest angle between the unit vector `c` and the unit vectors `points`. The exact angle
/// (`atan2` of the cross and dot products, accurate at every size) is evaluated only for points
/// whose dot product is within rounding of the smallest so far, so the result is the exact
/// maximum over all points at a few `atan2` calls per node instead of one per point.
#[cfg(test)]
fn widest_angle(c: DVec3, points: impl Iterator<Item = DVec3>) -> f64 {
    let mut w = Widest::default();
    for p in points {
        w.add(c, p);
    }
    w.widest
}

/// [`widest_angle`] over both endpoints of `arcs`, from each of up to two centres `cs` in one pass
/// over the arcs (the first `cs.len()` results; the others are 0), a group of 4 arcs at a time
/// ([`Widest::add_group`]). The build runs this over every arc at every level.
fn widest_angles_of_arcs(cs: &[DVec3], arcs: &[Arc]) -> [f64; 2] {
    let mut w = [Widest::default(), Widest::default()];
    let cs = &cs[..cs.len().min(2)];
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: the CPU has AVX, the one feature the function is compiled with.
    let arcs = if std::arch::is_x86_feature_detected!("avx") { unsafe { widest_avx(cs, arcs, &mut w) } } else { arcs };
    for four in arcs.chunks(4) {
        for (&c, w) in cs.iter().zip(w.iter_mut()) {
            let mut dots = [f64::NAN; 8];
            for (k, a) in four.iter().enumerate() {
                dots[2 * k] = c.dot(a.n1);
                dots[2 * k + 1] = c.dot(a.n2);
            }
            w.add_group(c, &dots[..2 * four.len()], |k| if k % 2 == 0 { four[k / 2].n1 } else { four[k / 2].n2 });
        }
    }
    [w[0].widest, w[1].widest]
}

/// [`widest_angles_of_arcs`] on the arcs in whole groups of 4, into `w`; returns the arcs left.
/// The 8 dot products of a group with each centre in one pass (rounded as glam's, without FMA,
/// so the same bits as the scalar loop), their minimum across the lanes, and `atan2` only for the
/// lanes [`Widest::add_group`] picks. Small nodes (most of them hold a handful of arcs) spent most
/// of this function in `atan2` when every point of a group that came near the smallest dot product
/// so far was measured.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn widest_avx<'a>(cs: &[DVec3], arcs: &'a [Arc], w: &mut [Widest; 2]) -> &'a [Arc] {
    use std::arch::x86_64::*;
    let splat = |x: f64| _mm256_set1_pd(x);
    let groups = arcs.chunks_exact(4);
    let rest = groups.remainder();
    for four in groups {
        let lanes = |f: fn(&Arc) -> f64| _mm256_setr_pd(f(&four[0]), f(&four[1]), f(&four[2]), f(&four[3]));
        let n1 = [lanes(|a| a.n1.x), lanes(|a| a.n1.y), lanes(|a| a.n1.z)];
        let n2 = [lanes(|a| a.n2.x), lanes(|a| a.n2.y), lanes(|a| a.n2.z)];
        for (&c, w) in cs.iter().zip(w.iter_mut()) {
            let dot = |[x, y, z]: [__m256d; 3]| {
                _mm256_add_pd(
                    _mm256_add_pd(_mm256_mul_pd(splat(c.x), x), _mm256_mul_pd(splat(c.y), y)),
                    _mm256_mul_pd(splat(c.z), z),
                )
            };
            let (d1, d2) = (dot(n1), dot(n2));
            // The smallest of the 8 (a minimum of non-NaN values in any order is the same value).
            let m = _mm256_min_pd(d1, d2);
            let m = _mm256_min_pd(m, _mm256_permute2f128_pd::<1>(m, m));
            let m = _mm256_min_pd(m, _mm256_permute_pd::<0b0101>(m));
            let smallest = _mm256_cvtsd_f64(m);
            if smallest > w.cos_min + Widest::DOT_SLACK || smallest.is_nan() {
                continue;
            }
            let mut dots = [0f64; 8];
            // SAFETY: `dots` holds 8 f64s; the stores are unaligned.
            #[allow(unsafe_code)]
            unsafe {
                _mm256_storeu_pd(dots.as_mut_ptr(), d1);
                _mm256_storeu_pd(dots.as_mut_ptr().add(4), d2);
            }
            // Lane k of `d1` is arc k's first endpoint, lane k of `d2` its second.
            w.add_group(c, &dots, |k| if k < 4 { four[k].n1 } else { four[k - 4].n2 });
        }
    }
    rest
}

/// The running state of [`widest_angle`].
struct Widest {
    cos_min: f64,
    widest: f64,
}

impl Default for Widest {
    fn default() -> Self {
        Widest { cos_min: f64::INFINITY, widest: 0.0 }
    }
}

impl Widest {
    /// A dot product of unit vectors is off by at most a few ulp of 1; two points whose true
    /// angles are in the opposite order of their rounded dot products differ by less than this.
    const DOT_SLACK: f64 = 1e-15;

    #[cfg(test)]
    fn add(&mut self, c: DVec3, p: DVec3) {
        self.add_group(c, &[c.dot(p)], |_| p);
    }

    /// Takes the points `point(k)` whose dot products with the centre `c` are `dots[k]`: the
    /// smallest dot product so far is lowered to theirs, and the exact angle of a point is
    /// measured only where its dot product is within [`Self::DOT_SLACK`] of that. A point outside
    /// has a dot product beyond the slack above the smallest one seen by then, which stays above
    /// the final smallest, so its angle is below that point's, which is measured: the widest angle
    /// is the maximum over every point whichever way the points are grouped.
    #[inline(always)]
    fn add_group(&mut self, c: DVec3, dots: &[f64], point: impl Fn(usize) -> DVec3) {
        let smallest = dots.iter().fold(f64::INFINITY, |m, &d| min(m, d));
        // (NaN compares false: nothing to take.)
        if smallest.is_nan() || smallest > self.cos_min + Self::DOT_SLACK {
            return;
        }
        self.cos_min = self.cos_min.min(smallest);
        let near = self.cos_min + Self::DOT_SLACK;
        for (k, &d) in dots.iter().enumerate() {
            if d <= near {
                self.widest = self.widest.max(c.cross(point(k)).length().atan2(d));
            }
        }
    }
}

/// The cap of a set of unit endpoints: `[cx, cy, cz, threshold]` with the centre in `f32` and the
/// threshold `sin r + ε` rounded up, `r` measured from the `f32` centre. The centre is the cell's
/// centre or the endpoints' mean (`mean`: their sum, any length), whichever gives the smaller
/// radius; `widest` is the widest angle from a unit centre to the endpoints.
fn cap_of(cell_center: Option<DVec3>, mean: DVec3, widest: impl Fn(&[DVec3]) -> [f64; 2]) -> [f32; 4] {
    let mut centres = [(Vec3::ZERO, DVec3::ZERO); 2];
    let mut count = 0;
    for center in [cell_center, (mean.length() > 1e-12).then(|| mean.normalize())].into_iter().flatten() {
        let c32 = center.as_vec3();
        centres[count] = (c32, c32.as_dvec3().normalize());
        count += 1;
    }
    let units = centres.map(|(_, c)| c);
    let radii = widest(&units[..count]);
    let mut best: Option<([f32; 3], f64)> = None;
    for ((c32, _), r) in centres.into_iter().zip(radii).take(count) {
        if best.is_none_or(|(_, b)| r < b) {
            best = Some((c32.to_array(), r));
        }
    }
    let Some(([x, y, z], r)) = best else { return [0.0, 0.0, 1.0, NEVER_CULL] };
    // 1e-9 rad covers the rounding of atan2 itself.
    let r = r + 1e-9;
    if r >= std::f64::consts::FRAC_PI_2 - 1e-3 {
        return [x, y, z, NEVER_CULL];
    }
    [x, y, z, round_up(r.sin() + CULL_MARGIN)]
}

fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

impl GaussMapHierarchy {
    /// Builds the hierarchy over candidates with `normals` (see [`crate::FeatureEdges`]).
    pub fn build(normals: &[[Vec3; 2]], options: &GaussMapOptions, cost: &CostModel) -> Self {
        Self::build_with_cells(normals, options, cost, Purpose::Query).0
    }

    /// [`GaussMapHierarchy::build`], also giving where each arc went (in storage order). A
    /// [`Purpose::Storage`] build cannot answer queries (it has no arc blocks); only its arrays,
    /// predicted cost and cells are used.
    pub(crate) fn build_with_cells(
        normals: &[[Vec3; 2]],
        options: &GaussMapOptions,
        cost: &CostModel,
        purpose: Purpose,
    ) -> (Self, ArcCells) {
        Self::build_stopping(normals, options, cost, true, purpose)
    }

    /// [`GaussMapHierarchy::build_with_cells`]; `early_stop` false builds every subtree to
    /// `max_depth` before pruning (the reference the stop rule is tested against).
    fn build_stopping(
        normals: &[[Vec3; 2]],
        options: &GaussMapOptions,
        cost: &CostModel,
        early_stop: bool,
        purpose: Purpose,
    ) -> (Self, ArcCells) {
        let max_depth = options.max_depth.unwrap_or_else(|| depth_for_count(normals.len(), options.base)).min(12);
        let stop = (options.prune && early_stop).then(|| StopRule {
            enter: f64::from(cost.gauss_enter_ns),
            test: f64::from(cost.gauss_test_ns),
            range: f64::from(cost.gauss_range_ns),
            block: f64::from(cost.gauss_block_ns),
        });
        let Some((nodes, arcs)) = assign(normals, options.base, options.bins, max_depth, None, stop) else {
            unreachable!("an unguided assignment always succeeds")
        };
        let mut order: Vec<u32> = arcs.par_iter().map(|a| a.id).collect();
        // Caps over each subtree's endpoints, computed by the build.
        let caps: Vec<[f32; 4]> = nodes.iter().map(|n| n.cap).collect();
        let by_id = ArcCells::by_candidate(&nodes, &arcs);
        drop(arcs);
        let assigned =
            LevelHistogram::from_nodes(nodes.iter().map(|n| (u32::from(n.depth), (n.own.1 - n.own.0) as usize)));

        // Expected cost, bottom-up: collapse a subtree when one node is cheaper.
        let prob = visit_probabilities(&nodes, &caps);
        let enter = f64::from(cost.gauss_enter_ns);
        let test = f64::from(cost.gauss_test_ns);
        let range = f64::from(cost.gauss_range_ns);
        let block = f64::from(cost.gauss_block_ns);
        let mut best = vec![0.0f64; nodes.len()];
        let mut collapse = vec![false; nodes.len()];
        for i in (0..nodes.len()).rev() {
            let n = &nodes[i];
            let own = f64::from((n.own.1 - n.own.0).div_ceil(4));
            let sub = f64::from((n.sub_end - n.own.0).div_ceil(4));
            let children: f64 = n.children.iter().map(|&c| best[c as usize]).sum();
            let split = prob[i]
                * (enter + test * n.children.len() as f64 + if own > 0.0 { range + block * own } else { 0.0 })
                + children;
            let collapsed = prob[i] * (enter + range + block * sub);
            if options.prune && !n.children.is_empty() && collapsed <= split {
                collapse[i] = true;
                best[i] = collapsed;
            } else {
                best[i] = split;
            }
        }

        // Collapsed nodes own their whole subtree (contiguous in the preorder `order`), in input
        // order: the order in which the arcs reached the node, so that a reader's assignment can
        // stop there (see `assign`). The scatter is stable, so that is ascending candidate order.
        let mut inside_collapsed = vec![false; nodes.len()];
        let mut sorted_ranges = Vec::new();
        for i in 0..nodes.len() {
            if collapse[i] && !inside_collapsed[i] {
                let n = &nodes[i];
                sorted_ranges.push(n.own.0 as usize..n.sub_end as usize);
            }
            if collapse[i] || inside_collapsed[i] {
                for &c in &nodes[i].children {
                    inside_collapsed[c as usize] = true;
                }
            }
        }
        sort_ranges(&mut order, &sorted_ranges);
        let no_children: &[u32] = &[];
        let (flat, bfs_order, source) = breadth_first(
            0,
            |i| if collapse[i] { no_children } else { &nodes[i].children },
            |i| {
                let n = &nodes[i];
                &order[n.own.0 as usize..if collapse[i] { n.sub_end } else { n.own.1 } as usize]
            },
        );
        let flat_caps: Vec<[f32; 4]> = source.iter().map(|&i| caps[i]).collect();
        let a = assemble(&flat, &flat_caps, &bfs_order, normals, purpose);
        let cells = ArcCells::new(options.base, options.bins, &by_id, &bfs_order);
        let mut h = GaussMapHierarchy {
            base: options.base,
            bins: options.bins,
            max_depth,
            nodes: a.nodes,
            widest: a.widest,
            blocks: a.blocks,
            identity: is_identity(&bfs_order),
            flat,
            caps: flat_caps,
            order: bfs_order,
            assigned: Some(assigned),
            predicted_ns: 0.0,
        };
        h.predicted_ns = h.estimate_ns(cost);
        (h, cells)
    }

    /// The bins the hierarchy was built with.
    pub fn bins(&self) -> Bins {
        self.bins
    }

    /// Mean modelled cost of a query over 64 fixed directions.
    fn estimate_ns(&self, cost: &CostModel) -> f64 {
        let dirs = sample_directions(64);
        // On the thread pool, summed in direction order: the same figure at any thread count.
        let costs: Vec<f64> = dirs.par_iter().map(|&d| self.counts_only(d).cost_ns(cost, true)).collect();
        costs.iter().sum::<f64>() / dirs.len() as f64
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    pub fn node_count(&self) -> usize {
        self.flat.len()
    }

    pub fn base(&self) -> BaseSolid {
        self.base
    }

    /// The deepest level that was built (before pruning).
    pub fn max_depth(&self) -> u8 {
        self.max_depth
    }

    /// Arcs and nodes per level as stored (after pruning).
    pub fn histogram(&self) -> LevelHistogram {
        let depth = depths(&self.flat);
        LevelHistogram::from_nodes(self.flat.iter().zip(depth).map(|(n, d)| (d, (n[3] - n[2]) as usize)))
    }

    /// Arcs per level as assigned by the bins, before pruning (Table 2 of the paper), as far as
    /// the build descended (it stops where the pruning provably collapses a subtree, whose arcs
    /// then count at that node); `None` for a hierarchy loaded from arrays.
    pub fn assigned_histogram(&self) -> Option<&LevelHistogram> {
        self.assigned.as_ref()
    }

    /// Expected time of one query under the cost model used to build it, estimated over fixed
    /// directions (0 when loaded from arrays).
    pub fn predicted_ns_per_query(&self) -> f64 {
        self.predicted_ns
    }

    /// Silhouettes for view direction `direction` into `out` (reset to [`GaussMapHierarchy::len`]).
    pub fn query(&self, direction: Vec3, out: &mut EdgeSet) {
        self.walk::<false>(direction, out);
    }

    /// [`GaussMapHierarchy::query`] that also counts its work.
    pub fn query_counted(&self, direction: Vec3, out: &mut EdgeSet) -> QueryCounts {
        self.walk::<true>(direction, out)
    }

    /// Bits of the nodes `first..first + 4` whose caps meet the great circle of `u`.
    #[inline(always)]
    fn meets4(&self, first: usize, u: Vec3) -> u32 {
        let Some(four) = self.nodes.get(first..first + 4) else { return 0 };
        // Rows of the transpose: x, y, z and threshold of the 4 caps.
        let m = glam::Mat4::from_cols(four[0].cap, four[1].cap, four[2].cap, four[3].cap).transpose();
        let d = m.x_axis * u.x + m.y_axis * u.y + m.z_axis * u.z;
        // Culled iff |c·u| > threshold; NaN compares false and is entered.
        d.abs().cmpgt(m.w_axis).bitmask() ^ 0xF
    }

    /// The counts of [`GaussMapHierarchy::query_counted`] without testing any arc: which nodes a
    /// walk enters and which blocks it reads depend on the caps alone.
    fn counts_only(&self, direction: Vec3) -> QueryCounts {
        let Some(u) = unit_direction(direction) else { return QueryCounts::default() };
        self.walk_into::<true, false>(u, &mut [], &mut Vec::new())
    }

    /// Answers in storage order (`into_storage_order`) go straight into `out`; otherwise through
    /// a storage-order bitset mapped by `order`.
    #[inline]
    fn walk<const COUNT: bool>(&self, direction: Vec3, out: &mut EdgeSet) -> QueryCounts {
        out.reset(self.len());
        let Some(u) = unit_direction(direction) else { return QueryCounts::default() };
        if self.identity {
            let (words, dirty) = out.words_and_dirty();
            return self.walk_into::<COUNT, true>(u, words, dirty);
        }
        let mut storage = vec![0u64; self.len().div_ceil(64)];
        let counts = self.walk_into::<COUNT, true>(u, &mut storage, &mut Vec::new());
        for (w, &word) in storage.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let k = 64 * w + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                out.insert(self.order[k] as usize);
            }
        }
        counts
    }

    /// Breadth-first walk: for the nodes of a level, test their children's caps (4 at a time)
    /// into the next level and collect their own block ranges; then test the ranges in one
    /// stream (the data of a query over a large model is scattered over far more memory than the
    /// caches hold, and a stream keeps the loads in flight). Hits set storage positions in `words`;
    /// without `TEST` no arc is tested (the counts alone).
    #[inline]
    fn walk_into<const COUNT: bool, const TEST: bool>(
        &self,
        u: Vec3,
        words: &mut [u64],
        dirty: &mut Vec<u32>,
    ) -> QueryCounts {
        let mut counts = QueryCounts { bounds_tested: usize::from(COUNT), ..Default::default() };
        if self.flat.is_empty() || self.meets4(0, u) & 1 == 0 {
            return counts;
        }
        with_ranges(|ranges| {
            with_levels(self.widest + 4, |level, next| {
                level[0] = 0;
                let mut width = 1;
                while width > 0 {
                    let mut next_width = 0;
                    for &i in &level[..width] {
                        let n = &self.nodes[i as usize];
                        let (first, end) = (n.first_child as usize, (n.first_child + n.child_count) as usize);
                        push_children(next, &mut next_width, first, end, |f| self.meets4(f, u));
                        if n.block_start < n.block_end {
                            ranges.push([n.block_start, n.block_end]);
                        }
                        if COUNT {
                            counts.nodes_entered += 1;
                            counts.bounds_tested += end - first;
                            if n.block_start < n.block_end {
                                let [_, _, start, end] = self.flat[i as usize];
                                counts.ranges += 1;
                                counts.blocks_tested += (n.block_end - n.block_start) as usize;
                                counts.arcs_tested += (end - start) as usize;
                            }
                        }
                    }
                    std::mem::swap(level, next);
                    width = next_width;
                }
            });
            if TEST {
                self.blocks.test_ranges(ranges, u, words, dirty);
            }
        });
        counts
    }

    /// The candidate index of each storage position.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The same hierarchy with candidates renumbered in its storage order, and the permutation:
    /// candidate `k` of the result is candidate `permutation[k]` of the input. Reorder the
    /// candidates with it (as [`crate::SilhouetteIndex`] does) and queries write their hits
    /// straight into the answer instead of mapping each through `order`.
    pub fn into_storage_order(mut self) -> (Self, Vec<u32>) {
        let identity = (0..self.order.len() as u32).collect();
        let permutation = std::mem::replace(&mut self.order, identity);
        self.identity = true;
        (self, permutation)
    }

    /// The flat arrays (see [`GaussMapArrays`]).
    pub fn to_arrays(&self) -> GaussMapArrays {
        GaussMapArrays {
            base: self.base.code(),
            max_depth: u32::from(self.max_depth),
            node_caps: self.caps.iter().flatten().copied().collect(),
            overlap: match self.bins {
                Bins::Strict => 0.0,
                Bins::Overlapping { factor } => factor,
            },
            nodes: self.flat.iter().flatten().copied().collect(),
        }
    }

    /// Rebuilds a hierarchy from its arrays and the candidates' normals: assigns every arc to its
    /// cell with the builder's own arithmetic (the storage order is not stored), checks that the
    /// result has exactly the stored nodes, and that every cap really bounds the endpoints below
    /// it (so a corrupted file cannot make a query drop a silhouette).
    pub fn from_arrays(arrays: &GaussMapArrays, normals: &[[Vec3; 2]]) -> Result<Self, ArraysError> {
        Ok(Self::from_arrays_with_cells(arrays, normals)?.0)
    }

    /// [`GaussMapHierarchy::from_arrays`], also giving where each arc went (in storage order).
    pub(crate) fn from_arrays_with_cells(
        arrays: &GaussMapArrays,
        normals: &[[Vec3; 2]],
    ) -> Result<(Self, ArcCells), ArraysError> {
        let base = match arrays.base {
            0 => BaseSolid::Octahedron,
            1 => BaseSolid::Icosahedron,
            other => return Err(ArraysError::Value { array: "base", index: 0, value: f64::from(other) }),
        };
        let max_depth = u8::try_from(arrays.max_depth).ok().filter(|&d| d <= 12).ok_or(ArraysError::Value {
            array: "max_depth",
            index: 0,
            value: f64::from(arrays.max_depth),
        })?;
        let bins = match arrays.overlap {
            0.0 => Bins::Strict,
            f if (1.0..=8.0).contains(&f) => Bins::Overlapping { factor: f },
            f => return Err(ArraysError::Value { array: "overlap", index: 0, value: f64::from(f) }),
        };
        let count = arrays.nodes.len() / 4;
        if arrays.nodes.len() != count * 4 || count == 0 {
            return Err(ArraysError::Length { array: "nodes", expected: 4 * count.max(1), found: arrays.nodes.len() });
        }
        if arrays.node_caps.len() != 4 * count {
            return Err(ArraysError::Length { array: "node_caps", expected: 4 * count, found: arrays.node_caps.len() });
        }
        let flat: Vec<[u32; 4]> = arrays.nodes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let caps: Vec<[f32; 4]> = arrays.node_caps.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let parents = check_breadth_first(&flat, normals.len())?;
        let mut centers = Vec::with_capacity(count);
        for (i, cap) in caps.iter().enumerate() {
            if cap.iter().any(|x| !x.is_finite()) {
                return Err(ArraysError::Value { array: "node_caps", index: 4 * i, value: f64::NAN });
            }
            let c = Vec3::new(cap[0], cap[1], cap[2]).as_dvec3();
            if cap[3] < 1.0 && (c.length() - 1.0).abs() > 1e-6 {
                return Err(ArraysError::Value { array: "node_caps", index: 4 * i, value: c.length() });
            }
            centers.push(c.normalize_or_zero());
        }
        let (order, arcs, ranges, by_id) = derived_order(&flat, normals, base, bins, max_depth)?;
        // Every arc lies in the cap of the node that owns it and in each of that node's ancestors'.
        // Each node checks its own arcs (a range of the builder's preorder) against its chain of
        // caps: all nodes in parallel, every arc read once.
        ranges.par_iter().enumerate().try_for_each(|(node, &(lo, hi))| {
            let mut chain = Vec::new();
            let mut at = node as u32;
            while at != u32::MAX {
                if caps[at as usize][3] < 1.0 {
                    chain.push((at as usize, centers[at as usize], f64::from(caps[at as usize][3])));
                }
                at = parents[at as usize];
            }
            if chain.is_empty() {
                return Ok(());
            }
            for g in &arcs[lo..hi] {
                // For unit vectors the angle r is below π/2 iff c·p > 0, and then sin r = |c × p|
                // (no atan2 per point and ancestor). A zero normal (degenerate face) is inside
                // every cap, as the builder counts it.
                for p in [g.n1, g.n2].into_iter().filter(|p| *p != DVec3::ZERO) {
                    for &(owner, c, threshold) in &chain {
                        if c.dot(p) <= 0.0 || c.cross(p).length() + CULL_MARGIN * 0.5 > threshold {
                            return Err(ArraysError::NotConservative { node: owner, candidate: g.id });
                        }
                    }
                }
            }
            Ok(())
        })?;
        drop(arcs);
        let a = assemble(&flat, &caps, &order, normals, Purpose::Query);
        let cells = ArcCells::new(base, bins, &by_id, &order);
        let h = GaussMapHierarchy {
            base,
            bins,
            max_depth,
            nodes: a.nodes,
            widest: a.widest,
            blocks: a.blocks,
            identity: is_identity(&order),
            flat,
            caps,
            order,
            assigned: None,
            predicted_ns: 0.0,
        };
        Ok((h, cells))
    }
}

/// Every arc assigned to its cell by the bin rule: the builder's nodes in preorder and the arcs in
/// preorder storage order (each node's own arcs, then its children's subtrees; input order within
/// each). The one definition of where an arc goes, used by the build and by
/// [`GaussMapHierarchy::from_arrays`], so that both find the same cells bit for bit. With `guide`
/// (a stored breadth-first tree, already checked by [`check_breadth_first`]) the descent stops at
/// the stored leaves, whose arcs stay in input order; `None` where the arcs do not split as stored.
/// Without `guide`, every node's cap is computed, and with `stop` the descent ends where the
/// pruning would collapse the node whatever lies below (see [`StopRule`]).
fn assign(
    normals: &[[Vec3; 2]],
    base: BaseSolid,
    bins: Bins,
    max_depth: u8,
    guide: Option<&[[u32; 4]]>,
    stop: Option<StopRule>,
) -> Option<(Vec<BuildNode>, Vec<Arc>)> {
    let mut arcs = arc_records(normals);
    let base = base_cells(base);
    let builder = Builder { bins, max_depth, by_octant: BaseByOctant::new(&base), base, caps: guide.is_none(), stop };
    let mut nodes = Vec::new();
    let mut scratch = drafter_core::filled_in_parallel(arcs.len(), Arc::default());
    let guide = (0, guide.map(|g| (g, 0)));
    let ok = builder.node(None, 0, &mut arcs, &mut scratch, false, 0, &mut nodes, guide, 1.0);
    ok.then_some((nodes, arcs))
}

/// The storage order of a stored tree `flat` (breadth-first, pruned, checked by
/// [`check_breadth_first`]) over `normals`: the arcs are assigned again down the stored tree
/// ([`assign`]), and the breadth-first layout of the result must reproduce `flat` exactly. Also
/// returns the arcs in the builder's preorder, each stored node's range of them (its own arcs) and
/// each arc's cell by candidate ([`ArcCells::by_candidate`]).
type Derived = (Vec<u32>, Vec<Arc>, Vec<(usize, usize)>, Vec<(u32, u8, bool)>);

fn derived_order(
    flat: &[[u32; 4]],
    normals: &[[Vec3; 2]],
    base: BaseSolid,
    bins: Bins,
    max_depth: u8,
) -> Result<Derived, ArraysError> {
    let (nodes, arcs) =
        assign(normals, base, bins, max_depth, Some(flat), None).ok_or(ArraysError::Tree { node: 0 })?;
    let order: Vec<u32> = arcs.iter().map(|a| a.id).collect();
    let (derived, bfs_order, source) = breadth_first(
        0,
        |i| &nodes[i].children,
        |i| {
            let n = &nodes[i];
            &order[n.own.0 as usize..n.own.1 as usize]
        },
    );
    if let Some(node) = derived.iter().zip(flat).position(|(a, b)| a != b) {
        return Err(ArraysError::Tree { node });
    }
    if derived.len() != flat.len() {
        return Err(ArraysError::Tree { node: derived.len().min(flat.len()) });
    }
    let ranges = source.iter().map(|&i| (nodes[i].own.0 as usize, nodes[i].own.1 as usize)).collect();
    let by_id = ArcCells::by_candidate(&nodes, &arcs);
    Ok((bfs_order, arcs, ranges, by_id))
}

fn is_identity(order: &[u32]) -> bool {
    order.iter().enumerate().all(|(k, &i)| i as usize == k)
}

fn visit_probabilities(nodes: &[BuildNode], caps: &[[f32; 4]]) -> Vec<f64> {
    let mut prob = vec![1.0f64; nodes.len()];
    // Preorder: parents come before children.
    for i in 0..nodes.len() {
        let own = f64::from(caps[i][3]).min(1.0);
        prob[i] = prob[i].min(own);
        for &c in &nodes[i].children {
            prob[c as usize] = prob[i];
        }
    }
    prob
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chunked scatter puts every arc where the serial stable scatter does, with the same
    /// bucket starts, for 4 and 20 children and counts around the chunk size.
    #[test]
    fn parallel_scatter_is_the_serial_scatter() {
        let mut rng = crate::measure::ViewRng::new(9);
        for (len, children) in [(SCATTER_CHUNK * 3 + 17, 20usize), (SCATTER_CHUNK + 1, 4), (SCATTER_CHUNK - 1, 4)] {
            let arcs: Vec<Arc> = (0..len as u32).map(|id| Arc { id, ..Arc::default() }).collect();
            let targets: Vec<u8> = (0..len)
                .map(|_| {
                    let k = (rng.unit() * (children + 1) as f32) as usize;
                    if k >= children { STAY } else { k as u8 }
                })
                .collect();
            let bucket = |t: u8| if t == STAY { 0 } else { usize::from(t) + 1 };
            let mut expected_starts = vec![0usize; children + 2];
            for &t in &targets {
                expected_starts[bucket(t) + 1] += 1;
            }
            for k in 1..expected_starts.len() {
                expected_starts[k] += expected_starts[k - 1];
            }
            let mut expected: Vec<u32> = Vec::with_capacity(len);
            for b in 0..=children {
                expected.extend(arcs.iter().zip(&targets).filter(|(_, t)| bucket(**t) == b).map(|(a, _)| a.id));
            }
            let mut spare = vec![Arc { id: u32::MAX, ..Arc::default() }; len];
            let mut starts = vec![0usize; children + 2];
            drafter_core::scatter_in_parallel(&arcs, |i| bucket(targets[i]), SCATTER_CHUNK, &mut spare, &mut starts);
            assert_eq!(starts, expected_starts);
            assert!(spare.iter().map(|a| a.id).eq(expected.iter().copied()), "{len} arcs, {children} children");
        }
    }

    /// Disjoint increasing ranges sort on the pool, anything else one range after another; either
    /// way every range ends sorted and nothing outside the ranges moves.
    #[test]
    fn sort_ranges_sorts_each_range_only() {
        let mut rng = crate::measure::ViewRng::new(5);
        for case in 0..400 {
            let items: Vec<u32> = (0..200).map(|_| (rng.unit().abs() * 1000.0) as u32).collect();
            let mut cuts: Vec<usize> = (0..8).map(|_| (rng.unit().abs() * 200.0) as usize % 201).collect();
            cuts.sort_unstable();
            let mut ranges: Vec<std::ops::Range<usize>> = cuts.chunks_exact(2).map(|c| c[0]..c[1]).collect();
            if case % 3 == 1 {
                ranges.reverse();
            }
            if case % 3 == 2 {
                ranges.push(10..150);
            }
            let mut expected = items.clone();
            for r in &ranges {
                expected[r.clone()].sort_unstable();
            }
            let mut sorted = items.clone();
            sort_ranges(&mut sorted, &ranges);
            assert_eq!(sorted, expected, "case {case}: {ranges:?}");
        }
    }

    /// The nine-product scoring of four children picks the child `Cell::score` and the
    /// first-of-equals maximum pick, on points inside, on the edges and at the corners of cells
    /// down to level 8, and on points far outside.
    #[test]
    fn quad_scores_pick_the_cell_scores_pick() {
        let mut rng = crate::measure::ViewRng::new(11);
        let mut cell = base_cells(BaseSolid::Icosahedron)[3];
        for level in 0..9 {
            let children = cell.children();
            let bins: Vec<BinCell> = children.iter().map(|&cell| BinCell { cell, cos_bin: 0.0 }).collect();
            let quad = Quad::of(&bins);
            let [a, b, c] = cell.v;
            let mut points = vec![a, b, c, (a + b).normalize(), (b + c).normalize(), (c + a).normalize()];
            for _ in 0..3000 {
                let w = [rng.unit().abs(), rng.unit().abs(), rng.unit().abs()];
                // Inside, and pulled onto an edge by zeroing one weight.
                let k = points.len() % 4;
                let w = if k < 3 { std::array::from_fn(|i| if i == k { 0.0 } else { w[i] }) } else { w };
                points.push((a * f64::from(w[0]) + b * f64::from(w[1]) + c * f64::from(w[2])).normalize_or_zero());
                points.push(rng.direction().as_dvec3().normalize());
            }
            for p in points {
                if p == DVec3::ZERO {
                    continue;
                }
                let expected = most_inside_reference(&children, p);
                assert_eq!(quad.most_inside(p), expected, "level {level}, point {p}");
            }
            cell = children[level % 4];
        }
    }

    /// The cell-choice rule as first written: `f64::min` of the three plane dots, the first of
    /// equals over `cells`. The fast paths must give what this gives.
    fn most_inside_reference(cells: &[Cell], p: DVec3) -> usize {
        cells
            .iter()
            .enumerate()
            .map(|(k, c)| (k, c.planes[0].dot(p).min(c.planes[1].dot(p)).min(c.planes[2].dot(p))))
            .fold((usize::MAX, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc })
            .0
    }

    /// Points on and near the cells' corners, edges and the octants' planes, and random ones.
    fn awkward_points(cells: &[Cell], rng: &mut crate::measure::ViewRng, random: usize) -> Vec<DVec3> {
        let mut points = Vec::new();
        for c in cells {
            let [a, b, c] = c.v;
            points.extend([a, b, c, (a + b).normalize(), (b + c).normalize(), (c + a).normalize(), -a]);
        }
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            points.extend([axis, -axis, (axis + DVec3::new(-0.0, -0.0, -0.0)).normalize()]);
        }
        points.push(DVec3::new(-0.0, 0.6, -0.8));
        points.push(DVec3::new(0.6, -0.0, 0.8));
        for _ in 0..random {
            let p = rng.direction().as_dvec3().normalize();
            points.push(p);
            // The same point with one component zeroed: on an octant's plane.
            let k = points.len() % 3;
            let mut q = p;
            q[k] = if k == 1 { -0.0 } else { 0.0 };
            points.push(q.normalize_or_zero());
        }
        points.retain(|p| *p != DVec3::ZERO);
        points
    }

    #[test]
    fn base_by_octant_picks_what_all_cells_pick() {
        let mut rng = crate::measure::ViewRng::new(5);
        for solid in [BaseSolid::Icosahedron, BaseSolid::Octahedron] {
            let base = base_cells(solid);
            let index = BaseByOctant::new(&base);
            let listed: usize = index.cells.iter().map(Vec::len).sum();
            assert!(listed < 8 * base.len(), "{solid:?}: the octants list {listed} cells");
            for p in awkward_points(&base, &mut rng, 20_000) {
                assert_eq!(index.most_inside(&base, p), most_inside_reference(&base, p), "{solid:?}, point {p}");
            }
        }
    }

    #[test]
    fn quad_targets_are_the_bin_rule() {
        let mut rng = crate::measure::ViewRng::new(13);
        let mut cell = base_cells(BaseSolid::Icosahedron)[7];
        let mut checked = 0;
        for level in 0..10 {
            let children = cell.children();
            for factor in [1.0, 1.5, 2.0] {
                let bins: Vec<BinCell> =
                    children.iter().map(|&cell| BinCell { cell, cos_bin: bin_cos(&cell, factor) }).collect();
                let quad = Quad::of(&bins);
                let mut points = awkward_points(&children, &mut rng, 300);
                // Points inside the cell, where its arcs' midpoints lie.
                let [a, b, c] = cell.v;
                for _ in 0..600 {
                    let w = [rng.unit().abs(), rng.unit().abs(), rng.unit().abs()].map(f64::from);
                    points.push((a * w[0] + b * w[1] + c * w[2]).normalize_or_zero());
                }
                points.retain(|p| *p != DVec3::ZERO);
                let mut arcs = Vec::new();
                let arc = |n1: DVec3, n2: DVec3| Arc { n1, n2, id: 0, p: 0.0 };
                for (i, &p) in points.iter().enumerate() {
                    let q = points[(i * 7 + 3) % points.len()];
                    // A short arc around p, a long one, p alone, antipodal, and degenerate faces.
                    let near = (p + (q - p) * 0.01).normalize();
                    arcs.extend([
                        arc(p, near),
                        arc(p, q),
                        arc(p, p),
                        arc(p, -p),
                        arc(DVec3::ZERO, p),
                        arc(p, DVec3::ZERO),
                    ]);
                }
                arcs.push(arc(DVec3::ZERO, DVec3::ZERO));
                let mut fast = vec![0u8; arcs.len()];
                quad.targets(&bins, &arcs, &mut fast);
                for (g, &t) in arcs.iter().zip(&fast) {
                    let expected = arc_mid([g.n1, g.n2])
                        .map(|m| most_inside_reference(&children, m))
                        .filter(|&k| fits_bin(&children[k], bins[k].cos_bin, [g.n1, g.n2]))
                        .map_or(STAY, |k| k as u8);
                    assert_eq!(t, expected, "level {level}, factor {factor}, arc {} – {}", g.n1, g.n2);
                    assert_eq!(quad.target(&bins, g), expected, "scalar, level {level}, arc {} – {}", g.n1, g.n2);
                    checked += usize::from(expected != STAY);
                }
            }
            cell = children[(level + 1) % 4];
        }
        assert!(checked > 10_000, "only {checked} arcs went down");
    }

    #[test]
    fn arc_paths_equal_arc_path_arc_by_arc() {
        let mut rng = crate::measure::ViewRng::new(7);
        let base = base_cells(BaseSolid::Icosahedron);
        // Random arcs of every length (short ones go deep), plus zero and antipodal ones.
        let mut unit: Vec<[DVec3; 2]> = (0..20_000)
            .map(|k| {
                let a = rng.direction().as_dvec3().normalize();
                let spread = [1e-4, 1e-2, 0.1, 0.5, 2.0][k % 5];
                let b = (a + rng.direction().as_dvec3() * spread).normalize_or_zero();
                [a, b]
            })
            .collect();
        unit.push([DVec3::ZERO, DVec3::Z]);
        unit.push([DVec3::X, DVec3::NEG_X]);
        for level in [0u8, 3, 6] {
            let batch = arc_paths(&unit, &base, level, f64::from(DEFAULT_OVERLAP));
            let deep = batch.iter().filter(|p| p.1 > level).count();
            assert!(deep > 1000, "level {level}: only {deep} arcs reached the deepest level");
            for (i, &[a, b]) in unit.iter().enumerate() {
                assert_eq!(
                    batch[i],
                    arc_path(a, b, &base, level, f64::from(DEFAULT_OVERLAP)),
                    "arc {i}, level {level}"
                );
            }
        }
    }

    #[test]
    fn a_gauss_maps_arc_cells_give_the_bvh_paths() {
        let mut rng = crate::measure::ViewRng::new(3);
        let normals: Vec<[Vec3; 2]> = (0..30_000)
            .map(|k| {
                let a = rng.direction();
                let spread = [1e-4, 1e-2, 0.1, 0.5][k % 4];
                [a, (a + rng.direction() * spread).normalize_or_zero()]
            })
            .collect();
        let cost = CostModel::default();
        let factor = f64::from(DEFAULT_OVERLAP);
        let base = base_cells(BaseSolid::Icosahedron);
        // Shallow maps stop above the BVH's level (max_depth; collapsed subtrees, where a reader
        // stops), so the descent goes on from their cells.
        for max_depth in [1u8, 3, 8] {
            let options = GaussMapOptions { max_depth: Some(max_depth), ..Default::default() };
            let (built, cells) = GaussMapHierarchy::build_with_cells(&normals, &options, &cost, Purpose::Query);
            let (loaded, loaded_cells) =
                GaussMapHierarchy::from_arrays_with_cells(&built.to_arrays(), &normals).unwrap();
            assert_eq!(loaded.order, built.order);
            let assigned = built.assigned_histogram().unwrap();
            let assigned_nodes = assigned.root.nodes + assigned.levels.iter().map(|l| l.nodes).sum::<usize>();
            assert!(max_depth < 8 || built.node_count() < assigned_nodes, "some subtree is collapsed");
            let unit: Vec<[DVec3; 2]> =
                built.order.iter().map(|&i| normals[i as usize].map(|n| n.as_dvec3().normalize_or_zero())).collect();
            for level in [0u8, 2, 4, 6] {
                let expected = arc_paths(&unit, &base, level, factor);
                assert_eq!(
                    cells.paths(&unit, level, factor).unwrap(),
                    expected,
                    "built, depth {max_depth}, level {level}"
                );
                assert_eq!(loaded_cells.paths(&unit, level, factor).unwrap(), expected, "loaded, depth {max_depth}");
            }
        }
        // Another rule: no paths.
        let octahedron = GaussMapOptions { base: BaseSolid::Octahedron, ..Default::default() };
        let (built, cells) = GaussMapHierarchy::build_with_cells(&normals, &octahedron, &cost, Purpose::Query);
        let unit: Vec<[DVec3; 2]> =
            built.order.iter().map(|&i| normals[i as usize].map(|n| n.as_dvec3().normalize_or_zero())).collect();
        assert!(cells.paths(&unit, 3, factor).is_none());
    }

    /// The stop rule only skips subtrees the pruning collapses: the stored map (tree, caps, storage
    /// order, predicted cost) is the one built to `max_depth` and pruned, on arcs of every length,
    /// on CAD-like repeated normals and under skewed cost models, while most of the deep nodes are
    /// never made.
    #[test]
    fn early_stop_keeps_the_pruned_tree() {
        let mut rng = crate::measure::ViewRng::new(19);
        let mixed: Vec<[Vec3; 2]> = (0..40_000)
            .map(|k| {
                let a = rng.direction();
                let spread = [0.0, 1e-5, 1e-3, 1e-2, 0.1, 0.7][k % 6];
                [a, (a + rng.direction() * spread).normalize_or_zero()]
            })
            .collect();
        // A machined part: a few exact directions, arcs between neighbouring ones and fillets.
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::NEG_X, Vec3::NEG_Y, Vec3::NEG_Z];
        let cad: Vec<[Vec3; 2]> = (0..20_000)
            .map(|k| {
                let a = axes[k % 6];
                let b = if k % 3 == 0 { axes[(k / 6) % 6] } else { (a + rng.direction() * 0.05).normalize() };
                if a.dot(b) < -0.5 { [a, a] } else { [a, b] }
            })
            .collect();
        let skewed = CostModel { gauss_enter_ns: 20.0, gauss_block_ns: 0.5, ..CostModel::default() };
        let blocky = CostModel { gauss_test_ns: 0.2, gauss_block_ns: 8.0, ..CostModel::default() };
        let mut skipped = 0;
        for (name, normals) in [("mixed", &mixed), ("cad", &cad)] {
            for cost in [CostModel::default(), skewed, blocky] {
                let options = GaussMapOptions::default();
                // The stopping build as a bake makes it (no arc blocks), the reference with them.
                let (fast, _) = GaussMapHierarchy::build_stopping(normals, &options, &cost, true, Purpose::Storage);
                let (full, _) = GaussMapHierarchy::build_stopping(normals, &options, &cost, false, Purpose::Query);
                assert_eq!(fast.flat, full.flat, "{name}: tree");
                assert_eq!(fast.caps, full.caps, "{name}: caps");
                assert_eq!(fast.order, full.order, "{name}: storage order");
                assert_eq!(fast.predicted_ns, full.predicted_ns, "{name}: predicted cost");
                let made = |h: &GaussMapHierarchy| {
                    let a = h.assigned_histogram().unwrap();
                    a.root.nodes + a.levels.iter().map(|l| l.nodes).sum::<usize>()
                };
                assert!(made(&fast) <= made(&full));
                skipped += made(&full) - made(&fast);
            }
        }
        assert!(skipped > 10_000, "the rule skipped only {skipped} nodes");
    }

    /// The predicted cost walks without testing arcs: its counts must be a query's.
    #[test]
    fn counting_walk_counts_what_a_query_does() {
        let mut rng = crate::measure::ViewRng::new(8);
        let normals: Vec<[Vec3; 2]> = (0..30_000)
            .map(|_| {
                let a = rng.direction();
                [a, (a + rng.direction() * 0.3).normalize()]
            })
            .collect();
        let h = GaussMapHierarchy::build(&normals, &GaussMapOptions::default(), &CostModel::default());
        let mut out = EdgeSet::default();
        let mut blocks = 0;
        for _ in 0..500 {
            let d = rng.direction();
            let counted = h.counts_only(d);
            assert_eq!(counted, h.query_counted(d, &mut out), "direction {d}");
            blocks += counted.blocks_tested;
        }
        assert_eq!(h.counts_only(Vec3::ZERO), h.query_counted(Vec3::ZERO, &mut out), "no direction");
        assert!(blocks > 500, "the walks read {blocks} blocks");
    }

    #[test]
    fn widest_angle_is_the_exact_maximum() {
        let mut rng = crate::measure::ViewRng::new(11);
        for round in 0..200 {
            let c = rng.direction().as_dvec3().normalize();
            let spread = [1e-7, 1e-3, 0.3, 1.5][round % 4];
            let points: Vec<DVec3> = (0..500).map(|_| (c + rng.direction().as_dvec3() * spread).normalize()).collect();
            let exact = points.iter().map(|p| c.cross(*p).length().atan2(c.dot(*p))).fold(0.0f64, f64::max);
            assert_eq!(widest_angle(c, points.iter().copied()), exact, "round {round}");
            // The pass over arcs from two centres at once gives each centre's widest angle.
            let arcs: Vec<Arc> = points.chunks_exact(2).map(|p| Arc { n1: p[0], n2: p[1], ..Arc::default() }).collect();
            let other = (c + rng.direction().as_dvec3() * spread).normalize();
            let of_other = widest_angle(other, points.iter().copied());
            assert_eq!(widest_angles_of_arcs(&[c, other], &arcs), [exact, of_other], "round {round}");
            assert_eq!(widest_angles_of_arcs(&[other], &arcs), [of_other, 0.0], "round {round}");
            // Widest last (every point a new smallest dot product, so every group of 4 is
            // re-added one by one) and widest first, on lengths that leave remainders.
            let mut sorted = points.clone();
            sorted.sort_by(|a, b| c.dot(*b).total_cmp(&c.dot(*a)));
            for points in [sorted.clone(), sorted.into_iter().rev().collect()] {
                let take = 2 * (round % 9 + 1) + 2 * 4 * (round % 3);
                let arcs: Vec<Arc> = points
                    .chunks_exact(2)
                    .take(take / 2)
                    .map(|p| Arc { n1: p[0], n2: p[1], ..Arc::default() })
                    .collect();
                let ends = arcs.iter().flat_map(|a| [a.n1, a.n2]);
                let expected = [widest_angle(c, ends.clone()), widest_angle(other, ends)];
                assert_eq!(widest_angles_of_arcs(&[c, other], &arcs), expected, "round {round}, {take} points");
            }
        }
    }

    #[test]
    fn base_solids_tile_the_sphere() {
        for (base, faces) in [(BaseSolid::Octahedron, 8), (BaseSolid::Icosahedron, 20)] {
            let cells = base_cells(base);
            assert_eq!(cells.len(), faces);
            // Every direction lies in exactly one cell (up to boundaries).
            let mut s = 1u64;
            for _ in 0..2000 {
                let mut r = || {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
                };
                let p = DVec3::new(r(), r(), r()).normalize();
                let inside = cells.iter().filter(|c| c.score(p) > 1e-12).count();
                assert!(inside <= 1);
                assert!(cells.iter().any(|c| c.score(p) >= -1e-12));
                // The 4 children tile their parent.
                let c = cells.iter().find(|c| c.score(p) >= -1e-12).unwrap();
                assert!(c.children().iter().any(|k| k.score(p) >= -1e-9));
            }
        }
    }

    #[test]
    fn depth_grows_with_count() {
        assert_eq!(depth_for_count(0, BaseSolid::Icosahedron), 0);
        assert!(depth_for_count(150_000, BaseSolid::Icosahedron) >= 5);
        assert_eq!(depth_for_count(usize::MAX / 2, BaseSolid::Icosahedron), 10);
    }
}
