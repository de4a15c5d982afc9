//! Where the bin rule left each arc as far as a Gauss map followed it: the cells the cone BVH's
//! normal split reads instead of assigning every arc again.

use glam::DVec3;
use rayon::prelude::*;

use super::assign::{Arc, BuildNode};
use super::cells::{PathDescent, base_cells, cell_of};
use super::{BaseSolid, Bins};

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
    pub(super) fn by_candidate(nodes: &[BuildNode], arcs: &[Arc]) -> Vec<(u32, u8, bool)> {
        use std::sync::atomic::{AtomicU64, Ordering};
        // On the thread pool, node by node: every arc is in one node's own range, so each slot is
        // written once (a relaxed atomic store is a plain store). The scatter by candidate misses
        // the cache for nearly every arc, so the misses are spread over the pool's cores.
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
    pub(super) fn new(base: BaseSolid, bins: Bins, by_id: &[(u32, u8, bool)], order: &[u32]) -> Self {
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

#[cfg(test)]
mod tests {
    use super::super::cells::arc_paths;
    use super::super::{DEFAULT_OVERLAP, GaussMapHierarchy, GaussMapOptions, random_arcs};
    use super::*;
    use crate::CostModel;
    use crate::tree::Purpose;

    #[test]
    fn a_gauss_maps_arc_cells_give_the_bvh_paths() {
        let mut rng = drafter_core::rng::Rng::new(3);
        let normals = random_arcs(&mut rng, 30_000, &[1e-4, 1e-2, 0.1, 0.5]);
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
            assert_eq!(loaded.tree.order, built.tree.order);
            let assigned = built.assigned_histogram().unwrap();
            let assigned_nodes = assigned.root.nodes + assigned.levels.iter().map(|l| l.nodes).sum::<usize>();
            assert!(max_depth < 8 || built.node_count() < assigned_nodes, "some subtree is collapsed");
            let unit: Vec<[DVec3; 2]> = built
                .tree
                .order
                .iter()
                .map(|&i| normals[i as usize].map(|n| n.as_dvec3().normalize_or_zero()))
                .collect();
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
            built.tree.order.iter().map(|&i| normals[i as usize].map(|n| n.as_dvec3().normalize_or_zero())).collect();
        assert!(cells.paths(&unit, 3, factor).is_none());
    }
}
