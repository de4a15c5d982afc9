//! The bounds of a node: its box, its normal cone and the range of its face planes' offsets from
//! the box centre, measured in one pass (4 candidates at a time with AVX where the CPU has it),
//! and the plane-offset cull test on them (see the module docs of `cone_bvh`).

use glam::{DVec3, Vec3};

use super::{CONE_MARGIN, PLANE_MARGIN};
use crate::sphere::{NEVER_CULL, Widest, round_down, round_up, sine_threshold};

/// A candidate's two normals in `f64`, normalised (zero for a degenerate face): what every bound
/// of the build is computed from.
pub(super) fn unit_pair([a, b]: [Vec3; 2]) -> [DVec3; 2] {
    [a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero()]
}

/// The plane-offset bound of a node: `[cos α, h_lo, h_hi, reach]`, where every face plane below
/// the node (normal `n̂` normalised, through the candidate's point `v`) has the offset
/// `h = n̂·(v − p₀)` in `[h_lo, h_hi]` from the anchor `p₀` (the centre of the node's box) and
/// `reach ≥ |v − p₀|`. A node that cannot use it stores `[0, −∞, +∞, 0]`: the test never culls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct PlaneBound(pub(super) [f32; 4]);

impl PlaneBound {
    const NEVER: PlaneBound = PlaneBound([0.0, f32::NEG_INFINITY, f32::INFINITY, 0.0]);

    /// The bound of the candidates with unit normals `unit` (see [`unit_pair`]) and `points`
    /// (box `b`, cone `c` as stored).
    #[cfg(test)]
    fn of(unit: &[[DVec3; 2]], points: &[Vec3], b: &[f32; 6], c: &[f32; 4]) -> Self {
        let mut acc = PlaneAcc::new(b);
        for (&u, &p) in unit.iter().zip(points) {
            acc.add(u, p);
        }
        acc.finish(c)
    }
}

/// Offsets and reach of face planes from a node's anchor, accumulated in `f64`.
#[derive(Clone, Copy, Debug)]
pub(super) struct PlaneAcc {
    p0: DVec3,
    lo: f64,
    hi: f64,
    /// The largest `|v − p₀|²`: its square root is the largest `|v − p₀|` (a correctly rounded
    /// square root is monotonic), taken once per node instead of once per candidate.
    reach_squared: f64,
    count: usize,
}

impl PlaneAcc {
    pub(super) fn new(b: &[f32; 6]) -> Self {
        Self { p0: anchor(b).as_dvec3(), lo: f64::INFINITY, hi: f64::NEG_INFINITY, reach_squared: 0.0, count: 0 }
    }

    /// Adds a candidate with unit normals `unit` (see [`unit_pair`]) and point `point`.
    pub(super) fn add(&mut self, unit: [DVec3; 2], point: Vec3) {
        let d = point.as_dvec3() - self.p0;
        self.reach_squared = self.reach_squared.max(d.dot(d));
        for n in unit {
            let h = n.dot(d);
            self.lo = self.lo.min(h);
            self.hi = self.hi.max(h);
        }
        self.count += 1;
    }

    /// The bound for a node whose stored cone is `c`.
    pub(super) fn finish(&self, c: &[f32; 4]) -> PlaneBound {
        let reach = self.reach_squared.sqrt();
        if c[3] >= 1.0 || self.count == 0 || !(self.lo.is_finite() && self.hi.is_finite() && reach.is_finite()) {
            return PlaneBound::NEVER;
        }
        // cos α from the stored sine (which includes the cone margin): rounded down.
        let sin = f64::from(c[3]);
        let cos = (1.0 - sin * sin).max(0.0).sqrt();
        // `+ 0.0` turns a zero offset of -0.0 into +0.0: which zero a minimum or maximum keeps
        // depends on the order it met them in (the four-lane pass meets them in another), and no
        // comparison of the bound tells them apart.
        PlaneBound([round_down(cos), round_down(self.lo + 0.0), round_up(self.hi + 0.0), round_up(reach)])
    }
}

/// The anchor `p₀` of a node: its box centre, computed the same way at build, load and query.
#[inline(always)]
pub(super) fn anchor(b: &[f32; 6]) -> Vec3 {
    Vec3::new((b[0] + b[3]) * 0.5, (b[1] + b[4]) * 0.5, (b[2] + b[5]) * 0.5)
}

