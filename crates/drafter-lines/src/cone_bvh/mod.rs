//! A normal-cone BVH for perspective silhouettes.
//!
//! Gooch et al. (1999, §5.1.4) leave perspective open: "some form of bounding volume hierarchy would
//! have to be employed". This is a spatialised normal-cone hierarchy (Johnson & Cohen 2001,
//! "Spatialized normal cone hierarchies", I3D; anchored cones as in Sander et al. 2000,
//! "Silhouette clipping", SIGGRAPH), culled by a plane-offset test:
//!
//! * candidates are first split by normal, following the Gauss-map cells of the orthographic
//!   hierarchy (`gauss/cells.rs`): an arc goes down the icosahedral cells containing its midpoint for as
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
//!   minimises `Σ count · width` over the two sides (see [`dual_node`](dual::dual_node)). Any subtree of at most
//!   [`ConeBvhOptions::leaf_size`] candidates becomes a leaf. Written here because [`obvhs`]
//!   builds in 3D only; against obvhs' BVH2 (PLOC) over the points stretched 8× along the
//!   cell's mean normal, what this crate used before, a perspective view tests fewer candidates
//!   on every mesh measured, with the largest saving on CAD models (coplanar CAD faces coincide
//!   in the dual space), each with the default pruning;
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
//! for the box's angular size. On the dragon the corner test culled almost nothing beyond what
//! the plane test culls, at 8 square roots per node, so the query uses the plane test alone
//! (`box_culls` stays as a tested reference).
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
//! bottom-up pass with the [`CostModel`](crate::CostModel) collapses subtrees that are cheaper as one leaf. The
//! final tree is priced by counting the work of the same sampled queries.

mod arrays;
mod bounds;
mod build;
mod dual;
mod normal_split;
mod query;
mod spatial;

pub use drafter_core::hierarchy::ConeBvhArrays;
use glam::{Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::brute::{Stream, keeps_pretest};
use crate::tree::{QueryTree, tree_accessors};
use bounds::{PlaneBound, anchor};

/// Margin added to the sine of every cone's half-angle.
pub const CONE_MARGIN: f64 = 1e-5;

/// Default largest leaf, in candidates, before the cost-model pruning. The pruning keeps leaves
/// larger than this on average on a large mesh, so a build that starts from smaller leaves makes
/// levels it only collapses: starting from 16 instead built many more nodes, in more time, while
/// the query cost changed little (`silhouette_bench --leaf` prints both).
pub const DEFAULT_LEAF_SIZE: u32 = 64;

/// Default number of eyes sampled to estimate visit frequencies.
pub const DEFAULT_SAMPLE_EYES: u32 = 96;

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

/// The split byte of an inner node split at the median of its widest axis of centres.
pub const MEDIAN_SPLIT: u8 = u8::MAX;

/// See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct ConeBvh {
    /// What a query reads about nodes, bounds included (padded with 4 entries so that up to 4
    /// children are tested in one SIMD pass), and the query layout: `[first_child, child_count,
    /// arc_start, arc_end]` per node, own candidates in `order`.
    tree: QueryTree<BvhNode>,
    /// The leaves' candidates in blocks, leaf after leaf.
    stream: Stream,
    stored: Stored,
    predicted_ns: f64,
}

/// What a file stores of a [`ConeBvh`] (see [`ConeBvhArrays`]).
#[derive(Clone, Debug, PartialEq)]
struct Stored {
    /// The stored layout: first child, child count and the subtree's range of the preorder
    /// candidate order (see [`ConeBvhArrays::nodes`]).
    nodes: Vec<[u32; 4]>,
    boxes: Vec<[f32; 6]>,
    cones: Vec<[f32; 4]>,
    leaf_size: u32,
    normal_level: Option<u8>,
    splits: Vec<u8>,
    split_starts: Vec<u32>,
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

/// Relative margin of the plane-offset test (see the module docs).
pub const PLANE_MARGIN: f32 = 1e-5;

/// Weight of the normal against the plane offset in the dual space of `dual_node`, in
/// half-diagonals of the bounding box. Over a box of dual points, `n̂·(e − v)` for an eye at
/// distance `D` from the centre in direction `u` varies by `D·Σ|u_i|·Δn_i + Δh`, and `|u_i|`
/// averages ½: so the normal's extents count about `D/2`, and the sampled eyes lie 1.2 to 4
/// half-diagonals away (half and twice this weight tested about as many candidates per view on
/// the dragon).
pub const DUAL_NORMAL_WEIGHT: f32 = 1.25;

impl ConeBvh {
    /// The hierarchy of the breadth-first query layout `flat` over `order`, with the stored form
    /// `stored` and each node's plane bound `planes`: the query records and, with the candidates'
    /// normals and points (a [`Purpose::Query`](crate::tree::Purpose::Query) build), the candidates' blocks. No predicted cost.
    fn assemble(
        flat: Vec<[u32; 4]>,
        order: Vec<u32>,
        stored: Stored,
        planes: &[PlaneBound],
        candidates: Option<(&[[Vec3; 2]], &[Vec3])>,
    ) -> Self {
        let (boxes, cones) = (&stored.boxes, &stored.cones);
        let ranges: Vec<(usize, usize)> =
            flat.iter().map(|&[_, _, start, end]| (start as usize, end as usize)).collect();
        let (stream, at, reaches) = match candidates {
            Some((normals, points)) => {
                let anchors: Vec<Vec3> = boxes.iter().map(anchor).collect();
                Stream::from_ranges(&ranges, &anchors, &order, (normals, points), keeps_pretest(order.len()))
            }
            None => (Stream::new(), Stream::layout(&ranges), vec![0.0; ranges.len()]),
        };
        let nodes: Vec<BvhNode> = flat
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
        ConeBvh { tree: QueryTree::new(flat, order, nodes, pad), stream, stored, predicted_ns: 0.0 }
    }

    tree_accessors!();

    pub fn leaf_count(&self) -> usize {
        self.tree.flat.iter().filter(|n| n[1] == 0).count()
    }

    /// The leaf size the tree was cut at before pruning.
    pub fn leaf_size(&self) -> u32 {
        self.stored.leaf_size
    }

    /// The Gauss-map level of the normal split, `None` if the BVH is purely spatial (or loaded).
    pub fn normal_level(&self) -> Option<u8> {
        self.stored.normal_level
    }

    /// Expected time of one query from eyes outside the box, under the cost model used to build it
    /// (0 when loaded from arrays or built without sample eyes).
    pub fn predicted_ns_per_query(&self) -> f64 {
        self.predicted_ns
    }
}
