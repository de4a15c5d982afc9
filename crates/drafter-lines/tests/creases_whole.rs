//! Creases kept whole (hysteresis, `classify` docs) and CAD face borders (tangent edges), on meshes
//! generated here: a chamfered cylinder whose 30° chamfer is tessellated at 29.5–30.5° draws each
//! chamfer circle as one closed crease loop; scan-like noise and a coarse cylinder's facet lines
//! gain no creases; the result does not depend on the thread count; borders between input faces
//! are tangent edges below the crease angle, creases above it, and nothing where coplanar.

mod common;

use common::{Rng, noisy_sphere};

use drafter_core::{Topology, Weld};
use drafter_lines::*;
use glam::Vec3;

/// A cylinder of radius 1 along +z with `n` columns, a chamfer at both ends meeting the flat caps
/// at 30° + δ (δ per column, within ±`spread` degrees: the chamfer's facet next to the cap circle
/// has exactly that dihedral angle with the cap) and the side wall at about 60°. Returns the mesh
/// and the welded ids of the two cap circles' vertices, in order around.
fn chamfered_cylinder(n: u32, spread: f32, seed: u64) -> (Vec<Vec3>, Vec<[u32; 3]>, [Vec<u32>; 2]) {
    let mut rng = Rng::new(seed);
    let (radius, chamfer, height) = (1.0f32, 0.15f32, 1.0f32);
    let step = std::f32::consts::TAU / n as f32;
    // The chord of a column is `cos(step / 2)` of the radius from the axis, so a drop of
    // `chamfer · cos(step / 2) · tan(angle)` over the chamfer gives the facet that angle to the cap.
    let half = (step / 2.0).cos();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut circles: [Vec<u32>; 2] = [Vec::new(), Vec::new()];
    for (end, sign) in [(0usize, 1.0f32), (1, -1.0)] {
        let top = sign * height / 2.0;
        let centre = positions.len() as u32;
        positions.push(Vec3::new(0.0, 0.0, top));
        let inner = positions.len() as u32;
        for k in 0..n {
            let a = step * k as f32;
            positions.push(Vec3::new((radius - chamfer) * a.cos(), (radius - chamfer) * a.sin(), top));
        }
        let outer = positions.len() as u32;
        for k in 0..n {
            let a = step * k as f32;
            let angle = (30.0 + spread * rng.range_f32(-1.0, 1.0)).to_radians();
            let drop = chamfer * half * angle.tan();
            positions.push(Vec3::new(radius * a.cos(), radius * a.sin(), top - sign * drop));
        }
        circles[end] = (inner..inner + n).collect();
        for k in 0..n {
            let (i0, i1) = (inner + k, inner + (k + 1) % n);
            let (o0, o1) = (outer + k, outer + (k + 1) % n);
            // Cap fan, then the chamfer: the triangle on the cap circle's edge i0-i1 takes o1.
            let mut push = |t: [u32; 3]| triangles.push(if sign > 0.0 { t } else { [t[0], t[2], t[1]] });
            push([centre, i0, i1]);
            push([i0, o1, i1]);
            push([i0, o0, o1]);
        }
    }
    // The side wall between the two outer rings.
    let (top_outer, bottom_outer) = (1 + n, (1 + 2 * n) + 1 + n);
    for k in 0..n {
        let (t0, t1) = (top_outer + k, top_outer + (k + 1) % n);
        let (b0, b1) = (bottom_outer + k, bottom_outer + (k + 1) % n);
        triangles.push([t0, b0, b1]);
        triangles.push([t0, b1, t1]);
    }
    (positions, triangles, circles)
}

/// The edge id between welded vertices `a` and `b`.
fn edge(topology: &Topology, a: u32, b: u32) -> usize {
    let key = [a.min(b), a.max(b)];
    topology.edges.binary_search(&key).expect("an edge of the mesh")
}

/// Dihedral angles of the edges around each circle, and how many are creases.
fn circle_edges(topology: &Topology, circle: &[u32]) -> Vec<usize> {
    (0..circle.len()).map(|k| edge(topology, circle[k], circle[(k + 1) % circle.len()])).collect()
}

