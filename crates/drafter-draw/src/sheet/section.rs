//! Section cuts: the faces a plane cuts from a model's closed bodies, and their hatching
//! (ISO 128-50: thin lines at 45°, the angle and spacing varied from part to part so that
//! neighbouring parts read apart).
//!
//! # How it works
//! Each mesh is welded exactly ([`Topology`]) and split into its vertex-connected components. A
//! component is a closed body when every edge has exactly two faces that run along it opposite
//! ways, and its enclosed volume is not negligible; other components are not cut and are counted
//! ([`Section::open_components`]). For a closed body the plane's signed distance is taken at every
//! welded vertex, a vertex exactly on the plane counting as above it (a symbolic perturbation, so
//! every face the plane meets is crossed on exactly two of its edges and no loop touches itself);
//! each crossed edge gets one point, interpolated from its two ends in a fixed order so that both
//! of its faces share it bit for bit; each crossed face links its two crossed edges. Every crossed
//! edge then has exactly two links, so the cut is a set of cycles, walked edge to edge without any
//! geometric matching. Each face's link runs from the edge where the face's boundary comes down
//! through the plane to the one where it goes up again (for outward normals), so loops around
//! material and loops around holes turn opposite ways; with the body's orientation that makes the signed area of a cut the
//! area of material.
//!
//! On a sheet ([`super::SheetOptions::section`]) the cut faces are outlined and hatched in a
//! section view whose lines are drawn by [`crate::draw_clipped`] with a [`Clip`].
//!
//! Limits: no `[draw] uncut` list (shafts, bolts); bodies whose meshes do not weld into closed
//! surfaces (cracks, slivers collapsed to a point) are left uncut and counted.

use glam::{DVec2, DVec3, Vec3};

use drafter_core::{EDGE_NONE, Topology, Weld};
use drafter_scene::model::Model;

/// A cutting plane: the points `p` with `normal · p = offset` (world units, normal of length 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub normal: DVec3,
    pub offset: f64,
}

impl Plane {
    /// `x=10`, `y=-2.5`, `z=0` (a plane across an axis), or `px,py,pz,nx,ny,nz` (a point and a normal).
    pub fn parse(text: &str) -> Result<Plane, String> {
        let bad = || format!("--section {text}: not a plane (x=10, y=-2.5, z=0, or px,py,pz,nx,ny,nz)");
        if let Some((axis, value)) = text.split_once('=') {
            let normal = match axis.trim().to_ascii_lowercase().as_str() {
                "x" => DVec3::X,
                "y" => DVec3::Y,
                "z" => DVec3::Z,
                _ => return Err(bad()),
            };
            let offset: f64 = value.trim().parse().map_err(|_| bad())?;
            return if offset.is_finite() { Ok(Plane { normal, offset }) } else { Err(bad()) };
        }
        let numbers: Vec<f64> =
            text.split(',').map(|v| v.trim().parse::<f64>()).collect::<Result<_, _>>().map_err(|_| bad())?;
        let [px, py, pz, nx, ny, nz] = numbers[..] else { return Err(bad()) };
        let (point, normal) = (DVec3::new(px, py, pz), DVec3::new(nx, ny, nz));
        let length = normal.length();
        if !(point.is_finite() && length.is_finite() && length > 0.0) {
            return Err(bad());
        }
        let normal = normal / length;
        Ok(Plane { normal, offset: normal.dot(point) })
    }

