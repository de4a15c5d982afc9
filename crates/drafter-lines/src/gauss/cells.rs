//! The cells: the base solids' spherical triangles, their 4:1 splits, the bin rule, and the paths
//! it gives arcs, for many arcs at once (what the cone BVH's normal split reads).

use glam::DVec3;
use rayon::prelude::*;

use super::BaseSolid;
use crate::sphere::min;

/// A spherical triangle, counter-clockwise seen from outside.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cell {
    pub(super) v: [DVec3; 3],
    /// Unit normals of the planes through the origin and each edge, pointing inside.
    pub(super) planes: [DVec3; 3],
    pub(super) center: DVec3,
    /// Cosine of the circumradius.
    pub(super) cos_radius: f64,
}

impl Cell {
    fn new(a: DVec3, b: DVec3, c: DVec3) -> Cell {
        let center = (a + b + c).normalize();
        let cos_radius = center.dot(a).min(center.dot(b)).min(center.dot(c));
        let planes = [a.cross(b).normalize(), b.cross(c).normalize(), c.cross(a).normalize()];
        Cell { v: [a, b, c], planes, center, cos_radius }
    }

    /// Signed inside-ness: ≥ 0 inside, the larger the deeper.
    #[inline]
    pub(crate) fn score(&self, p: DVec3) -> f64 {
        min(min(self.planes[0].dot(p), self.planes[1].dot(p)), self.planes[2].dot(p))
    }

    pub(crate) fn children(&self) -> [Cell; 4] {
        let [a, b, c] = self.v;
        let ab = (a + b).normalize();
        let bc = (b + c).normalize();
        let ca = (c + a).normalize();
        [Cell::new(a, ab, ca), Cell::new(ab, b, bc), Cell::new(ca, bc, c), Cell::new(ab, bc, ca)]
    }
}

pub(crate) fn base_cells(base: BaseSolid) -> Vec<Cell> {
    let (vertices, edge_len2): (Vec<DVec3>, f64) = match base {
        BaseSolid::Octahedron => (vec![DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z], 2.0),
        BaseSolid::Icosahedron => {
            let phi = (1.0 + 5f64.sqrt()) / 2.0;
            let mut v = Vec::new();
            for s1 in [-1.0, 1.0] {
                for s2 in [-1.0, 1.0] {
                    v.push(DVec3::new(0.0, s1, s2 * phi));
                    v.push(DVec3::new(s1, s2 * phi, 0.0));
                    v.push(DVec3::new(s2 * phi, 0.0, s1));
                }
            }
            (v, 4.0)
        }
    };
    let n = vertices.len();
    let adjacent = |i: usize, j: usize| (vertices[i].distance_squared(vertices[j]) - edge_len2).abs() < 1e-9;
    let mut cells = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if adjacent(i, j) && adjacent(j, k) && adjacent(k, i) {
                    let (a, mut b, mut c) = (vertices[i], vertices[j], vertices[k]);
                    if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                        std::mem::swap(&mut b, &mut c);
                    }
                    cells.push(Cell::new(a.normalize(), b.normalize(), c.normalize()));
                }
            }
        }
    }
    cells
}

/// Where the overlapping-bin rule stores the arc `n1`–`n2` (unit; zero for a degenerate face):
/// the cells containing its midpoint, level after level, for as long as both endpoints lie in the
/// cell's bin (the cap of `factor` circumradii around its centre), at most `level` splits below
/// the base. Returns `(digits, cells)`: `cells` is how many cells the arc went down (0: it fits
/// no base cell), `digits` the path as `base · 4^level + child digits` with unused digits 0.
/// The reference for [`arc_paths`], which computes it for many arcs at once.
#[cfg(test)]
pub(crate) fn arc_path(n1: DVec3, n2: DVec3, base: &[Cell], level: u8, factor: f64) -> (u32, u8) {
    let sum = n1 + n2;
    if n1 == DVec3::ZERO || n2 == DVec3::ZERO || sum.length() <= 1e-9 {
        return (0, 0);
    }
    let mid = sum.normalize();
    let fits = |c: &Cell| fits_bin(c, bin_cos(c, factor), [n1, n2]);
    let b = most_inside(base, mid);
    if !fits(&base[b]) {
        return (0, 0);
    }
    let (mut key, mut cells, mut cell) = (b as u32, 1u8, base[b]);
    for _ in 0..level {
        let children = cell.children();
        let k = most_inside(&children, mid);
        if !fits(&children[k]) {
            break;
        }
        key = key * 4 + k as u32;
        cells += 1;
        cell = children[k];
    }
    (key * 4u32.pow(u32::from(level + 1 - cells)), cells)
}

