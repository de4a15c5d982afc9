//! A spur gear with true involute flanks, a bore and flat faces.
//!
//! How the profile is made (standard full-depth teeth, ISO 53 proportions): pitch radius r_p = m z / 2, base
//! radius r_b = r_p cos α, tip radius r_a = r_p + m, root radius r_f = r_p − 1.25 m, tooth thickness on the
//! pitch circle π m / 2. Each flank is the involute of the base circle,
//! `P(t) = r_b (cos(β + t) + t sin(β + t), sin(β + t) − t cos(β + t))`, whose polar angle is `β + t − atan t`;
//! β = −(π / 2z + inv α) puts the pitch point at half the tooth thickness (inv α = tan α − α). Below the base
//! circle (when r_f < r_b) the flank continues as a radial line, tangent to the involute where they meet, so one
//! flank is one smooth face. The tip and the root are circular arcs. There is no root fillet: flank and root
//! meet at a sharp edge (a good approximation of a hobbed gear for illustration, not for stress analysis).
//!
//! Object frame: the gear axis is z, faces at z = ±face_width/2; tooth 0 is centred on +x.
//!
//! B-rep faces: 2 planar faces (each with the bore as a hole), per tooth 2 flanks (extruded involutes), a tip
//! and a root land (cylinders), and the bore (cylinder): 2 + 4 z + 1.

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3, Vec3};

use crate::detmath;
use crate::solid::{GeometryError, SolidBuilder, Surface, TriMesh, ring, ring_normals};

/// Default module (pitch diameter per tooth), in metres.
pub const DEFAULT_MODULE: f64 = 0.002;
/// Default number of teeth.
pub const DEFAULT_TEETH: usize = 20;
/// Default pressure angle, in degrees.
pub const DEFAULT_PRESSURE_ANGLE_DEG: f64 = 20.0;

/// Parameters of the spur gear (metres). See the module docs for the construction and frame.
#[derive(Debug, Clone, PartialEq)]
pub struct SpurGear {
    /// Module m. Default [`DEFAULT_MODULE`]; > 0.
    pub module: f64,
    /// Number of teeth z. Default [`DEFAULT_TEETH`]; 8 or more.
    pub teeth: usize,
    /// Pressure angle α in degrees. Default [`DEFAULT_PRESSURE_ANGLE_DEG`]; (0, 35).
    pub pressure_angle_deg: f64,
    /// Width along the axis. Default 0.01.
    pub face_width: f64,
    /// Radius of the bore. Default 0.0062 (a sliding fit on a 12 mm shaft); below the root radius.
    pub bore_radius: f64,
    /// Segments along each involute (from the base or root circle to the tip). Default 6.
    pub flank_segments: usize,
    /// Segments along each tip land. Default 3.
    pub tip_segments: usize,
    /// Segments along each root land. Default 4.
    pub root_segments: usize,
    /// Segments around the bore. Default 32.
    pub bore_segments: usize,
}

impl Default for SpurGear {
    fn default() -> Self {
        Self {
            module: DEFAULT_MODULE,
            teeth: DEFAULT_TEETH,
            pressure_angle_deg: DEFAULT_PRESSURE_ANGLE_DEG,
            face_width: 0.01,
            bore_radius: 0.0062,
            flank_segments: 6,
            tip_segments: 3,
            root_segments: 4,
            bore_segments: 32,
        }
    }
}

/// A run of profile points forming one side face, with the face's own normal at each point.
#[derive(Debug, Clone)]
struct ProfileFace {
    surface: Surface,
    /// Indices into the profile loop.
    points: Vec<usize>,
    /// Outward unit normals in the x-y plane, one per point.
    normals: Vec<DVec2>,
}

impl SpurGear {
    /// Pitch radius r_p = m z / 2.
    pub fn pitch_radius(&self) -> f64 {
        self.module * self.teeth as f64 / 2.0
    }

    /// Tip (addendum) radius r_a = r_p + m.
    pub fn tip_radius(&self) -> f64 {
        self.pitch_radius() + self.module
    }

    /// Root (dedendum) radius r_f = r_p − 1.25 m.
    pub fn root_radius(&self) -> f64 {
        self.pitch_radius() - 1.25 * self.module
    }

