//! Tessellation the CAD way: a solid is built face by face, each B-rep face a patch with its own vertices.
//!
//! This is what OpenCascade-based exporters write: vertices are not shared across a face boundary, so planar faces
//! carry their flat normal and curved faces (cylinders, cones, extruded curves) carry smooth analytic normals that
//! are shared only inside the face. The solid is still closed: every boundary edge of a face is discretised with
//! exactly the same `f32` points as the matching edge of the neighbouring face, so welding the vertices by
//! position (bit equality) gives a closed, consistently oriented 2-manifold.
//!
//! Invariant: a caller computes each boundary polyline (a circle, a profile edge) once and hands the same `Vec3`
//! values to both faces that share it. [`ring`] is deterministic, so calling it twice with the same arguments is
//! as good as computing once.
//!
//! Winding is derived, not trusted: planar faces are triangulated counter-clockwise around the given normal, and
//! a ruled face is wound so its triangles agree with the given vertex normals (an error if some quads disagree).

use std::fmt;

use glam::{DVec2, DVec3, Vec3};

use crate::detmath;
use crate::triangulate::{self, TriangulateError};

/// Kind of the surface a B-rep face lies on (what a CAD kernel would call its geometry).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Surface {
    /// A plane: flat normal.
    Plane,
    /// A circular cylinder: radial normals.
    Cylinder,
    /// A circular cone (a chamfer): normals tilted by the half-angle.
    Cone,
    /// A general curve extruded along a straight line (a gear's involute flank).
    Extrusion,
}

/// One B-rep face of a [`TriMesh`]: a contiguous run of vertices and of triangles.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Face {
    /// Surface the face lies on.
    pub surface: Surface,
    /// First vertex of the face.
    pub first_vertex: u32,
    /// Number of vertices of the face.
    pub vertex_count: u32,
    /// First triangle of the face.
    pub first_triangle: u32,
    /// Number of triangles of the face.
    pub triangle_count: u32,
}

/// An indexed triangle mesh in object space (metres), with per-vertex normals and its B-rep face list.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals, one per position.
    pub normals: Vec<[f32; 3]>,
    /// Counter-clockwise triangles seen from outside the solid.
    pub triangles: Vec<[u32; 3]>,
    /// Faces in the order they were built.
    pub faces: Vec<Face>,
}

/// Why a face could not be built (a bug in a part's parameters or construction, not bad user input).
#[derive(Debug, Clone, PartialEq)]
pub enum GeometryError {
    /// The planar face's boundary could not be triangulated.
    Triangulate {
        /// Index of the face in the solid.
        face: usize,
        /// What the triangulator said.
        source: TriangulateError,
    },
    /// A point of a planar face is off its plane.
    NotPlanar {
        /// Index of the face in the solid.
        face: usize,
        /// Distance of the farthest point from the plane of the first point.
        distance: f64,
    },
    /// The two rows of a ruled face differ in length, are too short or their normals are not unit-able.
    BadRows {
        /// Index of the face in the solid.
        face: usize,
    },
    /// Some quads of a ruled face disagree with its normals about which side is outside.
    InconsistentNormals {
        /// Index of the face in the solid.
        face: usize,
    },
    /// Part parameters describe no valid solid (e.g. a hole larger than its plate).
    BadParameters(&'static str),
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Triangulate { face, source } => write!(f, "face {face}: {source}"),
            Self::NotPlanar { face, distance } => write!(f, "face {face}: point {distance:e} m off the plane"),
            Self::BadRows { face } => write!(f, "face {face}: ruled face rows are mismatched or degenerate"),
            Self::InconsistentNormals { face } => write!(f, "face {face}: normals disagree on the outside"),
            Self::BadParameters(why) => write!(f, "bad part parameters: {why}"),
        }
    }
}

