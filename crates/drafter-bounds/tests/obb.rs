//! Oriented boxes: validity, minimality against independent computations, invariance under rigid
//! motion and re-indexing, determinism, and the inputs where box fitting is known to fail.

#![allow(clippy::unwrap_used)] // tests (clippy.toml allows unwrap in #[test] fns; this covers helpers)

mod common;

use common::shapes::{self, Rng};
use common::{assert_valid_box, rel_diff};
use drafter_bounds::{
    BoundsError, Coverage, HullOptions, Obb, ObbMethod, ObbOptions, aabb, convex_hull, oriented_box, oriented_box_f32,
    oriented_box_with_stats, world_points,
};
use glam::{DMat3, DMat4, DQuat, DVec2, DVec3, Vec3};

/// Test-sized parts: every family, several seeds, reduced tessellation (the test profile is opt-level 1).
fn test_shapes(count: usize) -> Vec<shapes::Shape> {
    (0..count).map(|i| shapes::cad_like_with(7, i, 0.25)).collect()
}

fn fit(points: &[DVec3], method: ObbMethod) -> Obb {
    oriented_box(points, &ObbOptions::with_method(method)).unwrap()
}

#[test]
fn every_box_contains_its_points() {
    let shapes = test_shapes(3 * shapes::FAMILIES);
    assert_eq!(shapes.len(), 33);
    for shape in &shapes {
        for method in ObbMethod::ALL {
            let obb = fit(&shape.points, method);
            assert_eq!(obb.method, method);
            assert_valid_box(&obb, &shape.points, &format!("{} {method}", shape.name));
        }
    }
}

#[test]
fn optimal_is_never_larger_than_the_other_methods() {
    for shape in test_shapes(2 * shapes::FAMILIES) {
        let optimal = fit(&shape.points, ObbMethod::Optimal).volume;
        for method in [ObbMethod::Aabb, ObbMethod::Pca, ObbMethod::Hull, ObbMethod::Default] {
            let other = fit(&shape.points, method).volume;
            assert!(optimal <= other * (1.0 + 1e-9), "{}: optimal {optimal} > {method} {other}", shape.name);
        }
    }
}

/// Independent reference for case 1 (what trimesh's `oriented_bounds` computes): for every hull triangle
/// normal, the projected points' minimum-area rectangle by brute force over the edges of a gift-wrapped
/// 2D hull.
fn face_flush_reference(points: &[DVec3]) -> f64 {
    let hull = convex_hull(points, &HullOptions::default()).unwrap();
    let mut best = f64::INFINITY;
    for t in &hull.triangles {
        let [a, b, c] = t.map(|i| hull.vertices[i as usize]);
        let n = (b - a).cross(c - a).normalize();
        let u = n.any_orthonormal_vector();
        let v = n.cross(u);
        let flat: Vec<DVec2> = hull.vertices.iter().map(|p| DVec2::new(u.dot(*p), v.dot(*p))).collect();
        let ring = gift_wrap(&flat);
        let (lo, hi) = hull
            .vertices
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(n.dot(*p)), hi.max(n.dot(*p))));
        for k in 0..ring.len() {
            let e = (ring[(k + 1) % ring.len()] - ring[k]).normalize();
            let f = e.perp();
            let (mut e0, mut e1, mut f0, mut f1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
            for p in &ring {
                e0 = e0.min(e.dot(*p));
                e1 = e1.max(e.dot(*p));
                f0 = f0.min(f.dot(*p));
                f1 = f1.max(f.dot(*p));
            }
            best = best.min((e1 - e0) * (f1 - f0) * (hi - lo));
        }
    }
    best
}

/// Jarvis march (independent of the crate's monotone chain).
fn gift_wrap(points: &[DVec2]) -> Vec<DVec2> {
    let start = (0..points.len())
        .min_by(|&a, &b| points[a].x.total_cmp(&points[b].x).then(points[a].y.total_cmp(&points[b].y)))
        .unwrap();
    let mut ring = vec![points[start]];
    let mut current = start;
    loop {
        let mut next = (current + 1) % points.len();
        for (k, p) in points.iter().enumerate() {
            let cross = (points[next] - points[current]).perp_dot(*p - points[current]);
            let farther = points[current].distance_squared(*p) > points[current].distance_squared(points[next]);
            if cross < -1e-12 || (cross.abs() <= 1e-12 && farther) {
                next = k;
            }
        }
        if next == start || ring.len() > points.len() {
            break;
        }
        ring.push(points[next]);
        current = next;
    }
    ring
}