    /// Signed distance of `p` above the plane.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// The cut of one closed body.
#[derive(Clone, Debug, PartialEq)]
pub struct CutFace {
    /// The instance the body belongs to and the part of its first cut face.
    pub instance: u32,
    pub part: Option<u32>,
    /// Closed loops on the plane (world space; the last point is not repeated). Loops around
    /// material turn counter-clockwise seen from above the plane (from where the normal points),
    /// loops around holes clockwise.
    pub loops: Vec<Vec<DVec3>>,
}

impl CutFace {
    /// The area of material: the signed areas of the loops seen from above the plane.
    pub fn area(&self, plane: &Plane) -> f64 {
        self.loops.iter().map(|l| signed_area(l, plane.normal)).sum()
    }
}

/// Signed area of a closed loop in a plane of normal `normal` (positive when it turns
/// counter-clockwise seen from where the normal points).
pub fn signed_area(points: &[DVec3], normal: DVec3) -> f64 {
    let mut twice = DVec3::ZERO;
    for (k, p) in points.iter().enumerate() {
        twice += p.cross(points[(k + 1) % points.len()]);
    }
    0.5 * twice.dot(normal)
}

/// What a plane cuts from a model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    pub faces: Vec<CutFace>,
    /// Components the plane crosses that are not closed bodies, left uncut.
    pub open_components: usize,
}

/// Which of `topology`'s components are closed bodies, and the sign that turns their faces'
/// normals outward (+1, −1; 0 where not closed or of negligible volume).
pub fn closed_components(topology: &Topology, positions: &[DVec3]) -> Vec<i8> {
    let n = topology.component_count;
    let (mut closed, mut volume, mut magnitude) = (vec![true; n], vec![0.0f64; n], vec![0.0f64; n]);
    for (f, face) in topology.faces.iter().enumerate() {
        let c = topology.face_component[f] as usize;
        for k in 0..3 {
            let (u, v) = (face[k], face[(k + 1) % 3]);
            let edge = topology.face_edges[f][k];
            let paired = edge != EDGE_NONE
                && match *topology.faces_of_edge(edge as usize) {
                    [g, h] if g != h => {
                        let other = topology.faces[(if g as usize == f { h } else { g }) as usize];
                        (0..3).any(|j| other[j] == v && other[(j + 1) % 3] == u)
                    }
                    _ => false,
                };
            closed[c] &= paired;
        }
        let p = face.map(|w| positions[w as usize]);
        let term = p[0].dot(p[1].cross(p[2]));
        volume[c] += term;
        magnitude[c] += term.abs();
    }
    (0..n)
        .map(|c| match (closed[c], volume[c]) {
            (false, _) => 0,
            (true, v) if v.abs() <= 1e-9 * magnitude[c] => 0,
            (true, v) if v > 0.0 => 1,
            _ => -1,
        })
        .collect()
}

/// Cuts every closed body of `model` by `plane`.
pub fn cut(model: &Model, plane: &Plane) -> Section {
    let mut section = Section::default();
    for batch in &model.batches {
        let positions: Vec<Vec3> = batch.vertices.iter().map(|v| Vec3::from_array(v.position_in_object)).collect();
        let triangles: Vec<[u32; 3]> = batch.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        if triangles.iter().flatten().any(|&v| v as usize >= positions.len()) {
            continue;
        }
        let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
        let object: Vec<DVec3> = topology.welded_positions.iter().map(|p| p.as_dvec3()).collect();
        let sides = closed_components(&topology, &object);
        for instance in batch.instances.clone() {
            let Some(world) = model.instance_world_from_object.get(instance as usize) else { continue };
            let points: Vec<DVec3> = object.iter().map(|p| world.transform_point3(*p)).collect();
            let mirror = if world.determinant() < 0.0 { -1.0 } else { 1.0 };
            cut_instance(model, batch, instance, &topology, &points, &sides, mirror, plane, &mut section);
        }
    }
    section
}