impl std::error::Error for GeometryError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Triangulate { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// Builds a [`TriMesh`] one B-rep face at a time.
#[derive(Debug, Default)]
pub struct SolidBuilder {
    mesh: TriMesh,
}

impl SolidBuilder {
    /// An empty solid.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a planar face bounded by `outer` with `holes` (loops of points on the plane, any orientation),
    /// triangulated without extra vertices and wound counter-clockwise around `normal` (the outward normal).
    pub fn planar_face(&mut self, normal: DVec3, outer: &[Vec3], holes: &[&[Vec3]]) -> Result<(), GeometryError> {
        let face = self.mesh.faces.len();
        let normal = normal.try_normalize().ok_or(GeometryError::BadRows { face })?;
        let (u, v) = plane_basis(normal);
        let loops_3d: Vec<&[Vec3]> = std::iter::once(outer).chain(holes.iter().copied()).collect();
        let origin = outer.first().ok_or(GeometryError::BadRows { face })?.as_dvec3();
        let mut extent = 0.0_f64;
        let mut off_plane = 0.0_f64;
        let loops_2d: Vec<Vec<triangulate::Point2>> = loops_3d
            .iter()
            .map(|l| {
                l.iter()
                    .map(|p| {
                        let d = p.as_dvec3() - origin;
                        extent = extent.max(d.abs().max_element());
                        off_plane = off_plane.max(d.dot(normal).abs());
                        [p.as_dvec3().dot(u), p.as_dvec3().dot(v)]
                    })
                    .collect()
            })
            .collect();
        if off_plane > 1e-6 * extent.max(1e-3) {
            return Err(GeometryError::NotPlanar { face, distance: off_plane });
        }
        let triangles =
            triangulate::triangulate(&loops_2d).map_err(|source| GeometryError::Triangulate { face, source })?;
        let first_vertex = self.mesh.positions.len() as u32;
        let points: Vec<Vec3> = loops_3d.iter().flat_map(|l| l.iter().copied()).collect();
        let normals = vec![normal; points.len()];
        self.push_vertices(&points, &normals);
        let triangles = triangles.iter().map(|t| t.map(|i| first_vertex + i)).collect::<Vec<_>>();
        self.push_face(Surface::Plane, first_vertex, triangles);
        Ok(())
    }

    /// Adds a ruled face between two rows of points (e.g. the two rims of a cylinder), with one normal per point.
    /// `closed` joins the last point of each row back to the first (a full cylinder). Each quad is split into two
    /// triangles, wound to agree with the normals.
    pub fn ruled_face(
        &mut self,
        surface: Surface,
        rows: [&[Vec3]; 2],
        normals: [&[DVec3]; 2],
        closed: bool,
    ) -> Result<(), GeometryError> {
        let face = self.mesh.faces.len();
        let n = rows[0].len();
        let min_points = if closed { 3 } else { 2 };
        if n < min_points || rows[1].len() != n || normals[0].len() != n || normals[1].len() != n {
            return Err(GeometryError::BadRows { face });
        }
        let first_vertex = self.mesh.positions.len() as u32;
        let mut unit = Vec::with_capacity(2 * n);
        for row in normals {
            for normal in row {
                unit.push(normal.try_normalize().ok_or(GeometryError::BadRows { face })?);
            }
        }
        let points: Vec<Vec3> = rows[0].iter().chain(rows[1]).copied().collect();
        self.push_vertices(&points, &unit);

        let quads = if closed { n } else { n - 1 };
        let (mut agree, mut disagree) = (0, 0);
        let mut triangles = Vec::with_capacity(2 * quads);
        for i in 0..quads {
            let j = (i + 1) % n;
            let (a0, a1, b1, b0) = (i, j, n + j, n + i);
            let corner = |k: usize| points[k].as_dvec3();
            let geometric = (corner(a1) - corner(a0)).cross(corner(b1) - corner(a0))
                + (corner(b1) - corner(a0)).cross(corner(b0) - corner(a0));
            let given = unit[a0] + unit[a1] + unit[b1] + unit[b0];
            if geometric.dot(given) > 0.0 {
                agree += 1
            } else {
                disagree += 1
            }
            triangles.push([a0, a1, b1]);
            triangles.push([a0, b1, b0]);
        }
        if agree > 0 && disagree > 0 {
            return Err(GeometryError::InconsistentNormals { face });
        }
        let flip = disagree > 0;
        let triangles = triangles
            .into_iter()
            .map(|[a, b, c]| {
                let [a, b, c] = [a, b, c].map(|k| first_vertex + k as u32);
                if flip { [a, c, b] } else { [a, b, c] }
            })
            .collect();
        self.push_face(surface, first_vertex, triangles);
        Ok(())
    }

    /// The finished mesh.
    pub fn finish(self) -> TriMesh {
        self.mesh
    }

    fn push_vertices(&mut self, points: &[Vec3], normals: &[DVec3]) {
        for (p, n) in points.iter().zip(normals) {
            // `+ 0.0` turns -0.0 into +0.0, so equal positions are also equal bit patterns.
            self.mesh.positions.push([p.x + 0.0, p.y + 0.0, p.z + 0.0]);
            let n = n.normalize().as_vec3();
            self.mesh.normals.push([n.x + 0.0, n.y + 0.0, n.z + 0.0]);
        }
    }

