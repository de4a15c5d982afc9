//! Convex hull: every point inside every face plane, closed 2-manifold with Euler characteristic 2,
//! vertices are input points, degenerate dimensions, determinism.

#![allow(clippy::unwrap_used)] // tests (clippy.toml allows unwrap in #[test] fns; this covers helpers)

mod common;

use common::shapes;
use drafter_bounds::{ConvexHull, HullDimension, HullOptions, convex_hull};
use glam::{DMat3, DVec3};

fn hull(points: &[DVec3]) -> ConvexHull {
    convex_hull(points, &HullOptions::default()).unwrap()
}

/// Checks a solid hull against its input: containment, closedness, Euler, orientation, provenance.
fn check_solid(points: &[DVec3], h: &ConvexHull, what: &str) {
    assert_eq!(h.dimension, HullDimension::Solid, "{what}");
    // Provenance: vertices are input points.
    for (v, &i) in h.vertices.iter().zip(&h.input_indices) {
        assert_eq!(*v, points[i as usize], "{what}");
    }
    // Every vertex used, every index valid.
    let mut used = vec![false; h.vertices.len()];
    for t in &h.triangles {
        for &i in t {
            used[i as usize] = true;
        }
    }
    assert!(used.iter().all(|u| *u), "{what}: unused hull vertex");
    // Closed and consistently oriented: every directed edge appears once and its reverse once.
    let mut directed: Vec<(u32, u32)> =
        h.triangles.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
    directed.sort_unstable();
    let before = directed.len();
    directed.dedup();
    assert_eq!(before, directed.len(), "{what}: a directed edge is used twice");
    for &(a, b) in &directed {
        assert!(directed.binary_search(&(b, a)).is_ok(), "{what}: edge {a}-{b} has valence 1");
    }
    let (v, e, f) = (h.vertices.len() as i64, directed.len() as i64 / 2, h.triangles.len() as i64);
    assert_eq!(v - e + f, 2, "{what}: Euler characteristic V={v} E={e} F={f}");
    // Every input point is inside or on every face plane (within the hull tolerance plus rounding).
    let magnitude = points.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let eps = 4.0 * h.tolerance + 1e-12 * magnitude;
    let centroid = h.vertices.iter().copied().sum::<DVec3>() / h.vertices.len() as f64;
    for t in &h.triangles {
        let [a, b, c] = t.map(|i| h.vertices[i as usize]);
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len == 0.0 {
            continue; // a zero-area sliver in a flat facet has no plane of its own
        }
        let n = n / len;
        assert!(n.dot(centroid - a) <= eps, "{what}: face faces inwards");
        for p in points {
            // The float plane of a thin triangle is uncertain by ~8ε|b − a||c − a||p − a| / |cross|.
            let rounding = 8.0 * f64::EPSILON * (b - a).length() * (c - a).length() * (*p - a).length() / len;
            let d = n.dot(*p - a);
            assert!(d <= eps + rounding, "{what}: point {p:?} is {d:e} outside a face (eps {eps:e})");
        }
    }
}

fn clouds() -> Vec<(String, Vec<DVec3>)> {
    let mut rng = shapes::rng(17);
    let mut out: Vec<(String, Vec<DVec3>)> = Vec::new();
    for trial in 0..6 {
        let n = 20 + trial * 150;
        out.push((
            format!("uniform {n}"),
            (0..n).map(|_| DVec3::new(rng.unit_f64(), rng.unit_f64(), rng.unit_f64())).collect(),
        ));
        out.push((format!("gaussian {n}"), shapes::noisy_cloud(&mut rng, n, DVec3::new(1.0, 0.3, 2.0))));
        out.push((format!("sphere {n}"), shapes::ellipsoid(&mut rng, n, DVec3::ONE)));
    }
    // Exactly coplanar tessellations, duplicates, lattices: the degenerate cases of quickhull.
    out.push(("box grid".into(), shapes::box_surface(DVec3::new(2.0, 1.0, 0.5), 9)));
    let r = DMat3::from_quat(rng.rotation());
    out.push((
        "rotated box grid".into(),
        shapes::box_surface(DVec3::new(2.0, 1.0, 0.5), 9).iter().map(|p| r * *p).collect(),
    ));
    out.push(("cylinder".into(), shapes::cylinder(1.0, 2.0, 64, 5)));
    let lattice: Vec<DVec3> =
        (0..216).map(|i| DVec3::new((i % 6) as f64, ((i / 6) % 6) as f64, (i / 36) as f64)).collect();
    out.push(("integer lattice".into(), lattice));
    let mut dup = shapes::ellipsoid(&mut rng, 100, DVec3::new(1.0, 2.0, 3.0));
    dup.extend(dup.clone());
    out.push(("duplicated".into(), dup));
    out.push((
        "far away".into(),
        shapes::noisy_cloud(&mut rng, 300, DVec3::ONE).iter().map(|p| *p + DVec3::new(1e6, -3e6, 2e6)).collect(),
    ));
    for i in 0..shapes::FAMILIES {
        let s = shapes::cad_like_with(3, i, 0.3);
        out.push((s.name, s.points));
    }
    out
}

#[test]
fn every_point_is_inside_and_the_hull_is_closed() {
    for (name, points) in clouds() {
        let h = hull(&points);
        check_solid(&points, &h, &name);
    }
}

#[test]
fn points_on_a_sphere_are_all_vertices() {
    let mut rng = shapes::rng(8);
    let points = shapes::ellipsoid(&mut rng, 500, DVec3::ONE);
    assert_eq!(hull(&points).vertices.len(), 500);
    let cube = shapes::box_surface(DVec3::ONE, 7);
    let h = hull(&cube);
    assert_eq!(h.vertices.len(), 8, "grid points on faces and edges are not vertices");
    assert_eq!(h.triangles.len(), 12);
}

#[test]
fn lower_dimensions() {
    let p = DVec3::new(1.0, 2.0, 3.0);
    let h = hull(&[p, p, p]);
    assert_eq!((h.dimension, h.vertices.len()), (HullDimension::Point, 1));
    let line: Vec<DVec3> = (0..10).map(|i| p + DVec3::new(1.0, -1.0, 0.5) * (i as f64)).collect();
    let h = hull(&line);
    assert_eq!(h.dimension, HullDimension::Segment);
    assert_eq!(h.input_indices.len(), 2);
    assert!(h.input_indices.contains(&0) && h.input_indices.contains(&9));
    let r = DMat3::from_quat(shapes::rng(1).rotation());
    let square: Vec<DVec3> = (0..25).map(|i| r * DVec3::new((i % 5) as f64, (i / 5) as f64, 0.0) + p).collect();
    let h = hull(&square);
    assert_eq!((h.dimension, h.vertices.len()), (HullDimension::Polygon, 4));
    assert!(h.triangles.is_empty());
    assert!((h.polygon_normal.length() - 1.0).abs() < 1e-12);
    assert!(h.polygon_normal.dot(r * DVec3::Z).abs() > 1.0 - 1e-12);
    // counter-clockwise around the normal
    let [a, b, c] = [h.vertices[0], h.vertices[1], h.vertices[2]];
    assert!((b - a).cross(c - b).dot(h.polygon_normal) > 0.0);
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    assert_eq!(hull(&tri).dimension, HullDimension::Polygon);
    assert!(convex_hull(&[], &HullOptions::default()).is_err());
}

#[test]
fn hull_is_deterministic() {
    for (name, points) in clouds().into_iter().take(6) {
        assert_eq!(hull(&points), hull(&points), "{name}");
    }
}
