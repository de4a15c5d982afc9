//! Assemblies whose parts touch, merged into one mesh the way a CAD exporter writes an STL, with
//! the true part of every triangle; and the accuracy of a segmentation against that
//! truth.
//!
//! Each part is a closed, outward-oriented solid of revolution ([`lathe`]) or a box whose faces
//! are grids ([`grid_box`]). The parts touch where assemblies are typical: a gasket clamped
//! between two flanges, a washer under a screw head (the shank pressed through a plate), a pin
//! pressed into a hole, stacked plates, a cover over a casing with a gasket. Every assembly comes
//! twice:
//!
//! * **matching** tessellation across the contact: the same segments and phase around the axis,
//!   and profile points inserted where the other part's contact begins and ends, so coincident
//!   faces are the same triangles in opposite orientations;
//! * **non-matching**: different segment counts, phases and spacings; contact faces overlap
//!   without sharing edges, and a few vertices coincide by chance.
//!
//! [`merged_stl`] writes the parts as one unwelded triangle soup (three vertices per triangle, in
//! f32, as in a binary STL); [`flatten`] does the same for any scene (every instance in world
//! space, the true part = the instance). Everything is deterministic.

use std::f64::consts::{FRAC_PI_4, TAU};

use drafter_core::{EDGE_NONE, InstanceId, Mesh, PartId, Scene, SourceFormat, Topology, Weld};
use drafter_segment::{FanPairing, Parts, SegmentMode, SegmentOptions, segment};
use glam::DVec3;

/// A solid part in world space: positions (f64) and outward triangles.
#[derive(Clone, Debug, Default)]
pub struct Solid {
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Solid {
    /// Signed enclosed volume (positive for outward faces).
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    fn flipped(mut self) -> Self {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
        self
    }
}

/// How a solid of revolution is tessellated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lathe {
    /// Segments around the axis.
    pub segments: u32,
    /// Angle of the first segment, radians.
    pub phase: f64,
    /// Longest step along the profile: each profile edge is cut into equal steps no longer than
    /// this, counted from its start.
    pub step: f64,
    /// A crack, as CAD exporters leave where two faces of a B-rep are discretized differently:
    /// the profile edge that ends at this corner (an index into the profile) ends on a ring of
    /// twice the segments, while the next edge starts on the usual ring. The vertices of the
    /// coarse ring lie on the fine one (T-junctions), so the solid is closed in space but its
    /// welded surface has a boundary loop there. `None`: no crack.
    pub crack_at: Option<usize>,
}

impl Lathe {
    /// `segments` around, `phase`, `step`, no crack.
    pub const fn new(segments: u32, phase: f64, step: f64) -> Self {
        Self { segments, phase, step, crack_at: None }
    }

    /// The same with a crack at profile corner `corner`.
    pub const fn cracked(self, corner: usize) -> Self {
        Self { crack_at: Some(corner), ..self }
    }
}

