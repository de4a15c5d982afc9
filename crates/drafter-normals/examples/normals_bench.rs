//! Throughput of the normals stage: face-iterations per second per core of the low-pass filter, and
//! the time of every other step, on a model file or on a generated ~1M-triangle bumpy sphere.
//!
//! ```text
//! cargo run --release -p drafter-normals --example normals_bench -- [MODEL] [--iterations N] [--repeat R]
//! ```
//! The filter is timed on a 1-thread pool (the per-core figure) and on the global pool (all cores), so
//! the parallel scaling is measured in the same run; CPU seconds are printed beside wall seconds because
//! the machines are shared and a loaded machine stretches wall time.

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::PathBuf;
use std::time::Instant;

use drafter_core::{Mesh, Topology, Weld};
use drafter_normals::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut path: Option<PathBuf> = None;
    let mut iterations = DEFAULT_ITERATIONS;
    let mut repeat = 3;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--iterations" => iterations = args.next().ok_or("--iterations N")?.parse()?,
            "--repeat" => repeat = args.next().ok_or("--repeat R")?.parse()?,
            _ => path = Some(PathBuf::from(arg)),
        }
    }
    let mesh = match &path {
        Some(path) => load_largest_mesh(path)?,
        None => common::bumpy_sphere(708, 708, 0.002),
    };
    let threads = rayon::current_num_threads();
    println!(
        "mesh '{}': {} triangles, {} vertices; {threads} threads",
        mesh.name,
        mesh.triangles.len(),
        mesh.positions.len()
    );

    let t = Instant::now();
    let topology = Topology::build(&mesh, Weld::Exact);
    let topology_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let geometry = FaceGeometry::compute(&topology);
    let geometry_s = t.elapsed().as_secs_f64();
    println!("topology {:.3} s, face geometry {:.3} s", topology_s, geometry_s);

    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let faces = mesh.triangles.len() as f64;
    for neighborhood in [Neighborhood::Edge, Neighborhood::Vertex] {
        let t = Instant::now();
        let adjacency = FaceAdjacency::build(&topology, &geometry, neighborhood, Weighting::ScaleDependent);
        let adjacency_s = t.elapsed().as_secs_f64();
        // Best wall time and best CPU time (all threads) of `repeat` runs.
        let best = |f: &dyn Fn() -> Vec<glam::Vec3>| -> (f64, f64) {
            (0..repeat).fold((f64::INFINITY, f64::INFINITY), |(wall, cpu), _| {
                let (t, c) = (Instant::now(), common::cpu_seconds());
                std::hint::black_box(f());
                (wall.min(t.elapsed().as_secs_f64()), cpu.min(common::cpu_seconds() - c))
            })
        };
        let (single_s, single_cpu) = one.install(|| best(&|| low_pass(&adjacency, &geometry.normals, iterations)));
        let (all_s, all_cpu) = best(&|| low_pass(&adjacency, &geometry.normals, iterations));
        let work = faces * iterations as f64 / 1e6;
        println!(
            "{neighborhood:?}: adjacency {adjacency_s:.3} s ({:.1} neighbours/face); {iterations} iterations:",
            adjacency.entry_count() as f64 / faces
        );
        println!(
            "  1 thread: {single_s:.3} s wall = {:.1} M face-it/s/core; {single_cpu:.3} CPU-s = {:.1} M face-it per CPU-second",
            work / single_s,
            work / single_cpu
        );
        println!(
            "  {threads} threads: {all_s:.3} s wall = {:.1} M face-it/s ({:.1} per core, scaling {:.2}x); {all_cpu:.3} CPU-s = {:.1} M face-it per CPU-second",
            work / all_s,
            work / all_s / threads as f64,
            single_s / all_s,
            work / all_cpu
        );
    }

    let t = Instant::now();
    let layout = VertexLayout::build(&mesh, &topology, &geometry, &CreaseOptions::default());
    let layout_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    std::hint::black_box(layout.vertex_normals(&geometry.normals));
    let vertex_normals_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    std::hint::black_box(TessellationStats::measure(&topology));
    let stats_s = t.elapsed().as_secs_f64();
    println!(
        "crease layout {layout_s:.3} s ({} output vertices), vertex normals {vertex_normals_s:.3} s, tessellation stats {stats_s:.3} s (not part of the stage: the survey's figure)",
        layout.vertex_count()
    );
    let t = Instant::now();
    let options = NormalsOptions { enhance: EnhanceOptions { iterations, ..Default::default() }, ..Default::default() };
    let (result, _) = compute_normals(&mesh, &topology, &options);
    println!(
        "whole stage (filter, layout, 2x vertex normals; topology excluded): {:.3} s; {} output vertices ({} splits)",
        t.elapsed().as_secs_f64(),
        result.report.output_vertices,
        result.report.split_vertices
    );
    Ok(())
}

fn load_largest_mesh(path: &std::path::Path) -> Result<Mesh, Box<dyn std::error::Error>> {
    let imported = drafter_io::import(path)?;
    imported.scene.meshes.into_iter().max_by_key(|m| m.triangles.len()).ok_or_else(|| "no mesh in the file".into())
}