#[allow(clippy::too_many_arguments)]
fn cut_instance(
    model: &Model,
    batch: &drafter_scene::model::Batch,
    instance: u32,
    topology: &Topology,
    points: &[DVec3],
    sides: &[i8],
    mirror: f64,
    plane: &Plane,
    section: &mut Section,
) {
    // Above (or on) the plane: the symbolic perturbation of the module docs.
    let above: Vec<bool> = points.iter().map(|p| plane.distance(*p) >= 0.0).collect();
    let crossed = |e: u32| {
        let [a, b] = topology.edges[e as usize];
        above[a as usize] != above[b as usize]
    };
    // Per component: does the plane cross it at all?
    let mut met = vec![false; topology.component_count];
    for (e, &[a, b]) in topology.edges.iter().enumerate() {
        if above[a as usize] != above[b as usize] {
            let f = topology.faces_of_edge(e)[0];
            met[topology.face_component[f as usize] as usize] = true;
        }
    }
    for (c, &side) in sides.iter().enumerate() {
        if met[c] && side == 0 {
            section.open_components += 1;
        }
    }
    // Links: per crossed face of a closed body, from the edge where its boundary goes up through
    // the plane to the one where it comes down (for outward normals; the other way for inward).
    let mut next: std::collections::HashMap<u32, (u32, usize)> = std::collections::HashMap::new();
    let mut starts = Vec::new();
    for (f, face) in topology.faces.iter().enumerate() {
        let c = topology.face_component[f] as usize;
        if sides[c] == 0 {
            continue;
        }
        let (mut up, mut down) = (None, None);
        for k in 0..3 {
            let e = topology.face_edges[f][k];
            if e == EDGE_NONE || !crossed(e) {
                continue;
            }
            if above[face[(k + 1) % 3] as usize] { up = Some(e) } else { down = Some(e) }
        }
        let (Some(up), Some(down)) = (up, down) else { continue };
        // With outward normals a face's boundary comes down through the plane before it goes up
        // again, seen from above turning counter-clockwise around the material.
        let outward = f64::from(sides[c]) * mirror > 0.0;
        let (from, to) = if outward { (down, up) } else { (up, down) };
        next.insert(from, (to, f));
        starts.push(from);
    }
    let point_of = |e: u32| {
        let [a, b] = topology.edges[e as usize];
        let (pa, pb) = (points[a as usize], points[b as usize]);
        let (da, db) = (plane.distance(pa), plane.distance(pb));
        let t = da / (da - db);
        pa + (pb - pa) * t
    };
    // Walk the cycles, one cut face per component.
    let mut by_component: std::collections::BTreeMap<u32, CutFace> = std::collections::BTreeMap::new();
    let mut done = std::collections::HashSet::new();
    for &start in &starts {
        if done.contains(&start) {
            continue;
        }
        let mut ring = Vec::new();
        let mut at = start;
        let mut first_face = None;
        while done.insert(at) {
            ring.push(point_of(at));
            let Some(&(to, f)) = next.get(&at) else { break };
            first_face.get_or_insert(f);
            at = to;
        }
        let Some(f) = first_face else { continue };
        let component = topology.face_component[f];
        let part = crate::part_of(model, Some(batch), instance, f);
        by_component.entry(component).or_insert_with(|| CutFace { instance, part, loops: Vec::new() }).loops.push(ring);
    }
    section.faces.extend(by_component.into_values());
}

/// What a section leaves of a view ([`crate::visibility_clipped`]): what lies above the plane is
/// taken away (edges and occluding triangles cut at it), and the cut faces, which lie in the plane
/// in front of everything left (the view looks down the plane's normal), hide what lies behind them
/// on the screen. Exact as the rest of the drawing: a triangle cut by the plane is the polygon
/// below it (as triangles from its first corner), and an edge behind a cut face is hidden where its
/// projection is inside the face's loops (even-odd, decided at the middle of every piece between
/// crossings of the loops).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Clip {
    pub plane: Plane,
    /// The cut faces' loops on the screen (the view's pixels).
    pub cut: Vec<Vec<DVec2>>,
    /// Parts drawn whole, not cut (ISO 128-50: shafts, bolts, pins, keys), sorted.
    pub uncut: Vec<u32>,
    /// The plane's closeness in the view (it lies across the view direction): the cut faces hide
    /// only what lies behind it.
    pub plane_closeness: f64,
}

impl Default for Plane {
    fn default() -> Self {
        Plane { normal: DVec3::Z, offset: 0.0 }
    }
}

impl Clip {
    fn is_uncut(&self, part: Option<u32>) -> bool {
        part.is_some_and(|p| self.uncut.binary_search(&p).is_ok())
    }

