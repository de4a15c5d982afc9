//! A normal-cone BVH for perspective silhouettes.
//!
//! Gooch et al. (1999, §5.1.4) leave perspective open: "some form of bounding volume hierarchy would
//! have to be employed". This is a spatialised normal-cone hierarchy (Johnson & Cohen 2001,
//! "Spatialized normal cone hierarchies", I3D; anchored cones as in Sander et al. 2000,
//! "Silhouette clipping", SIGGRAPH), culled by a plane-offset test:
//!
//! * candidates are first split by normal, following the Gauss-map cells of the orthographic
//!   hierarchy (`gauss.rs`): an arc goes down the icosahedral cells containing its midpoint for as
//!   long as both its normals fit the cell's overlapping bin, at most [`NormalSplit`] levels (about
//!   5°–20° cells, chosen by count). Short arcs thus land in fine cells with narrow cones, long
//!   ones stay in coarse cells, instead of one long arc widening a fine cell's cone;
//! * within each normal cell a binary tree is built top-down in the *dual space of face planes*
//!   (Hertzmann & Zorin 2000, "Illustrating smooth surfaces", SIGGRAPH, search silhouettes in
//!   the same dual space, with an octree over the faces of the 4D hypercube): a plane is the 4D
//!   point `(k·n̂, n̂·(v − c))`, `c` the centre of the bounding box and `k` = [`DUAL_NORMAL_WEIGHT`] half-diagonals, and an eye is the
//!   hyperplane of the points on which `n̂·(e − v)` vanishes, so a group of candidates is cut
//!   by the view exactly when that hyperplane crosses the 4D points of their planes. Splits are
//!   chosen by a binned surface-area-style heuristic: the probability that a random hyperplane
//!   crosses a box is proportional to its mean width, the sum of its 4 extents, so a split
//!   minimises `Σ count · width` over the two sides (see [`dual_node`]). Any subtree of at most
//!   [`ConeBvhOptions::leaf_size`] candidates becomes a leaf. Written here because [`obvhs`]
//!   builds in 3D only; it is measured against obvhs' BVH2 (PLOC) over the points stretched
//!   8× along the cell's mean normal, what this crate used before: per perspective view on the
//!   dragon 213.7k instead of 228.9k candidates tested (54.0k instead of 57.8k blocks), on the
//!   bunny 25.6k instead of 29.6k, on fandisk 432 instead of 1,339 (coplanar CAD faces
//!   coincide in the dual space), each with the default pruning;
//! * [`NormalSplit::Off`] builds an [`obvhs`] BVH2 (PLOC) over the points `v` alone, the plain
//!   spatialised hierarchy of Johnson & Cohen, kept as the baseline;
//! * every node stores the tight box `B` of the points `v` below it and a cone (unit axis `c`,
//!   half-angle `α`) holding every face normal of those candidates (both `n1` and `n2`); at load
//!   and build the node also gets the range of its face planes' offsets (below);
//! * subtrees that the cost model finds cheaper as one leaf are collapsed, binary nodes absorb
//!   inner children up to 4 children, and the tree is laid out breadth-first (see `tree.rs`), so a
//!   query tests up to 4 children in one SIMD pass and reads each level's nodes with overlapping
//!   memory accesses.
//!
//! # The cull test, and why it is exact
//!
//! A candidate is a silhouette iff the eye `e` lies on different sides of its two face planes
//! (`n1·(e − v)` and `n2·(e − v)` of opposite signs). A node is skipped when the eye is strictly on
//! the same side of *every* face plane below it, which the bound proves as follows. With the
//! anchor `p₀` (the box centre) and `w = e − p₀`, each plane gives
//! `n̂·(e − v) = n̂·w − h` with the offset `h = n̂·(v − p₀)` (`n̂` the unit normal). The node
//! stores `h ∈ [h_lo, h_hi]` over all its planes, and every `n̂` lies in the cone, so with
//! `θ = ∠(c, w)`: `min n̂·w = |w| cos(min(θ + α, π))` and `max n̂·w = |w| cos(max(θ − α, 0))`,
//! evaluated as `t cos α ∓ s sin α` with `t = c·w`, `s = |c × w|` where the angle is in range and
//! `∓|w|` otherwise. All planes face the eye when `min − h_hi > τ`; all face away when
//! `max − h_lo < −τ`. The decoupling of `n̂` and `h` only loses tightness, never exactness.
//!
//! For nearly coplanar faces (what the stretched BVH groups) `h` spans almost nothing, and the
//! test is as tight as the orthographic one with the cone alone; the classic anchored-cone test
//! over the box corners (the cone must clear every direction from the eye to the box) also pays
//! for the box's angular size. Measured on the dragon (1.3M candidates, 200 eyes outside the box),
//! the corner test culled less than 0.1% beyond what the plane test culls, at 8 square roots per
//! node, so the query uses the plane test alone (`box_culls` stays as a tested reference).
//!
//! Rounding: the cone's `sin α` is rounded up with a margin of [`CONE_MARGIN`] = 1e-5, `cos α`,
//! `h_lo` rounded down and `h_hi`, the reach `max |v − p₀|` rounded up, all computed in `f64` from
//! the normalised normals; the tolerance is `τ = ` [`PLANE_MARGIN`]` · (|w| + reach)` = 1e-5 of the
//! distances involved. The `f32` bound errs by a few 1e-7 of `|w|` (the cross product keeps `s`
//! accurate where `|w|² − t²` would cancel), the predicate's own `f32` evaluation of `n·(e − v)`
//! by a few 1e-7 of `|e − v| ≤ |w| + reach`, and the stored normals' lengths differ from 1 by
//! about 1e-7 (which scales, not flips, the predicate): all far below `τ`, so a skipped candidate
//! has both `f32` values strictly of one sign and the predicate rejects it. NaN or infinite values
//! (eyes at infinity, overflow of `|w|²`) fail the comparisons and the node is entered; nodes
//! whose cone reaches 90° or that hold a zero normal are never culled. Entered leaves are tested
//! in blocks of 4, first by a 16-bit pretest with a proven error bound that decides a lane only
//! where the sign is certain, then, for blocks with an undecided lane, with the brute-force
//! arithmetic (`w = e − v`, same operations, same order; see `brute::FixedBlock`): results are
//! bit-identical to [`crate::BruteForce`].
//!
//! # How deep
//!
//! Queries from [`ConeBvhOptions::sample_eyes`] deterministic eyes outside the bounding box (1.2 to
//! 4 half-diagonals from its centre) measure how often each node is tested and passes; a
//! bottom-up pass with the [`CostModel`] collapses subtrees that are cheaper as one leaf. The
//! final tree is priced by counting the work of the same sampled queries.

use std::time::Duration;

/// How many leaves ahead of the one being tested a walk prefetches.
const PREFETCH_AHEAD: usize = 3;

use glam::{DVec3, Mat4, Vec3, Vec3A, Vec4};
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::brute::{Stream, keeps_pretest};
use crate::gauss::{ArcCells, BaseSolid, arc_paths, base_cells};
use crate::tree::QueryCounts;
use crate::tree::{Purpose, breadth_first, check_breadth_first, push_children, widest_level, with_levels, with_ranges};
use crate::{ArraysError, CostModel, EdgeSet};

/// Margin added to the sine of every cone's half-angle.
pub const CONE_MARGIN: f64 = 1e-5;

/// Default largest leaf, in candidates, before the cost-model pruning. The pruning keeps leaves of
/// about 120 candidates on average on the dragon, so a build that starts from 16 makes levels it
/// only collapses (dragon: 243,802 nodes built, 15,592 stored). Measured with
/// `silhouette_bench --leaf` (16 → 64): predicted query cost +0.1% on the dragon and the bunny,
/// +0.2% rocker-arm, +2.6% a 100k-face sphere, +6.8% fandisk (1.21 → 1.29 µs a view); measured
/// perspective query times equal within the noise; both hierarchies of the dragon built in
/// 1.38–1.43 s instead of 1.59–1.88 s.
pub const DEFAULT_LEAF_SIZE: u32 = 64;

/// Default number of eyes sampled to estimate visit frequencies.
pub const DEFAULT_SAMPLE_EYES: u32 = 96;

const NEVER_CULL: f32 = 2.0;

/// How candidates are split by normal before the spatial BVH.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", content = "level", rename_all = "snake_case")]
pub enum NormalSplit {
    /// Spatial BVH over all candidates.
    Off,
    /// First by the icosahedral Gauss-map cell (this many 4:1 splits) of the arc midpoint, then
    /// a spatial BVH per cell.
    Level(u8),
    /// [`NormalSplit::Level`] chosen by [`normal_level_for_count`] (default).
    Auto,
}

/// The Gauss-map level used by [`NormalSplit::Auto`]: cells of about 20° (level 1) for small
/// meshes, 10° (level 2) from 20k candidates, 5° (level 3) from 300k.
pub fn normal_level_for_count(candidates: usize) -> u8 {
    match candidates {
        0..20_000 => 1,
        20_000..300_000 => 2,
        _ => 3,
    }
}

/// Options of [`ConeBvh::build`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConeBvhOptions {
    /// Subtrees with at most this many candidates become one leaf before pruning.
    /// Default [`DEFAULT_LEAF_SIZE`]; range 1..=4096.
    pub leaf_size: u32,
    /// Split by normal first. Default [`NormalSplit::Auto`].
    pub normal_split: NormalSplit,
    /// Collapse subtrees that the cost model says are cheaper as one leaf. Default `true`.
    pub prune: bool,
    /// Eyes outside the bounding box used to estimate visit frequencies and the cost of a query.
    /// 0 disables pruning and the estimate (a [`crate::SilhouetteIndex`] then keeps the BVH only
    /// with `min_speedup` 0). Default [`DEFAULT_SAMPLE_EYES`].
    pub sample_eyes: u32,
}

impl Default for ConeBvhOptions {
    fn default() -> Self {
        Self {
            leaf_size: DEFAULT_LEAF_SIZE,
            normal_split: NormalSplit::Auto,
            prune: true,
            sample_eyes: DEFAULT_SAMPLE_EYES,
        }
    }
}

/// The flat arrays of a [`ConeBvh`], ready for glTF buffer views.
///
/// The storage order of the candidates is not stored: [`ConeBvh::from_arrays`] builds the binary
/// tree again, replaying the recorded split of every inner node (`splits`) with the builder's
/// arithmetic instead of searching for it, which gives the builder's candidate order; `nodes`
/// then refer to ranges of that order.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ConeBvhArrays {
    /// 6 `f32` per node: box min x, y, z, max x, y, z of the candidate points below.
    pub node_boxes: Vec<f32>,
    /// 4 `f32` per node: cone axis x, y, z and `sin α + margin` (≥ 1: never culled).
    pub node_cones: Vec<f32>,
    /// 4 `u32` per node, nodes breadth-first from the root: first child, child count, and the
    /// range of the node's candidates (its whole subtree) in the binary tree's preorder candidate
    /// order; the children's ranges tile their parent's in order.
    pub nodes: Vec<u32>,
    /// The Gauss-map level of the normal split (see [`NormalSplit::Level`]).
    pub normal_level: u32,
    /// The leaf size the binary tree was cut at ([`ConeBvhOptions::leaf_size`]).
    pub leaf_size: u32,
    /// One byte per inner node of each dual-space tree, in preorder: `axis · 32 + bin`, the split
    /// between bins `bin − 1` and `bin` of `DUAL_BINS` (32) on that axis, or `MEDIAN_SPLIT`.
    pub splits: Vec<u8>,
    /// Where each dual-space tree's bytes start in `splits`, one per tree in the order the normal
    /// split emits them.
    pub split_starts: Vec<u32>,
}

/// The split byte of an inner node split at the median of its widest axis of centres.
pub const MEDIAN_SPLIT: u8 = u8::MAX;

