//! Stability suite: inputs where each method is known to fail, generated here, and the CAD parts of
//! `samples/` under random rigid motions and re-indexings.
//!
//! For every input and every method the suite asserts that the result is
//! * **valid** — no NaN anywhere; each box is orthonormal and contains every point within
//!   `CONTAIN_EPS` × the points' diagonal; every vertex normal (plain and enhanced) has unit length
//!   within `UNIT_EPS`;
//! * **stable** — under random rotations (and a translation by 10⁶) and under vertex/triangle
//!   re-indexing: the `default` and `optimal` boxes keep their volume (the area of a flat set, the
//!   length of a linear one) within `VOLUME_RTOL` plus the rounding of the coordinates, and stay as
//!   thin as the set; `optimal` is never larger than any other method; vertex normals follow the
//!   rotation within `NORMAL_TOL_DEG`; edge classes are identical; silhouette sets are identical
//!   except for edges within `TIE_EPS` of the tie (a face seen exactly edge-on, where rounding may
//!   decide either way); the number of parts is identical;
//! * **deterministic** — the same input twice gives bit-identical boxes, normals, edge classes and
//!   silhouette sets; hierarchies answer exactly as brute force.
//!
//! PCA and hull-covariance boxes are *not* rotation-stable on symmetric shapes (their axes are
//! undefined there, so they are snapped to the world axes, which do not rotate with the part): for
//! them the suite asserts validity, determinism and `optimal ≤ them` only, and
//! `pca_is_unstable_on_a_rotated_cube` pins the failure down so that it stays documented.

use std::path::PathBuf;

use drafter_bounds::{Obb, ObbMethod, ObbOptions, oriented_box};
use drafter_core::{PartId, Topology, Weld};
use drafter_lines::{
    BruteForce, EdgeClass, EdgeSet, LineOptions, SilhouetteIndex, SilhouetteOptions, View, classify_edges,
};
use drafter_normals::{NormalsOptions, compute_normals};
use drafter_segment::{SegmentOptions, segment};
use drafter_testkit::Rng;
use drafter_testkit::generate::{self, TriMesh};
use glam::{DMat4, DQuat, DVec3, Vec3};

/// A box may miss a point by this fraction of the points' bounding diagonal (rounding of one dot
/// product is ~1e-16; the margin covers 10⁶ offsets).
const CONTAIN_EPS: f64 = 1e-9;
/// `default` and `optimal`: relative volume change under rotation or re-indexing (the corpus test
/// uses the same 0.1%).
const VOLUME_RTOL: f64 = 1e-3;
/// Unit length of normals.
const UNIT_EPS: f32 = 1e-4;
/// Rotated normals against the normals of the rotated mesh (f32 filtering).
const NORMAL_TOL_DEG: f64 = 0.05;
/// A flat edge may turn into a silhouette candidate (or back) under rotation only below this
/// dihedral angle (f32 rounding of vertex positions tilts the 1e-4-high sides of a thin plate by ~0.03°).
const FLAT_FLIP_DEG: f32 = 0.1;
/// An edge may turn from crease to candidate (or back) only this close to the 30° crease angle.
const THRESHOLD_FLIP_DEG: f32 = 0.01;
/// An edge may change silhouette state only when `min(|n1·w|, |n2·w|)` is below this.
const TIE_EPS: f64 = 1e-5;

struct Case {
    name: &'static str,
    mesh: TriMesh,
    /// Whether the shape survives a rotation of its f32 positions. A plate thinner than f32
    /// resolution (~1e-7 of its size) does not: rounding the rotated corners tilts its side
    /// faces by tens of degrees. Such cases are rotated in f64 (boxes) only.
    f32_rotation: bool,
    /// Whether the enhanced normals are defined up to rounding. Not on a non-manifold fan of evenly
    /// spread wings: the low-pass averages normals that sum to about zero, so its direction is
    /// rounding noise (see `enhanced_normals_of_a_nonmanifold_fan_follow_a_rotation`).
    enhanced_defined: bool,
}

