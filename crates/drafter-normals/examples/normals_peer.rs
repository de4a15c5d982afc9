//! Our side of the MeshLab comparison (bench/normals/compare_meshlab.py): reads a mesh, enhances its
//! face normals and writes them as little-endian f32 triples, one per input triangle, in input order.
//!
//! ```text
//! normals_peer INPUT --out FILE [--strength K] [--iterations N] [--weighting area|uniform|scale-dependent]
//!              [--neighborhood edge|vertex] [--repeat R]
//! ```
//! INPUT is a model file (read with drafter-io; its largest mesh is used) or a `.rawmesh` dump:
//! `u32 vertex_count, u32 triangle_count, f32 xyz × vertex_count, u32 abc × triangle_count` (LE).
//! Prints one JSON line with the timings (best of R runs): topology, filter (face geometry, adjacency,
//! low-pass, enhancement), their total, and the CPU time of that total summed over threads.

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::{Path, PathBuf};
use std::time::Instant;

use drafter_core::{Mesh, Topology, Weld};
use drafter_normals::*;
use glam::Vec3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut input: Option<PathBuf> = None;
    let mut out: Option<PathBuf> = None;
    let mut options = EnhanceOptions::default();
    let mut repeat = 1usize;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--out" => out = Some(PathBuf::from(value()?)),
            "--strength" => options.strength = value()?.parse()?,
            "--iterations" => options.iterations = value()?.parse()?,
            "--repeat" => repeat = value()?.parse()?,
            "--weighting" => {
                options.weighting = match value()?.as_str() {
                    "area" => Weighting::Area,
                    "uniform" => Weighting::Uniform,
                    "scale-dependent" => Weighting::ScaleDependent,
                    other => return Err(format!("unknown weighting {other}").into()),
                }
            }
            "--neighborhood" => {
                options.neighborhood = match value()?.as_str() {
                    "edge" => Neighborhood::Edge,
                    "vertex" => Neighborhood::Vertex,
                    other => return Err(format!("unknown neighborhood {other}").into()),
                }
            }
            _ => input = Some(PathBuf::from(arg)),
        }
    }
    let input = input.ok_or("usage: normals_peer INPUT --out FILE [options]")?;
    let mesh =
        if input.extension().is_some_and(|e| e == "rawmesh") { read_raw(&input)? } else { load_largest_mesh(&input)? };

    let mut best = (f64::INFINITY, f64::INFINITY);
    let mut best_cpu = f64::INFINITY;
    let mut enhanced = Vec::new();
    for _ in 0..repeat.max(1) {
        let cpu = common::cpu_seconds();
        let t = Instant::now();
        let topology = Topology::build(&mesh, Weld::Exact);
        let topology_s = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let faces = enhance_faces(&topology, &options);
        let filter_s = t.elapsed().as_secs_f64();
        best_cpu = best_cpu.min(common::cpu_seconds() - cpu);
        if std::env::var_os("NORMALS_PEER_BREAKDOWN").is_some() {
            // CPU seconds of each step, summed over threads.
            let c0 = common::cpu_seconds();
            let topology = Topology::build(&mesh, Weld::Exact);
            let c1 = common::cpu_seconds();
            let geometry = FaceGeometry::compute(&topology);
            let c2 = common::cpu_seconds();
            let adjacency = FaceAdjacency::build(&topology, &geometry, options.neighborhood, options.weighting);
            let c3 = common::cpu_seconds();
            let low = low_pass(&adjacency, &geometry.normals, options.iterations);
            let c4 = common::cpu_seconds();
            std::hint::black_box(enhance(&geometry.normals, &low, options.strength));
            let c5 = common::cpu_seconds();
            eprintln!(
                "CPU s: topology {:.4} geometry {:.4} adjacency {:.4} low-pass {:.4} enhance {:.4}",
                c1 - c0,
                c2 - c1,
                c3 - c2,
                c4 - c3,
                c5 - c4
            );
        }
        if topology_s + filter_s < best.0 + best.1 {
            best = (topology_s, filter_s);
        }
        enhanced = faces.enhanced;
    }
    if let Some(out) = out {
        write_normals(&out, &enhanced)?;
    }
    println!(
        "{{\"triangles\": {}, \"threads\": {}, \"topology_s\": {:.6}, \"filter_s\": {:.6}, \"total_s\": {:.6}, \"cpu_s\": {:.6}}}",
        mesh.triangles.len(),
        rayon::current_num_threads(),
        best.0,
        best.1,
        best.0 + best.1,
        best_cpu
    );
    Ok(())
}

fn load_largest_mesh(path: &Path) -> Result<Mesh, Box<dyn std::error::Error>> {
    let imported = drafter_io::import(path)?;
    imported.scene.meshes.into_iter().max_by_key(|m| m.triangles.len()).ok_or_else(|| "no mesh in the file".into())
}

fn read_raw(path: &Path) -> Result<Mesh, Box<dyn std::error::Error>> {
    let bytes = std::fs::read(path)?;
    let word = |i: usize| -> Result<[u8; 4], Box<dyn std::error::Error>> {
        Ok(bytes.get(4 * i..4 * i + 4).ok_or("truncated .rawmesh")?.try_into()?)
    };
    let vertex_count = u32::from_le_bytes(word(0)?) as usize;
    let triangle_count = u32::from_le_bytes(word(1)?) as usize;
    let mut positions = Vec::with_capacity(vertex_count);
    for v in 0..vertex_count {
        let c = |k: usize| -> Result<f32, Box<dyn std::error::Error>> { Ok(f32::from_le_bytes(word(2 + 3 * v + k)?)) };
        positions.push(Vec3::new(c(0)?, c(1)?, c(2)?));
    }
    let base = 2 + 3 * vertex_count;
    let mut triangles = Vec::with_capacity(triangle_count);
    for f in 0..triangle_count {
        let i =
            |k: usize| -> Result<u32, Box<dyn std::error::Error>> { Ok(u32::from_le_bytes(word(base + 3 * f + k)?)) };
        let tri = [i(0)?, i(1)?, i(2)?];
        if tri.iter().any(|&v| v as usize >= vertex_count) {
            return Err(format!("triangle {f} indexes past the {vertex_count} vertices").into());
        }
        triangles.push(tri);
    }
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    Ok(Mesh { name, positions, triangles, ..Default::default() })
}

fn write_normals(path: &Path, normals: &[Vec3]) -> std::io::Result<()> {
    let bytes: Vec<u8> = normals.iter().flat_map(|n| n.to_array()).flat_map(f32::to_le_bytes).collect();
    std::fs::write(path, bytes)
}