#[test]
fn optimal_is_never_larger_than_the_best_face_flush_box() {
    for shape in test_shapes(2 * shapes::FAMILIES) {
        let optimal = fit(&shape.points, ObbMethod::Optimal).volume;
        let reference = face_flush_reference(&shape.points);
        assert!(optimal <= reference * (1.0 + 1e-9), "{}: optimal {optimal} > face-flush {reference}", shape.name);
    }
}

/// Dense search on SO(3): many seeded random rotations, the best ones polished by coordinate descent.
fn dense_search(points: &[DVec3], rng: &mut Rng) -> f64 {
    let volume = |r: &DMat3| {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for p in points {
            let q = r.transpose() * *p;
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let d = hi - lo;
        d.x * d.y * d.z
    };
    let mut starts: Vec<(f64, DMat3)> = (0..3000)
        .map(|_| {
            let r = DMat3::from_quat(rng.rotation());
            (volume(&r), r)
        })
        .collect();
    starts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = f64::INFINITY;
    for (mut v, mut r) in starts.into_iter().take(8) {
        let mut step = 0.05;
        while step > 1e-9 {
            let mut improved = false;
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                for sign in [1.0, -1.0] {
                    let candidate = r * DMat3::from_axis_angle(axis, sign * step);
                    let w = volume(&candidate);
                    if w < v {
                        v = w;
                        r = candidate;
                        improved = true;
                    }
                }
            }
            if !improved {
                step *= 0.5;
            }
        }
        best = best.min(v);
    }
    best
}

#[test]
fn optimal_matches_a_dense_search_on_small_clouds() {
    let mut rng = shapes::rng(2024);
    for trial in 0..12 {
        let n = 6 + trial * 2;
        let scale = DVec3::new(rng.range_f64(0.5, 3.0), rng.range_f64(0.5, 3.0), rng.range_f64(0.5, 3.0));
        let points: Vec<DVec3> = (0..n)
            .map(|_| DVec3::new(rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0), rng.range_f64(-1.0, 1.0)) * scale)
            .collect();
        let (obb, stats) = oriented_box_with_stats(&points, &ObbOptions::with_method(ObbMethod::Optimal)).unwrap();
        assert_eq!(stats.edge_search, Coverage::Exhaustive);
        assert_eq!(stats.face_search, Coverage::Exhaustive);
        let dense = dense_search(&points, &mut rng);
        assert!(obb.volume <= dense * (1.0 + 1e-6), "trial {trial}: optimal {} > dense search {dense}", obb.volume);
    }
}

#[test]
fn volume_is_invariant_under_rotation() {
    let mut rng = shapes::rng(99);
    for shape in test_shapes(2 * shapes::FAMILIES) {
        let base_optimal = fit(&shape.points, ObbMethod::Optimal).volume;
        let base_default = fit(&shape.points, ObbMethod::Default).volume;
        for _ in 0..2 {
            let r = DMat3::from_quat(rng.rotation());
            let rotated: Vec<DVec3> = shape.points.iter().map(|p| r * *p).collect();
            let optimal = fit(&rotated, ObbMethod::Optimal);
            let default = fit(&rotated, ObbMethod::Default);
            assert_valid_box(&optimal, &rotated, &shape.name);
            assert!(
                rel_diff(optimal.volume, base_optimal) < 1e-3,
                "{}: optimal {} vs {base_optimal}",
                shape.name,
                optimal.volume
            );
            assert!(
                rel_diff(default.volume, base_default) < 1e-3,
                "{}: default {} vs {base_default}",
                shape.name,
                default.volume
            );
        }
    }
}

#[test]
fn translation_by_a_million_changes_nothing() {
    let offset = DVec3::new(1.0e6, -2.0e6, 3.0e6);
    for shape in test_shapes(shapes::FAMILIES) {
        let moved: Vec<DVec3> = shape.points.iter().map(|p| *p + offset).collect();
        for method in ObbMethod::ALL {
            let a = fit(&shape.points, method);
            let b = fit(&moved, method);
            assert_valid_box(&b, &moved, &format!("{} {method} moved", shape.name));
            assert!(rel_diff(a.volume, b.volume) < 1e-6, "{} {method}: {} vs {}", shape.name, a.volume, b.volume);
            let size = a.half_extents.max_element();
            assert!((b.center - offset - a.center).length() < 1e-6 * size.max(1.0), "{} {method}: centre", shape.name);
        }
    }
}