fn cases() -> Vec<Case> {
    vec![
        Case { name: "cube", mesh: generate::cube(), f32_rotation: true, enhanced_defined: true },
        Case { name: "cylinder", mesh: generate::cylinder(48, 2.0), f32_rotation: true, enhanced_defined: true },
        Case {
            name: "disc-like cylinder",
            mesh: generate::cylinder(64, 0.05),
            f32_rotation: true,
            enhanced_defined: true,
        },
        Case { name: "paper-thin plate 1e-4", mesh: generate::plate(1e-4), f32_rotation: true, enhanced_defined: true },
        Case {
            name: "paper-thin plate 1e-7",
            mesh: generate::plate(1e-7),
            f32_rotation: false,
            enhanced_defined: true,
        },
        Case { name: "sliver fan", mesh: generate::sliver_fan(2000, 1.0), f32_rotation: true, enhanced_defined: true },
        Case {
            name: "non-manifold fan 3",
            mesh: generate::nonmanifold_fan(3),
            f32_rotation: true,
            enhanced_defined: false,
        },
        Case {
            name: "non-manifold fan 6",
            mesh: generate::nonmanifold_fan(6),
            f32_rotation: true,
            enhanced_defined: false,
        },
        Case { name: "open box", mesh: generate::open_box(), f32_rotation: true, enhanced_defined: true },
        Case { name: "single triangle", mesh: generate::single_triangle(), f32_rotation: true, enhanced_defined: true },
        Case {
            name: "subdivided cylinder",
            mesh: generate::cylinder(16, 1.0).subdivided().subdivided(),
            f32_rotation: true,
            enhanced_defined: true,
        },
    ]
}

fn diagonal(points: &[DVec3]) -> f64 {
    let b = drafter_bounds::aabb(points);
    (b.max - b.min).length()
}

fn rotate(points: &[DVec3], m: &DMat4) -> Vec<DVec3> {
    points.iter().map(|&p| m.transform_point3(p)).collect()
}

/// Valid: finite, orthonormal, right-handed, non-negative extents, volume consistent, contains
/// every point.
fn assert_valid_box(obb: &Obb, points: &[DVec3], what: &str) {
    let diag = diagonal(points);
    assert!(obb.center.is_finite() && obb.half_extents.is_finite() && obb.volume.is_finite(), "{what}: NaN in {obb:?}");
    for i in 0..3 {
        assert!(obb.axes[i].is_finite(), "{what}: NaN axis");
        assert!(obb.half_extents[i] >= 0.0, "{what}: negative extent");
        for j in 0..3 {
            let want = if i == j { 1.0 } else { 0.0 };
            assert!((obb.axes[i].dot(obb.axes[j]) - want).abs() < 1e-9, "{what}: axes not orthonormal: {obb:?}");
        }
    }
    assert!(obb.axes[0].cross(obb.axes[1]).dot(obb.axes[2]) > 0.0, "{what}: left-handed axes");
    let h = obb.half_extents;
    assert!((obb.volume - 8.0 * h.x * h.y * h.z).abs() <= 1e-12 * obb.volume.max(1e-300), "{what}: volume");
    let eps = CONTAIN_EPS * diag.max(f64::MIN_POSITIVE);
    let outside = points.iter().filter(|&&p| !obb.contains(p, eps)).count();
    assert_eq!(outside, 0, "{what}: {outside} of {} points outside the {} box", points.len(), obb.method);
}

fn boxes(points: &[DVec3], what: &str) -> Vec<Obb> {
    ObbMethod::ALL
        .iter()
        .map(|&m| {
            let obb = oriented_box(points, &ObbOptions::with_method(m)).unwrap_or_else(|e| panic!("{what} {m}: {e}"));
            assert_valid_box(&obb, points, &format!("{what} {m}"));
            obb
        })
        .collect()
}

fn by_method(boxes: &[Obb], m: ObbMethod) -> &Obb {
    boxes.iter().find(|b| b.method == m).expect("every method ran")
}

/// Relative noise floor for zero measures (volume of a flat set, area of a linear one).
const NOISE: f64 = 1e-12;

fn sorted_extents(obb: &Obb) -> [f64; 3] {
    let mut h = obb.half_extents.to_array();
    h.sort_by(f64::total_cmp);
    h
}

