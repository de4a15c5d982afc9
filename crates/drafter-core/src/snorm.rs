//! Unit vectors as glTF's normalized signed integers (`normalized: true`): BYTE for
//! `EXT_mesh_primitive_edge_visibility`'s `silhouetteNormals` (the merged draft's recommendation)
//! and for our compact `_ENHANCED_NORMAL`; SHORT where a reader meets it in another writer's file.
//! One definition for the writer (drafter-lines, drafter-format) and every reader, so the decoded
//! values are bit-identical wherever they are computed.
//!
//! Silhouette normals are encoded by [`snorm8_encode_direction`]: of the 8 lattice points around
//! `127·n`, the one whose direction is nearest `n`. Our hierarchies answer exactly for the decoded
//! values; what the quantization changes against `f32` face normals (edges within a fraction of a
//! degree of tangent) is measured by drafter-lines' `examples/normal_precision.rs` (docs/bench.md).

use glam::Vec3;

/// `round(m·x)` per component, `x` clamped to [−1, 1]; a non-finite component encodes 0.
fn encode(n: Vec3, m: f32) -> [f32; 3] {
    let q = |x: f32| if x.is_finite() { (x.clamp(-1.0, 1.0) * m).round() } else { 0.0 };
    [q(n.x), q(n.y), q(n.z)]
}

/// A unit vector as normalized signed bytes.
pub fn snorm8_encode(n: Vec3) -> [i8; 3] {
    encode(n, 127.0).map(|c| c as i8)
}

/// The squared lengths of the lattice points whose length is within 0.866026 (√3/2 rounded up:
/// how far per-component rounding can move a point of the lattice) of 127: 126.134² = 15909.8
/// and 127.867² = 16349.7, and no integer is near either bound (the test
/// `lattice_length_range_is_the_float_rule` checks every integer against the lengths).
const LATTICE_LENGTHS_SQUARED: std::ops::RangeInclusive<f64> = 15910.0..=16349.0;

/// A unit vector as the normalized signed bytes whose direction is nearest to it: of the 8 points
/// `floor`/`ceil` of `127·n` per component whose length is within `√3/2` of 127 (as long or short
/// as per-component rounding can make it, so the decoded vector stays within 0.7 % of unit length,
/// as the draft asks of `silhouetteNormals`), the one with the largest cosine to `n` (ties: the
/// first in floor-before-ceil order, x slowest). Per-component rounding ([`snorm8_encode`], always
/// one of those points) ignores that a facing test only compares signs: choosing by angle brings
/// the mean angular error from 0.17° to 0.14° and the largest from 0.38° to 0.31°. A non-finite or
/// zero `n` encodes as [`snorm8_encode`] does.
pub fn snorm8_encode_direction(input: Vec3) -> [i8; 3] {
    if !input.is_finite() || input == Vec3::ZERO {
        return snorm8_encode(input);
    }
    let n = input.as_dvec3().normalize();
    let s = n * 127.0;
    // Floor and ceiling through a truncating conversion (|s| ≤ 127 plus rounding): the baseline
    // x86-64 target has no rounding instruction, and the library calls were a large share of this
    // function's time in profiles of a bake. Only the sign of a zero can differ
    // from `f64::floor`, which no product, sum or cast below sees.
    let floor_ceil = |x: f64| {
        let t = x as i64 as f64;
        (if t > x { t - 1.0 } else { t }, if t < x { t + 1.0 } else { t })
    };
    let [(lx, hx), (ly, hy), (lz, hz)] = [s.x, s.y, s.z].map(floor_ceil);
    let (lo, hi) = (glam::DVec3::new(lx, ly, lz), glam::DVec3::new(hx, hy, hz));
    // All eight points are scored without skipping any (a point too long or short scores −∞),
    // and the first of the largest cosines wins: a loop without branches to mispredict is faster
    // than one that skips the points out of range. Equal to the rule as stated (test
    // `the_direction_encoder_is_its_rule`).
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    let cosines = if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, the one feature the function is compiled with.
        unsafe { lattice_cosines_avx(lo, hi, n) }
    } else {
        lattice_cosines(lo, hi, n)
    };
    #[cfg(not(target_arch = "x86_64"))]
    let cosines = lattice_cosines(lo, hi, n);
    let (mut best_cos, mut best) = (f64::NEG_INFINITY, 8usize);
    for (k, cos) in cosines.into_iter().enumerate() {
        if cos > best_cos {
            (best_cos, best) = (cos, k);
        }
    }
    if best == 8 {
        return snorm8_encode(input);
    }
    let pick = |axis: usize, l: f64, h: f64| if best >> (2 - axis) & 1 == 0 { l } else { h };
    let c = glam::DVec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z))
        .clamp(glam::DVec3::splat(-127.0), glam::DVec3::splat(127.0));
    [c.x as i8, c.y as i8, c.z as i8]
}

