//! Hierarchy answers equal brute-force answers exactly, over thousands of random and adversarial
//! views on generated meshes (a fine UV sphere, a noisy sphere, an unwelded CAD-like plate, random
//! lattice soups and random blobs), for several hierarchy configurations.

// Helpers outside #[test] functions unwrap too: this whole file is test code.
#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use drafter_core::{Topology, Weld};
use drafter_lines::*;
use glam::Vec3;

struct Indexed {
    mesh: TestMesh,
    lines: FeatureEdges,
    index: SilhouetteIndex,
}

/// Options that always store both hierarchies, whatever they cost.
fn forced(gauss: GaussMapOptions, bvh: ConeBvhOptions) -> SilhouetteOptions {
    SilhouetteOptions { min_candidates: 0, min_speedup: 0.0, gauss, bvh, ..Default::default() }
}

fn index(mesh: TestMesh, options: &SilhouetteOptions) -> Indexed {
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let index = SilhouetteIndex::build(&lines, options);
    Indexed { mesh, lines, index }
}

/// Random and adversarial views: uniform directions, axis and lattice directions, directions in
/// the plane of a candidate's normal (a = 0 up to rounding), eyes outside, inside, on a face plane,
/// on a vertex and far away.
fn views(x: &Indexed, rng: &mut Rng, ortho: usize, perspective: usize) -> Vec<View> {
    let (lo, hi) = bounds(&x.mesh.positions);
    let n = x.lines.candidates.len() as u32;
    let mut out = Vec::with_capacity(ortho + perspective);
    for k in 0..ortho {
        let direction = match k % 6 {
            0 | 1 => rng.direction_f32(),
            2 => Vec3::new(rng.below(5) as f32 - 2.0, rng.below(5) as f32 - 2.0, rng.below(5) as f32 - 2.0),
            3 if n > 0 => {
                let [n1, n2] = x.lines.candidate_normals[rng.below(u64::from(n)) as usize];
                n1.cross(n2)
            }
            4 if n > 0 => {
                let [n1, _] = x.lines.candidate_normals[rng.below(u64::from(n)) as usize];
                n1.cross(rng.direction_f32())
            }
            _ => rng.direction_f32() * rng.range_f32(1e-3, 1e3),
        };
        out.push(View::Orthographic { direction });
    }
    for k in 0..perspective {
        let eye = match k % 8 {
            0..=2 => eye_outside(rng, lo, hi),
            3 | 4 => eye_inside(rng, lo, hi),
            5 if n > 0 => {
                // On the plane of a candidate's first face.
                let c = rng.below(u64::from(n)) as usize;
                let [n1, _] = x.lines.candidate_normals[c];
                let t = n1.cross(rng.direction_f32()).normalize_or_zero();
                x.lines.candidate_points[c] + t * rng.range_f32(0.0, 2.0) * (hi - lo).length()
            }
            6 => x.mesh.positions[rng.index(x.mesh.positions.len())],
            _ => (lo + hi) * 0.5 + rng.direction_f32() * (hi - lo).length() * 1e3,
        };
        out.push(View::Perspective { eye });
    }
    out
}

/// Brute force vs each stored hierarchy; returns the number of views checked.
fn check(x: &Indexed, views: &[View]) -> usize {
    let brute = x.index.brute_force();
    let (mut expected, mut got) = (EdgeSet::default(), EdgeSet::default());
    for &view in views {
        brute.query_serial(view, &mut expected);
        match view {
            View::Orthographic { direction } => {
                let g = x.index.gauss_map().expect("a Gauss map is stored");
                g.query(direction, &mut got);
            }
            View::Perspective { eye } => {
                let b = x.index.cone_bvh().expect("a cone BVH is stored");
                b.query(eye, &mut got);
            }
        }
        assert_eq!(
            expected,
            got,
            "{}: {view:?}: {} silhouettes by brute force, {} by the hierarchy, differing candidates {:?}",
            x.mesh.name,
            expected.count(),
            got.count(),
            &expected.symmetric_difference(&got)[..expected.symmetric_difference(&got).len().min(10)]
        );
        // The index answers the same through its own dispatch.
        x.index.query(view, &mut got);
        assert_eq!(expected, got);
    }
    views.len()
}

