//! Which faces of a welded mesh belong together: edge-connected components and crease-bounded
//! regions. See the crate docs for the rules.

use drafter_core::{EDGE_NONE, Topology};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::FanPairing;
use crate::union_find::{ConcurrentUnionFind, UnionFind};

/// Which vertex-connected components are inside-out (negative signed volume), so that edge
/// directions are read reversed there when faces are paired around a non-manifold edge.
pub(crate) struct Orientation {
    inside_out: Vec<bool>,
}

impl Orientation {
    /// Computed only when the mesh has a non-manifold edge; otherwise nothing reads it.
    fn new(topo: &Topology) -> Self {
        if !(0..topo.edge_count()).into_par_iter().any(|e| topo.edge_valence(e) >= 3) {
            return Self { inside_out: Vec::new() };
        }
        let volume = topo
            .faces
            .par_iter()
            .zip(topo.face_component.par_iter())
            .with_min_len(1 << 14)
            .fold(
                || vec![0.0f64; topo.component_count],
                |mut acc, (&[a, b, c], &comp)| {
                    let p = |v: u32| topo.welded_positions[v as usize].as_dvec3();
                    acc[comp as usize] += p(a).dot(p(b).cross(p(c)));
                    acc
                },
            )
            .reduce(
                || vec![0.0f64; topo.component_count],
                |mut x, y| {
                    x.iter_mut().zip(y).for_each(|(x, y)| *x += y);
                    x
                },
            );
        Self { inside_out: volume.into_iter().map(|v| v < 0.0).collect() }
    }
}

/// Edges along which a face has no partner.
pub(crate) struct FreeEdges {
    /// Non-manifold edges whose faces could not be paired, increasing.
    pub(crate) unpaired: Vec<u32>,
    /// Non-manifold edges whose faces were paired in part ([`partial_pairs`]), increasing.
    pub(crate) partial: Vec<u32>,
    /// Faces left without a partner at the edges of `partial`.
    pub(crate) left_open: usize,
    /// Faces with a boundary edge, an unpaired non-manifold edge, or no partner at a partly paired one.
    pub(crate) open_faces: Vec<bool>,
}

/// Calls `link(f, g)` (from several threads) for every pair of faces joined across an edge: the
/// two faces of a manifold edge, and at a non-manifold edge the faces paired by the radial rule
/// (see the crate docs). Returns the free edges: boundary edges, and non-manifold edges whose faces
/// could not be paired (left unjoined).
fn for_each_link(topo: &Topology, pairing: FanPairing, link: impl Fn(u32, u32) + Sync) -> FreeEdges {
    let orientation = Orientation::new(topo);
    let (mut unpaired, mut partial, open) = (0..topo.edge_count())
        .into_par_iter()
        .with_min_len(1 << 14)
        .fold(
            || (Vec::new(), Vec::new(), Vec::new(), Vec::new()),
            |(mut unpaired, mut partial, mut open, mut fan), e| {
                let faces = topo.faces_of_edge(e);
                match faces.len() {
                    0 => {}
                    1 => open.push(faces[0]),
                    2 => link(faces[0], faces[1]),
                    _ => {
                        // A face repeated in the same orientation is the same surface twice: the copies
                        // join the first and the fan is paired without them (otherwise every copy would
                        // be a one-triangle part, and the merge of small parts quadratic in the copies).
                        let distinct = distinct_faces(topo, faces, &link);
                        let pairing = match distinct.len() {
                            1 => {
                                open.push(distinct[0]);
                                Pairing::Full
                            }
                            2 => {
                                link(distinct[0], distinct[1]);
                                Pairing::Full
                            }
                            _ => radial_pairs(topo, &orientation, e, &distinct, pairing, &mut fan, &link),
                        };
                        match pairing {
                            Pairing::Full => {}
                            Pairing::Partial => {
                                // The faces left over are the fan's entries without a partner.
                                let before = open.len();
                                open.extend(fan.iter().filter(|x| x.1 == LEFT_OVER).map(|x| x.2));
                                partial.push((e as u32, (open.len() - before) as u32));
                            }
                            Pairing::None => {
                                unpaired.push(e as u32);
                                open.extend_from_slice(faces);
                            }
                        }
                    }
                }
                (unpaired, partial, open, fan)
            },
        )
        .map(|(unpaired, partial, open, _)| (unpaired, partial, open))
        .reduce(
            || (Vec::new(), Vec::new(), Vec::new()),
            |(mut u1, mut p1, mut o1), (mut u2, mut p2, mut o2)| {
                u1.append(&mut u2);
                p1.append(&mut p2);
                o1.append(&mut o2);
                (u1, p1, o1)
            },
        );
    unpaired.sort_unstable();
    partial.sort_unstable();
    let left_open = partial.iter().map(|&(_, n)| n as usize).sum();
    let partial = partial.into_iter().map(|(e, _)| e).collect();
    let mut open_faces = vec![false; topo.faces.len()];
    for f in open {
        open_faces[f as usize] = true;
    }
    FreeEdges { unpaired, partial, left_open, open_faces }
}

