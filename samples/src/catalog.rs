//! The committed samples: three single parts and the assembly, as glTF documents.
//!
//! The assembly is a small gear drive on a base plate (metres, y up):
//!
//! ```text
//! assembly
//! ├── base_plate                          mesh base_plate
//! ├── frame
//! │   ├── bracket_right                   mesh l_bracket, translation
//! │   ├── bracket_left_mirrored           mesh l_bracket, scale (−1, 1, 1): the mirrored instance
//! │   └── fasteners
//! │       └── bolted_joint_1..4           translation + rotation (bolt axis z → y)
//! │           ├── bolt_k                  mesh hex_bolt_m6
//! │           └── nut_k                   mesh hex_nut_m6, translation
//! └── drive                               matrix (shaft axis z → world x)
//!     ├── shaft_input                     mesh flanged_shaft, translation
//!     │   └── gear_input                  mesh spur_gear, translation
//!     └── shaft_output                    mesh flanged_shaft, translation
//!         └── gear_output                 mesh spur_gear, translation + rotation by half a tooth (meshing)
//! ```
//!
//! The brackets stand on the plate facing each other, their base plates pointing outwards; each is held by two
//! bolts through its base holes and the plate, with nuts underneath. The two shafts run through both brackets'
//! upright holes; their gears sit next to the flanges and mesh (centre distance = pitch diameter). Six meshes are
//! stored once and drawn by 15 nodes.

use std::f64::consts::FRAC_PI_4;

use crate::detmath;
use crate::glb::{Document, Material, MaterialId, Transform};
use crate::parts::{BasePlate, Bracket, FlangedShaft, HexBolt, HexNut, SpurGear};
use crate::solid::{GeometryError, TriMesh};

/// Inner distance between the two brackets' uprights in the assembly, in metres.
pub const UPRIGHT_GAP: f64 = 0.07;

/// One sample file: its name and its document.
#[derive(Debug, Clone)]
pub struct Sample {
    /// File name, e.g. "gear.glb".
    pub file_name: &'static str,
    /// The document written to it.
    pub document: Document,
}

/// Steel: metallic, fairly smooth.
pub fn steel() -> Material {
    Material { name: "steel".into(), base_color: [0.56, 0.57, 0.58, 1.0], metallic: 1.0, roughness: 0.35 }
}

/// Painted aluminium: a blue dielectric coat.
pub fn painted_aluminium() -> Material {
    Material { name: "painted aluminium".into(), base_color: [0.1, 0.27, 0.6, 1.0], metallic: 0.0, roughness: 0.5 }
}

/// Brass: yellow metal.
pub fn brass() -> Material {
    Material { name: "brass".into(), base_color: [0.91, 0.78, 0.42, 1.0], metallic: 1.0, roughness: 0.3 }
}

/// Painted cast iron: a matte dark grey coat.
pub fn painted_cast_iron() -> Material {
    Material { name: "painted cast iron".into(), base_color: [0.25, 0.26, 0.27, 1.0], metallic: 0.0, roughness: 0.8 }
}

/// A document with one node drawing one mesh.
fn single_part(name: &str, mesh_name: &str, geometry: TriMesh, material: Material) -> Document {
    let mut doc = Document::new(name);
    let material = doc.add_material(material);
    let mesh = doc.add_mesh(mesh_name, geometry, material);
    doc.add_node(None, name, Transform::Identity, Some(mesh));
    doc
}

/// Unit quaternion (x, y, z, w) of a rotation by `angle` radians about a coordinate axis (0 = x, 1 = y, 2 = z).
fn axis_rotation(axis: usize, angle: f64) -> [f64; 4] {
    let (s, c) = detmath::sin_cos(angle / 2.0);
    let mut q = [0.0, 0.0, 0.0, c];
    q[axis] = s;
    q
}

/// All samples, in a fixed order.
pub fn samples() -> Result<Vec<Sample>, GeometryError> {
    let gear = SpurGear::default();
    let shaft = FlangedShaft::default();
    let bracket = Bracket { upright_hole_spacing: 2.0 * gear.pitch_radius(), ..Bracket::default() };
    let bolt = HexBolt::default();
    let nut = HexNut::default();
    let plate = BasePlate::default();

    let bracket_mesh = bracket.build()?;
    let gear_mesh = gear.build()?;
    let shaft_mesh = shaft.build()?;
    Ok(vec![
        Sample {
            file_name: "bracket.glb",
            document: single_part("bracket", "l_bracket", bracket_mesh.clone(), painted_aluminium()),
        },
        Sample { file_name: "gear.glb", document: single_part("gear", "spur_gear", gear_mesh.clone(), brass()) },
        Sample { file_name: "shaft.glb", document: single_part("shaft", "flanged_shaft", shaft_mesh.clone(), steel()) },
        Sample {
            file_name: "assembly.glb",
            document: assembly(
                Parts { bracket: &bracket, gear: &gear, shaft: &shaft, nut: &nut, plate: &plate },
                [bracket_mesh, gear_mesh, shaft_mesh, bolt.build()?, nut.build()?, plate.build()?],
            ),
        },
    ])
}

