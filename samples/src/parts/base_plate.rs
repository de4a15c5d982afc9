//! A rectangular base plate with vertical through holes.
//!
//! Object frame: the top face is y = 0 (parts stand on it), the plate spans y ∈ [−thickness, 0] and is centred
//! on x = z = 0. Holes run along y.
//!
//! B-rep faces: top and bottom (each with every hole), 4 sides, one cylinder per hole.

use glam::{DVec3, Vec3};

use crate::solid::{GeometryError, SolidBuilder, Surface, TriMesh, ring, ring_normals};

/// A vertical through hole of the base plate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlateHole {
    /// x of the axis.
    pub x: f64,
    /// z of the axis.
    pub z: f64,
    /// Radius.
    pub radius: f64,
}

/// Parameters of the base plate (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct BasePlate {
    /// Extent along x. Default 0.16.
    pub length: f64,
    /// Extent along z. Default 0.1.
    pub depth: f64,
    /// Extent along y. Default 0.008.
    pub thickness: f64,
    /// Through holes. Default: 4 M6 clearance holes (radius 0.0033) at (±0.053, ±0.022), under the brackets'
    /// bolts, and 4 mounting holes (radius 0.0045) at (±0.07, ±0.04).
    pub holes: Vec<PlateHole>,
    /// Segments per hole. Default 32.
    pub hole_segments: usize,
}

impl Default for BasePlate {
    fn default() -> Self {
        let mut holes = Vec::new();
        for (x, z, radius) in [(0.053, 0.022, 0.0033), (0.07, 0.04, 0.0045)] {
            for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                holes.push(PlateHole { x: sx * x, z: sz * z, radius });
            }
        }
        Self { length: 0.16, depth: 0.1, thickness: 0.008, holes, hole_segments: 32 }
    }
}

impl BasePlate {
    /// Tessellates the plate.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        let (hx, hz) = (self.length / 2.0, self.depth / 2.0);
        let inside = |h: &PlateHole| h.radius > 0.0 && h.x.abs() + h.radius < hx && h.z.abs() + h.radius < hz;
        if !(self.thickness > 0.0 && self.hole_segments >= 3 && self.holes.iter().all(inside)) {
            return Err(GeometryError::BadParameters("plate holes must lie inside the plate"));
        }
        let n = self.hole_segments;
        let footprint = [[-hx, -hz], [hx, -hz], [hx, hz], [-hx, hz]];
        let levels = [-self.thickness, 0.0];
        let corners: [Vec<Vec3>; 2] =
            levels.map(|y| footprint.iter().map(|&[x, z]| DVec3::new(x, y, z).as_vec3()).collect());
        let rims: Vec<[Vec<Vec3>; 2]> = self
            .holes
            .iter()
            .map(|h| levels.map(|y| ring(DVec3::new(h.x, y, h.z), DVec3::X, DVec3::Z, h.radius, n, 0.0)))
            .collect();

        let mut solid = SolidBuilder::new();
        for (side, normal) in [(0, -DVec3::Y), (1, DVec3::Y)] {
            let holes: Vec<&[Vec3]> = rims.iter().map(|r| r[side].as_slice()).collect();
            solid.planar_face(normal, &corners[side], &holes)?;
        }
        for i in 0..4 {
            let j = (i + 1) % 4;
            let (dx, dz) = (footprint[j][0] - footprint[i][0], footprint[j][1] - footprint[i][1]);
            // The footprint runs counter-clockwise in (x, z), i.e. clockwise seen from +y: outward is (dz, −dx).
            let normal = DVec3::new(dz, 0.0, -dx);
            solid.planar_face(normal, &[corners[0][i], corners[0][j], corners[1][j], corners[1][i]], &[])?;
        }
        let inward = ring_normals(DVec3::X, DVec3::Z, n, 0.0, -1.0);
        for [bottom, top] in &rims {
            solid.ruled_face(Surface::Cylinder, [bottom, top], [&inward, &inward], true)?;
        }
        Ok(solid.finish())
    }
}
