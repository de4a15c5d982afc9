//! The build: every arc assigned to its cell ([`assign`]), then the cost-model pruning bottom-up,
//! the collapsed subtrees' arcs in input order, and the breadth-first layout.

use glam::Vec3;
use rayon::prelude::*;

use super::assign::{BuildNode, StopRule, assign};
use super::{ArcCells, GaussMapHierarchy, GaussMapOptions, LevelHistogram, Rule, depth_for_count};
use crate::CostModel;
use crate::tree::{Purpose, breadth_first};

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
        let rule = Rule { base: options.base, bins: options.bins, max_depth };
        let costs = StopRule::of(cost);
        let stop = (options.prune && early_stop).then_some(costs);
        let Some((nodes, arcs)) = assign(normals, rule, None, stop) else {
            unreachable!("an unguided assignment always succeeds")
        };
        let mut order: Vec<u32> = arcs.par_iter().map(|a| a.id).collect();
        // Caps over each subtree's endpoints, computed by the build.
        let caps: Vec<[f32; 4]> = nodes.iter().map(|n| n.cap).collect();
        let by_id = ArcCells::by_candidate(&nodes, &arcs);
        drop(arcs);
        let assigned =
            LevelHistogram::from_nodes(nodes.iter().map(|n| (u32::from(n.depth), (n.own.1 - n.own.0) as usize)));
        let collapse = collapse_by_cost(&nodes, &caps, costs, options.prune);

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
        let cells = ArcCells::new(options.base, options.bins, &by_id, &bfs_order);
        let mut h = Self::assemble(rule, flat, flat_caps, bfs_order, normals, purpose);
        h.assigned = Some(assigned);
        h.predicted_ns = h.estimate_ns(cost);
        (h, cells)
    }
}

/// Which nodes the pruning collapses (with `prune`; none without): bottom-up, a subtree whose
/// expected cost is lower as one node, each node entered with the probability of
/// [`visit_probabilities`] and priced with `costs`.
fn collapse_by_cost(nodes: &[BuildNode], caps: &[[f32; 4]], costs: StopRule, prune: bool) -> Vec<bool> {
    // Expected cost, bottom-up: collapse a subtree when one node is cheaper.
    let prob = visit_probabilities(nodes, caps);
    let StopRule { enter, test, range, block } = costs;
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
        if prune && !n.children.is_empty() && collapsed <= split {
            collapse[i] = true;
            best[i] = collapsed;
        } else {
            best[i] = split;
        }
    }
    collapse
}

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

/// The probability that a query enters each node: its cap's, at most its parent's.
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
    use super::super::random_arcs;
    use super::*;

    /// Disjoint increasing ranges sort on the pool, anything else one range after another; either
    /// way every range ends sorted and nothing outside the ranges moves.
    #[test]
    fn sort_ranges_sorts_each_range_only() {
        let mut rng = drafter_core::rng::Rng::new(5);
        for case in 0..400 {
            let items: Vec<u32> = (0..200).map(|_| (rng.unit_f32().abs() * 1000.0) as u32).collect();
            let mut cuts: Vec<usize> = (0..8).map(|_| (rng.unit_f32().abs() * 200.0) as usize % 201).collect();
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
    /// The stop rule only skips subtrees the pruning collapses: the stored map (tree, caps, storage
    /// order, predicted cost) is the one built to `max_depth` and pruned, on arcs of every length,
    /// on CAD-like repeated normals and under skewed cost models, while most of the deep nodes are
    /// never made.
    #[test]
    fn early_stop_keeps_the_pruned_tree() {
        let mut rng = drafter_core::rng::Rng::new(19);
        let mixed = random_arcs(&mut rng, 40_000, &[0.0, 1e-5, 1e-3, 1e-2, 0.1, 0.7]);
        // A machined part: a few exact directions, arcs between neighbouring ones and fillets.
        let axes = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::NEG_X, Vec3::NEG_Y, Vec3::NEG_Z];
        let cad: Vec<[Vec3; 2]> = (0..20_000)
            .map(|k| {
                let a = axes[k % 6];
                let b = if k % 3 == 0 { axes[(k / 6) % 6] } else { (a + rng.direction_f32() * 0.05).normalize() };
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
                assert_eq!(fast.tree.flat, full.tree.flat, "{name}: tree");
                assert_eq!(fast.caps, full.caps, "{name}: caps");
                assert_eq!(fast.tree.order, full.tree.order, "{name}: storage order");
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
}
