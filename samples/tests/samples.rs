//! Checks the committed samples: up to date, deterministic, structurally as documented, and every mesh a closed,
//! consistently oriented solid of the expected genus and volume once welded by position.
//!
//! The GLB files are read back with a reader written here (not the generator's writer), and volumes and genera
//! are computed from the part parameters independently of the tessellation.

use std::collections::{BTreeMap, BTreeSet};
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use drafter_samples::parts::{BasePlate, Bracket, FlangedShaft, HexBolt, HexNut, SpurGear};
use serde_json::Value;

const SAMPLE_FILES: [&str; 4] = ["bracket.glb", "gear.glb", "shaft.glb", "assembly.glb"];

fn committed_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A GLB read back: its JSON and BIN chunk.
struct Glb {
    json: Value,
    bin: Vec<u8>,
}

fn u32_at(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
}

/// Reads a sample back through drafter-core's GLB framer, checking what the samples promise beyond a valid
/// container: the declared length is the file's, both chunks are padded to 4 bytes and nothing follows BIN.
fn read_glb(bytes: &[u8]) -> Glb {
    let chunks = drafter_format::glb::split(bytes).expect("valid GLB container");
    assert_eq!(u32_at(bytes, 8) as usize, bytes.len(), "declared length");
    assert_eq!(chunks.json.len() % 4, 0, "JSON chunk padded to 4 bytes");
    let json: Value = serde_json::from_slice(chunks.json).expect("JSON chunk parses");
    let bin = chunks.bin.expect("BIN chunk");
    assert_eq!(bin.len() % 4, 0, "BIN chunk padded to 4 bytes");
    assert_eq!(12 + 8 + chunks.json.len() + 8 + bin.len(), bytes.len(), "nothing after the BIN chunk");
    Glb { json, bin: bin.to_vec() }
}

/// One mesh read back from a GLB.
struct MeshData {
    name: String,
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    /// (surface, first triangle, triangle count) from `extras.brepFaces`.
    faces: Vec<(String, usize, usize)>,
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().expect("an unsigned integer") as usize
}

fn accessor_bytes(glb: &Glb, accessor: usize) -> (&Value, &[u8]) {
    let acc = &glb.json["accessors"][accessor];
    let view = &glb.json["bufferViews"][usize_of(&acc["bufferView"])];
    let offset = usize_of(&view["byteOffset"]) + acc.get("byteOffset").map_or(0, usize_of);
    let length = usize_of(&view["byteLength"]);
    assert_eq!(offset % 4, 0, "accessor aligned");
    assert!(view.get("byteStride").is_none(), "tightly packed");
    (acc, &glb.bin[offset..usize_of(&view["byteOffset"]) + length])
}

fn read_vec3(glb: &Glb, accessor: usize) -> Vec<[f32; 3]> {
    let (acc, bytes) = accessor_bytes(glb, accessor);
    assert_eq!(acc["componentType"], 5126);
    assert_eq!(acc["type"], "VEC3");
    let count = usize_of(&acc["count"]);
    (0..count)
        .map(|i| {
            [0, 1, 2]
                .map(|c| f32::from_le_bytes(bytes[12 * i + 4 * c..12 * i + 4 * c + 4].try_into().expect("4 bytes")))
        })
        .collect()
}

