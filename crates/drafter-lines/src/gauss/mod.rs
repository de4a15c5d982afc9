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

mod arc_cells;
mod arrays;
mod assign;
mod build;
mod cap;
mod cells;
mod quad;
mod query;

pub use drafter_core::hierarchy::GaussMapArrays;
use glam::{Vec3, Vec4};
use serde::{Deserialize, Serialize};

use crate::brute::OrthoBlocks;
use crate::tree::{Purpose, QueryTree, depths, tree_accessors};

pub(crate) use arc_cells::ArcCells;
pub(crate) use cells::{arc_paths, base_cells};

/// Margin added to the sine of every cap radius (see the module docs).
pub const CULL_MARGIN: f64 = 1e-5;

/// Default bin size of [`Bins::Overlapping`], in cell circumradii.
pub const DEFAULT_OVERLAP: f32 = 1.5;

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

/// See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussMapHierarchy {
    rule: Rule,
    /// What a query reads: the nodes, each with its cap (padded with 4 culled entries), and the
    /// serialised form, `[first_child, child_count, arc_start, arc_end]` per node.
    tree: QueryTree<GaussNode>,
    /// The arcs in storage order, in blocks of 4.
    blocks: OrthoBlocks,
    /// Whether `order` is the identity, so that storage positions are candidate indices and hits
    /// go straight into the answer (see [`GaussMapHierarchy::into_storage_order`]).
    identity: bool,
    caps: Vec<[f32; 4]>,
    assigned: Option<LevelHistogram>,
    predicted_ns: f64,
}

/// Where the bin rule sends arcs: the level-0 cells, the bin shape and the deepest level built.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Rule {
    base: BaseSolid,
    bins: Bins,
    max_depth: u8,
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

impl GaussMapHierarchy {
    /// The hierarchy of the breadth-first tree `flat` with caps `caps` over the candidates in
    /// storage order `order` (with `normals`): the query records and, for a [`Purpose::Query`],
    /// the arc blocks. Neither assigned histogram nor predicted cost.
    fn assemble(
        rule: Rule,
        flat: Vec<[u32; 4]>,
        caps: Vec<[f32; 4]>,
        order: Vec<u32>,
        normals: &[[Vec3; 2]],
        purpose: Purpose,
    ) -> Self {
        let nodes: Vec<GaussNode> = flat
            .iter()
            .zip(&caps)
            .map(|(&[first_child, child_count, start, end], &cap)| GaussNode {
                cap: Vec4::from(cap),
                first_child,
                child_count,
                block_start: start / 4,
                block_end: if end > start { end.div_ceil(4) } else { start / 4 },
            })
            .collect();
        // Padding: threshold -1 is culled by any finite direction (and masked off anyway).
        let pad = GaussNode {
            cap: Vec4::new(0.0, 0.0, 0.0, -1.0),
            first_child: 0,
            child_count: 0,
            block_start: 0,
            block_end: 0,
        };
        let blocks = match purpose {
            Purpose::Query => OrthoBlocks::new(&order, normals),
            Purpose::Storage => OrthoBlocks::default(),
        };
        GaussMapHierarchy {
            rule,
            identity: is_identity(&order),
            tree: QueryTree::new(flat, order, nodes, pad),
            blocks,
            caps,
            assigned: None,
            predicted_ns: 0.0,
        }
    }

    /// The bins the hierarchy was built with.
    pub fn bins(&self) -> Bins {
        self.rule.bins
    }

    tree_accessors!();

    pub fn base(&self) -> BaseSolid {
        self.rule.base
    }

    /// The deepest level that was built (before pruning).
    pub fn max_depth(&self) -> u8 {
        self.rule.max_depth
    }

    /// Arcs and nodes per level as stored (after pruning).
    pub fn histogram(&self) -> LevelHistogram {
        let depth = depths(&self.tree.flat);
        LevelHistogram::from_nodes(self.tree.flat.iter().zip(depth).map(|(n, d)| (d, (n[3] - n[2]) as usize)))
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

    /// The candidate index of each storage position.
    pub fn order(&self) -> &[u32] {
        &self.tree.order
    }

    /// The same hierarchy with candidates renumbered in its storage order, and the permutation:
    /// candidate `k` of the result is candidate `permutation[k]` of the input. Reorder the
    /// candidates with it (as [`crate::SilhouetteIndex`] does) and queries write their hits
    /// straight into the answer instead of mapping each through `order`.
    pub fn into_storage_order(mut self) -> (Self, Vec<u32>) {
        let identity = (0..self.tree.order.len() as u32).collect();
        let permutation = std::mem::replace(&mut self.tree.order, identity);
        self.identity = true;
        (self, permutation)
    }
}

fn is_identity(order: &[u32]) -> bool {
    order.iter().enumerate().all(|(k, &i)| i as usize == k)
}

/// `count` random arcs: a random first normal and a second one `spreads[k % spreads.len()]` away
/// (normalised; zero where the two cancel).
#[cfg(test)]
fn random_arcs(rng: &mut drafter_core::rng::Rng, count: usize, spreads: &[f32]) -> Vec<[Vec3; 2]> {
    (0..count)
        .map(|k| {
            let a = rng.direction_f32();
            let spread = spreads[k % spreads.len()];
            [a, (a + rng.direction_f32() * spread).normalize_or_zero()]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_grows_with_count() {
        assert_eq!(depth_for_count(0, BaseSolid::Icosahedron), 0);
        assert!(depth_for_count(150_000, BaseSolid::Icosahedron) >= 5);
        assert_eq!(depth_for_count(usize::MAX / 2, BaseSolid::Icosahedron), 10);
    }
}