#[test]
fn fine_sphere_matches_brute_force() {
    let x = index(uv_sphere(128, 80), &forced(Default::default(), Default::default()));
    assert!(x.mesh.triangles.len() >= 20_000);
    // Quads of a UV sphere are planar trapezoids: their diagonals are coplanar, every other edge
    // is a candidate.
    let c = x.lines.counts;
    assert_eq!(c.silhouette_candidate + c.coplanar, x.lines.classes.len());
    assert_eq!(c.coplanar, 128 * 78);
    let mut rng = Rng::new(1);
    let checked = check(&x, &views(&x, &mut rng, 2000, 1500));
    assert_eq!(checked, 3500);
}

#[test]
fn noisy_sphere_matches_brute_force() {
    let x = index(noisy_sphere(96, 60, 0.01, 5), &forced(Default::default(), Default::default()));
    let mut rng = Rng::new(2);
    check(&x, &views(&x, &mut rng, 1500, 1500));
}

#[test]
fn cad_plate_matches_brute_force() {
    let x = index(plate_with_holes(24, 24), &forced(Default::default(), Default::default()));
    assert!(x.lines.counts.crease > 0 && x.lines.counts.coplanar > 0 && x.lines.counts.boundary > 0);
    assert!(x.lines.candidates.len() > 1000);
    let mut rng = Rng::new(3);
    check(&x, &views(&x, &mut rng, 1000, 1000));
}

#[test]
fn random_meshes_match_brute_force() {
    let mut total = 0;
    for seed in 0..20 {
        let x = index(random_lattice_mesh(30, 120, seed), &forced(Default::default(), Default::default()));
        let mut rng = Rng::new(100 + seed);
        total += check(&x, &views(&x, &mut rng, 50, 50));
    }
    for seed in 0..5 {
        let x = index(random_blob(seed), &forced(Default::default(), Default::default()));
        let mut rng = Rng::new(200 + seed);
        total += check(&x, &views(&x, &mut rng, 150, 150));
    }
    assert_eq!(total, 3500);
}

/// Other bases, bins, depths and no pruning: the answers never change.
#[test]
fn hierarchy_variants_match_brute_force() {
    let variants = [
        GaussMapOptions { base: BaseSolid::Octahedron, ..Default::default() },
        GaussMapOptions { bins: Bins::Strict, ..Default::default() },
        GaussMapOptions { prune: false, max_depth: Some(6), ..Default::default() },
        GaussMapOptions { bins: Bins::Overlapping { factor: 3.0 }, max_depth: Some(2), ..Default::default() },
    ];
    let bvhs = [
        ConeBvhOptions { leaf_size: 1, prune: false, ..Default::default() },
        ConeBvhOptions { leaf_size: 64, ..Default::default() },
        ConeBvhOptions { sample_eyes: 0, ..Default::default() },
        ConeBvhOptions { leaf_size: 4, ..Default::default() },
    ];
    for (k, (g, b)) in variants.into_iter().zip(bvhs).enumerate() {
        for mesh in [noisy_sphere(48, 30, 0.02, 9), plate_with_holes(9, 12)] {
            let x = index(mesh, &forced(g, b));
            let mut rng = Rng::new(300 + k as u64);
            check(&x, &views(&x, &mut rng, 200, 200));
        }
    }
}

/// Per-level histogram (Gooch Table 2): every arc stored once; overlapping bins push arcs deeper
/// than strict bins.
#[test]
fn histogram_counts_every_arc_and_overlap_goes_deeper() {
    let mesh = uv_sphere(128, 80);
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let cost = CostModel::default();
    let mean_level = |h: &LevelHistogram| {
        let total: usize = h.root.arcs + h.levels.iter().map(|l| l.arcs).sum::<usize>();
        assert_eq!(total, lines.candidates.len());
        h.levels.iter().enumerate().map(|(k, l)| (k + 1) as f64 * l.arcs as f64).sum::<f64>() / total as f64
    };
    let strict = GaussMapHierarchy::build(
        &lines.candidate_normals,
        &GaussMapOptions { bins: Bins::Strict, max_depth: Some(4), prune: false, ..Default::default() },
        &cost,
    );
    let overlap = GaussMapHierarchy::build(
        &lines.candidate_normals,
        &GaussMapOptions { max_depth: Some(4), prune: false, ..Default::default() },
        &cost,
    );
    let (s, o) = (strict.assigned_histogram().unwrap(), overlap.assigned_histogram().unwrap());
    assert!(mean_level(o) > mean_level(s));
    // On a fine sphere with overlapping bins nearly every arc reaches the deepest level (as in the
    // paper's sphere, where all did).
    assert!(o.levels[4].arcs as f64 > 0.95 * lines.candidates.len() as f64, "{o:?}");
    assert_eq!(mean_level(&overlap.histogram()), mean_level(o));
}