/// Where the overlapping-bin rule stores each arc `unit[i]` (unit normals; zero for a degenerate
/// face): the cells containing its midpoint, level after level, for as long as both endpoints lie
/// in the cell's bin (the cap of `factor` circumradii around its centre), at most `level` splits
/// below the base. Each path is `(digits, cells)`: `cells` is how many cells the arc went down
/// (0: it fits no base cell), `digits` the path as `base · 4^level + child digits` with unused
/// digits 0. Computed top-down over the cells instead of arc by arc:
/// each visited cell's children (and their bins) are built once for all the arcs that reach it,
/// rather than once per arc and level. Equal to `arc_path` on every arc (tested).
pub(crate) fn arc_paths(unit: &[[DVec3; 2]], base: &[Cell], level: u8, factor: f64) -> Vec<(u32, u8)> {
    let mids: Vec<Option<DVec3>> = unit.par_iter().map(|&u| arc_mid(u)).collect();
    let bins: Vec<f64> = base.iter().map(|c| bin_cos(c, factor)).collect();
    let mut groups: Vec<Vec<u32>> = vec![Vec::new(); base.len()];
    for (i, mid) in mids.iter().enumerate() {
        if let Some(m) = mid {
            let b = most_inside(base, *m);
            if fits_bin(&base[b], bins[b], unit[i]) {
                groups[b].push(i as u32);
            }
        }
    }
    let descend = PathDescent { unit, level, factor };
    let found: Vec<Vec<(u32, (u32, u8))>> = groups
        .into_par_iter()
        .enumerate()
        .map(|(b, ids)| {
            let mut out = Vec::with_capacity(ids.len());
            descend.cell(base[b], b as u32, 1, ids, &mut out);
            out
        })
        .collect();
    let mut paths = vec![(0u32, 0u8); unit.len()];
    for (i, path) in found.into_iter().flatten() {
        paths[i as usize] = path;
    }
    paths
}

/// Cosine of the overlapping bin radius of `c` (`factor` circumradii, at most π).
pub(super) fn bin_cos(c: &Cell, factor: f64) -> f64 {
    (c.cos_radius.clamp(-1.0, 1.0).acos() * factor.max(1.0)).min(std::f64::consts::PI).cos()
}

#[inline]
pub(super) fn fits_bin(c: &Cell, cos_bin: f64, [n1, n2]: [DVec3; 2]) -> bool {
    c.center.dot(n1) >= cos_bin && c.center.dot(n2) >= cos_bin
}

/// The cell whose inside-ness score of `p` is the largest (the first of equals).
pub(super) fn most_inside(cells: &[Cell], p: DVec3) -> usize {
    cells
        .iter()
        .enumerate()
        .map(|(k, c)| (k, c.score(p)))
        .fold((0, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc })
        .0
}

/// The midpoint of the arc between unit normals `n1`, `n2`; `None` for a zero or antipodal arc.
pub(super) fn arc_mid([n1, n2]: [DVec3; 2]) -> Option<DVec3> {
    let sum = n1 + n2;
    let length = sum.length();
    // `sum * (1 / length)` is glam's `normalize`, without taking the length a second time.
    (n1 != DVec3::ZERO && n2 != DVec3::ZERO && length > 1e-9).then(|| sum * (1.0 / length))
}

/// The cell with digits `key` ([`BuildNode::key`]) `cells` cells down from `base`.
pub(super) fn cell_of(base: &[Cell], key: u32, cells: u8) -> Cell {
    let digit = |i: u8| (key >> (2 * u32::from(i))) as usize;
    let mut cell = base[digit(cells - 1)];
    for i in (0..cells - 1).rev() {
        cell = cell.children()[digit(i) & 3];
    }
    cell
}

pub(super) struct PathDescent<'a> {
    pub(super) unit: &'a [[DVec3; 2]],
    pub(super) level: u8,
    pub(super) factor: f64,
}