/// See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct ConeBvh {
    /// What a query reads about nodes, bounds included, padded with 4 entries so that up to 4
    /// children are tested in one SIMD pass.
    nodes: Vec<BvhNode>,
    /// The most nodes at one depth (sizes the walk's level buffers).
    widest: usize,
    /// The leaves' candidates in blocks, leaf after leaf.
    stream: Stream,
    /// The query layout: `[first_child, child_count, arc_start, arc_end]` per node, own
    /// candidates in `order`.
    flat: Vec<[u32; 4]>,
    /// The stored layout: first child, child count and the subtree's range of the preorder
    /// candidate order (see [`ConeBvhArrays::nodes`]).
    stored: Vec<[u32; 4]>,
    boxes: Vec<[f32; 6]>,
    cones: Vec<[f32; 4]>,
    order: Vec<u32>,
    leaf_size: u32,
    normal_level: Option<u8>,
    splits: Vec<u8>,
    split_starts: Vec<u32>,
    predicted_ns: f64,
}

/// A node as the query reads it: its plane-offset bound and its record in one cache line (the
/// bound as 14 separate arrays touched 14 or more lines per 4 children).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct BvhNode {
    /// Anchor `p₀` x, y, z and `sin α + margin`.
    anchor_sin: Vec4,
    /// Cone axis x, y, z and `cos α`.
    axis_cos: Vec4,
    /// `h_lo`, `h_hi`, reach (see [`PlaneBound`]), and the reach of the own candidates' points
    /// from the anchor for the stream's 16-bit pretest (see [`Stream::perspective_leaf`]).
    offsets: Vec4,
    first_child: u32,
    child_count: u32,
    /// First quad of the own candidates' blocks in the stream, and their number.
    quad: u32,
    blocks: u32,
}

/// What a query reads, built from the serialised form.
struct Assembled {
    nodes: Vec<BvhNode>,
    widest: usize,
    stream: Stream,
}

/// Query records, bound arrays and blocks of a breadth-first tree; the blocks only with the
/// candidates' normals and points (a [`Purpose::Query`] build).
fn assemble(
    flat: &[[u32; 4]],
    boxes: &[[f32; 6]],
    cones: &[[f32; 4]],
    planes: &[PlaneBound],
    order: &[u32],
    candidates: Option<(&[[Vec3; 2]], &[Vec3])>,
) -> Assembled {
    let ranges: Vec<(usize, usize)> = flat.iter().map(|&[_, _, start, end]| (start as usize, end as usize)).collect();
    let (stream, at, reaches) = match candidates {
        Some((normals, points)) => {
            let anchors: Vec<Vec3> = boxes.iter().map(anchor).collect();
            Stream::from_ranges(&ranges, &anchors, order, (normals, points), keeps_pretest(order.len()))
        }
        None => (Stream::new(), Stream::layout(&ranges), vec![0.0; ranges.len()]),
    };
    let mut nodes: Vec<BvhNode> = flat
        .iter()
        .enumerate()
        .map(|(i, &[first_child, child_count, _, _])| {
            let (quad, blocks) = at[i];
            let (p0, c, [cos, lo, hi, reach]) = (anchor(&boxes[i]), cones[i], planes[i].0);
            BvhNode {
                anchor_sin: p0.extend(c[3]),
                axis_cos: Vec4::new(c[0], c[1], c[2], cos),
                offsets: Vec4::new(lo, hi, reach, reaches[i]),
                first_child,
                child_count,
                quad,
                blocks,
            }
        })
        .collect();
    // Padding lanes are masked off by the child count; these never cull anyway.
    let pad = BvhNode {
        anchor_sin: Vec4::ZERO,
        axis_cos: Vec4::ZERO,
        offsets: Vec4::new(f32::NEG_INFINITY, f32::INFINITY, 0.0, 0.0),
        first_child: 0,
        child_count: 0,
        quad: 0,
        blocks: 0,
    };
    nodes.extend(std::iter::repeat_n(pad, 4));
    Assembled { nodes, widest: widest_level(flat), stream }
}

/// The exact anchored-cone test over the box corners (see the module docs: kept as a reference,
/// the query uses [`plane_culls`]).
#[cfg(test)]
fn box_culls(b: &[f32; 6], c: &[f32; 4], e: Vec3) -> bool {
    let s = c[3];
    let wx = [e.x - b[0], e.x - b[3]];
    let wy = [e.y - b[1], e.y - b[4]];
    let wz = [e.z - b[2], e.z - b[5]];
    let mut front = true;
    let mut back = true;
    for k in 0..8 {
        let (x, y, z) = (wx[k & 1], wy[(k >> 1) & 1], wz[k >> 2]);
        let t = c[0] * x + c[1] * y + c[2] * z;
        let r = s * (x * x + y * y + z * z).sqrt();
        front &= t > r;
        back &= t < -r;
    }
    front | back
}

/// Relative margin of the plane-offset test (see the module docs).
pub const PLANE_MARGIN: f32 = 1e-5;

/// Weight of the normal against the plane offset in the dual space of `dual_node`, in
/// half-diagonals of the bounding box. Over a box of dual points, `n̂·(e − v)` for an eye at
/// distance `D` from the centre in direction `u` varies by `D·Σ|u_i|·Δn_i + Δh`, and `|u_i|`
/// averages ½: so the normal's extents count about `D/2`, and the sampled eyes lie 1.2 to 4
/// half-diagonals away (0.6, 1.25 and 2.5 measured alike on the dragon: 213.9k, 213.7k and
/// 217.4k candidates tested per view).
pub const DUAL_NORMAL_WEIGHT: f32 = 1.25;

/// Bins per axis of the dual-space split search.
const DUAL_BINS: usize = 32;

/// Below this depth the dual-space build takes the heuristic's split; deeper (only for
/// adversarial distributions that peel off a few candidates per split) it splits at the median,
/// which bounds the recursion.
const DUAL_SAH_DEPTH: u32 = 48;

/// A candidate's two normals in `f64`, normalised (zero for a degenerate face): what every bound
/// of the build is computed from.
fn unit_pair([a, b]: [Vec3; 2]) -> [DVec3; 2] {
    [a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero()]
}

/// The plane-offset bound of a node: `[cos α, h_lo, h_hi, reach]`, where every face plane below
/// the node (normal `n̂` normalised, through the candidate's point `v`) has the offset
/// `h = n̂·(v − p₀)` in `[h_lo, h_hi]` from the anchor `p₀` (the centre of the node's box) and
/// `reach ≥ |v − p₀|`. A node that cannot use it stores `[0, −∞, +∞, 0]`: the test never culls.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlaneBound([f32; 4]);

impl PlaneBound {
    const NEVER: PlaneBound = PlaneBound([0.0, f32::NEG_INFINITY, f32::INFINITY, 0.0]);

    /// The bound of the candidates with unit normals `unit` (see [`unit_pair`]) and `points`
    /// (box `b`, cone `c` as stored).
    #[cfg(test)]
    fn of(unit: &[[DVec3; 2]], points: &[Vec3], b: &[f32; 6], c: &[f32; 4]) -> Self {
        let mut acc = PlaneAcc::new(b);
        for (&u, &p) in unit.iter().zip(points) {
            acc.add(u, p);
        }
        acc.finish(c)
    }
}

/// Offsets and reach of face planes from a node's anchor, accumulated in `f64`.
#[derive(Clone, Copy, Debug)]
struct PlaneAcc {
    p0: DVec3,
    lo: f64,
    hi: f64,
    /// The largest `|v − p₀|²`: its square root is the largest `|v − p₀|` (a correctly rounded
    /// square root is monotonic), taken once per node instead of once per candidate.
    reach_squared: f64,
    count: usize,
}

impl PlaneAcc {
    fn new(b: &[f32; 6]) -> Self {
        Self { p0: anchor(b).as_dvec3(), lo: f64::INFINITY, hi: f64::NEG_INFINITY, reach_squared: 0.0, count: 0 }
    }

    /// Adds a candidate with unit normals `unit` (see [`unit_pair`]) and point `point`.
    fn add(&mut self, unit: [DVec3; 2], point: Vec3) {
        let d = point.as_dvec3() - self.p0;
        self.reach_squared = self.reach_squared.max(d.dot(d));
        for n in unit {
            let h = n.dot(d);
            self.lo = self.lo.min(h);
            self.hi = self.hi.max(h);
        }
        self.count += 1;
    }

    /// The bound for a node whose stored cone is `c`.
    fn finish(&self, c: &[f32; 4]) -> PlaneBound {
        let reach = self.reach_squared.sqrt();
        if c[3] >= 1.0 || self.count == 0 || !(self.lo.is_finite() && self.hi.is_finite() && reach.is_finite()) {
            return PlaneBound::NEVER;
        }
        // cos α from the stored sine (which includes the cone margin): rounded down.
        let sin = f64::from(c[3]);
        let cos = (1.0 - sin * sin).max(0.0).sqrt();
        // `+ 0.0` turns a zero offset of -0.0 into +0.0: which zero a minimum or maximum keeps
        // depends on the order it met them in (the four-lane pass meets them in another), and no
        // comparison of the bound tells them apart.
        PlaneBound([round_down(cos), round_down(self.lo + 0.0), round_up(self.hi + 0.0), round_up(reach)])
    }
}

/// The anchor `p₀` of a node: its box centre, computed the same way at build, load and query.
#[inline(always)]
fn anchor(b: &[f32; 6]) -> Vec3 {
    Vec3::new((b[0] + b[3]) * 0.5, (b[1] + b[4]) * 0.5, (b[2] + b[5]) * 0.5)
}

fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

/// The plane-offset test of the module docs, on one node.
fn plane_culls(b: &[f32; 6], c: &[f32; 4], p: &PlaneBound, e: Vec3) -> bool {
    let w = e - anchor(b);
    let axis = Vec3::new(c[0], c[1], c[2]);
    let [cos, lo, hi, reach] = p.0;
    let sin = c[3];
    let t = axis.dot(w);
    let s = axis.cross(w).length();
    let len = w.length();
    let min = if t >= -len * cos { t * cos - s * sin } else { -len };
    let max = if t <= len * cos { t * cos + s * sin } else { len };
    let tol = PLANE_MARGIN * (len + reach);
    min - hi > tol || max - lo < -tol
}

/// The tree as built, in preorder with skip pointers and subtree ranges into `order` (used to
/// estimate visit frequencies and choose collapses before the breadth-first layout).
#[derive(Default)]
struct Tree {
    /// start, end, skip, leaf flag.
    nodes: Vec<[u32; 4]>,
    children: Vec<Vec<u32>>,
    order: Vec<u32>,
    /// The split byte of every inner node of the dual-space trees, in preorder.
    splits: Vec<u8>,
}

impl Tree {
    fn open(&mut self) -> usize {
        let at = self.nodes.len();
        let start = self.order.len() as u32;
        self.nodes.push([start, start, 0, 0]);
        self.children.push(Vec::new());
        at
    }

    fn close(&mut self, at: usize, leaf: bool) {
        self.nodes[at][1] = self.order.len() as u32;
        self.nodes[at][2] = self.nodes.len() as u32;
        self.nodes[at][3] = u32::from(leaf);
    }

    /// Appends `sub` (built on its own) as the next child of node `at`: its node indices, skip
    /// pointers and ranges are shifted past this tree's.
    fn append_child(&mut self, at: usize, sub: Tree) {
        let node_offset = self.nodes.len() as u32;
        self.children[at].push(node_offset);
        self.extend(sub);
    }

    /// Appends `sub` (built on its own) at the end of this tree, as [`Tree::open`] would start it.
    fn extend(&mut self, sub: Tree) {
        let (node_offset, arc_offset) = (self.nodes.len() as u32, self.order.len() as u32);
        self.splits.extend(sub.splits);
        self.nodes.extend(
            sub.nodes
                .into_iter()
                .map(|[start, end, skip, leaf]| [start + arc_offset, end + arc_offset, skip + node_offset, leaf]),
        );
        self.children
            .extend(sub.children.into_iter().map(|c| c.into_iter().map(|k| k + node_offset).collect::<Vec<u32>>()));
        self.order.extend(sub.order);
    }
}

