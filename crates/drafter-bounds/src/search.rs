//! Orientation search for oriented boxes: candidate orientations from hull features, each completed by
//! the exact minimum-area rectangle, and local refinement on SO(3).
//!
//! Pieces: face normals with slivers resolved (`resolve_slivers`, `distinct_normals`); projections via
//! silhouettes (`Silhouettes`, `fit_with_normal`); crease edges with their Gauss arcs (`edge_arcs`),
//! antipodal pairs and perpendicular-arc partners in one pair scan (`edge_pairs`), closed-form edge
//! triples pruned by width bounds (`edge_triples`); support queries by hill climbing on the hull graph
//! (`HullGraph`, which also makes each refinement step O(walk) instead of O(hull)).
//!
//! All functions work on hull vertices in the local frame (see `hull::LocalPoints`) and are
//! deterministic: parallel loops only map candidates independently (each with its own scratch state)
//! and the results are reduced in index order, so nothing depends on the thread count.

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use crate::linalg::{frame_from_direction, orthonormalize, rotate};
use crate::rect::{convex_hull_2d, min_area_rect};

pub(crate) type Frame = [DVec3; 3];

/// An orientation and the volume of the box it gives around the hull vertices.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    pub axes: Frame,
    pub volume: f64,
}

impl Candidate {
    pub(crate) fn of(verts: &[DVec3], axes: Frame) -> Self {
        Self { axes, volume: frame_volume(verts, &axes) }
    }
}

/// Volume of the box with orientation `axes` around `verts`.
pub(crate) fn frame_volume(verts: &[DVec3], axes: &Frame) -> f64 {
    let (lo, hi) = frame_extents(verts, axes);
    (hi - lo).x * (hi - lo).y * (hi - lo).z
}

/// Minimum and maximum of the projections of `verts` onto the three axes.
pub(crate) fn frame_extents(verts: &[DVec3], axes: &Frame) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for v in verts {
        let d = DVec3::new(axes[0].dot(*v), axes[1].dot(*v), axes[2].dot(*v));
        lo = lo.min(d);
        hi = hi.max(d);
    }
    (lo, hi)
}

/// Vertex adjacency of a closed hull, for support queries by hill climbing: on a convex polytope a
/// vertex with no neighbour higher along a direction is a highest vertex (the simplex method's
/// optimality condition), so a walk from a nearby vertex replaces an O(h) scan.
#[derive(Clone, Debug)]
pub(crate) struct HullGraph<'a> {
    pub verts: &'a [DVec3],
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
    /// Vertices inside a flat facet (all their triangles coplanar): the only places where an ascent
    /// can stop below the maximum.
    flat: Vec<bool>,
    /// Values within this of each other count as equal when a walk meets a plateau.
    tol: f64,
}

