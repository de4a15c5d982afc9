//! Mesh generators shared by the tests and the benchmark examples (included with `#[path]`).
#![allow(dead_code)]

use drafter_core::Mesh;
use glam::Vec3;

pub fn mesh(name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Mesh {
    Mesh { name: name.into(), positions, triangles, ..Default::default() }
}

/// A unit cube exported the CAD way (4 vertices per face, nothing shared) or welded (8 vertices).
pub fn cube(welded: bool) -> Mesh {
    let drafter_testkit::generate::TriMesh { mut positions, mut triangles } =
        drafter_testkit::generate::unwelded_cube();
    if welded {
        let mut unique: Vec<Vec3> = Vec::new();
        let remap: Vec<u32> = positions
            .iter()
            .map(|p| match unique.iter().position(|q| q == p) {
                Some(i) => i as u32,
                None => {
                    unique.push(*p);
                    (unique.len() - 1) as u32
                }
            })
            .collect();
        triangles = triangles.iter().map(|t| t.map(|v| remap[v as usize])).collect();
        positions = unique;
    }
    mesh("cube", positions, triangles)
}

/// A UV sphere of radius 1 with `slices` longitudes and `stacks` latitudes. With `seam`, the u = 0 and
/// u = 2π columns are separate vertices (as texture-mapped exports have them); the poles are single
/// vertices either way.
pub fn uv_sphere(slices: u32, stacks: u32, seam: bool) -> Mesh {
    let columns = if seam { slices + 1 } else { slices };
    let mut positions = vec![Vec3::Z];
    for i in 1..stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        for j in 0..columns {
            let phi = std::f32::consts::TAU * (j % slices) as f32 / slices as f32;
            let phi = if seam && j == slices { std::f32::consts::TAU } else { phi };
            positions.push(Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()));
        }
    }
    positions.push(-Vec3::Z);
    let south = positions.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * columns + if seam { j } else { j % slices };
    let mut triangles = Vec::new();
    for j in 0..slices {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
    }
    for i in 1..stacks - 1 {
        for j in 0..slices {
            let (a, b, c, d) = (ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    for j in 0..slices {
        triangles.push([south, ring(stacks - 1, j + 1), ring(stacks - 1, j)]);
    }
    mesh("sphere", positions, triangles)
}

/// A flat `n × n` grid in the z = 0 plane over [0, 1]², each cell cut along a pseudo-random diagonal.
pub fn plane(n: u32) -> Mesh {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            positions.push(Vec3::new(x as f32 / n as f32, y as f32 / n as f32, 0.0));
        }
    }
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let mut triangles = Vec::new();
    let mut rng = drafter_testkit::Rng::new(0x9e37_79b9);
    for y in 0..n {
        for x in 0..n {
            let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
            if rng.below(2) == 0 {
                triangles.push([a, b, c]);
                triangles.push([a, c, d]);
            } else {
                triangles.push([a, b, d]);
                triangles.push([b, c, d]);
            }
        }
    }
    mesh("plane", positions, triangles)
}

/// A folded sheet: the grid of [`plane`] bent along x = 0.5 so the two halves meet at `angle_deg`
/// (the dihedral between their normals). Returns the mesh and the welded-id column of the crease.
pub fn roof(n: u32, angle_deg: f32) -> Mesh {
    let mut m = plane(n);
    let half = angle_deg.to_radians() / 2.0;
    for p in &mut m.positions {
        let x = p.x - 0.5;
        let tilt = if x < 0.0 { half } else { -half };
        // Rotate each half about the crease line (the y axis through x = 0.5) by ±half.
        p.x = 0.5 + x * tilt.cos();
        p.z = -x * tilt.sin();
    }
    m.name = "roof".into();
    m
}

/// A noisy sphere of about `2 * slices * stacks` triangles: radial jitter of `noise` (deterministic).
pub fn bumpy_sphere(slices: u32, stacks: u32, noise: f32) -> Mesh {
    let mut m = uv_sphere(slices, stacks, false);
    let mut state = 0x2545_f491u32;
    for p in &mut m.positions {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let r = 1.0 + noise * ((state % 10_000) as f32 / 10_000.0 - 0.5);
        *p *= r;
    }
    m.name = "bumpy-sphere".into();
    m
}

/// Angle in degrees between two vectors.
pub fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    a.angle_between(b).to_degrees()
}

/// CPU time of all this process's threads so far (Linux `schedstat`, nanosecond resolution); 0 where
/// unavailable. On a shared, loaded machine it is steadier than wall time. Rayon workers that spin
/// while waiting are counted too, so it is an upper bound on the work.
pub fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else { return 0.0 };
    tasks
        .flatten()
        .filter_map(|task| std::fs::read_to_string(task.path().join("schedstat")).ok())
        .filter_map(|line| line.split_whitespace().next()?.parse::<f64>().ok())
        .sum::<f64>()
        * 1e-9
}