/// The plane-offset test of the module docs, on one node.
pub(super) fn plane_culls(b: &[f32; 6], c: &[f32; 4], p: &PlaneBound, e: Vec3) -> bool {
    let w = e - anchor(b);
    let axis = Vec3::new(c[0], c[1], c[2]);
    let [cos, lo, hi, reach] = p.0;
    let sin = c[3];
    let t = axis.dot(w);
    let s = axis.cross(w).length();
    let len = w.length();
    let min = if t >= -len * cos { t * cos - s * sin } else { -len };
    let max = if t <= len * cos { t * cos + s * sin } else { len };
    let tol = PLANE_MARGIN * (len + reach);
    min - hi > tol || max - lo < -tol
}

/// The box of no points (what [`bounding_box`] returns for none).
pub(super) const EMPTY_AABB: [f32; 6] =
    [f32::INFINITY, f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY];

pub(super) fn bounding_box(points: impl Iterator<Item = Vec3>) -> [f32; 6] {
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in points {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z]
}

/// [`bounding_cone`] of `pairs` and [`PlaneBound::of`] the candidates (`pairs`, `points`, box `b`)
/// under that cone, with one pass over the candidates after the normals' sum instead of two
/// (the build measures every node over its whole range, so every candidate once per level); a
/// node that never culls skips the plane pass. Equal to the two apart (tested).
pub(super) fn cone_and_planes(pairs: &[[DVec3; 2]], points: &[Vec3], b: &[f32; 6]) -> ([f32; 4], PlaneBound) {
    let mut sum = DVec3::ZERO;
    for &[a, b] in pairs {
        sum = sum + a + b;
    }
    if sum.length().is_nan() || sum.length() <= 1e-12 {
        return ([0.0, 0.0, 1.0, NEVER_CULL], PlaneBound::NEVER);
    }
    let axis32 = sum.normalize().as_vec3();
    let axis = axis32.as_dvec3().normalize();
    let never = ([axis32.x, axis32.y, axis32.z, NEVER_CULL], PlaneBound::NEVER);
    let mut widest = Widest { cos_min: 1.0, angle: 0.0 };
    let mut acc = PlaneAcc::new(b);
    #[cfg(target_arch = "x86_64")]
    #[allow(unsafe_code)]
    let done = if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU has AVX, the one feature the function is compiled with.
        match unsafe { cone_and_planes_avx(axis, pairs, points, &mut widest, &mut acc) } {
            Some(done) => done,
            None => return never,
        }
    } else {
        0
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = 0;
    if !add_candidates(&mut widest, axis, &pairs[done..], &points[done..], &mut acc) {
        return never;
    }
    let Some(s32) = sine_threshold(widest.angle, CONE_MARGIN) else { return never };
    let cone = [axis32.x, axis32.y, axis32.z, s32];
    (cone, acc.finish(&cone))
}

/// Adds the candidates `pairs` (unit normals) at `points` to the widest angle `widest` from
/// `axis` ([`Widest::add`]) and to `acc`, in order; false (and stops) at a zero normal.
fn add_candidates(widest: &mut Widest, axis: DVec3, pairs: &[[DVec3; 2]], points: &[Vec3], acc: &mut PlaneAcc) -> bool {
    for (&pair, &point) in pairs.iter().zip(points) {
        for n in pair {
            if n == DVec3::ZERO {
                return false;
            }
            widest.add(axis, n);
        }
        acc.add(pair, point);
    }
    true
}