/// `optimal` is no larger than any method; `default` and `optimal` agree with `reference`
/// (the same shape in another pose or order).
fn assert_stable_boxes(boxes: &[Obb], reference: &[Obb], diag: f64, what: &str) {
    let optimal = by_method(boxes, ObbMethod::Optimal);
    // Coordinates at distance D from the origin are rounded to about D·2⁻⁵², so an extent h is
    // only known to that over h: a 1e-7 plate at 10⁶ has a volume known to ~1e-3.
    let offset =
        by_method(boxes, ObbMethod::Aabb).center.length().max(by_method(reference, ObbMethod::Aabb).center.length());
    let rounding = 8.0 * f64::EPSILON * (offset + diag);
    for b in boxes {
        assert!(
            optimal.volume <= b.volume * (1.0 + 1e-9) + NOISE * diag.powi(3),
            "{what}: optimal {optimal:?} > {b:?}"
        );
    }
    for m in [ObbMethod::Default, ObbMethod::Optimal] {
        let (a, r) = (by_method(boxes, m), by_method(reference, m));
        // Compare what is defined: the volume of a solid, the area of a flat set (its rectangle
        // may tie between orientations: every side of an acute triangle gives the same area), the
        // length of a linear one.
        let (ea, er) = (sorted_extents(a), sorted_extents(r));
        let (measure_a, measure_r, dimension) = if r.volume > NOISE * diag.powi(3) {
            (a.volume, r.volume, 3)
        } else if er[2] * er[1] > NOISE * diag * diag {
            (ea[2] * ea[1], er[2] * er[1], 2)
        } else {
            (ea[2], er[2], 1)
        };
        let thinnest = if dimension == 3 {
            er[0]
        } else if dimension == 2 {
            er[1]
        } else {
            er[2]
        };
        let allowed = VOLUME_RTOL + 3.0 * rounding / thinnest.max(f64::MIN_POSITIVE);
        let rel = (measure_a - measure_r).abs() / measure_r.max(f64::MIN_POSITIVE);
        assert!(
            measure_r == 0.0 && measure_a <= NOISE * diag || rel <= allowed,
            "{what} {m}: {dimension}-d measure {measure_a} vs {measure_r} (rel {rel:e}, allowed {allowed:e}); {a:?} vs {r:?}"
        );
        // The box stays as thin as the set: a flat set gets a flat box, a linear set a line.
        if dimension < 3 {
            assert!(a.volume <= NOISE * diag.powi(3), "{what} {m}: volume {} of a {dimension}-d set", a.volume);
        }
    }
}

#[test]
fn boxes_of_generated_shapes_are_valid_stable_and_deterministic() {
    let mut rng = Rng::new(2013);
    for case in cases() {
        let points = case.mesh.points();
        let diag = diagonal(&points);
        let base = boxes(&points, case.name);
        // Deterministic: bit-identical on a second run.
        assert_eq!(base, boxes(&points, case.name), "{}: not deterministic", case.name);
        // Random rotations, and a rotation plus a translation by 10⁶.
        for k in 0..6 {
            let q = rng.rotation();
            let t = if k == 5 { DVec3::new(1e6, -2e6, 3e6) } else { DVec3::ZERO };
            let m = DMat4::from_rotation_translation(q, t);
            let moved = rotate(&points, &m);
            let what = format!("{} rotated #{k}", case.name);
            assert_stable_boxes(&boxes(&moved, &what), &base, diag, &what);
        }
        // Re-indexed (the points in another order).
        let (re, _, _) = case.mesh.reindexed(&mut rng);
        let what = format!("{} re-indexed", case.name);
        assert_stable_boxes(&boxes(&re.points(), &what), &base, diag, &what);
    }
}

#[test]
fn boxes_of_degenerate_point_sets() {
    let mut rng = Rng::new(5);
    let sets: Vec<(&str, Vec<DVec3>)> = vec![
        ("collinear", generate::collinear_points(101, DVec3::new(-1.0, 0.5, 2.0), DVec3::new(3.0, 1.5, -2.0))),
        (
            "collinear far away",
            generate::collinear_points(50, DVec3::new(1e6, 1e6, 1e6), DVec3::new(1e6 + 1.0, 1e6, 1e6 + 2.0)),
        ),
        ("coincident", generate::coincident_points(10, DVec3::new(1.0, -2.0, 3.0))),
        ("one point", vec![DVec3::new(0.25, 0.5, 0.75)]),
        ("two points", vec![DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)]),
    ];
    for (name, points) in sets {
        let base = boxes(&points, name);
        for b in base.iter().filter(|b| b.method != ObbMethod::Aabb) {
            assert!(b.volume.abs() < 1e-12, "{name} {}: volume {} of a degenerate set", b.method, b.volume);
        }
        // The segment's length is the longest extent of the optimal box.
        let diag = diagonal(&points);
        let optimal = by_method(&base, ObbMethod::Optimal);
        assert!((2.0 * optimal.half_extents.max_element() - diag).abs() <= 1e-9 * diag.max(1.0), "{name}: {optimal:?}");
        for k in 0..4 {
            let m = DMat4::from_quat(rng.rotation());
            let what = format!("{name} rotated #{k}");
            let moved = boxes(&rotate(&points, &m), &what);
            assert_stable_boxes(&moved, &base, diag.max(1e-300), &what);
        }
    }
    // No points, and NaN: errors, not boxes.
    assert!(oriented_box(&[], &ObbOptions::default()).is_err());
    assert!(oriented_box(&[DVec3::ZERO, DVec3::NAN], &ObbOptions::default()).is_err());
}

