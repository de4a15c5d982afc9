//! Exact orientation predicate for the convex hull.
//!
//! `orient3d(a, b, c, p)` is the sign of `(p − a) · ((b − a) × (c − a))`: positive when `p` lies on the side
//! that the counter-clockwise triangle `a, b, c` faces. It is evaluated first in floating point with
//! Shewchuk's forward error bound (Shewchuk 1997, "Adaptive Precision Floating-Point Arithmetic and Fast
//! Robust Geometric Predicates", bound `o3derrboundA`); only when the float result is too close to zero to
//! trust is the determinant recomputed exactly with floating-point expansions (same paper, §2). The exact
//! path is slow (allocating) and rare: it runs for points on or within rounding error of a plane.
//!
//! With an exact sign, the beneath-beyond step of the hull never sees contradictory visibility, so the
//! hull's topology stays a closed 2-manifold on any input, including exactly coplanar tessellations.

/// Sign of `(p − a) · ((b − a) × (c − a))`: `1`, `-1` or `0` (exact).
pub(crate) fn orient3d(a: [f64; 3], b: [f64; 3], c: [f64; 3], p: [f64; 3]) -> i8 {
    let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let w = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    // det of rows u, v, w = w · (u × v)
    let uv_yz = u[1] * v[2] - u[2] * v[1];
    let uv_zx = u[2] * v[0] - u[0] * v[2];
    let uv_xy = u[0] * v[1] - u[1] * v[0];
    let det = w[0] * uv_yz + w[1] * uv_zx + w[2] * uv_xy;
    let permanent = w[0].abs() * ((u[1] * v[2]).abs() + (u[2] * v[1]).abs())
        + w[1].abs() * ((u[2] * v[0]).abs() + (u[0] * v[2]).abs())
        + w[2].abs() * ((u[0] * v[1]).abs() + (u[1] * v[0]).abs());
    // Shewchuk's o3derrboundA = (7 + 56ε)ε with ε = 2^-53; a little wider here.
    let bound = 4.0 * f64::EPSILON * permanent;
    if det > bound {
        1
    } else if det < -bound {
        -1
    } else {
        orient3d_exact(a, b, c, p)
    }
}

fn orient3d_exact(a: [f64; 3], b: [f64; 3], c: [f64; 3], p: [f64; 3]) -> i8 {
    let d = |x: f64, y: f64| -> Vec<f64> {
        let (hi, lo) = two_diff(x, y);
        let mut e = Vec::with_capacity(2);
        if lo != 0.0 {
            e.push(lo);
        }
        if hi != 0.0 || e.is_empty() {
            e.push(hi);
        }
        e
    };
    let u = [d(b[0], a[0]), d(b[1], a[1]), d(b[2], a[2])];
    let v = [d(c[0], a[0]), d(c[1], a[1]), d(c[2], a[2])];
    let w = [d(p[0], a[0]), d(p[1], a[1]), d(p[2], a[2])];
    let minor = |i: usize, j: usize| -> Vec<f64> {
        // u_i v_j − u_j v_i
        let left = expansion_product(&u[i], &v[j]);
        let right = expansion_product(&u[j], &v[i]);
        expansion_sum(&left, &negate(&right))
    };
    let t0 = expansion_product(&w[0], &minor(1, 2));
    let t1 = expansion_product(&w[1], &minor(2, 0));
    let t2 = expansion_product(&w[2], &minor(0, 1));
    let det = expansion_sum(&expansion_sum(&t0, &t1), &t2);
    // The most significant component (the last non-zero one) carries the sign.
    match det.iter().rev().find(|x| **x != 0.0) {
        Some(x) if *x > 0.0 => 1,
        Some(_) => -1,
        None => 0,
    }
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    let br = b - bv;
    let ar = a - av;
    (x, ar + br)
}

#[inline]
fn two_diff(a: f64, b: f64) -> (f64, f64) {
    let x = a - b;
    let bv = a - x;
    let av = x + bv;
    let br = bv - b;
    let ar = a - av;
    (x, ar + br)
}

#[inline]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

fn negate(e: &[f64]) -> Vec<f64> {
    e.iter().map(|x| -x).collect()
}

