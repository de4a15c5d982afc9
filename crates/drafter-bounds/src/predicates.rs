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
    // Differences as exact two-term expansions (low, high).
    let d = |x: f64, y: f64| -> [f64; 2] {
        let (hi, lo) = two_diff(x, y);
        [lo, hi]
    };
    let u = [d(b[0], a[0]), d(b[1], a[1]), d(b[2], a[2])];
    let v = [d(c[0], a[0]), d(c[1], a[1]), d(c[2], a[2])];
    let w = [d(p[0], a[0]), d(p[1], a[1]), d(p[2], a[2])];
    // minor(i, j) = u_i v_j − u_j v_i (≤ 16 terms), then w_k · minor (≤ 64), summed (≤ 192).
    let minor = |i: usize, j: usize, out: &mut [f64; 16]| -> usize {
        let mut left = [0.0; 8];
        let mut right = [0.0; 8];
        let nl = product(&u[i], &v[j], &mut left);
        let nr = product(&u[j], &v[i], &mut right);
        for x in &mut right[..nr] {
            *x = -*x;
        }
        sum(&left[..nl], &right[..nr], out)
    };
    let term = |k: usize, i: usize, j: usize, out: &mut [f64; 64]| -> usize {
        let mut m = [0.0; 16];
        let nm = minor(i, j, &mut m);
        product(&w[k], &m[..nm], out)
    };
    let (mut t0, mut t1, mut t2) = ([0.0; 64], [0.0; 64], [0.0; 64]);
    let n0 = term(0, 1, 2, &mut t0);
    let n1 = term(1, 2, 0, &mut t1);
    let n2 = term(2, 0, 1, &mut t2);
    let mut s01 = [0.0; 128];
    let n01 = sum(&t0[..n0], &t1[..n1], &mut s01);
    let mut det = [0.0; 192];
    let n = sum(&s01[..n01], &t2[..n2], &mut det);
    // The most significant component (the last non-zero one) carries the sign.
    match det[..n].iter().rev().find(|x| **x != 0.0) {
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
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    (x, b - bv)
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

/// `h = e + f` for non-overlapping expansions sorted by increasing magnitude (Shewchuk's
/// Fast-Expansion-Sum, zero-eliminating). Returns the length of `h` (≥ 1); `h` must hold
/// `e.len() + f.len()` values.
fn sum(e: &[f64], f: &[f64], h: &mut [f64]) -> usize {
    if e.is_empty() || f.is_empty() {
        let src = if e.is_empty() { f } else { e };
        let mut n = 0;
        for &x in src {
            if x != 0.0 {
                h[n] = x;
                n += 1;
            }
        }
        if n == 0 {
            h[0] = 0.0;
            n = 1;
        }
        return n;
    }
    let (mut ei, mut fi) = (0, 0);
    // Take the component of smaller magnitude first.
    let take = |ei: &mut usize, fi: &mut usize| -> f64 {
        if *fi >= f.len() || (*ei < e.len() && (f[*fi] > e[*ei]) == (f[*fi] > -e[*ei])) {
            *ei += 1;
            e[*ei - 1]
        } else {
            *fi += 1;
            f[*fi - 1]
        }
    };
    let mut q = take(&mut ei, &mut fi);
    let mut n = 0;
    let mut first = true;
    while ei < e.len() || fi < f.len() {
        let next = take(&mut ei, &mut fi);
        let (sum, err) = if first { fast_two_sum(next, q) } else { two_sum(q, next) };
        first = false;
        q = sum;
        if err != 0.0 {
            h[n] = err;
            n += 1;
        }
    }
    if q != 0.0 || n == 0 {
        h[n] = q;
        n += 1;
    }
    n
}

/// `h = e · b` (Shewchuk's Scale-Expansion, zero-eliminating); `h` must hold `2·e.len()` values.
fn scale(e: &[f64], b: f64, h: &mut [f64]) -> usize {
    let Some((&first, rest)) = e.split_first() else {
        h[0] = 0.0;
        return 1;
    };
    let mut n = 0;
    let (mut q, err) = two_product(first, b);
    if err != 0.0 {
        h[n] = err;
        n += 1;
    }
    for &ei in rest {
        let (hi, lo) = two_product(ei, b);
        let (s, err) = two_sum(q, lo);
        if err != 0.0 {
            h[n] = err;
            n += 1;
        }
        let (s2, err2) = fast_two_sum(hi, s);
        if err2 != 0.0 {
            h[n] = err2;
            n += 1;
        }
        q = s2;
    }
    if q != 0.0 || n == 0 {
        h[n] = q;
        n += 1;
    }
    n
}

/// `h = e · f` for a short `e` (one scaled copy of `f` per component of `e`, summed); `h` must hold
/// `2·e.len()·f.len()` values (at most 64 here).
fn product(e: &[f64], f: &[f64], h: &mut [f64]) -> usize {
    let mut acc = [0.0; 64];
    let mut acc_len = 0;
    let mut part = [0.0; 64];
    let mut tmp = [0.0; 64];
    for &ei in e {
        let np = scale(f, ei, &mut part);
        let n = sum(&acc[..acc_len], &part[..np], &mut tmp);
        acc[..n].copy_from_slice(&tmp[..n]);
        acc_len = n;
    }
    h[..acc_len].copy_from_slice(&acc[..acc_len]);
    acc_len
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
    fn exact_path_matches_integer_arithmetic() {
        // Integer coordinates near 2^30: differences are exact in f64, products are not, and i128
        // evaluates the determinant exactly. Near-coplanar points make the float filter give up.
        let mut rng = drafter_core::rng::Rng::new(0x2545_f491_4f6c_dd1du64);
        let mut next = |range: i64| -> i64 { rng.below(2 * range as u64 + 1) as i64 - range };
        let big = 1i64 << 30;
        for _ in 0..3000 {
            let a = [next(big), next(big), next(big)];
            let b = [next(big), next(big), next(big)];
            let c = [next(big), next(big), next(big)];
            let (k1, k2, m) = (next(1000), next(1000), 997);
            let p: [i64; 3] = std::array::from_fn(|i| a[i] + ((b[i] - a[i]) * k1 + (c[i] - a[i]) * k2) / m + next(1));
            let d = |x: [i64; 3], y: [i64; 3]| [(x[0] - y[0]) as i128, (x[1] - y[1]) as i128, (x[2] - y[2]) as i128];
            let (u, v, w) = (d(b, a), d(c, a), d(p, a));
            let det = w[0] * (u[1] * v[2] - u[2] * v[1])
                + w[1] * (u[2] * v[0] - u[0] * v[2])
                + w[2] * (u[0] * v[1] - u[1] * v[0]);
            let f = |x: [i64; 3]| x.map(|c| c as f64);
            assert_eq!(orient3d(f(a), f(b), f(c), f(p)), det.signum() as i8);
            assert_eq!(orient3d_exact(f(a), f(b), f(c), f(p)), det.signum() as i8);
        }
    }

    #[test]
    fn filter_and_exact_agree_on_random_inputs() {
        let mut rng = drafter_core::rng::Rng::new(0x9e37_79b9_7f4a_7c15u64);
        let mut next = || rng.unit_f64() - 0.5;
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