/// `faces` (of one edge) without their same-orientation copies: faces whose welded vertices are
/// equal in the same cyclic order are linked to the lowest-numbered of them, which alone is kept.
/// A copy in the opposite orientation is kept: that is two solids touching along a face.
fn distinct_faces(topo: &Topology, faces: &[u32], link: &impl Fn(u32, u32)) -> Vec<u32> {
    let key = |f: u32| {
        let [a, b, c] = topo.faces[f as usize];
        // The rotation that starts at the smallest vertex names the oriented face.
        if a <= b && a <= c {
            [a, b, c]
        } else if b <= c {
            [b, c, a]
        } else {
            [c, a, b]
        }
    };
    let mut keyed: Vec<([u32; 3], u32)> = faces.iter().map(|&f| (key(f), f)).collect();
    keyed.sort_unstable();
    let mut distinct: Vec<u32> = Vec::with_capacity(keyed.len());
    let mut first = 0;
    for i in 0..keyed.len() {
        if i > 0 && keyed[i].0 == keyed[first].0 {
            link(keyed[first].1, keyed[i].1);
        } else {
            first = i;
            distinct.push(keyed[i].1);
        }
    }
    if distinct.len() == faces.len() {
        // No copies: keep the edge's own face order.
        distinct.copy_from_slice(faces);
    } else {
        distinct.sort_unstable();
    }
    distinct
}

/// How the faces around a non-manifold edge were paired.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pairing {
    /// Every face has its partner.
    Full,
    /// Some faces were paired; the others (marked [`LEFT_OVER`] in the fan) have none here.
    Partial,
    /// Nothing was linked.
    None,
}

/// Pairs the faces around non-manifold edge `e` into the wedges of the solids that meet there.
///
/// Around the edge `a → b` (a < b), a face that runs `a → b` has its outward normal pointing to
/// increasing angle, one that runs `b → a` to decreasing angle. For closed, outward-oriented solids
/// that do not overlap, the faces sorted by angle therefore alternate `b → a`, `a → b`, and each
/// solid fills the wedge from a `b → a` face to the next `a → b` face. Ties (coincident faces of
/// two solids touching along a face) put `a → b` first: the empty wedge between two solids has zero
/// width. When the fan does not alternate, [`partial_pairs`] pairs what it can.
fn radial_pairs(
    topo: &Topology,
    orientation: &Orientation,
    e: usize,
    faces: &[u32],
    pairing: FanPairing,
    fan: &mut Vec<(f64, i8, u32)>,
    link: &impl Fn(u32, u32),
) -> Pairing {
    fan.clear();
    let [a, b] = topo.edges[e];
    let pa = topo.welded_positions[a as usize].as_dvec3();
    let axis = (topo.welded_positions[b as usize].as_dvec3() - pa).normalize_or_zero();
    if axis == DVec3::ZERO {
        return Pairing::None;
    }
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    for &f in faces {
        let tri = topo.faces[f as usize];
        let Some(k) = topo.face_edges[f as usize].iter().position(|&x| x as usize == e) else {
            fan.clear();
            return Pairing::None;
        };
        let forward = tri[k] == a;
        let inside_out = orientation.inside_out.get(topo.face_component[f as usize] as usize).copied();
        let forward = forward != inside_out.unwrap_or(false);
        let c = topo.welded_positions[tri[(k + 2) % 3] as usize].as_dvec3() - pa;
        let angle = c.dot(v).atan2(c.dot(u));
        fan.push((angle, if forward { CLOSES } else { OPENS }, f));
    }
    fan.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
    if !alternate(fan) {
        return match pairing {
            FanPairing::Partial => partial_pairs(fan, link),
            FanPairing::Whole => Pairing::None,
        };
    }
    let n = fan.len();
    for i in 0..n {
        if fan[i].1 == OPENS {
            link(fan[i].2, fan[(i + 1) % n].2);
        }
    }
    Pairing::Full
}

