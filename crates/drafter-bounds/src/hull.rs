//! 3D convex hull by quickhull (Barber, Dobkin & Huhdanpaa 1996) in f64, with an exact orientation
//! predicate for visibility.
//!
//! # How it works
//! 1. Points are moved to a local origin (the centre of their axis-aligned box), so a part placed 10⁶
//!    units from the world origin keeps its full f64 precision relative to its own size.
//! 2. The dimension is found from extreme points: the two farthest of the six axis extremes, the point
//!    farthest from their line, the point farthest from that plane. If the spread along a step is within the
//!    tolerance the hull is a [`HullDimension::Point`], a [`HullDimension::Segment`] or a planar
//!    [`HullDimension::Polygon`] (2D monotone chain in the plane); otherwise a tetrahedron starts the 3D hull.
//! 3. Every point is assigned to one face it lies more than the tolerance `ε` above (*conflict list*);
//!    points within `ε` of the current hull are discarded, which keeps the hull of a tessellated plane from
//!    filling with rounding-noise vertices.
//! 4. Repeatedly the farthest conflict point of a face is added: the faces it sees are found by a
//!    breadth-first walk using the *exact* sign of `orient3d` (see `predicates`), their boundary is the
//!    horizon, a cone of new triangles joins the horizon to the point, and the orphaned conflict points are
//!    reassigned to the new faces. With exact visibility the visible region is always a disk, so the hull
//!    stays a closed, consistently oriented triangle mesh whatever the input's degeneracies.
//!
//! # Guarantees and limits
//! * Every input point is inside the hull or within `ε` (plus rounding) of a face plane; `ε` is
//!   `tolerance × max |local coordinate|` (see [`HullOptions`]).
//! * A 3D hull is closed: every edge has two triangles, V − E + F = 2, triangles wind counter-clockwise
//!   seen from outside, and it is convex in exact arithmetic. Coplanar hull facets stay triangulated
//!   (they are not merged into polygons), and a point that was extreme when inserted stays a vertex even
//!   if later points leave it inside a flat facet or within `ε` of an edge (then it forms a sliver
//!   triangle). Consumers that need face normals resolve such slivers (`search::resolve_slivers`).
//!   Tested on the 664 parts of ../shared/models: every point within 0.96 `ε` of every face plane.
//! * Deterministic: no hashing, no randomness, one fixed processing order.
//! * Expected O(n log n); pathological inputs (all points on a sphere) grow towards O(n·h).

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use crate::BoundsError;
use crate::predicates::orient3d;
use crate::rect::convex_hull_2d;

/// Default of [`HullOptions::tolerance`].
pub const DEFAULT_HULL_TOLERANCE: f64 = 1e-10;

/// Options of [`convex_hull`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HullOptions {
    /// Relative distance below which a point counts as on the hull (and is dropped), as a fraction of the
    /// largest coordinate magnitude after centring. Default [`DEFAULT_HULL_TOLERANCE`] (1e-10); range
    /// [0, 1e-3]. Larger values give smaller hulls of noisy tessellations; oriented boxes are always fitted
    /// to *all* input points at the end, so this only trades hull size against box tightness.
    pub tolerance: f64,
}

impl Default for HullOptions {
    fn default() -> Self {
        Self { tolerance: DEFAULT_HULL_TOLERANCE }
    }
}

/// The dimension of a point set's hull.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HullDimension {
    /// All points coincide (within tolerance).
    Point,
    /// All points lie on a line: the hull is its two end points.
    Segment,
    /// All points lie in a plane: the hull is a convex polygon.
    Polygon,
    /// A closed convex polyhedron.
    Solid,
}

/// The convex hull of a point set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConvexHull {
    /// Hull vertices in world space (copies of input points).
    pub vertices: Vec<DVec3>,
    /// For each vertex, its index in the input slice.
    pub input_indices: Vec<u32>,
    /// Outward-facing, counter-clockwise triangles over `vertices`; only for [`HullDimension::Solid`].
    /// For [`HullDimension::Polygon`], `vertices` are the polygon in counter-clockwise order around
    /// `polygon_normal` and this list is empty.
    pub triangles: Vec<[u32; 3]>,
    pub dimension: HullDimension,
    /// Unit normal of the plane of a [`HullDimension::Polygon`] hull; zero otherwise.
    pub polygon_normal: DVec3,
    /// The absolute distance tolerance `ε` that was used (world units).
    pub tolerance: f64,
}