    /// Cuts `triangles` and `edges` to what lies below the plane (on it counts as below), but for
    /// the uncut parts'.
    pub(crate) fn keep_below(&self, triangles: &mut crate::Triangles, edges: &mut Vec<crate::Edge>) {
        let s = |p: DVec3| self.plane.distance(p);
        let (mut kept, mut parts) = (Vec::with_capacity(triangles.corners.len()), Vec::new());
        for (t, &part) in triangles.corners.iter().zip(&triangles.parts) {
            if self.is_uncut(part) || t.iter().all(|p| s(*p) <= 0.0) {
                kept.push(*t);
                parts.push(part);
                continue;
            }
            let polygon = self.below(t);
            for i in 1..polygon.len().saturating_sub(1) {
                kept.push([polygon[0], polygon[i], polygon[i + 1]]);
                parts.push(part);
            }
        }
        (triangles.corners, triangles.parts) = (kept, parts);
        // The cut opens the bodies: every remaining face hides from either side.
        triangles.outward = vec![0; triangles.corners.len()];
        edges.retain_mut(|e| {
            if self.is_uncut(e.part) {
                return true;
            }
            let (sa, sb) = (s(e.a), s(e.b));
            match (sa <= 0.0, sb <= 0.0) {
                (true, true) => true,
                (false, false) => false,
                (true, false) => {
                    e.b = e.a + (e.b - e.a) * (sa / (sa - sb));
                    true
                }
                (false, true) => {
                    e.a = e.b + (e.a - e.b) * (sb / (sb - sa));
                    true
                }
            }
        });
    }

    /// `hidden` (intervals of the screen segment `a → b`) with the stretches behind the cut faces added.
    pub(crate) fn hide(&self, a: crate::Projected, b: crate::Projected, hidden: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
        let (pa, pb) = (DVec2::new(a.x, a.y), DVec2::new(b.x, b.y));
        let (lo, hi) = (pa.min(pb), pa.max(pb));
        let d = pb - pa;
        let mut cuts = vec![0.0, 1.0];
        let mut near = false;
        for ring in &self.cut {
            let (rlo, rhi) =
                ring.iter().fold((DVec2::INFINITY, DVec2::NEG_INFINITY), |(l, h), p| (l.min(*p), h.max(*p)));
            if rhi.x < lo.x || rhi.y < lo.y || rlo.x > hi.x || rlo.y > hi.y {
                continue;
            }
            near = true;
            for (i, p) in ring.iter().enumerate() {
                let q = ring[(i + 1) % ring.len()];
                let e = q - *p;
                let denominator = d.perp_dot(e);
                if denominator == 0.0 {
                    continue;
                }
                let w = *p - pa;
                let (u, v) = (w.perp_dot(e) / denominator, w.perp_dot(d) / denominator);
                if u > 0.0 && u < 1.0 && (0.0..=1.0).contains(&v) {
                    cuts.push(u);
                }
            }
        }
        if !near {
            return hidden;
        }
        cuts.sort_by(f64::total_cmp);
        // Only behind the plane (an uncut part's edge may lie in front of it): where the
        // closeness, affine along the segment, is below the plane's.
        let limit = self.plane_closeness - 1e-9 * self.plane_closeness.abs();
        let (behind_from, behind_to) = match (a.c < limit, b.c < limit) {
            (true, true) => (0.0, 1.0),
            (false, false) => return hidden,
            (true, false) => (0.0, (limit - a.c) / (b.c - a.c)),
            (false, true) => ((limit - a.c) / (b.c - a.c), 1.0),
        };
        let mut intervals = hidden;
        for w in cuts.windows(2) {
            let (lo, hi) = (w[0].max(behind_from), w[1].min(behind_to));
            if hi > lo && inside(&self.cut, pa + d * (0.5 * (w[0] + w[1]))) {
                intervals.push((lo, hi));
            }
        }
        crate::union(&mut intervals)
    }
}

impl Clip {
    fn below(&self, t: &[DVec3; 3]) -> Vec<DVec3> {
        below(&self.plane, t)
    }
}