#[test]
fn reindexing_does_not_change_the_box() {
    let mut rng = shapes::rng(5);
    for shape in test_shapes(shapes::FAMILIES) {
        let mut shuffled = shape.points.clone();
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, rng.index(i + 1));
        }
        for method in ObbMethod::ALL {
            let a = fit(&shape.points, method).volume;
            let b = fit(&shuffled, method).volume;
            // PCA's covariance sums in another order: rounding only.
            assert!(rel_diff(a, b) < 1e-6, "{} {method}: {a} vs {b}", shape.name);
        }
    }
}

fn cube(side: f64, n: usize) -> Vec<DVec3> {
    shapes::box_surface(DVec3::splat(side), n)
}

#[test]
fn cube_box_is_exact_and_the_same_every_run() {
    let side = 2.0;
    let mut rng = shapes::rng(11);
    for trial in 0..4 {
        let points: Vec<DVec3> = if trial == 0 {
            cube(side, 5)
        } else {
            let r = DMat3::from_quat(rng.rotation());
            cube(side, 5).iter().map(|p| r * *p + DVec3::new(3.0, -1.0, 2.0)).collect()
        };
        for method in [ObbMethod::Default, ObbMethod::Optimal] {
            let first = fit(&points, method);
            assert_valid_box(&first, &points, "cube");
            assert!(rel_diff(first.volume, side.powi(3)) < 1e-9, "trial {trial} {method}: {}", first.volume);
            let again = fit(&points, method);
            assert_eq!(first, again, "same input, same box");
        }
    }
    // Axis-aligned: the box is the world box, axes exactly world axes.
    let obb = fit(&cube(side, 5), ObbMethod::Optimal);
    for a in obb.axes {
        assert_eq!(a.abs().max_element(), 1.0);
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let shapes = test_shapes(shapes::FAMILIES);
    let run = |threads: usize| -> Vec<Obb> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| shapes.iter().flat_map(|s| ObbMethod::ALL.map(|m| fit(&s.points, m))).collect())
    };
    assert_eq!(run(1), run(3));
}

#[test]
fn cylinder_box_is_minimal_and_stable() {
    // A regular 32-gon prism: the minimum rectangle of the cap has sides 2r·cos(π/32) (edge-flush).
    let (r, h, k) = (1.0, 3.0, 32);
    let expected = h * (2.0 * r * (std::f64::consts::PI / k as f64).cos()).powi(2);
    let mut rng = shapes::rng(3);
    for trial in 0..3 {
        let rot = if trial == 0 { DMat3::IDENTITY } else { DMat3::from_quat(rng.rotation()) };
        let points: Vec<DVec3> = shapes::cylinder(r, h, k, 5).iter().map(|p| rot * *p).collect();
        for method in [ObbMethod::Default, ObbMethod::Optimal] {
            let obb = fit(&points, method);
            assert_valid_box(&obb, &points, "cylinder");
            assert!(rel_diff(obb.volume, expected) < 1e-9, "trial {trial} {method}: {} vs {expected}", obb.volume);
            assert_eq!(obb, fit(&points, method));
        }
        // PCA and Hull: the cross-section's covariance is isotropic; still deterministic and valid.
        for method in [ObbMethod::Pca, ObbMethod::Hull] {
            let obb = fit(&points, method);
            assert_valid_box(&obb, &points, "cylinder");
            assert_eq!(obb, fit(&points, method));
        }
    }
}

#[test]
fn degenerate_inputs_give_valid_boxes() {
    let rot = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 0.7));
    let far = DVec3::new(1.0e6, 2.0e6, -1.0e6);
    let grid: Vec<DVec3> = (0..100)
        .map(|i| DVec3::new((i % 10) as f64 * 0.3, (i / 10) as f64 * 0.2, 0.0))
        .map(|p| rot * p + far)
        .collect();
    let thin: Vec<DVec3> = shapes::box_surface(DVec3::new(2.0, 1.0, 1e-9), 4).iter().map(|p| rot * *p).collect();
    let cases: Vec<(&str, Vec<DVec3>, [f64; 3])> = vec![
        // (name, points, upper bounds of the three sorted half extents)
        ("single point", vec![DVec3::new(1.0, 2.0, 3.0)], [0.0, 0.0, 0.0]),
        ("coincident", vec![far; 7], [0.0, 0.0, 0.0]),
        ("two points", vec![DVec3::ZERO, DVec3::new(1.0, 2.0, 2.0)], [1.5 + 1e-12, 1e-12, 1e-12]),
        (
            "collinear far away",
            (0..50).map(|i| far + rot * DVec3::new(i as f64 * 0.1, 0.0, 0.0)).collect(),
            [2.45 + 1e-6, 1e-6, 1e-6],
        ),
        (
            "single triangle",
            [DVec3::ZERO, DVec3::X, DVec3::new(0.2, 1.0, 0.0)].iter().map(|p| rot * *p).collect(),
            [1.0, 1.0, 1e-12],
        ),
        ("coplanar grid far away", grid, [2.0, 2.0, 1e-6]),
        ("paper-thin plate", thin, [1.0 + 1e-9, 0.5 + 1e-9, 1e-9]),
    ];
    for (name, points, bounds) in &cases {
        for method in ObbMethod::ALL {
            let obb = fit(points, method);
            assert_valid_box(&obb, points, &format!("{name} {method}"));
            if method != ObbMethod::Aabb && method != ObbMethod::Pca && method != ObbMethod::Hull {
                for (k, bound) in bounds.iter().enumerate() {
                    assert!(obb.half_extents[k] <= *bound, "{name} {method}: {:?}", obb.half_extents);
                }
            }
        }
    }
    // The plate's box is its 2 × 1 face.
    let flat = fit(&cases[6].1, ObbMethod::Optimal);
    assert!(rel_diff(flat.half_extents.x, 1.0) < 1e-9 && rel_diff(flat.half_extents.y, 0.5) < 1e-9);
}