#[test]
fn a_chamfer_tessellated_across_the_crease_angle_is_one_closed_loop() {
    for (n, seed) in [(48, 1u64), (64, 2), (96, 3), (200, 4)] {
        let (positions, triangles, circles) = chamfered_cylinder(n, 0.5, seed);
        let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
        assert_eq!(topology.boundary_edge_count(), 0, "closed");
        let full = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        let off =
            classify_edges(&topology, None, &LineOptions { crease_continue: 1.0, ..LineOptions::default() }).unwrap();
        // The threshold alone, specks kept.
        let raw = classify_edges(
            &topology,
            None,
            &LineOptions { crease_continue: 1.0, crease_min_edges: 0, ..LineOptions::default() },
        )
        .unwrap();
        for circle in &circles {
            let ids = circle_edges(&topology, circle);
            // The premise: the circle's dihedral angles straddle 30° within 29.5–30.5°.
            let angles: Vec<f32> = ids.iter().map(|&e| full.dihedral_deg[e]).collect();
            assert!(angles.iter().all(|a| (29.49..=30.51).contains(a)), "n {n}: {angles:?}");
            assert!(angles.iter().any(|&a| a < 30.0) && angles.iter().any(|&a| a > 30.0), "n {n}: both sides");
            let crease_off = ids.iter().filter(|&&e| off.classes[e] == EdgeClass::Crease).count();
            assert!(crease_off < ids.len(), "n {n}: a threshold alone draws it dotted ({crease_off} of {})", ids.len());
            // With hysteresis: every edge of the circle a crease, so it is one closed loop.
            let kept: Vec<usize> = ids.iter().copied().filter(|&e| full.classes[e] != EdgeClass::Crease).collect();
            assert!(kept.is_empty(), "n {n}: {} of {} circle edges not creases: {kept:?}", kept.len(), ids.len());
        }
        // Nothing else was continued: the continued edges are the circles' edges below 30°.
        let below: usize = circles
            .iter()
            .flat_map(|c| circle_edges(&topology, c))
            .filter(|&e| raw.classes[e] != EdgeClass::Crease)
            .count();
        assert_eq!(full.counts.continued, below, "n {n}");
        assert_eq!(full.counts.crease, raw.counts.crease + below, "n {n}");
        // Every crease vertex of the cap circles is on exactly two creases of its circle.
        for circle in &circles {
            for &v in circle {
                let creases = (0..topology.edges.len())
                    .filter(|&e| full.classes[e] == EdgeClass::Crease && topology.edges[e].contains(&v))
                    .count();
                assert_eq!(creases, 2, "n {n}: vertex {v} of a cap circle");
            }
        }
    }
}