impl<'a> HullGraph<'a> {
    /// `normals`: one per triangle, as from [`resolve_slivers`].
    pub(crate) fn new(verts: &'a [DVec3], tris: &[[u32; 3]], normals: &[DVec3]) -> Self {
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(6 * tris.len());
        for t in tris {
            for k in 0..3 {
                pairs.push((t[k], t[(k + 1) % 3]));
                pairs.push((t[(k + 1) % 3], t[k]));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; verts.len() + 1];
        for &(a, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for i in 0..verts.len() {
            offsets[i + 1] += offsets[i];
        }
        let neighbours = pairs.into_iter().map(|(_, b)| b).collect();
        let scale = verts.iter().fold(0.0f64, |s, v| s.max(v.abs().max_element()));
        let mut first: Vec<Option<DVec3>> = vec![None; verts.len()];
        let mut flat = vec![true; verts.len()];
        for (t, tri) in tris.iter().enumerate() {
            if normals[t] == DVec3::ZERO {
                continue; // an unresolved sliver says nothing about flatness
            }
            for &v in tri {
                match first[v as usize] {
                    None => first[v as usize] = Some(normals[t]),
                    Some(n) => {
                        if n.dot(normals[t]) < 1.0 - 1e-12 {
                            flat[v as usize] = false;
                        }
                    }
                }
            }
        }
        Self { verts, offsets, neighbours, flat, tol: 1e-12 * scale }
    }

    fn neighbours_of(&self, v: u32) -> &[u32] {
        &self.neighbours[self.offsets[v as usize] as usize..self.offsets[v as usize + 1] as usize]
    }

    /// A vertex maximising `dir · v`, found by ascent from `start`, and that maximum.
    ///
    /// Triangle hulls keep points that ended up inside a flat facet (they were extreme when inserted);
    /// at such a vertex every neighbour can tie, and a plain ascent would stop there. So when the ascent
    /// stops with tying neighbours, the plateau (values within `tol`) is searched for a way up.
    pub(crate) fn support(&self, dir: DVec3, start: u32) -> (u32, f64) {
        let value = |w: u32| dir.dot(self.verts[w as usize]);
        let mut v = start;
        let mut best = value(v);
        // Each step strictly increases the value (by more than `tol` after a plateau search), so the
        // walk ends; the cap guards against NaN directions.
        for _ in 0..=self.verts.len() {
            let mut moved = false;
            for &w in self.neighbours_of(v) {
                let d = value(w);
                if d > best {
                    best = d;
                    v = w;
                    moved = true;
                }
            }
            if moved {
                continue;
            }
            if !self.flat[v as usize] || !self.neighbours_of(v).iter().any(|&w| value(w) >= best - self.tol) {
                // A local maximum at a corner of the polytope is the maximum (the simplex method's
                // optimality condition): only a vertex inside a flat facet can trap the ascent.
                break;
            }
            match self.escape_plateau(dir, v, best) {
                Some((w, d)) => {
                    v = w;
                    best = d;
                }
                None => break,
            }
        }
        (v, best)
    }

    /// Searches the plateau around `v` (vertices within `tol` of `best`) for a vertex higher than
    /// `best + tol`.
    fn escape_plateau(&self, dir: DVec3, v: u32, best: f64) -> Option<(u32, f64)> {
        let value = |w: u32| dir.dot(self.verts[w as usize]);
        // Facets are usually small: a list beats hashing until it is long.
        let mut seen: Vec<u32> = vec![v];
        let mut seen_set: Option<std::collections::HashSet<u32>> = None;
        let mut stack = vec![v];
        while let Some(x) = stack.pop() {
            for &w in self.neighbours_of(x) {
                let d = value(w);
                if d > best + self.tol {
                    return Some((w, d));
                }
                if d < best - self.tol {
                    continue;
                }
                let new = match &mut seen_set {
                    Some(set) => set.insert(w),
                    None if seen.contains(&w) => false,
                    None => {
                        seen.push(w);
                        if seen.len() > 64 {
                            seen_set = Some(seen.iter().copied().collect());
                        }
                        true
                    }
                };
                if new {
                    stack.push(w);
                }
            }
        }
        None
    }

    /// Box volume along `axes`, with six support walks starting from (and updating) `hints`.
    pub(crate) fn volume(&self, axes: &Frame, hints: &mut [u32; 6]) -> f64 {
        let mut volume = 1.0;
        for k in 0..3 {
            let (hi_v, hi) = self.support(axes[k], hints[2 * k]);
            let (lo_v, lo) = self.support(-axes[k], hints[2 * k + 1]);
            hints[2 * k] = hi_v;
            hints[2 * k + 1] = lo_v;
            volume *= hi + lo;
        }
        volume
    }
}

/// Best box with one face normal to the unit vector `n`: the hull is projected onto the plane normal to
/// `n` and the minimum-area rectangle of the projection (rotating calipers) completes the frame. Exact
/// for the given `n`. `outline` lists the vertices whose projections can be on the projected hull
/// (all vertices, or a silhouette from [`Silhouettes`]).
pub(crate) fn fit_with_normal(verts: &[DVec3], outline: &[u32], n: DVec3, scratch: &mut Vec<DVec2>) -> Candidate {
    let [n, u, v] = frame_from_direction(n);
    scratch.clear();
    scratch.extend(outline.iter().map(|&i| DVec2::new(u.dot(verts[i as usize]), v.dot(verts[i as usize]))));
    let scale = scratch.iter().fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let ring = convex_hull_2d(scratch, 1e-12 * scale);
    let poly: Vec<DVec2> = ring.iter().map(|&i| scratch[i as usize]).collect();
    let rect = min_area_rect(&poly);
    let a0 = u * rect.dir.x + v * rect.dir.y;
    let axes = orthonormalize([a0, n.cross(a0), n]);
    // The volume is measured, not taken from the rectangle: robust to rounding in the projection.
    Candidate::of(verts, axes)
}

/// Silhouettes of a closed hull: the vertices on edges between triangles facing towards and away from a
/// direction are the only ones whose projections can be corners of the projected hull, which makes
/// each projection O(triangles + silhouette · log) instead of O(vertices · log vertices).
#[derive(Clone, Debug)]
pub(crate) struct Silhouettes<'a> {
    verts: &'a [DVec3],
    tri_normals: &'a [DVec3],
    edges: &'a [[u32; 4]],
}

impl<'a> Silhouettes<'a> {
    pub(crate) fn new(verts: &'a [DVec3], tri_normals: &'a [DVec3], edges: &'a [[u32; 4]]) -> Self {
        Self { verts, tri_normals, edges }
    }