/// Pairs what can be paired in a fan that does not alternate: an odd count, or a
/// closing face missing, where a part whose surface is cracked (a T-junction seam, its faces
/// meeting the edge on one side only) touches a closed solid along one of the solid's edges.
///
/// The fan is put in the order [`alternate`] starts from (rotated to start after its widest gap,
/// closing faces first among faces of equal angle). Then an opening face is paired with the
/// next face around the edge when that one closes: the wedge between them holds no other face, so
/// it is one solid's, whatever the rest of the fan is. Each face is paired at most once; faces
/// left over get sign [`LEFT_OVER`] and are linked to nothing here (they are free edges of their
/// part, as the crack makes them). A fan where no such pair exists links nothing
/// ([`Pairing::None`], as before this rule). Overlapping solids can make an adjacent pair that
/// belongs to two solids; partly paired edges are counted in a diagnostic for that reason.
fn partial_pairs(fan: &mut [(f64, i8, u32)], link: &impl Fn(u32, u32)) -> Pairing {
    let n = fan.len();
    // `alternate` may have unwrapped and reordered the fan: start again from angles in [-π, π).
    for x in fan.iter_mut() {
        x.0 = (x.0 + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    }
    fan.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
    rotate_after_widest_gap(fan);
    for run in tie_runs(fan) {
        fan[run].sort_by_key(|x| (x.1, x.2));
    }
    let mut paired = vec![false; n];
    let mut any = false;
    for i in 0..n {
        let j = (i + 1) % n;
        if i != j && !paired[i] && !paired[j] && fan[i].1 == OPENS && fan[j].1 == CLOSES {
            link(fan[i].2, fan[j].2);
            paired[i] = true;
            paired[j] = true;
            any = true;
        }
    }
    if !any {
        return Pairing::None;
    }
    for (entry, &p) in fan.iter_mut().zip(&paired) {
        if !p {
            entry.1 = LEFT_OVER;
        }
    }
    Pairing::Partial
}

/// Rotates a fan sorted by angle to start after its widest gap and unwraps the angles, so that no
/// run of equal angles wraps around.
fn rotate_after_widest_gap(fan: &mut [(f64, i8, u32)]) {
    let n = fan.len();
    let gap = |fan: &[(f64, i8, u32)], i: usize| {
        let next = if i + 1 == n { fan[0].0 + std::f64::consts::TAU } else { fan[i + 1].0 };
        next - fan[i].0
    };
    let mut widest = n - 1;
    for i in 0..n {
        if gap(fan, i) > gap(fan, widest) {
            widest = i;
        }
    }
    fan.rotate_left((widest + 1) % n);
    for i in 1..n {
        if fan[i].0 < fan[i - 1].0 {
            fan[i].0 += std::f64::consts::TAU;
        }
    }
}

/// The runs of entries of a rotated fan whose angles are equal (within [`ANGLE_TIE`]).
fn tie_runs(fan: &[(f64, i8, u32)]) -> Vec<std::ops::Range<usize>> {
    let n = fan.len();
    let mut runs = Vec::new();
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        while end < n && fan[end].0 - fan[end - 1].0 < ANGLE_TIE {
            end += 1;
        }
        runs.push(start..end);
        start = end;
    }
    runs
}

/// Sign of a fan entry whose face runs `a → b`: it closes a solid's wedge.
const CLOSES: i8 = 0;
/// Sign of a fan entry whose face runs `b → a`: it opens a solid's wedge.
const OPENS: i8 = 1;
/// Sign given by [`partial_pairs`] to a fan entry left without a partner.
const LEFT_OVER: i8 = 2;