/// The part of triangle `t` below `plane` (Sutherland–Hodgman against one plane; on it counts as below).
pub fn below(plane: &Plane, t: &[DVec3; 3]) -> Vec<DVec3> {
    {
        let s = |p: DVec3| plane.distance(p);
        let mut out = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (sa, sb) = (s(a), s(b));
            if sa <= 0.0 {
                out.push(a);
            }
            if (sa <= 0.0) != (sb <= 0.0) {
                out.push(a + (b - a) * (sa / (sa - sb)));
            }
        }
        out
    }
}

/// Hatching of a cut face seen in a view: lines at `angle_deg` (from the view's x axis, counter-
/// clockwise with y up) every `spacing`, clipped to the loops by the even-odd rule; `loops` in the
/// view's 2D coordinates (y up or down alike: the lines are clipped, not oriented).
pub fn hatch(loops: &[Vec<DVec2>], angle_deg: f64, spacing: f64) -> Vec<[DVec2; 2]> {
    let (sin, cos) = angle_deg.to_radians().sin_cos();
    let (along, across) = (DVec2::new(cos, sin), DVec2::new(-sin, cos));
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in loops.iter().flatten() {
        lo = lo.min(p.dot(across));
        hi = hi.max(p.dot(across));
    }
    if lo >= hi || !lo.is_finite() || !hi.is_finite() || spacing.is_nan() || spacing <= 0.0 {
        return Vec::new();
    }
    let mut out = Vec::new();
    // Lines at whole multiples of the spacing (so neighbouring faces' lines of one part continue).
    let first = (lo / spacing).ceil() as i64;
    let last = (hi / spacing).floor() as i64;
    for k in first..=last {
        let c = k as f64 * spacing;
        let mut hits: Vec<f64> = Vec::new();
        for ring in loops {
            for (i, a) in ring.iter().enumerate() {
                let b = ring[(i + 1) % ring.len()];
                let (sa, sb) = (a.dot(across) - c, b.dot(across) - c);
                // Half-open: a vertex on the line counts for one of its two edges only.
                if (sa >= 0.0) != (sb >= 0.0) {
                    let t = sa / (sa - sb);
                    hits.push((*a + (b - *a) * t).dot(along));
                }
            }
        }
        hits.sort_by(f64::total_cmp);
        for pair in hits.chunks_exact(2) {
            let base = across * c;
            out.push([base + along * pair[0], base + along * pair[1]]);
        }
    }
    out
}

/// Whether `p` lies inside `loops` by the even-odd rule.
pub fn inside(loops: &[Vec<DVec2>], p: DVec2) -> bool {
    let mut odd = false;
    for ring in loops {
        for (i, a) in ring.iter().enumerate() {
            let b = ring[(i + 1) % ring.len()];
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                odd = !odd;
            }
        }
    }
    odd
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_parse_and_name_a_mistake() {
        assert_eq!(Plane::parse("x=10").unwrap(), Plane { normal: DVec3::X, offset: 10.0 });
        let p = Plane::parse("0,0,2, 0,0,-4").unwrap();
        assert_eq!((p.normal, p.offset), (DVec3::NEG_Z, -2.0));
        for bad in ["w=1", "x=", "1,2,3", "0,0,0,0,0,0", "x=inf"] {
            assert!(Plane::parse(bad).unwrap_err().contains(bad), "{bad}");
        }
    }

    #[test]
    fn a_square_with_a_hole_hatches_inside_only() {
        let square = vec![DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0), DVec2::new(10.0, 10.0), DVec2::new(0.0, 10.0)];
        let hole = vec![DVec2::new(3.0, 3.0), DVec2::new(3.0, 7.0), DVec2::new(7.0, 7.0), DVec2::new(7.0, 3.0)];
        let loops = vec![square, hole];
        let lines = hatch(&loops, 45.0, 1.0);
        assert!(!lines.is_empty());
        for [a, b] in &lines {
            let middle = (*a + *b) * 0.5;
            assert!(inside(&loops, middle), "{middle}");
        }
        assert!(!inside(&loops, DVec2::new(5.0, 5.0)) && inside(&loops, DVec2::new(1.0, 5.0)));
    }
}