    /// The silhouette vertices for direction `n` into `out` (unique, in edge order).
    fn outline(&self, n: DVec3, front: &mut Vec<bool>, stamp: &mut Vec<bool>, out: &mut Vec<u32>) {
        front.clear();
        front.extend(self.tri_normals.iter().map(|t| t.dot(n) >= 0.0));
        stamp.clear();
        stamp.resize(self.verts.len(), false);
        out.clear();
        for &[a, b, t0, t1] in self.edges {
            if front[t0 as usize] != front[t1 as usize] {
                for x in [a, b] {
                    if !stamp[x as usize] {
                        stamp[x as usize] = true;
                        out.push(x);
                    }
                }
            }
        }
    }
}

/// Evaluates `fit_with_normal` for every normal in parallel; results in input order. With
/// `silhouettes`, only silhouette vertices are projected.
pub(crate) fn fit_normals(verts: &[DVec3], silhouettes: Option<&Silhouettes<'_>>, normals: &[DVec3]) -> Vec<Candidate> {
    let all: Vec<u32> = (0..verts.len() as u32).collect();
    normals
        .par_iter()
        .map_init(
            || (Vec::new(), Vec::new(), Vec::new(), Vec::new()),
            |(scratch, front, stamp, outline), n| match silhouettes {
                Some(s) => {
                    s.outline(*n, front, stamp, outline);
                    if outline.len() >= 3 {
                        fit_with_normal(verts, outline, *n, scratch)
                    } else {
                        fit_with_normal(verts, &all, *n, scratch)
                    }
                }
                None => fit_with_normal(verts, &all, *n, scratch),
            },
        )
        .collect()
}

/// Each edge of a closed triangle mesh once, as `[a, b, t0, t1]`: its end vertices and the triangles on
/// either side (`t0` holds the directed edge `a → b`).
pub(crate) fn mesh_edges(tris: &[[u32; 3]]) -> Vec<[u32; 4]> {
    let mut half: Vec<(u32, u32, u32, u32)> = Vec::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), t as u32, u32::from(a > b)));
        }
    }
    half.sort_unstable();
    half.chunks(2)
        .filter_map(|pair| match pair {
            [(a, b, t0, d0), (a1, b1, t1, _)] if (a, b) == (a1, b1) => {
                // orient so that t0 holds a → b
                Some(if *d0 == 0 { [*a, *b, *t0, *t1] } else { [*a, *b, *t1, *t0] })
            }
            _ => None,
        })
        .collect()
}

/// The smallest width of the hull along any of `normals` (a lower bound of the width in every direction
/// when `normals` holds every face normal and every antipodal edge-pair direction).
pub(crate) fn min_width(verts: &[DVec3], normals: &[DVec3]) -> f64 {
    normals
        .par_iter()
        .map(|n| {
            let (lo, hi) = verts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                let d = n.dot(*v);
                (lo.min(d), hi.max(d))
            });
            hi - lo
        })
        .reduce(|| f64::INFINITY, f64::min)
}

/// Index of the smallest candidate (ties: lowest index).
pub(crate) fn best_index(candidates: &[Candidate]) -> Option<usize> {
    let mut best: Option<usize> = None;
    for (i, c) in candidates.iter().enumerate() {
        if !c.volume.is_finite() {
            continue;
        }
        match best {
            Some(b) if candidates[b].volume <= c.volume => {}
            _ => best = Some(i),
        }
    }
    best
}

/// Up to `count` candidates with the smallest volumes, skipping orientations that repeat an earlier
/// pick (same three axis lines within 1e-3 rad).
pub(crate) fn best_distinct(candidates: &[Candidate], count: usize) -> Vec<Candidate> {
    let mut order: Vec<usize> = (0..candidates.len()).filter(|&i| candidates[i].volume.is_finite()).collect();
    order.sort_by(|&a, &b| candidates[a].volume.total_cmp(&candidates[b].volume).then(a.cmp(&b)));
    let mut picked: Vec<Candidate> = Vec::new();
    for i in order {
        if picked.len() >= count {
            break;
        }
        let c = candidates[i];
        if !picked.iter().any(|p| same_orientation(&p.axes, &c.axes)) {
            picked.push(c);
        }
    }
    picked
}

fn same_orientation(a: &Frame, b: &Frame) -> bool {
    let cos_tol = (1e-3f64).cos();
    a.iter().all(|x| b.iter().any(|y| x.dot(*y).abs() >= cos_tol))
}

