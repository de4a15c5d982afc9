//! The breadth-first layout shared by both hierarchies, its validation, and the level-by-level
//! walk of a query over it ([`QueryTree`]) with its counts ([`QueryCounts`]).
//!
//! Node `i` is `[first_child, child_count, arc_start, arc_end]`: its children are the nodes
//! `first_child..first_child + child_count` (all after `i`, so children of consecutive nodes are
//! consecutive), and it owns the candidates `order[arc_start..arc_end]`; the own ranges of the
//! nodes follow one another in node order. Node 0 is the root.
//!
//! Why breadth-first: a dependent cache miss costs as much as streaming brute force over tens to
//! hundreds of candidates, the more the larger the working set. A query therefore walks one level
//! at a time: every node of the level is known before any of them is read, so their memory accesses
//! overlap instead of waiting on one another, and the caps of a node's children sit side by side.

use std::cell::RefCell;

use serde::{Deserialize, Serialize};

use crate::{ArraysError, CostModel};

/// What a hierarchy build makes: everything a query reads, or only what a file stores and the
/// cost estimate counts. The query layouts (the Gauss map's arc blocks and their 16-bit copy,
/// the cone BVH's candidate stream) cost a bake peak memory and time, and a bake never queries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Purpose {
    Query,
    Storage,
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

    /// Counts a node entered and the bounds of its `children` tested.
    #[inline(always)]
    pub(crate) fn enter(&mut self, children: usize) {
        self.nodes_entered += 1;
        self.bounds_tested += children;
    }

    /// Counts the own candidates of node `[_, _, start, end]` tested in `blocks` blocks.
    #[inline(always)]
    pub(crate) fn range(&mut self, [_, _, start, end]: [u32; 4], blocks: usize) {
        self.ranges += 1;
        self.blocks_tested += blocks;
        self.arcs_tested += (end - start) as usize;
    }
}

/// What a query of either hierarchy walks: the nodes as it reads them and the layout they come
/// from.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct QueryTree<N> {
    /// The nodes as a query reads them, bounds next to the record, padded with 4 entries so that
    /// the up to 4 children of a node are tested in one SIMD pass.
    pub(crate) nodes: Vec<N>,
    /// The most nodes at one depth (sizes the walk's level buffers).
    pub(crate) widest: usize,
    /// The query layout: `[first_child, child_count, arc_start, arc_end]` per node, own
    /// candidates in `order`.
    pub(crate) flat: Vec<[u32; 4]>,
    /// The candidate index of each storage position.
    pub(crate) order: Vec<u32>,
}

impl<N: Copy> QueryTree<N> {
    /// The tree of the layout `flat` over `order`, whose nodes as a query reads them are `nodes`
    /// (one per entry of `flat`), padded with 4 copies of `pad`.
    pub(crate) fn new(flat: Vec<[u32; 4]>, order: Vec<u32>, mut nodes: Vec<N>, pad: N) -> Self {
        nodes.extend(std::iter::repeat_n(pad, 4));
        QueryTree { nodes, widest: widest_level(&flat), flat, order }
    }

    /// Walks the tree one level at a time from the root: `step` gets the nodes entered at a level
    /// and appends those entered at the next to `next[*width..]` (with [`push_children`]).
    #[inline(always)]
    pub(crate) fn walk_levels(&self, mut step: impl FnMut(&[u32], &mut [u32], &mut usize)) {
        with_levels(self.widest + 4, |level, next| {
            level[0] = 0;
            let mut width = 1;
            while width > 0 {
                let mut next_width = 0;
                step(&level[..width], next, &mut next_width);
                std::mem::swap(level, next);
                width = next_width;
            }
        });
    }
}

/// The accessors of a hierarchy whose `tree` field is a [`QueryTree`].
macro_rules! tree_accessors {
    () => {
        /// Number of candidates.
        pub fn len(&self) -> usize {
            self.tree.order.len()
        }

        /// Whether there are no candidates.
        pub fn is_empty(&self) -> bool {
            self.tree.order.is_empty()
        }

        /// Number of nodes.
        pub fn node_count(&self) -> usize {
            self.tree.flat.len()
        }
    };
}
pub(crate) use tree_accessors;

thread_local! {
    /// The current and next level of a breadth-first walk, reused across queries on a thread.
    static LEVELS: RefCell<(Vec<u32>, Vec<u32>)> = RefCell::new(Default::default());
}

/// Runs `walk` with two level buffers of at least `len` entries each.
pub(crate) fn with_levels<R>(len: usize, walk: impl FnOnce(&mut Vec<u32>, &mut Vec<u32>) -> R) -> R {
    let grow = |v: &mut Vec<u32>| {
        if v.len() < len {
            v.resize(len, 0);
        }
    };
    LEVELS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut pair) => {
            let (a, b) = &mut *pair;
            grow(a);
            grow(b);
            walk(a, b)
        }
        Err(_) => walk(&mut vec![0; len], &mut vec![0; len]),
    })
}

thread_local! {
    /// The block ranges a walk collects before testing them, or the blocks a perspective walk
    /// tests again in `f32` (reused between queries).
    static RANGES: RefCell<Vec<[u32; 2]>> = const { RefCell::new(Vec::new()) };
}

/// Runs `walk` with an empty list for the block ranges `[first, end)` a walk collects, reusing
/// this thread's allocation.
pub(crate) fn with_ranges<R>(walk: impl FnOnce(&mut Vec<[u32; 2]>) -> R) -> R {
    RANGES.with(|cell| match cell.try_borrow_mut() {
        Ok(mut ranges) => {
            ranges.clear();
            walk(&mut ranges)
        }
        Err(_) => walk(&mut Vec::new()),
    })
}

