//! Triangulation of a planar polygon with holes, using only the boundary vertices (no Steiner points), as a CAD
//! mesher does for a planar B-rep face whose edges are already discretised.
//!
//! How it works:
//! 1. Orient the outer loop counter-clockwise and the holes clockwise.
//! 2. Cut each hole into the outer loop with a zero-width bridge, holes taken in order of decreasing maximum x
//!    (D. Eberly, "Triangulation by Ear Clipping", 2002, section 3): cast a ray in +x from the hole's rightmost
//!    vertex M, take the nearest boundary edge it hits, and bridge M to that edge's rightmost end P unless a
//!    reflex vertex lies in the triangle (M, hit, P), in which case bridge to the one closest in angle to the ray.
//! 3. Clip ears, always the best-shaped valid ear (largest `area / sum of squared edges`).
//! 4. Lawson edge flips to the constrained Delaunay triangulation: every edge that is not a loop edge is flipped
//!    while the opposite vertex is strictly inside the circumcircle (relative tolerance 1e-10, so ties between
//!    cocircular points, e.g. the vertices of a circular hole, never flip back and forth).
//!
//! The result only depends on the input coordinates and their order (no hashing), so it is deterministic.
//!
//! Limits: loops must be simple, holes strictly inside the outer loop and disjoint from each other; consecutive
//! collinear vertices are kept (they must stay, or faces would not share edges) but may make ear clipping fail,
//! which is reported as an error rather than patched. O(n²) time, fine for the few hundred vertices of a face.

use std::collections::BTreeMap;
use std::fmt;

/// A 2-D point in the face's plane.
pub type Point2 = [f64; 2];

/// Why a polygon could not be triangulated.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum TriangulateError {
    /// A loop has fewer than 3 vertices or zero area.
    DegenerateLoop {
        /// Index of the loop (0 is the outer loop).
        loop_index: usize,
    },
    /// No ray from a hole reached the outer boundary (hole outside, or overlapping another loop).
    HoleNotInside {
        /// Index of the loop (1.. are holes).
        loop_index: usize,
    },
    /// Ear clipping found no ear with this many vertices left (self-intersecting or collinear input).
    NoEar {
        /// Vertices still unclipped.
        remaining: usize,
    },
    /// Delaunay flipping did not settle (should not happen; a bug if it does).
    FlipsDidNotConverge,
}

impl fmt::Display for TriangulateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::DegenerateLoop { loop_index } => write!(f, "loop {loop_index} has fewer than 3 vertices or no area"),
            Self::HoleNotInside { loop_index } => write!(f, "hole loop {loop_index} is not inside the outer loop"),
            Self::NoEar { remaining } => write!(f, "ear clipping stuck with {remaining} vertices left"),
            Self::FlipsDidNotConverge => write!(f, "Delaunay edge flips did not converge"),
        }
    }
}

impl std::error::Error for TriangulateError {}

/// Triangulates the region inside `loops[0]` and outside `loops[1..]`.
///
/// Returns triangles as indices into the concatenation of the loops (loop 0's points first), counter-clockwise
/// in the plane. Every loop edge is an edge of exactly one triangle and no other vertex is introduced.
pub fn triangulate(loops: &[Vec<Point2>]) -> Result<Vec<[u32; 3]>, TriangulateError> {
    let points: Vec<Point2> = loops.iter().flatten().copied().collect();
    let mut rings: Vec<Vec<u32>> = Vec::with_capacity(loops.len());
    let mut constrained: Vec<(u32, u32)> = Vec::new();
    let mut first = 0_u32;
    for (loop_index, ring) in loops.iter().enumerate() {
        let n = ring.len() as u32;
        let area = signed_area(ring);
        if n < 3 || area == 0.0 {
            return Err(TriangulateError::DegenerateLoop { loop_index });
        }
        let mut ids: Vec<u32> = (first..first + n).collect();
        let want_ccw = loop_index == 0;
        if (area > 0.0) != want_ccw {
            ids.reverse();
        }
        for (k, &a) in ids.iter().enumerate() {
            let b = ids[(k + 1) % ids.len()];
            constrained.push((a.min(b), a.max(b)));
        }
        rings.push(ids);
        first += n;
    }
    constrained.sort_unstable();

    let outer = bridge_holes(&points, rings)?;
    let mut triangles = clip_ears(&points, outer)?;
    delaunay_flips(&points, &mut triangles, &constrained)?;
    Ok(triangles)
}

