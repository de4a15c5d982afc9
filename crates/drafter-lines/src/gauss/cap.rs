//! The caps: the bounding cap of a node's arc endpoints, centred on the cell or on the endpoints'
//! mean, whichever is tighter, with the widest angle from both centres in one pass over the arcs
//! (4 arcs at a time with AVX where the CPU has it).

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::CULL_MARGIN;
use super::assign::{Arc, PARALLEL_ARCS};
use crate::sphere::{NEVER_CULL, Widest, sine_threshold};

/// Chunk of arcs whose endpoint sum is one partial sum of [`subtree_cap`]: sums in fixed chunks,
/// added in order, give the same bits on any number of threads.
const CAP_CHUNK: usize = 4096;

/// What [`subtree_cap`] measures of a node's arcs.
pub(super) struct Measured {
    pub(super) cap: [f32; 4],
    /// `Σ p_a` and `max p_a` of [`StopRule`].
    pub(super) p_sum: f64,
    pub(super) p_max: f64,
}

/// [`cap_of`] over the endpoints of `arcs` (centred on the cell or on the endpoints' mean,
/// whichever is tighter), and the arcs' probability bounds of [`StopRule`]. Large nodes are
/// measured on the thread pool, with the same result: the mean is summed in fixed chunks and the
/// widest angle is an exact maximum.
pub(super) fn subtree_cap(arcs: &[Arc], cell_center: Option<DVec3>) -> Measured {
    let partial = |chunk: &[Arc]| {
        let (mut sum, mut p_sum, mut p_max) = (DVec3::ZERO, 0.0f64, 0.0f64);
        for a in chunk {
            sum += a.n1;
            sum += a.n2;
            let p = f64::from(a.p);
            p_sum += p;
            p_max = p_max.max(p);
        }
        (sum, p_sum, p_max)
    };
    let parallel = arcs.len() > PARALLEL_ARCS;
    let (mut mean, mut p_sum, mut p_max) = (DVec3::ZERO, 0.0, 0.0f64);
    let add = |(s, ps, pm): (DVec3, f64, f64)| {
        mean += s;
        p_sum += ps;
        p_max = p_max.max(pm);
    };
    // The partial sums added in chunk order either way (a small node's in place: most nodes are).
    if parallel {
        arcs.par_chunks(CAP_CHUNK).map(partial).collect::<Vec<_>>().into_iter().for_each(add);
    } else {
        arcs.chunks(CAP_CHUNK).map(partial).for_each(add);
    }
    let widest = |c: &[DVec3]| {
        let of = |chunk: &[Arc]| widest_angles_of_arcs(c, chunk);
        let max = |a: [f64; 2], b: [f64; 2]| [a[0].max(b[0]), a[1].max(b[1])];
        if parallel { arcs.par_chunks(CAP_CHUNK).map(of).reduce(|| [0.0; 2], max) } else { of(arcs) }
    };
    // A bound below the true one (rounding of the norms and of `sin`) keeps the rule conservative.
    let shrink = 1.0 - 1e-9;
    Measured { cap: cap_of(cell_center, mean, widest), p_sum: p_sum * shrink, p_max: p_max * shrink }
}

/// The widest angle between the unit vector `c` and the unit vectors `points`. The exact angle
/// (`atan2` of the cross and dot products, accurate at every size) is evaluated only for points
/// whose dot product is within rounding of the smallest so far, so the result is the exact
/// maximum over all points at a few `atan2` calls per node instead of one per point.
#[cfg(test)]
fn widest_angle(c: DVec3, points: impl Iterator<Item = DVec3>) -> f64 {
    let mut w = Widest::default();
    for p in points {
        w.add_group(c, &[c.dot(p)], |_| p);
    }
    w.angle
}

/// [`widest_angle`] over both endpoints of `arcs`, from each of up to two centres `cs` in one pass
/// over the arcs (the first `cs.len()` results; the others are 0), a group of 4 arcs at a time
/// ([`Widest::add_group`]). The build runs this over every arc at every level.
fn widest_angles_of_arcs(cs: &[DVec3], arcs: &[Arc]) -> [f64; 2] {
    let mut w = [Widest::default(), Widest::default()];
    let cs = &cs[..cs.len().min(2)];
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    // SAFETY: the CPU has AVX, the one feature the function is compiled with.
    let arcs = if std::arch::is_x86_feature_detected!("avx") { unsafe { widest_avx(cs, arcs, &mut w) } } else { arcs };
    for four in arcs.chunks(4) {
        for (&c, w) in cs.iter().zip(w.iter_mut()) {
            let mut dots = [f64::NAN; 8];
            for (k, a) in four.iter().enumerate() {
                dots[2 * k] = c.dot(a.n1);
                dots[2 * k + 1] = c.dot(a.n2);
            }
            w.add_group(c, &dots[..2 * four.len()], |k| if k % 2 == 0 { four[k / 2].n1 } else { four[k / 2].n2 });
        }
    }
    [w[0].angle, w[1].angle]
}