/// Computes the convex hull of `points`. Errors on empty input and on non-finite coordinates.
pub fn convex_hull(points: &[DVec3], options: &HullOptions) -> Result<ConvexHull, BoundsError> {
    let local = LocalPoints::new(points)?;
    let hull = LocalHull::build(&local, options.tolerance);
    Ok(ConvexHull {
        vertices: hull.input_indices.iter().map(|&i| points[i as usize]).collect(),
        input_indices: hull.input_indices.clone(),
        triangles: hull.triangles.clone(),
        dimension: hull.dimension,
        polygon_normal: hull.polygon_normal,
        tolerance: hull.eps,
    })
}

/// Input points moved to a local origin.
#[derive(Clone, Debug)]
pub(crate) struct LocalPoints {
    pub origin: DVec3,
    pub points: Vec<DVec3>,
    /// Largest coordinate magnitude after centring (0 for a single point).
    pub scale: f64,
}

impl LocalPoints {
    pub(crate) fn new(points: &[DVec3]) -> Result<Self, BoundsError> {
        if points.is_empty() {
            return Err(BoundsError::EmptyInput);
        }
        if points.len() > u32::MAX as usize {
            return Err(BoundsError::TooManyPoints { count: points.len() });
        }
        let mut min = DVec3::splat(f64::INFINITY);
        let mut max = DVec3::splat(f64::NEG_INFINITY);
        for (index, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(BoundsError::NonFinitePoint { index });
            }
            min = min.min(*p);
            max = max.max(*p);
        }
        let origin = 0.5 * (min + max);
        let local: Vec<DVec3> = points.iter().map(|p| *p - origin).collect();
        let scale = local.iter().fold(0.0f64, |s, p| s.max(p.abs().max_element()));
        Ok(Self { origin, points: local, scale })
    }
}

/// A hull in the local frame of a [`LocalPoints`].
#[derive(Clone, Debug)]
pub(crate) struct LocalHull {
    pub vertices: Vec<DVec3>,
    pub input_indices: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
    pub dimension: HullDimension,
    pub polygon_normal: DVec3,
    pub eps: f64,
}

const NONE: u32 = u32::MAX;

impl LocalHull {
    pub(crate) fn build(local: &LocalPoints, tolerance: f64) -> Self {
        let tolerance = if tolerance.is_finite() { tolerance.clamp(0.0, 1e-3) } else { DEFAULT_HULL_TOLERANCE };
        // Never below what f64 can resolve at this scale.
        let eps = (tolerance * local.scale).max(64.0 * f64::EPSILON * local.scale);
        Self::of_points(&local.points, eps)
    }

