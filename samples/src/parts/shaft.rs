//! A flanged, stepped shaft: a solid of revolution with a drilled flange.
//!
//! Object frame: the axis is z, from z = 0 to z = `length`. Along z: an end face, a 45° chamfer, a reduced stub
//! (coupling end), a shoulder (the step), the journal, the flange (a disc with a bolt circle of through holes),
//! the journal again, a chamfer and the other end face.
//!
//! The profile is a list of (radius, z) stations; each segment between stations is one B-rep face: a cylinder
//! (equal radii), a cone (chamfer) or a planar annulus (equal z), and the two end discs are planar too. All
//! circles use the same number of segments and phase, so the rim of a cylinder and the edge of the annulus it
//! meets are the same points.
//!
//! B-rep faces: 2 end discs, 2 cones, 4 cylinders, 3 annuli and the flange rim (cylinder), plus one cylinder
//! per bolt hole.

use std::f64::consts::TAU;

use glam::{DVec3, Vec3};

use crate::solid::{GeometryError, SolidBuilder, Surface, TriMesh, cone_normals, ring, ring_normals};

/// Default segments per circle of the shaft.
pub const DEFAULT_SEGMENTS: usize = 48;

/// Parameters of the flanged shaft (metres). See the module docs for the frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FlangedShaft {
    /// Overall length along z. Default 0.1.
    pub length: f64,
    /// Radius of the journal (the bearing seats either side of the flange). Default 0.006.
    pub journal_radius: f64,
    /// Radius of the reduced stub at z = 0. Default 0.0045; below the journal radius.
    pub stub_radius: f64,
    /// z of the shoulder between stub and journal. Default 0.008.
    pub step_z: f64,
    /// Size of the 45° chamfers at both ends. Default 0.0005.
    pub chamfer: f64,
    /// Radius of the flange. Default 0.015.
    pub flange_radius: f64,
    /// z of the flange's face towards z = 0. Default 0.05.
    pub flange_z: f64,
    /// Flange thickness. Default 0.005.
    pub flange_thickness: f64,
    /// Number of through holes on the flange's bolt circle. Default 6 (0 for none).
    pub flange_holes: usize,
    /// Radius of the flange holes. Default 0.0016.
    pub flange_hole_radius: f64,
    /// Radius of the bolt circle. Default 0.0105.
    pub bolt_circle_radius: f64,
    /// Segments per circle of the shaft. Default [`DEFAULT_SEGMENTS`].
    pub segments: usize,
    /// Segments per flange hole. Default 24.
    pub hole_segments: usize,
}

impl Default for FlangedShaft {
    fn default() -> Self {
        Self {
            length: 0.1,
            journal_radius: 0.006,
            stub_radius: 0.0045,
            step_z: 0.008,
            chamfer: 0.0005,
            flange_radius: 0.015,
            flange_z: 0.05,
            flange_thickness: 0.005,
            flange_holes: 6,
            flange_hole_radius: 0.0016,
            bolt_circle_radius: 0.0105,
            segments: DEFAULT_SEGMENTS,
            hole_segments: 24,
        }
    }
}

impl FlangedShaft {
    /// The (radius, z) stations of the outer profile, from the end at z = 0 to the end at z = length.
    pub fn stations(&self) -> Vec<[f64; 2]> {
        let (c, rj, rs) = (self.chamfer, self.journal_radius, self.stub_radius);
        let (fz0, fz1) = (self.flange_z, self.flange_z + self.flange_thickness);
        vec![
            [rs - c, 0.0],
            [rs, c],
            [rs, self.step_z],
            [rj, self.step_z],
            [rj, fz0],
            [self.flange_radius, fz0],
            [self.flange_radius, fz1],
            [rj, fz1],
            [rj, self.length - c],
            [rj - c, self.length],
        ]
    }