fn read_meshes(glb: &Glb) -> Vec<MeshData> {
    let views = glb.json["bufferViews"].as_array().expect("bufferViews");
    for view in views {
        assert_eq!(usize_of(&view["byteOffset"]) % 4, 0, "views start on 4 bytes");
        assert!(view["target"] == 34962 || view["target"] == 34963, "views have a target");
    }
    let mut meshes = Vec::new();
    for mesh in glb.json["meshes"].as_array().expect("meshes") {
        let primitives = mesh["primitives"].as_array().expect("primitives");
        assert_eq!(primitives.len(), 1);
        let primitive = &primitives[0];
        let position_acc = usize_of(&primitive["attributes"]["POSITION"]);
        let positions = read_vec3(glb, position_acc);
        let normals = read_vec3(glb, usize_of(&primitive["attributes"]["NORMAL"]));
        // min / max are required on POSITION and must be the exact extremes (compared in f32: serde_json's
        // default float parser may be 1 f64 ulp off, which rounding to f32 absorbs).
        let acc = &glb.json["accessors"][position_acc];
        for c in 0..3 {
            let min = positions.iter().map(|p| p[c]).fold(f32::INFINITY, f32::min);
            let max = positions.iter().map(|p| p[c]).fold(f32::NEG_INFINITY, f32::max);
            assert_eq!(acc["min"][c].as_f64().map(|v| v as f32), Some(min));
            assert_eq!(acc["max"][c].as_f64().map(|v| v as f32), Some(max));
        }
        let (acc, bytes) = accessor_bytes(glb, usize_of(&primitive["indices"]));
        let count = usize_of(&acc["count"]);
        let indices: Vec<u32> = match acc["componentType"].as_u64() {
            Some(5123) => {
                assert!(positions.len() <= 65535, "u16 indices only when they fit");
                (0..count).map(|i| u32::from(u16::from_le_bytes([bytes[2 * i], bytes[2 * i + 1]]))).collect()
            }
            Some(5125) => {
                assert!(positions.len() > 65535, "u32 indices only when u16 do not fit");
                (0..count).map(|i| u32_at(bytes, 4 * i)).collect()
            }
            other => panic!("unexpected index type {other:?}"),
        };
        assert_eq!(count % 3, 0);
        let faces = primitive["extras"]["brepFaces"]
            .as_array()
            .expect("brepFaces")
            .iter()
            .map(|f| (f[0].as_str().expect("surface").to_owned(), usize_of(&f[1]), usize_of(&f[2])))
            .collect();
        meshes.push(MeshData {
            name: mesh["name"].as_str().expect("mesh name").to_owned(),
            positions,
            normals,
            triangles: indices.chunks(3).map(|t| [t[0], t[1], t[2]]).collect(),
            faces,
        });
    }
    meshes
}

/// What the parameters say a mesh must be: its B-rep face count, genus and volume.
struct Expected {
    faces: usize,
    genus: i64,
    volume: f64,
}

/// Area of the regular n-gon inscribed in a circle of radius r (how every circle is tessellated).
fn ngon_area(r: f64, n: usize) -> f64 {
    0.5 * n as f64 * r * r * (TAU / n as f64).sin()
}

/// Volume of a frustum between two similar, aligned regular n-gons.
fn ngon_frustum(r0: f64, r1: f64, height: f64, n: usize) -> f64 {
    let (a0, a1) = (ngon_area(r0, n), ngon_area(r1, n));
    height / 3.0 * (a0 + a1 + (a0 * a1).sqrt())
}

fn hexagon_area(across_flats: f64) -> f64 {
    3f64.sqrt() / 2.0 * across_flats * across_flats
}

fn expected(mesh_name: &str) -> Expected {
    match mesh_name {
        "l_bracket" => {
            let b = Bracket::default();
            let section = b.base_length * b.thickness + (b.height - b.thickness) * b.thickness;
            let holes = 2.0 * ngon_area(b.base_hole_radius, b.hole_segments) * b.thickness
                + 2.0 * ngon_area(b.upright_hole_radius, b.hole_segments) * b.thickness;
            Expected { faces: 12, genus: 4, volume: section * b.width - holes }
        }
        "spur_gear" => {
            let g = SpurGear::default();
            let volume = g.section_area().expect("gear profile") * g.face_width;
            Expected { faces: 2 + 4 * g.teeth + 1, genus: 1, volume }
        }
        "flanged_shaft" => {
            let s = FlangedShaft::default();
            let stations = s.stations();
            let mut volume = 0.0;
            for w in stations.windows(2) {
                volume += ngon_frustum(w[0][0], w[1][0], w[1][1] - w[0][1], s.segments);
            }
            volume -= s.flange_holes as f64 * ngon_area(s.flange_hole_radius, s.hole_segments) * s.flange_thickness;
            Expected { faces: 11 + s.flange_holes, genus: s.flange_holes as i64, volume }
        }
        "hex_bolt_m6" => {
            let b = HexBolt::default();
            let head = hexagon_area(b.across_flats) * b.head_height;
            let shank = ngon_area(b.shank_radius, b.segments) * (b.length - b.chamfer)
                + ngon_frustum(b.shank_radius - b.chamfer, b.shank_radius, b.chamfer, b.segments);
            Expected { faces: 11, genus: 0, volume: head + shank }
        }
        "hex_nut_m6" => {
            let n = HexNut::default();
            let volume = (hexagon_area(n.across_flats) - ngon_area(n.hole_radius, n.segments)) * n.height;
            Expected { faces: 9, genus: 1, volume }
        }
        "base_plate" => {
            let p = BasePlate::default();
            let holes: f64 = p.holes.iter().map(|h| ngon_area(h.radius, p.hole_segments)).sum();
            Expected {
                faces: 6 + p.holes.len(),
                genus: p.holes.len() as i64,
                volume: (p.length * p.depth - holes) * p.thickness,
            }
        }
        other => panic!("no expectation for mesh {other}"),
    }
}