/// A closed solid of revolution about the z axis through `centre`: `profile` is a closed polygon
/// in (r, z), r ≥ 0; points with r = 0 are poles. Quads are split along the diagonal from the
/// profile edge's lexicographically smaller end at one angle to the larger end at the next, so two
/// parts that share a profile segment (in either direction) get the same triangles there.
pub fn lathe(profile: &[(f64, f64)], centre: DVec3, t: Lathe) -> Solid {
    let n = t.segments.max(3) as usize;
    // Refine the profile: (r, z, segments of the ring).
    let mut points: Vec<(f64, f64, usize)> = Vec::new();
    for i in 0..profile.len() {
        let (p, q) = (profile[i], profile[(i + 1) % profile.len()]);
        let len = ((q.0 - p.0).powi(2) + (q.1 - p.1).powi(2)).sqrt();
        let steps = (len / t.step).ceil().max(1.0) as usize;
        // Steps are counted from the lexicographically smaller end, so both directions agree.
        let forward = p <= q;
        let (a, b) = if forward { (p, q) } else { (q, p) };
        let cut: Vec<(f64, f64)> = (0..steps)
            .map(|k| {
                let s = k as f64 / steps as f64;
                (a.0 + (b.0 - a.0) * s, a.1 + (b.1 - a.1) * s)
            })
            .collect();
        if forward {
            points.extend(cut.iter().map(|&(r, z)| (r, z, n)));
        } else {
            // From p (= b) down to just above a.
            points.push((b.0, b.1, n));
            points.extend(cut[1..].iter().rev().map(|&(r, z)| (r, z, n)));
        }
        if t.crack_at == Some((i + 1) % profile.len()) {
            // The edge ends on a fine ring at q; the next edge starts on the usual one.
            points.push((q.0, q.1, 2 * n));
        }
    }
    let mut solid = Solid::default();
    // First vertex of each ring (a pole has one vertex).
    let mut first = Vec::with_capacity(points.len());
    for &(r, z, count) in &points {
        first.push(solid.positions.len() as u32);
        let at = |j: usize| {
            let angle = t.phase + TAU * j as f64 / n as f64;
            centre + DVec3::new(r * angle.cos(), r * angle.sin(), z)
        };
        if r == 0.0 {
            solid.positions.push(at(0));
        } else if count == n {
            solid.positions.extend((0..n).map(at));
        } else {
            // The fine ring of a crack: the coarse ring's vertices and the midpoints of its
            // chords, so the coarse edges of the next face pass exactly through them.
            solid
                .positions
                .extend((0..count).map(|j| if j % 2 == 0 { at(j / 2) } else { (at(j / 2) + at(j / 2 + 1)) * 0.5 }));
        }
    }
    // Vertex j of ring i, with j counted in units of that ring's segments.
    let v = |i: usize, j: usize| if points[i].0 == 0.0 { first[i] } else { first[i] + (j % points[i].2) as u32 };
    for i in 0..points.len() {
        let k = (i + 1) % points.len();
        if (points[i].0, points[i].1) == (points[k].0, points[k].1) {
            continue; // the two rings of a crack
        }
        let mut tris: Vec<[u32; 3]> = Vec::new();
        if points[i].2 == points[k].2 {
            let (lo, hi) = if (points[i].0, points[i].1) <= (points[k].0, points[k].1) { (i, k) } else { (k, i) };
            for j in 0..points[i].2 {
                // Quad lo_j, hi_j, hi_j+1, lo_j+1 split along lo_j–hi_j+1, written from i to k.
                let mut pair = [[v(lo, j), v(hi, j), v(hi, j + 1)], [v(lo, j), v(hi, j + 1), v(lo, j + 1)]];
                if lo != i {
                    for tri in &mut pair {
                        tri.swap(1, 2);
                    }
                }
                tris.extend(pair);
            }
        } else {
            // From a ring of m segments to one of 2m (or back), written from i to k.
            let coarse_first = points[i].2 < points[k].2;
            let (c, f) = if coarse_first { (i, k) } else { (k, i) };
            for j in 0..points[c].2 {
                let mut three = [
                    [v(c, j), v(f, 2 * j), v(f, 2 * j + 1)],
                    [v(c, j), v(f, 2 * j + 1), v(c, j + 1)],
                    [v(c, j + 1), v(f, 2 * j + 1), v(f, 2 * j + 2)],
                ];
                if !coarse_first {
                    for tri in &mut three {
                        tri.swap(1, 2);
                    }
                }
                tris.extend(three);
            }
        }
        solid.triangles.extend(tris.into_iter().filter(|t| t[0] != t[1] && t[1] != t[2] && t[2] != t[0]));
    }
    if solid.volume() < 0.0 { solid.flipped() } else { solid }
}