/// [`add_candidates`] on the candidates in whole groups of 4, with AVX: the candidates processed
/// (`None` at a zero normal, where the plain loop gives up too). The dot products with the axis
/// are taken 4 at a time and a group goes through [`Widest::add`] one by one only where one of
/// them reaches the smallest so far: elsewhere `add` would change nothing, so the widest angle is
/// the plain loop's bit for bit. The planes' offsets and reach take 4-lane minima and maxima,
/// joined at the end: the same values in any order, but for the sign of a zero, which
/// [`PlaneAcc::finish`] makes +0. The products round as glam's, with no fused multiply-add.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[allow(unsafe_code)]
fn cone_and_planes_avx(
    axis: DVec3,
    pairs: &[[DVec3; 2]],
    points: &[Vec3],
    widest: &mut Widest,
    acc: &mut PlaneAcc,
) -> Option<usize> {
    use std::arch::x86_64::*;
    let splat = |x: f64| _mm256_set1_pd(x);
    let dot = |[ax, ay, az]: [__m256d; 3], [bx, by, bz]: [__m256d; 3]| {
        _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, bx), _mm256_mul_pd(ay, by)), _mm256_mul_pd(az, bz))
    };
    let zero = _mm256_setzero_pd();
    let is_zero = |[x, y, z]: [__m256d; 3]| {
        _mm256_and_pd(
            _mm256_and_pd(_mm256_cmp_pd::<_CMP_EQ_OQ>(x, zero), _mm256_cmp_pd::<_CMP_EQ_OQ>(y, zero)),
            _mm256_cmp_pd::<_CMP_EQ_OQ>(z, zero),
        )
    };
    let a = [splat(axis.x), splat(axis.y), splat(axis.z)];
    let p0 = [splat(acc.p0.x), splat(acc.p0.y), splat(acc.p0.z)];
    let (mut lo, mut hi, mut reach) = (splat(f64::INFINITY), splat(f64::NEG_INFINITY), zero);
    let n = pairs.len().min(points.len()) / 4 * 4;
    for (four, at) in pairs[..n].chunks_exact(4).zip(points[..n].chunks_exact(4)) {
        let lanes = |f: &dyn Fn(usize) -> f64| _mm256_setr_pd(f(0), f(1), f(2), f(3));
        let n1 = [lanes(&|k| four[k][0].x), lanes(&|k| four[k][0].y), lanes(&|k| four[k][0].z)];
        let n2 = [lanes(&|k| four[k][1].x), lanes(&|k| four[k][1].y), lanes(&|k| four[k][1].z)];
        if _mm256_movemask_pd(_mm256_or_pd(is_zero(n1), is_zero(n2))) != 0 {
            return None;
        }
        let near = splat(widest.cos_min);
        let close =
            _mm256_or_pd(_mm256_cmp_pd::<_CMP_LE_OQ>(dot(a, n1), near), _mm256_cmp_pd::<_CMP_LE_OQ>(dot(a, n2), near));
        if _mm256_movemask_pd(close) != 0 {
            for pair in four {
                widest.add(axis, pair[0]);
                widest.add(axis, pair[1]);
            }
        }
        // `point.as_dvec3() - p0`: the conversion is exact.
        let d = [
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].x)), p0[0]),
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].y)), p0[1]),
            _mm256_sub_pd(lanes(&|k| f64::from(at[k].z)), p0[2]),
        ];
        // Each new value first: `_mm256_min_pd(new, old)` keeps `old` where `new` is NaN, as
        // `f64::min` ignores a NaN.
        reach = _mm256_max_pd(dot(d, d), reach);
        for h in [dot(n1, d), dot(n2, d)] {
            lo = _mm256_min_pd(h, lo);
            hi = _mm256_max_pd(h, hi);
        }
    }
    let mut out = [[0f64; 4]; 3];
    for (v, o) in [lo, hi, reach].into_iter().zip(&mut out) {
        // SAFETY: `o` holds 4 f64s; the store is unaligned.
        unsafe { _mm256_storeu_pd(o.as_mut_ptr(), v) };
    }
    let [lo, hi, reach] = out;
    acc.lo = lo.into_iter().fold(acc.lo, f64::min);
    acc.hi = hi.into_iter().fold(acc.hi, f64::max);
    acc.reach_squared = reach.into_iter().fold(acc.reach_squared, f64::max);
    acc.count += n;
    Some(n)
}