/// Subtrees over more candidates than this are built on the thread pool and appended to their
/// parent; smaller ones in the calling thread. The tree is the same either way.
const PARALLEL_CANDIDATES: usize = 32 * 1024;

impl ConeBvh {
    /// Builds the hierarchy over candidates with `normals` and points `points` (one each).
    pub fn build(normals: &[[Vec3; 2]], points: &[Vec3], options: &ConeBvhOptions, cost: &CostModel) -> Self {
        Self::build_with_cells(normals, points, options, cost, None, Purpose::Query)
    }

    /// [`ConeBvh::build`] over candidates in a Gauss map's storage order, whose arc cells the
    /// normal split reads (`cells`) instead of assigning the arcs again. A [`Purpose::Storage`]
    /// build has no candidate stream and cannot answer queries; only its arrays and predicted
    /// cost are used.
    pub(crate) fn build_with_cells(
        normals: &[[Vec3; 2]],
        points: &[Vec3],
        options: &ConeBvhOptions,
        cost: &CostModel,
        cells: Option<&ArcCells>,
        purpose: Purpose,
    ) -> Self {
        let n = normals.len().min(points.len());
        let (normals, points) = (&normals[..n], &points[..n]);
        let leaf_size = options.leaf_size.clamp(1, 4096);
        let unit: Vec<[DVec3; 2]> = normals.par_iter().map(|&n| unit_pair(n)).collect();
        let normal_level = match options.normal_split {
            NormalSplit::Off => None,
            NormalSplit::Level(l) => Some(l.min(6)),
            NormalSplit::Auto => Some(normal_level_for_count(n)),
        };
        let (tree, split_starts) = match build_tree(points, &unit, leaf_size, normal_level, None, cells) {
            Ok(built) => built,
            Err(_) => unreachable!("a build without a replay script does not fail"),
        };
        // The candidates in tree order, so that every node's bounds read one contiguous range
        // (gathering through `order` per node and level missed the cache on every candidate).
        let (tree_points, tree_unit) =
            (drafter_core::gather(points, &tree.order), drafter_core::gather(&unit, &tree.order));
        drop(unit);
        let range = |start: u32, end: u32| start as usize..end as usize;
        // Boxes bottom-up: a leaf's from its points, an inner node's the union of its children's
        // (whose ranges tile its own), the same box as from its points at a fraction of the work.
        let mut boxes: Vec<[f32; 6]> = tree
            .nodes
            .par_iter()
            .map(
                |&[start, end, _, leaf]| {
                    if leaf == 1 { bounding_box(tree_points[range(start, end)].iter().copied()) } else { EMPTY_AABB }
                },
            )
            .collect();
        for i in (0..tree.nodes.len()).rev() {
            for &c in &tree.children[i] {
                let b = boxes[c as usize];
                let a = &mut boxes[i];
                for k in 0..3 {
                    a[k] = a[k].min(b[k]);
                    a[k + 3] = a[k + 3].max(b[k + 3]);
                }
            }
        }
        let (cones, planes): (Vec<[f32; 4]>, Vec<PlaneBound>) = tree
            .nodes
            .par_iter()
            .enumerate()
            .map(|(i, &[start, end, _, _])| {
                let r = range(start, end);
                cone_and_planes(&tree_unit[r.clone()], &tree_points[r], &boxes[i])
            })
            .unzip();
        drop((tree_points, tree_unit));
        let eyes = sample_eyes(points, options.sample_eyes);
        let mut leaf: Vec<bool> = tree.nodes.iter().map(|n| n[3] == 1).collect();
        if !eyes.is_empty() && options.prune {
            let (visits, passes) = visit_frequencies(&tree.nodes, &boxes, &cones, &planes, &eyes);
            for (i, c) in collapse_by_cost(&tree.nodes, &tree.children, &visits, &passes, cost).into_iter().enumerate()
            {
                leaf[i] |= c;
            }
        }
        // Up to 4 children per node: absorb the largest inner children into their parent.
        let size = |i: usize| tree.nodes[i][1] - tree.nodes[i][0];
        let wide: Vec<Vec<u32>> = (0..tree.nodes.len())
            .map(|i| {
                if leaf[i] {
                    return Vec::new();
                }
                let mut kids = tree.children[i].clone();
                while kids.len() < 4 {
                    let Some((k, _)) = kids
                        .iter()
                        .enumerate()
                        .filter(|&(_, &c)| !leaf[c as usize] && kids.len() - 1 + tree.children[c as usize].len() <= 4)
                        .max_by_key(|&(_, &c)| size(c as usize))
                    else {
                        break;
                    };
                    let c = kids.remove(k) as usize;
                    kids.splice(k..k, tree.children[c].iter().copied());
                }
                kids
            })
            .collect();
        let (flat, order, source) = breadth_first(
            0,
            |i| &wide[i],
            |i| if leaf[i] { &tree.order[tree.nodes[i][0] as usize..tree.nodes[i][1] as usize] } else { &[] },
        );
        let boxes: Vec<[f32; 6]> = source.iter().map(|&i| boxes[i]).collect();
        let cones: Vec<[f32; 4]> = source.iter().map(|&i| cones[i]).collect();
        let planes: Vec<PlaneBound> = source.iter().map(|&i| planes[i]).collect();
        let stored: Vec<[u32; 4]> = flat
            .iter()
            .zip(&source)
            .map(|(&[first, count, _, _], &i)| [first, count, tree.nodes[i][0], tree.nodes[i][1]])
            .collect();
        let candidates = (purpose == Purpose::Query).then_some((normals, points));
        let a = assemble(&flat, &boxes, &cones, &planes, &order, candidates);
        let mut bvh = ConeBvh {
            nodes: a.nodes,
            widest: a.widest,
            stream: a.stream,
            flat,
            stored,
            boxes,
            cones,
            order,
            leaf_size,
            normal_level,
            splits: tree.splits,
            split_starts,
            predicted_ns: 0.0,
        };
        if !eyes.is_empty() {
            // On the thread pool, summed in eye order: the same figure at any thread count.
            let costs: Vec<f64> = eyes
                .par_iter()
                .map(|&e| bvh.walk::<true, false>(e, &mut EdgeSet::default()).cost_ns(cost, false))
                .collect();
            bvh.predicted_ns = costs.iter().sum::<f64>() / eyes.len() as f64;
        }
        bvh
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

    pub fn leaf_count(&self) -> usize {
        self.flat.iter().filter(|n| n[1] == 0).count()
    }

    /// The leaf size the tree was cut at before pruning.
    pub fn leaf_size(&self) -> u32 {
        self.leaf_size
    }

    /// The Gauss-map level of the normal split, `None` if the BVH is purely spatial (or loaded).
    pub fn normal_level(&self) -> Option<u8> {
        self.normal_level
    }

    /// Expected time of one query from eyes outside the box, under the cost model used to build it
    /// (0 when loaded from arrays or built without sample eyes).
    pub fn predicted_ns_per_query(&self) -> f64 {
        self.predicted_ns
    }

    /// Silhouettes seen from `eye` into `out` (reset to [`ConeBvh::len`]).
    pub fn query(&self, eye: Vec3, out: &mut EdgeSet) {
        self.walk::<false, true>(eye, out);
    }

    /// [`ConeBvh::query`] that also counts its work.
    pub fn query_counted(&self, eye: Vec3, out: &mut EdgeSet) -> QueryCounts {
        self.walk::<true, true>(eye, out)
    }

    /// Bits of the nodes `first..first + 4` that the plane-offset test culls: [`plane_culls`] on 4
    /// lanes.
    #[inline(always)]
    fn culls4(&self, first: usize, e: Vec3) -> u32 {
        let Some(four) = self.nodes.get(first..first + 4) else { return 0 };
        // Transposes: rows are one field of the 4 nodes.
        let rows =
            |f: fn(&BvhNode) -> Vec4| Mat4::from_cols(f(&four[0]), f(&four[1]), f(&four[2]), f(&four[3])).transpose();
        let (a, b, o) = (rows(|n| n.anchor_sin), rows(|n| n.axis_cos), rows(|n| n.offsets));
        let (ex, ey, ez) = (Vec4::splat(e.x), Vec4::splat(e.y), Vec4::splat(e.z));
        let (x, y, z, sin) = (ex - a.x_axis, ey - a.y_axis, ez - a.z_axis, a.w_axis);
        let (cx, cy, cz, cos) = (b.x_axis, b.y_axis, b.z_axis, b.w_axis);
        let t = cx * x + cy * y + cz * z;
        let (qx, qy, qz) = (cy * z - cz * y, cz * x - cx * z, cx * y - cy * x);
        let s = (qx * qx + qy * qy + qz * qz).sqrt();
        let len = (x * x + y * y + z * z).sqrt();
        let (lo, hi, reach) = (o.x_axis, o.y_axis, o.z_axis);
        let min = Vec4::select(t.cmpge(-len * cos), t * cos - s * sin, -len);
        let max = Vec4::select(t.cmple(len * cos), t * cos + s * sin, len);
        let tol = Vec4::splat(PLANE_MARGIN) * (len + reach);
        (min - hi).cmpgt(tol).bitmask() | (max - lo).cmplt(-tol).bitmask()
    }

    /// Breadth-first walk, as in the Gauss map. Without `TEST` no candidate is tested and `out`
    /// is left alone: which nodes a walk enters and which blocks it reads depend on the bounds
    /// alone, so the counts are those of the query.
    #[inline]
    fn walk<const COUNT: bool, const TEST: bool>(&self, eye: Vec3, out: &mut EdgeSet) -> QueryCounts {
        if TEST {
            out.reset(self.len());
        }
        let mut counts = QueryCounts::default();
        if self.flat.is_empty() || self.culls4(0, eye) & 1 == 1 {
            counts.bounds_tested = usize::from(COUNT);
            return counts;
        }
        let words = out.words_mut();
        with_ranges(|pending| {
            with_levels(self.widest + 4, |level, next| {
                level[0] = 0;
                let mut width = 1;
                counts.bounds_tested = usize::from(COUNT);
                while width > 0 {
                    let mut next_width = 0;
                    for &i in &level[..width] {
                        let n = &self.nodes[i as usize];
                        let (first, end) = (n.first_child as usize, (n.first_child + n.child_count) as usize);
                        push_children(next, &mut next_width, first, end, |f| !self.culls4(f, eye));
                        if COUNT {
                            counts.nodes_entered += 1;
                            counts.bounds_tested += end - first;
                        }
                    }
                    for (j, &i) in level[..width].iter().enumerate() {
                        // Start loading a later leaf while this one is tested (see `brute::prefetch`).
                        if TEST && let Some(&ahead) = level[..width].get(j + PREFETCH_AHEAD) {
                            let a = &self.nodes[ahead as usize];
                            self.stream.prefetch(a.quad as usize, a.blocks);
                        }
                        let n = &self.nodes[i as usize];
                        if n.blocks > 0 {
                            if TEST {
                                let frame = (n.anchor_sin.truncate(), n.offsets.w);
                                self.stream.perspective_leaf(n.quad as usize, n.blocks, frame, eye, words, pending);
                            }
                            if COUNT {
                                let [_, _, start, end] = self.flat[i as usize];
                                counts.ranges += 1;
                                counts.blocks_tested += n.blocks as usize;
                                counts.arcs_tested += (end - start) as usize;
                            }
                        }
                    }
                    std::mem::swap(level, next);
                    width = next_width;
                }
            });
            if TEST {
                self.stream.perspective_pending(pending, eye, words);
            }
        });
        counts
    }

    /// The flat arrays (see [`ConeBvhArrays`]); `None` for a tree without a normal split
    /// ([`NormalSplit::Off`]), whose obvhs build cannot be replayed from split bytes.
    pub fn to_arrays(&self) -> Option<ConeBvhArrays> {
        Some(ConeBvhArrays {
            node_boxes: self.boxes.iter().flatten().copied().collect(),
            node_cones: self.cones.iter().flatten().copied().collect(),
            nodes: self.stored.iter().flatten().copied().collect(),
            normal_level: u32::from(self.normal_level?),
            leaf_size: self.leaf_size,
            splits: self.splits.clone(),
            split_starts: self.split_starts.clone(),
        })
    }

    /// Rebuilds a hierarchy from its arrays and the candidates: the binary tree is built again by
    /// replaying its recorded splits (which gives the builder's candidate order), the stored
    /// nodes must tile that order, and every box and cone must really bound the candidates below
    /// it, so a corrupted file cannot make a query drop a silhouette.
    pub fn from_arrays(arrays: &ConeBvhArrays, normals: &[[Vec3; 2]], points: &[Vec3]) -> Result<Self, ArraysError> {
        Self::from_arrays_with_cells(arrays, normals, points, None)
    }

    /// [`ConeBvh::from_arrays`] over candidates in a Gauss map's storage order, whose arc cells
    /// the normal split reads (`cells`) instead of assigning the arcs again.
    pub(crate) fn from_arrays_with_cells(
        arrays: &ConeBvhArrays,
        normals: &[[Vec3; 2]],
        points: &[Vec3],
        cells: Option<&ArcCells>,
    ) -> Result<Self, ArraysError> {
        if points.len() != normals.len() {
            return Err(ArraysError::Length { array: "points", expected: normals.len(), found: points.len() });
        }
        let normal_level = u8::try_from(arrays.normal_level).ok().filter(|&l| l <= 6).ok_or(ArraysError::Value {
            array: "normal_level",
            index: 0,
            value: f64::from(arrays.normal_level),
        })?;
        if !(1..=4096).contains(&arrays.leaf_size) {
            return Err(ArraysError::Value { array: "leaf_size", index: 0, value: f64::from(arrays.leaf_size) });
        }
        let count = arrays.nodes.len() / 4;
        if count == 0 || arrays.nodes.len() != 4 * count {
            return Err(ArraysError::Length { array: "nodes", expected: 4 * count.max(1), found: arrays.nodes.len() });
        }
        if arrays.node_boxes.len() != 6 * count {
            return Err(ArraysError::Length {
                array: "node_boxes",
                expected: 6 * count,
                found: arrays.node_boxes.len(),
            });
        }
        if arrays.node_cones.len() != 4 * count {
            return Err(ArraysError::Length {
                array: "node_cones",
                expected: 4 * count,
                found: arrays.node_cones.len(),
            });
        }
        let stored: Vec<[u32; 4]> = arrays.nodes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let boxes: Vec<[f32; 6]> =
            arrays.node_boxes.chunks_exact(6).map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]]).collect();
        let cones: Vec<[f32; 4]> = arrays.node_cones.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let unit: Vec<[DVec3; 2]> = normals.par_iter().map(|&n| unit_pair(n)).collect();
        let (tree, _) = build_tree(
            points,
            &unit,
            arrays.leaf_size,
            Some(normal_level),
            Some((&arrays.splits, &arrays.split_starts)),
            cells,
        )?;
        drop(unit);
        let (flat, order) = query_layout(&stored, &tree.order)?;
        check_breadth_first(&flat, normals.len())?;
        let mut axes = Vec::with_capacity(count);
        for (i, c) in cones.iter().enumerate() {
            if c.iter().any(|x| !x.is_finite()) {
                return Err(ArraysError::Value { array: "node_cones", index: 4 * i, value: f64::NAN });
            }
            let axis = Vec3::new(c[0], c[1], c[2]).as_dvec3();
            if c[3] < 1.0 && (axis.length() - 1.0).abs() > 1e-6 {
                return Err(ArraysError::Value { array: "node_cones", index: 4 * i, value: axis.length() });
            }
            axes.push(axis.normalize_or_zero());
        }
        // Every stored node's candidates are a range of the replayed preorder: each node checks its
        // range against its box and cone and gathers its plane offsets (not stored: they follow
        // from the boxes and the candidates), all nodes in parallel over contiguous memory.
        let (pre_points, pre_unit): (Vec<Vec3>, Vec<[DVec3; 2]>) =
            tree.order.par_iter().map(|&k| (points[k as usize], unit_pair(normals[k as usize]))).unzip();
        let planes: Vec<PlaneBound> = stored
            .par_iter()
            .enumerate()
            .map(|(node, &[_, _, start, end])| {
                let r = start as usize..end as usize;
                let (b, s, a) = (boxes[node], f64::from(cones[node][3]), axes[node]);
                let mut acc = PlaneAcc::new(&b);
                for (i, (&p, &unit)) in pre_points[r.clone()].iter().zip(&pre_unit[r.clone()]).enumerate() {
                    let inside = b[0] <= p.x && p.x <= b[3] && b[1] <= p.y && p.y <= b[4] && b[2] <= p.z && p.z <= b[5];
                    // Angle below π/2 iff axis·n > 0, and then its sine is |axis × n| (unit vectors).
                    let in_cone = s >= 1.0
                        || unit.iter().all(|&n| {
                            n != DVec3::ZERO && a.dot(n) > 0.0 && a.cross(n).length() + CONE_MARGIN * 0.5 <= s
                        });
                    if !(inside && in_cone) {
                        return Err(ArraysError::NotConservative { node, candidate: tree.order[r.start + i] });
                    }
                    acc.add(unit, p);
                }
                Ok(acc.finish(&cones[node]))
            })
            .collect::<Result<_, _>>()?;
        let a = assemble(&flat, &boxes, &cones, &planes, &order, Some((normals, points)));
        Ok(ConeBvh {
            nodes: a.nodes,
            widest: a.widest,
            stream: a.stream,
            flat,
            stored,
            boxes,
            cones,
            order,
            leaf_size: arrays.leaf_size,
            normal_level: Some(normal_level),
            splits: arrays.splits.clone(),
            split_starts: arrays.split_starts.clone(),
            predicted_ns: 0.0,
        })
    }
}