/// Welds by exact bit equality and checks the solid is closed, oriented, of the expected genus and volume.
fn check_closed_solid(mesh: &MeshData) {
    let name = &mesh.name;
    let expected = expected(name);
    let mut ids: BTreeMap<[u32; 3], u32> = BTreeMap::new();
    let welded: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p.map(f32::to_bits)).or_insert(next)
        })
        .collect();
    // No near-misses: distinct welded positions are far apart (a crack would show as a pair 1 ulp apart).
    let unique: Vec<[f32; 3]> = ids.keys().map(|b| b.map(f32::from_bits)).collect();
    for (i, a) in unique.iter().enumerate() {
        for b in &unique[i + 1..] {
            let d2: f32 = (0..3).map(|c| (a[c] - b[c]).powi(2)).sum();
            assert!(d2 > 1e-12, "{name}: welded positions {a:?} and {b:?} almost coincide");
        }
    }
    let mut directed: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for t in &mesh.triangles {
        let w = t.map(|i| welded[i as usize]);
        assert!(w[0] != w[1] && w[1] != w[2] && w[2] != w[0], "{name}: degenerate welded triangle {t:?}");
        for e in 0..3 {
            *directed.entry((w[e], w[(e + 1) % 3])).or_default() += 1;
        }
    }
    let mut undirected: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    for (&(a, b), &count) in &directed {
        assert_eq!(count, 1, "{name}: directed edge {a}->{b} used {count} times (inconsistent orientation)");
        assert!(directed.contains_key(&(b, a)), "{name}: edge {a}->{b} has no twin (open boundary)");
        *undirected.entry((a.min(b), a.max(b))).or_default() += count;
    }
    assert!(undirected.values().all(|&v| v == 2), "{name}: every edge has valence 2");
    let (v, e, f) = (ids.len() as i64, undirected.len() as i64, mesh.triangles.len() as i64);
    assert_eq!(v - e + f, 2 - 2 * expected.genus, "{name}: Euler characteristic (V {v}, E {e}, F {f})");

    let volume: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
            let cross = [b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2], b[0] * c[1] - b[1] * c[0]];
            (a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2]) / 6.0
        })
        .sum();
    let relative = (volume - expected.volume).abs() / expected.volume;
    assert!(relative < 1e-5, "{name}: volume {volume:e} m³ vs expected {:e} (outward winding)", expected.volume);
    assert_eq!(mesh.faces.len(), expected.faces, "{name}: B-rep face count");
}

/// Checks the CAD-style patches: faces tile the triangles, share no vertex, planes are flat, normals are unit and
/// agree with the winding.
fn check_patches(mesh: &MeshData) {
    let name = &mesh.name;
    let mut next_triangle = 0;
    let mut owner: Vec<Option<usize>> = vec![None; mesh.positions.len()];
    for (face, (surface, first, count)) in mesh.faces.iter().enumerate() {
        assert_eq!(*first, next_triangle, "{name}: faces are contiguous");
        next_triangle += count;
        let triangles = &mesh.triangles[*first..first + count];
        for &i in triangles.iter().flatten() {
            let slot = &mut owner[i as usize];
            assert!(slot.is_none_or(|f| f == face), "{name}: vertex {i} shared by faces {slot:?} and {face}");
            *slot = Some(face);
        }
        if surface == "plane" {
            let n0 = mesh.normals[triangles[0][0] as usize];
            assert!(
                triangles.iter().flatten().all(|&i| mesh.normals[i as usize] == n0),
                "{name}: face {face} not flat"
            );
        }
    }
    assert_eq!(next_triangle, mesh.triangles.len(), "{name}: faces cover every triangle");
    assert!(owner.iter().all(Option::is_some), "{name}: every vertex is used");
    for n in &mesh.normals {
        let len = n.iter().map(|c| f64::from(*c).powi(2)).sum::<f64>().sqrt();
        assert!((len - 1.0).abs() < 1e-6, "{name}: normal {n:?} not unit");
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].map(f64::from));
        let (u, v) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
        let g = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        let g_len = g.iter().map(|x| x * x).sum::<f64>().sqrt();
        assert!(g_len > 0.0, "{name}: zero-area triangle {t:?}");
        for &i in t {
            let n = mesh.normals[i as usize].map(f64::from);
            let cos = (g[0] * n[0] + g[1] * n[1] + g[2] * n[2]) / g_len;
            assert!(cos > 0.5, "{name}: triangle {t:?} disagrees with its vertex normal (cos {cos})");
        }
    }
}