/// The cosine between `n` and each of the 8 lattice points with components `lo` or `hi` (point `k`
/// takes `hi` on x, y, z where bits 2, 1, 0 of `k` are set), clamped to ±127; −∞ for a point whose
/// length is out of [`LATTICE_LENGTHS_SQUARED`].
fn lattice_cosines(lo: glam::DVec3, hi: glam::DVec3, n: glam::DVec3) -> [f64; 8] {
    std::array::from_fn(|k| {
        let pick = |axis: usize, l: f64, h: f64| if k >> (2 - axis) & 1 == 0 { l } else { h };
        let c = glam::DVec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z))
            .clamp(glam::DVec3::splat(-127.0), glam::DVec3::splat(127.0));
        // The components are integers, so the squared length is an exact integer and the length
        // test an integer range.
        let length_squared = c.dot(c);
        let kept = LATTICE_LENGTHS_SQUARED.contains(&length_squared);
        let cos = c.dot(n) / length_squared.sqrt();
        if kept { cos } else { f64::NEG_INFINITY }
    })
}

/// [`lattice_cosines`] with AVX, points 0–3 and 4–7 in one vector each: the same operations per
/// lane in the same order (glam's dot product `(x·x' + y·y') + z·z'`, the clamp as a maximum then
/// a minimum, no fused multiply-add), so the same bits; the 8 square roots and divisions take 2
/// instructions each. The encoder runs once per face of every silhouette candidate, and its byte
/// rounding is a large share of the edge encoding's time
/// (docs/bench.md#where-the-dragons-lines-stage-goes).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[allow(unsafe_code)]
fn lattice_cosines_avx(lo: glam::DVec3, hi: glam::DVec3, n: glam::DVec3) -> [f64; 8] {
    use std::arch::x86_64::*;
    let splat = |x: f64| _mm256_set1_pd(x);
    let y = _mm256_setr_pd(lo.y, lo.y, hi.y, hi.y);
    let z = _mm256_setr_pd(lo.z, hi.z, lo.z, hi.z);
    let clamp = |v: __m256d| _mm256_min_pd(_mm256_max_pd(v, splat(-127.0)), splat(127.0));
    let (lower, upper) = (splat(*LATTICE_LENGTHS_SQUARED.start()), splat(*LATTICE_LENGTHS_SQUARED.end()));
    let mut out = [0f64; 8];
    for (x, half) in [lo.x, hi.x].into_iter().zip(out.chunks_exact_mut(4)) {
        let (cx, cy, cz) = (clamp(splat(x)), clamp(y), clamp(z));
        let length_squared =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(cx, cx), _mm256_mul_pd(cy, cy)), _mm256_mul_pd(cz, cz));
        let kept = _mm256_and_pd(
            _mm256_cmp_pd::<_CMP_GE_OQ>(length_squared, lower),
            _mm256_cmp_pd::<_CMP_LE_OQ>(length_squared, upper),
        );
        let dot = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(cx, splat(n.x)), _mm256_mul_pd(cy, splat(n.y))),
            _mm256_mul_pd(cz, splat(n.z)),
        );
        let cos = _mm256_div_pd(dot, _mm256_sqrt_pd(length_squared));
        let cos = _mm256_blendv_pd(splat(f64::NEG_INFINITY), cos, kept);
        // SAFETY: `half` holds 4 f64s; the store is unaligned.
        unsafe { _mm256_storeu_pd(half.as_mut_ptr(), cos) };
    }
    out
}

