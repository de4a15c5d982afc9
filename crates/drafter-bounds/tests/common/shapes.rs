//! Seeded generators of CAD-like point sets, shared by the tests and `examples/obb_bench.rs`
//! (included there with `#[path]`). Surface samples of tessellated parts, not volumes: what a mesh's
//! vertices look like.

#![allow(dead_code)]

use std::f64::consts::{PI, TAU};

use glam::{DMat3, DVec3};

pub use drafter_core::rng::Rng;

/// The generator these shapes are drawn with for `seed`: the workspace's one, its seed salted so
/// that small seeds do not start the shapes of different tests alike.
pub fn rng(seed: u64) -> Rng {
    Rng::new(seed ^ 0x5851_f42d_4c95_7f2d)
}

/// A tessellated box surface: a grid of `n × n` points on each face (exactly coplanar in object space).
pub fn box_surface(size: DVec3, n: usize) -> Vec<DVec3> {
    let mut pts = Vec::new();
    let h = size * 0.5;
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [-1.0, 1.0] {
            for i in 0..n {
                for j in 0..n {
                    let mut p = DVec3::ZERO;
                    p[axis] = side * h[axis];
                    p[u] = -h[u] + size[u] * i as f64 / (n - 1) as f64;
                    p[v] = -h[v] + size[v] * j as f64 / (n - 1) as f64;
                    pts.push(p);
                }
            }
        }
    }
    pts
}

/// A cylinder along z with `segments` around, `rings` along, and the two cap centres.
pub fn cylinder(radius: f64, height: f64, segments: usize, rings: usize) -> Vec<DVec3> {
    let mut pts = vec![DVec3::new(0.0, 0.0, -height / 2.0), DVec3::new(0.0, 0.0, height / 2.0)];
    for r in 0..rings {
        let z = -height / 2.0 + height * r as f64 / (rings - 1).max(1) as f64;
        for s in 0..segments {
            let a = TAU * s as f64 / segments as f64;
            pts.push(DVec3::new(radius * a.cos(), radius * a.sin(), z));
        }
    }
    pts
}

/// Points on holes through a plate: cylinder walls inside `size` along z (interior to the hull).
fn holes(rng: &mut Rng, size: DVec3, count: usize) -> Vec<DVec3> {
    let mut pts = Vec::new();
    for _ in 0..count {
        let r = rng.range_f64(0.05, 0.2) * size.x.min(size.y);
        let cx = rng.range_f64(-0.5 * size.x + r, 0.5 * size.x - r);
        let cy = rng.range_f64(-0.5 * size.y + r, 0.5 * size.y - r);
        for p in cylinder(r, size.z, 24, 2) {
            pts.push(p + DVec3::new(cx, cy, 0.0));
        }
    }
    pts
}

/// An L-shaped bracket (two boxes), non-convex.
pub fn l_bracket(a: f64, b: f64, t: f64, w: f64) -> Vec<DVec3> {
    let mut pts: Vec<DVec3> =
        box_surface(DVec3::new(a, t, w), 6).into_iter().map(|p| p + DVec3::new(a / 2.0, t / 2.0, 0.0)).collect();
    pts.extend(box_surface(DVec3::new(t, b, w), 6).into_iter().map(|p| p + DVec3::new(t / 2.0, b / 2.0, 0.0)));
    pts
}

/// A box with rounded edges (radius `r`), sampled on its surface.
pub fn rounded_box(size: DVec3, r: f64, n: usize) -> Vec<DVec3> {
    let inner = (size * 0.5 - DVec3::splat(r)).max(DVec3::ZERO);
    let mut pts = Vec::new();
    // Sample a sphere and push each point out to the inner box: a rounded box's surface.
    for i in 0..n {
        let z = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
        let phi = i as f64 * PI * (3.0 - 5f64.sqrt());
        let rr = (1.0 - z * z).sqrt();
        let d = DVec3::new(rr * phi.cos(), rr * phi.sin(), z);
        let c = DVec3::new(inner.x.copysign(d.x), inner.y.copysign(d.y), inner.z.copysign(d.z));
        pts.push(c + d * r);
    }
    pts.extend(box_surface(size - DVec3::splat(2.0 * r), 4).into_iter().map(|p| p * 1.0));
    pts
}

/// A regular prism (hex nut for 6) with a hole.
pub fn prism(sides: usize, radius: f64, height: f64) -> Vec<DVec3> {
    let mut pts = cylinder(radius, height, sides, 3);
    pts.extend(cylinder(radius * 0.5, height, 32, 2));
    pts
}

/// A gear-like star prism: `teeth` teeth between two radii.
pub fn gear(teeth: usize, r_in: f64, r_out: f64, height: f64) -> Vec<DVec3> {
    let mut pts = Vec::new();
    for k in 0..teeth * 4 {
        let a = TAU * k as f64 / (teeth * 4) as f64;
        let r = if (k / 2) % 2 == 0 { r_out } else { r_in };
        for z in [-height / 2.0, height / 2.0] {
            pts.push(DVec3::new(r * a.cos(), r * a.sin(), z));
        }
    }
    pts
}

