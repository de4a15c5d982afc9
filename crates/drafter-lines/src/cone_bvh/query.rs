//! The query: a breadth-first walk that tests up to 4 children's plane-offset bounds in one pass
//! and streams each entered leaf's blocks through the 16-bit pretest.

use glam::{Mat4, Vec3, Vec4};

use super::{BvhNode, ConeBvh, PLANE_MARGIN};
use crate::EdgeSet;
use crate::tree::{QueryCounts, push_children, with_ranges};

/// How many leaves ahead of the one being tested a walk prefetches.
const PREFETCH_AHEAD: usize = 3;

impl ConeBvh {
    /// Silhouettes seen from `eye` into `out` (reset to [`ConeBvh::len`]).
    pub fn query(&self, eye: Vec3, out: &mut EdgeSet) {
        self.walk::<false, true>(eye, out);
    }

    /// [`ConeBvh::query`] that also counts its work.
    pub fn query_counted(&self, eye: Vec3, out: &mut EdgeSet) -> QueryCounts {
        self.walk::<true, true>(eye, out)
    }

    /// Bits of the nodes `first..first + 4` that the plane-offset test culls: [`plane_culls`](super::bounds::plane_culls) on 4
    /// lanes.
    #[inline(always)]
    fn culls4(&self, first: usize, e: Vec3) -> u32 {
        let Some(four) = self.tree.nodes.get(first..first + 4) else { return 0 };
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
    pub(super) fn walk<const COUNT: bool, const TEST: bool>(&self, eye: Vec3, out: &mut EdgeSet) -> QueryCounts {
        if TEST {
            out.reset(self.len());
        }
        let mut counts = QueryCounts { bounds_tested: usize::from(COUNT), ..Default::default() };
        if self.tree.flat.is_empty() || self.culls4(0, eye) & 1 == 1 {
            return counts;
        }
        let words = out.words_mut();
        with_ranges(|pending| {
            self.tree.walk_levels(|level, next, next_width| {
                for &i in level {
                    let n = &self.tree.nodes[i as usize];
                    let (first, end) = (n.first_child as usize, (n.first_child + n.child_count) as usize);
                    push_children(next, next_width, first, end, |f| !self.culls4(f, eye));
                    if COUNT {
                        counts.enter(end - first);
                    }
                }
                for (j, &i) in level.iter().enumerate() {
                    // Start loading a later leaf while this one is tested (see `brute::prefetch`).
                    if TEST && let Some(&ahead) = level.get(j + PREFETCH_AHEAD) {
                        let a = &self.tree.nodes[ahead as usize];
                        self.stream.prefetch(a.quad as usize, a.blocks);
                    }
                    let n = &self.tree.nodes[i as usize];
                    if n.blocks > 0 {
                        if TEST {
                            let frame = (n.anchor_sin.truncate(), n.offsets.w);
                            self.stream.perspective_leaf(n.quad as usize, n.blocks, frame, eye, words, pending);
                        }
                        if COUNT {
                            counts.range(self.tree.flat[i as usize], n.blocks as usize);
                        }
                    }
                }
            });
            if TEST {
                self.stream.perspective_pending(pending, eye, words);
            }
        });
        counts
    }
}

#[cfg(test)]
mod tests {
    use super::super::ConeBvhOptions;
    use super::*;
    use crate::CostModel;

    /// The predicted cost walks without testing candidates: its counts must be a query's.
    #[test]
    fn counting_walk_counts_what_a_query_does() {
        let mut rng = drafter_core::rng::Rng::new(4);
        let points: Vec<Vec3> = (0..20_000).map(|_| rng.direction_f32() * 3.0).collect();
        let normals: Vec<[Vec3; 2]> = points
            .iter()
            .map(|&p| {
                let n = p.normalize();
                [(n + rng.direction_f32() * 0.2).normalize(), (n + rng.direction_f32() * 0.2).normalize()]
            })
            .collect();
        let bvh = ConeBvh::build(&normals, &points, &ConeBvhOptions::default(), &CostModel::default());
        let mut out = EdgeSet::default();
        let mut entered = 0;
        for k in 0..500 {
            let eye = rng.direction_f32() * if k % 2 == 0 { 10.0 } else { 1.5 };
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
        let mut rng = drafter_core::rng::Rng::new(7);
        let points: Vec<Vec3> = (0..20_000).map(|_| rng.direction_f32() * 3.0 + Vec3::new(1e4, 0.0, 0.0)).collect();
        let normals: Vec<[Vec3; 2]> = points
            .iter()
            .map(|&p| {
                let n = (p - Vec3::new(1e4, 0.0, 0.0)).normalize();
                [(n + rng.direction_f32() * 0.05).normalize(), (n + rng.direction_f32() * 0.05).normalize()]
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
            let eye = Vec3::new(1e4, 0.0, 0.0) + rng.direction_f32() * distance;
            bvh.query(eye, &mut got);
            brute.query(crate::View::Perspective { eye }, &mut expected);
            assert_eq!(got.to_vec(), expected.to_vec(), "eye {eye}");
            silhouettes += expected.to_vec().len();
        }
        assert!(silhouettes > 100_000, "{silhouettes} silhouettes");
    }
}