/// Cone around the normalised mean of the unit normals of `pairs` (both of each, in order):
/// `[axis, sin α + margin]` with α measured from the `f32` axis, or a never-culled cone. The sum
/// is a plain loop over the pairs (the build runs this over every candidate at every level; the
/// Gauss map's widest angle was several times slower through a `flat_map` over pairs).
#[cfg(test)]
fn bounding_cone(pairs: &[[DVec3; 2]]) -> [f32; 4] {
    let mut sum = DVec3::ZERO;
    for &[a, b] in pairs {
        sum = sum + a + b;
    }
    if sum.length().is_nan() || sum.length() <= 1e-12 {
        return [0.0, 0.0, 1.0, NEVER_CULL];
    }
    let axis32 = sum.normalize().as_vec3();
    let axis = axis32.as_dvec3().normalize();
    let mut widest = Widest { cos_min: 1.0, angle: 0.0 };
    for n in pairs.iter().flatten().copied() {
        if n == DVec3::ZERO {
            return [axis32.x, axis32.y, axis32.z, NEVER_CULL];
        }
        // Exact angle only where it matters (the widest normal so far).
        widest.add(axis, n);
    }
    [axis32.x, axis32.y, axis32.z, sine_threshold(widest.angle, CONE_MARGIN).unwrap_or(NEVER_CULL)]
}