    /// Centres (in the x-y plane) of the flange holes.
    pub fn flange_hole_centres(&self) -> Vec<DVec3> {
        (0..self.flange_holes)
            .map(|k| {
                crate::solid::ring_direction(DVec3::X, DVec3::Y, k, self.flange_holes, TAU / 12.0)
                    * self.bolt_circle_radius
            })
            .collect()
    }

    fn check(&self) -> Result<(), GeometryError> {
        let stations = self.stations();
        let increasing = stations.windows(2).all(|w| w[1][1] >= w[0][1]);
        let hole_fits = self.flange_holes == 0
            || (self.bolt_circle_radius - self.flange_hole_radius > self.journal_radius
                && self.bolt_circle_radius + self.flange_hole_radius < self.flange_radius
                && (self.flange_holes == 1
                    || self.bolt_circle_radius * crate::detmath::sin(TAU / 2.0 / self.flange_holes as f64)
                        > self.flange_hole_radius));
        let fits = increasing
            && self.chamfer > 0.0
            && self.stub_radius > self.chamfer
            && self.stub_radius < self.journal_radius
            && self.flange_radius > self.journal_radius
            && self.step_z > self.chamfer
            && self.flange_z > self.step_z
            && self.flange_z + self.flange_thickness < self.length - self.chamfer
            && hole_fits
            && self.segments >= 3
            && self.hole_segments >= 3;
        if fits {
            Ok(())
        } else {
            Err(GeometryError::BadParameters("shaft stations must be ordered and holes inside the flange"))
        }
    }

    /// Tessellates the shaft.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        self.check()?;
        let stations = self.stations();
        let n = self.segments;
        let centre = |z: f64| DVec3::new(0.0, 0.0, z);
        // Every station's circle, computed once and shared by the two faces that meet there.
        let rings: Vec<Vec<Vec3>> =
            stations.iter().map(|&[r, z]| ring(centre(z), DVec3::X, DVec3::Y, r, n, 0.0)).collect();
        let (fz0, fz1) = (self.flange_z, self.flange_z + self.flange_thickness);
        let hole_centres = self.flange_hole_centres();
        let hole_rim = |c: DVec3, z: f64| {
            ring(c + DVec3::Z * z, DVec3::X, DVec3::Y, self.flange_hole_radius, self.hole_segments, 0.0)
        };
        let hole_rims: Vec<[Vec<Vec3>; 2]> =
            hole_centres.iter().map(|&c| [hole_rim(c, fz0), hole_rim(c, fz1)]).collect();

        let mut solid = SolidBuilder::new();
        let last = stations.len() - 1;
        solid.planar_face(-DVec3::Z, &rings[0], &[])?;
        for i in 0..last {
            let ([r0, z0], [r1, z1]) = (stations[i], stations[i + 1]);
            if z0 == z1 {
                // A planar annulus; the profile runs outwards (normal −z) or inwards (normal +z).
                let (normal, outer, inner) =
                    if r1 > r0 { (-DVec3::Z, &rings[i + 1], &rings[i]) } else { (DVec3::Z, &rings[i], &rings[i + 1]) };
                let mut holes: Vec<&[Vec3]> = vec![inner];
                if z0 == fz0 || z0 == fz1 {
                    let side = usize::from(z0 == fz1);
                    holes.extend(hole_rims.iter().map(|rims| rims[side].as_slice()));
                }
                solid.planar_face(normal, outer, &holes)?;
            } else {
                let surface = if r0 == r1 { Surface::Cylinder } else { Surface::Cone };
                let normals = cone_normals(DVec3::X, DVec3::Y, DVec3::Z, n, 0.0, [r0, r1], [z0, z1]);
                solid.ruled_face(surface, [&rings[i], &rings[i + 1]], [&normals, &normals], true)?;
            }
        }
        solid.planar_face(DVec3::Z, &rings[last], &[])?;
        let inward = ring_normals(DVec3::X, DVec3::Y, self.hole_segments, 0.0, -1.0);
        for [front, back] in &hole_rims {
            solid.ruled_face(Surface::Cylinder, [front, back], [&inward, &inward], true)?;
        }
        Ok(solid.finish())
    }
}
