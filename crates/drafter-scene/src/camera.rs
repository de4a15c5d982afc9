//! The camera: a view direction from azimuth and elevation, fitted tightly around what must be seen.
//!
//! Gooch et al. (1999, §4.1) turn the *object* in front of a fixed viewer and light so that the
//! cool-to-warm shading sweeps the whole surface. For one frame that is the same as orbiting the
//! camera with the light fixed to it, which is what this module does: the key light is constant in
//! view space ([`LIGHT_IN_VIEW`]).

use glam::{DVec3, Mat4, Vec3, Vec4Swizzles};

use crate::style::View;

/// Direction towards the key light in view space (x right, y up, z towards the viewer): up and to
/// the right of the viewer, as in Gooch et al. 1999, Fig. 5.
pub const LIGHT_IN_VIEW: Vec3 = Vec3::new(0.40, 0.72, 0.56);

/// Share of the frame left empty around the fitted points, across their larger relative side
/// (half of it on each side): their projected bounding rectangle is centred and its width spans
/// `1 − FIT_MARGIN` of the frame's width, or its height of the frame's height, whichever is the
/// larger share.
pub const FIT_MARGIN: f32 = 0.06;

/// How many directions [`hull_sample`] keeps a point set's extreme points along (at most this
/// many points are kept).
pub const SUPPORT_DIRECTIONS: usize = 1024;

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
    /// Fits a camera looking from `view` at `points`: their projected bounding rectangle is
    /// centred in the frame and fills it up to [`FIT_MARGIN`] (see there). `aspect` is width /
    /// height.
    ///
    /// # How it works
    /// In the view's orientation (camera looking down −z from `(cx, cy, z)`), orthographic is the
    /// points' box scaled to the frame. In perspective a point `q` is at
    /// `x = (q.x − cx) / ((z − q.z) tan_x)`, so it stays inside the band `|x| ≤ f` (`f = 1 −
    /// FIT_MARGIN`) when `q.x + a q.z ≤ cx + a z` and `−q.x + a q.z ≤ −cx + a z` with `a = f
    /// tan_x`: the frustum's side planes touch the points when `z = (R + L) / 2a`, `R = max(q.x +
    /// a q.z)`, `L = max(−q.x + a q.z)`, and the same in y. The eye takes the farther of the two
    /// distances, so the limiting axis fills `f` exactly; then each axis is centred at that
    /// distance by bisection on `cx` (resp. `cy`), where the largest projection to the right
    /// minus the largest to the left decreases monotonically.
    pub fn fit(points: &[Vec3], view: View, aspect: f32, orthographic: bool, fov_y_deg: f32) -> Camera {
        let rotation = view_rotation(view);
        let rotated: Vec<DVec3> = points.iter().map(|p| rotation.transform_vector3(*p).as_dvec3()).collect();
        let (lo, hi) =
            rotated.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let (lo, hi) = if lo.x <= hi.x { (lo, hi) } else { (DVec3::splat(-1.0), DVec3::splat(1.0)) };
        let extent = (hi - lo).max(DVec3::splat(1e-6));
        let radius = extent.length() * 0.5;
        let fill = f64::from(1.0 - FIT_MARGIN);
        let aspect = f64::from(aspect);

        let (eye, clip_from_view, near, far) = if orthographic {
            let mut half_w = extent.x * 0.5 / fill;
            let mut half_h = extent.y * 0.5 / fill;
            if half_w / half_h > aspect {
                half_h = half_w / aspect;
            } else {
                half_w = half_h * aspect;
            }
            let z = hi.z + radius;
            let near = radius * 0.5;
            let far = z - lo.z + radius * 0.5;
            let proj = glam::camera::rh::proj::directx::orthographic(
                -half_w as f32,
                half_w as f32,
                -half_h as f32,
                half_h as f32,
                near as f32,
                far as f32,
            );
            (DVec3::new((lo.x + hi.x) * 0.5, (lo.y + hi.y) * 0.5, z), proj, near, far)
        } else {
            let tan_y = (f64::from(fov_y_deg).to_radians() * 0.5).tan();
            let tan_x = tan_y * aspect;
            // The eye distance at which the frustum's two side planes of one axis touch the points.
            let touching = |axis: fn(&DVec3) -> f64, slope: f64| {
                let (mut plus, mut minus) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
                for q in &rotated {
                    plus = plus.max(axis(q) + slope * q.z);
                    minus = minus.max(-axis(q) + slope * q.z);
                }
                (plus + minus) / (2.0 * slope)
            };
            let z = touching(|q| q.x, fill * tan_x)
                .max(touching(|q| q.y, fill * tan_y))
                // Points on a line through the eye would have no depth: keep the eye in front.
                .max(hi.z + radius * 1e-3);
            // The centre of one axis at distance z: the largest projection on the positive side
            // equals the largest on the negative side.
            let centre = |axis: fn(&DVec3) -> f64, mut low: f64, mut high: f64| {
                for _ in 0..64 {
                    let c = 0.5 * (low + high);
                    let (mut plus, mut minus) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
                    for q in &rotated {
                        let depth = z - q.z;
                        plus = plus.max((axis(q) - c) / depth);
                        minus = minus.max((c - axis(q)) / depth);
                    }
                    if plus > minus {
                        low = c;
                    } else {
                        high = c;
                    }
                }
                0.5 * (low + high)
            };
            let (cx, cy) = (centre(|q| q.x, lo.x, hi.x), centre(|q| q.y, lo.y, hi.y));
            let near = ((z - hi.z) * 0.9).max(radius * 1e-3);
            let far = (z - lo.z) * 1.1 + radius * 1e-3;
            let proj = glam::camera::rh::proj::directx::perspective(
                fov_y_deg.to_radians(),
                aspect as f32,
                near as f32,
                far as f32,
            );
            (DVec3::new(cx, cy, z), proj, near, far)
        };
        let eye = eye.as_vec3();
        let view_from_render = Mat4::from_translation(-eye) * rotation;
        let position_in_render = rotation.inverse().transform_point3(eye);
        Camera {
            view_from_render,
            clip_from_view,
            position_in_render,
            orthographic,
            near: near as f32,
            far: far as f32,
        }
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

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice).
pub fn sphere_directions(n: usize) -> Vec<Vec3> {
    let golden_angle = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden_angle * i as f32;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// Indices (ascending, each once) of the points of `points` that lie farthest along one of
/// `directions`: vertices of the points' convex hull, whose projection bounds the projection of
/// all of them up to the spacing of the directions.
///
/// How much the kept points' extent along a direction `u` can fall short of all points': with
/// `d` the nearest of `directions` at angle `θ`, at most `sin θ` times the points' diameter in
/// general, and `r (1 − cos θ)` for a sphere or the round parts of CAD models (cylinders,
/// fillets) of radius `r`.
///
/// Equal to scanning every point for every direction (the farthest, the first of equals), which
/// on a large scan would cost a noticeable part of the load: the points are bucketed into a grid
/// of cells, each bounded by a sphere around its points, the cells into blocks of 4³ bounded by
/// spheres around theirs; for each direction the blocks are visited farthest reach first, and a
/// block or cell is scanned only while its sphere reaches the farthest point found so far (with a
/// margin far above `f32` rounding), so a direction costs a sort of the blocks and a few cells.
/// Hand-written: no crate does support queries with ties resolved this way.
pub fn support_points(points: &[Vec3], directions: &[Vec3]) -> Vec<usize> {
    const GRID: usize = 16;
    const BLOCK: usize = 4;
    if points.is_empty() {
        return Vec::new();
    }
    let along = |p: &Vec3, d: Vec3| p.x * d.x + p.y * d.y + p.z * d.z;
    // Cells of a GRID³ grid over the finite points' box (stable: ascending indices in a cell);
    // non-finite points share one more cell, always scanned.
    let (lo, hi) = points
        .iter()
        .filter(|p| p.is_finite())
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let scale = Vec3::splat(GRID as f32) / (hi - lo);
    let cell_of = |p: &Vec3| {
        if !p.is_finite() {
            return GRID * GRID * GRID;
        }
        // `as` saturates (a flat axis gives NaN, read as 0).
        let c = ((*p - lo) * scale).to_array().map(|x| (x as usize).min(GRID - 1));
        (c[2] * GRID + c[1]) * GRID + c[0]
    };
    let cells: Vec<usize> = points.iter().map(cell_of).collect();
    let mut starts = vec![0usize; GRID * GRID * GRID + 2];
    for &c in &cells {
        starts[c + 1] += 1;
    }
    for k in 1..starts.len() {
        starts[k] += starts[k - 1];
    }
    let mut next = starts.clone();
    let mut sorted = vec![0u32; points.len()];
    for (i, &c) in cells.iter().enumerate() {
        sorted[next[c]] = i as u32;
        next[c] += 1;
    }
    // Per occupied cell: its points, centre and reach along any direction (radius plus a
    // rounding margin far above f32 rounding), grouped by the block of BLOCK³ cells it lies in.
    // The non-finite points' cell is scanned for every direction.
    // A cell: its points, its centre and its reach.
    type Cell<'a> = (&'a [u32], Vec3, f32);
    const BLOCKS: usize = GRID / BLOCK;
    let mut unbounded: &[u32] = &[];
    let mut blocks: Vec<Vec<Cell>> = vec![Vec::new(); BLOCKS * BLOCKS * BLOCKS];
    for (cell, w) in starts.windows(2).enumerate().filter(|(_, w)| w[1] > w[0]) {
        let ids = &sorted[w[0]..w[1]];
        if cell == GRID * GRID * GRID {
            unbounded = ids;
            continue;
        }
        let (a, b) = ids
            .iter()
            .map(|&i| points[i as usize])
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), p| (a.min(p), b.max(p)));
        let centre = (a + b) * 0.5;
        let radius = ids.iter().map(|&i| (points[i as usize] - centre).length()).fold(0.0f32, f32::max);
        let margin = 1e-5 * (centre.length() + radius) + f32::MIN_POSITIVE;
        let (x, y, z) = (cell % GRID / BLOCK, cell / GRID % GRID / BLOCK, cell / (GRID * GRID) / BLOCK);
        blocks[(z * BLOCKS + y) * BLOCKS + x].push((ids, centre, radius + margin));
    }
    // Per occupied block: its cells and a sphere around their spheres, the reach again with a
    // margin of its own.
    let blocks: Vec<(Vec<Cell>, Vec3, f32)> = blocks
        .into_iter()
        .filter(|cells| !cells.is_empty())
        .map(|cells| {
            let (a, b) = cells
                .iter()
                .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), &(_, c, r)| (a.min(c - r), b.max(c + r)));
            let centre = (a + b) * 0.5;
            let radius = cells.iter().map(|&(_, c, r)| (c - centre).length() + r).fold(0.0f32, f32::max);
            let reach = radius + 1e-5 * (centre.length() + radius) + f32::MIN_POSITIVE;
            (cells, centre, reach)
        })
        .collect();
    let mut reach: Vec<f32> = Vec::with_capacity(blocks.len());
    let mut indices: Vec<usize> = directions
        .iter()
        .map(|&d| {
            let (mut best, mut arg) = (f32::NEG_INFINITY, usize::MAX);
            let scan = |ids: &[u32], best: &mut f32, arg: &mut usize| {
                for &i in ids {
                    let x = along(&points[i as usize], d);
                    if x > *best || (x == *best && *best > f32::NEG_INFINITY && (i as usize) < *arg) {
                        (*best, *arg) = (x, i as usize);
                    }
                }
            };
            scan(unbounded, &mut best, &mut arg);
            // The block that reaches farthest along `d` first, then every other that can still
            // reach the farthest point found; inside them, only cells that can. Every point of a
            // skipped block or cell lies short of a point already found, so the answer is the
            // full scan's, ties included. (A reach that overflowed to NaN is scanned.)
            reach.clear();
            reach.extend(blocks.iter().map(|&(_, c, r)| along(&c, d) + r));
            let first = (0..blocks.len()).fold(0, |k, j| if reach[j] > reach[k] || reach[j].is_nan() { j } else { k });
            let others = (0..blocks.len()).filter(|&k| k != first);
            for k in (!blocks.is_empty()).then_some(first).into_iter().chain(others) {
                if reach[k] < best {
                    continue;
                }
                for &(ids, c, r) in &blocks[k].0 {
                    if along(&c, d) + r >= best || (along(&c, d) + r).is_nan() {
                        scan(ids, &mut best, &mut arg);
                    }
                }
            }
            // No point compares (all non-finite): the scan's answer is the first point.
            if arg == usize::MAX { 0 } else { arg }
        })
        .collect();
    indices.sort_unstable();
    indices.dedup();
    indices
}