/// The query layout of a stored tree (see [`ConeBvhArrays::nodes`]) over the preorder candidate
/// order `preorder`: the leaves' ranges gathered breadth-first into `order`, each node's own range
/// into it. The stored ranges must tile: the root holds every candidate and each node's children
/// split its range in order, so every candidate lands in exactly one leaf.
fn query_layout(stored: &[[u32; 4]], preorder: &[u32]) -> Result<(Vec<[u32; 4]>, Vec<u32>), ArraysError> {
    let n = preorder.len();
    if stored.first().is_none_or(|r| r[2] != 0 || r[3] as usize != n) {
        return Err(ArraysError::Tree { node: 0 });
    }
    let mut flat = Vec::with_capacity(stored.len());
    let mut order = Vec::with_capacity(n);
    for (i, &[first, count, start, end]) in stored.iter().enumerate() {
        let bad = ArraysError::Tree { node: i };
        if start > end || end as usize > n {
            return Err(bad);
        }
        if count > 0 {
            let kids = stored.get(first as usize..first as usize + count as usize).ok_or(bad.clone())?;
            let mut at = start;
            for kid in kids {
                if kid[2] != at {
                    return Err(bad);
                }
                at = kid[3];
            }
            if at != end {
                return Err(bad);
            }
            flat.push([first, count, order.len() as u32, order.len() as u32]);
        } else {
            let from = order.len() as u32;
            order.extend_from_slice(&preorder[start as usize..end as usize]);
            flat.push([first, count, from, order.len() as u32]);
        }
    }
    Ok((flat, order))
}

/// For each node, the fraction of `eyes` that test its bound and the fraction for which it is not
/// culled.
fn visit_frequencies(
    flat: &[[u32; 4]],
    boxes: &[[f32; 6]],
    cones: &[[f32; 4]],
    planes: &[PlaneBound],
    eyes: &[Vec3],
) -> (Vec<f64>, Vec<f64>) {
    let n = flat.len();
    let counts = eyes
        .par_iter()
        .fold(
            || vec![[0u32; 2]; n],
            |mut acc, &eye| {
                let mut i = 0;
                while i < n {
                    let [_, _, skip, leaf] = flat[i];
                    acc[i][0] += 1;
                    if plane_culls(&boxes[i], &cones[i], &planes[i], eye) {
                        i = skip as usize;
                        continue;
                    }
                    acc[i][1] += 1;
                    i = if leaf == 1 { skip as usize } else { i + 1 };
                }
                acc
            },
        )
        .reduce(|| vec![[0u32; 2]; n], |a, b| a.iter().zip(&b).map(|(x, y)| [x[0] + y[0], x[1] + y[1]]).collect());
    let k = eyes.len() as f64;
    counts.iter().map(|c| (f64::from(c[0]) / k, f64::from(c[1]) / k)).unzip()
}

/// Bottom-up choice of the nodes to turn into leaves, by expected cost over the sampled eyes
/// (on the preorder tree, before it is widened).
fn collapse_by_cost(
    nodes: &[[u32; 4]],
    children: &[Vec<u32>],
    visits: &[f64],
    passes: &[f64],
    cost: &CostModel,
) -> Vec<bool> {
    let n = nodes.len();
    let enter = f64::from(cost.bvh_enter_ns);
    let test = f64::from(cost.bvh_test_ns);
    let range = f64::from(cost.bvh_range_ns);
    let block = f64::from(cost.bvh_block_ns);
    let mut best = vec![0.0f64; n];
    let mut collapse = vec![false; n];
    for i in (0..n).rev() {
        let [start, end, _, leaf] = nodes[i];
        let blocks = f64::from((end - start).div_ceil(4));
        // Tested by the parent on every visit; entered and its range read when it passes.
        let leaf_cost = visits[i] * test + passes[i] * (enter + range + block * blocks);
        if leaf == 1 {
            best[i] = leaf_cost;
            continue;
        }
        let split = visits[i] * test + passes[i] * enter + children[i].iter().map(|&c| best[c as usize]).sum::<f64>();
        if leaf_cost < split {
            collapse[i] = true;
            best[i] = leaf_cost;
        } else {
            best[i] = split;
        }
    }
    collapse
}

/// The whole tree: normal cells (if any) on top, a spatial BVH below each. With `replay`
/// (`splits`, `split_starts` of [`ConeBvhArrays`]) the dual-space trees take the recorded splits
/// instead of searching for them (only with a normal level: the obvhs tree of
/// [`NormalSplit::Off`] cannot be replayed).
fn build_tree(
    points: &[Vec3],
    unit: &[[DVec3; 2]],
    leaf_size: u32,
    normal_level: Option<u8>,
    replay: Option<(&[u8], &[u32])>,
    cells: Option<&ArcCells>,
) -> Result<(Tree, Vec<u32>), ArraysError> {
    let mut tree = Tree::default();
    let ids: Vec<u32> = (0..points.len() as u32).collect();
    let Some(level) = normal_level else {
        if replay.is_some() {
            return Err(ArraysError::Value { array: "normal_level", index: 0, value: f64::NAN });
        }
        spatial(&mut tree, &ids, points, leaf_size);
        return Ok((tree, Vec::new()));
    };
    let factor = f64::from(crate::gauss::DEFAULT_OVERLAP);
    let paths = match cells.and_then(|c| c.paths(unit, level, factor)) {
        Some(paths) => paths,
        None => arc_paths(unit, &base_cells(BaseSolid::Icosahedron), level, factor),
    };
    let split = NormalSplitter { level };
    let records: Vec<u64> = paths.par_iter().enumerate().map(|(id, &path)| path_record(id as u32, path)).collect();
    drop(paths);
    // Three passes: the normal split lists its dual-space trees and records the tree around
    // them as steps, the dual-space trees are built (or replayed) on the thread pool, and the
    // steps are replayed, splicing them in where they were asked for.
    let mut jobs: Vec<Vec<u32>> = Vec::new();
    let mut plan: Vec<Step> = Vec::new();
    split.node(records, 0, leaf_size, &mut plan, &mut jobs);
    let built: Vec<Tree> = match replay {
        None => {
            let dual = dual_points(points, unit);
            let records = |ids: &[u32]| -> Vec<DualRecord> {
                ids.iter().map(|&id| DualRecord { b: dual[id as usize], id }).collect()
            };
            jobs.par_iter()
                .map(|ids| {
                    let mut sub = Tree::default();
                    let mut records = records(ids);
                    let bounds = centre_bounds(&records);
                    dual_node(&mut sub, &mut records, bounds, leaf_size, 0);
                    sub
                })
                .collect()
        }
        Some((splits, starts)) => {
            // The replay needs only the boxes' centres: records of 20 bytes instead of 36.
            let centres = dual_centres(points, unit);
            let records = |ids: &[u32]| -> Vec<CentreRecord> {
                ids.iter().map(|&id| CentreRecord { c: centres[id as usize], id }).collect()
            };
            if starts.len() != jobs.len() {
                return Err(ArraysError::Length { array: "split_starts", expected: jobs.len(), found: starts.len() });
            }
            let bad = |index: usize| ArraysError::Value { array: "split_starts", index, value: f64::NAN };
            jobs.par_iter()
                .enumerate()
                .map(|(j, ids)| {
                    let from = starts[j] as usize;
                    let to = starts.get(j + 1).map_or(splits.len(), |&e| e as usize);
                    let script = splits.get(from..to).ok_or_else(|| bad(j))?;
                    let mut sub = Tree::default();
                    let mut at = 0;
                    let mut records = records(ids);
                    let bounds = centre_bounds(&records);
                    replay_dual_node(&mut sub, &mut records, bounds, leaf_size, script, &mut at)?;
                    if at != script.len() { Err(bad(j)) } else { Ok(sub) }
                })
                .collect::<Result<_, _>>()?
        }
    };
    let mut starts = Vec::with_capacity(built.len());
    let mut built = built.into_iter();
    replay_plan(&mut tree, &plan, &mut |tree| {
        if let Some(sub) = built.next() {
            starts.push(tree.splits.len() as u32);
            tree.extend(sub);
        }
    });
    Ok((tree, starts))
}

