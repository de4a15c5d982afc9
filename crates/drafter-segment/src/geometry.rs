//! Exact distance predicates between triangles, in f64: "are these two triangles within `tol` of
//! each other". Closest-point routines follow Ericson, *Real-Time Collision Detection* (2005),
//! §5.1.5 (point–triangle) and §5.1.9 (segment–segment).

use glam::DVec3;

/// Closest point to `p` on triangle `abc` (degenerate triangles included).
pub(crate) fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + v * ab;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + w * ac;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + w * (c - b);
    }
    let denom = va + vb + vc;
    if !(denom.abs() > 0.0) {
        // Degenerate (collinear) triangle: the closest of its three edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(s, t)| closest_point_on_segment(p, s, t))
            .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
            .unwrap_or(a);
    }
    let v = vb / denom;
    let w = vc / denom;
    a + ab * v + ac * w
}

fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// Squared distance between segments `p1q1` and `p2q2`.
pub(crate) fn segment_segment_distance_squared(p1: DVec3, q1: DVec3, p2: DVec3, q2: DVec3) -> f64 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    let (s, t);
    if a <= f64::MIN_POSITIVE && e <= f64::MIN_POSITIVE {
        return r.length_squared();
    }
    if a <= f64::MIN_POSITIVE {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= f64::MIN_POSITIVE {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    (p1 + d1 * s).distance_squared(p2 + d2 * t)
}

/// True when segment `pq` crosses triangle `abc` (touching counts).
fn segment_crosses_triangle(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    let n = (b - a).cross(c - a);
    let dp = n.dot(p - a);
    let dq = n.dot(q - a);
    if (dp > 0.0 && dq > 0.0) || (dp < 0.0 && dq < 0.0) || dp == dq {
        // Same side, or parallel (then the edge and point tests decide).
        return false;
    }
    let x = p + (q - p) * (dp / (dp - dq));
    let inside = |u: DVec3, v: DVec3| n.dot((v - u).cross(x - u)) >= 0.0;
    inside(a, b) && inside(b, c) && inside(c, a)
}

/// True when triangles `t` and `u` come within `tol` of each other (shared points and
/// intersections included).
pub(crate) fn triangles_within(t: &[DVec3; 3], u: &[DVec3; 3], tol: f64) -> bool {
    let tol2 = tol * tol;
    for p in t {
        if closest_point_on_triangle(*p, u[0], u[1], u[2]).distance_squared(*p) <= tol2 {
            return true;
        }
    }
    for p in u {
        if closest_point_on_triangle(*p, t[0], t[1], t[2]).distance_squared(*p) <= tol2 {
            return true;
        }
    }
    for i in 0..3 {
        let (p, q) = (t[i], t[(i + 1) % 3]);
        for j in 0..3 {
            if segment_segment_distance_squared(p, q, u[j], u[(j + 1) % 3]) <= tol2 {
                return true;
            }
        }
        if segment_crosses_triangle(p, q, u[0], u[1], u[2]) {
            return true;
        }
        if segment_crosses_triangle(u[i], u[(i + 1) % 3], t[0], t[1], t[2]) {
            return true;
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [DVec3; 3] {
        [DVec3::from(a), DVec3::from(b), DVec3::from(c)]
    }

    #[test]
    fn point_triangle_regions() {
        let [a, b, c] = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(closest_point_on_triangle(DVec3::new(0.2, 0.2, 1.0), a, b, c), DVec3::new(0.2, 0.2, 0.0));
        assert_eq!(closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c), a);
        assert_eq!(closest_point_on_triangle(DVec3::new(2.0, -0.5, 0.0), a, b, c), b);
        assert_eq!(closest_point_on_triangle(DVec3::new(0.5, -1.0, 0.0), a, b, c), DVec3::new(0.5, 0.0, 0.0));
        let far = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((far - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-12);
        // Collinear triangle.
        let p = closest_point_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, b, DVec3::new(2.0, 0.0, 0.0));
        assert!((p - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn segment_distances() {
        let d = segment_segment_distance_squared(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, -1.0, 1.0),
            DVec3::new(0.5, 1.0, 1.0),
        );
        assert!((d - 1.0).abs() < 1e-12);
        let parallel =
            segment_segment_distance_squared(DVec3::ZERO, DVec3::X, DVec3::new(2.0, 1.0, 0.0), DVec3::new(3.0, 1.0, 0.0));
        assert!((parallel - 2.0).abs() < 1e-12);
    }

    #[test]
    fn triangle_pairs() {
        let t = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        // Crossing through the interior with no vertex or edge near.
        let cross = tri([0.2, 0.2, -1.0], [0.3, 0.2, 1.0], [0.25, 0.3, 1.0]);
        assert!(triangles_within(&t, &cross, 1e-9));
        // Edge over edge, 0.1 apart.
        let above = tri([0.5, -1.0, 0.1], [0.5, 1.0, 0.1], [0.5, 0.0, 5.0]);
        assert!(triangles_within(&t, &above, 0.11));
        assert!(!triangles_within(&t, &tri([0.5, -1.0, 0.2], [0.5, -0.5, 0.2], [0.5, -0.7, 5.0]), 0.11));
        // Parallel, offset.
        let lifted = tri([0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]);
        assert!(!triangles_within(&t, &lifted, 0.4));
        assert!(triangles_within(&t, &lifted, 0.5));
    }
}