impl PathDescent<'_> {
    /// Paths of `ids`, all of which went down to `cell` (`cells` cells so far, digits `key`).
    pub(super) fn cell(&self, cell: Cell, key: u32, cells: u8, ids: Vec<u32>, out: &mut Vec<(u32, (u32, u8))>) {
        let here = (key * 4u32.pow(u32::from(self.level + 1 - cells)), cells);
        if cells > self.level {
            out.extend(ids.into_iter().map(|i| (i, here)));
            return;
        }
        let children = cell.children();
        let bins = children.each_ref().map(|c| bin_cos(c, self.factor));
        let mut groups: [Vec<u32>; 4] = Default::default();
        for i in ids {
            let Some(m) = arc_mid(self.unit[i as usize]) else { continue };
            let k = most_inside(&children, m);
            if fits_bin(&children[k], bins[k], self.unit[i as usize]) {
                groups[k].push(i);
            } else {
                out.push((i, here));
            }
        }
        for (k, ids) in groups.into_iter().enumerate() {
            if !ids.is_empty() {
                self.cell(children[k], key * 4 + k as u32, cells + 1, ids, out);
            }
        }
    }
}

/// For each octant of the sphere, the base cells whose circumcap, widened by [`OCTANT_MARGIN`],
/// reaches into it: the only cells [`most_inside`] can pick for a point there. The root assigns
/// every arc to a base cell, and scoring all 20 icosahedron faces (60 dot products an arc) was a
/// visible share of the assignment's profile; each octant meets 10 of them.
///
/// Why skipping the others picks the same cell, bit for bit: the point lies in some cell, whose
/// computed score is within rounding (about 1e-15) of a non-negative one, and that cell's cap
/// holds the point, so it is listed. A cell that is not listed is at least the margin (0.01 rad)
/// away from the point, so one of its edge planes is violated by far more than rounding and its
/// score is below that cell's. The listed cells are scored in index order with the same
/// first-of-equals rule.
#[derive(Debug)]
pub(super) struct BaseByOctant {
    cells: [Vec<u8>; 8],
}

/// Angle by which [`BaseByOctant`] widens each base cell's circumcap.
const OCTANT_MARGIN: f64 = 0.01;

impl BaseByOctant {
    pub(super) fn new(base: &[Cell]) -> Self {
        let mut cells: [Vec<u8>; 8] = Default::default();
        for (o, list) in cells.iter_mut().enumerate() {
            let sign = |bit: usize| if o >> bit & 1 == 1 { -1.0 } else { 1.0 };
            let s = DVec3::new(sign(0), sign(1), sign(2));
            for (k, c) in base.iter().enumerate() {
                // max c·p over unit p in the closed octant is |c⁺|, c with the components of the
                // wrong sign zeroed (c·p ≤ c⁺·p there).
                let reach = (c.center * s).max(DVec3::ZERO).length();
                let radius = c.cos_radius.clamp(-1.0, 1.0).acos();
                if reach >= (radius + OCTANT_MARGIN).min(std::f64::consts::PI).cos() - 1e-9 {
                    list.push(k as u8);
                }
            }
        }
        BaseByOctant { cells }
    }

    /// [`most_inside`] over `base` for the unit point `p` (the first of equals).
    #[inline]
    pub(super) fn most_inside(&self, base: &[Cell], p: DVec3) -> usize {
        let octant = usize::from(p.x < 0.0) | usize::from(p.y < 0.0) << 1 | usize::from(p.z < 0.0) << 2;
        let mut best = (usize::MAX, f64::NEG_INFINITY);
        for &k in &self.cells[octant] {
            let s = base[usize::from(k)].score(p);
            if s > best.1 {
                best = (usize::from(k), s);
            }
        }
        best.0
    }
}

/// The cell-choice rule as first written: `f64::min` of the three plane dots, the first of
/// equals over `cells`. The fast paths must give what this gives.
#[cfg(test)]
pub(super) fn most_inside_reference(cells: &[Cell], p: DVec3) -> usize {
    cells
        .iter()
        .enumerate()
        .map(|(k, c)| (k, c.planes[0].dot(p).min(c.planes[1].dot(p)).min(c.planes[2].dot(p))))
        .fold((usize::MAX, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc })
        .0
}