/// [`widest_angles_of_arcs`] on the arcs in whole groups of 4, into `w`; returns the arcs left.
/// The 8 dot products of a group with each centre in one pass (rounded as glam's, without FMA,
/// so the same bits as the scalar loop), their minimum across the lanes, and `atan2` only for the
/// lanes [`Widest::add_group`] picks. Small nodes (most of them hold a handful of arcs) spent most
/// of this function in `atan2` when every point of a group that came near the smallest dot product
/// so far was measured.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn widest_avx<'a>(cs: &[DVec3], arcs: &'a [Arc], w: &mut [Widest; 2]) -> &'a [Arc] {
    use std::arch::x86_64::*;
    let splat = |x: f64| _mm256_set1_pd(x);
    let groups = arcs.chunks_exact(4);
    let rest = groups.remainder();
    for four in groups {
        let lanes = |f: fn(&Arc) -> f64| _mm256_setr_pd(f(&four[0]), f(&four[1]), f(&four[2]), f(&four[3]));
        let n1 = [lanes(|a| a.n1.x), lanes(|a| a.n1.y), lanes(|a| a.n1.z)];
        let n2 = [lanes(|a| a.n2.x), lanes(|a| a.n2.y), lanes(|a| a.n2.z)];
        for (&c, w) in cs.iter().zip(w.iter_mut()) {
            let dot = |[x, y, z]: [__m256d; 3]| {
                _mm256_add_pd(
                    _mm256_add_pd(_mm256_mul_pd(splat(c.x), x), _mm256_mul_pd(splat(c.y), y)),
                    _mm256_mul_pd(splat(c.z), z),
                )
            };
            let (d1, d2) = (dot(n1), dot(n2));
            // The smallest of the 8 (a minimum of non-NaN values in any order is the same value).
            let m = _mm256_min_pd(d1, d2);
            let m = _mm256_min_pd(m, _mm256_permute2f128_pd::<1>(m, m));
            let m = _mm256_min_pd(m, _mm256_permute_pd::<0b0101>(m));
            let smallest = _mm256_cvtsd_f64(m);
            if smallest > w.cos_min + Widest::DOT_SLACK || smallest.is_nan() {
                continue;
            }
            let mut dots = [0f64; 8];
            // SAFETY: `dots` holds 8 f64s; the stores are unaligned.
            #[allow(unsafe_code)]
            unsafe {
                _mm256_storeu_pd(dots.as_mut_ptr(), d1);
                _mm256_storeu_pd(dots.as_mut_ptr().add(4), d2);
            }
            // Lane k of `d1` is arc k's first endpoint, lane k of `d2` its second.
            w.add_group(c, &dots, |k| if k < 4 { four[k].n1 } else { four[k - 4].n2 });
        }
    }
    rest
}

/// The cap of a set of unit endpoints: `[cx, cy, cz, threshold]` with the centre in `f32` and the
/// threshold `sin r + ε` rounded up, `r` measured from the `f32` centre. The centre is the cell's
/// centre or the endpoints' mean (`mean`: their sum, any length), whichever gives the smaller
/// radius; `widest` is the widest angle from a unit centre to the endpoints.
fn cap_of(cell_center: Option<DVec3>, mean: DVec3, widest: impl Fn(&[DVec3]) -> [f64; 2]) -> [f32; 4] {
    let mut centres = [(Vec3::ZERO, DVec3::ZERO); 2];
    let mut count = 0;
    for center in [cell_center, (mean.length() > 1e-12).then(|| mean.normalize())].into_iter().flatten() {
        let c32 = center.as_vec3();
        centres[count] = (c32, c32.as_dvec3().normalize());
        count += 1;
    }
    let units = centres.map(|(_, c)| c);
    let radii = widest(&units[..count]);
    let mut best: Option<([f32; 3], f64)> = None;
    for ((c32, _), r) in centres.into_iter().zip(radii).take(count) {
        if best.is_none_or(|(_, b)| r < b) {
            best = Some((c32.to_array(), r));
        }
    }
    let Some(([x, y, z], r)) = best else { return [0.0, 0.0, 1.0, NEVER_CULL] };
    [x, y, z, sine_threshold(r, CULL_MARGIN).unwrap_or(NEVER_CULL)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widest_angle_is_the_exact_maximum() {
        let mut rng = drafter_core::rng::Rng::new(11);
        for round in 0..200 {
            let c = rng.direction_f32().as_dvec3().normalize();
            let spread = [1e-7, 1e-3, 0.3, 1.5][round % 4];
            let points: Vec<DVec3> =
                (0..500).map(|_| (c + rng.direction_f32().as_dvec3() * spread).normalize()).collect();
            let exact = points.iter().map(|p| c.cross(*p).length().atan2(c.dot(*p))).fold(0.0f64, f64::max);
            assert_eq!(widest_angle(c, points.iter().copied()), exact, "round {round}");
            // The pass over arcs from two centres at once gives each centre's widest angle.
            let arcs: Vec<Arc> = points.chunks_exact(2).map(|p| Arc { n1: p[0], n2: p[1], ..Arc::default() }).collect();
            let other = (c + rng.direction_f32().as_dvec3() * spread).normalize();
            let of_other = widest_angle(other, points.iter().copied());
            assert_eq!(widest_angles_of_arcs(&[c, other], &arcs), [exact, of_other], "round {round}");
            assert_eq!(widest_angles_of_arcs(&[other], &arcs), [of_other, 0.0], "round {round}");
            // Widest last (every point a new smallest dot product, so every group of 4 is
            // re-added one by one) and widest first, on lengths that leave remainders.
            let mut sorted = points.clone();
            sorted.sort_by(|a, b| c.dot(*b).total_cmp(&c.dot(*a)));
            for points in [sorted.clone(), sorted.into_iter().rev().collect()] {
                let take = 2 * (round % 9 + 1) + 2 * 4 * (round % 3);
                let arcs: Vec<Arc> = points
                    .chunks_exact(2)
                    .take(take / 2)
                    .map(|p| Arc { n1: p[0], n2: p[1], ..Arc::default() })
                    .collect();
                let ends = arcs.iter().flat_map(|a| [a.n1, a.n2]);
                let expected = [widest_angle(c, ends.clone()), widest_angle(other, ends)];
                assert_eq!(widest_angles_of_arcs(&[c, other], &arcs), expected, "round {round}, {take} points");
            }
        }
    }
}