#[test]
fn choices_follow_size() {
    let small = index(random_blob(1), &SilhouetteOptions::default());
    assert!(matches!(
        small.index.orthographic_choice(),
        HierarchyChoice::BruteForce(BruteForceReason::TooFewCandidates { .. })
    ));
    assert!(small.index.gauss_map().is_none() && small.index.cone_bvh().is_none());
    let sphere = index(uv_sphere(128, 80), &SilhouetteOptions::default());
    assert!(matches!(sphere.index.orthographic_choice(), HierarchyChoice::GaussMap { .. }));
    assert!(sphere.index.gauss_map().is_some());
    let disabled =
        index(uv_sphere(64, 40), &SilhouetteOptions { orthographic: false, perspective: false, ..Default::default() });
    assert_eq!(disabled.index.perspective_choice(), HierarchyChoice::BruteForce(BruteForceReason::Disabled));
}

/// Arrays round-trip to an index that answers identically; tampered arrays are rejected.
#[test]
fn arrays_round_trip_and_validation() {
    let x = index(noisy_sphere(64, 40, 0.01, 4), &forced(Default::default(), Default::default()));
    let arrays = x.index.to_arrays();
    let loaded = SilhouetteIndex::from_arrays(&arrays).unwrap();
    let mut rng = Rng::new(77);
    let (mut a, mut b) = (EdgeSet::default(), EdgeSet::default());
    for view in views(&x, &mut rng, 100, 100) {
        x.index.query(view, &mut a);
        loaded.query(view, &mut b);
        assert_eq!(a, b);
    }
    let json = serde_json_like(&arrays);
    assert!(json > 0);
    // A baked file stores no node counts (its reader passes zeros): the loaded index reports those
    // of the hierarchies it loaded, the built ones, and keeps the given (absent) prediction.
    let as_read = SilhouetteArrays {
        orthographic: HierarchyChoice::GaussMap { max_depth: 0, nodes: 0, predicted_speedup: 0.0 },
        perspective: HierarchyChoice::ConeBvh { leaf_size: 0, nodes: 0, predicted_speedup: 0.0 },
        ..arrays.clone()
    };
    let reread = SilhouetteIndex::from_arrays(&as_read).unwrap();
    let unpredicted = |c: HierarchyChoice| match c {
        HierarchyChoice::GaussMap { max_depth, nodes, .. } => {
            HierarchyChoice::GaussMap { max_depth, nodes, predicted_speedup: 0.0 }
        }
        HierarchyChoice::ConeBvh { leaf_size, nodes, .. } => {
            HierarchyChoice::ConeBvh { leaf_size, nodes, predicted_speedup: 0.0 }
        }
        other => other,
    };
    assert_eq!(reread.orthographic_choice(), unpredicted(x.index.orthographic_choice()));
    assert_eq!(reread.perspective_choice(), unpredicted(x.index.perspective_choice()));
    assert!(matches!(reread.orthographic_choice(), HierarchyChoice::GaussMap { nodes, .. } if nodes > 1));
    assert!(
        matches!(reread.perspective_choice(), HierarchyChoice::ConeBvh { nodes, leaf_size, .. } if nodes > 1 && leaf_size > 0)
    );

    // A cap shrunk below its arcs.
    let mut bad = arrays.clone();
    let g = bad.gauss_map.as_mut().unwrap();
    let k = (0..g.node_caps.len() / 4).find(|&i| g.node_caps[4 * i + 3] < 1.0).unwrap();
    g.node_caps[4 * k + 3] *= 0.5;
    assert!(matches!(SilhouetteIndex::from_arrays(&bad), Err(ArraysError::NotConservative { .. })));
    // Stored own ranges that are not where the bin rule puts the arcs: an arc moved from a
    // node to the next one in storage order.
    let mut bad = arrays.clone();
    let g = bad.gauss_map.as_mut().unwrap();
    let k = (0..g.nodes.len() / 4 - 1).find(|&i| g.nodes[4 * i + 3] > g.nodes[4 * i + 2]).unwrap();
    g.nodes[4 * k + 3] -= 1;
    g.nodes[4 * (k + 1) + 2] -= 1;
    assert!(SilhouetteIndex::from_arrays(&bad).is_err());
    // A BVH split byte changed: the replay finds another tree, which the stored nodes and bounds
    // do not fit.
    let mut bad = arrays.clone();
    let b = bad.cone_bvh.as_mut().unwrap();
    b.splits[0] = if b.splits[0] == 0x21 { 0x22 } else { 0x21 };
    assert!(SilhouetteIndex::from_arrays(&bad).is_err());
    // A script cut short.
    let mut bad = arrays.clone();
    bad.cone_bvh.as_mut().unwrap().splits.pop();
    assert!(SilhouetteIndex::from_arrays(&bad).is_err());
    // A broken child range.
    let mut bad = arrays.clone();
    bad.gauss_map.as_mut().unwrap().nodes[0] = 5;
    assert!(matches!(SilhouetteIndex::from_arrays(&bad), Err(ArraysError::Tree { .. })));
    // A BVH box that misses its points.
    let mut bad = arrays.clone();
    let b = bad.cone_bvh.as_mut().unwrap();
    b.node_boxes[3] = b.node_boxes[0];
    assert!(SilhouetteIndex::from_arrays(&bad).is_err());
    // A BVH cone made too narrow.
    let mut bad = arrays.clone();
    let b = bad.cone_bvh.as_mut().unwrap();
    let k = (0..b.node_cones.len() / 4).find(|&i| b.node_cones[4 * i + 3] < 1.0).unwrap();
    b.node_cones[4 * k + 3] *= 0.5;
    assert!(matches!(SilhouetteIndex::from_arrays(&bad), Err(ArraysError::NotConservative { .. })));
    // Wrong lengths.
    let mut bad = arrays.clone();
    bad.candidate_normals.pop();
    assert!(matches!(SilhouetteIndex::from_arrays(&bad), Err(ArraysError::Length { .. })));
}

