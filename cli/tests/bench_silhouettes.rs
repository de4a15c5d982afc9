//! `drafter bench silhouettes`: the JSON has the promised fields, the hierarchy agrees with brute
//! force, and the per-view counts equal an independent world-space count (every instance
//! transformed into the world, its own topology, brute force with the world view).

#![allow(clippy::unwrap_used)]

mod common;

use std::path::Path;

use drafter_core::{Topology, Weld};
use drafter_lines::measure::icosa_directions;
use drafter_lines::{BruteForce, EdgeSet, LineOptions, View, classify_edges};

fn bench_json(args: &[&str]) -> serde_json::Value {
    let out = common::run(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Silhouette count of each view over every instance, each instance's mesh moved into the world.
fn world_counts(path: &Path, views: &[View]) -> Vec<usize> {
    let scene = drafter_io::import(path).unwrap().scene;
    let mut counts = vec![0; views.len()];
    for inst in &scene.instances {
        let mesh = &scene.meshes[inst.mesh.index()];
        let world: Vec<glam::Vec3> =
            mesh.positions.iter().map(|p| inst.world_from_object.transform_point3(p.as_dvec3()).as_vec3()).collect();
        let mut triangles = mesh.triangles.clone();
        if inst.flips_winding() {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        let topology = Topology::from_triangles(&world, &triangles, Weld::default());
        let Ok(lines) = classify_edges(&topology, None, &LineOptions::default()) else { continue };
        let brute = BruteForce::new(&lines.candidate_normals, &lines.candidate_points);
        let mut set = EdgeSet::default();
        for (c, &v) in counts.iter_mut().zip(views) {
            brute.query_serial(v, &mut set);
            *c += set.count();
        }
    }
    counts
}

#[test]
fn icosa_views_on_a_single_mesh() {
    let path = common::shared_models().join("obj/common-3d-test-models/fandisk.obj");
    let r = bench_json(&["bench", "silhouettes", path.to_str().unwrap(), "--views", "icosa", "--json"]);
    for key in ["edges", "candidates", "views", "brute_ns_per_view", "hierarchy_ns_per_view", "speedup", "mismatches"] {
        assert!(r.get(key).is_some(), "missing {key}");
    }
    assert_eq!(r["views"], 20);
    assert_eq!(r["mismatches"], 0);
    assert_eq!(r["edges"], 19419);
    let counts: Vec<usize> = r["counts"].as_array().unwrap().iter().map(|c| c.as_u64().unwrap() as usize).collect();
    let views: Vec<View> = icosa_directions().into_iter().map(|direction| View::Orthographic { direction }).collect();
    assert_eq!(counts, world_counts(&path, &views));
    // Fandisk is big enough for a Gauss map.
    assert_eq!(r["meshes"][0]["choice"]["kind"], "gauss_map");
}

#[test]
fn instanced_assembly_counts_match_the_world() {
    // The sample assembly instances its parts with rotations and a mirrored node.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb");
    let r = bench_json(&["bench", "silhouettes", path.to_str().unwrap(), "--views", "icosa", "--json"]);
    assert_eq!(r["mismatches"], 0);
    let counts: Vec<usize> = r["counts"].as_array().unwrap().iter().map(|c| c.as_u64().unwrap() as usize).collect();
    let views: Vec<View> = icosa_directions().into_iter().map(|direction| View::Orthographic { direction }).collect();
    // Object space against world space: the same geometry, but rotated normals round differently.
    // The symmetric sample seen along a cube diagonal has faces exactly edge-on (ties), which may
    // fall either way; anything beyond that is a transform bug (a wrong or missing instance
    // shifts counts by tens).
    let world = world_counts(&path, &views);
    for (k, (&a, &b)) in counts.iter().zip(&world).enumerate() {
        assert!(a.abs_diff(b) <= 2, "view {k}: bench {a}, world {b}");
    }
    assert!(counts.iter().all(|&c| c > 0));
}

/// A baked file is measured as a reader loads it: its stored candidates and hierarchies (both
/// orders derived at load), which answer as brute force over the same decoded data.
#[test]
fn a_baked_file_is_measured_with_its_stored_hierarchies() {
    let dir = common::scratch("bench-silhouettes-stored");
    let baked = dir.join("fandisk.glb");
    common::bake(&common::shared_models().join("obj/common-3d-test-models/fandisk.obj"), &baked, &[]);
    let file = baked.to_str().unwrap();
    for mode in [&[][..], &["--perspective"][..]] {
        let mut args = vec!["bench", "silhouettes", file, "--views", "300", "--json"];
        args.extend_from_slice(mode);
        let r = bench_json(&args);
        assert_eq!(r["hierarchies"], "stored");
        assert_eq!(r["mismatches"], 0);
        let kind = if mode.is_empty() { "gauss_map" } else { "cone_bvh" };
        assert_eq!(r["meshes"][0]["choice"]["kind"], kind, "{mode:?}");
    }
    let r = bench_json(&["bench", "silhouettes", file, "--views", "50", "--rebuild", "--json"]);
    assert_eq!(r["hierarchies"], "built");
    assert_eq!(r["mismatches"], 0);
}

#[test]
fn perspective_agrees_with_brute_force() {
    let path = common::shared_models().join("obj/v-hacd/crank.off");
    let r = bench_json(&["bench", "silhouettes", path.to_str().unwrap(), "--views", "200", "--perspective", "--json"]);
    assert_eq!(r["mode"], "perspective");
    assert_eq!(r["views"], 200);
    assert_eq!(r["mismatches"], 0);
    assert_eq!(r["counts"].as_array().unwrap().len(), 200);
}

#[test]
fn bad_arguments_are_bad_input() {
    let path = common::shared_models().join("obj/common-3d-test-models/fandisk.obj");
    let out = common::run(&["bench", "silhouettes", path.to_str().unwrap(), "--views", "icosa", "--perspective"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    let out = common::run(&["bench", "silhouettes", "no/such/file.obj"]);
    assert_eq!(out.status.code(), Some(2));
}