/// A box from `lo` to `hi` whose six faces are grids of `cells` (per axis) quads, each split along
/// the diagonal from its smallest corner; outward-facing.
pub fn grid_box(lo: DVec3, hi: DVec3, cells: [u32; 3]) -> Solid {
    let mut solid = Solid::default();
    for axis in 0..3 {
        for side in [false, true] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let (nu, nv) = (cells[u].max(1), cells[v].max(1));
            let base = solid.positions.len() as u32;
            for j in 0..=nv {
                for i in 0..=nu {
                    let mut p = DVec3::ZERO;
                    p[axis] = if side { hi[axis] } else { lo[axis] };
                    p[u] = lo[u] + (hi[u] - lo[u]) * i as f64 / nu as f64;
                    p[v] = lo[v] + (hi[v] - lo[v]) * j as f64 / nv as f64;
                    solid.positions.push(p);
                }
            }
            for j in 0..nv {
                for i in 0..nu {
                    let a = base + j * (nu + 1) + i;
                    let (b, c, d) = (a + 1, a + nu + 2, a + nu + 1);
                    if side {
                        solid.triangles.extend([[a, b, c], [a, c, d]]);
                    } else {
                        solid.triangles.extend([[a, c, b], [a, d, c]]);
                    }
                }
            }
        }
    }
    solid
}

/// An annulus (ring) profile from radius `r0` to `r1` and height `z0` to `z1`, with extra points
/// on its bottom and top at the radii in `marks` (where a touching part's contact begins and ends,
/// for matching tessellation). `r0 = 0` gives a disc.
fn ring(r0: f64, r1: f64, z0: f64, z1: f64, marks: &[f64]) -> Vec<(f64, f64)> {
    let mut inner: Vec<f64> = marks.iter().copied().filter(|&m| m > r0 && m < r1).collect();
    inner.sort_by(f64::total_cmp);
    inner.dedup();
    let mut p = vec![(r0, z0)];
    p.extend(inner.iter().map(|&r| (r, z0)));
    p.push((r1, z0));
    p.push((r1, z1));
    p.extend(inner.iter().rev().map(|&r| (r, z1)));
    p.push((r0, z1));
    p
}

/// Inserts points at heights `marks` on the vertical edges of `profile`.
fn mark_heights(profile: &[(f64, f64)], marks: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for i in 0..profile.len() {
        let (p, q) = (profile[i], profile[(i + 1) % profile.len()]);
        out.push(p);
        if p.0 == q.0 && p.0 > 0.0 {
            let mut between: Vec<f64> = marks.iter().copied().filter(|&z| (z - p.1) * (z - q.1) < 0.0).collect();
            between.sort_by(f64::total_cmp);
            if q.1 < p.1 {
                between.reverse();
            }
            out.extend(between.into_iter().map(|z| (p.0, z)));
        }
    }
    out
}

/// A generated assembly: its parts as solids, and what kind of contact it tests.
#[derive(Clone, Debug)]
pub struct ContactAssembly {
    /// `kind/matching`, `kind/non-matching` or `kind/cracked`.
    pub name: String,
    /// Whether coincident faces share their tessellation.
    pub matching: bool,
    /// The parts, each closed and outward-facing.
    pub parts: Vec<Solid>,
}

impl ContactAssembly {
    /// The parts as one unwelded mesh (see [`merged_stl`]) with the true part of each triangle.
    pub fn merged(&self) -> (Scene, Vec<u32>) {
        merged_stl(&self.name, &self.parts)
    }
}