/// A height field over the unit square (`cells` × `cells`, two triangles a cell) with random
/// heights of `amplitude` cell sizes: a scan-like surface.
fn noisy_plane(cells: u32, amplitude: f32, seed: u64) -> Topology {
    let mut rng = Rng::new(seed);
    let h = 1.0 / cells as f32;
    let mut positions = Vec::new();
    for j in 0..=cells {
        for i in 0..=cells {
            positions.push(Vec3::new(i as f32 * h, j as f32 * h, amplitude * h * rng.range_f32(-1.0, 1.0)));
        }
    }
    let mut triangles = Vec::new();
    let at = |i: u32, j: u32| j * (cells + 1) + i;
    for j in 0..cells {
        for i in 0..cells {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Topology::from_triangles(&positions, &triangles, Weld::Exact)
}

/// A folded sheet over the unit square: folds along y at every column, each at 27° ± 2° (random
/// heights per vertex), the cells between them planar but for the noise. Every fold edge lies in the
/// continuation band, none above the crease angle.
fn folded_sheet(cells: u32, seed: u64) -> Topology {
    let mut rng = Rng::new(seed);
    let h = 1.0 / cells as f32;
    // Alternate heights 0 and c·h give folds of 2·atan(c).
    let c = 13.5f32.to_radians().tan();
    let mut positions = Vec::new();
    for j in 0..=cells {
        for i in 0..=cells {
            let z = if i % 2 == 1 { c * h } else { 0.0 } + 0.008 * h * rng.range_f32(-1.0, 1.0);
            positions.push(Vec3::new(i as f32 * h, j as f32 * h, z));
        }
    }
    let mut triangles = Vec::new();
    let at = |i: u32, j: u32| j * (cells + 1) + i;
    for j in 0..cells {
        for i in 0..cells {
            triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    Topology::from_triangles(&positions, &triangles, Weld::Exact)
}

/// Scan-like noise gains no creases: a surface whose dihedral angles lie at 25–29°, in the
/// continuation band but below the crease angle, has no crease to continue; on rough noise with
/// creases among it, hysteresis bridges few gaps (it never extends a chain into the open) and the
/// speck rule still counts only the creases above the angle.
#[test]
fn scan_noise_gains_no_creases() {
    let topology = folded_sheet(150, 7);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let angles: Vec<f32> = lines.dihedral_deg.iter().copied().filter(|a| a.is_finite() && *a > 5.0).collect();
    let (lo, hi) = angles.iter().fold((f32::MAX, 0.0f32), |(lo, hi), &a| (lo.min(a), hi.max(a)));
    assert!(angles.len() > 20_000 && lo > 24.0 && hi < 30.0, "the premise: {} folds at {lo}–{hi}°", angles.len());
    assert_eq!((lines.counts.crease, lines.counts.continued), (0, 0));
    // Rough noise: many creases above the angle, most of them specks.
    for (amplitude, seed) in [(0.15f32, 1u64), (0.2, 2), (0.25, 3), (0.3, 4)] {
        let topology = noisy_plane(120, amplitude, seed);
        let on = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        let off =
            classify_edges(&topology, None, &LineOptions { crease_continue: 1.0, ..LineOptions::default() }).unwrap();
        let raw = classify_edges(
            &topology,
            None,
            &LineOptions { crease_continue: 1.0, crease_min_edges: 0, ..LineOptions::default() },
        )
        .unwrap();
        let near = on.dihedral_deg.iter().filter(|&&a| (24.0..30.0).contains(&a)).count();
        eprintln!(
            "noisy plane {amplitude}: {} edges, {near} at 24–30°, {} above 30°, {} kept without hysteresis, {} with ({} continued)",
            topology.edges.len(),
            raw.counts.crease,
            off.counts.crease,
            on.counts.crease,
            on.counts.continued
        );
        assert!(near > topology.edges.len() / 50, "the premise: near-creases in the noise");
        assert!(
            on.counts.continued as f64 <= 0.04 * raw.counts.crease as f64,
            "amplitude {amplitude}: {} continued for {} creases above the angle",
            on.counts.continued,
            raw.counts.crease
        );
    }
}

/// A closed prism over a 12-gon of 11 sides spanning 28.6° and one 45.4°: its columns turn by
/// 28.6° (10 of them) and 37° (the two beside the wide side). The 28.6° facet lines lie in the
/// continuation band but meet the cap creases at 90° and have no crease end to start from, so the
/// creases are the two caps' circles and the two 37° facet lines.
#[test]
fn a_coarse_cylinder_gains_no_facet_lines() {
    let mut turn = 0.0f32;
    let mut ring = Vec::new();
    for k in 0..12 {
        ring.push(Vec3::new(turn.to_radians().cos(), turn.to_radians().sin(), 0.0));
        turn += if k == 11 { 45.4 } else { 28.6 };
    }
    let n = ring.len() as u32;
    let mut positions: Vec<Vec3> = ring.iter().map(|p| *p - Vec3::Z).chain(ring.iter().map(|p| *p + Vec3::Z)).collect();
    positions.push(-Vec3::Z);
    positions.push(Vec3::Z);
    let (bottom, top) = (2 * n, 2 * n + 1);
    let mut triangles = Vec::new();
    for k in 0..n {
        let (a, b) = (k, (k + 1) % n);
        triangles.push([a, b, b + n]);
        triangles.push([a, b + n, a + n]);
        triangles.push([bottom, b, a]);
        triangles.push([top, a + n, b + n]);
    }
    let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let columns: Vec<f32> = (0..n).map(|k| lines.dihedral_deg[edge(&topology, k, k + n)]).collect();
    assert_eq!(columns.iter().filter(|&&a| (28.0..29.0).contains(&a)).count(), 10, "{columns:?}");
    assert_eq!(lines.counts.continued, 0);
    assert_eq!(lines.counts.crease, 2 * n as usize + 2);
}

/// The classes do not depend on the thread count (the continuation is serial, in vertex order).
#[test]
fn hysteresis_is_independent_of_the_thread_count() {
    let (positions, triangles, _) = chamfered_cylinder(96, 0.5, 11);
    let mut meshes = vec![Topology::from_triangles(&positions, &triangles, Weld::Exact), noisy_plane(80, 0.25, 5)];
    meshes.push({
        let m = noisy_sphere(120, 60, 0.02, 3);
        Topology::from_triangles(&m.positions, &m.triangles, Weld::Exact)
    });
    for topology in &meshes {
        let classes = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| classify_edges(topology, None, &LineOptions::default()).unwrap().classes)
        };
        let one = classes(1);
        assert_eq!(one, classes(3));
        assert_eq!(one, classes(8));
    }
}

/// Input faces: a plate with a rounded edge, its faces labelled as a CAD export's primitives.
/// Borders below the crease angle are tangent edges, the ones above it creases, a border between
/// two coplanar faces nothing; without labels the same mesh has no tangent edge.
#[test]
fn borders_between_input_faces_are_tangent_edges() {
    // Profile in (x, y), extruded along z over [0, 1]: the top (y = 1, split at x = 0.25 into two
    // faces), a quarter-round of radius 0.3 in 6 facets, the right side (x = 1).
    let r = 0.3f32;
    let mut profile = vec![(0.0f32, 1.0f32), (0.25, 1.0), (1.0 - r, 1.0)];
    for k in 1..=6 {
        let a = std::f32::consts::FRAC_PI_2 * (1.0 - k as f32 / 6.0);
        profile.push((1.0 - r + r * a.cos(), 1.0 - r + r * a.sin()));
    }
    profile.push((1.0, 0.0));
    // Face of each profile segment: top-left, top-right, fillet ×6, right.
    let face_of_segment = [0u32, 1, 2, 2, 2, 2, 2, 2, 3];
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut faces = Vec::new();
    for (i, w) in profile.windows(2).enumerate() {
        let base = positions.len() as u32;
        for &(x, y) in w {
            positions.push(Vec3::new(x, y, 0.0));
            positions.push(Vec3::new(x, y, 1.0));
        }
        // Outward (up and to the right) for a profile running left to right, top to bottom.
        triangles.push([base, base + 1, base + 3]);
        triangles.push([base, base + 3, base + 2]);
        faces.extend([face_of_segment[i]; 2]);
    }
    let topology = Topology::from_triangles(&positions, &triangles, Weld::Exact);
    let labels = FaceLabels { parts: None, input_faces: Some(&faces) };
    let lines = classify_edges_labelled(&topology, labels, &LineOptions::default()).unwrap();
    let column = |x: f32, y: f32| {
        let v = |z: f32| topology.welded_positions.iter().position(|p| *p == Vec3::new(x, y, z)).unwrap() as u32;
        edge(&topology, v(0.0), v(1.0))
    };
    assert_eq!(lines.classes[column(0.25, 1.0)], EdgeClass::Coplanar, "a seam between coplanar faces");
    assert_eq!(lines.classes[column(1.0 - r, 1.0)], EdgeClass::Tangent, "plane to fillet, 7.5°");
    assert_eq!(lines.classes[column(1.0, 1.0 - r)], EdgeClass::Tangent, "fillet to plane");
    let (x, y) = profile[4];
    assert_eq!(lines.classes[column(x, y)], EdgeClass::SilhouetteCandidate, "inside the fillet, 15°");
    assert_eq!(lines.counts.tangent, 2);
    assert!(EdgeClass::Tangent.is_hard() && lines.counts.hard() == lines.counts.boundary + 2);
    let plain = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    assert_eq!(plain.counts.tangent, 0);
    assert_eq!(plain.classes[column(1.0 - r, 1.0)], EdgeClass::SilhouetteCandidate);
    // Above the crease angle a border stays a crease (here a crease angle of 5°, below 7.5°).
    let steep = LineOptions { crease_angle_deg: 5.0, ..LineOptions::default() };
    let lines = classify_edges_labelled(&topology, labels, &steep).unwrap();
    assert_eq!(lines.classes[column(1.0 - r, 1.0)], EdgeClass::Crease);
    // Labels of the wrong length are a caller's bug.
    assert!(
        classify_edges_labelled(&topology, FaceLabels { parts: None, input_faces: Some(&faces[1..]) }, &steep).is_err()
    );
    // One label for every face is no border.
    let one = vec![4u32; faces.len()];
    let lines = classify_edges_labelled(
        &topology,
        FaceLabels { parts: None, input_faces: Some(&one) },
        &LineOptions::default(),
    )
    .unwrap();
    assert_eq!(lines.classes, plain.classes);
}