/// The exact anchored-cone test over the box corners (see the module docs: kept as a reference,
/// the query uses [`plane_culls`]).
#[cfg(test)]
fn box_culls(b: &[f32; 6], c: &[f32; 4], e: Vec3) -> bool {
    let s = c[3];
    let wx = [e.x - b[0], e.x - b[3]];
    let wy = [e.y - b[1], e.y - b[4]];
    let wz = [e.z - b[2], e.z - b[5]];
    let mut front = true;
    let mut back = true;
    for k in 0..8 {
        let (x, y, z) = (wx[k & 1], wy[(k >> 1) & 1], wz[k >> 2]);
        let t = c[0] * x + c[1] * y + c[2] * z;
        let r = s * (x * x + y * y + z * z).sqrt();
        front &= t > r;
        back &= t < -r;
    }
    front | back
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::measure::signed_uniform;

    /// The corner test agrees with dense sampling of the box and the cone.
    #[test]
    fn cull_test_is_conservative_on_samples() {
        let mut r = signed_uniform(99);
        let mut culled = 0;
        for _ in 0..3000 {
            let axis = Vec3::new(r(), r(), r()).normalize();
            let alpha = (r() * 0.5 + 0.5) * 1.2;
            let lo = Vec3::new(r(), r(), r());
            let hi = lo + Vec3::new(r().abs(), r().abs(), r().abs()) * 0.5;
            let b = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z];
            let c = [axis.x, axis.y, axis.z, alpha.sin() + 1e-5];
            let e = Vec3::new(r(), r(), r()) * 3.0;
            if !box_culls(&b, &c, e) {
                continue;
            }
            culled += 1;
            // Any normal inside the cone and any point in the box give the same sign.
            let mut sign = 0.0f32;
            for _ in 0..200 {
                let p = lo + (hi - lo) * Vec3::new(r() * 0.5 + 0.5, r() * 0.5 + 0.5, r() * 0.5 + 0.5);
                let tangent = axis.any_orthonormal_vector();
                let n = (axis * alpha.cos() * 1.0001
                    + tangent.rotate_towards(axis.cross(tangent), r() * 3.2) * alpha.sin())
                .normalize();
                let v = n.dot(e - p);
                assert!(v != 0.0);
                if sign == 0.0 {
                    sign = v.signum();
                }
                assert_eq!(sign, v.signum());
            }
        }
        assert!(culled > 100, "only {culled} culled");
    }
    /// Whenever the plane-offset test culls a node, the `f32` predicate rejects every candidate
    /// below it: random nodes of nearly coplanar faces (the case the test is for) and of scattered
    /// ones, eyes near and far.
    #[test]
    fn plane_test_is_conservative() {
        let mut r = signed_uniform(7);
        let (mut culled, mut tested) = (0, 0);
        for case in 0..400 {
            let axis = Vec3::new(r(), r(), r()).normalize();
            let spread = if case % 2 == 0 { 0.05 } else { 0.6 };
            let center = Vec3::new(r(), r(), r()) * 10.0;
            let size = 0.1 + r().abs();
            let (t1, t2) = axis.any_orthonormal_pair();
            // Candidates on a slightly bumpy patch through `center` with normals near `axis`.
            let n = 24;
            let mut normals = Vec::new();
            let mut points = Vec::new();
            for _ in 0..n {
                let v = center + (t1 * r() + t2 * r()) * size + axis * (r() * size * spread);
                let tilt = |r: &mut dyn FnMut() -> f32| (axis + (t1 * r() + t2 * r()) * spread).normalize();
                normals.push([tilt(&mut r), tilt(&mut r)]);
                points.push(v);
            }
            let b = bounding_box(points.iter().copied());
            let pairs: Vec<[DVec3; 2]> = normals.iter().map(|&n| unit_pair(n)).collect();
            let c = bounding_cone(&pairs);
            let p = PlaneBound::of(&pairs, &points, &b, &c);
            for k in 0..200 {
                let dir = Vec3::new(r(), r(), r()).normalize();
                let dist = if k % 2 == 0 { size * (0.01 + 3.0 * r().abs()) } else { 50.0 * r().abs() };
                let e = center + dir * dist;
                tested += 1;
                if !plane_culls(&b, &c, &p, e) {
                    continue;
                }
                culled += 1;
                for (nn, v) in normals.iter().zip(&points) {
                    let w = e - *v;
                    let (a1, a2) = (nn[0].dot(w), nn[1].dot(w));
                    assert!(a1 != 0.0 && a2 != 0.0 && (a1 > 0.0) == (a2 > 0.0), "case {case}: culled a silhouette");
                }
            }
        }
        assert!(culled > tested / 4, "only {culled} of {tested} culled");
    }
    /// The fused pass gives the cone and plane bound of the two passes apart, bit for bit: random
    /// patches of every spread (some past a hemisphere), with zero normals and repeated points.
    #[test]
    fn cone_and_planes_equal_the_two_passes() {
        let mut rng = drafter_core::rng::Rng::new(3);
        let mut never = 0;
        for case in 0..3000 {
            let axis = rng.direction_f32();
            let spread = [1e-4, 0.05, 0.6, 3.0][case % 4];
            let n = 1 + case % 40;
            let mut normals: Vec<[Vec3; 2]> =
                (0..n).map(|_| [0, 1].map(|_| (axis + rng.direction_f32() * spread).normalize_or_zero())).collect();
            let mut points: Vec<Vec3> = (0..n).map(|_| rng.direction_f32() * (1.0 + rng.unit_f32() * 1e3)).collect();
            if case % 97 == 0 {
                normals[n / 2][1] = Vec3::ZERO;
            }
            if case % 5 == 0 {
                points[0] = points[n - 1];
            }
            if case % 3 == 0 {
                // Candidates at the anchor: offsets of zero, -0.0 for normals with no positive
                // component (the four-lane path must keep the plain loop's zero).
                let centre = anchor(&bounding_box(points.iter().copied()));
                let at = (case / 3) % (n + 1);
                points.insert(at, centre);
                normals.insert(
                    at,
                    [Vec3::new(-0.6, -0.8, -0.0), (axis + rng.direction_f32() * spread).normalize_or_zero()],
                );
                points.push(centre);
                normals.push([(axis + rng.direction_f32() * spread).normalize_or_zero(), Vec3::new(0.0, 0.6, 0.8)]);
            }
            if case % 11 == 0 {
                // Every candidate at one point: every offset is a zero of either sign.
                // Normals with no positive component give -0.0, the others +0.0; all within a
                // narrow cone, so that the planes are used.
                points.iter_mut().for_each(|p| *p = Vec3::new(1.5, -2.0, 0.25));
                let (negative, mixed) = (Vec3::new(-0.48, -0.6, -0.64), Vec3::new(0.05, -0.6, -0.8).normalize());
                for (k, pair) in normals.iter_mut().enumerate() {
                    *pair = [0, 1].map(|side| if (k * 2 + side + case / 11) % 5 < 2 { negative } else { mixed });
                }
            }
            let pairs: Vec<[DVec3; 2]> = normals.iter().map(|&n| unit_pair(n)).collect();
            let b = bounding_box(points.iter().copied());
            let cone = bounding_cone(&pairs);
            let planes = PlaneBound::of(&pairs, &points, &b, &cone);
            let (fused_cone, fused_planes) = cone_and_planes(&pairs, &points, &b);
            assert_eq!(fused_cone.map(f32::to_bits), cone.map(f32::to_bits), "case {case}");
            assert_eq!(fused_planes.0.map(f32::to_bits), planes.0.map(f32::to_bits), "case {case}");
            never += usize::from(cone[3] >= 1.0);
        }
        assert!(never > 300 && never < 2500, "{never} never-culling cones");
    }
}
