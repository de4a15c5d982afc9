//! Generated inputs: the shapes where each method is known to struggle, rigid motions and
//! re-indexings of any mesh, and 4:1 midpoint subdivision for the scaling benchmark.
//!
//! Everything here is deterministic: the random rotations and permutations come from a seeded
//! SplitMix64 ([`Rng`]), so a failing case reproduces from its seed.
//!
//! | shape | why it is hard |
//! |---|---|
//! | [`cube`], [`cylinder`] | symmetric: the covariance has repeated eigenvalues, PCA axes are undefined |
//! | [`box_mesh`] with a tiny extent ([`plate`]) | paper-thin: one extent near zero, hull nearly planar |
//! | [`collinear_points`], [`coincident_points`] | hull of dimension 1 or 0 |
//! | [`sliver_fan`] | triangles with aspect ratios of 10⁴: normals from near-zero areas |
//! | [`nonmanifold_fan`] | three or more faces on one edge |
//! | [`open_box`] | boundary edges |
//! | [`single_triangle`] | one face, three boundary edges, no interior |
//! | [`unwelded_cube`] | a CAD export: no vertex shared between faces |

use drafter_core::{Mesh, Scene, SourceFormat, TriangleGroup};
use glam::{DMat4, DVec3, Vec3};

use crate::Rng;

/// A triangle mesh as plain arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// A [`Mesh`] with one triangle group (primitive 0).
    pub fn to_mesh(&self, name: &str) -> Mesh {
        Mesh {
            name: name.to_owned(),
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            normals: None,
            uvs: None,
            groups: vec![TriangleGroup {
                start: 0,
                count: self.triangles.len() as u32,
                material: None,
                primitive: Some(0),
                first_vertex: 0,
                vertex_count: self.positions.len() as u32,
            }],
        }
    }

    /// A scene of this mesh placed once, at the identity.
    pub fn to_scene(&self, name: &str) -> Scene {
        Scene::single_mesh(SourceFormat::Obj, self.to_mesh(name), name)
    }

    /// Positions moved by `world_from_object` (computed in f64, stored in f32).
    pub fn transformed(&self, world_from_object: &DMat4) -> TriMesh {
        TriMesh {
            positions: self
                .positions
                .iter()
                .map(|p| world_from_object.transform_point3(p.as_dvec3()).as_vec3())
                .collect(),
            triangles: self.triangles.clone(),
        }
    }

    /// The same surface with vertices and triangles in a random order and each triangle's corners
    /// rotated (winding kept). Returns the mesh, `new_vertex[old]` and `old_triangle[new]`.
    pub fn reindexed(&self, rng: &mut Rng) -> (TriMesh, Vec<u32>, Vec<u32>) {
        let new_vertex = rng.permutation(self.positions.len());
        let old_triangle = rng.permutation(self.triangles.len());
        let mut positions = vec![Vec3::ZERO; self.positions.len()];
        for (old, &new) in new_vertex.iter().enumerate() {
            positions[new as usize] = self.positions[old];
        }
        let triangles = old_triangle
            .iter()
            .map(|&t| {
                let [a, b, c] = self.triangles[t as usize].map(|v| new_vertex[v as usize]);
                match rng.below(3) {
                    0 => [a, b, c],
                    1 => [b, c, a],
                    _ => [c, a, b],
                }
            })
            .collect();
        (TriMesh { positions, triangles }, new_vertex, old_triangle)
    }

    /// 4:1 midpoint subdivision: every triangle becomes four, each edge's midpoint is shared by the
    /// triangles that use the edge (by vertex indices, so the input's seams stay seams).
    pub fn subdivided(&self) -> TriMesh {
        let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(self.triangles.len() * 3);
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.push((a.min(b), a.max(b), (t * 3 + k) as u32));
            }
        }
        edges.sort_unstable();
        let mut positions = self.positions.clone();
        let mut midpoint_of_corner = vec![0u32; self.triangles.len() * 3];
        let mut i = 0;
        while i < edges.len() {
            let (a, b, _) = edges[i];
            let m = positions.len() as u32;
            positions.push((self.positions[a as usize] + self.positions[b as usize]) * 0.5);
            while i < edges.len() && edges[i].0 == a && edges[i].1 == b {
                midpoint_of_corner[edges[i].2 as usize] = m;
                i += 1;
            }
        }
        let mut triangles = Vec::with_capacity(self.triangles.len() * 4);
        for (t, &[a, b, c]) in self.triangles.iter().enumerate() {
            let [ab, bc, ca] = [0, 1, 2].map(|k| midpoint_of_corner[t * 3 + k]);
            triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        TriMesh { positions, triangles }
    }

    /// World-space points in f64.
    pub fn points(&self) -> Vec<DVec3> {
        self.positions.iter().map(|p| p.as_dvec3()).collect()
    }
}