/// A cone frustum.
pub fn frustum(r0: f64, r1: f64, height: f64, segments: usize) -> Vec<DVec3> {
    let mut pts = Vec::new();
    for s in 0..segments {
        let a = TAU * s as f64 / segments as f64;
        pts.push(DVec3::new(r0 * a.cos(), r0 * a.sin(), 0.0));
        pts.push(DVec3::new(r1 * a.cos(), r1 * a.sin(), height));
    }
    pts
}

/// An anisotropic Gaussian cloud (scan noise, organic parts).
pub fn noisy_cloud(rng: &mut Rng, n: usize, sigma: DVec3) -> Vec<DVec3> {
    (0..n).map(|_| DVec3::new(rng.normal(), rng.normal(), rng.normal()) * sigma).collect()
}

/// Points on an ellipsoid (a smooth convex part: every point is on the hull).
pub fn ellipsoid(rng: &mut Rng, n: usize, radii: DVec3) -> Vec<DVec3> {
    (0..n)
        .map(|_| {
            let d = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize_or(DVec3::X);
            d * radii
        })
        .collect()
}

/// A thin sheet-metal plate with holes (thickness `t`).
pub fn plate_with_holes(rng: &mut Rng, size: DVec3, holes_n: usize) -> Vec<DVec3> {
    let mut pts = box_surface(size, 8);
    pts.extend(holes(rng, size, holes_n));
    pts
}

/// One named, seeded CAD-like part, rotated and translated at random.
#[derive(Clone, Debug)]
pub struct Shape {
    pub name: String,
    pub points: Vec<DVec3>,
}

/// The `index`-th generated part (names say the family), placed with a random rotation and offset.
pub fn cad_like(seed: u64, index: usize) -> Shape {
    cad_like_with(seed, index, 1.0)
}

/// Number of families [`cad_like`] cycles through.
pub const FAMILIES: usize = 11;

/// [`cad_like`] with tessellation density scaled by `detail` (1 = bench size; tests use less).
pub fn cad_like_with(seed: u64, index: usize, detail: f64) -> Shape {
    let mut rng = rng(seed.wrapping_mul(1_000_003).wrapping_add(index as u64));
    let kind = index % FAMILIES;
    let count = |n: usize| ((n as f64 * detail).round() as usize).max(8);
    let s = |rng: &mut Rng| rng.range_f64(0.2, 3.0);
    let (name, pts) = match kind {
        0 => {
            let size = DVec3::new(s(&mut rng), s(&mut rng), s(&mut rng));
            let mut p = box_surface(size, count(10).min(10));
            p.extend(holes(&mut rng, size, 3));
            ("box_with_holes", p)
        }
        1 => {
            ("cylinder", cylinder(rng.range_f64(0.1, 1.0), rng.range_f64(0.1, 4.0), count(8 * (2 + rng.index(16))), 4))
        }
        2 => ("l_bracket", l_bracket(s(&mut rng), s(&mut rng), rng.range_f64(0.05, 0.3), s(&mut rng))),
        3 => {
            let size = DVec3::new(s(&mut rng), s(&mut rng), s(&mut rng));
            let r = 0.2 * size.min_element();
            ("rounded_box", rounded_box(size, r, count(600)))
        }
        4 => ("hex_nut", prism(6, rng.range_f64(0.2, 1.0), rng.range_f64(0.1, 0.6))),
        5 => ("gear", gear(count(10 + rng.index(30)), 1.0, 1.15, rng.range_f64(0.1, 0.8))),
        6 => {
            ("frustum", frustum(rng.range_f64(0.2, 1.0), rng.range_f64(0.05, 1.0), rng.range_f64(0.2, 2.0), count(48)))
        }
        7 => {
            let sigma = DVec3::new(s(&mut rng), s(&mut rng), s(&mut rng));
            ("noisy_cloud", noisy_cloud(&mut rng, count(800), sigma))
        }
        8 => {
            let radii = DVec3::new(s(&mut rng), s(&mut rng), s(&mut rng));
            ("ellipsoid", ellipsoid(&mut rng, count(400), radii))
        }
        9 => {
            let size = DVec3::new(s(&mut rng), s(&mut rng), rng.range_f64(0.005, 0.05));
            ("sheet_plate", plate_with_holes(&mut rng, size, 4))
        }
        _ => {
            // A box with noise on its vertices (scanned or badly exported part).
            let size = DVec3::new(s(&mut rng), s(&mut rng), s(&mut rng));
            let mut p = box_surface(size, 6);
            for q in &mut p {
                *q += DVec3::new(rng.normal(), rng.normal(), rng.normal()) * 0.01 * size.min_element();
            }
            ("noisy_box", p)
        }
    };
    let rot = DMat3::from_quat(rng.rotation());
    let offset = DVec3::new(rng.range_f64(-10.0, 10.0), rng.range_f64(-10.0, 10.0), rng.range_f64(-10.0, 10.0));
    Shape { name: format!("{name}_{index}"), points: pts.into_iter().map(|p| rot * p + offset).collect() }
}
