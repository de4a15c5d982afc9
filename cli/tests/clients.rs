//! Baked files in the clients that really consume them, under headless Chromium (SwiftShader
//! WebGL): three.js (GLTFLoader) loads them as plain models and sees the triangles our reader sees;
//! CesiumJS 1.145 draws their `EXT_mesh_primitive_edge_visibility` edges, checked on pixels.
//!
//! The harness is `tools/browser-test/run.mjs`; `scripts/test` installs Chromium and its npm
//! packages. These tests fail (never skip) when it is not installed.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn harness() -> PathBuf {
    let run = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/browser-test/run.mjs");
    let modules = run.with_file_name("node_modules");
    assert!(
        modules.is_dir() && Path::new("/usr/bin/chromium").exists(),
        "the browser-client harness is not installed: run scripts/test (it runs tools/browser-test/setup.sh)"
    );
    run
}

/// Runs `node run.mjs ARGS` and returns its one JSON line.
fn client(args: &[&str]) -> Value {
    let out = Command::new("node").arg(harness()).args(args).output().expect("node runs (scripts/test installs it)");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let json: Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("{args:?}: no JSON ({e}): {stdout} {}", String::from_utf8_lossy(&out.stderr)));
    assert!(out.status.success() && json["ok"] == true, "{args:?}: {json}");
    json
}

/// A closed cylinder as an OBJ: `segments` around the +Y axis, radius 1, height 2, caps as fans.
fn cylinder_obj(segments: u32) -> String {
    let mut obj = String::from("o cylinder\n");
    for y in [-1.0f64, 1.0] {
        for k in 0..segments {
            let a = -std::f64::consts::TAU * f64::from(k) / f64::from(segments);
            obj += &format!("v {} {y} {}\n", a.cos(), a.sin());
        }
    }
    obj += "v 0 -1 0\nv 0 1 0\n";
    let (bottom, top) = (2 * segments + 1, 2 * segments + 2);
    for k in 0..segments {
        let (a, b) = (k + 1, (k + 1) % segments + 1);
        let (c, d) = (b + segments, a + segments);
        obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\nf {bottom} {b} {a}\nf {top} {d} {c}\n");
    }
    obj
}

fn pixels(image: &Path, region: &str) -> u64 {
    let image = image.to_str().expect("utf-8 path");
    let json = client(&["pixels", image, "--color", "255,0,0", "--tol", "100", "--region", region]);
    json["match"]["count"].as_u64().expect("count")
}

#[test]
fn three_js_sees_the_triangles_our_reader_sees() {
    let dir = common::scratch("clients-three");
    let models = common::shared_models();
    let inputs = [
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb"),
        models.join("obj/common-3d-test-models/fandisk.obj"),
        models.join("gltf/RodAssembly/rod.glb"),
    ];
    for input in inputs {
        // Plain, and with EXT_meshopt_compression (three.js decodes it with its MeshoptDecoder).
        for extra in [&[][..], &["--compress"][..]] {
            let output = dir.join("baked.glb");
            common::bake(&input, &output, extra);
            let bytes = std::fs::read(&output).expect("baked");
            let ours = drafter_io::import_bytes(&output, &bytes).expect("imports").scene.instanced_triangle_count();
            let json = client(&["three", output.to_str().expect("utf-8")]);
            assert_eq!(json["triangles"].as_u64(), Some(ours as u64), "{} {extra:?}: {json}", input.display());
        }
    }
}

/// CesiumJS reads `--compress` files (EXT_meshopt_compression) and draws the same edges as from
/// the plain file: the same cylinder, the same view, pixel for pixel.
#[test]
fn cesium_draws_the_same_edges_from_a_compressed_file() {
    let dir = common::scratch("clients-cesium-compressed");
    let obj = dir.join("cylinder.obj");
    std::fs::write(&obj, cylinder_obj(64)).expect("writes");
    let mut shots = Vec::new();
    for (name, extra) in [("plain", &[][..]), ("compressed", &["--compress"][..])] {
        let baked = dir.join(format!("{name}.glb"));
        common::bake(&obj, &baked, extra);
        let shot = dir.join(format!("{name}.png"));
        let (file, image) = (baked.to_str().expect("utf-8"), shot.to_str().expect("utf-8"));
        client(&["cesium", file, "--view", "0,15", "--edge-color", "255,0,0", "--screenshot", image]);
        shots.push(shot);
    }
    let plain = std::fs::read(dir.join("plain.glb")).expect("plain");
    let packed = std::fs::read(dir.join("compressed.glb")).expect("compressed");
    assert!(packed.len() < plain.len(), "compressed {} B, plain {} B", packed.len(), plain.len());
    let whole = "0,0,800,600";
    let (a, b) = (pixels(&shots[0], whole), pixels(&shots[1], whole));
    assert!(a > 500, "the plain file drew only {a} edge pixels");
    assert_eq!(a, b, "edge pixels: plain {a}, compressed {b}");
}