/// The hierarchies store no candidate order: an index built over candidates in some order (a
/// file keeps the Khronos encoding order) loads from its hierarchies and the candidates in that
/// same order to the same storage order, and the same answers, edge for edge.
#[test]
fn arrays_load_from_candidates_in_the_build_order() {
    let options = forced(Default::default(), Default::default());
    let x = index(noisy_sphere(48, 32, 0.01, 9), &options);
    let n = x.lines.candidates.len();
    // The build order: a fixed shuffle of the candidates.
    let mut rng = Rng::new(5);
    let mut perm: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        perm.swap(i, rng.index(i + 1));
    }
    let edges: Vec<u32> = perm.iter().map(|&k| x.lines.candidates[k]).collect();
    let normals: Vec<[Vec3; 2]> = perm.iter().map(|&k| x.lines.candidate_normals[k]).collect();
    let points: Vec<Vec3> = perm.iter().map(|&k| x.lines.candidate_points[k]).collect();
    let built = SilhouetteIndex::from_candidates(edges.clone(), normals.clone(), points.clone(), &options);
    // The cost model collapsed subtrees: their arcs are stored in input order, and the reader's
    // assignment stops at them.
    let g = built.gauss_map().unwrap();
    let assigned = g.assigned_histogram().unwrap();
    let assigned_nodes = assigned.root.nodes + assigned.levels.iter().map(|l| l.nodes).sum::<usize>();
    assert!(g.node_count() < assigned_nodes, "{} stored of {assigned_nodes} nodes", g.node_count());
    let stored = built.to_arrays();
    let file = SilhouetteArrays {
        candidate_edges: edges,
        candidate_normals: normals.iter().flat_map(|[a, b]| [a.x, a.y, a.z, b.x, b.y, b.z]).collect(),
        candidate_points: points.iter().flat_map(|p| p.to_array()).collect(),
        ..stored
    };
    let loaded = SilhouetteIndex::from_arrays(&file).unwrap();
    assert!(loaded.gauss_map().is_some() && loaded.cone_bvh().is_some());
    assert_eq!(loaded.candidate_edges(), built.candidate_edges(), "the same storage order is derived");
    let (mut a, mut b) = (EdgeSet::default(), EdgeSet::default());
    for view in views(&x, &mut rng, 200, 200) {
        built.query(view, &mut a);
        loaded.query(view, &mut b);
        assert_eq!(a, b);
    }
}

/// The arrays are plain vectors: their total size in bytes (stand-in for a writer).
fn serde_json_like(a: &SilhouetteArrays) -> usize {
    let g = a.gauss_map.as_ref().map_or(0, |g| 4 * (g.node_caps.len() + g.nodes.len()));
    let b = a.cone_bvh.as_ref().map_or(0, |b| {
        4 * (b.node_boxes.len() + b.node_cones.len() + b.nodes.len() + b.split_starts.len()) + b.splits.len()
    });
    4 * (a.candidate_edges.len() + a.candidate_normals.len() + a.candidate_points.len()) + g + b
}