    /// Hull of `pts` (indices in the result refer to `pts`).
    fn of_points(pts: &[DVec3], eps: f64) -> Self {
        let single = |i: usize| LocalHull {
            vertices: vec![pts[i]],
            input_indices: vec![i as u32],
            triangles: Vec::new(),
            dimension: HullDimension::Point,
            polygon_normal: DVec3::ZERO,
            eps,
        };
        // Extreme points along the axes.
        let mut ext = [0usize; 6];
        for (i, p) in pts.iter().enumerate() {
            for k in 0..3 {
                if p[k] < pts[ext[2 * k]][k] {
                    ext[2 * k] = i;
                }
                if p[k] > pts[ext[2 * k + 1]][k] {
                    ext[2 * k + 1] = i;
                }
            }
        }
        let (mut i0, mut i1, mut best) = (ext[0], ext[0], -1.0);
        for a in 0..6 {
            for b in (a + 1)..6 {
                let d = pts[ext[a]].distance_squared(pts[ext[b]]);
                if d > best {
                    best = d;
                    i0 = ext[a];
                    i1 = ext[b];
                }
            }
        }
        if best.sqrt() <= eps {
            return single(i0);
        }
        let dir = (pts[i1] - pts[i0]).normalize();
        let (i2, d2) = farthest(pts, |p| (*p - pts[i0]).cross(dir).length_squared());
        if d2.sqrt() <= eps {
            // Collinear: the two ends along the line.
            let (lo, _) = farthest(pts, |p| -(*p - pts[i0]).dot(dir));
            let (hi, _) = farthest(pts, |p| (*p - pts[i0]).dot(dir));
            return LocalHull {
                vertices: vec![pts[lo], pts[hi]],
                input_indices: vec![lo as u32, hi as u32],
                triangles: Vec::new(),
                dimension: HullDimension::Segment,
                polygon_normal: DVec3::ZERO,
                eps,
            };
        }
        let normal = (pts[i1] - pts[i0]).cross(pts[i2] - pts[i0]).normalize();
        let (i3, d3) = farthest(pts, |p| (*p - pts[i0]).dot(normal).abs());
        if d3 <= eps {
            return planar_hull(pts, i0, i1, normal, eps);
        }
        match Quickhull::run(pts, eps, [i0 as u32, i1 as u32, i2 as u32, i3 as u32]) {
            Some(triangles) => {
                // Compact to the used vertices, in order of first use.
                let mut remap = vec![NONE; pts.len()];
                let mut vertices = Vec::new();
                let mut input_indices = Vec::new();
                let triangles = triangles
                    .iter()
                    .map(|t| {
                        t.map(|i| {
                            if remap[i as usize] == NONE {
                                remap[i as usize] = vertices.len() as u32;
                                vertices.push(pts[i as usize]);
                                input_indices.push(i);
                            }
                            remap[i as usize]
                        })
                    })
                    .collect();
                LocalHull {
                    vertices,
                    input_indices,
                    triangles,
                    dimension: HullDimension::Solid,
                    polygon_normal: DVec3::ZERO,
                    eps,
                }
            }
            // Unreachable with exact predicates; degrade to the planar hull rather than fail a bake.
            None => planar_hull(pts, i0, i1, normal, eps),
        }
    }

    /// Outward unit normal and area of each triangle (for [`HullDimension::Solid`]); for a polygon, the
    /// fan triangles of the polygon with the polygon normal.
    pub(crate) fn surface_triangles(&self) -> Vec<[DVec3; 3]> {
        match self.dimension {
            HullDimension::Solid => self.triangles.iter().map(|t| t.map(|i| self.vertices[i as usize])).collect(),
            HullDimension::Polygon => (1..self.vertices.len().saturating_sub(1))
                .map(|k| [self.vertices[0], self.vertices[k], self.vertices[k + 1]])
                .collect(),
            _ => Vec::new(),
        }
    }
}

fn farthest(pts: &[DVec3], f: impl Fn(&DVec3) -> f64) -> (usize, f64) {
    let mut best = (0, f64::NEG_INFINITY);
    for (i, p) in pts.iter().enumerate() {
        let v = f(p);
        if v > best.1 {
            best = (i, v);
        }
    }
    best
}

fn planar_hull(pts: &[DVec3], i0: usize, i1: usize, normal: DVec3, eps: f64) -> LocalHull {
    let u = (pts[i1] - pts[i0]).normalize();
    let v = normal.cross(u);
    let flat: Vec<DVec2> = pts.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect();
    let ring = convex_hull_2d(&flat, eps);
    let dimension = if ring.len() >= 3 { HullDimension::Polygon } else { HullDimension::Segment };
    LocalHull {
        vertices: ring.iter().map(|&i| pts[i as usize]).collect(),
        input_indices: ring,
        triangles: Vec::new(),
        dimension,
        polygon_normal: if dimension == HullDimension::Polygon { normal } else { DVec3::ZERO },
        eps,
    }
}

#[derive(Clone, Debug)]
struct Face {
    v: [u32; 3],
    /// Neighbour across edge `(v[i], v[i+1])`.
    adj: [u32; 3],
    normal: DVec3,
    offset: f64,
    outside: Vec<u32>,
    far: u32,
    far_dist: f64,
    alive: bool,
}

struct Quickhull<'a> {
    pts: &'a [DVec3],
    eps: f64,
    faces: Vec<Face>,
    free: Vec<u32>,
}