/// The merged draft's `silhouetteNormals` (VEC3) as CesiumJS reads them: the curved side of a
/// cylinder carries no lines (the oct16 form of format 0.1 hatched it), the cap circles and the
/// outline are drawn. Edges are drawn red (`--edge-color` gives them a red material in memory) on
/// a white background, seen from the front and 15° above (the screenshot is in docs/img/clients/).
#[test]
fn cesium_draws_a_cylinder_with_its_outline_and_caps_only() {
    let dir = common::scratch("clients-cesium");
    let obj = dir.join("cylinder.obj");
    std::fs::write(&obj, cylinder_obj(64)).expect("writes");
    let baked = dir.join("cylinder.glb");
    common::bake(&obj, &baked, &[]);
    let shot = dir.join("cylinder-cesium.png");
    let (file, image) = (baked.to_str().expect("utf-8"), shot.to_str().expect("utf-8"));
    client(&["cesium", file, "--view", "0,15", "--edge-color", "255,0,0", "--screenshot", image]);

    // Regions of the 800×600 frame (the cylinder spans x 238..561, y 132..510).
    let face = pixels(&shot, "290,190,510,440");
    let top_cap = pixels(&shot, "200,110,600,180");
    let bottom_arc = pixels(&shot, "260,470,540,520");
    let left_outline = pixels(&shot, "225,190,280,440");
    assert_eq!(face, 0, "lines across the curved face: silhouette normals misread");
    assert!(top_cap >= 300, "top cap circle: {top_cap} edge pixels");
    assert!(bottom_arc >= 50, "bottom cap arc: {bottom_arc} edge pixels");
    assert!(left_outline >= 80, "left outline: {left_outline} edge pixels");
}

/// The cylinder of [`cylinder_obj`] (64 segments, radius 1, length 2) lying along the mesh's +X
/// axis, as a glTF whose scene places the one mesh under each of `nodes` (glTF node objects;
/// `"mesh": 0` is added). Written as `NAME.gltf` with its buffer in `NAME.bin`.
fn cylinder_gltf(dir: &Path, name: &str, nodes: &[Value]) -> PathBuf {
    let segments = 64u16;
    let mut positions = Vec::new();
    for x in [-1.0f32, 1.0] {
        for k in 0..segments {
            let a = -std::f32::consts::TAU * f32::from(k) / f32::from(segments);
            positions.push([x, a.sin(), a.cos()]);
        }
    }
    positions.extend([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]);
    let (low, high) = (2 * segments, 2 * segments + 1);
    let mut indices = Vec::new();
    for k in 0..segments {
        let (a, b) = (k, (k + 1) % segments);
        let (c, d) = (b + segments, a + segments);
        indices.extend([a, b, c, a, c, d, low, b, a, high, d, c]);
    }
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let position_bytes = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join(format!("{name}.bin")), &bin).expect("writes");
    let nodes: Vec<Value> = nodes
        .iter()
        .map(|node| {
            let mut node = node.clone();
            node["mesh"] = 0.into();
            node
        })
        .collect();
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len(), "uri": format!("{name}.bin")}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": position_bytes, "target": 34962},
            {"buffer": 0, "byteOffset": position_bytes, "byteLength": bin.len() - position_bytes, "target": 34963}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": positions.len(), "type": "VEC3",
             "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}
        ]
    });
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_vec_pretty(&json).expect("json")).expect("writes");
    path
}

/// `q` (x, y, z, w) applied to `v`.
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let [x, y, z, w] = q;
    let u = [x, y, z];
    let cross =
        |a: [f64; 3], b: [f64; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let t = cross(u, v).map(|c| 2.0 * c);
    let s = cross(u, t);
    [0, 1, 2].map(|i| v[i] + w * t[i] + s[i])
}