/// Adds the scalar `b` to the non-overlapping expansion `e` (Shewchuk's Grow-Expansion, zero-eliminating).
fn grow_expansion(e: &[f64], b: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(e.len() + 1);
    let mut q = b;
    for &ei in e {
        let (sum, err) = two_sum(q, ei);
        if err != 0.0 {
            out.push(err);
        }
        q = sum;
    }
    if q != 0.0 || out.is_empty() {
        out.push(q);
    }
    out
}

fn expansion_sum(e: &[f64], f: &[f64]) -> Vec<f64> {
    let mut out = e.to_vec();
    for &fi in f {
        out = grow_expansion(&out, fi);
    }
    out
}

/// Multiplies the expansion `e` by the scalar `b` (Shewchuk's Scale-Expansion, zero-eliminating).
fn scale_expansion(e: &[f64], b: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(2 * e.len());
    let Some((&first, rest)) = e.split_first() else {
        return vec![0.0];
    };
    let (mut q, err) = two_product(first, b);
    if err != 0.0 {
        out.push(err);
    }
    for &ei in rest {
        let (hi, lo) = two_product(ei, b);
        let (sum, err) = two_sum(q, lo);
        if err != 0.0 {
            out.push(err);
        }
        let (sum2, err2) = two_sum(hi, sum);
        if err2 != 0.0 {
            out.push(err2);
        }
        q = sum2;
    }
    if q != 0.0 || out.is_empty() {
        out.push(q);
    }
    out
}

fn expansion_product(e: &[f64], f: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0];
    for &fi in f {
        out = expansion_sum(&out, &scale_expansion(e, fi));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn signs_of_simple_configurations() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.0, 0.0];
        let c = [0.0, 1.0, 0.0];
        assert_eq!(orient3d(a, b, c, [0.2, 0.3, 1.0]), 1);
        assert_eq!(orient3d(a, b, c, [0.2, 0.3, -1.0]), -1);
        assert_eq!(orient3d(a, b, c, [0.2, 0.3, 0.0]), 0);
    }

    #[test]
    fn exact_on_nearly_coplanar_points() {
        // Points on the plane x + y + z = 1 with coordinates that are not exactly representable sums;
        // a one-ulp nudge must flip the sign, and exactly coplanar dyadic points must give zero.
        let a = [0.5, 0.25, 0.25];
        let b = [0.125, 0.625, 0.25];
        let c = [0.25, 0.25, 0.5];
        let on = [0.375, 0.375, 0.25];
        assert_eq!(orient3d(a, b, c, on), 0);
        let up = [0.375, 0.375, f64::from_bits(0.25f64.to_bits() + 1)];
        let down = [0.375, 0.375, f64::from_bits(0.25f64.to_bits() - 1)];
        let s_up = orient3d(a, b, c, up);
        let s_down = orient3d(a, b, c, down);
        assert_ne!(s_up, 0);
        assert_eq!(s_up, -s_down);
        // Far-away translated copy: the float filter fails, the exact path decides.
        let t = 1.0e6 + 0.1;
        let shift = |p: [f64; 3]| [p[0] + t, p[1] + t, p[2] + t];
        let s = orient3d(shift(a), shift(b), shift(c), shift(on));
        // The shifted coordinates are rounded, so the sign may be anything, but it must match the exact
        // evaluation of the rounded inputs, which is what orient3d_exact computes.
        assert_eq!(s, orient3d_exact(shift(a), shift(b), shift(c), shift(on)));
    }

    #[test]
    fn filter_and_exact_agree_on_random_inputs() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..2000 {
            let a = [next(), next(), next()];
            let b = [next(), next(), next()];
            let c = [next(), next(), next()];
            // p on the plane of a, b, c up to rounding: the filter is unsure, the exact path decides.
            let s = next();
            let t = next();
            let p = [
                a[0] + s * (b[0] - a[0]) + t * (c[0] - a[0]),
                a[1] + s * (b[1] - a[1]) + t * (c[1] - a[1]),
                a[2] + s * (b[2] - a[2]) + t * (c[2] - a[2]),
            ];
            assert_eq!(orient3d(a, b, c, p), orient3d_exact(a, b, c, p));
            let q = [next(), next(), next()];
            assert_eq!(orient3d(a, b, c, q), orient3d_exact(a, b, c, q));
        }
    }
}