/// Pattern search on SO(3): rotations of the box about its three axes and the six diagonals between
/// them, both signs, starting at `start_step` radians and halving down to `min_step`. Accepts any
/// strict improvement. The diagonal moves let the search follow the creases of the volume function (its
/// minima are typically kinks where the supporting vertices change).
pub(crate) fn refine(
    graph: &HullGraph<'_>,
    start: Candidate,
    start_step: f64,
    min_step: f64,
    max_evals: usize,
) -> Candidate {
    let mut hints = [0u32; 6];
    let mut best = Candidate { axes: start.axes, volume: graph.volume(&start.axes, &mut hints) };
    let mut step = start_step;
    let mut evals = 0;
    let s = std::f64::consts::FRAC_1_SQRT_2;
    let combos: [(f64, f64, f64); 9] = [
        (1.0, 0.0, 0.0),
        (0.0, 1.0, 0.0),
        (0.0, 0.0, 1.0),
        (s, s, 0.0),
        (s, -s, 0.0),
        (s, 0.0, s),
        (s, 0.0, -s),
        (0.0, s, s),
        (0.0, s, -s),
    ];
    while step >= min_step && evals < max_evals {
        let mut improved = false;
        let (sin, cos) = step.sin_cos();
        for &(x, y, z) in &combos {
            for sign in [1.0, -1.0] {
                let axis = (best.axes[0] * x + best.axes[1] * y + best.axes[2] * z).normalize();
                let axes = orthonormalize(best.axes.map(|a| rotate(a, axis, cos, sign * sin)));
                let volume = graph.volume(&axes, &mut hints);
                evals += 1;
                if volume < best.volume {
                    best = Candidate { axes, volume };
                    improved = true;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    best
}

/// A hull edge with its arc on the Gauss sphere: the directions in which the edge is a supporting edge
/// are the great-circle arc between the normals of its two triangles (the circle normal to `dir`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct EdgeArc {
    /// Unit edge direction.
    pub dir: DVec3,
    /// Unit midpoint of the arc (perpendicular to `dir`).
    pub centre: DVec3,
    /// `dir × centre`: with `centre`, a basis of the arc's great circle.
    pub side: DVec3,
    /// Half the arc angle (radians).
    pub radius: f64,
    /// `cos(radius + slack)`: a direction `n` on the circle is on the arc (up to sign) iff
    /// `|n · centre| ≥ cos_reach`.
    pub cos_reach: f64,
    /// One end of the edge (index into the hull vertices).
    pub vertex: u32,
    /// A hull vertex lowest along `centre`: the opposite side of a box face flush with this edge is
    /// near it (walks start there, and it bounds the box's width from below).
    pub opposite: u32,
    /// A lower bound of the hull's width along any direction on the arc (0 until `find_opposites`).
    pub width_lb: f64,
    /// `cos` and `sin` of `radius` and of `radius + slack`, for angle sums without trigonometric calls.
    pub cos_r: f64,
    pub sin_r: f64,
    pub sin_reach: f64,
}

/// Unit normals and areas of the hull triangles.
pub(crate) fn triangle_normals(verts: &[DVec3], tris: &[[u32; 3]]) -> (Vec<DVec3>, Vec<f64>) {
    tris.iter()
        .map(|t| {
            let p = t.map(|i| verts[i as usize]);
            let l = [p[1].distance_squared(p[2]), p[2].distance_squared(p[0]), p[0].distance_squared(p[1])];
            let k = if l[0] >= l[1] && l[0] >= l[2] {
                0
            } else if l[1] >= l[2] {
                1
            } else {
                2
            };
            let c = (p[(k + 1) % 3] - p[k]).cross(p[(k + 2) % 3] - p[k]);
            (c.normalize_or_zero(), 0.5 * c.length())
        })
        .unzip()
}

/// Normals with slivers resolved. Quickhull keeps a point that was extreme when inserted even if it
/// ends up within `eps` of a hull edge (the midpoint of a straight CAD edge, once the edge's ends
/// arrive): the triangle it forms with that edge is a sliver whose computed normal is noise. Its true
/// neighbourhood is the plane across its long edge, so a sliver takes that triangle's normal (following
/// further slivers a few steps); the mid-edge point then sits on a crease between two real faces, as it
/// geometrically does. Unresolvable slivers get a zero normal (ignored by the callers).
pub(crate) fn resolve_slivers(verts: &[DVec3], tris: &[[u32; 3]], edges: &[[u32; 4]], eps: f64) -> Vec<DVec3> {
    let (mut normals, _) = triangle_normals(verts, tris);
    // Neighbour across each triangle's longest edge.
    let mut across_long: Vec<Option<u32>> = vec![None; tris.len()];
    let mut sliver = vec![false; tris.len()];
    let long_edge = |t: &[u32; 3]| -> (u32, u32, f64) {
        let p = t.map(|i| verts[i as usize]);
        let len = [p[0].distance(p[1]), p[1].distance(p[2]), p[2].distance(p[0])];
        let e = if len[0] >= len[1] && len[0] >= len[2] {
            0
        } else if len[1] >= len[2] {
            1
        } else {
            2
        };
        let (a, b, m) = (p[e], p[(e + 1) % 3], p[(e + 2) % 3]);
        let height = (b - a).cross(m - a).length() / len[e].max(f64::MIN_POSITIVE);
        let (i, j) = (t[e], t[(e + 1) % 3]);
        (i.min(j), i.max(j), height)
    };
    let longs: Vec<(u32, u32, f64)> = tris.iter().map(long_edge).collect();
    for (t, &(_, _, height)) in longs.iter().enumerate() {
        sliver[t] = height <= eps || normals[t] == DVec3::ZERO;
    }
    if !sliver.iter().any(|s| *s) {
        return normals;
    }
    for &[a, b, t0, t1] in edges {
        for (t, other) in [(t0, t1), (t1, t0)] {
            let (la, lb, _) = longs[t as usize];
            if sliver[t as usize] && (la, lb) == (a.min(b), a.max(b)) {
                across_long[t as usize] = Some(other);
            }
        }
    }
    for t in 0..tris.len() {
        if !sliver[t] {
            continue;
        }
        let mut cur = t;
        let mut resolved = DVec3::ZERO;
        for _ in 0..8 {
            let Some(next) = across_long[cur] else { break };
            cur = next as usize;
            if !sliver[cur] {
                resolved = normals[cur];
                break;
            }
        }
        normals[t] = resolved;
    }
    // Only non-sliver normals are copied, and those never change: the loop order does not matter.
    normals
}

/// Distinct face normals with their total areas, largest area first. Triangles whose normals agree to
/// 1e-9 (after making the sign canonical: a box normal to `n` is also normal to `−n`) are one face.
pub(crate) fn distinct_normals(normals: &[DVec3], areas: &[f64]) -> Vec<(DVec3, f64)> {
    let quantum = 1e-9;
    let mut keyed: Vec<([i64; 3], usize)> = normals
        .iter()
        .enumerate()
        .filter(|(_, n)| **n != DVec3::ZERO)
        .map(|(i, n)| {
            let c = crate::linalg::canonical_sign(*n);
            ([(c.x / quantum).round() as i64, (c.y / quantum).round() as i64, (c.z / quantum).round() as i64], i)
        })
        .collect();
    keyed.sort_unstable();
    let mut out: Vec<(DVec3, f64, f64)> = Vec::new(); // normal of the largest member, its area, total area
    let mut last_key: Option<[i64; 3]> = None;
    for (key, i) in keyed {
        let n = crate::linalg::canonical_sign(normals[i]);
        if last_key == Some(key) {
            if let Some(group) = out.last_mut() {
                if areas[i] > group.1 {
                    group.0 = n;
                    group.1 = areas[i];
                }
                group.2 += areas[i];
            }
        } else {
            out.push((n, areas[i], areas[i]));
            last_key = Some(key);
        }
    }
    let mut out: Vec<(DVec3, f64)> = out.into_iter().map(|(n, _, total)| (n, total)).collect();
    // Stable sort: equal areas keep the key order, which is deterministic.
    out.sort_by(|a, b| b.1.total_cmp(&a.1));
    out
}

/// Removes repeated directions (equal to 1e-9 up to sign), keeping the first occurrence of each.
pub(crate) fn dedupe_directions(dirs: &[DVec3]) -> Vec<DVec3> {
    let quantum = 1e-9;
    let mut keyed: Vec<([i64; 3], usize)> = dirs
        .iter()
        .enumerate()
        .filter(|(_, d)| d.is_finite() && **d != DVec3::ZERO)
        .map(|(i, d)| {
            let c = crate::linalg::canonical_sign(d.normalize());
            ([(c.x / quantum).round() as i64, (c.y / quantum).round() as i64, (c.z / quantum).round() as i64], i)
        })
        .collect();
    keyed.sort_unstable();
    keyed.dedup_by(|a, b| a.0 == b.0);
    let mut keep: Vec<usize> = keyed.into_iter().map(|(_, i)| i).collect();
    keep.sort_unstable();
    keep.into_iter().map(|i| dirs[i].normalize()).collect()
}

/// Hull edges that are creases (their two triangles are not coplanar), with their Gauss arcs.
pub(crate) fn edge_arcs(verts: &[DVec3], edges: &[[u32; 4]], normals: &[DVec3]) -> Vec<EdgeArc> {
    let mut arcs = Vec::new();
    for &[a, b, t0, t1] in edges {
        let (na, nb) = (normals[t0 as usize], normals[t1 as usize]);
        if na == DVec3::ZERO || nb == DVec3::ZERO {
            continue;
        }
        let angle = na.angle_between(nb);
        if angle <= 1e-9 {
            continue;
        }
        let dir = (verts[b as usize] - verts[a as usize]).normalize_or_zero();
        if dir == DVec3::ZERO {
            continue;
        }
        let mid = na + nb;
        let centre = (mid - dir * dir.dot(mid)).normalize_or_zero();
        if centre == DVec3::ZERO {
            continue;
        }
        let radius = 0.5 * angle;
        arcs.push(EdgeArc {
            dir,
            centre,
            side: dir.cross(centre),
            radius,
            cos_reach: (radius + ARC_SLACK).min(std::f64::consts::FRAC_PI_2).cos(),
            vertex: a,
            opposite: 0,
            width_lb: 0.0,
            cos_r: radius.cos(),
            sin_r: radius.sin(),
            sin_reach: (radius + ARC_SLACK).min(std::f64::consts::FRAC_PI_2).sin(),
        });
    }
    arcs
}

/// Angular slack when testing whether a direction lies on an edge's arc.
const ARC_SLACK: f64 = 1e-9;

/// Fills [`EdgeArc::opposite`] by support walks (each from the previous answer).
pub(crate) fn find_opposites(graph: &HullGraph<'_>, arcs: &mut [EdgeArc]) {
    let mut hint = 0;
    for arc in arcs.iter_mut() {
        let (v, _) = graph.support(-arc.centre, hint);
        arc.opposite = v;
        hint = v;
        // For n on the arc, |n − centre| ≤ 2 sin(r/2), so n·(p − q) ≥ centre·(p − q) − 2 sin(r/2)|p − q|
        // with p on the edge and q any hull vertex.
        let d = graph.verts[arc.vertex as usize] - graph.verts[v as usize];
        let slack = 2.0 * (0.5 * (arc.radius + ARC_SLACK)).sin() * d.length();
        arc.width_lb = ((arc.centre.dot(d) - slack) * (1.0 - 1e-9)).max(0.0);
    }
}

/// The pairwise relations between crease edges, found in one scan over all pairs.
#[derive(Clone, Debug)]
pub(crate) struct EdgePairs {
    /// Normals `e_i × e_j` of antipodal edge pairs: edge `i` supports the hull in direction `n` and edge
    /// `j` in `−n` (or the reverse), so a box with that face normal has both edges flush with opposite
    /// faces.
    pub antipodal: Vec<DVec3>,
    /// For each edge `i`, the edges `j > i` whose arcs hold perpendicular directions (candidates for
    /// adjacent box faces); `None` when there are more than the budget.
    pub partners: Option<Vec<Vec<u32>>>,
}

/// Scans all pairs of crease edges. `None` when the scan itself (`E²/2` tests) exceeds `budget`.
pub(crate) fn edge_pairs(arcs: &[EdgeArc], budget: u64) -> Option<EdgePairs> {
    let e = arcs.len() as u64;
    if e * e.saturating_sub(1) / 2 > budget {
        return None;
    }
    // Partner lists can be quadratic: stop collecting them once their total passes the budget (the
    // outcome, "over budget", does not depend on which thread noticed first).
    let collected = std::sync::atomic::AtomicU64::new(0);
    let over = std::sync::atomic::AtomicBool::new(false);
    let per_edge: Vec<(Vec<DVec3>, Vec<u32>)> = (0..arcs.len())
        .into_par_iter()
        .map(|i| {
            let a = arcs[i];
            let mut antipodal = Vec::new();
            let mut partners = Vec::new();
            let keep_partners = !over.load(std::sync::atomic::Ordering::Relaxed);
            for (j, b) in arcs.iter().enumerate().skip(i + 1) {
                // reach = r_a + slack + r_b, by the angle-sum formulas.
                let cos_reach = a.cos_reach * b.cos_r - a.sin_reach * b.sin_r;
                let sin_reach = a.sin_reach * b.cos_r + a.cos_reach * b.sin_r;
                let cos_centres = a.centre.dot(b.centre).abs();
                // Perpendicular directions on both arcs: the centre lines are at least 90° − reach apart.
                if keep_partners && (cos_reach <= 0.0 || cos_centres <= sin_reach) {
                    partners.push(j as u32);
                }
                // Antipodal: the centres are (nearly) opposite or equal up to the radii.
                if cos_reach > 0.0 && cos_centres < cos_reach {
                    continue;
                }
                let n = a.dir.cross(b.dir);
                let len = n.length();
                if len < 1e-12 {
                    continue;
                }
                let n = n / len;
                // n lies on both circles; it (or −n) must be on arc a, and the opposite sign on arc b.
                let sa = a.centre.dot(n);
                let sb = b.centre.dot(n);
                if sa.abs() >= a.cos_reach && sb.abs() >= b.cos_reach && sa * sb < 0.0 {
                    antipodal.push(n);
                }
            }
            if keep_partners {
                let total = collected.fetch_add(partners.len() as u64, std::sync::atomic::Ordering::Relaxed);
                if total + partners.len() as u64 > budget {
                    over.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }
            (antipodal, partners)
        })
        .collect();
    let over = over.load(std::sync::atomic::Ordering::Relaxed);
    let mut antipodal = Vec::new();
    let mut partners = Vec::with_capacity(per_edge.len());
    for (a, p) in per_edge {
        antipodal.extend(a);
        partners.push(p);
    }
    Some(EdgePairs { antipodal, partners: (!over).then_some(partners) })
}

/// Outcome of the three-edge search.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TripleSearch {
    pub best: Option<(Frame, f64)>,
    /// Whether every compatible edge triple was solved.
    pub complete: bool,
    /// Number of valid configurations whose volume was evaluated.
    pub evaluated: u64,
}

/// Every orientation whose three box faces are each flush with a different hull edge: for edges
/// `e1, e2, e3` the face normals satisfy `n_k ⊥ e_k`, and `n_k` (or `−n_k`) must lie on edge `k`'s Gauss
/// arc. With `n1(t) = u cos t + v sin t` on the circle normal to `e1`, `n2 ∝ e2 × n1` and
/// `n3 = n1 × n2 ∝ e2 − (n1·e2) n1`, the last condition `n3 · e3 = 0` becomes
/// `(n1·e2)(n1·e3) = e2·e3`, i.e. `A cos 2t + B sin 2t = C`: at most two orientations per triple, in
/// closed form. Pairs whose arcs cannot hold perpendicular directions are pruned first; the search is
/// skipped (`complete = false`) when its work estimate exceeds `budget`.
///
/// `limit` is the best volume known (from cases 1–2) and `min_width` a lower bound of the hull's width
/// in every direction: a triple whose arcs' width bounds multiply to `limit` or more cannot win and is
/// skipped unsolved, and so is every pair for which `w_i · w_j · min_width ≥ limit`.
pub(crate) fn edge_triples(
    graph: &HullGraph<'_>,
    arcs: &[EdgeArc],
    partners: &[Vec<u32>],
    budget: u64,
    limit: f64,
    min_width: f64,
) -> TripleSearch {
    let e = arcs.len();
    // Pairs that cannot beat `limit` whatever the third width: w_i · w_j · min_width ≥ limit.
    let partners: Vec<Vec<u32>> = partners
        .par_iter()
        .enumerate()
        .map(|(i, list)| {
            list.iter().copied().filter(|&j| arcs[i].width_lb * arcs[j as usize].width_lb * min_width < limit).collect()
        })
        .collect();
    let work: u64 =
        partners.iter().map(|list| list.iter().map(|&j| partners[j as usize].len() as u64).sum::<u64>()).sum::<u64>();
    if work > budget {
        return TripleSearch::default();
    }
    let results: Vec<(Option<(Frame, f64)>, u64)> = (0..e)
        .into_par_iter()
        .map_init(
            || vec![false; e],
            |mark, i| {
                let mut best: Option<(Frame, f64)> = None;
                let mut evaluated = 0;
                for &j in &partners[i] {
                    mark[j as usize] = true;
                }
                for &j in &partners[i] {
                    let pb = PairBasis::new(&arcs[i], &arcs[j as usize]);
                    let wij = arcs[i].width_lb * arcs[j as usize].width_lb;
                    for &k in &partners[j as usize] {
                        if !mark[k as usize] || wij * arcs[k as usize].width_lb >= limit {
                            continue;
                        }
                        let edges = [&arcs[i], &arcs[j as usize], &arcs[k as usize]];
                        for axes in solve_triple(edges[0], edges[1], edges[2], pb).into_iter().flatten() {
                            evaluated += 1;
                            let bound = best.map_or(limit, |(_, v): (Frame, f64)| v.min(limit));
                            if let Some(volume) = triple_volume(graph, &axes, edges, bound)
                                && volume < bound
                            {
                                best = Some((axes, volume));
                            }
                        }
                    }
                }
                for &j in &partners[i] {
                    mark[j as usize] = false;
                }
                (best, evaluated)
            },
        )
        .collect();
    let mut out = TripleSearch { best: None, complete: true, evaluated: 0 };
    for (best, evaluated) in results {
        out.evaluated += evaluated;
        if let Some((axes, v)) = best
            && out.best.is_none_or(|(_, b)| v < b)
        {
            out.best = Some((axes, v));
        }
    }
    // Re-measure the winner by a full scan (the walk values assume the edge is exactly flush).
    out.best = out.best.map(|(axes, _)| {
        let axes = orthonormalize(axes);
        (axes, frame_volume(graph.verts, &axes))
    });
    out
}

/// Quantities of a triple that depend only on its first two edges.
#[derive(Clone, Copy)]
struct PairBasis {
    /// `(u·e2, v·e2)` with `(u, v)` the basis of arc 1's circle.
    a2: f64,
    b2: f64,
}

impl PairBasis {
    fn new(a: &EdgeArc, b: &EdgeArc) -> Self {
        Self { a2: a.centre.dot(b.dir), b2: a.side.dot(b.dir) }
    }
}

/// The (at most two) frames with face normals `n_k ⊥ e_k` on the three arcs. Square-root-free
/// rejection first: most triples fail one of the arc tests.
fn solve_triple(a: &EdgeArc, b: &EdgeArc, c: &EdgeArc, pb: PairBasis) -> [Option<Frame>; 2] {
    let (u, v) = (a.centre, a.side);
    let (a2, b2) = (pb.a2, pb.b2);
    let (a3, b3) = (u.dot(c.dir), v.dot(c.dir));
    let k = b.dir.dot(c.dir);
    // (a2 cos t + b2 sin t)(a3 cos t + b3 sin t) = k  ⇔  P cos 2t + Q sin 2t = C
    let p = 0.5 * (a2 * a3 - b2 * b3);
    let q = 0.5 * (a2 * b3 + b2 * a3);
    let rhs = k - 0.5 * (a2 * a3 + b2 * b3);
    let r2 = p * p + q * q;
    if r2 < 1e-30 || rhs * rhs > r2 * (1.0 + 1e-12) {
        return [None, None];
    }
    let r = r2.sqrt();
    // cos(2t − β) = C/R with (cos β, sin β) = (P, Q)/R, solved without trigonometric calls.
    let (cb, sb) = (p / r, q / r);
    let cd = (rhs / r).clamp(-1.0, 1.0);
    let sd = (1.0 - cd * cd).max(0.0).sqrt();
    let min_cos2 = a.cos_reach * a.cos_reach;
    let solve = |sign: f64| -> Option<Frame> {
        let (cos2t, sin2t) = (cb * cd - sign * sb * sd, sb * cd + sign * cb * sd);
        // Half angle folded to cos t ≥ 0 (n1 and −n1 give the same box): cos² t = (1 + cos 2t)/2.
        let cos_sq = 0.5 * (1.0 + cos2t);
        if cos_sq < min_cos2 {
            return None; // outside arc a
        }
        let co = cos_sq.sqrt();
        let si = if co > 1e-12 { 0.5 * sin2t / co } else { 1.0 };
        let n1 = u * co + v * si;
        let n2 = b.dir.cross(n1);
        let len2 = n2.length_squared();
        if len2 < 1e-24 {
            return None;
        }
        let d2 = n2.dot(b.centre);
        if d2 * d2 < b.cos_reach * b.cos_reach * len2 {
            return None;
        }
        // |n1 × n2| = |n2| since n1 ⊥ n2.
        let n3 = n1.cross(n2);
        let d3 = n3.dot(c.centre);
        if d3 * d3 < c.cos_reach * c.cos_reach * len2 || n3.dot(c.dir).abs() > 1e-9 * len2.sqrt() {
            return None;
        }
        let len = len2.sqrt();
        Some([n1, n2 / len, n3 / len])
    };
    [solve(1.0), if sd > 0.0 { solve(-1.0) } else { None }]
}

/// Volume of a three-edge configuration, or `None` when a lower bound already reaches `limit`. Along
/// each axis one side is known (the flush edge's vertex); the other starts at the arc's opposite
/// vertex, which gives the lower bound, and is completed by a support walk.
fn triple_volume(graph: &HullGraph<'_>, axes: &Frame, edges: [&EdgeArc; 3], limit: f64) -> Option<f64> {
    let mut dirs = [DVec3::ZERO; 3];
    let mut tops = [0.0; 3];
    let mut lower = 1.0;
    for k in 0..3 {
        let n = if axes[k].dot(edges[k].centre) >= 0.0 { axes[k] } else { -axes[k] };
        dirs[k] = n;
        tops[k] = n.dot(graph.verts[edges[k].vertex as usize]);
        lower *= tops[k] - n.dot(graph.verts[edges[k].opposite as usize]);
    }
    if lower >= limit {
        return None;
    }
    let mut volume = 1.0;
    for k in 0..3 {
        let (_, low) = graph.support(-dirs[k], edges[k].opposite);
        volume *= tops[k] + low;
    }
    Some(volume)
}