/// Angles closer than this (radians) count as equal around a non-manifold edge: coplanar faces of
/// two solids that touch along a face differ by rounding only.
const ANGLE_TIE: f64 = 1e-3;

/// Orders a fan sorted by angle so that opening and closing faces alternate around the edge, if
/// that is possible by reordering faces of equal angle (within [`ANGLE_TIE`]). The fan is rotated
/// to start after its widest gap, so no run of equal angles wraps around. Within a run, closing
/// faces go first (two solids touching along a face leave an empty wedge of zero width); when
/// that does not alternate, each run is ordered to continue the alternation (a zero-thickness
/// sheet between two wedges).
fn alternate(fan: &mut [(f64, i8, u32)]) -> bool {
    let n = fan.len();
    if !n.is_multiple_of(2) {
        return false;
    }
    rotate_after_widest_gap(fan);
    let runs = tie_runs(fan);
    let alternates = |fan: &[(f64, i8, u32)]| (0..n).all(|i| fan[i].1 != fan[(i + 1) % n].1);
    for run in &runs {
        fan[run.clone()].sort_by_key(|x| (x.1, x.2));
    }
    if alternates(fan) {
        return true;
    }
    // Greedy: each run continues the alternation of the runs before it.
    let original = fan.to_vec();
    for first in [OPENS, CLOSES] {
        let mut need = first;
        let mut ok = true;
        for run in &runs {
            let entries = &original[run.clone()];
            let mut same: Vec<_> = entries.iter().filter(|x| x.1 == need).copied().collect();
            let mut other: Vec<_> = entries.iter().filter(|x| x.1 != need).copied().collect();
            if !(same.len() == other.len() || same.len() == other.len() + 1) {
                ok = false;
                break;
            }
            same.sort_by_key(|x| x.2);
            other.sort_by_key(|x| x.2);
            let mut k = run.start;
            for (i, &entry) in same.iter().enumerate() {
                fan[k] = entry;
                k += 1;
                if let Some(&o) = other.get(i) {
                    fan[k] = o;
                    k += 1;
                }
            }
            need = 1 - fan[run.end - 1].1;
        }
        if ok && need == first {
            return true;
        }
    }
    false
}

/// Faces with no edge (all three welded vertices not distinct) join the first edge-carrying face
/// around one of their vertices, so that they do not stand alone as parts.
fn attach_collapsed(topo: &Topology, uf: &mut UnionFind) {
    for (f, edges) in topo.face_edges.iter().enumerate() {
        if edges.iter().all(|&e| e == EDGE_NONE) {
            let target = topo.faces[f]
                .iter()
                .flat_map(|&v| topo.faces_of_vertex(v as usize).iter().copied())
                .find(|&g| topo.face_edges[g as usize].iter().any(|&e| e != EDGE_NONE));
            if let Some(g) = target {
                uf.union(f as u32, g);
            }
        }
    }
}

/// Result of a per-mesh labelling: one label per face, labels `0..count` in order of first face.
pub(crate) struct Labelling {
    pub(crate) labels: Vec<u32>,
    pub(crate) count: u32,
    /// Non-manifold edges whose faces could not be paired, increasing.
    pub(crate) unpaired_edges: Vec<u32>,
    /// Non-manifold edges whose faces were paired in part, increasing.
    pub(crate) partial_edges: Vec<u32>,
    /// Faces left without a partner at the edges of `partial_edges`.
    pub(crate) left_open: usize,
    /// Per label: true when one of its faces has a free edge (the label is not a closed surface).
    pub(crate) open: Vec<bool>,
}

impl Labelling {
    fn new(labels: Vec<u32>, count: u32, free: FreeEdges) -> Self {
        let mut open = vec![false; count as usize];
        for (f, &l) in labels.iter().enumerate() {
            if free.open_faces[f] {
                open[l as usize] = true;
            }
        }
        Self {
            labels,
            count,
            unpaired_edges: free.unpaired,
            partial_edges: free.partial,
            left_open: free.left_open,
            open,
        }
    }
}