fn generated() -> Vec<(&'static str, Vec<u8>)> {
    drafter_samples::sample_files().expect("samples generate")
}

#[test]
fn committed_samples_are_up_to_date() {
    let dir = std::env::temp_dir().join(format!("drafter-samples-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let written = drafter_samples::write_samples(&dir).expect("samples are written");
    let names: Vec<String> =
        written.iter().map(|(p, _)| p.file_name().expect("file name").to_string_lossy().into_owned()).collect();
    assert_eq!(names, SAMPLE_FILES);
    for name in SAMPLE_FILES {
        let fresh = std::fs::read(dir.join(name)).expect("regenerated file");
        let committed_path = committed_dir().join(name);
        let committed = std::fs::read(&committed_path).unwrap_or_else(|e| {
            panic!("{}: {e}; run `cargo run -p drafter-samples --release`", committed_path.display())
        });
        assert!(
            fresh == committed,
            "{} is stale ({} bytes committed, {} generated): run `cargo run -p drafter-samples --release`",
            committed_path.display(),
            committed.len(),
            fresh.len()
        );
    }
    std::fs::remove_dir_all(&dir).expect("temp dir removed");
}

#[test]
fn generation_is_deterministic() {
    assert_eq!(generated(), generated());
}

#[test]
fn every_mesh_is_a_closed_solid_made_of_cad_patches() {
    let mut checked = BTreeSet::new();
    for (file, bytes) in generated() {
        let glb = read_glb(&bytes);
        assert_eq!(glb.json["asset"]["generator"], "drafter-samples", "{file}");
        assert_eq!(glb.json["asset"]["version"], "2.0", "{file}");
        for mesh in read_meshes(&glb) {
            check_closed_solid(&mesh);
            check_patches(&mesh);
            checked.insert(mesh.name);
        }
    }
    let all: BTreeSet<String> =
        ["l_bracket", "spur_gear", "flanged_shaft", "hex_bolt_m6", "hex_nut_m6", "base_plate"].map(String::from).into();
    assert_eq!(checked, all, "every part was checked");
}

/// Column-major 4×4 product a · b.
fn mul(a: &[f64; 16], b: &[f64; 16]) -> [f64; 16] {
    let mut m = [0.0; 16];
    for col in 0..4 {
        for row in 0..4 {
            m[4 * col + row] = (0..4).map(|k| a[4 * k + row] * b[4 * col + k]).sum();
        }
    }
    m
}

/// A node's local matrix from its JSON (matrix, or TRS).
fn local_matrix(node: &Value) -> [f64; 16] {
    let nums = |key: &str, default: &[f64]| -> Vec<f64> {
        node.get(key).map_or(default.to_vec(), |v| {
            v.as_array().expect("array").iter().map(|x| x.as_f64().expect("number")).collect()
        })
    };
    if let Some(m) = node.get("matrix") {
        assert!(node.get("translation").is_none() && node.get("rotation").is_none() && node.get("scale").is_none());
        return m
            .as_array()
            .expect("matrix")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect::<Vec<_>>()
            .try_into()
            .expect("16");
    }
    let (t, q, s) = (nums("translation", &[0.0; 3]), nums("rotation", &[0.0, 0.0, 0.0, 1.0]), nums("scale", &[1.0; 3]));
    let (x, y, z, w) = (q[0], q[1], q[2], q[3]);
    assert!(((x * x + y * y + z * z + w * w) - 1.0).abs() < 1e-12, "unit quaternion");
    let r = [
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y + z * w),
        2.0 * (x * z - y * w),
        2.0 * (x * y - z * w),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z + x * w),
        2.0 * (x * z + y * w),
        2.0 * (y * z - x * w),
        1.0 - 2.0 * (x * x + y * y),
    ];
    [
        r[0] * s[0],
        r[1] * s[0],
        r[2] * s[0],
        0.0,
        r[3] * s[1],
        r[4] * s[1],
        r[5] * s[1],
        0.0,
        r[6] * s[2],
        r[7] * s[2],
        r[8] * s[2],
        0.0,
        t[0],
        t[1],
        t[2],
        1.0,
    ]
}

fn det3(m: &[f64; 16]) -> f64 {
    m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2])
}

