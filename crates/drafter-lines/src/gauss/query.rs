//! The query: a breadth-first walk over the caps that collects the block ranges of the nodes it
//! enters, then tests them as one stream.

use glam::Vec3;
use rayon::prelude::*;

use super::GaussMapHierarchy;
use crate::CostModel;
use crate::EdgeSet;
use crate::brute::unit_direction;
use crate::sphere::fibonacci_direction;
use crate::tree::{QueryCounts, push_children, with_ranges};

impl GaussMapHierarchy {
    /// Mean modelled cost of a query over 64 fixed directions.
    pub(super) fn estimate_ns(&self, cost: &CostModel) -> f64 {
        let dirs: Vec<Vec3> = (0..64).map(|k| fibonacci_direction(k, 64)).collect();
        // On the thread pool, summed in direction order: the same figure at any thread count.
        let costs: Vec<f64> = dirs.par_iter().map(|&d| self.counts_only(d).cost_ns(cost, true)).collect();
        costs.iter().sum::<f64>() / dirs.len() as f64
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
        let Some(four) = self.tree.nodes.get(first..first + 4) else { return 0 };
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
                out.insert(self.tree.order[k] as usize);
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
        if self.tree.flat.is_empty() || self.meets4(0, u) & 1 == 0 {
            return counts;
        }
        with_ranges(|ranges| {
            self.tree.walk_levels(|level, next, next_width| {
                for &i in level {
                    let n = &self.tree.nodes[i as usize];
                    let (first, end) = (n.first_child as usize, (n.first_child + n.child_count) as usize);
                    push_children(next, next_width, first, end, |f| self.meets4(f, u));
                    if n.block_start < n.block_end {
                        ranges.push([n.block_start, n.block_end]);
                    }
                    if COUNT {
                        counts.enter(end - first);
                        if n.block_start < n.block_end {
                            counts.range(self.tree.flat[i as usize], (n.block_end - n.block_start) as usize);
                        }
                    }
                }
            });
            if TEST {
                self.blocks.test_ranges(ranges, u, words, dirty);
            }
        });
        counts
    }
}

#[cfg(test)]
mod tests {
    use super::super::GaussMapOptions;
    use super::*;

    /// The predicted cost walks without testing arcs: its counts must be a query's.
    #[test]
    fn counting_walk_counts_what_a_query_does() {
        let mut rng = drafter_core::rng::Rng::new(8);
        let normals: Vec<[Vec3; 2]> = (0..30_000)
            .map(|_| {
                let a = rng.direction_f32();
                [a, (a + rng.direction_f32() * 0.3).normalize()]
            })
            .collect();
        let h = GaussMapHierarchy::build(&normals, &GaussMapOptions::default(), &CostModel::default());
        let mut out = EdgeSet::default();
        let mut blocks = 0;
        for _ in 0..500 {
            let d = rng.direction_f32();
            let counted = h.counts_only(d);
            assert_eq!(counted, h.query_counted(d, &mut out), "direction {d}");
            blocks += counted.blocks_tested;
        }
        assert_eq!(h.counts_only(Vec3::ZERO), h.query_counted(Vec3::ZERO, &mut out), "no direction");
        assert!(blocks > 500, "the walks read {blocks} blocks");
    }
}
