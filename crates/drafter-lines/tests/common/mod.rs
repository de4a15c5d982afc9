//! Generated meshes and views shared by the integration tests and the `silhouette_bench` example
//! (which includes this file with `#[path]`).

#![allow(dead_code)]

use std::f32::consts::{PI, TAU};

use glam::Vec3;

/// A triangle mesh as plain arrays.
#[derive(Clone, Debug, Default)]
pub struct TestMesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// The seeded generator of the tests' views and meshes: the workspace's one.
pub use drafter_core::rng::Rng;

/// A UV sphere of radius 1: `segments` around, `rings` from pole to pole; 2·segments·(rings−1) faces.
pub fn uv_sphere(segments: u32, rings: u32) -> TestMesh {
    noisy_sphere(segments, rings, 0.0, 0)
}

/// A UV sphere whose vertices move radially by up to `amplitude` (a scan-like surface).
pub fn noisy_sphere(segments: u32, rings: u32, amplitude: f32, seed: u64) -> TestMesh {
    let mut rng = Rng::new(seed);
    let mut positions = vec![Vec3::Z];
    for r in 1..rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = TAU * s as f32 / segments as f32;
            let radius = 1.0 + amplitude * rng.range_f32(-1.0, 1.0);
            positions.push(radius * Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    positions.push(Vec3::NEG_Z);
    let south = positions.len() as u32 - 1;
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, ring(1, s), ring(1, s + 1)]);
        triangles.push([south, ring(rings - 1, s + 1), ring(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    let name = if amplitude > 0.0 { "noisy sphere" } else { "uv sphere" };
    TestMesh { name: name.into(), positions, triangles }
}

/// A CAD-like part exported the CAD way (every face its own patch, nothing welded): a plate
/// with square through-holes on a grid, and round bosses (faceted cylinders with caps) on top.
pub fn plate_with_holes(cells: u32, boss_segments: u32) -> TestMesh {
    let mut m = TestMesh { name: "plate with holes".into(), ..Default::default() };
    let size = 1.0 / cells as f32;
    let hole = |i: u32, j: u32| i % 3 == 1 && j % 3 == 1;
    let (z0, z1) = (0.0f32, 0.2f32);
    // Top and bottom: one quad per non-hole cell, one patch per face.
    for (z, up) in [(z1, true), (z0, false)] {
        let base = m.positions.len() as u32;
        for j in 0..=cells {
            for i in 0..=cells {
                m.positions.push(Vec3::new(i as f32 * size, j as f32 * size, z));
            }
        }
        let at = |i: u32, j: u32| base + j * (cells + 1) + i;
        for j in 0..cells {
            for i in 0..cells {
                if hole(i, j) {
                    continue;
                }
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                if up {
                    m.triangles.extend([[a, b, c], [a, c, d]]);
                } else {
                    m.triangles.extend([[a, c, b], [a, d, c]]);
                }
            }
        }
    }
    // Walls: outer boundary and hole sides, each as its own quad patch facing outwards of the solid.
    let wall = |m: &mut TestMesh, p: Vec3, q: Vec3| {
        // Quad from p to q (bottom), extruded to z1; outward is (q − p) × Z.
        let base = m.positions.len() as u32;
        m.positions.extend([p, q, Vec3::new(q.x, q.y, z1), Vec3::new(p.x, p.y, z1)]);
        m.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    };
    let pt = |i: u32, j: u32| Vec3::new(i as f32 * size, j as f32 * size, z0);
    for k in 0..cells {
        wall(&mut m, pt(k, 0), pt(k + 1, 0));
        wall(&mut m, pt(cells, k), pt(cells, k + 1));
        wall(&mut m, pt(k + 1, cells), pt(k, cells));
        wall(&mut m, pt(0, k + 1), pt(0, k));
    }
    for j in 0..cells {
        for i in 0..cells {
            if hole(i, j) {
                // The solid is outside the hole: walls face into the hole.
                wall(&mut m, pt(i + 1, j), pt(i, j));
                wall(&mut m, pt(i + 1, j + 1), pt(i + 1, j));
                wall(&mut m, pt(i, j + 1), pt(i + 1, j + 1));
                wall(&mut m, pt(i, j), pt(i, j + 1));
            }
        }
    }
    // Bosses on cells (i, j) with i % 3 == 0 and j % 3 == 0: a faceted cylinder (side patch with
    // shared vertices, so its edges are silhouette candidates) and a cap fan.
    for j in (0..cells).step_by(3) {
        for i in (0..cells).step_by(3) {
            let center = Vec3::new((i as f32 + 0.5) * size, (j as f32 + 0.5) * size, z1);
            let radius = 0.35 * size;
            let height = 0.5 * size * (1.0 + (i + j) as f32 % 3.0);
            let base = m.positions.len() as u32;
            for s in 0..boss_segments {
                let phi = TAU * s as f32 / boss_segments as f32;
                let p = center + radius * Vec3::new(phi.cos(), phi.sin(), 0.0);
                m.positions.push(p);
                m.positions.push(p + Vec3::new(0.0, 0.0, height));
            }
            for s in 0..boss_segments {
                let (a, b) = (base + 2 * s, base + 2 * ((s + 1) % boss_segments));
                m.triangles.extend([[a, b, b + 1], [a, b + 1, a + 1]]);
            }
            let cap = m.positions.len() as u32;
            m.positions.push(center + Vec3::new(0.0, 0.0, height));
            for s in 0..boss_segments {
                let phi = TAU * s as f32 / boss_segments as f32;
                m.positions.push(center + radius * Vec3::new(phi.cos(), phi.sin(), 0.0) + Vec3::new(0.0, 0.0, height));
            }
            for s in 0..boss_segments {
                m.triangles.push([cap, cap + 1 + s, cap + 1 + (s + 1) % boss_segments]);
            }
        }
    }
    m
}

/// Random triangles over a few vertices on a small integer lattice: non-manifold edges, flipped
/// faces, degenerate faces and many exactly axis-aligned or rational normals (exact ties).
pub fn random_lattice_mesh(vertices: u32, triangles: u32, seed: u64) -> TestMesh {
    let mut rng = Rng::new(seed);
    let positions: Vec<Vec3> =
        (0..vertices).map(|_| Vec3::new(rng.below(5) as f32, rng.below(5) as f32, rng.below(5) as f32)).collect();
    let tris = (0..triangles).map(|_| [0; 3].map(|_| rng.below(u64::from(vertices)) as u32)).collect();
    TestMesh { name: format!("random lattice {seed}"), positions, triangles: tris }
}

/// A random closed-ish surface: a coarse sphere with strong noise (long Gauss arcs, a mix of
/// candidates and creases).
pub fn random_blob(seed: u64) -> TestMesh {
    let mut m = noisy_sphere(24, 14, 0.3, seed);
    m.name = format!("random blob {seed}");
    m
}

/// Bounding box.
pub fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
}

/// A random eye outside the box (drafter-lines' own, which the benchmarks draw their views with).
#[allow(unused_imports)]
pub use drafter_lines::measure::eye_outside;

/// A random eye inside the box.
pub fn eye_inside(rng: &mut Rng, lo: Vec3, hi: Vec3) -> Vec3 {
    lo + (hi - lo) * Vec3::new(rng.unit_f32(), rng.unit_f32(), rng.unit_f32())
}

/// Imports `path` with drafter-io and flattens every instance into one world-space mesh; the part
/// id of a face is the index of its instance.
pub fn load_model(path: &std::path::Path) -> Result<(TestMesh, Vec<drafter_core::PartId>), String> {
    let imported = drafter_io::import(path).map_err(|e| e.to_string())?;
    let scene = imported.scene;
    let mut mesh = TestMesh {
        name: path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
        ..Default::default()
    };
    let mut parts = Vec::new();
    for (k, instance) in scene.instances.iter().enumerate() {
        let Some(source) = scene.meshes.get(instance.mesh.index()) else { continue };
        let base = mesh.positions.len() as u32;
        let m = instance.world_from_object;
        mesh.positions.extend(source.positions.iter().map(|p| m.transform_point3(p.as_dvec3()).as_vec3()));
        let flip = instance.flips_winding();
        for t in &source.triangles {
            let t = if flip { [t[0], t[2], t[1]] } else { *t };
            mesh.triangles.push(t.map(|v| v + base));
            parts.push(drafter_core::PartId(k as u32));
        }
    }
    if mesh.triangles.is_empty() {
        return Err(format!("{}: no triangles", path.display()));
    }
    Ok((mesh, parts))
}

/// `../shared/models/<rel>` relative to this crate; panics loudly if the folder is missing.
pub fn shared_model(rel: &str) -> std::path::PathBuf {
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/models"));
    assert!(root.is_dir(), "the shared models folder {} is missing", root.display());
    let path = root.join(rel);
    assert!(path.is_file(), "shared model {} is missing", path.display());
    path
}