/// Appends to `next[*width..]` those of the children `first..end` whose bit is set in
/// `mask4(f)`, the 4-lane mask of children `f..f + 4` (lanes past `end` are ignored): the step
/// both hierarchy walks take from one level to the next, branch-free per child.
#[inline(always)]
pub(crate) fn push_children(
    next: &mut [u32],
    width: &mut usize,
    first: usize,
    end: usize,
    mut mask4: impl FnMut(usize) -> u32,
) {
    let mut f = first;
    while f < end {
        let mask = mask4(f) & lanes(end - f);
        for lane in 0..4 {
            next[*width] = (f + lane) as u32;
            *width += ((mask >> lane) & 1) as usize;
        }
        f += 4;
    }
}

/// Bits `0..k` set (k ≤ 4).
#[inline(always)]
pub(crate) fn lanes(k: usize) -> u32 {
    if k >= 4 { 0xF } else { (1u32 << k) - 1 }
}

/// The largest number of nodes at one depth.
pub(crate) fn widest_level(nodes: &[[u32; 4]]) -> usize {
    let depth = depths(nodes);
    let mut count = vec![0usize; depth.iter().map(|&d| d as usize + 1).max().unwrap_or(0)];
    for d in depth {
        count[d as usize] += 1;
    }
    count.into_iter().max().unwrap_or(0)
}

/// Builds the breadth-first layout of a tree given as children lists and own candidates; returns
/// the nodes, the new `order`, and for each new node the index of the node it came from.
pub(crate) fn breadth_first<'a>(
    root: usize,
    children: impl Fn(usize) -> &'a [u32],
    own: impl Fn(usize) -> &'a [u32],
) -> (Vec<[u32; 4]>, Vec<u32>, Vec<usize>) {
    let mut source = vec![root];
    let mut nodes = Vec::new();
    let mut order = Vec::new();
    let mut i = 0;
    while i < source.len() {
        let old = source[i];
        let kids = children(old);
        let first = source.len() as u32;
        source.extend(kids.iter().map(|&k| k as usize));
        let start = order.len() as u32;
        order.extend_from_slice(own(old));
        nodes.push([if kids.is_empty() { 0 } else { first }, kids.len() as u32, start, order.len() as u32]);
        i += 1;
    }
    (nodes, order, source)
}

/// Checks the layout over `len` candidates and returns each node's parent (`u32::MAX` for the root).
pub(crate) fn check_breadth_first(nodes: &[[u32; 4]], len: usize) -> Result<Vec<u32>, ArraysError> {
    let n = nodes.len();
    if n == 0 {
        return Err(ArraysError::Length { array: "nodes", expected: 4, found: 0 });
    }
    let mut parent = vec![u32::MAX; n];
    let mut next_child = 1usize;
    let mut next_arc = 0u32;
    for (i, &[first, count, start, end]) in nodes.iter().enumerate() {
        let bad = ArraysError::Tree { node: i };
        if count > 0 {
            if first as usize != next_child || first as usize <= i {
                return Err(bad);
            }
            let stop = next_child.checked_add(count as usize).filter(|&s| s <= n).ok_or(bad.clone())?;
            for p in &mut parent[next_child..stop] {
                *p = i as u32;
            }
            next_child = stop;
        }
        if start != next_arc || end < start || end as usize > len {
            return Err(bad);
        }
        next_arc = end;
        if i > 0 && parent[i] == u32::MAX {
            return Err(bad);
        }
    }
    if next_child != n || next_arc as usize != len {
        return Err(ArraysError::Tree { node: n - 1 });
    }
    Ok(parent)
}

/// Depth of every node (root 0).
pub(crate) fn depths(nodes: &[[u32; 4]]) -> Vec<u32> {
    let mut depth = vec![0u32; nodes.len()];
    for (i, &[first, count, _, _]) in nodes.iter().enumerate() {
        let below = depth[i] + 1;
        for c in first..first + count {
            if let Some(d) = depth.get_mut(c as usize) {
                *d = below;
            }
        }
    }
    depth
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_checks() {
        // 0 -> {1, 2}, 1 -> {3}; own candidates: 0: [5], 1: [], 2: [0, 1], 3: [2, 3, 4].
        let children: Vec<Vec<u32>> = vec![vec![1, 2], vec![3], vec![], vec![]];
        let own: Vec<Vec<u32>> = vec![vec![5], vec![], vec![0, 1], vec![2, 3, 4]];
        let (nodes, order, source) = breadth_first(0, |i| &children[i], |i| &own[i]);
        assert_eq!(source, vec![0, 1, 2, 3]);
        assert_eq!(nodes, vec![[1, 2, 0, 1], [3, 1, 1, 1], [0, 0, 1, 3], [0, 0, 3, 6]]);
        assert_eq!(order, vec![5, 0, 1, 2, 3, 4]);
        let parent = check_breadth_first(&nodes, 6).unwrap();
        assert_eq!(parent, vec![u32::MAX, 0, 0, 1]);
        assert_eq!(depths(&nodes), vec![0, 1, 1, 2]);
        let mut bad = nodes.clone();
        bad[1][0] = 2;
        assert!(check_breadth_first(&bad, 6).is_err());
        let mut bad = nodes.clone();
        bad[2][3] = 2;
        assert!(check_breadth_first(&bad, 6).is_err());
    }
}
