//! Gradient projectors (Lux et al. 2013, §3 "Projector Parametrization"; ../shared/papers/000_*).
//!
//! A projector `P = (a, d, s)` places a 1D gradient on a part: anchor `a` (world space), unit direction
//! `d`, and length `s`. The paper derives the initial projector from a bounding volume: anchor = box
//! centre, direction = the box's longest axis, turned to face away from the scene centre "where the
//! geometric symmetry of an object should be maintained", scale = the box's extent along it
//! ([`Projector::from_obb`]). Unlike the paper, which keeps `s ∈ [0, 1]` as a relative length, `scale`
//! here is in world units: the full extent of the box along `d`.
//!
//! # The matrix
//! The paper composes `M := V·P·R` (OpenSceneGraph's row-vector convention, `v' = v·M`): orientation `V`,
//! orthographic projection `P`, and the bias `R` that maps [−1, 1] to [0, 1]. Its printed matrices are
//! garbled in the available text, so here is the construction used, in glam's column-vector convention
//! (`v' = M·v`, hence the reversed product `M = R · P · V`):
//! * `V` (view): rows `d, t, b` and translation `−(d·a, t·a, b·a)`, i.e. world → projector frame with the
//!   anchor at the origin; `t` is a unit vector perpendicular to `d` (the world axis least aligned with
//!   `d`, made orthogonal: deterministic) and `b = d × t`;
//! * `P` (orthographic): uniform scale `2/s`, so the slab `|d·(x − a)| ≤ s/2` maps to [−1, 1];
//! * `R` (bias): `x ↦ x/2 + 1/2` on the first three coordinates.
//!
//! `M · (x, 1) = (p, t, r, 1)` with `p = 1/2 + d·(x − a)/s`: 0 at the box face behind the anchor, 1 at
//! the face in front, which is what the gradient function reads. `t` and `r` are the same orthographic
//! mapping across (a cube of side `s` around the anchor maps to the unit cube); the gradient ignores
//! them. A projector with `scale` ≈ 0 (a point-like part) maps everything to `p = 1/2`.

use glam::{DMat4, DVec3, DVec4, Mat4};
use serde::{Deserialize, Serialize};

use crate::error::ParamError;
use crate::linalg::frame_from_direction;
use crate::obb::Obb;

/// `R`: maps clip-style [−1, 1] to texture-style [0, 1] on x, y, z.
pub const BIAS_MATRIX: DMat4 = DMat4::from_cols(
    DVec4::new(0.5, 0.0, 0.0, 0.0),
    DVec4::new(0.0, 0.5, 0.0, 0.0),
    DVec4::new(0.0, 0.0, 0.5, 0.0),
    DVec4::new(0.5, 0.5, 0.5, 1.0),
);

/// A gradient projector `(anchor, direction, scale)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Projector {
    /// Where the gradient is centred (`p = 1/2`), world space.
    pub anchor: DVec3,
    /// Unit direction in which `p` grows, world space.
    pub direction: DVec3,
    /// Length over which `p` goes from 0 to 1, world units (≥ 0).
    pub scale: f64,
}

/// The initial projector's sign rule (Lux et al. 2013, §3): `axis` or its opposite, whichever points
/// away from the scene centre, `offset` being the part's centre minus the scene's; within `1e-12`
/// of `|offset| + size` of perpendicular (a part at the centre, an axis across the offset) `axis`
/// keeps its own sign. The bake's projectors and the viewer's stand-in for an unbaked part both use
/// it.
pub fn facing_away(axis: DVec3, offset: DVec3, size: f64) -> DVec3 {
    let tolerance = 1e-12 * (offset.length() + size);
    if axis.dot(offset) < -tolerance { -axis } else { axis }
}

impl Projector {
    /// The paper's initial projector for a part with box `obb` in a scene centred at `scene_center`:
    /// anchor = box centre, direction = longest box axis (`obb.axes[0]`) with the sign that points away
    /// from the scene centre, scale = the box's extent along it. When the box centre is (within 1e-12 of
    /// the box size) at the scene centre or the axis is perpendicular to the offset, the box's canonical
    /// sign is kept (largest world component positive).
    pub fn from_obb(obb: &Obb, scene_center: DVec3) -> Self {
        let scale = 2.0 * obb.half_extents.x;
        let direction = facing_away(obb.axes[0], obb.center - scene_center, scale);
        Self { anchor: obb.center, direction, scale }
    }