/// The known failure of covariance boxes, kept visible: PCA's axes on a cube are undefined and
/// snapped to the world axes, so a rotated cube gets a box up to 3√3 ≈ 5.2× too large. `default`
/// and `optimal` do not have the problem.
#[test]
fn pca_is_unstable_on_a_rotated_cube() {
    let points = generate::cube().points();
    let q = DQuat::from_axis_angle(DVec3::new(1.0, 1.0, 0.0).normalize(), 0.6);
    let moved = rotate(&points, &DMat4::from_quat(q));
    let b = boxes(&moved, "rotated cube");
    let pca = by_method(&b, ObbMethod::Pca).volume;
    let optimal = by_method(&b, ObbMethod::Optimal).volume;
    assert!((optimal - 1.0).abs() < 1e-6, "optimal box of the unit cube: {optimal}");
    assert!(
        pca > 1.2,
        "PCA on a rotated cube was expected to fail (got {pca}); update the module docs if it no longer does"
    );
}

/// Per triangle corner, the normal of `normals` (one per output vertex of `layout`).
fn corner_normals(layout_triangles: &[[u32; 3]], normals: &[Vec3]) -> Vec<[Vec3; 3]> {
    layout_triangles.iter().map(|t| t.map(|v| normals[v as usize])).collect()
}

fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

struct NormalsOut {
    plain: Vec<[Vec3; 3]>,
    enhanced: Vec<[Vec3; 3]>,
}

fn normals_of(mesh: &TriMesh, what: &str) -> NormalsOut {
    let m = mesh.to_mesh(what);
    let topology = Topology::build(&m, Weld::Snap(drafter_core::DEFAULT_SNAP_FRACTION));
    let (out, _) = compute_normals(&m, &topology, &NormalsOptions::default());
    for (k, n) in out.normals.iter().chain(&out.enhanced_normals).enumerate() {
        assert!(n.is_finite() && (n.length() - 1.0).abs() < UNIT_EPS, "{what}: normal {k} = {n:?}");
    }
    for (f, n) in out.faces.enhanced.iter().enumerate() {
        assert!(n.is_finite(), "{what}: face {f} enhanced normal {n:?}");
        assert!(out.faces.geometry.is_degenerate(f) || (n.length() - 1.0).abs() < UNIT_EPS, "{what}: face {f} {n:?}");
    }
    NormalsOut {
        plain: corner_normals(&out.layout.triangles, &out.normals),
        enhanced: corner_normals(&out.layout.triangles, &out.enhanced_normals),
    }
}

fn assert_normals_follow(
    a: &[[Vec3; 3]],
    b: &[[Vec3; 3]],
    rotation: DQuat,
    corner_of: impl Fn(usize, usize) -> (usize, usize),
    what: &str,
) {
    let mut worst = 0f64;
    for (t, corners) in b.iter().enumerate() {
        for (k, &normal) in corners.iter().enumerate() {
            let (ot, ok) = corner_of(t, k);
            let expected = (rotation * a[ot][ok].as_dvec3()).as_vec3();
            worst = worst.max(angle_deg(expected, normal));
        }
    }
    assert!(worst <= NORMAL_TOL_DEG, "{what}: normals moved by {worst}° beyond the rotation");
}