#[test]
fn bad_input_is_an_error() {
    let options = ObbOptions::default();
    assert_eq!(oriented_box(&[], &options), Err(BoundsError::EmptyInput));
    let nan = [DVec3::ZERO, DVec3::new(f64::NAN, 0.0, 0.0)];
    assert_eq!(oriented_box(&nan, &options), Err(BoundsError::NonFinitePoint { index: 1 }));
    assert!(aabb(&[]).is_empty());
}

#[test]
fn f32_helpers_agree_with_f64() {
    let shape = shapes::cad_like_with(1, 0, 0.25);
    let f32_points: Vec<Vec3> = shape.points.iter().map(|p| p.as_vec3()).collect();
    let exact: Vec<DVec3> = f32_points.iter().map(|p| p.as_dvec3()).collect();
    let options = ObbOptions::with_method(ObbMethod::Optimal);
    assert_eq!(oriented_box_f32(&f32_points, &options).unwrap(), oriented_box(&exact, &options).unwrap());
    let m = DMat4::from_rotation_translation(DQuat::from_rotation_z(0.5), DVec3::new(1e6, 0.0, 0.0));
    let world = world_points(&f32_points, &m);
    for (w, p) in world.iter().zip(&f32_points) {
        assert_eq!(*w, m.transform_point3(p.as_dvec3()));
    }
}

#[test]
fn boxes_serialise_and_methods_parse() {
    let obb = fit(&shapes::cad_like_with(2, 3, 0.25).points, ObbMethod::Default);
    let json = serde_json::to_string(&obb).unwrap();
    assert!(json.contains("\"method\":\"default\""), "{json}");
    let back: Obb = serde_json::from_str(&json).unwrap();
    assert_eq!(back, obb);
    for method in ObbMethod::ALL {
        assert_eq!(method.name().parse::<ObbMethod>().unwrap(), method);
    }
    assert!("minimal".parse::<ObbMethod>().is_err());
    let options: ObbOptions = serde_json::from_str(r#"{"method":"optimal"}"#).unwrap();
    assert_eq!(options, ObbOptions::with_method(ObbMethod::Optimal));
    assert!(serde_json::from_str::<ObbOptions>(r#"{"methd":"optimal"}"#).is_err(), "unknown keys are rejected");
}

#[test]
fn budget_zero_still_gives_the_face_flush_box() {
    let shape = shapes::cad_like_with(4, 5, 0.25); // a gear: many crease edges
    let full = oriented_box_with_stats(&shape.points, &ObbOptions::with_method(ObbMethod::Optimal)).unwrap();
    let cheap = oriented_box_with_stats(
        &shape.points,
        &ObbOptions { optimal_budget: 0, ..ObbOptions::with_method(ObbMethod::Optimal) },
    )
    .unwrap();
    assert_eq!(full.1.edge_search, Coverage::Exhaustive);
    assert_eq!(cheap.1.edge_search, Coverage::OverBudget);
    assert_valid_box(&cheap.0, &shape.points, "budget 0");
    if cheap.1.face_search == Coverage::Exhaustive {
        assert!(cheap.0.volume <= face_flush_reference(&shape.points) * (1.0 + 1e-9));
    }
    assert!(full.0.volume <= cheap.0.volume * (1.0 + 1e-9));
}