/// A copy of the baked GLB `baked` whose `silhouetteNormals` (VEC3 normalized bytes) are turned by
/// `q`: the file a writer would make that stored them in the world space of an instance rotated by
/// `q` instead of the mesh's own space.
fn with_normals_rotated(baked: &[u8], q: [f64; 4]) -> Vec<u8> {
    let chunks = drafter_format::glb::split(baked).expect("a GLB");
    let json: Value = serde_json::from_slice(chunks.json).expect("json");
    let mut bin = chunks.bin.expect("a BIN chunk").to_vec();
    let mut turned = 0;
    for primitive in
        json["meshes"].as_array().expect("meshes").iter().flat_map(|m| m["primitives"].as_array().expect("primitives"))
    {
        let Some(normals) = primitive["extensions"]["EXT_mesh_primitive_edge_visibility"]["silhouetteNormals"].as_u64()
        else {
            continue;
        };
        let accessor = &json["accessors"][normals as usize];
        assert_eq!(
            (accessor["componentType"].as_u64(), accessor["type"].as_str()),
            (Some(5120), Some("VEC3")),
            "{accessor}"
        );
        let view = &json["bufferViews"][accessor["bufferView"].as_u64().expect("view") as usize];
        let start = (view["byteOffset"].as_u64().unwrap_or(0) + accessor["byteOffset"].as_u64().unwrap_or(0)) as usize;
        let stride = view["byteStride"].as_u64().unwrap_or(3) as usize;
        for k in 0..accessor["count"].as_u64().expect("count") as usize {
            let at = start + k * stride;
            let v = [0, 1, 2].map(|i| (f64::from(bin[at + i] as i8) / 127.0).max(-1.0));
            let r = rotate(q, v);
            for i in 0..3 {
                bin[at + i] = ((r[i] * 127.0).round().clamp(-127.0, 127.0) as i8) as u8;
            }
            turned += 1;
        }
    }
    assert!(turned > 0, "no silhouette normals in the file");
    drafter_format::glb::write(&serde_json::to_vec(&json).expect("json"), &bin).expect("GLB")
}

/// Red pixels of one upright cylinder in a CesiumJS shot, in the columns `x0..=x1`: on its left and
/// right outlines and on its face, in a band of rows clear of both caps.
#[derive(Debug)]
struct Sides {
    left: u64,
    right: u64,
    face: u64,
    rows: u64,
}

impl Sides {
    fn of(image: &Path, x0: u32, x1: u32) -> Sides {
        let file = image.to_str().expect("utf-8 path");
        let json = client(&["pixels", file, "--region", &format!("{x0},0,{x1},599")]);
        let bbox: Vec<i64> =
            serde_json::from_value(json["differ"]["bbox"].clone()).expect("the cylinder is in the frame");
        let [xmin, ymin, xmax, ymax] = [bbox[0], bbox[1], bbox[2], bbox[3]];
        let (w, h) = (xmax - xmin, ymax - ymin);
        // Rows 30 % to 75 % down the cylinder: below the top cap's ellipse, above the bottom arc.
        let (top, bottom) = (ymin + 3 * h / 10, ymin + 3 * h / 4);
        let red = |xa: i64, xb: i64| pixels(image, &format!("{xa},{top},{xb},{bottom}"));
        let margin = w / 12;
        Sides {
            left: red(xmin - 2, xmin + margin),
            right: red(xmax - margin, xmax + 2),
            face: red(xmin + w / 6, xmax - w / 6),
            rows: (bottom - top + 1) as u64,
        }
    }

    /// A drawn outline: a red pixel in at least a quarter of the band's rows (CesiumJS composites
    /// an outline only where the pixel's centre falls on the face, so it comes out dotted: 35–40 %
    /// of the rows here).
    fn drawn(&self, count: u64) -> bool {
        4 * count >= self.rows
    }

    fn one_outline(&self) -> bool {
        self.face == 0 && (self.drawn(self.left) || self.drawn(self.right))
    }

    fn both_outlines(&self) -> bool {
        self.face == 0 && self.drawn(self.left) && self.drawn(self.right)
    }
}