/// Splits candidates by the Gauss-map cell their arc is stored in (see [`arc_paths`]), given as
/// [`path_record`]s.
struct NormalSplitter {
    level: u8,
}

/// Candidate `id` with its path `(key, cells)` ([`arc_paths`]) in one word: the key above bit 40,
/// the cell count in bits 32–39, the id below. The split moves these records instead of ids, so
/// no level reads a path table at random (two serial passes over the dragon's 1.3M candidates
/// took 30–40 ms each that way, most of it cache misses).
fn path_record(id: u32, (key, cells): (u32, u8)) -> u64 {
    u64::from(key) << 40 | u64::from(cells) << 32 | u64::from(id)
}

/// The normal split's tree as [`NormalSplitter::node`] built it, step by step, so that it is
/// built again around the dual-space trees without partitioning the candidates a second time
/// (that second pass was 25 ms of one core on the dragon).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// [`Tree::open`] a node.
    Open,
    /// A child of the open node starts here.
    Child,
    /// The child started last ends: it becomes a child of the open node.
    EndChild,
    /// The next dual-space tree goes here.
    Dual,
    /// [`Tree::close`] the open node.
    Close,
}

/// Builds the tree of `plan` in `tree`, calling `dual` wherever a dual-space tree goes.
fn replay_plan(tree: &mut Tree, plan: &[Step], dual: &mut dyn FnMut(&mut Tree)) {
    let (mut open, mut children) = (Vec::new(), Vec::new());
    for step in plan {
        match step {
            Step::Open => open.push(tree.open()),
            Step::Child => children.push(tree.nodes.len() as u32),
            Step::EndChild => {
                if let (Some(&at), Some(child)) = (open.last(), children.pop()) {
                    tree.children[at].push(child);
                }
            }
            Step::Dual => dual(tree),
            Step::Close => {
                if let Some(at) = open.pop() {
                    tree.close(at, false);
                }
            }
        }
    }
}

impl NormalSplitter {
    /// Plans the subtree of `records`, whose arcs all went down at least `depth` cells and share
    /// their first `depth` digits: arcs that stop here get a dual-space tree of their own (their
    /// ids go to `jobs`, a [`Step::Dual`] to `plan`), the others are grouped by their next cell.
    fn node(&self, records: Vec<u64>, depth: u8, leaf_size: u32, plan: &mut Vec<Step>, jobs: &mut Vec<Vec<u32>>) {
        let mut sink = |records: Vec<u64>, plan: &mut Vec<Step>| {
            plan.push(Step::Dual);
            jobs.push(records.into_iter().map(|r| r as u32).collect());
        };
        if depth > self.level || records.len() <= leaf_size as usize {
            sink(records, plan);
            return;
        }
        // The key's digit at this depth: a shift, not a division by 4^k (this runs for every
        // candidate at every level, twice).
        let shift = 40 + 2 * u32::from(self.level - depth);
        let digit = |r: u64| if depth == 0 { r >> shift } else { (r >> shift) & 3 };
        let mut stay = Vec::new();
        let mut groups: Vec<Vec<u64>> = vec![Vec::new(); if depth == 0 { 20 } else { 4 }];
        for r in records {
            if (r >> 32) as u8 <= depth {
                stay.push(r);
            } else {
                groups[digit(r) as usize].push(r);
            }
        }
        let parts = usize::from(!stay.is_empty()) + groups.iter().filter(|g| !g.is_empty()).count();
        if parts == 1 && stay.is_empty() {
            let only = groups.into_iter().find(|g| !g.is_empty()).unwrap_or_default();
            self.node(only, depth + 1, leaf_size, plan, jobs);
            return;
        }
        if parts == 1 {
            sink(stay, plan);
            return;
        }
        plan.push(Step::Open);
        if !stay.is_empty() {
            plan.push(Step::Child);
            sink(stay, plan);
            plan.push(Step::EndChild);
        }
        for g in groups.into_iter().filter(|g| !g.is_empty()) {
            plan.push(Step::Child);
            self.node(g, depth + 1, leaf_size, plan, jobs);
            plan.push(Step::EndChild);
        }
        plan.push(Step::Close);
    }
}

/// A candidate in the dual space of face planes: the 4D box (min, max) of its two planes'
/// points `(k·n̂, n̂·(v − c))` (see the module docs).
type DualBox = [[f32; 4]; 2];

/// The frame of the dual space over `points`: the centre `c` of their bounding box and the normal
/// weight `k` (see the module docs).
fn dual_frame(points: &[Vec3]) -> (Vec3, f32) {
    let b = bounding_box(points.iter().copied());
    let (lo, hi) = (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]));
    (anchor(&b), DUAL_NORMAL_WEIGHT * ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE))
}

/// A candidate's [`DualBox`] in the frame `(c, k)` of [`dual_frame`].
fn dual_box((c, k): (Vec3, f32), [n1, n2]: [DVec3; 2], v: Vec3) -> DualBox {
    let d = v - c;
    let plane = |n: DVec3| {
        let n = n.as_vec3();
        [k * n.x, k * n.y, k * n.z, n.dot(d)]
    };
    let (a, b) = (plane(n1), plane(n2));
    [std::array::from_fn(|i| a[i].min(b[i])), std::array::from_fn(|i| a[i].max(b[i]))]
}

/// Every candidate's [`DualBox`].
fn dual_points(points: &[Vec3], unit: &[[DVec3; 2]]) -> Vec<DualBox> {
    let frame = dual_frame(points);
    unit.par_iter().zip(points).map(|(&n, &v)| dual_box(frame, n, v)).collect()
}

/// Every candidate's [`DualBox`] centre, as [`DualRecord::centre`] computes it.
fn dual_centres(points: &[Vec3], unit: &[[DVec3; 2]]) -> Vec<[f32; 4]> {
    let frame = dual_frame(points);
    unit.par_iter().zip(points).map(|(&n, &v)| box_centre(&dual_box(frame, n, v))).collect()
}

fn box_centre(b: &DualBox) -> [f32; 4] {
    std::array::from_fn(|a| (b[0][a] + b[1][a]) * 0.5)
}

/// Mean-width measure of a 4D box: the sum of its extents.
fn dual_width(b: &DualBox) -> f32 {
    (0..4).map(|i| (b[1][i] - b[0][i]).max(0.0)).sum()
}

const EMPTY_BOX: DualBox = [[f32::INFINITY; 4], [f32::NEG_INFINITY; 4]];

fn grow(a: &mut DualBox, b: &DualBox) {
    for i in 0..4 {
        a[0][i] = a[0][i].min(b[0][i]);
        a[1][i] = a[1][i].max(b[1][i]);
    }
}

/// A candidate as the dual-space build moves it: its box and its index. The build reorders
/// these records in place, so that every pass reads memory in sequence (indices into a shared box
/// array cost a cache miss per candidate and level on a million-candidate mesh).
#[derive(Clone, Copy)]
struct DualRecord {
    b: DualBox,
    id: u32,
}

/// What [`apply_split`] needs of a record: its dual-space box centre and its candidate.
trait Centred {
    fn centre(&self) -> [f32; 4];
    fn id(&self) -> u32;
}

impl Centred for DualRecord {
    fn centre(&self) -> [f32; 4] {
        box_centre(&self.b)
    }
    fn id(&self) -> u32 {
        self.id
    }
}

/// A candidate as the replay moves it: the centre of its [`DualBox`] and its index (the replay
/// never needs the box itself).
#[derive(Clone, Copy)]
struct CentreRecord {
    c: [f32; 4],
    id: u32,
}

impl Centred for CentreRecord {
    fn centre(&self) -> [f32; 4] {
        self.c
    }
    fn id(&self) -> u32 {
        self.id
    }
}

/// Emits the dual-space tree over `records` (reordered in place), binary, top-down: on each of the
/// 4 axes the candidates' box centres go into [`DUAL_BINS`] bins, and the split between bins
/// that minimises `count_left · width_left + count_right · width_right` is taken (the binned
/// surface-area heuristic of ray tracing, with the mean width that measures how often a random
/// hyperplane crosses a box). Deterministic: in place, ties to the first axis and bin; subtrees
/// of more than [`PARALLEL_CANDIDATES`] are built on the thread pool, which gives the same tree.
/// Candidates whose centres coincide on every axis are split in halves. `bounds` is the box of the
/// records' centres.
fn dual_node(tree: &mut Tree, records: &mut [DualRecord], bounds: DualBox, leaf_size: u32, depth: u32) {
    let at = tree.open();
    if records.len() <= leaf_size as usize || records.len() < 2 {
        tree.order.extend(records.iter().map(|r| r.id));
        tree.close(at, true);
        return;
    }
    // Axes whose centres all coincide (or are not finite) offer no split.
    let splittable: [bool; 4] =
        std::array::from_fn(|a| (bounds[1][a] - bounds[0][a]).partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater));
    // (cost, axis, first bin of the right side)
    let mut best: Option<(f32, usize, usize)> = None;
    if depth < DUAL_SAH_DEPTH && splittable.iter().any(|&s| s) {
        // All four axes binned in one pass over the records; on the thread pool for large nodes
        // (counts add and boxes take minima and maxima: the same bins in any split).
        type Bins = ([[usize; DUAL_BINS]; 4], [[DualBox; DUAL_BINS]; 4]);
        let empty = || -> Bins { ([[0usize; DUAL_BINS]; 4], [[EMPTY_BOX; DUAL_BINS]; 4]) };
        let bin = |chunk: &[DualRecord]| {
            let mut acc = empty();
            for r in chunk {
                let bins = bins_of(&bounds, r.centre());
                for a in (0..4).filter(|&a| splittable[a]) {
                    let k = bins[a];
                    acc.0[a][k] += 1;
                    grow(&mut acc.1[a][k], &r.b);
                }
            }
            acc
        };
        let (count, bin_box) = if records.len() > PARALLEL_CANDIDATES {
            records.par_chunks(16 * 1024).map(bin).reduce(empty, |mut x, y| {
                for a in 0..4 {
                    for k in 0..DUAL_BINS {
                        x.0[a][k] += y.0[a][k];
                        grow(&mut x.1[a][k], &y.1[a][k]);
                    }
                }
                x
            })
        } else {
            bin(records)
        };
        for a in (0..4).filter(|&a| splittable[a]) {
            let (count, bin_box) = (&count[a], &bin_box[a]);
            let mut right_cost = [0f32; DUAL_BINS];
            let (mut acc, mut n) = (EMPTY_BOX, 0usize);
            for k in (1..DUAL_BINS).rev() {
                n += count[k];
                grow(&mut acc, &bin_box[k]);
                right_cost[k] = n as f32 * dual_width(&acc);
            }
            let (mut acc, mut n) = (EMPTY_BOX, 0usize);
            for k in 0..DUAL_BINS - 1 {
                n += count[k];
                grow(&mut acc, &bin_box[k]);
                if n == 0 || n == records.len() {
                    continue;
                }
                let cost = n as f32 * dual_width(&acc) + right_cost[k + 1];
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, a, k + 1));
                }
            }
        }
    }
    let split = match best {
        Some((_, a, split)) => (a as u8) << 5 | split as u8,
        None => MEDIAN_SPLIT,
    };
    tree.splits.push(split);
    // The partition pass also gives each side's centre box.
    let (mid, sides) = apply_split(records, &bounds, split);
    let parallel = records.len() > PARALLEL_CANDIDATES;
    let (left, right) = records.split_at_mut(mid);
    if parallel {
        let build = |part: &mut [DualRecord], b: DualBox| {
            let mut sub = Tree::default();
            dual_node(&mut sub, part, b, leaf_size, depth + 1);
            sub
        };
        let (l, r) = rayon::join(|| build(left, sides[0]), || build(right, sides[1]));
        tree.append_child(at, l);
        tree.append_child(at, r);
    } else {
        for (part, b) in [(left, sides[0]), (right, sides[1])] {
            let child = tree.nodes.len() as u32;
            dual_node(tree, part, b, leaf_size, depth + 1);
            tree.children[at].push(child);
        }
    }
    tree.close(at, false);
}

