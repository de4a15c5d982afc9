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