/// Points on and near the cells' corners, edges and the octants' planes, and random ones.
#[cfg(test)]
pub(super) fn awkward_points(cells: &[Cell], rng: &mut drafter_core::rng::Rng, random: usize) -> Vec<DVec3> {
    let mut points = Vec::new();
    for c in cells {
        let [a, b, c] = c.v;
        points.extend([a, b, c, (a + b).normalize(), (b + c).normalize(), (c + a).normalize(), -a]);
    }
    for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
        points.extend([axis, -axis, (axis + DVec3::new(-0.0, -0.0, -0.0)).normalize()]);
    }
    points.push(DVec3::new(-0.0, 0.6, -0.8));
    points.push(DVec3::new(0.6, -0.0, 0.8));
    for _ in 0..random {
        let p = rng.direction_f32().as_dvec3().normalize();
        points.push(p);
        // The same point with one component zeroed: on an octant's plane.
        let k = points.len() % 3;
        let mut q = p;
        q[k] = if k == 1 { -0.0 } else { 0.0 };
        points.push(q.normalize_or_zero());
    }
    points.retain(|p| *p != DVec3::ZERO);
    points
}

#[cfg(test)]
mod tests {
    use super::super::DEFAULT_OVERLAP;
    use super::*;

    #[test]
    fn base_by_octant_picks_what_all_cells_pick() {
        let mut rng = drafter_core::rng::Rng::new(5);
        for solid in [BaseSolid::Icosahedron, BaseSolid::Octahedron] {
            let base = base_cells(solid);
            let index = BaseByOctant::new(&base);
            let listed: usize = index.cells.iter().map(Vec::len).sum();
            assert!(listed < 8 * base.len(), "{solid:?}: the octants list {listed} cells");
            for p in awkward_points(&base, &mut rng, 20_000) {
                assert_eq!(index.most_inside(&base, p), most_inside_reference(&base, p), "{solid:?}, point {p}");
            }
        }
    }
    #[test]
    fn arc_paths_equal_arc_path_arc_by_arc() {
        let mut rng = drafter_core::rng::Rng::new(7);
        let base = base_cells(BaseSolid::Icosahedron);
        // Random arcs of every length (short ones go deep), plus zero and antipodal ones.
        let mut unit: Vec<[DVec3; 2]> = (0..20_000)
            .map(|k| {
                let a = rng.direction_f32().as_dvec3().normalize();
                let spread = [1e-4, 1e-2, 0.1, 0.5, 2.0][k % 5];
                let b = (a + rng.direction_f32().as_dvec3() * spread).normalize_or_zero();
                [a, b]
            })
            .collect();
        unit.push([DVec3::ZERO, DVec3::Z]);
        unit.push([DVec3::X, DVec3::NEG_X]);
        for level in [0u8, 3, 6] {
            let batch = arc_paths(&unit, &base, level, f64::from(DEFAULT_OVERLAP));
            let deep = batch.iter().filter(|p| p.1 > level).count();
            assert!(deep > 1000, "level {level}: only {deep} arcs reached the deepest level");
            for (i, &[a, b]) in unit.iter().enumerate() {
                assert_eq!(
                    batch[i],
                    arc_path(a, b, &base, level, f64::from(DEFAULT_OVERLAP)),
                    "arc {i}, level {level}"
                );
            }
        }
    }
    #[test]
    fn base_solids_tile_the_sphere() {
        for (base, faces) in [(BaseSolid::Octahedron, 8), (BaseSolid::Icosahedron, 20)] {
            let cells = base_cells(base);
            assert_eq!(cells.len(), faces);
            // Every direction lies in exactly one cell (up to boundaries).
            let mut rng = drafter_core::rng::Rng::new(1);
            for _ in 0..2000 {
                let mut r = || rng.signed_f64();
                let p = DVec3::new(r(), r(), r()).normalize();
                let inside = cells.iter().filter(|c| c.score(p) > 1e-12).count();
                assert!(inside <= 1);
                assert!(cells.iter().any(|c| c.score(p) >= -1e-12));
                // The 4 children tile their parent.
                let c = cells.iter().find(|c| c.score(p) >= -1e-12).unwrap();
                assert!(c.children().iter().any(|k| k.score(p) >= -1e-9));
            }
        }
    }
}