/// The box of the records' centres.
fn centre_bounds(records: &[impl Centred]) -> DualBox {
    let mut bounds = EMPTY_BOX;
    for r in records {
        let c = r.centre();
        grow(&mut bounds, &[c, c]);
    }
    bounds
}

/// The bin of centre coordinate `c` on axis `a` of the centre box `bounds`: the rule that
/// [`bins_of`] and [`left_of`] compute faster (and that the tests hold them to).
#[cfg(test)]
fn bin_of(bounds: &DualBox, c: f32, a: usize) -> usize {
    let ext = bounds[1][a] - bounds[0][a];
    // `as` saturates (NaN to 0): no bin index leaves the range.
    (((c - bounds[0][a]) / ext * DUAL_BINS as f32) as usize).min(DUAL_BINS - 1)
}

/// Whether `bin_of` puts centre coordinate `c` on axis `a` below `bin` (≥ 1), decided on the
/// scaled coordinate itself: for `t ≥ 0`, `⌊t⌋ < bin` iff `t < bin`; a negative or NaN `t` is bin
/// 0, and `t` at or past the last bin is at least `bin`. The partition asks this of every record
/// at every level, and the saturating conversion and clamp of `bin_of` cost more than the test.
#[inline]
fn left_of(bounds: &DualBox, c: f32, a: usize, bin: usize) -> bool {
    let ext = bounds[1][a] - bounds[0][a];
    let t = (c - bounds[0][a]) / ext * DUAL_BINS as f32;
    t.partial_cmp(&(bin as f32)).is_none_or(std::cmp::Ordering::is_lt)
}

/// `bin_of` on all four axes at once: the same subtraction, division and product per lane
/// (one vector division instead of four: the binning pass divides for every candidate on every
/// axis at every level, and the scalar rule's line held 3 % of the samples of a one-thread
/// profile of the dragon's whole bake). The lanes are clamped to the bins as floats, NaN to 0
/// (on x86-64 the vector maximum returns its second operand there; the test
/// `bins_of_is_bin_of_on_each_axis` holds NaN lanes to the rule), so each conversion is a 32-bit
/// one rather than `as usize`'s longer 64-bit sequence. With [`left_of`] in the partition, the
/// dragon's dual-space trees took 147–175 ms (one run 202) instead of 164–194 (temporary timers,
/// bakes alternating with the build before).
#[inline(always)]
fn bins_of(bounds: &DualBox, c: [f32; 4]) -> [usize; 4] {
    let lo = Vec4::from_array(bounds[0]);
    let ext = Vec4::from_array(bounds[1]) - lo;
    let t = (Vec4::from_array(c) - lo) / ext * DUAL_BINS as f32;
    let t = t.max(Vec4::ZERO).min(Vec4::splat((DUAL_BINS - 1) as f32));
    t.to_array().map(|x| x as i32 as usize)
}

/// Reorders `records` (centre box `bounds`) by the split byte `split` (see
/// [`ConeBvhArrays::splits`]) and returns the size of the left side and the centre boxes of both
/// sides: the records in bins below `bin` on `axis`, or for [`MEDIAN_SPLIT`] the lower half by
/// centre on the widest axis (ties by candidate). The one definition both the build and the
/// replay use; the order it leaves depends only on the records' centres and candidates, not on
/// the record type.
fn apply_split(records: &mut [impl Centred], bounds: &DualBox, split: u8) -> (usize, [DualBox; 2]) {
    let mut sides = [EMPTY_BOX; 2];
    if split != MEDIAN_SPLIT {
        let (a, bin) = (usize::from(split >> 5), usize::from(split & 31));
        let mut left = 0;
        for j in 0..records.len() {
            let c = records[j].centre();
            if left_of(bounds, c[a], a, bin) {
                grow(&mut sides[0], &[c, c]);
                records.swap(left, j);
                left += 1;
            } else {
                grow(&mut sides[1], &[c, c]);
            }
        }
        return (left, sides);
    }
    // Median of the widest axis of centres (all equal: any halves): the key of rank `mid` is
    // found on a copy of the keys, then the records are partitioned against it in one pass.
    let a =
        (0..4).max_by(|&x, &y| (bounds[1][x] - bounds[0][x]).total_cmp(&(bounds[1][y] - bounds[0][y])).then(y.cmp(&x)));
    let mid = records.len() / 2;
    let key = |r: &dyn Centred| (r.centre()[a.unwrap_or(0)], r.id());
    let before = |x: (f32, u32), y: (f32, u32)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
    let mut keys: Vec<(f32, u32)> = records.iter().map(|r| key(r)).collect();
    if keys.is_empty() {
        return (0, sides);
    }
    let (_, &mut pivot, _) = keys.select_nth_unstable_by(mid, |&x, &y| before(x, y));
    drop(keys);
    let mut left = 0;
    for j in 0..records.len() {
        let c = records[j].centre();
        if before(key(&records[j]), pivot).is_lt() {
            grow(&mut sides[0], &[c, c]);
            records.swap(left, j);
            left += 1;
        } else {
            grow(&mut sides[1], &[c, c]);
        }
    }
    (left, sides)
}

/// [`dual_node`] with the recorded split bytes `script` (read from `at`) instead of the
/// heuristic's search: the same tree over the same records, whose centre box is `bounds`. Serial;
/// a split byte that does not split (an empty side, an axis or bin out of range) or a script that
/// ends early is refused.
fn replay_dual_node(
    tree: &mut Tree,
    records: &mut [CentreRecord],
    bounds: DualBox,
    leaf_size: u32,
    script: &[u8],
    at: &mut usize,
) -> Result<(), ArraysError> {
    let node = tree.open();
    if records.len() <= leaf_size as usize || records.len() < 2 {
        tree.order.extend(records.iter().map(|r| r.id));
        tree.close(node, true);
        return Ok(());
    }
    let bad = ArraysError::Value { array: "splits", index: *at, value: f64::NAN };
    let split = *script.get(*at).ok_or(bad.clone())?;
    *at += 1;
    if split != MEDIAN_SPLIT && (split >> 5 > 3 || usize::from(split & 31) == 0) {
        return Err(bad);
    }
    tree.splits.push(split);
    let (mid, sides) = apply_split(records, &bounds, split);
    if mid == 0 || mid == records.len() {
        return Err(bad);
    }
    let (left, right) = records.split_at_mut(mid);
    for (part, b) in [(left, sides[0]), (right, sides[1])] {
        let child = tree.nodes.len() as u32;
        replay_dual_node(tree, part, b, leaf_size, script, at)?;
        tree.children[node].push(child);
    }
    tree.close(node, false);
    Ok(())
}

/// Emits an obvhs BVH2 (PLOC) over the points of `ids`, cut at `leaf_size` ([`NormalSplit::Off`]).
fn spatial(tree: &mut Tree, ids: &[u32], points: &[Vec3], leaf_size: u32) {
    if ids.len() <= leaf_size as usize || ids.len() < 2 {
        let at = tree.open();
        tree.order.extend_from_slice(ids);
        tree.close(at, true);
        return;
    }
    let aabbs: Vec<Aabb> = ids.iter().map(|&i| Aabb::from_point(Vec3A::from(points[i as usize]))).collect();
    let params = BvhBuildParams { max_prims_per_leaf: 1, ..BvhBuildParams::fast_build() };
    let bvh = build_bvh2(&aabbs, params, &mut Duration::default());
    // Subtree sizes, children before parents: obvhs places children after their parent.
    let mut size = vec![0u32; bvh.nodes.len()];
    for i in (0..bvh.nodes.len()).rev() {
        let node = &bvh.nodes[i];
        size[i] = if node.is_leaf() {
            node.prim_count
        } else {
            let c = node.first_index as usize;
            size.get(c).copied().unwrap_or(0) + size.get(c + 1).copied().unwrap_or(0)
        };
    }
    emit_bvh_node(tree, &bvh, 0, &size, ids, leaf_size);
}

fn emit_bvh_node(tree: &mut Tree, bvh: &obvhs::bvh2::Bvh2, i: usize, size: &[u32], ids: &[u32], leaf_size: u32) {
    let at = tree.open();
    let node = &bvh.nodes[i];
    let leaf = node.is_leaf() || size[i] <= leaf_size;
    if leaf {
        gather(bvh, i, ids, &mut tree.order);
    } else {
        let c = node.first_index as usize;
        for child in [c, c + 1] {
            let k = tree.nodes.len() as u32;
            emit_bvh_node(tree, bvh, child, size, ids, leaf_size);
            tree.children[at].push(k);
        }
    }
    tree.close(at, leaf);
}

fn gather(bvh: &obvhs::bvh2::Bvh2, i: usize, ids: &[u32], order: &mut Vec<u32>) {
    let node = &bvh.nodes[i];
    if node.is_leaf() {
        let first = node.first_index as usize;
        order.extend(bvh.primitive_indices[first..first + node.prim_count as usize].iter().map(|&p| ids[p as usize]));
    } else {
        gather(bvh, node.first_index as usize, ids, order);
        gather(bvh, node.first_index as usize + 1, ids, order);
    }
}

/// The box of no points (what [`bounding_box`] returns for none).
const EMPTY_AABB: [f32; 6] =
    [f32::INFINITY, f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY];

fn bounding_box(points: impl Iterator<Item = Vec3>) -> [f32; 6] {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z]
}

