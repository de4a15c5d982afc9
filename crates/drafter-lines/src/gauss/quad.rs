//! The child choice of a 4:1 split under overlapping bins: which child's bin takes each arc, four
//! arcs at a time with AVX where the CPU has it, lane for lane the scalar rule's operations.

use glam::DVec3;

use super::assign::{Arc, BinCell, STAY};
use crate::sphere::min;

/// The four children of a cell ([`Cell::children`]: three corners, then the middle one) for
/// [`Quad::most_inside`]. Each corner shares one edge with the middle cell, and its edge plane
/// is the middle's plane negated, bit for bit (a cross product with its factors swapped, then
/// normalised), so the four scores need 9 dot products instead of 12.
pub(super) struct Quad {
    /// Each corner's two planes not shared with the middle cell.
    outer: [[DVec3; 2]; 3],
    middle: [DVec3; 3],
}

impl Quad {
    pub(super) fn of(children: &[BinCell]) -> Quad {
        let [c0, c1, c2, c3] = [0, 1, 2, 3].map(|k| children[k].cell.planes);
        debug_assert!(c0[1] == -c3[2] && c1[2] == -c3[0] && c2[0] == -c3[1]);
        Quad { outer: [[c0[0], c0[2]], [c1[0], c1[1]], [c2[1], c2[2]]], middle: c3 }
    }

    /// What `Cell::score` and the first-of-equals maximum give over the four children.
    #[inline(always)]
    pub(super) fn most_inside(&self, p: DVec3) -> usize {
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
    pub(super) fn targets(&self, bins: &[BinCell], arcs: &[Arc], out: &mut [u8]) {
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

#[cfg(test)]
mod tests {
    use super::super::BaseSolid;
    use super::super::cells::{arc_mid, awkward_points, base_cells, bin_cos, fits_bin, most_inside_reference};
    use super::*;

    /// The nine-product scoring of four children picks the child `Cell::score` and the
    /// first-of-equals maximum pick, on points inside, on the edges and at the corners of cells
    /// down to level 8, and on points far outside.
    #[test]
    fn quad_scores_pick_the_cell_scores_pick() {
        let mut rng = drafter_core::rng::Rng::new(11);
        let mut cell = base_cells(BaseSolid::Icosahedron)[3];
        for level in 0..9 {
            let children = cell.children();
            let bins: Vec<BinCell> = children.iter().map(|&cell| BinCell { cell, cos_bin: 0.0 }).collect();
            let quad = Quad::of(&bins);
            let [a, b, c] = cell.v;
            let mut points = vec![a, b, c, (a + b).normalize(), (b + c).normalize(), (c + a).normalize()];
            for _ in 0..3000 {
                let w = [rng.unit_f32().abs(), rng.unit_f32().abs(), rng.unit_f32().abs()];
                // Inside, and pulled onto an edge by zeroing one weight.
                let k = points.len() % 4;
                let w = if k < 3 { std::array::from_fn(|i| if i == k { 0.0 } else { w[i] }) } else { w };
                points.push((a * f64::from(w[0]) + b * f64::from(w[1]) + c * f64::from(w[2])).normalize_or_zero());
                points.push(rng.direction_f32().as_dvec3().normalize());
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
    #[test]
    fn quad_targets_are_the_bin_rule() {
        let mut rng = drafter_core::rng::Rng::new(13);
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
                    let w = [rng.unit_f32().abs(), rng.unit_f32().abs(), rng.unit_f32().abs()].map(f64::from);
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
}