/// The generated family: five kinds of contact, each with matching and non-matching tessellation.
pub fn contact_assemblies() -> Vec<ContactAssembly> {
    let mut out = Vec::new();
    for (suffix, matching, cracked) in
        [("matching", true, false), ("non-matching", false, false), ("cracked", true, true)]
    {
        // The cracked variant: matching tessellation, and the clamped or pressed part has a crack
        // (see [`Lathe::crack_at`]) along a rim that lies on edges of the part it touches, so the
        // welded mesh has non-manifold edges of three faces there.
        let crack = |t: Lathe, corner: usize| if cracked { t.cracked(corner) } else { t };
        // Round parts: the same tessellation on both sides of a contact, or another one.
        let base = Lathe::new(48, 0.0, 0.5);
        let other = if matching { base } else { Lathe::new(40, 0.05, 0.35) };
        let marks = |m: &[f64]| if matching { m.to_vec() } else { Vec::new() };

        // 1. A gasket clamped between two flanges, narrower than them.
        let gasket = [5.0, 9.0];
        out.push(ContactAssembly {
            name: format!("flange-gasket/{suffix}"),
            matching,
            parts: vec![
                lathe(&ring(3.0, 10.0, 0.0, 2.0, &marks(&gasket)), DVec3::ZERO, base),
                lathe(&ring(5.0, 9.0, 2.0, 2.3, &[]), DVec3::ZERO, crack(other, 2)),
                lathe(&ring(3.0, 10.0, 2.3, 4.3, &marks(&gasket)), DVec3::ZERO, base),
            ],
        });

        // 2. A flush gasket: same radii as its flanges, so the rims meet edge to edge.
        out.push(ContactAssembly {
            name: format!("flush-gasket/{suffix}"),
            matching,
            parts: vec![
                lathe(&ring(3.0, 10.0, 0.0, 2.0, &[]), DVec3::ZERO, base),
                lathe(&ring(3.0, 10.0, 2.0, 2.2, &[]), DVec3::ZERO, crack(other, 2)),
                lathe(&ring(3.0, 10.0, 2.2, 4.2, &[]), DVec3::ZERO, base),
            ],
        });

        // 3. Screws with washers under their heads, the shanks pressed through holes of a plate.
        let mut parts = vec![];
        let holes = [DVec3::new(-6.0, 0.0, 0.0), DVec3::new(6.0, 0.0, 0.0)];
        // The plate is a boss around each hole (a plate with holes is no solid of revolution).
        for (k, &c) in holes.iter().enumerate() {
            let bolt = if k == 0 { base } else { other };
            let boss_marks = marks(&[1.05, 2.2]);
            parts.push(lathe(&ring(1.0, 3.0, -3.0, 0.0, &boss_marks), c, base));
            parts.push(lathe(&ring(1.05, 2.2, 0.0, 0.4, &[]), c, crack(bolt, 2)));
            let mut screw = vec![(0.0, -4.0), (1.0, -4.0)];
            if matching {
                screw.extend([(1.0, -3.0), (1.0, 0.0)]);
            }
            screw.push((1.0, 0.4));
            if matching {
                screw.extend([(1.05, 0.4), (2.2, 0.4)]);
            }
            screw.extend([(2.4, 0.4), (2.4, 1.6), (0.0, 1.6)]);
            parts.push(lathe(&screw, c, bolt));
        }
        out.push(ContactAssembly { name: format!("screws-washers/{suffix}"), matching, parts });

        // 4. Pins pressed into holes of a bushing, sticking out on both sides.
        let pin_marks = if matching { vec![0.0, 4.0] } else { vec![] };
        let pin_profile = mark_heights(&[(0.0, -1.0), (1.5, -1.0), (1.5, 5.0), (0.0, 5.0)], &pin_marks);
        out.push(ContactAssembly {
            name: format!("pin-in-hole/{suffix}"),
            matching,
            parts: vec![
                lathe(&ring(1.5, 5.0, 0.0, 4.0, &[]), DVec3::ZERO, base),
                lathe(&pin_profile, DVec3::ZERO, crack(other, 3)),
                lathe(&ring(1.5, 5.0, 0.0, 4.0, &[]), DVec3::new(12.0, 0.0, 0.0), base),
                lathe(&pin_profile, DVec3::new(12.0, 0.0, 0.0), other),
            ],
        });

        // 5. Stacked plates: two of the same footprint, a smaller one on top.
        let cells = |n: u32| if matching { [n, n, 1] } else { [n + 1, n, 2] };
        out.push(ContactAssembly {
            name: format!("stacked-plates/{suffix}"),
            matching,
            parts: vec![
                grid_box(DVec3::new(0.0, 0.0, 0.0), DVec3::new(10.0, 10.0, 1.0), [5, 5, 1]),
                grid_box(DVec3::new(0.0, 0.0, 1.0), DVec3::new(10.0, 10.0, 2.0), cells(5)),
                grid_box(
                    DVec3::new(2.0, 2.0, 2.0),
                    DVec3::new(8.0, 8.0, 2.5),
                    if matching { [3, 3, 1] } else { [4, 3, 1] },
                ),
            ],
        });

        // 6. A cover over a casing with a gasket between them; round and square.
        for (shape, t) in [("round", base), ("square", Lathe::new(4, FRAC_PI_4, 1.0))] {
            let t_other = if matching { t } else { Lathe::new(t.segments * 5 / 4, t.phase + 0.05, 0.7) };
            let casing = vec![(0.0, 0.0), (10.0, 0.0), (10.0, 6.0), (8.0, 6.0), (8.0, 1.0), (0.0, 1.0)];
            out.push(ContactAssembly {
                name: format!("cover-casing-{shape}/{suffix}"),
                matching,
                parts: vec![
                    lathe(&casing, DVec3::ZERO, t),
                    lathe(&ring(8.0, 10.0, 6.0, 6.3, &[]), DVec3::ZERO, crack(t_other, 2)),
                    lathe(&ring(0.0, 10.0, 6.3, 7.3, &marks(&[8.0])), DVec3::ZERO, t),
                ],
            });
        }
    }
    out
}