/// Silhouettes of one mesh under transformed nodes. The cylinder lies along the mesh's X
/// axis and every node stands it up, so that its outlines are upright on screen: rotated (120°
/// about (1, 1, 1)), instanced twice (stood up, and upside down), mirrored (determinant −1) and
/// scaled unevenly. `silhouetteNormals` are in the mesh's space, as every glTF vertex attribute;
/// CesiumJS turns them with `czm_normal`, the inverse transpose of each node's model-view matrix.
///
/// Stock CesiumJS 1.145 draws one outline of a cylinder, not always the same one: it culls the
/// quad of an edge by the edge's direction on screen (docs/clients.md). So every cylinder must show
/// at least one outline and no line on its face; with the one-line fix (`--no-edge-cull`), both
/// outlines. A file whose normals are in the world space of the rotated instance instead (turned
/// by the node's rotation) moves the silhouettes onto the face, and the same checks reject it.
#[test]
fn cesium_draws_silhouettes_of_transformed_instances() {
    let dir = common::scratch("clients-cesium-instances");
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let stand = serde_json::json!([0.0, 0.0, h, h]); // 90° about Z: the mesh's +X becomes +Y
    let spun = [0.5, 0.5, 0.5, 0.5]; // that, then 90° about Y
    let upside_down = serde_json::json!([h, -h, 0.0, 0.0]); // 90° about Z, then 180° about X
    let cases = [
        ("rotated", vec![serde_json::json!({"rotation": spun})]),
        (
            "instanced",
            vec![
                serde_json::json!({"translation": [-1.6, 0, 0], "rotation": stand}),
                serde_json::json!({"translation": [1.6, 0, 0], "rotation": upside_down}),
            ],
        ),
        ("mirrored", vec![serde_json::json!({"rotation": stand, "scale": [1, 1, -1]})]),
        ("scaled", vec![serde_json::json!({"rotation": stand, "scale": [1.5, 1, 0.5]})]),
    ];
    let mut files = Vec::new();
    for (name, nodes) in &cases {
        let baked = dir.join(format!("{name}.glb"));
        common::bake(&cylinder_gltf(&dir, name, nodes), &baked, &[]);
        files.push((name.to_string(), baked, nodes.len()));
    }
    let wrong = dir.join("rotated-world-normals.glb");
    std::fs::write(&wrong, with_normals_rotated(&std::fs::read(&files[0].1).expect("baked"), spun)).expect("writes");

    // Every cylinder of a file: (stock CesiumJS, CesiumJS without the edge culling).
    let shoot = |file: &Path, cylinders: usize| -> Vec<(Sides, Sides)> {
        let mut shots = Vec::new();
        for extra in [&[][..], &["--no-edge-cull"][..]] {
            let stem = file.file_stem().and_then(|s| s.to_str()).expect("name");
            let shot = dir.join(format!("{stem}{}.png", if extra.is_empty() { "" } else { "-no-cull" }));
            let (file, image) = (file.to_str().expect("utf-8"), shot.to_str().expect("utf-8"));
            let mut args = vec!["cesium", file, "--view", "0,15", "--edge-color", "255,0,0", "--screenshot", image];
            args.extend(extra);
            client(&args);
            shots.push(shot);
        }
        let columns: Vec<(u32, u32)> = if cylinders == 1 { vec![(0, 799)] } else { vec![(0, 399), (400, 799)] };
        columns.iter().map(|&(x0, x1)| (Sides::of(&shots[0], x0, x1), Sides::of(&shots[1], x0, x1))).collect()
    };
    for (name, file, cylinders) in &files {
        for (k, (stock, fixed)) in shoot(file, *cylinders).iter().enumerate() {
            assert!(stock.one_outline(), "{name}, cylinder {k}, stock CesiumJS: {stock:?}");
            assert!(fixed.both_outlines(), "{name}, cylinder {k}, CesiumJS without edge culling: {fixed:?}");
        }
    }
    // The same checks tell the wrong file apart: its silhouettes run down the face.
    let (stock, fixed) = &shoot(&wrong, 1)[0];
    assert!(!stock.one_outline() && stock.face > 0, "normals in world space passed as: {stock:?}");
    assert!(!fixed.both_outlines() && fixed.face > 0, "normals in world space passed as: {fixed:?}");
}
