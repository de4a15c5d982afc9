//! Closest point on a triangle, in f64, after Ericson, *Real-Time Collision Detection* (2005),
//! §5.1.5 (Voronoi regions of the vertices, edges and face).

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
    if denom == 0.0 || denom.is_nan() {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_triangle_regions() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let inside = closest_point_on_triangle(DVec3::new(0.2, 0.2, 1.0), a, b, c);
        assert!((inside - DVec3::new(0.2, 0.2, 0.0)).length() < 1e-12);
        assert_eq!(closest_point_on_triangle(DVec3::new(-1.0, -1.0, 0.0), a, b, c), a);
        assert_eq!(closest_point_on_triangle(DVec3::new(2.0, -0.5, 0.0), a, b, c), b);
        assert_eq!(closest_point_on_triangle(DVec3::new(0.5, -1.0, 0.0), a, b, c), DVec3::new(0.5, 0.0, 0.0));
        let far = closest_point_on_triangle(DVec3::new(1.0, 1.0, 0.0), a, b, c);
        assert!((far - DVec3::new(0.5, 0.5, 0.0)).length() < 1e-12);
        // Collinear triangle.
        let p = closest_point_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, b, DVec3::new(2.0, 0.0, 0.0));
        assert!((p - DVec3::new(0.5, 0.0, 0.0)).length() < 1e-12);
    }
}