/// The glTF validator's tolerance for unit vectors (`ACCESSOR_VECTOR3_NON_UNIT`): the decoded
/// length may differ from 1 by at most this much.
pub const VALIDATOR_UNIT_TOLERANCE: f32 = 0.00674;

/// A unit vector as normalized signed bytes that a validator accepts as unit length, for a
/// quantized `NORMAL` (`KHR_mesh_quantization`): of the 27 lattice points around `127·n` whose
/// length is within 0.84 of 127 (decoded: within 0.0066 of 1, inside
/// [`VALIDATOR_UNIT_TOLERANCE`]; per-component rounding and [`snorm8_encode_direction`] can land
/// up to 0.0068 away), the one with the largest cosine to `n` (ties: the first in x-slowest,
/// low-before-high order). If no such point exists, which the tests have not found for any
/// direction, [`snorm8_encode_direction`]. A non-finite or zero `n` encodes as [`snorm8_encode`].
pub fn snorm8_encode_unit(n: Vec3) -> [i8; 3] {
    const LENGTH_TOLERANCE: f64 = 0.84;
    if !n.is_finite() || n == Vec3::ZERO {
        return snorm8_encode(n);
    }
    let n = n.as_dvec3().normalize();
    let centre = (n * 127.0).round();
    let mut best: Option<(f64, [i8; 3])> = None;
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                let c = (centre + glam::DVec3::new(f64::from(dx), f64::from(dy), f64::from(dz)))
                    .clamp(glam::DVec3::splat(-127.0), glam::DVec3::splat(127.0));
                let length = c.length();
                if length == 0.0 || (length - 127.0).abs() > LENGTH_TOLERANCE {
                    continue;
                }
                let cos = c.dot(n) / length;
                if best.is_none_or(|(b, _)| cos > b) {
                    best = Some((cos, [c.x as i8, c.y as i8, c.z as i8]));
                }
            }
        }
    }
    best.map_or_else(|| snorm8_encode_direction(n.as_vec3()), |b| b.1)
}