#[test]
fn normals_of_generated_shapes_are_unit_stable_and_deterministic() {
    let mut rng = Rng::new(2005);
    for case in cases() {
        let base = normals_of(&case.mesh, case.name);
        let again = normals_of(&case.mesh, case.name);
        assert!(base.plain == again.plain && base.enhanced == again.enhanced, "{}: not deterministic", case.name);
        for k in 0..if case.f32_rotation { 3 } else { 0 } {
            let q = rng.rotation();
            let what = format!("{} rotated #{k}", case.name);
            let moved = normals_of(&case.mesh.transformed(&DMat4::from_quat(q)), &what);
            assert_normals_follow(&base.plain, &moved.plain, q, |t, c| (t, c), &what);
            if case.enhanced_defined {
                assert_normals_follow(&base.enhanced, &moved.enhanced, q, |t, c| (t, c), &what);
            }
        }
        let (re, new_vertex, old_triangle) = case.mesh.reindexed(&mut rng);
        let what = format!("{} re-indexed", case.name);
        let moved = normals_of(&re, &what);
        let corner_of = |t: usize, k: usize| {
            let ot = old_triangle[t] as usize;
            let v = re.triangles[t][k];
            let ok = (0..3).find(|&c| new_vertex[case.mesh.triangles[ot][c] as usize] == v).expect("same corners");
            (ot, ok)
        };
        assert_normals_follow(&base.plain, &moved.plain, DQuat::IDENTITY, corner_of, &what);
        if case.enhanced_defined {
            assert_normals_follow(&base.enhanced, &moved.enhanced, DQuat::IDENTITY, corner_of, &what);
        }
    }
}

/// Edge classes and silhouette sets keyed by input-vertex pairs (renamed by `rename`), so that
/// they compare across poses and orders.
struct LinesOut {
    /// (key, class code), sorted.
    classes: Vec<((u32, u32), u8)>,
    /// Per view, the silhouette edges' keys, sorted.
    silhouettes: Vec<Vec<(u32, u32)>>,
    /// key → the candidate's two normals (for the tie test).
    normals: std::collections::BTreeMap<(u32, u32), [Vec3; 2]>,
    /// key → dihedral angle (degrees).
    dihedral: std::collections::BTreeMap<(u32, u32), f32>,
}

fn lines_of(mesh: &TriMesh, views: &[View], rename: &dyn Fn(u32) -> u32, what: &str) -> LinesOut {
    let topology =
        Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Snap(drafter_core::DEFAULT_SNAP_FRACTION));
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap_or_else(|e| panic!("{what}: {e}"));
    assert_eq!(lines.classes.len(), topology.edges.len());
    // A welded vertex is named by its lowest input vertex (after renaming).
    let mut name = vec![u32::MAX; topology.welded_positions.len()];
    for (v, &w) in topology.welded_of_vertex.iter().enumerate() {
        name[w as usize] = name[w as usize].min(rename(v as u32));
    }
    let key = |e: u32| {
        let [a, b] = topology.edges[e as usize].map(|w| name[w as usize]);
        (a.min(b), a.max(b))
    };
    let mut classes: Vec<_> =
        (0..topology.edges.len() as u32).map(|e| (key(e), lines.classes[e as usize].code())).collect();
    classes.sort_unstable();
    let brute = BruteForce::new(&lines.candidate_normals, &lines.candidate_points);
    let forced = SilhouetteOptions { min_candidates: 0, min_speedup: 0.0, ..SilhouetteOptions::default() };
    let index = SilhouetteIndex::build(&lines, &forced);
    let (mut a, mut b, mut c) = (EdgeSet::default(), EdgeSet::default(), EdgeSet::default());
    let mut silhouettes = Vec::new();
    for &view in views {
        brute.query_serial(view, &mut a);
        for v in a.iter() {
            assert!((v as usize) < lines.candidates.len(), "{what}: index out of range");
        }
        // Hierarchies (forced even where brute force would be stored) answer exactly.
        index.query(view, &mut b);
        index.brute_force().query_serial(view, &mut c);
        assert!(b == c, "{what}: hierarchy differs from brute force for {view:?}");
        let mut keys: Vec<_> = a.iter().map(|i| key(lines.candidates[i as usize])).collect();
        keys.sort_unstable();
        let mut via_index: Vec<_> = index.edge_ids(&b).map(key).collect();
        via_index.sort_unstable();
        assert_eq!(keys, via_index, "{what}: index numbering");
        silhouettes.push(keys);
    }
    let normals = lines.candidates.iter().zip(&lines.candidate_normals).map(|(&e, &n)| (key(e), n)).collect();
    let dihedral = (0..topology.edges.len() as u32).map(|e| (key(e), lines.dihedral_deg[e as usize])).collect();
    LinesOut { classes, silhouettes, normals, dihedral }
}