#[test]
fn assembly_has_hierarchy_instancing_a_mirror_and_materials() {
    let (_, bytes) = generated().into_iter().find(|(f, _)| *f == "assembly.glb").expect("assembly generated");
    let glb = read_glb(&bytes);
    let json = &glb.json;
    let nodes = json["nodes"].as_array().expect("nodes");
    let scene_roots = json["scenes"][0]["nodes"].as_array().expect("scene nodes");
    assert_eq!(scene_roots.len(), 1);
    let root = usize_of(&scene_roots[0]);
    assert_eq!(nodes[root]["name"], "assembly");

    // Walk the tree: depth, world matrices, instances per mesh.
    let mut stack = vec![(root, 1usize, local_matrix(&nodes[root]))];
    let mut visited = BTreeSet::new();
    let mut max_depth = 0;
    let mut instances: BTreeMap<usize, usize> = BTreeMap::new();
    let mut mirrored = Vec::new();
    let mut world_triangles = 0;
    while let Some((index, depth, world)) = stack.pop() {
        assert!(visited.insert(index), "node {index} reached twice");
        let node = &nodes[index];
        max_depth = max_depth.max(depth);
        if let Some(mesh) = node.get("mesh") {
            *instances.entry(usize_of(mesh)).or_default() += 1;
            if det3(&world) < 0.0 {
                mirrored.push(node["name"].as_str().expect("name").to_owned());
            }
            let indices = usize_of(&json["meshes"][usize_of(mesh)]["primitives"][0]["indices"]);
            world_triangles += usize_of(&json["accessors"][indices]["count"]) / 3;
        }
        for child in node.get("children").and_then(Value::as_array).into_iter().flatten() {
            let child = usize_of(child);
            stack.push((child, depth + 1, mul(&world, &local_matrix(&nodes[child]))));
        }
    }
    assert_eq!(visited.len(), nodes.len(), "every node is in the scene");
    assert_eq!(nodes.len(), 23);
    assert!(max_depth >= 4, "assembly → sub-assembly → … → part, depth {max_depth}");
    assert_eq!(mirrored, ["bracket_left_mirrored"], "exactly one mirrored instance");
    assert!(nodes.iter().any(|n| n.get("matrix").is_some()), "a node with a matrix");
    assert!(nodes.iter().any(|n| n.get("rotation").is_some()), "a node with TRS rotation");

    let meshes = json["meshes"].as_array().expect("meshes");
    let mesh_names: Vec<&str> = meshes.iter().map(|m| m["name"].as_str().expect("name")).collect();
    assert_eq!(mesh_names, ["l_bracket", "spur_gear", "flanged_shaft", "hex_bolt_m6", "hex_nut_m6", "base_plate"]);
    let counts: Vec<usize> = (0..meshes.len()).map(|m| instances[&m]).collect();
    assert_eq!(counts, [2, 2, 2, 4, 4, 1], "instances per mesh (each mesh stored once)");
    assert!((5_000..=30_000).contains(&world_triangles), "{world_triangles} triangles drawn");

    let materials = json["materials"].as_array().expect("materials");
    let material =
        |name: &str| materials.iter().find(|m| m["name"] == name).unwrap_or_else(|| panic!("material {name}"));
    assert_eq!(material("steel")["pbrMetallicRoughness"]["metallicFactor"], 1.0);
    assert_eq!(material("steel")["pbrMetallicRoughness"]["roughnessFactor"], 0.35);
    assert_eq!(material("painted aluminium")["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    assert!(material("painted aluminium")["pbrMetallicRoughness"]["baseColorFactor"].is_array());
    assert_eq!(material("brass")["pbrMetallicRoughness"]["metallicFactor"], 1.0);
    assert_eq!(materials.len(), 4);
}

#[test]
fn samples_stay_small() {
    let total: usize = generated().iter().map(|(_, b)| b.len()).sum();
    assert!(total < 500_000, "samples total {total} bytes");
}

#[test]
fn single_part_files_hold_one_node_and_one_mesh() {
    for (file, bytes) in generated().into_iter().filter(|(f, _)| *f != "assembly.glb") {
        let glb = read_glb(&bytes);
        assert_eq!(glb.json["nodes"].as_array().map(Vec::len), Some(1), "{file}");
        assert_eq!(glb.json["meshes"].as_array().map(Vec::len), Some(1), "{file}");
        assert_eq!(glb.json["materials"].as_array().map(Vec::len), Some(1), "{file}");
        let stem = Path::new(file).file_stem().and_then(|s| s.to_str()).expect("stem");
        assert_eq!(glb.json["nodes"][0]["name"], stem);
    }
}