/// An axis-aligned box centred at the origin with the given full extents (8 vertices, 12 faces,
/// outward winding).
pub fn box_mesh(extents: DVec3) -> TriMesh {
    let h = (extents * 0.5).as_vec3();
    let positions = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 1 { h.x } else { -h.x },
                if i & 2 == 2 { h.y } else { -h.y },
                if i & 4 == 4 { h.z } else { -h.z },
            )
        })
        .collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
    TriMesh { positions, triangles }
}

/// The unit cube.
pub fn cube() -> TriMesh {
    box_mesh(DVec3::ONE)
}

/// The cube [0, 1]³ exported the CAD way: 4 vertices per face, nothing shared (24 vertices, 12
/// triangles, outward winding), so only a weld makes it one closed surface.
pub fn unwelded_cube() -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for axis in 0..3 {
        for side in [0.0f32, 1.0] {
            let base = positions.len() as u32;
            for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                let mut p = [0.0f32; 3];
                p[axis] = side;
                p[(axis + 1) % 3] = u;
                p[(axis + 2) % 3] = v;
                positions.push(Vec3::from(p));
            }
            if side == 0.0 {
                triangles.push([base, base + 2, base + 1]);
                triangles.push([base, base + 3, base + 2]);
            } else {
                triangles.push([base, base + 1, base + 2]);
                triangles.push([base, base + 2, base + 3]);
            }
        }
    }
    TriMesh { positions, triangles }
}

/// A paper-thin plate: 1 × 0.6 × `thickness`.
pub fn plate(thickness: f64) -> TriMesh {
    box_mesh(DVec3::new(1.0, 0.6, thickness))
}

/// The unit cube without its top face: an open surface whose rim is four boundary edges.
pub fn open_box() -> TriMesh {
    let mut m = cube();
    // The +z quad is faces 2 and 3 ([4, 5, 7, 6]).
    m.triangles.drain(2..4);
    m
}

/// A closed cylinder around +z: `segments` around, radius 1, height `height`, capped by fans
/// around a centre vertex.
pub fn cylinder(segments: u32, height: f32) -> TriMesh {
    let segments = segments.max(3);
    let mut positions = Vec::new();
    for z in [-0.5 * height, 0.5 * height] {
        for s in 0..segments {
            let a = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(Vec3::new(a.cos(), a.sin(), z));
        }
    }
    let bottom = positions.len() as u32;
    positions.push(Vec3::new(0.0, 0.0, -0.5 * height));
    positions.push(Vec3::new(0.0, 0.0, 0.5 * height));
    let top = bottom + 1;
    let mut triangles = Vec::new();
    for s in 0..segments {
        let n = (s + 1) % segments;
        let (b0, b1, t0, t1) = (s, n, s + segments, n + segments);
        triangles.push([b0, b1, t1]);
        triangles.push([b0, t1, t0]);
        triangles.push([bottom, b1, b0]);
        triangles.push([top, t0, t1]);
    }
    TriMesh { positions, triangles }
}

