//! The camera: a view direction from azimuth and elevation, fitted tightly around what must be seen.
//!
//! Gooch et al. (1999, §4.1) turn the *object* in front of a fixed viewer and light so that the
//! cool-to-warm shading sweeps the whole surface. For one frame that is the same as orbiting the
//! camera with the light fixed to it, which is what this module does: the key light is constant in
//! view space ([`LIGHT_IN_VIEW`]).

use glam::{Mat4, Vec3, Vec4Swizzles};

use crate::style::View;

/// Direction towards the key light in view space (x right, y up, z towards the viewer): up and to
/// the right of the viewer, as in Gooch et al. 1999, Fig. 5.
pub const LIGHT_IN_VIEW: Vec3 = Vec3::new(0.40, 0.72, 0.56);

/// Margin around the fitted points, as a factor of their extent.
pub const FIT_MARGIN: f32 = 1.06;

/// A fitted camera. All positions are in render space (see [`crate::Model::origin`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub view_from_render: Mat4,
    pub clip_from_view: Mat4,
    pub position_in_render: Vec3,
    pub orthographic: bool,
    /// Near and far planes (view units), bracketing every fitted point.
    pub near: f32,
    pub far: f32,
}

impl Camera {
    /// Fits a camera looking from `view` at `points` so that all of them are inside the frame with
    /// [`FIT_MARGIN`]. `aspect` is width / height.
    pub fn fit(points: &[Vec3], view: View, aspect: f32, orthographic: bool, fov_y_deg: f32) -> Camera {
        let rotation = view_rotation(view);
        let rotated: Vec<Vec3> = points.iter().map(|p| rotation.transform_vector3(*p)).collect();
        let (lo, hi) = rotated
            .iter()
            .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let (lo, hi) = if lo.x <= hi.x { (lo, hi) } else { (Vec3::splat(-1.0), Vec3::splat(1.0)) };
        let extent = (hi - lo).max(Vec3::splat(1e-6));
        let radius = extent.length() * 0.5;
        let cx = (lo.x + hi.x) * 0.5;
        let cy = (lo.y + hi.y) * 0.5;

        let (eye, clip_from_view, near, far) = if orthographic {
            let mut half_w = extent.x * 0.5 * FIT_MARGIN;
            let mut half_h = extent.y * 0.5 * FIT_MARGIN;
            if half_w / half_h > aspect {
                half_h = half_w / aspect;
            } else {
                half_w = half_h * aspect;
            }
            let z = hi.z + radius;
            let near = radius * 0.5;
            let far = z - lo.z + radius * 0.5;
            let proj = glam::camera::rh::proj::directx::orthographic(-half_w, half_w, -half_h, half_h, near, far);
            (Vec3::new(cx, cy, z), proj, near, far)
        } else {
            let tan_y = (fov_y_deg.to_radians() * 0.5).tan();
            let tan_x = tan_y * aspect;
            // The distance that fits every point around (cx, cy), then (cx, cy) moved to centre the
            // projected extent (nearer points spread further), a few times.
            let (mut cx, mut cy) = (cx, cy);
            let fit_z = |cx: f32, cy: f32| {
                rotated
                    .iter()
                    .map(|q| {
                        let need_x = (q.x - cx).abs() * FIT_MARGIN / tan_x;
                        let need_y = (q.y - cy).abs() * FIT_MARGIN / tan_y;
                        q.z + need_x.max(need_y)
                    })
                    .fold(hi.z + radius * 1e-3, f32::max)
            };
            let mut z = fit_z(cx, cy);
            for _ in 0..4 {
                let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
                for q in &rotated {
                    let depth = z - q.z;
                    let (x, y) = ((q.x - cx) / (depth * tan_x), (q.y - cy) / (depth * tan_y));
                    (x_lo, x_hi, y_lo, y_hi) = (x_lo.min(x), x_hi.max(x), y_lo.min(y), y_hi.max(y));
                }
                let depth = z - (lo.z + hi.z) * 0.5;
                cx += (x_lo + x_hi) * 0.5 * depth * tan_x;
                cy += (y_lo + y_hi) * 0.5 * depth * tan_y;
                z = fit_z(cx, cy);
            }
            let near = ((z - hi.z) * 0.9).max(radius * 1e-3);
            let far = (z - lo.z) * 1.1 + radius * 1e-3;
            let proj = glam::camera::rh::proj::directx::perspective(fov_y_deg.to_radians(), aspect, near, far);
            (Vec3::new(cx, cy, z), proj, near, far)
        };
        let view_from_render = Mat4::from_translation(-eye) * rotation;
        let position_in_render = rotation.inverse().transform_point3(eye);
        Camera { view_from_render, clip_from_view, position_in_render, orthographic, near, far }
    }