/// Parameters the assembly's layout is derived from.
struct Parts<'a> {
    bracket: &'a Bracket,
    gear: &'a SpurGear,
    shaft: &'a FlangedShaft,
    nut: &'a HexNut,
    plate: &'a BasePlate,
}

/// The assembly document; `meshes` are bracket, gear, shaft, bolt, nut and plate.
fn assembly(parts: Parts<'_>, meshes: [TriMesh; 6]) -> Document {
    let Parts { bracket, gear, shaft, nut, plate } = parts;
    let mut doc = Document::new("assembly");
    let [steel, aluminium, brass, cast_iron]: [MaterialId; 4] =
        [steel(), painted_aluminium(), brass(), painted_cast_iron()].map(|m| doc.add_material(m));
    let [bracket_mesh, gear_mesh, shaft_mesh, bolt_mesh, nut_mesh, plate_mesh] = meshes;
    let bracket_mesh = doc.add_mesh("l_bracket", bracket_mesh, aluminium);
    let gear_mesh = doc.add_mesh("spur_gear", gear_mesh, brass);
    let shaft_mesh = doc.add_mesh("flanged_shaft", shaft_mesh, steel);
    let bolt_mesh = doc.add_mesh("hex_bolt_m6", bolt_mesh, steel);
    let nut_mesh = doc.add_mesh("hex_nut_m6", nut_mesh, steel);
    let plate_mesh = doc.add_mesh("base_plate", plate_mesh, cast_iron);

    let root = doc.add_node(None, "assembly", Transform::Identity, None);
    doc.add_node(Some(root), "base_plate", Transform::Identity, Some(plate_mesh));

    // Frame: two brackets on the plate, uprights facing each other across the gap, base plates outwards.
    let frame = doc.add_node(Some(root), "frame", Transform::Identity, None);
    let half_gap = UPRIGHT_GAP / 2.0;
    doc.add_node(Some(frame), "bracket_right", Transform::translation([half_gap, 0.0, 0.0]), Some(bracket_mesh));
    let mirrored =
        Transform::Trs { translation: [-half_gap, 0.0, 0.0], rotation: [0.0, 0.0, 0.0, 1.0], scale: [-1.0, 1.0, 1.0] };
    doc.add_node(Some(frame), "bracket_left_mirrored", mirrored, Some(bracket_mesh));
    let fasteners = doc.add_node(Some(frame), "fasteners", Transform::Identity, None);
    // Bolt axis (object z, head up) turned to world y: −90° about x. Bearing face on the bracket's base plate.
    let bolt_up = axis_rotation(0, -2.0 * FRAC_PI_4);
    let bolt_x = half_gap + bracket.base_hole_x;
    let bolt_z = bracket.base_hole_spacing / 2.0;
    let nut_drop = bracket.thickness + plate.thickness + nut.height;
    for (k, (sx, sz)) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)].into_iter().enumerate() {
        let joint = doc.add_node(
            Some(fasteners),
            &format!("bolted_joint_{}", k + 1),
            Transform::Trs {
                translation: [sx * bolt_x, bracket.thickness, sz * bolt_z],
                rotation: bolt_up,
                scale: [1.0; 3],
            },
            None,
        );
        doc.add_node(Some(joint), &format!("bolt_{}", k + 1), Transform::Identity, Some(bolt_mesh));
        doc.add_node(
            Some(joint),
            &format!("nut_{}", k + 1),
            Transform::translation([0.0, 0.0, -nut_drop]),
            Some(nut_mesh),
        );
    }

    // Drive: a matrix turning the shafts' axis (object z) to world +x (object x goes to world −z), centred.
    #[rustfmt::skip]
    let drive_matrix = [
        0.0, 0.0, -1.0, 0.0,
        0.0, 1.0, 0.0, 0.0,
        1.0, 0.0, 0.0, 0.0,
        -shaft.length / 2.0, 0.0, 0.0, 1.0,
    ];
    let drive = doc.add_node(Some(root), "drive", Transform::Matrix(drive_matrix), None);
    let centre_distance = 2.0 * gear.pitch_radius();
    let axis_height = bracket.upright_hole_height;
    let gear_z = shaft.flange_z + shaft.flange_thickness + gear.face_width / 2.0;
    let half_tooth = std::f64::consts::PI / gear.teeth as f64;
    for (name, side, turn) in [("input", 1.0, 0.0), ("output", -1.0, half_tooth)] {
        let shaft_node = doc.add_node(
            Some(drive),
            &format!("shaft_{name}"),
            Transform::translation([side * centre_distance / 2.0, axis_height, 0.0]),
            Some(shaft_mesh),
        );
        let gear_transform =
            Transform::Trs { translation: [0.0, 0.0, gear_z], rotation: axis_rotation(2, turn), scale: [1.0; 3] };
        doc.add_node(Some(shaft_node), &format!("gear_{name}"), gear_transform, Some(gear_mesh));
    }
    doc
}