/// A rectangle 1 × `height` triangulated as a fan from one corner to `count` points on the far
/// side: slivers of aspect ratio about `count / height`, as CAD exporters make along long faces.
/// Lifted along z by a fold at x = 0.5 so that the surface has a crease to enhance.
pub fn sliver_fan(count: u32, height: f32) -> TriMesh {
    let count = count.max(1);
    let lift = |x: f32| if x > 0.5 { (x - 0.5) * 0.8 } else { 0.0 };
    let mut positions = vec![Vec3::new(0.0, 0.0, 0.0)];
    for i in 0..=count {
        let y = height * i as f32 / count as f32;
        positions.push(Vec3::new(1.0, y, lift(1.0)));
    }
    // A strip of quads between x = 0.5 and the far side adds the fold; the fan covers 0..0.5.
    let mut m = TriMesh { positions, triangles: Vec::new() };
    let mid: Vec<u32> = (0..=count)
        .map(|i| {
            let y = height * i as f32 / count as f32;
            m.positions.push(Vec3::new(0.5, y, 0.0));
            (m.positions.len() - 1) as u32
        })
        .collect();
    for i in 0..count {
        m.triangles.push([0, mid[i as usize], mid[i as usize + 1]]);
        let (a, b) = (mid[i as usize], mid[i as usize + 1]);
        let (c, d) = (1 + i, 2 + i);
        m.triangles.push([a, c, d]);
        m.triangles.push([a, d, b]);
    }
    m
}

/// `wings` triangles sharing the edge from (0,0,0) to (0,0,1), spread evenly around it: a
/// non-manifold fan (for `wings` ≥ 3).
pub fn nonmanifold_fan(wings: u32) -> TriMesh {
    let mut positions = vec![Vec3::ZERO, Vec3::Z];
    let mut triangles = Vec::new();
    for w in 0..wings {
        let a = std::f32::consts::TAU * w as f32 / wings as f32 + 0.1;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.5));
        triangles.push([0, 1, positions.len() as u32 - 1]);
    }
    TriMesh { positions, triangles }
}

/// One triangle.
pub fn single_triangle() -> TriMesh {
    TriMesh {
        positions: vec![Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.2, 0.7, 0.0)],
        triangles: vec![[0, 1, 2]],
    }
}

/// `count` points on a segment from `a` to `b` (not in order).
pub fn collinear_points(count: usize, a: DVec3, b: DVec3) -> Vec<DVec3> {
    (0..count).map(|i| a.lerp(b, ((i * 7919) % count.max(1)) as f64 / count.max(2) as f64)).collect()
}

/// `count` copies of one point.
pub fn coincident_points(count: usize, p: DVec3) -> Vec<DVec3> {
    vec![p; count]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subdivision_quadruples_triangles_and_shares_midpoints() {
        let c = cube();
        let s = c.subdivided();
        assert_eq!(s.triangles.len(), 48);
        // 8 corners + one midpoint per distinct edge (18 edges of the triangulated cube).
        assert_eq!(s.positions.len(), 8 + 18);
        let t = s.subdivided();
        assert_eq!(t.triangles.len(), 192);
    }

    #[test]
    fn reindexing_keeps_the_surface() {
        let c = cylinder(16, 2.0);
        let mut rng = Rng::new(7);
        let (r, new_vertex, old_triangle) = c.reindexed(&mut rng);
        for (new_t, &old_t) in old_triangle.iter().enumerate() {
            let mut old: Vec<Vec3> = c.triangles[old_t as usize].iter().map(|&v| c.positions[v as usize]).collect();
            let mut new: Vec<Vec3> = r.triangles[new_t].iter().map(|&v| r.positions[v as usize]).collect();
            let key = |p: &Vec3| (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
            old.sort_by_key(key);
            new.sort_by_key(key);
            assert_eq!(old, new);
        }
        assert!(new_vertex.iter().all(|&v| (v as usize) < c.positions.len()));
    }

    #[test]
    fn rotations_are_unit_and_deterministic() {
        let mut a = Rng::new(3);
        let mut b = Rng::new(3);
        for _ in 0..100 {
            let (qa, qb) = (a.rotation(), b.rotation());
            assert_eq!(qa, qb);
            assert!((qa.length() - 1.0).abs() < 1e-12);
        }
    }
}