    /// The same camera with the image magnified by `zoom` about the frame's centre, then shifted by
    /// `pan` in normalised device units (a zoom lens and a lens shift: the eye does not move).
    pub fn zoomed(mut self, zoom: f32, pan: [f32; 2]) -> Camera {
        let shift = Mat4::from_translation(Vec3::new(pan[0], pan[1], 0.0));
        self.clip_from_view = shift * Mat4::from_scale(Vec3::new(zoom, zoom, 1.0)) * self.clip_from_view;
        self
    }

    pub fn clip_from_render(&self) -> Mat4 {
        self.clip_from_view * self.view_from_render
    }

    /// The key light direction in render space.
    pub fn light_in_render(&self) -> Vec3 {
        self.view_from_render.inverse().transform_vector3(LIGHT_IN_VIEW.normalize())
    }

    /// Distance from the camera to a render-space point along the view axis.
    pub fn view_depth(&self, position_in_render: Vec3) -> f32 {
        -(self.view_from_render * position_in_render.extend(1.0)).xyz().z
    }
}

/// The rotation taking render space to view orientation for `view` (camera looking at the origin
/// from azimuth/elevation, +y up).
pub fn view_rotation(view: View) -> Mat4 {
    let (az, el) = (view.azimuth_deg.to_radians(), view.elevation_deg.to_radians());
    let towards_eye = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    glam::camera::rh::view::look_to_mat4(Vec3::ZERO, -towards_eye, Vec3::Y)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners() -> Vec<Vec3> {
        (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 == 0 { -2.0 } else { 2.0 },
                    if i & 2 == 0 { -0.5 } else { 0.5 },
                    if i & 4 == 0 { -1.0 } else { 1.0 },
                )
            })
            .collect()
    }

    #[test]
    fn fitted_points_are_inside_the_frame_and_depth_range() {
        for ortho in [false, true] {
            for (az, el) in [(0.0, 0.0), (35.0, 25.0), (-120.0, 60.0), (200.0, -30.0)] {
                let cam = Camera::fit(&corners(), View { azimuth_deg: az, elevation_deg: el }, 4.0 / 3.0, ortho, 30.0);
                let clip = cam.clip_from_render();
                let mut max_ndc = 0.0f32;
                for p in corners() {
                    let c = clip * p.extend(1.0);
                    let ndc = c.xyz() / c.w;
                    assert!(ndc.z > 0.0 && ndc.z < 1.0, "{ortho} {az} {el}: depth {}", ndc.z);
                    max_ndc = max_ndc.max(ndc.x.abs()).max(ndc.y.abs());
                }
                assert!(max_ndc <= 1.0 && max_ndc > 0.8, "{ortho} {az} {el}: {max_ndc}");
            }
        }
    }

    #[test]
    fn azimuth_zero_looks_down_minus_z() {
        let cam = Camera::fit(&corners(), View { azimuth_deg: 0.0, elevation_deg: 0.0 }, 1.0, false, 30.0);
        assert!(cam.position_in_render.z > 1.0 && cam.position_in_render.x.abs() < 1e-4);
        assert!(cam.view_depth(Vec3::ZERO) > 0.0);
        // The light is above the horizon.
        assert!(cam.light_in_render().y > 0.5);
    }
}