impl<'a> Quickhull<'a> {
    /// Returns the hull triangles (indices into `pts`), or `None` if the mesh invariants broke.
    fn run(pts: &'a [DVec3], eps: f64, tet: [u32; 4]) -> Option<Vec<[u32; 3]>> {
        let mut qh = Quickhull { pts, eps, faces: Vec::new(), free: Vec::new() };
        let [mut a, mut b, c, d] = tet;
        if qh.orient([a, b, c], d) > 0 {
            std::mem::swap(&mut a, &mut b);
        }
        // Faces of a tetrahedron with d below (a, b, c): (a,b,c), (a,d,b), (b,d,c), (c,d,a).
        let tris = [[a, b, c], [a, d, b], [b, d, c], [c, d, a]];
        for t in tris {
            qh.faces.push(qh.make_face(t));
        }
        for f in 0..4 {
            for e in 0..3 {
                let (u, w) = (tris[f][e], tris[f][(e + 1) % 3]);
                let g = (0..4).find(|&g| g != f && (0..3).any(|k| tris[g][k] == w && tris[g][(k + 1) % 3] == u))?;
                qh.faces[f].adj[e] = g as u32;
            }
        }
        // Initial conflict lists.
        for i in 0..pts.len() as u32 {
            if tet.contains(&i) {
                continue;
            }
            qh.assign(i, &[0, 1, 2, 3]);
        }
        let mut stack: Vec<u32> = (0..4u32).filter(|&f| !qh.faces[f as usize].outside.is_empty()).collect();
        let mut visited: Vec<u32> = Vec::new();
        let mut visible_mark: Vec<u32> = Vec::new();
        let mut start_of: Vec<u32> = vec![NONE; pts.len()];
        let mut start_stamp: Vec<u32> = vec![0; pts.len()];
        let mut stamp = 0u32;
        let mut visible: Vec<u32> = Vec::new();
        let mut horizon: Vec<(u32, u32, u32)> = Vec::new();
        let mut orphans: Vec<u32> = Vec::new();
        let mut new_faces: Vec<u32> = Vec::new();
        while let Some(fi) = stack.pop() {
            let face = &qh.faces[fi as usize];
            if !face.alive || face.outside.is_empty() {
                continue;
            }
            let eye = face.far;
            if qh.orient(face.v, eye) <= 0 {
                // Rounding put the point outside this face; the exact sign says otherwise. Re-home it.
                qh.remove_outside(fi, eye);
                if !qh.faces[fi as usize].outside.is_empty() {
                    stack.push(fi);
                }
                if let Some(g) = qh.rehome(eye) {
                    stack.push(g);
                }
                continue;
            }
            stamp = stamp.wrapping_add(1).max(1);
            visited.resize(qh.faces.len(), 0);
            visible_mark.resize(qh.faces.len(), 0);
            // Visible region by BFS with the exact predicate.
            visible.clear();
            visible.push(fi);
            visited[fi as usize] = stamp;
            visible_mark[fi as usize] = stamp;
            let mut k = 0;
            while k < visible.len() {
                let f = visible[k] as usize;
                k += 1;
                for e in 0..3 {
                    let g = qh.faces[f].adj[e];
                    if visited[g as usize] == stamp {
                        continue;
                    }
                    visited[g as usize] = stamp;
                    if qh.orient(qh.faces[g as usize].v, eye) > 0 {
                        visible_mark[g as usize] = stamp;
                        visible.push(g);
                    }
                }
            }
            // Horizon edges (a → b as seen from the visible side) with the invisible neighbour.
            horizon.clear();
            for &f in &visible {
                let face = &qh.faces[f as usize];
                for e in 0..3 {
                    let g = face.adj[e];
                    if visible_mark[g as usize] != stamp {
                        horizon.push((face.v[e], face.v[(e + 1) % 3], g));
                    }
                }
            }
            orphans.clear();
            for &f in &visible {
                let face = &mut qh.faces[f as usize];
                orphans.extend(face.outside.iter().copied().filter(|&p| p != eye));
                face.outside = Vec::new();
                face.alive = false;
                qh.free.push(f);
            }
            // Cone of new faces.
            new_faces.clear();
            for &(a, b, g) in &horizon {
                if start_stamp[a as usize] == stamp {
                    return None; // horizon is not a simple loop
                }
                let n = qh.alloc(qh.make_face([a, b, eye]));
                qh.faces[n as usize].adj[0] = g;
                let neighbour = &mut qh.faces[g as usize];
                let slot = (0..3).find(|&k| neighbour.v[k] == b && neighbour.v[(k + 1) % 3] == a)?;
                neighbour.adj[slot] = n;
                start_stamp[a as usize] = stamp;
                start_of[a as usize] = n;
                new_faces.push(n);
            }
            for &n in &new_faces {
                let b = qh.faces[n as usize].v[1];
                if start_stamp[b as usize] != stamp {
                    return None;
                }
                let m = start_of[b as usize];
                qh.faces[n as usize].adj[1] = m;
                qh.faces[m as usize].adj[2] = n;
            }
            for &p in &orphans {
                qh.assign(p, &new_faces);
            }
            for &n in &new_faces {
                if !qh.faces[n as usize].outside.is_empty() {
                    stack.push(n);
                }
            }
        }
        Some(qh.faces.iter().filter(|f| f.alive).map(|f| f.v).collect())
    }

