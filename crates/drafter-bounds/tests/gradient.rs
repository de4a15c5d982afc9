//! The gradient function ω of Lux et al. 2013 (Eqn. 1 / Listing 1), checked against a direct,
//! independent transcription of the paper's GLSL for the parameter sets of its Figures 5 and 6.

#![allow(clippy::unwrap_used)] // tests (clippy.toml allows unwrap in #[test] fns; this covers helpers)

use drafter_bounds::{GradientParams, IntensityTransfer, TransferCurve, omega};

/// Listing 1, transcribed literally in f64 (GLSL `mod`, `step`, `mix`). The only liberty: at `f = 1`
/// the listing computes `0 · (mf − 1) / 0`, which is NaN in IEEE arithmetic; its limit (no fade) is used.
fn listing_1(i: f64, q: f64, f: f64, p: f64) -> f64 {
    let glsl_mod = |x: f64, y: f64| x - y * (x / y).floor();
    let step = |edge: f64, x: f64| if x < edge { 0.0 } else { 1.0 };
    let mix = |a: f64, b: f64, t: f64| a * (1.0 - t) + b * t;
    let r = 0.5 / (q + 1.0);
    let ip = i.powf(p);
    let iq = (ip * q).floor() / q + r;
    let mut mf = glsl_mod(ip, 1.0 / q) * q;
    mf = if f == 1.0 { 0.0 } else { step(f, mf) * (mf - f) * 1.0 / (1.0 - f) };
    mix(iq - r, iq + r, mf)
}

/// The paper's parameter sets: Fig. 5 (q = 3, p = 1.0, f = 0.66) and Fig. 6 (b), (c), (d).
const PAPER_SETS: [(u32, f32, f32); 4] = [(3, 0.66, 1.0), (10, 1.0, 1.0), (17, 1.0, 0.19), (7, 0.715, 1.4)];

#[test]
fn paper_parameter_sets_match_listing_1() {
    for (q, f, p) in PAPER_SETS {
        let params = GradientParams { q, f, p };
        params.validate().unwrap();
        let (qf, ff, pf) = (f64::from(q), f64::from(f), f64::from(p));
        let mut compared = 0;
        let n = 4000;
        for k in 0..=n {
            let i = k as f64 / n as f64;
            // Near a band edge, floor(ip·q) and mod(ip, 1/q)·q may round to different bands in any
            // precision (the module docs explain); compare away from the edges.
            let t = i.powf(pf) * qf;
            let edge_distance = (t - t.round()).abs();
            if edge_distance < 1e-9 && k != 0 && k != n {
                continue;
            }
            let expected = listing_1(i, qf, ff, pf);
            let got = omega(i, q, ff, pf);
            assert!((got - expected).abs() < 1e-12, "q={q} f={f} p={p} i={i}: {got} vs {expected}");
            let got32 = params.eval(i as f32);
            // f32 input rounding moves i by 3e-8; skip samples whose band changes within that.
            if edge_distance > 1e-5 {
                assert!(
                    (f64::from(got32) - expected).abs() < 1e-5,
                    "f32: q={q} f={f} p={p} i={i}: {got32} vs {expected}"
                );
            }
            compared += 1;
        }
        assert!(compared > n * 98 / 100, "q={q}: only {compared} samples compared");
    }
}

#[test]
fn figure_6b_is_a_plain_staircase() {
    // q = 10, p = 1, f = 1: ω(i) = floor(10 i) / 10.
    for (i, expected) in [(0.0, 0.0), (0.05, 0.0), (0.25, 0.2), (0.5, 0.5), (0.999, 0.9), (1.0, 1.0)] {
        assert!((omega(i, 10, 1.0, 1.0) - expected).abs() < 1e-12, "i={i}");
    }
}

#[test]
fn fades_start_at_the_fade_step_and_rise() {
    // Fig. 6(d): q = 7, p = 1.4, f = 0.715. Inside each band the output is flat until the fraction f of
    // the band, then rises to band/q + 1/(q+1) (Listing 1's mix order; the printed Eqn. 1 would fall).
    let (q, f, p) = (7u32, 0.715f64, 1.4f64);
    let qf = f64::from(q);
    for band in 0..q {
        let level = f64::from(band) / qf;
        let at = |fraction: f64| {
            let ip = (f64::from(band) + fraction) / qf;
            omega(ip.powf(1.0 / p), q, f, p)
        };
        assert!((at(0.1) - level).abs() < 1e-9 && (at(0.7) - level).abs() < 1e-9, "band {band} flat part");
        let top = level + 1.0 / (qf + 1.0);
        assert!((at(0.9999999) - top).abs() < 1e-6, "band {band} fade end {}", at(0.9999999));
        let mut last = at(0.72);
        for s in 1..50 {
            let v = at(0.72 + 0.28 * f64::from(s) / 50.0 * 0.999);
            assert!(v >= last, "band {band}: the fade must rise");
            last = v;
        }
    }
    assert_eq!(omega(1.0, q, f, p), 1.0);
    assert_eq!(omega(0.0, q, f, p), 0.0);
}

#[test]
fn omega_stays_in_range_and_is_total() {
    for q in [1, 2, 3, 10, 255] {
        for f in [0.0, 0.3, 0.999, 1.0] {
            for p in [0.01, 0.19, 1.0, 1.4, 10.0] {
                for k in 0..=200 {
                    let v = omega(f64::from(k) / 200.0, q, f, p);
                    assert!((0.0..=1.0).contains(&v), "q={q} f={f} p={p}: {v}");
                }
            }
        }
    }
    // Out-of-range input is clamped, never NaN.
    for i in [-1.0, 2.0, f64::NAN, f64::INFINITY] {
        assert!(omega(i, 10, 0.5, 1.0).is_finite());
    }
    assert!(omega(0.5, 0, -1.0, -2.0).is_finite());
}

#[test]
fn shading_chain_uses_the_transfer_table() {
    let params = GradientParams { q: 10, f: 1.0, p: 1.0 };
    let identity = IntensityTransfer::default();
    let invert = IntensityTransfer::from_curve(TransferCurve::Invert);
    assert!((params.shade(0.25, &identity) - 0.2).abs() < 1e-6);
    assert!((params.shade(0.25, &invert) - 0.7).abs() < 1e-6);
    let json = serde_json_roundtrip(&params);
    assert_eq!(json, params);
}

fn serde_json_roundtrip(params: &GradientParams) -> GradientParams {
    serde_json::from_str(&serde_json::to_string(params).unwrap()).unwrap()
}