/// What a glTF reader decodes from normalized signed bytes: `max(c / 127, −1)` per component
/// (glTF 2.0 §3.11). Not renormalised.
pub fn snorm8_decode(c: [i8; 3]) -> Vec3 {
    let f = |c: i8| (f32::from(c) / 127.0).max(-1.0);
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

/// A unit vector as normalized signed shorts.
pub fn snorm16_encode(n: Vec3) -> [i16; 3] {
    encode(n, 32767.0).map(|c| c as i16)
}

/// What a glTF reader decodes from normalized signed shorts: `max(c / 32767, −1)` per component.
/// Not renormalised: the silhouette predicates only compare signs.
pub fn snorm16_decode(c: [i16; 3]) -> Vec3 {
    let f = |c: i16| (f32::from(c) / 32767.0).max(-1.0);
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform values in [−1, 1) from the seeded generator.
    fn uniform(seed: u64) -> impl FnMut() -> f32 {
        let mut rng = crate::rng::Rng::new(seed);
        move || rng.signed_f32()
    }

    fn worst_error_deg(round_trip: impl Fn(Vec3) -> Vec3) -> f32 {
        let mut r = uniform(3);
        let mut worst = 0.0f32;
        for k in 0..20000 {
            let n = match k {
                0 => Vec3::X,
                1 => Vec3::NEG_Z,
                2 => Vec3::new(-1.0, 0.0, -1.0).normalize(),
                _ => Vec3::new(r(), r(), r()).normalize(),
            };
            // In f64: an f32 dot product near 1 cannot resolve angles below ~0.02°.
            let back = round_trip(n).as_dvec3().normalize();
            worst = worst.max(n.as_dvec3().normalize().dot(back).clamp(-1.0, 1.0).acos().to_degrees() as f32);
        }
        worst
    }

    #[test]
    fn lattice_length_range_is_the_float_rule() {
        const HALF_LATTICE_DIAGONAL: f64 = 0.866_026;
        for k in 0..=3 * 127 * 127 {
            let length = f64::from(k).sqrt();
            let float_rule = length != 0.0 && (length - 127.0).abs() <= HALF_LATTICE_DIAGONAL;
            assert_eq!(LATTICE_LENGTHS_SQUARED.contains(&f64::from(k)), float_rule, "squared length {k}");
        }
    }

    #[test]
    fn round_trips_and_conventions() {
        assert!(worst_error_deg(|n| snorm8_decode(snorm8_encode(n))) < 0.5);
        assert!(worst_error_deg(|n| snorm16_decode(snorm16_encode(n))) < 0.002);
        // Decoding then encoding again gives the same integers (a reader that rewrites keeps them).
        for n in [Vec3::new(0.3, -0.9, 0.1).normalize(), Vec3::new(-1.0, 0.0, 1e-7)] {
            assert_eq!(snorm8_encode(snorm8_decode(snorm8_encode(n))), snorm8_encode(n));
            assert_eq!(snorm16_encode(snorm16_decode(snorm16_encode(n))), snorm16_encode(n));
        }
        assert_eq!(snorm8_encode(Vec3::Z), [0, 0, 127]);
        assert_eq!(snorm8_encode(Vec3::NEG_X), [-127, 0, 0]);
        assert_eq!(snorm8_encode(Vec3::new(f32::NAN, 1.0, 0.0)), [0, 127, 0]);
        assert_eq!(snorm8_decode([-128, 0, 127]), Vec3::new(-1.0, 0.0, 1.0));
        assert_eq!(snorm16_encode(Vec3::new(1.0, -1.0, 0.0)), [32767, -32767, 0]);
        assert_eq!(snorm16_decode([i16::MIN, 0, 32767]), Vec3::new(-1.0, 0.0, 1.0));
    }

    #[test]
    fn the_direction_encoder_is_never_worse_than_rounding_and_better_on_average() {
        let angle = |n: Vec3, c: [i8; 3]| {
            let back = snorm8_decode(c).as_dvec3().normalize();
            n.as_dvec3().normalize().dot(back).clamp(-1.0, 1.0).acos().to_degrees()
        };
        let mut r = uniform(11);
        let (mut plain, mut direction) = (0.0, 0.0);
        for _ in 0..20000 {
            let Some(n) = Vec3::new(r(), r(), r()).try_normalize() else { continue };
            let (a, b) = (angle(n, snorm8_encode(n)), angle(n, snorm8_encode_direction(n)));
            assert!(b <= a + 1e-9, "{n}: {b}° against {a}°");
            plain += a;
            direction += b;
            // Never longer or shorter than rounding makes a vector.
            let length = snorm8_decode(snorm8_encode_direction(n)).length();
            assert!((length - 1.0).abs() < 0.0069, "{n}: decoded length {length}");
        }
        assert!(direction < 0.9 * plain, "mean error {direction} against {plain}");
        assert_eq!(snorm8_encode_direction(Vec3::Z), [0, 0, 127]);
        assert_eq!(snorm8_encode_direction(Vec3::ZERO), [0, 0, 0]);
    }

    #[test]
    fn unit_bytes_pass_the_validator_and_point_the_right_way() {
        let mut r = uniform(11);
        let mut worst = 0.0f32;
        for k in 0..200_000 {
            let n = match k {
                0..6 => [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z][k],
                6..14 => Vec3::new(
                    if k & 1 == 0 { 1.0 } else { -1.0 },
                    if k & 2 == 0 { 1.0 } else { -1.0 },
                    if k & 4 == 0 { 1.0 } else { -1.0 },
                )
                .normalize(),
                _ => Vec3::new(r(), r(), r()).normalize_or(Vec3::X),
            };
            let d = snorm8_decode(snorm8_encode_unit(n));
            assert!((d.length() - 1.0).abs() <= VALIDATOR_UNIT_TOLERANCE, "{n}: {d} has length {}", d.length());
            worst = worst.max(n.angle_between(d).to_degrees());
        }
        // Within a lattice step of the best direction: below 0.7°.
        assert!(worst < 0.7, "worst angle {worst}°");
    }

    /// The rule as the docs state it, a loop over the eight points: the encoder is equal to it.
    fn reference_direction(n: Vec3) -> [i8; 3] {
        // √3/2, rounded up: how far per-component rounding can move a point of the lattice.
        const HALF_LATTICE_DIAGONAL: f64 = 0.866_026;
        let plain = snorm8_encode(n);
        if !n.is_finite() || n == Vec3::ZERO {
            return plain;
        }
        let n = n.as_dvec3().normalize();
        let s = n * 127.0;
        let (lo, hi) = (s.floor(), s.ceil());
        let mut best = (f64::NEG_INFINITY, plain);
        for k in 0..8 {
            let pick = |axis: usize, l: f64, h: f64| if k >> (2 - axis) & 1 == 0 { l } else { h };
            let c = glam::DVec3::new(pick(0, lo.x, hi.x), pick(1, lo.y, hi.y), pick(2, lo.z, hi.z))
                .clamp(glam::DVec3::splat(-127.0), glam::DVec3::splat(127.0));
            let length = c.length();
            if length == 0.0 || (length - 127.0).abs() > HALF_LATTICE_DIAGONAL {
                continue;
            }
            let cos = c.dot(n) / length;
            if cos > best.0 {
                best = (cos, [c.x as i8, c.y as i8, c.z as i8]);
            }
        }
        best.1
    }

    /// The AVX scoring gives the scalar scoring's cosines bit for bit (so the scalar path, which
    /// CPUs without AVX take, picks what the tests above check).
    #[cfg(target_arch = "x86_64")]
    #[test]
    #[allow(unsafe_code)]
    fn lattice_cosines_avx_are_the_scalar_ones() {
        if !std::arch::is_x86_feature_detected!("avx") {
            return;
        }
        let mut r = uniform(9);
        for i in 0..200_000 {
            let v = Vec3::new(r(), r(), r());
            let Some(n) = (if i % 7 == 0 { Some(Vec3::new(v.x.round(), v.y, 0.0)) } else { v.try_normalize() })
                .and_then(Vec3::try_normalize)
            else {
                continue;
            };
            let n = n.as_dvec3().normalize();
            let s = n * 127.0;
            let (lo, hi) = (s.floor(), s.ceil());
            // SAFETY: the CPU has AVX (checked above).
            let fast = unsafe { lattice_cosines_avx(lo, hi, n) };
            assert_eq!(fast.map(f64::to_bits), lattice_cosines(lo, hi, n).map(f64::to_bits), "{n}");
        }
    }

    #[test]
    fn the_direction_encoder_is_its_rule() {
        let mut r = uniform(5);
        let mut directions: Vec<Vec3> = (0..300_000).filter_map(|_| Vec3::new(r(), r(), r()).try_normalize()).collect();
        // Axes, diagonals, points on the lattice and halfway between, and unnormalised inputs.
        for x in -2..=2 {
            for y in -2..=2 {
                for z in -2..=2 {
                    directions.push(Vec3::new(x as f32, y as f32, z as f32));
                    directions.push(Vec3::new(x as f32 + 0.5, y as f32 * 63.5, z as f32 * 127.0));
                }
            }
        }
        directions.extend([
            Vec3::splat(f32::MAX),
            Vec3::new(f32::NAN, 0.0, 1.0),
            Vec3::new(1e-30, 0.0, 0.0),
            Vec3::ZERO,
        ]);
        for n in directions {
            assert_eq!(snorm8_encode_direction(n), reference_direction(n), "{n}");
        }
    }
}
