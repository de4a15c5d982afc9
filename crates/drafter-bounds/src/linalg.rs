//! Small dense linear algebra in f64: symmetric 3×3 eigen-decomposition (cyclic Jacobi), deterministic
//! perpendicular frames, and the axis canonicalisation every box goes through.

use glam::{DMat3, DVec3};

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations. Returns eigenvalues in
/// descending order with unit eigenvectors forming a right-handed frame. Deterministic, no allocation.
#[allow(clippy::needless_range_loop)] // index notation mirrors the textbook rotation formulas
pub(crate) fn symmetric_eigen(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z],
    ];
    // symmetrise (the caller's matrix may carry rounding asymmetry)
    for i in 0..3 {
        for j in (i + 1)..3 {
            let s = 0.5 * (a[i][j] + a[j][i]);
            a[i][j] = s;
            a[j][i] = s;
        }
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..64 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= f64::EPSILON * 1e-3 * diag || off == 0.0 || !off.is_finite() {
            break;
        }
        for (p, q) in [(0usize, 1usize), (0, 2), (1, 2)] {
            let apq = a[p][q];
            if apq == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for k in 0..3 {
                let akp = a[k][p];
                let akq = a[k][q];
                a[k][p] = c * akp - s * akq;
                a[k][q] = s * akp + c * akq;
            }
            for k in 0..3 {
                let apk = a[p][k];
                let aqk = a[q][k];
                a[p][k] = c * apk - s * aqk;
                a[q][k] = s * apk + c * aqk;
            }
            for row in v.iter_mut() {
                let vkp = row[p];
                let vkq = row[q];
                row[p] = c * vkp - s * vkq;
                row[q] = s * vkp + c * vkq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]).then(i.cmp(&j)));
    let values = [a[order[0]][order[0]], a[order[1]][order[1]], a[order[2]][order[2]]];
    let col = |k: usize| DVec3::new(v[0][k], v[1][k], v[2][k]);
    let e0 = col(order[0]).normalize_or(DVec3::X);
    let e1 = (col(order[1]) - e0 * e0.dot(col(order[1]))).normalize_or(perpendicular(e0));
    let e2 = e0.cross(e1);
    (values, [e0, e1, e2])
}

/// A unit vector perpendicular to the unit vector `d`, chosen deterministically: the world axis least
/// aligned with `d` (ties: x before y before z), made orthogonal to `d`.
pub(crate) fn perpendicular(d: DVec3) -> DVec3 {
    let a = d.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    (axis - d * d.dot(axis)).normalize_or(DVec3::X)
}

/// Right-handed orthonormal frame `[d, t, d × t]` with `t = perpendicular(d)`.
pub(crate) fn frame_from_direction(d: DVec3) -> [DVec3; 3] {
    let t = perpendicular(d);
    [d, t, d.cross(t)]
}

/// Re-orthonormalises a nearly orthonormal frame (Gram–Schmidt, right-handed result).
pub(crate) fn orthonormalize(axes: [DVec3; 3]) -> [DVec3; 3] {
    let a0 = axes[0].normalize_or(DVec3::X);
    let a1 = (axes[1] - a0 * a0.dot(axes[1])).normalize_or(perpendicular(a0));
    [a0, a1, a0.cross(a1)]
}

/// Index of the component of largest magnitude (ties: x, then y, then z).
pub(crate) fn dominant_component(v: DVec3) -> usize {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// Flips `v` so that its dominant component is positive.
pub(crate) fn canonical_sign(v: DVec3) -> DVec3 {
    if v[dominant_component(v)] < 0.0 { -v } else { v }
}

/// Rotation of `v` about the unit `axis` by `angle` (Rodrigues).
pub(crate) fn rotate(v: DVec3, axis: DVec3, cos: f64, sin: f64) -> DVec3 {
    v * cos + axis.cross(v) * sin + axis * axis.dot(v) * (1.0 - cos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_diagonal_and_rotated() {
        let d = DMat3::from_diagonal(DVec3::new(1.0, 3.0, 2.0));
        let (values, vectors) = symmetric_eigen(d);
        assert_eq!(values, [3.0, 2.0, 1.0]);
        assert!((vectors[0].abs() - DVec3::Y).length() < 1e-12);
        let r = DMat3::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
        let m = r * d * r.transpose();
        let (values, vectors) = symmetric_eigen(m);
        for (k, expected) in [3.0, 2.0, 1.0].iter().enumerate() {
            assert!((values[k] - expected).abs() < 1e-12);
            let mv = m * vectors[k];
            assert!((mv - vectors[k] * values[k]).length() < 1e-12);
        }
        assert!((vectors[0].cross(vectors[1]) - vectors[2]).length() < 1e-12);
    }

    #[test]
    fn perpendicular_frames_are_orthonormal() {
        for d in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Z, DVec3::new(1.0, 2.0, -3.0).normalize()] {
            let f = frame_from_direction(d);
            for i in 0..3 {
                assert!((f[i].length() - 1.0).abs() < 1e-14);
                for j in (i + 1)..3 {
                    assert!(f[i].dot(f[j]).abs() < 1e-14);
                }
            }
            assert!((f[0].cross(f[1]) - f[2]).length() < 1e-14);
        }
    }
}
