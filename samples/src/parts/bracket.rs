//! A drilled L-bracket: two plates at 90° with a sharp (fillet-free) corner, two bolt holes through the base
//! plate and two bearing holes through the upright plate.
//!
//! Object frame: the L profile lies in the x-y plane and is extruded along z, centred on z = 0. The base plate
//! occupies x ∈ [0, base_length], y ∈ [0, thickness]; the upright x ∈ [0, thickness], y ∈ [0, height]. So the
//! bracket stands on y = 0, the upright's back is x = 0, and the base plate points towards +x. Base holes run
//! along y at x = `base_hole_x`, z = ±`base_hole_spacing`/2; upright holes run along x at
//! y = `upright_hole_height`, z = ±`upright_hole_spacing`/2.
//!
//! B-rep faces (12): 2 L-shaped end caps, 6 side planes (4 of them drilled), 4 hole walls (cylinders).

use glam::{DVec3, Vec3};

use crate::solid::{GeometryError, SolidBuilder, Surface, TriMesh, ring, ring_normals};

/// Default plate width along z, in metres.
pub const DEFAULT_WIDTH: f64 = 0.07;
/// Default plate thickness, in metres.
pub const DEFAULT_THICKNESS: f64 = 0.006;
/// Default hole tessellation: segments per full circle.
pub const DEFAULT_HOLE_SEGMENTS: usize = 32;

/// Parameters of the L-bracket (metres). See the module docs for the frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Bracket {
    /// Extent along z. Default [`DEFAULT_WIDTH`]; must exceed the hole spacings plus diameters.
    pub width: f64,
    /// Thickness of both plates. Default [`DEFAULT_THICKNESS`]; (0, min(base_length, height)).
    pub thickness: f64,
    /// Extent of the base plate along x, upright included. Default 0.03.
    pub base_length: f64,
    /// Extent of the upright along y, base plate included. Default 0.05.
    pub height: f64,
    /// Radius of the two base (bolt) holes. Default 0.0033 (an M6 clearance hole).
    pub base_hole_radius: f64,
    /// x of the base holes' axes. Default 0.018 (middle of the free part of the base plate).
    pub base_hole_x: f64,
    /// Distance along z between the base holes. Default 0.044.
    pub base_hole_spacing: f64,
    /// Radius of the two upright (bearing) holes. Default 0.0062.
    pub upright_hole_radius: f64,
    /// y of the upright holes' axes. Default 0.035.
    pub upright_hole_height: f64,
    /// Distance along z between the upright holes. Default 0.04.
    pub upright_hole_spacing: f64,
    /// Segments per hole circle. Default [`DEFAULT_HOLE_SEGMENTS`]; at least 3.
    pub hole_segments: usize,
}

impl Default for Bracket {
    fn default() -> Self {
        Self {
            width: DEFAULT_WIDTH,
            thickness: DEFAULT_THICKNESS,
            base_length: 0.03,
            height: 0.05,
            base_hole_radius: 0.0033,
            base_hole_x: 0.018,
            base_hole_spacing: 0.044,
            upright_hole_radius: 0.0062,
            upright_hole_height: 0.035,
            upright_hole_spacing: 0.04,
            hole_segments: DEFAULT_HOLE_SEGMENTS,
        }
    }
}

impl Bracket {
    /// The L profile in the x-y plane, counter-clockwise: A(0,0) B(l,0) C(l,t) D(t,t) E(t,h) F(0,h).
    pub fn profile(&self) -> [[f64; 2]; 6] {
        let (t, l, h) = (self.thickness, self.base_length, self.height);
        [[0.0, 0.0], [l, 0.0], [l, t], [t, t], [t, h], [0.0, h]]
    }

    /// Axes (as points on the hole's entry face) of the base holes, then of the upright holes.
    pub fn hole_centres(&self) -> [DVec3; 4] {
        let (bz, uz) = (self.base_hole_spacing / 2.0, self.upright_hole_spacing / 2.0);
        [
            DVec3::new(self.base_hole_x, 0.0, -bz),
            DVec3::new(self.base_hole_x, 0.0, bz),
            DVec3::new(0.0, self.upright_hole_height, -uz),
            DVec3::new(0.0, self.upright_hole_height, uz),
        ]
    }

