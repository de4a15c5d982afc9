//! Planar helpers: 2D convex hull (Andrew's monotone chain) and the minimum-area enclosing rectangle by
//! rotating calipers (Toussaint 1983, "Solving geometric problems with the rotating calipers").
//!
//! The minimum-area rectangle of a convex polygon has a side collinear with a polygon edge (Freeman &
//! Shapira 1975), so trying every edge direction is exact; the calipers make that O(m) after the hull.

use glam::DVec2;

/// Indices of the convex hull of `points`, counter-clockwise. Points within `tol` of an earlier point
/// (after sorting) or within `tol` of the line through their hull neighbours are dropped, so rounding
/// noise neither adds near-duplicate vertices (whose edge directions would be noise) nor keeps
/// collinear ones. One index for coincident input, two for collinear input.
pub(crate) fn convex_hull_2d(points: &[DVec2], tol: f64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_unstable_by(|&a, &b| {
        let (pa, pb) = (points[a as usize], points[b as usize]);
        pa.x.total_cmp(&pb.x).then(pa.y.total_cmp(&pb.y)).then(a.cmp(&b))
    });
    order.dedup_by(|a, b| points[*a as usize].distance(points[*b as usize]) <= tol);
    if order.len() < 3 {
        return order;
    }
    // Keep b between a and c only for a left turn by more than `tol` (distance of b from line ac).
    let keep = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a) > tol * (c - a).length();
    let mut hull: Vec<u32> = Vec::with_capacity(2 * order.len());
    for &i in &order {
        while hull.len() >= 2
            && !keep(points[hull[hull.len() - 2] as usize], points[hull[hull.len() - 1] as usize], points[i as usize])
        {
            hull.pop();
        }
        hull.push(i);
    }
    let lower_len = hull.len() + 1;
    for &i in order.iter().rev().skip(1) {
        while hull.len() >= lower_len
            && !keep(points[hull[hull.len() - 2] as usize], points[hull[hull.len() - 1] as usize], points[i as usize])
        {
            hull.pop();
        }
        hull.push(i);
    }
    hull.pop(); // the first point again
    if hull.len() < 3 {
        // all collinear: keep the two ends
        let first = order[0];
        let last = order[order.len() - 1];
        return vec![first, last];
    }
    hull
}

/// A rectangle around a planar point set: `dir` is the unit direction of its first side; extents are
/// `[min, max]` along `dir` and along `dir.perp()`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rect2 {
    pub dir: DVec2,
    pub area: f64,
}

/// Minimum-area rectangle around the convex polygon `poly` (counter-clockwise, as returned by
/// [`convex_hull_2d`]). Ties keep the first edge. For one or two points the rectangle is degenerate
/// (area 0) with `dir` along the segment.
pub(crate) fn min_area_rect(poly: &[DVec2]) -> Rect2 {
    let m = poly.len();
    if m < 3 {
        let dir = if m == 2 { (poly[1] - poly[0]).normalize_or(DVec2::X) } else { DVec2::X };
        return Rect2 { dir, area: 0.0 };
    }
    let edge_dir = |i: usize| (poly[(i + 1) % m] - poly[i]).normalize_or(DVec2::X);
    // Initial calipers for edge 0 by full scans.
    let e = edge_dir(0);
    let n = e.perp();
    let argmax = |f: &dyn Fn(DVec2) -> f64| -> usize {
        let mut best = 0;
        let mut best_v = f64::NEG_INFINITY;
        for (k, p) in poly.iter().enumerate() {
            let v = f(*p);
            if v > best_v {
                best_v = v;
                best = k;
            }
        }
        best
    };
    let mut i_max = argmax(&|p| e.dot(p));
    let mut i_top = argmax(&|p| n.dot(p));
    let mut i_min = argmax(&|p| -e.dot(p));
    let mut best = Rect2 { dir: e, area: f64::INFINITY };
    for i in 0..m {
        let e = edge_dir(i);
        let n = e.perp(); // inward for a counter-clockwise polygon
        let base = poly[i];
        // Advance each caliper while the next vertex is at least as extreme (bounded by m steps).
        let advance = |mut k: usize, f: &dyn Fn(DVec2) -> f64| -> usize {
            for _ in 0..m {
                let next = (k + 1) % m;
                if f(poly[next]) >= f(poly[k]) {
                    k = next;
                } else {
                    break;
                }
            }
            k
        };
        i_max = advance(i_max, &|p| e.dot(p));
        i_top = advance(i_top, &|p| n.dot(p));
        i_min = advance(i_min, &|p| -e.dot(p));
        let width = e.dot(poly[i_max]) - e.dot(poly[i_min]);
        let height = n.dot(poly[i_top] - base);
        let area = width * height;
        if area < best.area {
            best = Rect2 { dir: e, area };
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_min_area(poly: &[DVec2]) -> f64 {
        let m = poly.len();
        let mut best = f64::INFINITY;
        for i in 0..m {
            let e = (poly[(i + 1) % m] - poly[i]).normalize();
            let n = e.perp();
            let (mut a0, mut a1, mut b0, mut b1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
            for p in poly {
                a0 = a0.min(e.dot(*p));
                a1 = a1.max(e.dot(*p));
                b0 = b0.min(n.dot(*p));
                b1 = b1.max(n.dot(*p));
            }
            best = best.min((a1 - a0) * (b1 - b0));
        }
        best
    }

    #[test]
    fn calipers_match_brute_force() {
        let mut rng = drafter_core::rng::Rng::new(12345);
        let mut next = || rng.unit_f64();
        for trial in 0..200 {
            let n = 3 + trial % 40;
            let pts: Vec<DVec2> = (0..n).map(|_| DVec2::new(next() * 3.0 - 1.0, next() - 0.5)).collect();
            let hull = convex_hull_2d(&pts, 0.0);
            let poly: Vec<DVec2> = hull.iter().map(|&i| pts[i as usize]).collect();
            // convex and counter-clockwise
            for k in 0..poly.len() {
                let a = poly[k];
                let b = poly[(k + 1) % poly.len()];
                for p in &pts {
                    assert!((b - a).perp_dot(*p - a) >= -1e-12);
                }
            }
            let r = min_area_rect(&poly);
            let brute = brute_min_area(&poly);
            assert!((r.area - brute).abs() <= 1e-12 * brute.max(1e-300), "{} vs {}", r.area, brute);
        }
    }

    #[test]
    fn degenerate_inputs() {
        assert_eq!(convex_hull_2d(&[], 0.0).len(), 0);
        assert_eq!(convex_hull_2d(&[DVec2::ONE, DVec2::ONE], 0.0).len(), 1);
        let line: Vec<DVec2> = (0..5).map(|i| DVec2::splat(i as f64)).collect();
        assert_eq!(convex_hull_2d(&line, 0.0), vec![0, 4]);
        let square = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y, DVec2::new(0.5, 0.5), DVec2::new(0.5, -1e-13)];
        assert_eq!(convex_hull_2d(&square, 0.0).len(), 5);
        let h = convex_hull_2d(&square, 1e-12);
        assert_eq!(h.len(), 4);
        let poly: Vec<DVec2> = h.iter().map(|&i| square[i as usize]).collect();
        assert!((min_area_rect(&poly).area - 1.0).abs() < 1e-15);
    }
}