    fn push_face(&mut self, surface: Surface, first_vertex: u32, triangles: Vec<[u32; 3]>) {
        let first_triangle = self.mesh.triangles.len() as u32;
        self.mesh.faces.push(Face {
            surface,
            first_vertex,
            vertex_count: self.mesh.positions.len() as u32 - first_vertex,
            first_triangle,
            triangle_count: triangles.len() as u32,
        });
        self.mesh.triangles.extend(triangles);
    }
}

/// Orthonormal (u, v) with u × v = n; axis-aligned (hence exact projections) when n is an axis.
fn plane_basis(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = (helper - n * n.dot(helper)).normalize();
    (u, n.cross(u))
}

/// Unit direction at angle `phase + 2π k / segments` in the frame (u, v). Sines and cosines below 1e-15 (the
/// rounding residue of cos(π/2) and the like) are snapped to 0, so points on the frame's axes have exact zeros.
pub fn ring_direction(u: DVec3, v: DVec3, k: usize, segments: usize, phase: f64) -> DVec3 {
    let (s, c) = detmath::sin_cos(phase + std::f64::consts::TAU * k as f64 / segments as f64);
    let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
    u * snap(c) + v * snap(s)
}

/// `segments` points on the circle of `radius` around `center` in the plane spanned by the unit vectors u and v,
/// starting at angle `phase` from u, turning towards v. Computed in f64 and rounded once to f32.
pub fn ring(center: DVec3, u: DVec3, v: DVec3, radius: f64, segments: usize, phase: f64) -> Vec<Vec3> {
    (0..segments).map(|k| (center + ring_direction(u, v, k, segments, phase) * radius).as_vec3()).collect()
}

/// The outward unit directions of [`ring`] (towards the points), or inward if `sign` is -1.
pub fn ring_normals(u: DVec3, v: DVec3, segments: usize, phase: f64, sign: f64) -> Vec<DVec3> {
    (0..segments).map(|k| ring_direction(u, v, k, segments, phase) * sign).collect()
}

/// Normals of a cone (or cylinder) between two coaxial rings: the profile goes from (r0, h0) to (r1, h1) in
/// (radius, height along `axis`) and the solid lies on the axis side when walking the profile, so the outward
/// profile normal is (dh, -dr). Returns one normal per ring point.
pub fn cone_normals(
    u: DVec3,
    v: DVec3,
    axis: DVec3,
    segments: usize,
    phase: f64,
    r: [f64; 2],
    h: [f64; 2],
) -> Vec<DVec3> {
    let profile = DVec2::new(h[1] - h[0], r[0] - r[1]).normalize();
    (0..segments).map(|k| ring_direction(u, v, k, segments, phase) * profile.x + axis * profile.y).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_with_a_hole_has_flat_and_radial_normals() {
        let mut solid = SolidBuilder::new();
        let rim_top = ring(DVec3::new(0.0, 0.0, 1.0), DVec3::X, DVec3::Y, 0.3, 16, 0.0);
        let rim_bottom = ring(DVec3::new(0.0, 0.0, -1.0), DVec3::X, DVec3::Y, 0.3, 16, 0.0);
        let square = |z: f32| [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]].map(|[x, y]| Vec3::new(x, y, z));
        solid.planar_face(DVec3::Z, &square(1.0), &[&rim_top]).expect("top");
        solid.planar_face(-DVec3::Z, &square(-1.0), &[&rim_bottom]).expect("bottom");
        let inward = ring_normals(DVec3::X, DVec3::Y, 16, 0.0, -1.0);
        solid.ruled_face(Surface::Cylinder, [&rim_bottom, &rim_top], [&inward, &inward], true).expect("wall");
        let mesh = solid.finish();
        assert_eq!(mesh.faces.len(), 3);
        assert_eq!(mesh.faces[2].triangle_count, 32);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| Vec3::from(mesh.positions[i as usize]));
            let n = Vec3::from(mesh.normals[t[0] as usize]);
            assert!((b - a).cross(c - a).dot(n) > 0.0, "triangle {t:?} wound against its normal");
        }
    }

    #[test]
    fn off_plane_points_and_inconsistent_normals_are_errors() {
        let mut solid = SolidBuilder::new();
        let bent = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.5), Vec3::Y];
        assert!(matches!(solid.planar_face(DVec3::Z, &bent, &[]), Err(GeometryError::NotPlanar { .. })));
        let rim = ring(DVec3::ZERO, DVec3::X, DVec3::Y, 1.0, 8, 0.0);
        let rim_up = ring(DVec3::Z, DVec3::X, DVec3::Y, 1.0, 8, 0.0);
        let mut mixed = ring_normals(DVec3::X, DVec3::Y, 8, 0.0, 1.0);
        for n in &mut mixed[..4] {
            *n = -*n;
        }
        let result = solid.ruled_face(Surface::Cylinder, [&rim, &rim_up], [&mixed, &mixed], true);
        assert!(matches!(result, Err(GeometryError::InconsistentNormals { .. })));
    }
}
