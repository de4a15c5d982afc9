//! How many vertices the 16-bit split (`drafter_bake::split`) writes twice, in the input's triangle
//! order and, for comparison, after sorting each primitive's triangles along a Morton curve of
//! their centroids (the reordering the bake does not do). At the real limit (65,535) and at smaller
//! ones, which stand in for larger meshes: a coherent triangle order duplicates little at any limit.
//!
//! `cargo run --release -p drafter-bake --example split_survey -- MODEL...`

use drafter_bake::split::split_mesh;
use drafter_core::Topology;
use drafter_format::VertexData;

mod common;

fn main() {
    let config = drafter_bake::BakeConfig::default();
    println!(
        "| model | limit | primitives split | chunks | vertices | duplicated (input order) | duplicated (Morton order) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (path, scene) in common::scenes_from_args() {
        // The layouts the bake's normal stage gives (what the split counts).
        let layouts: Vec<VertexData> = scene
            .meshes
            .iter()
            .map(|mesh| {
                let topology = Topology::build(mesh, config.segment.weld);
                let mut options = config.normals.options();
                options.crease.keep_input_seams = mesh.uvs.is_some();
                let (normals, _) = drafter_normals::compute_normals(mesh, &topology, &options);
                VertexData {
                    source_vertex: normals.layout.source_vertex.clone(),
                    triangles: normals.layout.triangles.clone(),
                    normals: Vec::new(),
                    enhanced: Vec::new(),
                }
            })
            .collect();
        let sorted: Vec<VertexData> =
            scene.meshes.iter().zip(&layouts).map(|(mesh, layout)| morton_sorted(mesh, layout)).collect();
        let name = std::path::Path::new(&path).file_name().map_or(path.clone(), |n| n.to_string_lossy().into_owned());
        for limit in [65_535u32, 16_384, 4_096] {
            let (mut split, mut chunks, mut vertices, mut dup, mut dup_sorted) = (0, 0, 0, 0, 0);
            for (m, mesh) in scene.meshes.iter().enumerate() {
                let (_, s) = split_mesh(mesh, Some(&layouts[m]), limit);
                let (_, t) = split_mesh(mesh, Some(&sorted[m]), limit);
                split += s.split_primitives;
                chunks += s.chunks;
                vertices += s.vertices;
                dup += s.duplicated_vertices;
                dup_sorted += t.duplicated_vertices;
            }
            let pct = |d: usize| if vertices == 0 { 0.0 } else { 100.0 * d as f64 / vertices as f64 };
            println!(
                "| {name} | {limit} | {split} | {chunks} | {vertices} | {dup} ({:.2} %) | {dup_sorted} ({:.2} %) |",
                pct(dup),
                pct(dup_sorted)
            );
        }
    }
}

/// `layout` with each group's triangles sorted by the Morton code of their centroids in the group's
/// bounding box (ties in input order).
fn morton_sorted(mesh: &drafter_core::Mesh, layout: &VertexData) -> VertexData {
    let mut out = layout.clone();
    for group in &mesh.groups {
        let range = group.start as usize..(group.start + group.count) as usize;
        let centroid = |t: usize| {
            let [a, b, c] = mesh.triangles[t];
            (mesh.positions[a as usize] + mesh.positions[b as usize] + mesh.positions[c as usize]) / 3.0
        };
        let (lo, hi) = range
            .clone()
            .map(centroid)
            .fold((glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        let extent = (hi - lo).max(glam::Vec3::splat(f32::MIN_POSITIVE));
        let mut order: Vec<(u64, usize)> = range
            .clone()
            .map(|t| {
                let q = ((centroid(t) - lo) / extent * 1_048_575.0).as_uvec3();
                (morton(q.x) | morton(q.y) << 1 | morton(q.z) << 2, t)
            })
            .collect();
        order.sort_unstable();
        for (slot, (_, t)) in range.zip(order) {
            out.triangles[slot] = layout.triangles[t];
        }
    }
    out
}

/// The bits of `v` (20 used) spread to every third bit.
fn morton(v: u32) -> u64 {
    let mut x = u64::from(v) & 0xF_FFFF;
    x = (x | x << 32) & 0x1F00000000FFFF;
    x = (x | x << 16) & 0x1F0000FF0000FF;
    x = (x | x << 8) & 0x100F00F00F00F00F;
    x = (x | x << 4) & 0x10C30C30C30C30C3;
    (x | x << 2) & 0x1249249249249249
}