    /// Checks that the anchor is finite, the direction is a unit vector (within 1e-6) and the scale
    /// finite and ≥ 0.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !self.anchor.is_finite() {
            return Err(ParamError { name: "anchor", value: format!("{:?}", self.anchor), expected: "finite" });
        }
        if !self.direction.is_finite() || (self.direction.length() - 1.0).abs() > 1e-6 {
            return Err(ParamError {
                name: "direction",
                value: format!("{:?}", self.direction),
                expected: "a unit vector",
            });
        }
        if !self.scale.is_finite() || self.scale < 0.0 {
            return Err(ParamError { name: "scale", value: format!("{}", self.scale), expected: "finite and >= 0" });
        }
        Ok(())
    }

    /// Whether the projector gives no gradient: a scale at or below 1e-12 of the anchor's largest
    /// coordinate (or not finite) makes [`Self::matrix`] map every point to the same `p`, and an
    /// anchor or scale beyond `f32` gives matrix entries a renderer cannot hold.
    pub fn is_degenerate(&self) -> bool {
        let fits_f32 = self.anchor.as_vec3().is_finite() && (self.scale as f32).is_finite();
        self.inverse_scale() == 0.0 || !fits_f32 || !self.matrix_f32().is_finite()
    }

    /// `1/s`, or 0 for a degenerate scale (≤ 1e-12 of the anchor's magnitude, or not finite).
    fn inverse_scale(&self) -> f64 {
        let floor = 1e-12 * self.anchor.abs().max_element().max(1e-300);
        if self.scale.is_finite() && self.scale > floor { 1.0 / self.scale } else { 0.0 }
    }

    /// The frame `[d, t, b]` of the view matrix (`d` normalised).
    pub fn frame(&self) -> [DVec3; 3] {
        frame_from_direction(self.direction.normalize_or(DVec3::X))
    }

    /// `V`: world → projector frame (rows `d, t, b`), anchor at the origin.
    pub fn view_matrix(&self) -> DMat4 {
        let [d, t, b] = self.frame();
        let rows = DMat4::from_cols(d.extend(0.0), t.extend(0.0), b.extend(0.0), DVec4::W).transpose();
        rows * DMat4::from_translation(-self.anchor)
    }

    /// `P`: orthographic projection, uniform scale `2/s` (zero for a degenerate scale).
    pub fn ortho_matrix(&self) -> DMat4 {
        DMat4::from_scale(DVec3::splat(2.0 * self.inverse_scale()))
    }

    /// `M = R · P · V`: world position → `(p, t, r, 1)`.
    pub fn matrix(&self) -> DMat4 {
        BIAS_MATRIX * self.ortho_matrix() * self.view_matrix()
    }

    /// [`Self::matrix`] in f32 (for a shader that receives world positions).
    pub fn matrix_f32(&self) -> Mat4 {
        self.matrix().as_mat4()
    }

    /// `M · world_from_object` in f32, for a shader that receives object-space positions: the product is
    /// formed in f64, so a part far from the origin keeps its precision.
    pub fn matrix_for_object(&self, world_from_object: &DMat4) -> Mat4 {
        (self.matrix() * *world_from_object).as_mat4()
    }

    /// The gradient coordinate `p = 1/2 + d·(x − a)/s` of a world position (not clamped).
    pub fn coordinate(&self, position_in_world: DVec3) -> f64 {
        let d = self.direction.normalize_or(DVec3::X);
        0.5 + d.dot(position_in_world - self.anchor) * self.inverse_scale()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::obb::ObbMethod;

    fn test_obb(center: DVec3, axes: [DVec3; 3], half: DVec3) -> Obb {
        Obb { center, axes, half_extents: half, volume: 8.0 * half.x * half.y * half.z, method: ObbMethod::Optimal }
    }

    #[test]
    fn degenerate_projectors_are_told_apart() {
        let obb = test_obb(DVec3::new(3.0, -1.0, 2.0), [DVec3::X, DVec3::Y, DVec3::Z], DVec3::new(2.0, 1.0, 0.5));
        let fitted = Projector::from_obb(&obb, DVec3::ZERO);
        assert!(!fitted.is_degenerate());
        assert!(!Projector { anchor: DVec3::new(1e30, 0.0, 0.0), scale: 1e20, ..fitted }.is_degenerate());
        for bad in [
            Projector { anchor: DVec3::new(1e300, 0.0, 0.0), ..fitted },
            Projector { anchor: DVec3::new(0.0, 1e39, 0.0), scale: 1e30, ..fitted },
            Projector { scale: 0.0, ..fitted },
            Projector { scale: 1e-300, ..fitted },
            Projector { scale: 1e39, ..fitted },
            Projector { scale: f64::NAN, ..fitted },
        ] {
            assert!(bad.is_degenerate(), "{bad:?}");
        }
    }

    #[test]
    fn matrix_maps_box_ends_to_zero_and_one() {
        let axes = crate::linalg::orthonormalize([DVec3::new(1.0, 2.0, 0.5), DVec3::new(-2.0, 1.0, 0.3), DVec3::ZERO]);
        let axes = [axes[0], axes[1], axes[0].cross(axes[1])];
        let obb = test_obb(DVec3::new(3.0, -1.0, 2.0), axes, DVec3::new(2.0, 1.0, 0.5));
        let proj = Projector::from_obb(&obb, DVec3::ZERO);
        proj.validate().unwrap();
        assert!(proj.direction.dot(obb.center) > 0.0, "faces away from the scene centre");
        let m = proj.matrix();
        let front = obb.center + proj.direction * 2.0;
        let back = obb.center - proj.direction * 2.0;
        assert!((m.transform_point3(front).x - 1.0).abs() < 1e-12);
        assert!(m.transform_point3(back).x.abs() < 1e-12);
        assert!((m.transform_point3(obb.center).x - 0.5).abs() < 1e-12);
        // p along the direction only: moving across does not change it
        let across = obb.center + axes[1] * 0.7 + axes[2] * 0.2;
        assert!((m.transform_point3(across).x - 0.5).abs() < 1e-12);
        assert!((proj.coordinate(front) - 1.0).abs() < 1e-12);
        // the composition equals the documented product and is affine
        let row3 = m.row(3);
        assert_eq!(row3, DVec4::W);
        let f = proj.matrix_f32();
        assert!((f.transform_point3(front.as_vec3()).x - 1.0).abs() < 1e-5);
    }

    #[test]
    fn direction_flips_to_face_away_and_degenerate_scale() {
        let obb = test_obb(DVec3::new(-5.0, 0.0, 0.0), [DVec3::X, DVec3::Y, DVec3::Z], DVec3::new(1.0, 0.5, 0.5));
        let proj = Projector::from_obb(&obb, DVec3::ZERO);
        assert_eq!(proj.direction, -DVec3::X);
        let at_centre = Projector::from_obb(&obb, obb.center);
        assert_eq!(at_centre.direction, DVec3::X);
        let point = test_obb(DVec3::new(1e6, 0.0, 0.0), [DVec3::X, DVec3::Y, DVec3::Z], DVec3::ZERO);
        let proj = Projector::from_obb(&point, DVec3::ZERO);
        let m = proj.matrix();
        assert!(m.is_finite());
        assert_eq!(m.transform_point3(DVec3::new(7.0, 8.0, 9.0)).x, 0.5);
    }

    #[test]
    fn object_matrix_keeps_precision_far_from_origin() {
        let obb = test_obb(DVec3::new(1e6, 2e6, -3e6), [DVec3::X, DVec3::Y, DVec3::Z], DVec3::new(0.01, 0.005, 0.001));
        let proj = Projector::from_obb(&obb, DVec3::ZERO);
        let world_from_object = DMat4::from_translation(obb.center);
        let m = proj.matrix_for_object(&world_from_object);
        // object-space point at the front face
        let p = m.transform_point3(glam::Vec3::new(0.01, 0.0, 0.0));
        assert!((p.x - 1.0).abs() < 1e-5, "{}", p.x);
    }
}