fn assert_same_silhouettes(base: &LinesOut, other: &LinesOut, directions: &[DVec3], what: &str) {
    // Classes are identical, except that a flat edge (coplanar, ≤ 0.001°) may become a silhouette
    // candidate or back when f32 rounding of the moved vertices tilts it by more than that.
    assert_eq!(base.classes.len(), other.classes.len(), "{what}: edge count changed");
    let (candidate, coplanar) = (EdgeClass::SilhouetteCandidate.code(), EdgeClass::Coplanar.code());
    for (&(ka, a), &(kb, b)) in base.classes.iter().zip(&other.classes) {
        assert_eq!(ka, kb, "{what}: edges differ");
        let crease = EdgeClass::Crease.code();
        let flat_flip = [a, b] == [candidate, coplanar] || [a, b] == [coplanar, candidate];
        let crease_flip = [a, b] == [candidate, crease] || [a, b] == [crease, candidate];
        let dihedral = base.dihedral[&ka].max(other.dihedral[&kb]);
        let at_threshold = (dihedral - drafter_lines::DEFAULT_CREASE_ANGLE_DEG).abs() < THRESHOLD_FLIP_DEG;
        assert!(
            a == b || flat_flip && dihedral < FLAT_FLIP_DEG || crease_flip && at_threshold,
            "{what}: edge {ka:?} class {a} -> {b} at dihedral {dihedral}°"
        );
    }
    for (k, (a, b)) in base.silhouettes.iter().zip(&other.silhouettes).enumerate() {
        let only: Vec<_> = a
            .iter()
            .filter(|e| b.binary_search(e).is_err())
            .chain(b.iter().filter(|e| a.binary_search(e).is_err()))
            .collect();
        for e in only {
            let [n1, n2] = base.normals[e];
            let w = directions[k];
            let tie = (n1.as_dvec3().dot(w)).abs().min((n2.as_dvec3().dot(w)).abs());
            assert!(tie < TIE_EPS, "{what}: view {k}: edge {e:?} changed silhouette state {tie:e} away from a tie");
        }
    }
}

fn ortho_views(directions: &[DVec3], rotation: DQuat) -> Vec<View> {
    directions.iter().map(|&d| View::Orthographic { direction: (rotation * d).as_vec3() }).collect()
}

#[test]
fn lines_of_generated_shapes_are_stable_exact_and_deterministic() {
    let mut rng = Rng::new(1999);
    let directions: Vec<DVec3> = (0..48).map(|_| rng.direction()).collect();
    for case in cases() {
        let id = |v: u32| v;
        let base = lines_of(&case.mesh, &ortho_views(&directions, DQuat::IDENTITY), &id, case.name);
        let again = lines_of(&case.mesh, &ortho_views(&directions, DQuat::IDENTITY), &id, case.name);
        assert!(
            base.classes == again.classes && base.silhouettes == again.silhouettes,
            "{}: not deterministic",
            case.name
        );
        // Perspective views from eyes around the shape: hierarchy = brute force (asserted inside).
        let eyes: Vec<View> = (0..24).map(|_| View::Perspective { eye: (rng.direction() * 3.0).as_vec3() }).collect();
        lines_of(&case.mesh, &eyes, &id, case.name);
        for k in 0..if case.f32_rotation { 3 } else { 0 } {
            let q = rng.rotation();
            let what = format!("{} rotated #{k}", case.name);
            let moved =
                lines_of(&case.mesh.transformed(&DMat4::from_quat(q)), &ortho_views(&directions, q), &id, &what);
            assert_same_silhouettes(&base, &moved, &directions, &what);
        }
        let (re, new_vertex, _) = case.mesh.reindexed(&mut rng);
        let mut old_vertex = vec![0u32; new_vertex.len()];
        for (old, &new) in new_vertex.iter().enumerate() {
            old_vertex[new as usize] = old as u32;
        }
        let what = format!("{} re-indexed", case.name);
        let moved = lines_of(&re, &ortho_views(&directions, DQuat::IDENTITY), &|v| old_vertex[v as usize], &what);
        assert_same_silhouettes(&base, &moved, &directions, &what);
    }
}