/// Indices of at most [`SUPPORT_DIRECTIONS`] points of `points` whose projection in any
/// direction bounds theirs closely: all of them when there are no more, otherwise their
/// [`support_points`] along as many [`sphere_directions`] (every direction within 4.8° of one of
/// them). The kept points' extent falls short of the full extent by about `r (1 − cos θ)` on
/// round shapes and more at a cylinder's flat ends, well inside [`FIT_MARGIN`] either way
/// (`support_points_bound_the_projection_of_round_parts` holds it under 1.5 % of the radius).
///
/// What the camera frames. An affine map takes hull vertices to hull vertices, so a mesh's
/// sample, computed once, serves every instance of it; the union over instances is sampled
/// again, so a frame's fit costs the same for any model size.
pub fn hull_sample(points: &[Vec3]) -> Vec<usize> {
    if points.len() <= SUPPORT_DIRECTIONS {
        return (0..points.len()).collect();
    }
    support_points(points, &sphere_directions(SUPPORT_DIRECTIONS))
}

/// Where `camera` looks from, in world space (the render space's `origin` added back in f64).
pub fn world_view(camera: &Camera, origin: glam::DVec3) -> crate::edges::WorldView {
    if camera.orthographic {
        let direction = camera.view_from_render.inverse().transform_vector3(Vec3::NEG_Z);
        crate::edges::WorldView::Orthographic { direction: direction.as_dvec3() }
    } else {
        crate::edges::WorldView::Perspective { eye: camera.position_in_render.as_dvec3() + origin }
    }
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

    /// [`support_points`] by scanning every point for every direction.
    fn support_points_by_scan(points: &[Vec3], directions: &[Vec3]) -> Vec<usize> {
        let mut indices: Vec<usize> = directions
            .iter()
            .map(|d| {
                let (mut best, mut arg) = (f32::NEG_INFINITY, 0usize);
                for (i, p) in points.iter().enumerate() {
                    let x = p.x * d.x + p.y * d.y + p.z * d.z;
                    if x > best {
                        (best, arg) = (x, i);
                    }
                }
                arg
            })
            .collect();
        indices.sort_unstable();
        indices.dedup();
        indices
    }

    #[test]
    fn support_points_equal_a_scan_of_every_point() {
        let mut rng = drafter_core::rng::Rng::new(214);
        let mut r = || rng.signed_f32();
        let directions = sphere_directions(SUPPORT_DIRECTIONS);
        for case in 0..120 {
            let n = [1, 7, 300, 2_000, 9_000][case % 5];
            let scale = [1.0, 1e-4, 3e5][case % 3];
            let offset = Vec3::new(r(), r(), r()) * [0.0, 1.0, 1e6][case % 3];
            let mut points: Vec<Vec3> = match case % 4 {
                // A sphere shell (every point on the hull), a box's corners repeated (ties), a flat
                // disc, random points.
                0 => (0..n).map(|_| Vec3::new(r(), r(), r()).normalize_or_zero()).collect(),
                1 => (0..n).map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32)).collect(),
                2 => (0..n).map(|_| Vec3::new(r(), r(), 0.0)).collect(),
                _ => (0..n).map(|_| Vec3::new(r(), r(), r())).collect(),
            };
            for p in &mut points {
                *p = *p * scale + offset;
            }
            if case % 7 == 3 {
                points[n / 2] = Vec3::new(f32::NAN, 0.0, 0.0);
            }
            // An infinite point, and points so far apart that sums of coordinates overflow.
            if case % 11 == 5 {
                points[n / 3] = Vec3::new(f32::INFINITY, 1.0, f32::NEG_INFINITY);
            }
            if case % 13 == 8 {
                for (i, p) in points.iter_mut().enumerate().step_by(5) {
                    *p = Vec3::new(3e38, -3e38, 2e38) * if i % 2 == 0 { 1.0 } else { -1.0 };
                }
            }
            assert_eq!(
                support_points(&points, &directions),
                support_points_by_scan(&points, &directions),
                "case {case}"
            );
        }
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

    /// The NDC bounding rectangle (x0, x1, y0, y1) of `points` seen by `camera`, and whether every
    /// point is within the depth range.
    fn projected_rect(camera: &Camera, points: &[Vec3]) -> ([f32; 4], bool) {
        let clip = camera.clip_from_render();
        let mut rect = [f32::MAX, f32::MIN, f32::MAX, f32::MIN];
        let mut in_depth = true;
        for p in points {
            let c = clip * p.extend(1.0);
            let ndc = c.xyz() / c.w;
            in_depth &= c.w > 0.0 && ndc.z > 0.0 && ndc.z < 1.0;
            rect = [rect[0].min(ndc.x), rect[1].max(ndc.x), rect[2].min(ndc.y), rect[3].max(ndc.y)];
        }
        (rect, in_depth)
    }

    #[test]
    fn fit_centres_the_points_and_fills_the_frame_up_to_the_margin() {
        let mut rng = drafter_core::rng::Rng::new(156);
        let mut r = || rng.signed_f32();
        for case in 0..400 {
            // Boxes of random proportions, off the origin, filled with random points; some flat.
            let scale = Vec3::new(r().abs() * 5.0 + 0.01, r().abs() * 5.0 + 0.01, r().abs() * 5.0 + 0.01)
                * if case % 7 == 0 { Vec3::new(1.0, 0.0, 1.0) } else { Vec3::ONE };
            let offset = Vec3::new(r(), r(), r()) * 3.0;
            let points: Vec<Vec3> = (0..40).map(|_| offset + Vec3::new(r(), r(), r()) * scale).collect();
            let view = View { azimuth_deg: r() * 180.0, elevation_deg: r() * 89.0 };
            let aspect = [0.5, 1.0, 4.0 / 3.0, 16.0 / 9.0, 3.0][case % 5];
            let fov = [20.0, 30.0, 60.0][case % 3];
            for orthographic in [false, true] {
                let camera = Camera::fit(&points, view, aspect, orthographic, fov);
                let ([x0, x1, y0, y1], in_depth) = projected_rect(&camera, &points);
                let what = format!("case {case} ortho {orthographic} {view:?} aspect {aspect} fov {fov}");
                assert!(in_depth, "{what}: a point outside the depth range");
                assert!((x0 + x1).abs() < 2e-3 && (y0 + y1).abs() < 2e-3, "{what}: off centre {x0} {x1} {y0} {y1}");
                let fill = ((x1 - x0) * 0.5).max((y1 - y0) * 0.5);
                assert!((fill - (1.0 - FIT_MARGIN)).abs() < 2e-3, "{what}: fills {fill}");
            }
        }
    }

    #[test]
    fn support_points_bound_the_projection_of_round_parts() {
        // A finely tessellated cylinder (radius 1, height 3, tilted) and a sphere: the kept points'
        // extent along random directions against all points'.
        let mut points = Vec::new();
        for i in 0..720 {
            let a = i as f32 * std::f32::consts::TAU / 720.0;
            for h in [-1.5, 1.5] {
                points.push(Mat4::from_rotation_x(0.3).transform_point3(Vec3::new(a.cos(), h, a.sin())));
            }
            for j in 1..180 {
                let b = j as f32 * std::f32::consts::PI / 180.0;
                points.push(Vec3::new(b.sin() * a.cos(), b.cos(), b.sin() * a.sin()) + Vec3::X * 4.0);
            }
        }
        let kept = hull_sample(&points);
        assert!(kept.len() <= SUPPORT_DIRECTIONS && kept.len() > 16, "{}", kept.len());
        let mut rng = drafter_core::rng::Rng::new(157);
        let mut worst = 0.0f32;
        for _ in 0..2000 {
            let u = Vec3::new(rng.signed_f32(), rng.signed_f32(), rng.signed_f32()).normalize_or(Vec3::X);
            let all = points.iter().map(|p| p.dot(u)).fold(f32::MIN, f32::max);
            let some = kept.iter().map(|&i| points[i].dot(u)).fold(f32::MIN, f32::max);
            assert!(some <= all);
            worst = worst.max(all - some);
        }
        // Unit radius: the shortfall is a fraction of the parts' radius.
        assert!(worst < 0.015, "worst shortfall {worst}");
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