/// [`bounding_cone`] of `pairs` and [`PlaneBound::of`] the candidates (`pairs`, `points`, box `b`)
/// under that cone, with one pass over the candidates after the normals' sum instead of two
/// (the build measures every node over its whole range, so every candidate once per level); a
/// node that never culls skips the plane pass. Equal to the two apart (tested).
fn cone_and_planes(pairs: &[[DVec3; 2]], points: &[Vec3], b: &[f32; 6]) -> ([f32; 4], PlaneBound) {
    let mut sum = DVec3::ZERO;
    for &[a, b] in pairs {
        sum = sum + a + b;
    }
    if sum.length().is_nan() || sum.length() <= 1e-12 {
        return ([0.0, 0.0, 1.0, NEVER_CULL], PlaneBound::NEVER);
    }
    let axis32 = sum.normalize().as_vec3();
    let axis = axis32.as_dvec3().normalize();
    let never = ([axis32.x, axis32.y, axis32.z, NEVER_CULL], PlaneBound::NEVER);
    let mut widest = Widest { cos_min: 1.0, max_angle: 0.0 };
    let mut acc = PlaneAcc::new(b);
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    let done = if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, the one feature the function is compiled with.
        match unsafe { cone_and_planes_avx(axis, pairs, points, &mut widest, &mut acc) } {
            Some(done) => done,
            None => return never,
        }
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = 0;
    if !widest.add_all(axis, &pairs[done..], &points[done..], &mut acc) {
        return never;
    }
    let max_angle = widest.max_angle;
    let alpha = max_angle + 1e-9;
    if alpha >= std::f64::consts::FRAC_PI_2 - 1e-3 {
        return never;
    }
    let s = alpha.sin() + CONE_MARGIN;
    let s32 = s as f32;
    let s32 = if f64::from(s32) < s { s32.next_up() } else { s32 };
    let cone = [axis32.x, axis32.y, axis32.z, s32];
    (cone, acc.finish(&cone))
}

/// The running widest angle of [`cone_and_planes`] from its axis: the smallest dot product so
/// far and the largest exact angle, evaluated where a normal comes within reach of the smallest.
#[derive(Clone, Copy, Debug)]
struct Widest {
    cos_min: f64,
    max_angle: f64,
}

impl Widest {
    /// Adds the candidates `pairs` (unit normals) at `points` to the widest angle and to `acc`,
    /// in order; false (and stops) at a zero normal.
    fn add_all(&mut self, axis: DVec3, pairs: &[[DVec3; 2]], points: &[Vec3], acc: &mut PlaneAcc) -> bool {
        for (&pair, &point) in pairs.iter().zip(points) {
            for n in pair {
                if n == DVec3::ZERO {
                    return false;
                }
                self.add(axis, n);
            }
            acc.add(pair, point);
        }
        true
    }

    #[inline(always)]
    fn add(&mut self, axis: DVec3, n: DVec3) {
        let d = axis.dot(n);
        if d <= self.cos_min {
            self.cos_min = d;
            self.max_angle = self.max_angle.max(axis.cross(n).length().atan2(d));
        }
    }
}

/// [`Widest::add_all`] on the candidates in whole groups of 4, with AVX: the candidates processed
/// (`None` at a zero normal, where the plain loop gives up too). The dot products with the axis
/// are taken 4 at a time and a group goes through [`Widest::add`] one by one only where one of
/// them reaches the smallest so far: elsewhere `add` would change nothing, so the widest angle is
/// the plain loop's bit for bit. The planes' offsets and reach take 4-lane minima and maxima,
/// joined at the end: the same values in any order, but for the sign of a zero, which
/// [`PlaneAcc::finish`] makes +0. The products round as glam's, with no fused multiply-add.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[allow(unsafe_code)]
fn cone_and_planes_avx(
    axis: DVec3,
    pairs: &[[DVec3; 2]],
    points: &[Vec3],
    widest: &mut Widest,
    acc: &mut PlaneAcc,
) -> Option<usize> {
    use std::arch::x86_64::*;
    let splat = |x: f64| _mm256_set1_pd(x);
    let dot = |[ax, ay, az]: [__m256d; 3], [bx, by, bz]: [__m256d; 3]| {
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, bx), _mm256_mul_pd(ay, by)), _mm256_mul_pd(az, bz))
    };
    let zero = _mm256_setzero_pd();
    let is_zero = |[x, y, z]: [__m256d; 3]| {
        _mm256_and_pd(
            _mm256_and_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(x, zero), _mm256_cmp_pd::<_CMP_EQ_OQ>(y, zero)),
            _mm256_cmp_pd::<_CMP_EQ_OQ>(z, zero),
        )
    };
    let a = [splat(axis.x), splat(axis.y), splat(axis.z)];
    let p0 = [splat(acc.p0.x), splat(acc.p0.y), splat(acc.p0.z)];
    let (mut lo, mut hi, mut reach) = (splat(f64::INFINITY), splat(f64::NEG_INFINITY), zero);
    let n = pairs.len().min(points.len()) / 4 * 4;
    for (four, at) in pairs[..n].chunks_exact(4).zip(points[..n].chunks_exact(4)) {
        let lanes = |f: &dyn Fn(usize) -> f64| _mm256_setr_pd(f(0), f(1), f(2), f(3));
        let n1 = [lanes(&|k| four[k][0].x), lanes(&|k| four[k][0].y), lanes(&|k| four[k][0].z)];
        let n2 = [lanes(&|k| four[k][1].x), lanes(&|k| four[k][1].y), lanes(&|k| four[k][1].z)];
        if _mm256_movemask_pd(_mm256_or_pd(is_zero(n1), is_zero(n2))) != 0 {
            return None;
        }
        let near = splat(widest.cos_min);
        let close =
            _mm256_or_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(dot(a, n1), near), _mm256_cmp_pd::<_CMP_LE_OQ>(dot(a, n2), near));
        if _mm256_movemask_pd(close) != 0 {
            for pair in four {
                widest.add(axis, pair[0]);
                widest.add(axis, pair[1]);
            }
        }
        // `point.as_dvec3() - p0`: the conversion is exact.
        let d = [
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].x)), p0[0]),
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].y)), p0[1]),
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].z)), p0[2]),
        ];
        // Each new value first: `_mm256_min_pd(new, old)` keeps `old` where `new` is NaN, as
        // `f64::min` ignores a NaN.
        reach = _mm256_max_pd(dot(d, d), reach);
        for h in [dot(n1, d), dot(n2, d)] {
            lo = _mm256_min_pd(h, lo);
            hi = _mm256_max_pd(h, hi);
        }
    }
    let mut out = [[0f64; 4]; 3];
    for (v, o) in [lo, hi, reach].into_iter().zip(&mut out) {
        // SAFETY: `o` holds 4 f64s; the store is unaligned.
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), v) };
    }
    let [lo, hi, reach] = out;
    acc.lo = lo.into_iter().fold(acc.lo, f64::min);
    acc.hi = hi.into_iter().fold(acc.hi, f64::max);
    acc.reach_squared = reach.into_iter().fold(acc.reach_squared, f64::max);
    acc.count += n;
    Some(n)
}

/// Cone around the normalised mean of the unit normals of `pairs` (both of each, in order):
/// `[axis, sin α + margin]` with α measured from the `f32` axis, or a never-culled cone. The sum
/// is a plain loop over the pairs (the build runs this over every candidate at every level; the
/// Gauss map's widest angle was several times slower through a `flat_map` over pairs).
#[cfg(test)]
fn bounding_cone(pairs: &[[DVec3; 2]]) -> [f32; 4] {
    let mut sum = DVec3::ZERO;
    for &[a, b] in pairs {
        sum = sum + a + b;
    }
    if sum.length().is_nan() || sum.length() <= 1e-12 {
        return [0.0, 0.0, 1.0, NEVER_CULL];
    }
    let axis32 = sum.normalize().as_vec3();
    let axis = axis32.as_dvec3().normalize();
    let mut cos_min = 1.0f64;
    let mut max_angle = 0.0f64;
    for n in pairs.iter().flatten().copied() {
        if n == DVec3::ZERO {
            return [axis32.x, axis32.y, axis32.z, NEVER_CULL];
        }
        let d = axis.dot(n);
        // Exact angle only where it matters (the widest normal so far).
        if d <= cos_min {
            cos_min = d;
            max_angle = max_angle.max(axis.cross(n).length().atan2(d));
        }
    }
    let alpha = max_angle + 1e-9;
    if alpha >= std::f64::consts::FRAC_PI_2 - 1e-3 {
        return [axis32.x, axis32.y, axis32.z, NEVER_CULL];
    }
    let s = alpha.sin() + CONE_MARGIN;
    let s32 = s as f32;
    let s32 = if f64::from(s32) < s { s32.next_up() } else { s32 };
    [axis32.x, axis32.y, axis32.z, s32]
}

