//! A hex bolt (head and chamfered shank, no thread) and a plain hex nut.
//!
//! Object frames: both have their axis on z. The bolt's bearing face (under the head) is z = 0, the head is above
//! it and the shank hangs down to z = −`length`. The nut's faces are z = 0 and z = `height`.
//!
//! B-rep faces: bolt 11 (head top, head underside with the shank as its inner edge, 6 head flats, shank
//! cylinder, chamfer cone, end disc); nut 9 (2 planar faces with the hole, 6 flats, the hole's cylinder).

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

use crate::solid::{GeometryError, SolidBuilder, Surface, TriMesh, cone_normals, ring, ring_direction, ring_normals};

/// Corners of a hexagon of `across_flats` around the z axis at height z, one corner at 30°.
fn hexagon(across_flats: f64, z: f64) -> Vec<Vec3> {
    ring(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y, across_flats / 3f64.sqrt(), 6, PI / 6.0)
}

/// The six flat side faces of a hexagonal prism between two hexagons from [`hexagon`].
fn hex_flats(solid: &mut SolidBuilder, bottom: &[Vec3], top: &[Vec3]) -> Result<(), GeometryError> {
    for k in 0..6 {
        let j = (k + 1) % 6;
        // Corners k and k+1 sit at 30° + 60°k and 90° + 60°k: the flat between them faces 60° + 60°k.
        let normal = ring_direction(DVec3::X, DVec3::Y, k, 6, PI / 3.0);
        solid.planar_face(normal, &[bottom[k], bottom[j], top[j], top[k]], &[])?;
    }
    Ok(())
}

/// Parameters of the hex bolt (metres). Defaults are an M6 × 21 bolt.
#[derive(Debug, Clone, PartialEq)]
pub struct HexBolt {
    /// Width across the head's flats. Default 0.01.
    pub across_flats: f64,
    /// Head height. Default 0.004.
    pub head_height: f64,
    /// Shank radius. Default 0.003; below half the across-flats width.
    pub shank_radius: f64,
    /// Shank length under the head, chamfer included. Default 0.021.
    pub length: f64,
    /// 45° chamfer at the shank's end. Default 0.0005.
    pub chamfer: f64,
    /// Segments per circle. Default 24.
    pub segments: usize,
}

impl Default for HexBolt {
    fn default() -> Self {
        Self {
            across_flats: 0.01,
            head_height: 0.004,
            shank_radius: 0.003,
            length: 0.021,
            chamfer: 0.0005,
            segments: 24,
        }
    }
}

impl HexBolt {
    /// Tessellates the bolt.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        let (r, c, n) = (self.shank_radius, self.chamfer, self.segments);
        if !(r > c && c > 0.0 && 2.0 * r < self.across_flats && self.length > c && self.head_height > 0.0 && n >= 3) {
            return Err(GeometryError::BadParameters("bolt shank must fit the head and be longer than its chamfer"));
        }
        let head = [hexagon(self.across_flats, 0.0), hexagon(self.across_flats, self.head_height)];
        // Shank stations (radius, z), bottom up: end-face rim, top of the chamfer, under the head.
        let stations = [[r - c, -self.length], [r, -self.length + c], [r, 0.0]];
        let rings: Vec<Vec<Vec3>> = stations
            .iter()
            .map(|&[radius, z]| ring(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y, radius, n, 0.0))
            .collect();

        let mut solid = SolidBuilder::new();
        solid.planar_face(DVec3::Z, &head[1], &[])?;
        solid.planar_face(-DVec3::Z, &head[0], &[&rings[2]])?;
        hex_flats(&mut solid, &head[0], &head[1])?;
        for (i, surface) in [(1, Surface::Cylinder), (0, Surface::Cone)] {
            let ([r0, z0], [r1, z1]) = (stations[i], stations[i + 1]);
            let normals = cone_normals(DVec3::X, DVec3::Y, DVec3::Z, n, 0.0, [r0, r1], [z0, z1]);
            solid.ruled_face(surface, [&rings[i], &rings[i + 1]], [&normals, &normals], true)?;
        }
        solid.planar_face(-DVec3::Z, &rings[0], &[])?;
        Ok(solid.finish())
    }
}

/// Parameters of the hex nut (metres). Defaults are an M6 nut.
#[derive(Debug, Clone, PartialEq)]
pub struct HexNut {
    /// Width across flats. Default 0.01.
    pub across_flats: f64,
    /// Height along z. Default 0.005.
    pub height: f64,
    /// Radius of the (unthreaded) hole. Default 0.00305, just clear of the bolt's shank.
    pub hole_radius: f64,
    /// Segments around the hole. Default 24.
    pub segments: usize,
}

impl Default for HexNut {
    fn default() -> Self {
        Self { across_flats: 0.01, height: 0.005, hole_radius: 0.00305, segments: 24 }
    }
}

impl HexNut {
    /// Tessellates the nut.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        let n = self.segments;
        if !(self.hole_radius > 0.0 && 2.0 * self.hole_radius < self.across_flats && self.height > 0.0 && n >= 3) {
            return Err(GeometryError::BadParameters("nut hole must fit inside the hexagon"));
        }
        let hex = [hexagon(self.across_flats, 0.0), hexagon(self.across_flats, self.height)];
        let hole: [Vec<Vec3>; 2] =
            [0.0, self.height].map(|z| ring(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y, self.hole_radius, n, 0.0));
        let mut solid = SolidBuilder::new();
        solid.planar_face(-DVec3::Z, &hex[0], &[&hole[0]])?;
        solid.planar_face(DVec3::Z, &hex[1], &[&hole[1]])?;
        hex_flats(&mut solid, &hex[0], &hex[1])?;
        let inward = ring_normals(DVec3::X, DVec3::Y, n, 0.0, -1.0);
        solid.ruled_face(Surface::Cylinder, [&hole[0], &hole[1]], [&inward, &inward], true)?;
        Ok(solid.finish())
    }
}
