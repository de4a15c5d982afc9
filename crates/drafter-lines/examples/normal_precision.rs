//! How many silhouettes change when the candidates' face normals are stored quantised, as
//! `EXT_mesh_primitive_edge_visibility`'s `silhouetteNormals` allows (VEC3 BYTE or SHORT normalized,
//! or FLOAT): the measurement behind the component type format 0.2 writes.
//!
//! ```text
//! cargo run --release -p drafter-lines --example normal_precision -- FILE... [--views N]
//! ```
//!
//! For every model and random view (orthographic directions, eyes outside the box), the reference
//! is the predicate on the full-precision f32 face normals; each quantisation is the same predicate
//! on the dequantised normals (`max(c / (2^(b-1) - 1), -1)`, as glTF defines normalized integers).
//! Printed per type: bytes per candidate, mean true silhouettes per view, mean edges that differ per
//! view and that as a share of the true silhouettes, the worst view's share, and how far from
//! tangent an edge that differs can be: the largest, over such edges, of the smaller angle between
//! one of its two (true) face planes and the view direction. "BYTE nearest" is what the bake
//! writes (`drafter_core::snorm8_encode_direction`), "BYTE" per-axis rounding.

#[path = "../tests/common/mod.rs"]
mod common;

use common::*;
use drafter_core::{Topology, Weld};
use drafter_lines::*;
use glam::Vec3;

fn quantize(n: Vec3, max: f32) -> Vec3 {
    let q = |x: f32| ((x * max).round().clamp(-max, max) / max).max(-1.0);
    Vec3::new(q(n.x), q(n.y), q(n.z))
}

fn main() {
    let mut files = Vec::new();
    let mut views = 500usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--views" {
            views = args.next().and_then(|v| v.parse().ok()).expect("--views N");
        } else {
            files.push(a);
        }
    }
    println!(
        "| model | candidates | view | type | bytes/candidate | silhouettes/view | differ/view | share | worst view | differing edges within |"
    );
    println!("|---|---:|---|---|---:|---:|---:|---:|---:|---:|");
    for file in &files {
        let (mesh, parts) = match load_model(std::path::Path::new(file)) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{e}");
                continue;
            }
        };
        let topology = Topology::from_triangles(&mesh.positions, &mesh.triangles, Weld::Exact);
        let Ok(lines) = classify_edges(&topology, Some(&parts), &LineOptions::default()) else { continue };
        let reference = &lines.candidate_normals;
        let points = &lines.candidate_points;
        let (lo, hi) = bounds(&mesh.positions);
        let mut rng = Rng::new(7);
        let ortho: Vec<Vec3> = (0..views).map(|_| rng.direction_f32()).collect();
        let eyes: Vec<Vec3> = (0..views).map(|_| eye_outside(&mut rng, lo, hi)).collect();
        for (name, bytes, max) in
            [("BYTE nearest", 6, -1.0f32), ("BYTE", 6, 127.0), ("SHORT", 12, 32767.0), ("FLOAT", 24, 0.0)]
        {
            let quantized: Vec<[Vec3; 2]> = reference
                .iter()
                .map(|&[a, b]| match max {
                    m if m < 0.0 => {
                        [a, b].map(|n| drafter_core::snorm8_decode(drafter_core::snorm8_encode_direction(n)))
                    }
                    m if m > 0.0 => [quantize(a, m), quantize(b, m)],
                    _ => [a, b],
                })
                .collect();
            for (mode, count) in [("ortho", ortho.len()), ("persp", eyes.len())] {
                let (mut truth, mut differ, mut worst, mut within) = (0usize, 0usize, 0f64, 0f64);
                for v in 0..count {
                    let (mut t, mut d) = (0usize, 0usize);
                    for c in 0..reference.len() {
                        let ([r1, r2], [q1, q2]) = (reference[c], quantized[c]);
                        let (a, b, w) = if mode == "ortho" {
                            let u = ortho[v];
                            (is_silhouette_orthographic(r1, r2, u), is_silhouette_orthographic(q1, q2, u), u)
                        } else {
                            let e = eyes[v];
                            let p = points[c];
                            (is_silhouette_perspective(r1, r2, p, e), is_silhouette_perspective(q1, q2, p, e), e - p)
                        };
                        t += usize::from(a);
                        d += usize::from(a != b);
                        if a != b {
                            let w = w.normalize_or_zero().as_dvec3();
                            let off =
                                |n: Vec3| n.as_dvec3().normalize_or_zero().dot(w).abs().min(1.0).asin().to_degrees();
                            within = within.max(off(r1).min(off(r2)));
                        }
                    }
                    truth += t;
                    differ += d;
                    worst = worst.max(d as f64 / t.max(1) as f64);
                }
                let n = count.max(1) as f64;
                println!(
                    "| {} | {} | {mode} | {name} | {bytes} | {:.1} | {:.2} | {:.3}% | {:.3}% | {:.3}° |",
                    mesh.name,
                    reference.len(),
                    truth as f64 / n,
                    differ as f64 / n,
                    100.0 * differ as f64 / truth.max(1) as f64,
                    100.0 * worst,
                    within
                );
            }
        }
    }
}
