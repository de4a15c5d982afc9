//! Deterministic `sin`, `cos` and `atan` in plain `f64` arithmetic.
//!
//! The committed samples must be byte-identical wherever they are regenerated, but `f64::sin` and friends call
//! the platform's libm, whose last bit differs between glibc, macOS and the MSVC runtime. These versions use only
//! `+ - * /` and `sqrt` (all correctly rounded by IEEE 754), so they give the same bits on every platform.
//!
//! How it works: `sin`/`cos` reduce the argument to `[-π/4, π/4]` with a two-part `π/2` (Cody–Waite, constants
//! from fdlibm) and evaluate Taylor polynomials to degree 19 / 18 (truncation error below 1e-21). `atan` maps
//! `|x| > 1` to `π/2 - atan(1/x)`, halves the angle twice with `atan(x) = 2 atan(x / (1 + sqrt(1 + x²)))` and
//! evaluates the Taylor series to degree 27 on `|x| ≤ tan(π/16)`.
//!
//! Limits: meant for the moderate angles a generator uses (|x| below about 1e6); accuracy is a few ulps, not
//! correctly rounded, which is plenty for geometry that is rounded to `f32` afterwards. NaN in, NaN out.

use std::f64::consts::FRAC_PI_2;

/// High part of π/2 (33 significant bits, so `k * PIO2_HI` is exact for moderate `k`).
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
/// π/2 − `PIO2_HI`.
const PIO2_LO: f64 = 6.077_100_506_506_192e-11;

/// `(sin x, cos x)`, deterministic across platforms.
pub fn sin_cos(x: f64) -> (f64, f64) {
    let k = (x / FRAC_PI_2).round();
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    let (s, c) = (sin_poly(r), cos_poly(r));
    // `k` is an integer-valued float; its quadrant is k mod 4.
    match k.rem_euclid(4.0) as u8 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `sin x`, deterministic across platforms.
pub fn sin(x: f64) -> f64 {
    sin_cos(x).0
}

/// `cos x`, deterministic across platforms.
pub fn cos(x: f64) -> f64 {
    sin_cos(x).1
}

/// `tan x`, deterministic across platforms.
pub fn tan(x: f64) -> f64 {
    let (s, c) = sin_cos(x);
    s / c
}

/// `atan x`, deterministic across platforms.
pub fn atan(x: f64) -> f64 {
    if x.is_nan() {
        return x;
    }
    if x.abs() > 1.0 {
        return FRAC_PI_2.copysign(x) - atan(1.0 / x);
    }
    // Two angle halvings bring |x| ≤ 1 down to |x| ≤ tan(π/16) ≈ 0.199.
    let h1 = x / (1.0 + (1.0 + x * x).sqrt());
    let h2 = h1 / (1.0 + (1.0 + h1 * h1).sqrt());
    4.0 * atan_series(h2)
}

/// Taylor series of sin on [-π/4, π/4], Horner form in r².
fn sin_poly(r: f64) -> f64 {
    let r2 = r * r;
    // Coefficients (-1)^n / (2n+1)! for n = 1..=9.
    let mut acc = 0.0;
    for n in (1..=9).rev() {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        acc = sign / factorial(2 * n + 1) + r2 * acc;
    }
    r + r * r2 * acc
}

/// Taylor series of cos on [-π/4, π/4], Horner form in r².
fn cos_poly(r: f64) -> f64 {
    let r2 = r * r;
    let mut acc = 0.0;
    for n in (1..=9).rev() {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        acc = sign / factorial(2 * n) + r2 * acc;
    }
    1.0 + r2 * acc
}

/// Taylor series of atan on |x| ≤ 0.2.
fn atan_series(x: f64) -> f64 {
    let x2 = x * x;
    let mut acc = 0.0;
    for n in (1..=13).rev() {
        let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
        acc = sign / f64::from(2 * n + 1) + x2 * acc;
    }
    x + x * x2 * acc
}

/// n! as f64 (exact for the n ≤ 19 used here).
fn factorial(n: u32) -> f64 {
    (2..=n).fold(1.0, |acc, k| acc * f64::from(k))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_std_on_a_dense_sweep() {
        let mut worst = 0.0_f64;
        for i in -20_000..=20_000 {
            let x = f64::from(i) * 1e-3;
            worst = worst.max((sin(x) - x.sin()).abs());
            worst = worst.max((cos(x) - x.cos()).abs());
            worst = worst.max((atan(x) - x.atan()).abs());
            worst = worst.max((atan(x * 1e3) - (x * 1e3).atan()).abs());
        }
        assert!(worst < 1e-15, "worst deviation from std: {worst:e}");
    }

    #[test]
    fn exact_at_zero_and_quadrants_are_right() {
        assert_eq!(sin(0.0), 0.0);
        assert_eq!(cos(0.0), 1.0);
        assert_eq!(atan(0.0), 0.0);
        assert!((sin(std::f64::consts::PI) - 0.0).abs() < 1e-15);
        assert!((cos(std::f64::consts::PI) + 1.0).abs() < 1e-15);
        assert!((tan(std::f64::consts::FRAC_PI_4) - 1.0).abs() < 1e-15);
        assert!(atan(f64::NAN).is_nan());
    }
}
