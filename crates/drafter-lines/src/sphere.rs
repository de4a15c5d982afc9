//! Bounds on the sphere of normals that both hierarchies compute the same way: the widest angle
//! from a centre, the rounded sine threshold of a cap or cone, and the Fibonacci sphere of sampled
//! directions. The Gauss map's caps (`gauss/cap.rs`) and the cone BVH's cones
//! (`cone_bvh/bounds.rs`) are built on these, so that one rounding rule serves both.

use glam::{DVec3, Vec3};

use crate::ArraysError;

/// A threshold at or above which a cap or cone is never culled.
pub(crate) const NEVER_CULL: f32 = 2.0;

/// `x` rounded up to the nearest `f32`.
pub(crate) fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

/// `x` rounded down to the nearest `f32`.
pub(crate) fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

/// The stored threshold of a cap or cone whose widest angle from its centre is `angle`: `sin` of
/// the angle plus `margin`, rounded up, or `None` (never culled) from about a right angle on.
/// 1e-9 rad covers the rounding of atan2 itself.
pub(crate) fn sine_threshold(angle: f64, margin: f64) -> Option<f32> {
    let r = angle + 1e-9;
    if r >= std::f64::consts::FRAC_PI_2 - 1e-3 {
        return None;
    }
    Some(round_up(r.sin() + margin))
}

/// The unit centres of stored caps or cones `bounds` (`[x, y, z, threshold]` each, from the array
/// `array`): every value finite, and the centre of a bound that may cull (threshold below 1) of
/// unit length within 1e-6, normalised in `f64`.
pub(crate) fn stored_axes(bounds: &[[f32; 4]], array: &'static str) -> Result<Vec<DVec3>, ArraysError> {
    let mut axes = Vec::with_capacity(bounds.len());
    for (i, b) in bounds.iter().enumerate() {
        if b.iter().any(|x| !x.is_finite()) {
            return Err(ArraysError::Value { array, index: 4 * i, value: f64::NAN });
        }
        let axis = Vec3::new(b[0], b[1], b[2]).as_dvec3();
        if b[3] < 1.0 && (axis.length() - 1.0).abs() > 1e-6 {
            return Err(ArraysError::Value { array, index: 4 * i, value: axis.length() });
        }
        axes.push(axis.normalize_or_zero());
    }
    Ok(axes)
}

/// The smaller of two scores. Scores are never NaN (finite planes and points), and for those this
/// is `f64::min` up to the sign of a zero, which no comparison of scores sees; it compiles to one
/// `minsd` where `f64::min` adds a NaN fix-up of four instructions.
#[inline(always)]
pub(crate) fn min(a: f64, b: f64) -> f64 {
    if a < b { a } else { b }
}

/// Direction `k` of `count` on a Fibonacci sphere: fixed, evenly spread directions for estimating
/// a hierarchy's cost.
pub(crate) fn fibonacci_direction(k: u32, count: u32) -> Vec3 {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let z = 1.0 - 2.0 * (k as f32 + 0.5) / count as f32;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = golden * k as f32;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The running widest angle from a unit centre: the smallest dot product so far and the largest
/// exact angle (`atan2` of the cross and dot products, accurate at every size), measured only for
/// points near the smallest dot product, so that a node costs a few `atan2` calls instead of one
/// per point. Two rules take points: [`Widest::add_group`], the Gauss map's exact maximum, and
/// [`Widest::add`], the cone BVH's rule (a point measured where its dot product reaches the
/// smallest so far), whose stored cones depend on it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Widest {
    pub(crate) cos_min: f64,
    pub(crate) angle: f64,
}

impl Default for Widest {
    fn default() -> Self {
        Widest { cos_min: f64::INFINITY, angle: 0.0 }
    }
}

impl Widest {
    /// A dot product of unit vectors is off by at most a few ulp of 1; two points whose true
    /// angles are in the opposite order of their rounded dot products differ by less than this.
    pub(crate) const DOT_SLACK: f64 = 1e-15;

    /// Takes the points `point(k)` whose dot products with the centre `c` are `dots[k]`: the
    /// smallest dot product so far is lowered to theirs, and the exact angle of a point is
    /// measured only where its dot product is within [`Self::DOT_SLACK`] of that. A point outside
    /// has a dot product beyond the slack above the smallest one seen by then, which stays above
    /// the final smallest, so its angle is below that point's, which is measured: the widest angle
    /// is the maximum over every point whichever way the points are grouped.
    #[inline(always)]
    pub(crate) fn add_group(&mut self, c: DVec3, dots: &[f64], point: impl Fn(usize) -> DVec3) {
        let smallest = dots.iter().fold(f64::INFINITY, |m, &d| min(m, d));
        // (NaN compares false: nothing to take.)
        if smallest.is_nan() || smallest > self.cos_min + Self::DOT_SLACK {
            return;
        }
        self.cos_min = self.cos_min.min(smallest);
        let near = self.cos_min + Self::DOT_SLACK;
        for (k, &d) in dots.iter().enumerate() {
            if d <= near {
                self.angle = self.angle.max(c.cross(point(k)).length().atan2(d));
            }
        }
    }

    /// Takes the unit normal `n` seen from the unit `axis`: measured where its dot product is at
    /// most the smallest so far (the widest normal so far).
    #[inline(always)]
    pub(crate) fn add(&mut self, axis: DVec3, n: DVec3) {
        let d = axis.dot(n);
        if d <= self.cos_min {
            self.cos_min = d;
            self.angle = self.angle.max(axis.cross(n).length().atan2(d));
        }
    }
}