/// `parts` as one mesh of unwelded triangles (three f32 vertices each, as a binary STL holds
/// them), in one instance, with the part of each triangle.
pub fn merged_stl(name: &str, parts: &[Solid]) -> (Scene, Vec<u32>) {
    let mut mesh = Mesh { name: name.to_owned(), ..Mesh::default() };
    let mut truth = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        for t in &part.triangles {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(t.iter().map(|&v| part.positions[v as usize].as_vec3()));
            mesh.triangles.push([base, base + 1, base + 2]);
            truth.push(k as u32);
        }
    }
    (single_mesh_scene(mesh, name), truth)
}

/// Every instance of `scene` in world space as one unwelded triangle soup (see [`merged_stl`]),
/// with the instance of each triangle as its true part.
pub fn flatten(scene: &Scene) -> (Scene, Vec<u32>) {
    let mut mesh = Mesh { name: "merged".into(), ..Mesh::default() };
    let mut truth = Vec::new();
    for (i, inst) in scene.instances.iter().enumerate() {
        let m = scene.mesh(inst.mesh);
        let flip = inst.flips_winding();
        for t in &m.triangles {
            let t = if flip { [t[0], t[2], t[1]] } else { *t };
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(
                t.iter()
                    .map(|&v| inst.world_from_object.transform_point3(m.positions[v as usize].as_dvec3()).as_vec3()),
            );
            mesh.triangles.push([base, base + 1, base + 2]);
            truth.push(i as u32);
        }
    }
    (single_mesh_scene(mesh, "merged"), truth)
}