/// Edge-connected components.
pub(crate) fn components(topo: &Topology, pairing: FanPairing) -> Labelling {
    let uf = ConcurrentUnionFind::new(topo.faces.len());
    let free = for_each_link(topo, pairing, |f, g| uf.union(f, g));
    let mut uf = uf.into_sequential();
    attach_collapsed(topo, &mut uf);
    let (labels, count) = uf.labels();
    Labelling::new(labels, count, free)
}

/// Unit normal of each face from the welded positions (zero for a degenerate face).
pub(crate) fn face_normals(topo: &Topology) -> Vec<Vec3> {
    topo.faces
        .par_iter()
        .map(|&[a, b, c]| {
            let p = |v: u32| topo.welded_positions[v as usize].as_dvec3();
            let n = (p(b) - p(a)).cross(p(c) - p(a));
            n.try_normalize().map_or(Vec3::ZERO, |n| n.as_vec3())
        })
        .collect()
}

/// Crease-bounded regions: edge-connected faces joined only where the angle between their normals
/// is below `angle_deg`. Faces without a normal join their first linked neighbour that has one.
pub(crate) fn regions(topo: &Topology, angle_deg: f64, pairing: FanPairing) -> Labelling {
    let normals = face_normals(topo);
    let cos_limit = angle_deg.clamp(0.0, 180.0).to_radians().cos() as f32;
    let uf = ConcurrentUnionFind::new(topo.faces.len());
    let degenerate_links = std::sync::Mutex::new(Vec::new());
    let free = for_each_link(topo, pairing, |f, g| {
        let (nf, ng) = (normals[f as usize], normals[g as usize]);
        if nf == Vec3::ZERO || ng == Vec3::ZERO {
            // Rare: a lock is cheaper than threading a list through every worker.
            if let Ok(mut list) = degenerate_links.lock() {
                list.push((f, g));
            }
            return;
        }
        // Faces that disagree on orientation across the edge (both run it the same way) are
        // compared with one normal flipped.
        let ng = if same_direction(topo, f, g) { -ng } else { ng };
        if nf.dot(ng) > cos_limit {
            uf.union(f, g);
        }
    });
    let mut uf = uf.into_sequential();
    let mut degenerate_links = degenerate_links.into_inner().unwrap_or_else(|poisoned| poisoned.into_inner());
    degenerate_links.sort_unstable();
    // Each degenerate face joins one set only, so it can not bridge two regions.
    let mut attached = vec![false; topo.faces.len()];
    for pass in 0..2 {
        for &(f, g) in &degenerate_links {
            for (x, y) in [(f, g), (g, f)] {
                let x_degenerate = normals[x as usize] == Vec3::ZERO;
                let y_ok = normals[y as usize] != Vec3::ZERO || pass == 1;
                if x_degenerate && y_ok && !attached[x as usize] {
                    attached[x as usize] = true;
                    uf.union(x, y);
                }
            }
        }
    }
    attach_collapsed(topo, &mut uf);
    let (labels, count) = uf.labels();
    Labelling::new(labels, count, free)
}