    fn orient(&self, v: [u32; 3], p: u32) -> i8 {
        let q = |i: u32| self.pts[i as usize].to_array();
        orient3d(q(v[0]), q(v[1]), q(v[2]), q(p))
    }

    fn make_face(&self, v: [u32; 3]) -> Face {
        let p = v.map(|i| self.pts[i as usize]);
        // Cross the two edges at the vertex opposite the longest edge: the best-conditioned choice.
        let l = [p[1].distance_squared(p[2]), p[2].distance_squared(p[0]), p[0].distance_squared(p[1])];
        let k = if l[0] >= l[1] && l[0] >= l[2] {
            0
        } else if l[1] >= l[2] {
            1
        } else {
            2
        };
        let (o, x, y) = (p[k], p[(k + 1) % 3], p[(k + 2) % 3]);
        let normal = (x - o).cross(y - o).normalize_or_zero();
        Face {
            v,
            adj: [NONE; 3],
            normal,
            offset: normal.dot(o),
            outside: Vec::new(),
            far: NONE,
            far_dist: f64::NEG_INFINITY,
            alive: true,
        }
    }

    fn alloc(&mut self, face: Face) -> u32 {
        if let Some(f) = self.free.pop() {
            self.faces[f as usize] = face;
            f
        } else {
            self.faces.push(face);
            (self.faces.len() - 1) as u32
        }
    }

    /// Puts point `p` on the conflict list of the first of `faces` it is more than `eps` above.
    fn assign(&mut self, p: u32, faces: &[u32]) -> Option<u32> {
        let q = self.pts[p as usize];
        for &f in faces {
            let face = &mut self.faces[f as usize];
            let d = face.normal.dot(q) - face.offset;
            if d > self.eps {
                face.outside.push(p);
                if d > face.far_dist {
                    face.far_dist = d;
                    face.far = p;
                }
                return Some(f);
            }
        }
        None
    }

    fn remove_outside(&mut self, f: u32, p: u32) {
        let pts = self.pts;
        let face = &mut self.faces[f as usize];
        face.outside.retain(|&q| q != p);
        face.far = NONE;
        face.far_dist = f64::NEG_INFINITY;
        for &q in &face.outside {
            let d = face.normal.dot(pts[q as usize]) - face.offset;
            if d > face.far_dist {
                face.far_dist = d;
                face.far = q;
            }
        }
    }

    /// Finds a live face that `p` is above both in floating point (by more than `eps`) and exactly.
    fn rehome(&mut self, p: u32) -> Option<u32> {
        let q = self.pts[p as usize];
        let f = (0..self.faces.len() as u32).find(|&f| {
            let face = &self.faces[f as usize];
            face.alive && face.normal.dot(q) - face.offset > self.eps && self.orient(face.v, p) > 0
        })?;
        let face = &mut self.faces[f as usize];
        let d = face.normal.dot(q) - face.offset;
        face.outside.push(p);
        if d > face.far_dist {
            face.far_dist = d;
            face.far = p;
        }
        Some(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_corners_and_interior() {
        let mut pts = Vec::new();
        for i in 0..8 {
            pts.push(DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64));
        }
        pts.push(DVec3::splat(0.5));
        pts.push(DVec3::new(0.5, 0.5, 1.0)); // on a face
        let hull = convex_hull(&pts, &HullOptions::default()).unwrap();
        assert_eq!(hull.dimension, HullDimension::Solid);
        assert_eq!(hull.vertices.len(), 8);
        assert_eq!(hull.triangles.len(), 12);
    }
}