/// The solids of every instance of `scene`, as the true part of each triangle of [`flatten`]'s
/// mesh: what "the parts" of a merged assembly can mean when some of its meshes hold several
/// separate bodies (a bearing and its balls, four bolts written as one mesh), which no method can
/// tell from one part by geometry alone.
///
/// Each unique mesh on its own is cut into edge-connected pieces (welded, with the faces around
/// non-manifold edges paired as [`SegmentMode::Components`] pairs them), and a piece is a *solid*
/// when it is closed: every welded edge it uses is used by at least two of its faces (checked
/// here, not taken from the segmentation). A mesh with fewer than two solids is one part, open
/// pieces and all (faces that do not weld are still one part). A mesh with several solids is that
/// many parts; each open piece goes with the solid that shares the most welded vertices with it,
/// else with the largest solid. Returns the truth and the number of instances that hold several
/// solids.
pub fn flatten_solids(scene: &Scene) -> (Vec<u32>, usize) {
    let mut of_mesh: Vec<Option<(Vec<u32>, u32)>> = vec![None; scene.meshes.len()];
    let mut truth = Vec::new();
    let (mut next, mut split) = (0u32, 0usize);
    for inst in &scene.instances {
        let entry = of_mesh[inst.mesh.index()].get_or_insert_with(|| mesh_solids(scene.mesh(inst.mesh)));
        let (labels, count) = (&entry.0, entry.1);
        truth.extend(labels.iter().map(|&l| next + l));
        next += count;
        split += usize::from(count > 1);
    }
    (truth, split)
}

/// The solid of each face of `mesh` (see [`flatten_solids`]) and their number.
fn mesh_solids(mesh: &Mesh) -> (Vec<u32>, u32) {
    let faces = mesh.triangles.len();
    let one = (vec![0; faces], u32::from(faces > 0));
    if faces == 0 {
        return one;
    }
    let scene = Scene::single_mesh(SourceFormat::Stl, mesh.clone(), "solids");
    let options =
        SegmentOptions { mode: SegmentMode::Components, fan_pairing: FanPairing::Partial, ..SegmentOptions::default() };
    let (parts, _) = segment(&scene, &options);
    let piece: Vec<u32> = (0..faces as u32).map(|f| parts.part_of(InstanceId(0), f).0).collect();
    let pieces = parts.len();
    // Closed: every welded edge a piece uses is used by two of its faces or more.
    let topo = Topology::build(mesh, Weld::default());
    let mut uses: Vec<(u32, u32)> = Vec::new();
    for (f, edges) in topo.face_edges.iter().enumerate() {
        uses.extend(edges.iter().filter(|&&e| e != EDGE_NONE).map(|&e| (e, piece[f])));
    }
    uses.sort_unstable();
    let mut closed = vec![true; pieces];
    for run in uses.chunk_by(|a, b| a == b) {
        if run.len() == 1 {
            closed[run[0].1 as usize] = false;
        }
    }
    let solids: Vec<usize> = (0..pieces).filter(|&p| closed[p]).collect();
    if solids.len() < 2 {
        return one;
    }
    let mut size = vec![0usize; pieces];
    for &p in &piece {
        size[p as usize] += 1;
    }
    let largest = *solids.iter().max_by_key(|&&p| (size[p], std::cmp::Reverse(p))).unwrap_or(&solids[0]);
    // Welded vertices shared between each open piece and each solid.
    let mut at_vertex: Vec<(u32, u32)> = Vec::new();
    for (f, tri) in topo.faces.iter().enumerate() {
        at_vertex.extend(tri.iter().map(|&v| (v, piece[f])));
    }
    at_vertex.sort_unstable();
    at_vertex.dedup();
    let mut shared: Vec<(u32, u32)> = Vec::new();
    for run in at_vertex.chunk_by(|a, b| a.0 == b.0) {
        for &(_, o) in run.iter().filter(|x| !closed[x.1 as usize]) {
            shared.extend(run.iter().filter(|x| closed[x.1 as usize]).map(|&(_, s)| (o, s)));
        }
    }
    shared.sort_unstable();
    let mut solid_of = vec![u32::MAX; pieces];
    for (k, &p) in solids.iter().enumerate() {
        solid_of[p] = k as u32;
    }
    let mut best: Vec<(usize, u32)> = vec![(0, u32::MAX); pieces];
    for run in shared.chunk_by(|a, b| a == b) {
        let (o, s) = run[0];
        if run.len() > best[o as usize].0 {
            best[o as usize] = (run.len(), s);
        }
    }
    let labels = piece
        .iter()
        .map(|&p| {
            let p = p as usize;
            if closed[p] {
                solid_of[p]
            } else if best[p].1 != u32::MAX {
                solid_of[best[p].1 as usize]
            } else {
                solid_of[largest]
            }
        })
        .collect();
    (labels, solids.len() as u32)
}

