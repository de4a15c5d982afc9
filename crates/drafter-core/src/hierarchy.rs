//! The silhouette hierarchies as a file stores them: flat arrays, one glTF accessor each.
//!
//! drafter-lines builds the hierarchies and rebuilds them from these arrays
//! (`GaussMapHierarchy::from_arrays`, `ConeBvh::from_arrays`); drafter-format writes and reads
//! them. Both depend on this crate, so the stored form is declared once, here, and passes between
//! them without a conversion.

use serde::{Deserialize, Serialize};

/// The flat arrays of a Gauss-map arc hierarchy (Gooch et al. 1999; drafter-lines'
/// `GaussMapHierarchy`), ready for glTF buffer views.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GaussMapArrays {
    /// 0 octahedron, 1 icosahedron.
    pub base: u32,
    /// Deepest level that was built.
    pub max_depth: u32,
    /// 4 `f32` per node: cap centre x, y, z and the cull threshold `sin r + ε` (≥ 1: never culled).
    pub node_caps: Vec<f32>,
    /// The overlapping-bin factor (drafter-lines' `Bins::Overlapping`); 0 for strict bins.
    pub overlap: f32,
    /// 4 `u32` per node, nodes breadth-first from the root (the whole sphere; depth 1 = level 0):
    /// first child, child count, first own arc and end of own arcs, positions in the storage
    /// order; own arcs of the nodes follow one another in node order.
    ///
    /// The storage order itself is not stored: which cell holds an arc is a function of its two
    /// normals (the bin rule), so a reader assigns the arcs again with the builder's arithmetic
    /// and checks the result against these nodes.
    pub nodes: Vec<u32>,
}

/// The flat arrays of a normal-cone BVH (drafter-lines' `ConeBvh`), ready for glTF buffer views.
///
/// The storage order of the candidates is not stored: a reader builds the binary tree again,
/// replaying the recorded split of every inner node (`splits`) with the builder's arithmetic
/// instead of searching for it, which gives the builder's candidate order; `nodes` then refer to
/// ranges of that order.
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
    /// The Gauss-map level of the normal split.
    pub normal_level: u32,
    /// The leaf size the binary tree was cut at.
    pub leaf_size: u32,
    /// One byte per inner node of each dual-space tree, in preorder: `axis · 32 + bin`, the split
    /// between bins `bin − 1` and `bin` of the 32 dual bins on that axis, or the median split
    /// (`u8::MAX`).
    pub splits: Vec<u8>,
    /// Where each dual-space tree's bytes start in `splits`, one per tree in the order the normal
    /// split emits them.
    pub split_starts: Vec<u32>,
}
