#![allow(dead_code)]

pub mod shapes;

use drafter_bounds::Obb;
use glam::DVec3;

/// Containment tolerance for a box around `points`: relative to the box's size, plus the rounding of
/// coordinates of the given magnitude.
pub fn containment_eps(obb: &Obb, points: &[DVec3]) -> f64 {
    let magnitude = points.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    1e-9 * (1.0 + 2.0 * obb.half_extents.max_element()) + 1e-14 * magnitude
}

/// Asserts that `obb` is a well-formed box containing every point.
pub fn assert_valid_box(obb: &Obb, points: &[DVec3], what: &str) {
    assert!(obb.center.is_finite(), "{what}: centre {:?}", obb.center);
    assert!(obb.half_extents.is_finite() && obb.volume.is_finite(), "{what}: {obb:?}");
    for k in 0..3 {
        assert!((obb.axes[k].length() - 1.0).abs() < 1e-12, "{what}: axis {k} not unit: {:?}", obb.axes);
        assert!(obb.half_extents[k] >= 0.0, "{what}: negative extent {:?}", obb.half_extents);
        for j in (k + 1)..3 {
            assert!(obb.axes[k].dot(obb.axes[j]).abs() < 1e-12, "{what}: axes not orthogonal {:?}", obb.axes);
        }
    }
    assert!((obb.axes[0].cross(obb.axes[1]) - obb.axes[2]).length() < 1e-12, "{what}: not right-handed");
    // Sorted longest first; near-ties (1e-9 relative) are ordered by world axis instead.
    let tie = 1e-9 * obb.half_extents.max_element();
    assert!(
        obb.half_extents.x >= obb.half_extents.y - tie && obb.half_extents.y >= obb.half_extents.z - tie,
        "{what}: extents not sorted {:?}",
        obb.half_extents
    );
    let h = obb.half_extents;
    let expected = 8.0 * h.x * h.y * h.z;
    assert!((obb.volume - expected).abs() <= 1e-12 * expected.max(f64::MIN_POSITIVE), "{what}: volume");
    let eps = containment_eps(obb, points);
    for (i, p) in points.iter().enumerate() {
        assert!(obb.contains(*p, eps), "{what}: point {i} {p:?} outside {obb:?} (eps {eps:e})");
    }
}

/// Relative difference `|a − b| / max(|a|, |b|)` (0 when both are 0).
pub fn rel_diff(a: f64, b: f64) -> f64 {
    let m = a.abs().max(b.abs());
    if m == 0.0 { 0.0 } else { (a - b).abs() / m }
}