fn single_mesh_scene(mesh: Mesh, name: &str) -> Scene {
    Scene::single_mesh(SourceFormat::Stl, mesh, name)
}

/// How well a segmentation of a single-instance scene recovers the true parts.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Accuracy {
    /// Fraction of triangles in a part that *matches* one original part: at least 99% of the
    /// found part's triangles come from that original, and it holds at least 99% of the
    /// original's triangles (so each original is matched at most once).
    pub matched: f64,
    /// Parts found.
    pub parts: usize,
    /// Original parts (those with at least one triangle).
    pub truth_parts: usize,
}

impl Accuracy {
    /// The bar a segmentation must reach: ≥ 99% matched and the right part count.
    pub fn passes(&self) -> bool {
        self.matched >= 0.99 && self.parts == self.truth_parts
    }
}

/// Compares `parts` (of a scene with one instance, instance 0) against `truth` (the original part
/// of each triangle).
pub fn accuracy(parts: &Parts, truth: &[u32]) -> Accuracy {
    let originals = truth.iter().map(|&t| t as usize + 1).max().unwrap_or(0);
    let mut size = vec![0usize; originals];
    for &t in truth {
        size[t as usize] += 1;
    }
    let mut matched = 0usize;
    let mut from = Vec::new();
    for p in 0..parts.len() {
        from.clear();
        from.extend(parts.triangles_of(PartId::from(p)).map(|t| truth[t as usize]));
        from.sort_unstable();
        let (mut best, mut best_of, mut run) = (0, 0, 0);
        for i in 0..from.len() {
            run = if i > 0 && from[i] == from[i - 1] { run + 1 } else { 1 };
            if run > best {
                best = run;
                best_of = from[i];
            }
        }
        if best > 0 && best * 100 >= from.len() * 99 && best * 100 >= size[best_of as usize] * 99 {
            matched += best;
        }
    }
    Accuracy {
        matched: if truth.is_empty() { 1.0 } else { matched as f64 / truth.len() as f64 },
        parts: parts.len(),
        truth_parts: size.iter().filter(|&&s| s > 0).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every edge of a solid is used once in each direction: closed and consistently oriented.
    fn closed_and_oriented(s: &Solid) -> bool {
        let mut directed: Vec<(DVec3Key, DVec3Key)> = Vec::new();
        for t in &s.triangles {
            for k in 0..3 {
                directed.push((key(s.positions[t[k] as usize]), key(s.positions[t[(k + 1) % 3] as usize])));
            }
        }
        directed.sort_unstable();
        let dup = directed.windows(2).any(|w| w[0] == w[1]);
        !dup && directed.iter().all(|&(a, b)| directed.binary_search(&(b, a)).is_ok())
    }

    type DVec3Key = [i64; 3];
    fn key(p: DVec3) -> DVec3Key {
        (p * 1e9).round().as_i64vec3().to_array()
    }

    #[test]
    fn every_generated_part_is_a_closed_outward_solid() {
        for a in contact_assemblies() {
            for (k, s) in a.parts.iter().enumerate() {
                // Cracked parts are closed in space only (T-junctions), see `Lathe::crack_at`.
                assert!(a.name.ends_with("cracked") || closed_and_oriented(s), "{} part {k} is not closed", a.name);
                assert!(s.volume() > 0.0, "{} part {k} is inside out", a.name);
            }
        }
    }
}