#[test]
fn segmentation_of_generated_shapes_is_stable_and_deterministic() {
    let mut rng = Rng::new(77);
    for case in cases() {
        let parts = |m: &TriMesh| {
            let (parts, _) = segment(&m.to_scene(case.name), &SegmentOptions::default());
            let mut sizes: Vec<u32> = parts.parts.iter().map(|p| p.triangles).collect();
            sizes.sort_unstable();
            assert_eq!(
                sizes.iter().map(|&s| s as usize).sum::<usize>(),
                m.triangles.len(),
                "{}: triangles lost",
                case.name
            );
            sizes
        };
        let base = parts(&case.mesh);
        assert_eq!(base, parts(&case.mesh), "{}: not deterministic", case.name);
        let rotated = case.mesh.transformed(&DMat4::from_quat(rng.rotation()));
        assert_eq!(base, parts(&rotated), "{}: parts changed under rotation", case.name);
        let (re, _, _) = case.mesh.reindexed(&mut rng);
        assert_eq!(base, parts(&re), "{}: parts changed under re-indexing", case.name);
    }
}

fn samples_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../samples")
}

/// Every part of the sample CAD files (committed in `samples/`), under random rotations: boxes,
/// normals, classes and silhouettes as above.
#[test]
fn sample_cad_parts_under_random_rotations() {
    let mut rng = Rng::new(42);
    let files = ["assembly.glb", "bracket.glb", "gear.glb", "shaft.glb"];
    let mut parts_seen = 0;
    for file in files {
        let path = samples_dir().join(file);
        let imported = drafter_io::import(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let scene = imported.scene;
        let (parts, _) = segment(&scene, &SegmentOptions::default());
        assert!(!parts.is_empty(), "{file}: no parts");
        for p in 0..parts.len() {
            let points = drafter_bake::part_points(&scene, &parts, PartId::from(p));
            let what = format!("{file} part {p}");
            let diag = diagonal(&points);
            let base = boxes(&points, &what);
            for k in 0..4 {
                let m = DMat4::from_quat(rng.rotation());
                let w = format!("{what} rotated #{k}");
                assert_stable_boxes(&boxes(&rotate(&points, &m), &w), &base, diag, &w);
            }
            parts_seen += 1;
        }
        // Meshes: normals follow a rotation; classes and silhouettes are unchanged.
        let directions: Vec<DVec3> = (0..24).map(|_| rng.direction()).collect();
        for (m, mesh) in scene.meshes.iter().enumerate() {
            let tri = TriMesh { positions: mesh.positions.clone(), triangles: mesh.triangles.clone() };
            let what = format!("{file} mesh {m}");
            let q = rng.rotation();
            let moved = tri.transformed(&DMat4::from_quat(q));
            let (a, b) = (normals_of(&tri, &what), normals_of(&moved, &what));
            assert_normals_follow(&a.plain, &b.plain, q, |t, c| (t, c), &what);
            assert_normals_follow(&a.enhanced, &b.enhanced, q, |t, c| (t, c), &what);
            let id = |v: u32| v;
            let base = lines_of(&tri, &ortho_views(&directions, DQuat::IDENTITY), &id, &what);
            let other = lines_of(&moved, &ortho_views(&directions, q), &id, &what);
            assert_same_silhouettes(&base, &other, &directions, &what);
        }
    }
    assert!(parts_seen >= 8, "only {parts_seen} sample parts: is samples/ complete?");
}

/// Finding of this suite (drafter-normals), fixed: across a non-manifold edge the filter
/// used to average every wing, and evenly spread wings sum to about zero, so the low-pass normal
/// (and with it the enhanced normal) pointed wherever rounding sent it: a rotation moved the
/// enhanced normals of a 3-wing fan by 11–22°. A non-manifold edge now bounds the filter.
#[test]
fn enhanced_normals_of_a_nonmanifold_fan_follow_a_rotation() {
    let mut rng = Rng::new(2005);
    for wings in [3, 6] {
        let mesh = generate::nonmanifold_fan(wings);
        let base = normals_of(&mesh, "fan");
        let q = rng.rotation();
        let moved = normals_of(&mesh.transformed(&DMat4::from_quat(q)), "fan rotated");
        assert_normals_follow(&base.enhanced, &moved.enhanced, q, |t, c| (t, c), &format!("{wings}-wing fan"));
    }
}