/// Deterministic eyes on spheres around the points' bounding box, 1.2 to 4 half-diagonals from its
/// centre (always outside the box).
pub(crate) fn sample_eyes(points: &[Vec3], count: u32) -> Vec<Vec3> {
    if points.is_empty() || count == 0 {
        return Vec::new();
    }
    let b = bounding_box(points.iter().copied());
    let (lo, hi) = (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]));
    let center = (lo + hi) * 0.5;
    let half = ((hi - lo) * 0.5).length().max(1e-6);
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .map(|k| {
            // Fibonacci sphere directions, radii cycling through [1.2, 4].
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / count as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * k as f32;
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            let dist = half * (1.2 + 2.8 * ((k as f32 * 0.618_034) % 1.0));
            center + dir * dist
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The predicted cost walks without testing candidates: its counts must be a query's.
    #[test]
    fn counting_walk_counts_what_a_query_does() {
        let mut rng = crate::measure::ViewRng::new(4);
        let points: Vec<Vec3> = (0..20_000).map(|_| rng.direction() * 3.0).collect();
        let normals: Vec<[Vec3; 2]> = points
            .iter()
            .map(|&p| {
                let n = p.normalize();
                [(n + rng.direction() * 0.2).normalize(), (n + rng.direction() * 0.2).normalize()]
            })
            .collect();
        let bvh = ConeBvh::build(&normals, &points, &ConeBvhOptions::default(), &CostModel::default());
        let mut out = EdgeSet::default();
        let mut entered = 0;
        for k in 0..500 {
            let eye = rng.direction() * if k % 2 == 0 { 10.0 } else { 1.5 };
            let counted = bvh.walk::<true, false>(eye, &mut EdgeSet::default());
            assert_eq!(counted, bvh.query_counted(eye, &mut out), "eye {eye}");
            entered += counted.nodes_entered;
        }
        assert!(entered > 500, "the walks entered {entered} nodes");
    }

    /// Queries through the 16-bit pretest (forced on for this small tree) give the brute force's
    /// answer, from eyes far away, near, and within leaves' reach (where the pretest leaves the
    /// leaf to `f32`); the normals are close to radial, so many are close to tangent to a view.
    #[test]
    fn pretest_queries_match_brute_force() {
        let mut rng = crate::measure::ViewRng::new(7);
        let points: Vec<Vec3> = (0..20_000).map(|_| rng.direction() * 3.0 + Vec3::new(1e4, 0.0, 0.0)).collect();
        let normals: Vec<[Vec3; 2]> = points
            .iter()
            .map(|&p| {
                let n = (p - Vec3::new(1e4, 0.0, 0.0)).normalize();
                [(n + rng.direction() * 0.05).normalize(), (n + rng.direction() * 0.05).normalize()]
            })
            .collect();
        crate::brute::FORCE_PRETEST.with(|f| f.set(true));
        let bvh = ConeBvh::build(&normals, &points, &ConeBvhOptions::default(), &CostModel::default());
        crate::brute::FORCE_PRETEST.with(|f| f.set(false));
        assert!(!bvh.stream.fixed_is_empty());
        let brute = crate::BruteForce::new(&normals, &points);
        let (mut got, mut expected) = (EdgeSet::default(), EdgeSet::default());
        let mut silhouettes = 0;
        for k in 0..2000 {
            let distance = [3.01, 3.5, 6.0, 30.0, 3000.0][k % 5];
            let eye = Vec3::new(1e4, 0.0, 0.0) + rng.direction() * distance;
            bvh.query(eye, &mut got);
            brute.query(crate::View::Perspective { eye }, &mut expected);
            assert_eq!(got.to_vec(), expected.to_vec(), "eye {eye}");
            silhouettes += expected.to_vec().len();
        }
        assert!(silhouettes > 100_000, "{silhouettes} silhouettes");
    }

    /// The corner test agrees with dense sampling of the box and the cone.
    #[test]
    fn cull_test_is_conservative_on_samples() {
        let mut s = 99u64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut culled = 0;
        for _ in 0..3000 {
            let axis = Vec3::new(r(), r(), r()).normalize();
            let alpha = (r() * 0.5 + 0.5) * 1.2;
            let lo = Vec3::new(r(), r(), r());
            let hi = lo + Vec3::new(r().abs(), r().abs(), r().abs()) * 0.5;
            let b = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z];
            let c = [axis.x, axis.y, axis.z, alpha.sin() + 1e-5];
            let e = Vec3::new(r(), r(), r()) * 3.0;
            if !box_culls(&b, &c, e) {
                continue;
            }
            culled += 1;
            // Any normal inside the cone and any point in the box give the same sign.
            let mut sign = 0.0f32;
            for _ in 0..200 {
                let p = lo + (hi - lo) * Vec3::new(r() * 0.5 + 0.5, r() * 0.5 + 0.5, r() * 0.5 + 0.5);
                let tangent = axis.any_orthonormal_vector();
                let n = (axis * alpha.cos() * 1.0001
                    + tangent.rotate_towards(axis.cross(tangent), r() * 3.2) * alpha.sin())
                .normalize();
                let v = n.dot(e - p);
                assert!(v != 0.0);
                if sign == 0.0 {
                    sign = v.signum();
                }
                assert_eq!(sign, v.signum());
            }
        }
        assert!(culled > 100, "only {culled} culled");
    }

    /// Whenever the plane-offset test culls a node, the `f32` predicate rejects every candidate
    /// below it: random nodes of nearly coplanar faces (the case the test is for) and of scattered
    /// ones, eyes near and far.
    #[test]
    fn plane_test_is_conservative() {
        let mut s = 7u64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let (mut culled, mut tested) = (0, 0);
        for case in 0..400 {
            let axis = Vec3::new(r(), r(), r()).normalize();
            let spread = if case % 2 == 0 { 0.05 } else { 0.6 };
            let center = Vec3::new(r(), r(), r()) * 10.0;
            let size = 0.1 + r().abs();
            let (t1, t2) = axis.any_orthonormal_pair();
            // Candidates on a slightly bumpy patch through `center` with normals near `axis`.
            let n = 24;
            let mut normals = Vec::new();
            let mut points = Vec::new();
            for _ in 0..n {
                let v = center + (t1 * r() + t2 * r()) * size + axis * (r() * size * spread);
                let tilt = |r: &mut dyn FnMut() -> f32| (axis + (t1 * r() + t2 * r()) * spread).normalize();
                normals.push([tilt(&mut r), tilt(&mut r)]);
                points.push(v);
            }
            let b = bounding_box(points.iter().copied());
            let pairs: Vec<[DVec3; 2]> = normals.iter().map(|&n| unit_pair(n)).collect();
            let c = bounding_cone(&pairs);
            let p = PlaneBound::of(&pairs, &points, &b, &c);
            for k in 0..200 {
                let dir = Vec3::new(r(), r(), r()).normalize();
                let dist = if k % 2 == 0 { size * (0.01 + 3.0 * r().abs()) } else { 50.0 * r().abs() };
                let e = center + dir * dist;
                tested += 1;
                if !plane_culls(&b, &c, &p, e) {
                    continue;
                }
                culled += 1;
                for (nn, v) in normals.iter().zip(&points) {
                    let w = e - *v;
                    let (a1, a2) = (nn[0].dot(w), nn[1].dot(w));
                    assert!(a1 != 0.0 && a2 != 0.0 && (a1 > 0.0) == (a2 > 0.0), "case {case}: culled a silhouette");
                }
            }
        }
        assert!(culled > tested / 4, "only {culled} of {tested} culled");
    }

    /// The fused pass gives the cone and plane bound of the two passes apart, bit for bit: random
    /// patches of every spread (some past a hemisphere), with zero normals and repeated points.
    #[test]
    fn cone_and_planes_equal_the_two_passes() {
        let mut rng = crate::measure::ViewRng::new(3);
        let mut never = 0;
        for case in 0..3000 {
            let axis = rng.direction();
            let spread = [1e-4, 0.05, 0.6, 3.0][case % 4];
            let n = 1 + case % 40;
            let mut normals: Vec<[Vec3; 2]> =
                (0..n).map(|_| [0, 1].map(|_| (axis + rng.direction() * spread).normalize_or_zero())).collect();
            let mut points: Vec<Vec3> = (0..n).map(|_| rng.direction() * (1.0 + rng.unit() * 1e3)).collect();
            if case % 97 == 0 {
                normals[n / 2][1] = Vec3::ZERO;
            }
            if case % 5 == 0 {
                points[0] = points[n - 1];
            }
            if case % 3 == 0 {
                // Candidates at the anchor: offsets of zero, -0.0 for normals with no positive
                // component (the four-lane path must keep the plain loop's zero).
                let centre = anchor(&bounding_box(points.iter().copied()));
                let at = (case / 3) % (n + 1);
                points.insert(at, centre);
                normals
                    .insert(at, [Vec3::new(-0.6, -0.8, -0.0), (axis + rng.direction() * spread).normalize_or_zero()]);
                points.push(centre);
                normals.push([(axis + rng.direction() * spread).normalize_or_zero(), Vec3::new(0.0, 0.6, 0.8)]);
            }
            if case % 11 == 0 {
                // Every candidate at one point: every offset is a zero of either sign.
                // Normals with no positive component give -0.0, the others +0.0; all within a
                // narrow cone, so that the planes are used.
                points.iter_mut().for_each(|p| *p = Vec3::new(1.5, -2.0, 0.25));
                let (negative, mixed) = (Vec3::new(-0.48, -0.6, -0.64), Vec3::new(0.05, -0.6, -0.8).normalize());
                for (k, pair) in normals.iter_mut().enumerate() {
                    *pair = [0, 1].map(|side| if (k * 2 + side + case / 11) % 5 < 2 { negative } else { mixed });
                }
            }
            let pairs: Vec<[DVec3; 2]> = normals.iter().map(|&n| unit_pair(n)).collect();
            let b = bounding_box(points.iter().copied());
            let cone = bounding_cone(&pairs);
            let planes = PlaneBound::of(&pairs, &points, &b, &cone);
            let (fused_cone, fused_planes) = cone_and_planes(&pairs, &points, &b);
            assert_eq!(fused_cone.map(f32::to_bits), cone.map(f32::to_bits), "case {case}");
            assert_eq!(fused_planes.0.map(f32::to_bits), planes.0.map(f32::to_bits), "case {case}");
            never += usize::from(cone[3] >= 1.0);
        }
        assert!(never > 300 && never < 2500, "{never} never-culling cones");
    }

    /// The four-lane binning gives each axis the bin of the scalar rule, and the partition's test
    /// agrees with it at every bin, also for coordinates on and past the box's faces, flat axes
    /// and non-finite ones.
    #[test]
    fn bins_of_is_bin_of_on_each_axis() {
        let mut rng = crate::measure::ViewRng::new(5);
        for case in 0..20_000 {
            let lo: [f32; 4] = std::array::from_fn(|_| rng.unit() * 10.0);
            let hi: [f32; 4] =
                std::array::from_fn(|a| if case % 7 == a { lo[a] } else { lo[a] + rng.unit().abs() * 5.0 });
            let bounds = [lo, hi];
            let c: [f32; 4] = std::array::from_fn(|a| match (case + a) % 9 {
                0 => lo[a],
                1 => hi[a],
                2 => f32::NAN,
                3 => lo[a] - 1.0,
                4 => f32::INFINITY,
                _ => lo[a] + (hi[a] - lo[a]) * rng.unit().abs(),
            });
            let bins = bins_of(&bounds, c);
            for a in 0..4 {
                assert_eq!(bins[a], bin_of(&bounds, c[a], a), "case {case} axis {a}");
                for bin in 1..DUAL_BINS {
                    assert_eq!(left_of(&bounds, c[a], a, bin), bins[a] < bin, "case {case} axis {a} bin {bin}");
                }
            }
        }
    }

    /// Depth of every node of a preorder [`Tree`] (children lists index the nodes).
    fn depths(tree: &Tree) -> Vec<u32> {
        let mut depth = vec![0u32; tree.nodes.len()];
        for i in 0..tree.nodes.len() {
            for &c in &tree.children[i] {
                depth[c as usize] = depth[i] + 1;
            }
        }
        depth
    }

    /// The dual-space build is a partition into leaves of at most `leaf_size`, and stays shallow
    /// on inputs that defeat the heuristic: values spread geometrically (each split can peel off
    /// one candidate), exact duplicates, zero and NaN normals.
    #[test]
    fn dual_tree_partitions_with_bounded_depth() {
        let n = 3000usize;
        let mut normals = Vec::new();
        let mut points = Vec::new();
        for i in 0..n {
            let x = 2f32.powi(-((i % 120) as i32));
            let (n1, n2) = match i % 7 {
                0 => (Vec3::ZERO, Vec3::Z),
                1 => (Vec3::new(f32::NAN, 0.0, 1.0), Vec3::Z),
                2 => (Vec3::Z, Vec3::Z),
                _ => (Vec3::new(x, 0.0, 1.0).normalize(), Vec3::new(0.0, x, 1.0).normalize()),
            };
            normals.push([n1, n2]);
            points.push(if i % 5 == 0 { Vec3::ONE } else { Vec3::new(x, x * x, 1.0 - x) });
        }
        let unit: Vec<[DVec3; 2]> = normals
            .iter()
            .map(|&[a, b]| [a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero()])
            .collect();
        for (leaf, level) in [(1u32, Some(1u8)), (4, Some(3)), (16, Some(2))] {
            let (tree, starts) = build_tree(&points, &unit, leaf, level, None, None).unwrap();
            // Replaying the recorded splits gives the same tree, node for node.
            let (again, starts_again) =
                build_tree(&points, &unit, leaf, level, Some((&tree.splits, &starts)), None).unwrap();
            assert_eq!((&again.nodes, &again.order, &again.splits), (&tree.nodes, &tree.order, &tree.splits));
            assert_eq!(starts_again, starts);
            // A script cut short, or with a split that empties a side, is refused.
            if let Some((_, short)) = tree.splits.split_last() {
                assert!(build_tree(&points, &unit, leaf, level, Some((short, &starts)), None).is_err());
            }
            let mut seen = tree.order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>(), "not a permutation");
            let bound = DUAL_SAH_DEPTH + 2 * (n as f64).log2().ceil() as u32 + 8;
            assert!(depths(&tree).into_iter().max().unwrap_or(0) <= bound);
            for &[start, end, _, is_leaf] in &tree.nodes {
                if is_leaf == 1 {
                    assert!(end - start <= leaf, "a leaf of {} candidates, leaf size {leaf}", end - start);
                }
            }
        }
    }

    /// Faces on two parallel planes 0.01 apart, interleaved over a 10 × 10 square: close in space
    /// but far apart as planes. Every dual-space leaf holds faces of one plane only.
    #[test]
    fn dual_tree_separates_parallel_planes() {
        let mut normals = Vec::new();
        let mut points = Vec::new();
        for i in 0..1024u32 {
            let (x, y) = ((i % 32) as f32 * 0.3, (i / 32) as f32 * 0.3);
            normals.push([Vec3::Z, Vec3::Z]);
            points.push(Vec3::new(x, y, if i % 2 == 0 { 0.0 } else { 0.01 }));
        }
        let unit: Vec<[DVec3; 2]> = normals.iter().map(|&[a, b]| [a.as_dvec3(), b.as_dvec3()]).collect();
        let (tree, _) = build_tree(&points, &unit, 8, Some(1), None, None).unwrap();
        for &[start, end, _, is_leaf] in &tree.nodes {
            if is_leaf == 1 {
                let leaf = &tree.order[start as usize..end as usize];
                assert!(leaf.iter().all(|&i| i % 2 == leaf[0] % 2), "a leaf mixes the two planes");
            }
        }
    }

    #[test]
    fn eyes_are_outside_the_box() {
        let pts = [Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)];
        for e in sample_eyes(&pts, 50) {
            assert!(!(e.cmpge(Vec3::ZERO).all() && e.cmple(Vec3::new(1.0, 2.0, 3.0)).all()));
        }
    }
}