    /// The closed tooth profile, counter-clockwise, as f64 points, and its side faces.
    fn profile(&self) -> Result<(Vec<DVec2>, Vec<ProfileFace>), GeometryError> {
        let alpha = self.pressure_angle_deg.to_radians();
        let (rp, ra, rf) = (self.pitch_radius(), self.tip_radius(), self.root_radius());
        let rb = rp * detmath::cos(alpha);
        let involute_alpha = detmath::tan(alpha) - alpha;
        let beta = -(PI / (2.0 * self.teeth as f64) + involute_alpha);
        let roll = |r: f64| ((r / rb).powi(2) - 1.0).max(0.0).sqrt();
        let polar = |t: f64| beta + t - detmath::atan(t);
        let start_radius = rf.max(rb);
        let (t_start, t_tip) = (roll(start_radius), roll(ra));
        let (start_angle, tip_angle) = (polar(t_start), polar(t_tip));
        let pitch_angle = TAU / self.teeth as f64;
        let fits = self.teeth >= 8
            && self.module > 0.0
            && self.face_width > 0.0
            && alpha > 0.0
            && alpha < 35f64.to_radians()
            && tip_angle < 0.0
            && pitch_angle + 2.0 * start_angle > 0.0
            && self.bore_radius > 0.0
            && self.bore_radius < rf
            && self.flank_segments >= 1
            && self.tip_segments >= 1
            && self.root_segments >= 1
            && self.bore_segments >= 3;
        if !fits {
            return Err(GeometryError::BadParameters("gear teeth must not overlap or come to a point"));
        }

        // Right flank (the clockwise side of tooth 0), from the root upwards, in the tooth's own frame.
        let mut right: Vec<(DVec2, DVec2)> = Vec::new();
        let (sb, cb) = detmath::sin_cos(beta);
        if rf < rb {
            right.push((DVec2::new(rf * cb, rf * sb), DVec2::new(sb, -cb)));
        }
        for i in 0..=self.flank_segments {
            let r = start_radius + (ra - start_radius) * i as f64 / self.flank_segments as f64;
            let t = roll(r);
            let (s, c) = detmath::sin_cos(beta + t);
            let point = DVec2::new(c + t * s, s - t * c) * rb;
            right.push((point, DVec2::new(s, -c)));
        }
        let radial = |angle: f64| {
            let (s, c) = detmath::sin_cos(angle);
            DVec2::new(c, s)
        };
        let tip_inner: Vec<DVec2> = (1..self.tip_segments)
            .map(|j| radial(tip_angle - 2.0 * tip_angle * j as f64 / self.tip_segments as f64) * ra)
            .collect();
        let left: Vec<(DVec2, DVec2)> =
            right.iter().rev().map(|&(p, n)| (p * DVec2::new(1.0, -1.0), n * DVec2::new(1.0, -1.0))).collect();
        let root_inner: Vec<DVec2> = (1..self.root_segments)
            .map(|j| {
                let from = -start_angle;
                radial(from + (pitch_angle + 2.0 * start_angle) * j as f64 / self.root_segments as f64) * rf
            })
            .collect();

        let per_tooth = 2 * right.len() + tip_inner.len() + root_inner.len();
        let total = per_tooth * self.teeth;
        let mut points = Vec::with_capacity(total);
        let mut faces = Vec::with_capacity(4 * self.teeth);
        for k in 0..self.teeth {
            let (s, c) = detmath::sin_cos(pitch_angle * k as f64);
            let rotate = |p: DVec2| DVec2::new(p.x * c - p.y * s, p.x * s + p.y * c);
            let base = points.len();
            let flank = |points: &mut Vec<DVec2>, side: &[(DVec2, DVec2)]| ProfileFace {
                surface: Surface::Extrusion,
                points: side
                    .iter()
                    .map(|&(p, _)| {
                        points.push(rotate(p));
                        points.len() - 1
                    })
                    .collect(),
                normals: side.iter().map(|&(_, n)| rotate(n)).collect(),
            };
            let right_face = flank(&mut points, &right);
            points.extend(tip_inner.iter().map(|&p| rotate(p)));
            let left_face = flank(&mut points, &left);
            points.extend(root_inner.iter().map(|&p| rotate(p)));
            // Tip: last right-flank point, the inner tip points, first left-flank point.
            let tip_points: Vec<usize> = (base + right.len() - 1..=base + right.len() + tip_inner.len()).collect();
            // Root: last left-flank point, the inner root points, first point of the next tooth.
            let root_first = base + 2 * right.len() + tip_inner.len() - 1;
            let root_points: Vec<usize> =
                (root_first..root_first + root_inner.len() + 1).chain([(base + per_tooth) % total]).collect();
            // Arc normals are radial (the point's direction); filled in below, once every tooth exists.
            let arc = |points: Vec<usize>| ProfileFace { surface: Surface::Cylinder, points, normals: Vec::new() };
            faces.push(right_face);
            faces.push(arc(tip_points));
            faces.push(left_face);
            faces.push(arc(root_points));
        }
        // The last root land ends on tooth 0's first point, so arc normals are computed after the loop.
        for face in &mut faces {
            if face.surface == Surface::Cylinder {
                face.normals = face.points.iter().map(|&i| points[i].normalize()).collect();
            }
        }
        Ok((points, faces))
    }

    /// Tessellates the gear.
    pub fn build(&self) -> Result<TriMesh, GeometryError> {
        let (profile, faces) = self.profile()?;
        let half_w = self.face_width / 2.0;
        let sides: [Vec<Vec3>; 2] =
            [-half_w, half_w].map(|z| profile.iter().map(|p| DVec3::new(p.x, p.y, z).as_vec3()).collect());
        let n = self.bore_segments;
        let bore: [Vec<Vec3>; 2] =
            [-half_w, half_w].map(|z| ring(DVec3::new(0.0, 0.0, z), DVec3::X, DVec3::Y, self.bore_radius, n, 0.0));

        let mut solid = SolidBuilder::new();
        solid.planar_face(-DVec3::Z, &sides[0], &[&bore[0]])?;
        solid.planar_face(DVec3::Z, &sides[1], &[&bore[1]])?;
        for face in &faces {
            let rows: [Vec<Vec3>; 2] = [0, 1].map(|side| face.points.iter().map(|&i| sides[side][i]).collect());
            let normals: Vec<DVec3> = face.normals.iter().map(|n| n.extend(0.0)).collect();
            solid.ruled_face(face.surface, [&rows[0], &rows[1]], [&normals, &normals], false)?;
        }
        let inward = ring_normals(DVec3::X, DVec3::Y, n, 0.0, -1.0);
        solid.ruled_face(Surface::Cylinder, [&bore[0], &bore[1]], [&inward, &inward], true)?;
        Ok(solid.finish())
    }

    /// Area of the tooth profile polygon minus the bore polygon (the exact cross-section of the tessellation).
    pub fn section_area(&self) -> Result<f64, GeometryError> {
        let (profile, _) = self.profile()?;
        let outer: Vec<[f64; 2]> = profile.iter().map(|p| [p.x, p.y]).collect();
        let n = self.bore_segments as f64;
        let bore = 0.5 * n * self.bore_radius.powi(2) * detmath::sin(TAU / n);
        Ok(crate::triangulate::signed_area(&outer) - bore)
    }
}