/// Signed area (shoelace formula), positive for counter-clockwise loops.
pub fn signed_area(ring: &[Point2]) -> f64 {
    let mut sum = 0.0;
    for (k, a) in ring.iter().enumerate() {
        let b = ring[(k + 1) % ring.len()];
        sum += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * sum
}

/// Twice the signed area of triangle (a, b, c): positive when counter-clockwise.
fn orient(a: Point2, b: Point2, c: Point2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Merges every hole into the outer ring through bridges; returns one weakly simple ring of point ids.
fn bridge_holes(points: &[Point2], mut rings: Vec<Vec<u32>>) -> Result<Vec<u32>, TriangulateError> {
    let mut outer = rings.remove(0);
    // Rightmost vertex of each hole; holes processed right to left (ties by loop order, for determinism).
    let mut holes: Vec<(usize, usize, Vec<u32>)> = rings
        .into_iter()
        .enumerate()
        .map(|(h, ring)| {
            let mut best = 0;
            for (k, &id) in ring.iter().enumerate() {
                let (p, q) = (points[id as usize], points[ring[best] as usize]);
                if p[0] > q[0] || (p[0] == q[0] && p[1] < q[1]) {
                    best = k;
                }
            }
            (h + 1, best, ring)
        })
        .collect();
    holes.sort_by(|a, b| {
        let xa = points[a.2[a.1] as usize][0];
        let xb = points[b.2[b.1] as usize][0];
        xb.total_cmp(&xa).then(a.0.cmp(&b.0))
    });

    for (loop_index, m_at, hole) in holes {
        let m_id = hole[m_at];
        let p_at =
            find_bridge(points, &outer, points[m_id as usize]).ok_or(TriangulateError::HoleNotInside { loop_index })?;
        let p_id = outer[p_at];
        let mut merged = Vec::with_capacity(outer.len() + hole.len() + 2);
        merged.extend_from_slice(&outer[..=p_at]);
        merged.extend((0..hole.len()).map(|k| hole[(m_at + k) % hole.len()]));
        merged.push(m_id);
        merged.push(p_id);
        merged.extend_from_slice(&outer[p_at + 1..]);
        outer = merged;
    }
    Ok(outer)
}

/// Position in `ring` of a vertex visible from `m` (inside the ring), found by Eberly's ray cast in +x.
fn find_bridge(points: &[Point2], ring: &[u32], m: Point2) -> Option<usize> {
    let n = ring.len();
    let at = |k: usize| points[ring[k % n] as usize];
    // Nearest crossing of the ray y = m.y, x > m.x with an edge going upwards (the interior is on its left).
    let mut hit: Option<(f64, usize)> = None;
    for k in 0..n {
        let (a, b) = (at(k), at(k + 1));
        if !(a[1] <= m[1] && m[1] <= b[1] && a[1] < b[1]) {
            continue;
        }
        let x = a[0] + (m[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
        if x > m[0] && hit.is_none_or(|(best, _)| x < best) {
            hit = Some((x, k));
        }
    }
    let (hit_x, edge) = hit?;
    let (a, b) = (at(edge), at(edge + 1));
    // Exact hits on an edge end bridge there directly.
    if a[1] == m[1] && a[0] == hit_x {
        return Some(edge % n);
    }
    if b[1] == m[1] && b[0] == hit_x {
        return Some((edge + 1) % n);
    }
    let mut p_at = if a[0] > b[0] { edge % n } else { (edge + 1) % n };
    let p = at(p_at);
    let i = [hit_x, m[1]];
    // Reflex vertices inside triangle (m, i, p) would block the bridge: take the one closest in angle to the ray.
    let (t0, t1, t2) = if orient(m, i, p) > 0.0 { (m, i, p) } else { (m, p, i) };
    let mut best: Option<(f64, f64)> = None;
    for k in 0..n {
        let q = at(k);
        if ring[k] == ring[p_at] || !is_reflex(at(k + n - 1), q, at(k + 1)) {
            continue;
        }
        if orient(t0, t1, q) >= 0.0 && orient(t1, t2, q) >= 0.0 && orient(t2, t0, q) >= 0.0 {
            let (dx, dy) = (q[0] - m[0], q[1] - m[1]);
            let key = (dy.abs() / dx, dx * dx + dy * dy);
            if best.is_none_or(|b| key < b) {
                best = Some(key);
                p_at = k;
            }
        }
    }
    // A vertex that is already a bridge end occurs twice: use the occurrence whose wedge contains m.
    let target = ring[p_at];
    let occurrence = (0..n).find(|&k| ring[k] == target && wedge_contains(at(k + n - 1), at(k), at(k + 1), m));
    Some(occurrence.unwrap_or(p_at))
}

/// Whether the vertex `b` between `a` and `c` of a counter-clockwise ring is reflex (interior angle > 180°).
fn is_reflex(a: Point2, b: Point2, c: Point2) -> bool {
    orient(a, b, c) < 0.0
}

/// Whether direction `target - b` points into the interior wedge at vertex `b` (between edges a→b and b→c).
fn wedge_contains(a: Point2, b: Point2, c: Point2, target: Point2) -> bool {
    if orient(a, b, c) >= 0.0 {
        orient(a, b, target) > 0.0 && orient(b, c, target) > 0.0
    } else {
        orient(a, b, target) > 0.0 || orient(b, c, target) > 0.0
    }
}

/// Ear clipping of a weakly simple counter-clockwise ring (bridges appear as repeated ids).
fn clip_ears(points: &[Point2], ring: Vec<u32>) -> Result<Vec<[u32; 3]>, TriangulateError> {
    let n = ring.len();
    let mut prev: Vec<usize> = (0..n).map(|k| (k + n - 1) % n).collect();
    let mut next: Vec<usize> = (0..n).map(|k| (k + 1) % n).collect();
    let mut alive = vec![true; n];
    let ear = |k: usize, prev: &[usize], next: &[usize], alive: &[bool]| -> Option<f64> {
        let (ia, ib, ic) = (ring[prev[k]], ring[k], ring[next[k]]);
        let (a, b, c) = (points[ia as usize], points[ib as usize], points[ic as usize]);
        let area2 = orient(a, b, c);
        if area2 <= 0.0 {
            return None;
        }
        for q_at in 0..n {
            let iq = ring[q_at];
            if !alive[q_at] || iq == ia || iq == ib || iq == ic {
                continue;
            }
            let q = points[iq as usize];
            if orient(a, b, q) >= 0.0 && orient(b, c, q) >= 0.0 && orient(c, a, q) >= 0.0 {
                return None;
            }
        }
        let sq = |p: Point2, q: Point2| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2);
        Some(area2 / (sq(a, b) + sq(b, c) + sq(c, a)))
    };
    let mut quality: Vec<Option<f64>> = (0..n).map(|k| ear(k, &prev, &next, &alive)).collect();

    let mut triangles = Vec::with_capacity(n.saturating_sub(2));
    let mut remaining = n;
    let mut start = 0;
    while remaining > 3 {
        // Best ear, scanning the live ring from a fixed start so ties resolve deterministically.
        let mut best: Option<(f64, usize)> = None;
        let mut k = start;
        for _ in 0..remaining {
            if let Some(q) = quality[k]
                && best.is_none_or(|(bq, _)| q > bq)
            {
                best = Some((q, k));
            }
            k = next[k];
        }
        let (_, k) = best.ok_or(TriangulateError::NoEar { remaining })?;
        let (a, c) = (prev[k], next[k]);
        triangles.push([ring[a], ring[k], ring[c]]);
        alive[k] = false;
        next[a] = c;
        prev[c] = a;
        remaining -= 1;
        start = c;
        quality[a] = ear(a, &prev, &next, &alive);
        quality[c] = ear(c, &prev, &next, &alive);
    }
    let k = start;
    triangles.push([ring[prev[k]], ring[k], ring[next[k]]]);
    Ok(triangles)
}

/// Lawson flips of every unconstrained edge that is not locally Delaunay.
fn delaunay_flips(
    points: &[Point2],
    triangles: &mut [[u32; 3]],
    constrained: &[(u32, u32)],
) -> Result<(), TriangulateError> {
    const MAX_PASSES: usize = 10_000;
    let p = |id: u32| points[id as usize];
    // Directed edge (a, b) → triangle holding it.
    let mut owner: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for (t, tri) in triangles.iter().enumerate() {
        for e in 0..3 {
            owner.insert((tri[e], tri[(e + 1) % 3]), t);
        }
    }
    for _ in 0..MAX_PASSES {
        let mut flipped = false;
        for t in 0..triangles.len() {
            for e in 0..3 {
                let tri = triangles[t];
                let (a, b, c) = (tri[e], tri[(e + 1) % 3], tri[(e + 2) % 3]);
                if constrained.binary_search(&(a.min(b), a.max(b))).is_ok() {
                    continue;
                }
                let Some(&u) = owner.get(&(b, a)) else { continue };
                let other = triangles[u];
                let Some(d) = other.iter().copied().find(|&v| v != a && v != b) else { continue };
                if !in_circle(p(a), p(b), p(c), p(d))
                    || orient(p(a), p(d), p(c)) <= 0.0
                    || orient(p(d), p(b), p(c)) <= 0.0
                {
                    continue;
                }
                for (tri, owner_t) in [(tri, t), (other, u)] {
                    for f in 0..3 {
                        let key = (tri[f], tri[(f + 1) % 3]);
                        if owner.get(&key) == Some(&owner_t) {
                            owner.remove(&key);
                        }
                    }
                }
                triangles[t] = [a, d, c];
                triangles[u] = [d, b, c];
                for owner_t in [t, u] {
                    let tri = triangles[owner_t];
                    for f in 0..3 {
                        owner.insert((tri[f], tri[(f + 1) % 3]), owner_t);
                    }
                }
                flipped = true;
                break;
            }
        }
        if !flipped {
            return Ok(());
        }
    }
    Err(TriangulateError::FlipsDidNotConverge)
}

/// Whether `d` is strictly inside the circumcircle of the counter-clockwise triangle (a, b, c), beyond a
/// relative tolerance.
fn in_circle(a: Point2, b: Point2, c: Point2, d: Point2) -> bool {
    let (adx, ady) = (a[0] - d[0], a[1] - d[1]);
    let (bdx, bdy) = (b[0] - d[0], b[1] - d[1]);
    let (cdx, cdy) = (c[0] - d[0], c[1] - d[1]);
    let (al, bl, cl) = (adx * adx + ady * ady, bdx * bdx + bdy * bdy, cdx * cdx + cdy * cdy);
    let det = al * (bdx * cdy - cdx * bdy) + bl * (cdx * ady - adx * cdy) + cl * (adx * bdy - bdx * ady);
    let scale = al * ((bdx * cdy).abs() + (cdx * bdy).abs())
        + bl * ((cdx * ady).abs() + (adx * cdy).abs())
        + cl * ((adx * bdy).abs() + (bdx * ady).abs());
    det > 1e-10 * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(cx: f64, cy: f64, r: f64, n: usize) -> Vec<Point2> {
        (0..n)
            .map(|k| {
                let (s, c) = crate::detmath::sin_cos(std::f64::consts::TAU * k as f64 / n as f64);
                [cx + r * c, cy + r * s]
            })
            .collect()
    }

    /// Checks the triangulation covers exactly the polygon area and uses every loop edge once.
    fn check(loops: &[Vec<Point2>]) -> Vec<[u32; 3]> {
        let triangles = triangulate(loops).expect("triangulates");
        let points: Vec<Point2> = loops.iter().flatten().copied().collect();
        let vertices = points.len();
        let holes = loops.len() - 1;
        assert_eq!(triangles.len(), vertices + 2 * holes - 2, "Euler count of a polygon with holes");
        let mut area = 0.0;
        for t in &triangles {
            let a2 = orient(points[t[0] as usize], points[t[1] as usize], points[t[2] as usize]);
            assert!(a2 > 0.0, "triangle {t:?} not counter-clockwise");
            area += 0.5 * a2;
        }
        let expected = signed_area(&loops[0]).abs() - loops[1..].iter().map(|l| signed_area(l).abs()).sum::<f64>();
        assert!((area - expected).abs() < 1e-12 * expected.abs().max(1.0), "area {area} vs {expected}");
        // Every undirected edge: interior edges twice (opposite directions), loop edges once.
        let mut uses: BTreeMap<(u32, u32), i32> = BTreeMap::new();
        for t in &triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        let mut first = 0;
        let mut loop_edges = 0;
        for l in loops {
            for k in 0..l.len() {
                let (a, b) = ((first + k) as u32, (first + (k + 1) % l.len()) as u32);
                assert!(uses.get(&(a.min(b), a.max(b))).is_some_and(|u| u.abs() == 1), "loop edge {a}-{b}");
                loop_edges += 1;
            }
            first += l.len();
        }
        let interior = uses.values().filter(|u| **u == 0).count();
        assert_eq!(interior + loop_edges, uses.len(), "every edge is a loop edge or shared by two triangles");
        triangles
    }

    #[test]
    fn square_and_l_shape() {
        check(&[vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]]);
        check(&[vec![[0.0, 0.0], [3.0, 0.0], [3.0, 0.5], [0.5, 0.5], [0.5, 2.0], [0.0, 2.0]]]);
    }

    #[test]
    fn clockwise_outer_and_counter_clockwise_hole_are_reoriented() {
        let mut outer = vec![[0.0, 0.0], [4.0, 0.0], [4.0, 2.0], [0.0, 2.0]];
        outer.reverse();
        let mut hole = circle(2.0, 1.0, 0.5, 16);
        hole.reverse();
        check(&[outer, hole]);
    }

    #[test]
    fn plate_with_many_holes_in_a_row_and_a_grid() {
        let outer = vec![[0.0, 0.0], [10.0, 0.0], [10.0, 4.0], [0.0, 4.0]];
        let mut loops = vec![outer.clone()];
        for k in 0..4 {
            loops.push(circle(1.5 + 2.3 * k as f64, 2.0, 0.6, 32));
        }
        check(&loops);
        let mut grid = vec![outer];
        for (x, y) in [(1.0, 1.0), (1.0, 3.0), (9.0, 1.0), (9.0, 3.0), (5.0, 2.0)] {
            grid.push(circle(x, y, 0.5, 24));
        }
        check(&grid);
    }

    #[test]
    fn delaunay_flips_remove_slivers_of_a_thin_fan() {
        // A long strip whose ear clipping alone gives a fan of needles: the flips must leave no edge illegal.
        let mut ring = Vec::new();
        for k in 0..=20 {
            ring.push([k as f64, 0.0 + 0.01 * (k % 2) as f64]);
        }
        for k in (0..=20).rev() {
            ring.push([k as f64, 1.0]);
        }
        let triangles = check(&[ring.clone()]);
        let longest = triangles
            .iter()
            .flat_map(|t| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
            .map(|(a, b)| {
                let (p, q) = (ring[a as usize], ring[b as usize]);
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        assert!(longest < 1.6, "a Delaunay strip has no long diagonal, found {longest}");
    }

    #[test]
    fn degenerate_loops_are_errors() {
        assert_eq!(
            triangulate(&[vec![[0.0, 0.0], [1.0, 0.0]]]),
            Err(TriangulateError::DegenerateLoop { loop_index: 0 })
        );
        let outer = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let outside = circle(5.0, 0.5, 0.2, 8);
        assert_eq!(triangulate(&[outer, outside]), Err(TriangulateError::HoleNotInside { loop_index: 1 }));
    }
}
