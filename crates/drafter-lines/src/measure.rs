//! Views and timing for silhouette benchmarks (`drafter bench silhouettes`, the
//! `silhouette_bench` example): the fixed icosahedral directions, seeded random directions and
//! eyes, and per-view timing that compares methods in the same process.
//!
//! Per-view timing, two ways, because the machines this runs on are shared and noisy:
//!
//! * [`Warmth::Warm`]: for every view each method runs three times in a row and its fastest run
//!   counts, as in an interactive loop where consecutive frames see nearly the same view (the
//!   data a method touches is in cache);
//! * [`Warmth::Cold`]: for every view the methods run in turn, three rounds, each keeping its
//!   fastest run; each run starts with the caches holding the previous method's data, the worst
//!   case for a hierarchy that jumps around in memory.
//!
//! Either way the figure is the mean over views of the per-view minimum, which is robust to
//! preemption and keeps ratios between methods meaningful under load.

use std::time::Instant;

use drafter_core::rng::Rng;
use glam::Vec3;

/// The 20 fixed orthographic directions of `--views icosa`, normalised: the 12 icosahedron
/// vertices (0, ±1, ±φ), (±1, ±φ, 0), (±φ, 0, ±1), then the 8 cube corners (±1, ±1, ±1).
pub fn icosa_directions() -> Vec<Vec3> {
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    let mut out = Vec::with_capacity(20);
    for (a, b) in [(1.0, phi), (1.0, -phi), (-1.0, phi), (-1.0, -phi)] {
        out.push(Vec3::new(0.0, a, b));
    }
    for (a, b) in [(1.0, phi), (1.0, -phi), (-1.0, phi), (-1.0, -phi)] {
        out.push(Vec3::new(a, b, 0.0));
    }
    for (a, b) in [(phi, 1.0), (phi, -1.0), (-phi, 1.0), (-phi, -1.0)] {
        out.push(Vec3::new(a, 0.0, b));
    }
    for k in 0..8 {
        let s = |bit: u32| if k & (1 << bit) == 0 { 1.0 } else { -1.0 };
        out.push(Vec3::new(s(2), s(1), s(0)));
    }
    out.into_iter().map(Vec3::normalize).collect()
}

/// Numbers in [-1, 1) from the workspace's generator seeded with `seed`: the generator of the unit
/// tests that place normals, boxes and eyes by hand.
#[cfg(test)]
pub(crate) fn signed_uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut rng = Rng::new(seed);
    move || rng.signed_f32()
}

/// An eye outside the box `lo..hi`, at 1.05 to 5 half-diagonals from its centre in a uniform
/// direction (drawn again while inside the box).
pub fn eye_outside(rng: &mut Rng, lo: Vec3, hi: Vec3) -> Vec3 {
    let center = (lo + hi) * 0.5;
    let half = ((hi - lo) * 0.5).length().max(1e-6);
    loop {
        let e = center + rng.direction_f32() * half * (1.05 + 3.95 * rng.unit_f32());
        if !(e.cmpge(lo).all() && e.cmple(hi).all()) {
            return e;
        }
    }
}

/// How repeated runs of one view are arranged (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Warmth {
    /// Each method three times in a row per view.
    Warm,
    /// The methods in turn, three rounds per view.
    Cold,
}

/// Mean nanoseconds per view of each method over `views` views (`method(k, view)` runs method
/// `k` on view `view`), the fastest of three runs per view counting.
pub fn time_per_view(views: usize, methods: usize, warmth: Warmth, mut method: impl FnMut(usize, usize)) -> Vec<f64> {
    let mut total = vec![0f64; methods];
    let mut best = vec![f64::INFINITY; methods];
    let mut run = |k: usize, v: usize, best: &mut [f64]| {
        let t = Instant::now();
        method(k, v);
        best[k] = best[k].min(t.elapsed().as_nanos() as f64);
    };
    for v in 0..views {
        best.fill(f64::INFINITY);
        match warmth {
            Warmth::Warm => {
                for k in 0..methods {
                    for _ in 0..3 {
                        run(k, v, &mut best);
                    }
                }
            }
            Warmth::Cold => {
                for _ in 0..3 {
                    for k in 0..methods {
                        run(k, v, &mut best);
                    }
                }
            }
        }
        for (t, b) in total.iter_mut().zip(&best) {
            *t += b;
        }
    }
    total.iter().map(|t| t / views.max(1) as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosa_directions_are_the_stated_twenty() {
        let d = icosa_directions();
        assert_eq!(d.len(), 20);
        let phi = (1.0 + 5f32.sqrt()) / 2.0;
        assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-6));
        assert!((d[0] - Vec3::new(0.0, 1.0, phi).normalize()).length() < 1e-6);
        assert!((d[19] - Vec3::splat(-1.0).normalize()).length() < 1e-6);
        // All distinct, and the set is symmetric under negation.
        for (i, a) in d.iter().enumerate() {
            assert!(d.iter().skip(i + 1).all(|b| (*a - *b).length() > 1e-3));
            assert!(d.iter().any(|b| (*a + *b).length() < 1e-6));
        }
    }

    #[test]
    fn eyes_are_outside() {
        let mut rng = Rng::new(3);
        let (lo, hi) = (Vec3::ZERO, Vec3::new(1.0, 2.0, 0.01));
        for _ in 0..1000 {
            let e = eye_outside(&mut rng, lo, hi);
            assert!(!(e.cmpge(lo).all() && e.cmple(hi).all()));
            assert!(e.is_finite());
        }
    }

    #[test]
    fn timing_runs_every_method_three_times_per_view() {
        let mut calls = [0usize; 2];
        let t = time_per_view(5, 2, Warmth::Cold, |k, _| calls[k] += 1);
        assert_eq!(calls, [15, 15]);
        assert_eq!(t.len(), 2);
        let t = time_per_view(4, 2, Warmth::Warm, |k, _| calls[k] += 1);
        assert_eq!(calls, [27, 27]);
        assert!(t.iter().all(|x| x.is_finite() && *x >= 0.0));
    }
}