/// Hierarchies used on their own (not through the index) answer in the input candidate order,
/// and `into_storage_order` gives the same answers renumbered.
#[test]
fn standalone_hierarchies_answer_in_input_order() {
    let mesh = noisy_sphere(64, 40, 0.02, 11);
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    let cost = CostModel::default();
    let brute = BruteForce::new(&lines.candidate_normals, &lines.candidate_points);
    let gauss = GaussMapHierarchy::build(&lines.candidate_normals, &GaussMapOptions::default(), &cost);
    let bvh = ConeBvh::build(&lines.candidate_normals, &lines.candidate_points, &ConeBvhOptions::default(), &cost);
    let (renumbered, permutation) = gauss.clone().into_storage_order();
    let mut rng = Rng::new(12);
    let (lo, hi) = bounds(&mesh.positions);
    let (mut a, mut b, mut c) = (EdgeSet::default(), EdgeSet::default(), EdgeSet::default());
    for _ in 0..300 {
        let d = rng.direction_f32();
        brute.query_serial(View::Orthographic { direction: d }, &mut a);
        gauss.query(d, &mut b);
        assert_eq!(a, b);
        renumbered.query(d, &mut c);
        let mut mapped: Vec<u32> = c.iter().map(|k| permutation[k as usize]).collect();
        mapped.sort_unstable();
        assert_eq!(mapped, a.to_vec());
        let e = eye_outside(&mut rng, lo, hi);
        brute.query_serial(View::Perspective { eye: e }, &mut a);
        bvh.query(e, &mut b);
        assert_eq!(a, b);
    }
}

/// Above 32k candidates the builds split their work over the thread pool (the Gauss map's cell
/// partitions, the cone BVH's dual-space subtrees and bins): the hierarchies must come out the
/// same on one thread and on several, and still answer as brute force.
#[test]
fn parallel_builds_equal_single_thread_builds() {
    let mesh = noisy_sphere(400, 200, 0.02, 5);
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
    assert!(lines.candidates.len() > 2 * 32 * 1024, "{} candidates: too few to split", lines.candidates.len());
    let options = forced(GaussMapOptions::default(), ConeBvhOptions::default());
    let build_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| SilhouetteIndex::build(&lines, &options).to_arrays())
    };
    let one = build_on(1);
    assert!(one.gauss_map.is_some() && one.cone_bvh.is_some());
    assert!(one == build_on(2), "2 threads built other hierarchies than 1");
    assert!(one == build_on(3), "3 threads built other hierarchies than 1");
    let x = Indexed { index: SilhouetteIndex::build(&lines, &options), lines, mesh };
    let mut rng = Rng::new(99);
    let v = views(&x, &mut rng, 300, 300);
    assert_eq!(check(&x, &v), 600, "every view checked against brute force");
}

/// A bake stores hierarchies built without their query layouts (arc blocks, candidate stream),
/// whose costs are predicted by walks that test no candidate: the arrays and the choices, with
/// their predicted speedups, must be exactly those of an index built for queries, under the
/// default options (hierarchies kept or refused by cost) and forced ones.
#[test]
fn stored_hierarchies_equal_the_arrays_of_a_built_index() {
    let meshes = [noisy_sphere(160, 80, 0.02, 3), plate_with_holes(24, 24), random_blob(2), uv_sphere(64, 32)];
    let mut stored_any = 0;
    for (m, mesh) in meshes.iter().enumerate() {
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        let lines = classify_edges(&topology, None, &LineOptions::default()).unwrap();
        for options in [SilhouetteOptions::default(), forced(Default::default(), Default::default())] {
            let built = SilhouetteIndex::build(&lines, &options).to_arrays();
            let stored = SilhouetteIndex::stored_hierarchies(
                lines.candidate_normals.clone(),
                lines.candidate_points.clone(),
                &options,
            );
            stored_any += usize::from(stored.gauss_map.is_some()) + usize::from(stored.cone_bvh.is_some());
            let expected = StoredHierarchies {
                gauss_map: built.gauss_map,
                cone_bvh: built.cone_bvh,
                orthographic: built.orthographic,
                perspective: built.perspective,
            };
            assert_eq!(stored, expected, "mesh {m}, {options:?}");
        }
    }
    assert!(stored_any >= 8, "only {stored_any} hierarchies stored");
}