/// True when faces `f` and `g` run their shared edge in the same direction.
fn same_direction(topo: &Topology, f: u32, g: u32) -> bool {
    let (tf, tg) = (topo.faces[f as usize], topo.faces[g as usize]);
    let directed = |t: [u32; 3]| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])];
    directed(tf).iter().any(|d| directed(tg).contains(d))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fan(entries: &[(f64, i8)]) -> Vec<(f64, i8, u32)> {
        let mut fan: Vec<_> =
            entries.iter().enumerate().map(|(i, &(deg, s))| (deg.to_radians(), s, i as u32)).collect();
        fan.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
        fan
    }

    /// The pairs (opening face, next face) after ordering, as face ids.
    fn pairs(entries: &[(f64, i8)]) -> Option<Vec<(u32, u32)>> {
        let mut fan = fan(entries);
        if !alternate(&mut fan) {
            return None;
        }
        let n = fan.len();
        let mut out: Vec<_> = (0..n).filter(|&i| fan[i].1 == OPENS).map(|i| (fan[i].2, fan[(i + 1) % n].2)).collect();
        out.sort_unstable();
        Some(out)
    }

    #[test]
    fn two_solids_sharing_an_edge() {
        // Solid A fills 0°..90° (opens at 0, closes at 90); solid B fills 180°..270°.
        assert_eq!(pairs(&[(0.0, OPENS), (90.0, CLOSES), (180.0, OPENS), (270.0, CLOSES)]), Some(vec![(0, 1), (2, 3)]));
    }

    #[test]
    fn coincident_faces_of_touching_solids() {
        // A fills 0°..180°, B fills 180°..300°: at 180° A closes and B opens with equal angles.
        // Listing B's face first must not matter.
        let a = [(0.0, OPENS), (180.0, OPENS), (180.0, CLOSES), (300.0, CLOSES)];
        assert_eq!(pairs(&a), Some(vec![(0, 2), (1, 3)]));
        // Rounding: the coincident faces differ in the last digits.
        let b = [(0.0, OPENS), (180.0 + 1e-9, OPENS), (180.0, CLOSES), (300.0, CLOSES)];
        assert_eq!(pairs(&b), Some(vec![(0, 2), (1, 3)]));
    }

    #[test]
    fn ties_across_the_wrap_around() {
        // A closes at 180°, B opens at -180° + 1e-9: the same half-plane.
        let f = [(-179.999_999_9, OPENS), (-90.0, CLOSES), (0.0, OPENS), (180.0, CLOSES)];
        assert_eq!(pairs(&f), Some(vec![(0, 1), (2, 3)]));
    }

    #[test]
    fn zero_thickness_sheet_between_wedges() {
        // A fills 0°..90°; a double-sided sheet (two faces) stands at 200°.
        assert_eq!(pairs(&[(0.0, OPENS), (90.0, CLOSES), (200.0, CLOSES), (200.0, OPENS)]), Some(vec![(0, 1), (3, 2)]));
    }

    #[test]
    fn fans_that_cannot_pair() {
        assert_eq!(pairs(&[(0.0, OPENS), (90.0, CLOSES), (180.0, OPENS)]), None, "odd count");
        assert_eq!(pairs(&[(0.0, OPENS), (90.0, OPENS), (180.0, CLOSES), (270.0, CLOSES)]), None, "overlapping");
    }

    /// Links made by [`partial_pairs`] on an entry list, and the faces left over.
    fn partial(entries: &[(f64, i8)]) -> (Vec<(u32, u32)>, Vec<u32>) {
        let mut fan = fan(entries);
        let links = std::sync::Mutex::new(Vec::new());
        let pairing = partial_pairs(&mut fan, &|f, g| links.lock().unwrap().push((f, g)));
        let mut links = links.into_inner().unwrap();
        links.sort_unstable();
        let mut left: Vec<u32> = fan.iter().filter(|x| x.1 == LEFT_OVER).map(|x| x.2).collect();
        left.sort_unstable();
        if pairing == Pairing::None {
            assert!(links.is_empty() && left.is_empty());
        }
        (links, left)
    }

    #[test]
    fn a_cracked_part_on_a_solid_edge_is_paired_in_part() {
        // A cover fills 0°..180° (its side opens at 0°, its bottom closes at 180°); a gasket with a
        // crack touches the bottom from below with one face at 180° that opens its wedge, whose
        // closing face is missing. The cover's faces pair; the gasket's face is left over, in
        // either listing order.
        assert_eq!(partial(&[(0.0, OPENS), (180.0, CLOSES), (180.0, OPENS)]), (vec![(0, 1)], vec![2]));
        assert_eq!(partial(&[(0.0, OPENS), (180.0, OPENS), (180.0, CLOSES)]), (vec![(0, 2)], vec![1]));
        // Across the wrap-around: the closing face at -180° + 1e-9 is the same half-plane.
        assert_eq!(partial(&[(-179.999_999_9, CLOSES), (0.0, OPENS), (180.0, OPENS)]), (vec![(1, 0)], vec![2]));
        // Nothing closes after an opening face: nothing is linked.
        assert_eq!(partial(&[(0.0, OPENS), (90.0, OPENS), (180.0, OPENS)]), (vec![], vec![]));
    }
}