    fn check(&self) -> Result<(), GeometryError> {
        let t = self.thickness;
        let fits = t > 0.0
            && t < self.base_length.min(self.height)
            && self.base_hole_x - self.base_hole_radius > t
            && self.base_hole_x + self.base_hole_radius < self.base_length
            && self.upright_hole_height - self.upright_hole_radius > t
            && self.upright_hole_height + self.upright_hole_radius < self.height
            && (self.base_hole_spacing + 2.0 * self.base_hole_radius) < self.width
            && (self.upright_hole_spacing + 2.0 * self.upright_hole_radius) < self.width
            && self.base_hole_spacing > 2.0 * self.base_hole_radius
            && self.upright_hole_spacing > 2.0 * self.upright_hole_radius
            && self.hole_segments >= 3;
        if fits { Ok(()) } else { Err(GeometryError::BadParameters("bracket holes must lie inside their plates")) }
    }

    /// Tessellates the bracket.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        self.check()?;
        let half_w = self.width / 2.0;
        let profile = self.profile();
        // Corner points, computed once: corners[side][i] is profile point i at z = -w/2 (side 0) or +w/2 (side 1).
        let corners: [Vec<Vec3>; 2] =
            [-half_w, half_w].map(|z| profile.iter().map(|&[x, y]| DVec3::new(x, y, z).as_vec3()).collect());
        let n = self.hole_segments;
        let t = self.thickness;
        // Hole rims, computed once per (hole, face): rims[hole][0] on the entry face, rims[hole][1] on the exit face.
        let centres = self.hole_centres();
        let rim = |hole: usize, depth: f64| -> Vec<Vec3> {
            let (centre, u, v, r) = if hole < 2 {
                (centres[hole] + DVec3::Y * depth, DVec3::X, DVec3::Z, self.base_hole_radius)
            } else {
                (centres[hole] + DVec3::X * depth, DVec3::Y, DVec3::Z, self.upright_hole_radius)
            };
            ring(centre, u, v, r, n, 0.0)
        };
        let rims: Vec<[Vec<Vec3>; 2]> = (0..4).map(|hole| [rim(hole, 0.0), rim(hole, t)]).collect();

        let mut solid = SolidBuilder::new();
        solid.planar_face(-DVec3::Z, &corners[0], &[])?;
        solid.planar_face(DVec3::Z, &corners[1], &[])?;
        for i in 0..profile.len() {
            let j = (i + 1) % profile.len();
            let edge = [profile[j][0] - profile[i][0], profile[j][1] - profile[i][1]];
            // Outward normal of a counter-clockwise profile edge: the edge direction turned clockwise.
            let normal = DVec3::new(edge[1], -edge[0], 0.0);
            let quad = [corners[0][i], corners[0][j], corners[1][j], corners[1][i]];
            let holes: Vec<&[Vec3]> = match i {
                0 => vec![&rims[0][0], &rims[1][0]], // A-B: underside of the base plate, y = 0
                2 => vec![&rims[0][1], &rims[1][1]], // C-D: top of the base plate, y = t
                3 => vec![&rims[2][1], &rims[3][1]], // D-E: front of the upright, x = t
                5 => vec![&rims[2][0], &rims[3][0]], // F-A: back of the upright, x = 0
                _ => Vec::new(),
            };
            solid.planar_face(normal, &quad, &holes)?;
        }
        for (hole, [entry, exit]) in rims.iter().enumerate() {
            let u = if hole < 2 { DVec3::X } else { DVec3::Y };
            let inward = ring_normals(u, DVec3::Z, n, 0.0, -1.0);
            solid.ruled_face(Surface::Cylinder, [entry, exit], [&inward, &inward], true)?;
        }
        Ok(solid.finish())
    }
}
