//! Projectors from oriented boxes (Lux et al. 2013, §3): the part spans p ∈ [0, 1] along its longest
//! axis, the direction faces away from the scene centre, and M = R · P · V.

#![allow(clippy::unwrap_used)] // tests (clippy.toml allows unwrap in #[test] fns; this covers helpers)

mod common;

use common::shapes;
use drafter_bounds::{BIAS_MATRIX, ObbMethod, ObbOptions, Projector, oriented_box};
use glam::{DMat4, DQuat, DVec3};

#[test]
fn parts_span_zero_to_one_along_their_longest_axis() {
    let parts: Vec<shapes::Shape> = (0..2 * shapes::FAMILIES).map(|i| shapes::cad_like_with(21, i, 0.25)).collect();
    let scene_center = parts.iter().map(|s| s.points[0]).sum::<DVec3>() / parts.len() as f64;
    for shape in &parts {
        let obb = oriented_box(&shape.points, &ObbOptions::with_method(ObbMethod::Default)).unwrap();
        let proj = Projector::from_obb(&obb, scene_center);
        proj.validate().unwrap();
        assert_eq!(proj.anchor, obb.center);
        assert!((proj.scale - 2.0 * obb.half_extents.x).abs() < 1e-15);
        assert!(proj.direction.dot(obb.axes[0]).abs() > 1.0 - 1e-15, "longest axis");
        assert!(proj.direction.dot(obb.center - scene_center) >= 0.0, "{}: faces the scene centre", shape.name);
        let m = proj.matrix();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &shape.points {
            let v = m.transform_point3(*p);
            assert!((v.x - proj.coordinate(*p)).abs() < 1e-9);
            assert!(v.is_finite());
            lo = lo.min(v.x);
            hi = hi.max(v.x);
        }
        assert!(lo.abs() < 1e-9 && (hi - 1.0).abs() < 1e-9, "{}: p spans [{lo}, {hi}]", shape.name);
    }
}

#[test]
fn matrix_is_bias_times_ortho_times_view() {
    let proj =
        Projector { anchor: DVec3::new(1.0, 2.0, -3.0), direction: DVec3::new(1.0, 1.0, 1.0).normalize(), scale: 4.0 };
    let product = BIAS_MATRIX * proj.ortho_matrix() * proj.view_matrix();
    assert!(proj.matrix().abs_diff_eq(product, 1e-15));
    // V is a rigid motion taking the anchor to the origin and the direction to +x.
    let v = proj.view_matrix();
    assert!(v.transform_point3(proj.anchor).length() < 1e-15);
    assert!((v.transform_vector3(proj.direction) - DVec3::X).length() < 1e-15);
    assert!((v.determinant() - 1.0).abs() < 1e-12);
    // The f32 and per-object forms agree with the f64 matrix.
    let world_from_object = DMat4::from_rotation_translation(DQuat::from_rotation_y(0.4), DVec3::new(5.0, 0.0, 1.0));
    let x = DVec3::new(0.3, -0.2, 0.9);
    let expected = proj.matrix().transform_point3(world_from_object.transform_point3(x));
    let got = proj.matrix_for_object(&world_from_object).transform_point3(x.as_vec3());
    assert!((got.as_dvec3() - expected).length() < 1e-6);
    assert!(
        (proj.matrix_f32().transform_point3(x.as_vec3()).as_dvec3() - proj.matrix().transform_point3(x)).length()
            < 1e-6
    );
}

#[test]
fn invalid_projectors_are_rejected() {
    let good = Projector { anchor: DVec3::ZERO, direction: DVec3::X, scale: 1.0 };
    good.validate().unwrap();
    assert!(Projector { direction: DVec3::new(2.0, 0.0, 0.0), ..good }.validate().is_err());
    assert!(Projector { scale: -1.0, ..good }.validate().is_err());
    assert!(Projector { anchor: DVec3::splat(f64::NAN), ..good }.validate().is_err());
    // A point-like part still gets a finite matrix: everything at p = 1/2.
    let point = Projector { scale: 0.0, ..good };
    assert!(point.matrix().is_finite());
    assert_eq!(point.coordinate(DVec3::new(9.0, 9.0, 9.0)), 0.5);
}
