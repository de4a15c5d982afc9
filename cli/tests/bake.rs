//! `drafter bake` end to end: every model of ../shared/models and samples/ bakes; every output passes
//! the Khronos glTF validator with 0 errors and 0 warnings, matches the extension's JSON Schema and
//! reads back into the parts of the bake report; output is byte-identical at 1 and 2 threads; a
//! failed bake leaves no output.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every model of the corpus but the Draco variants, which `cli/tests/draco.rs` bakes, validates and
/// compares with their uncompressed siblings (here they would only bake the same models again).
fn corpus_models() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).expect("read dir").map(|e| e.expect("entry").path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n != "draco") {
                    walk(&p, out);
                }
            } else if drafter_io::has_input_extension(&p) {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(&common::shared_models(), &mut out);
    assert!(out.len() >= 40, "only {} models found", out.len());
    out
}

fn schema(name: &str) -> jsonschema::Validator {
    let path = repo().join("crates/drafter-format/spec/schema").join(name);
    let schema: Value = serde_json::from_slice(&std::fs::read(&path).expect("schema")).expect("schema json");
    jsonschema::validator_for(&schema).expect("valid schema")
}

/// Validates the extension objects of a baked file against the schemas; returns the JSON.
fn check_schema(file: &Path) -> Value {
    let bytes = std::fs::read(file).expect("baked file");
    let (json, _) = drafter_format::split_container(&bytes).expect("container");
    let doc: Value = serde_json::from_slice(json).expect("json");
    let ext = drafter_format::EXTENSION;
    let (root, node, prim, mesh) = (
        schema("DRAFTER_illustration.root.schema.json"),
        schema("DRAFTER_illustration.node.schema.json"),
        schema("DRAFTER_illustration.primitive.schema.json"),
        schema("DRAFTER_illustration.mesh.schema.json"),
    );
    let errors =
        |v: &jsonschema::Validator, value: &Value| v.iter_errors(value).map(|e| e.to_string()).collect::<Vec<_>>();
    let r = errors(&root, &doc["extensions"][ext]);
    assert!(r.is_empty(), "{}: root: {r:?}", file.display());
    for n in doc["nodes"].as_array().into_iter().flatten() {
        if let Some(e) = n.get("extensions").and_then(|e| e.get(ext)) {
            let r = errors(&node, e);
            assert!(r.is_empty(), "{}: node: {r:?}", file.display());
        }
    }
    for m in doc["meshes"].as_array().into_iter().flatten() {
        if let Some(e) = m.get("extensions").and_then(|e| e.get(ext)) {
            let r = errors(&mesh, e);
            assert!(r.is_empty(), "{}: mesh: {r:?}", file.display());
        }
        for p in m["primitives"].as_array().into_iter().flatten() {
            if let Some(e) = p.get("extensions").and_then(|e| e.get(ext)) {
                let r = errors(&prim, e);
                assert!(r.is_empty(), "{}: primitive: {r:?}", file.display());
            }
        }
    }
    assert!(doc["extensionsUsed"].as_array().expect("used").iter().any(|e| e == ext));
    assert!(!doc.get("extensionsRequired").and_then(Value::as_array).is_some_and(|r| r.iter().any(|e| e == ext)));
    doc
}

/// Runs the Khronos validator (tools/validate-gltf) on `files`; panics unless all have 0 errors and
/// 0 warnings.
fn khronos_validate(files: &[PathBuf]) {
    let script = repo().join("tools/validate-gltf/validate.mjs");
    assert!(
        repo().join("tools/validate-gltf/node_modules/gltf-validator").is_dir(),
        "the Khronos validator is not installed: run `npm ci --prefix tools/validate-gltf` (CI does)"
    );
    for chunk in files.chunks(16) {
        let out = Command::new("node").arg(&script).args(chunk).output().expect("node runs (is Node.js installed?)");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "validator failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(stdout.matches(" 0 errors, 0 warnings").count(), chunk.len(), "{stdout}");
    }
}

#[test]
fn every_model_bakes_validates_and_reads_back() {
    let dir = common::scratch("bake-corpus");
    let mut inputs = corpus_models();
    for s in ["assembly.glb", "bracket.glb", "gear.glb", "shaft.glb"] {
        inputs.push(repo().join("samples").join(s));
    }
    let mut outputs = Vec::new();
    for (i, input) in inputs.iter().enumerate() {
        let output = dir.join(format!("{i:02}-{}.glb", input.file_stem().expect("stem").to_string_lossy()));
        let report = dir.join(format!("{i:02}.json"));
        common::bake(input, &output, &["--report", report.to_str().expect("utf-8")]);
        check_schema(&output);
        // Read back: the same parts as the report, labels for every split mesh.
        let baked = drafter_format::read(&std::fs::read(&output).expect("read"), &|_| None).expect("reads back");
        let report: Value = serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("report json");
        let parts = baked.parts();
        assert_eq!(parts.len(), report["parts"].as_array().expect("parts").len(), "{}", input.display());
        assert_eq!(baked.root.part_count as usize, parts.len());
        for (p, r) in parts.iter().zip(report["parts"].as_array().expect("parts")) {
            assert_eq!(p.name, r["name"].as_str().expect("name"));
            assert_eq!(u64::from(p.triangles), r["triangles"].as_u64().expect("triangles"));
            assert_eq!(p.obb.volume, r["obb"]["volume"].as_f64().expect("volume"));
            assert_eq!(p.projector.scale, r["projector"]["scale"].as_f64().expect("scale"));
        }
        assert!(report["output_bytes"].as_u64().expect("bytes") > 0);
        assert!(report["stages"].as_array().expect("stages").iter().any(|s| s["name"] == "bounds"));
        outputs.push(output);
    }
    khronos_validate(&outputs);
}

#[test]
fn output_is_identical_at_any_thread_count() {
    let dir = common::scratch("bake-threads");
    let models = common::shared_models();
    for input in [
        repo().join("samples/assembly.glb"),
        models.join("obj/occt/motor.stl"),
        models.join("gltf/RodAssembly/rod.glb"),
        models.join("obj/common-3d-test-models/fandisk.obj"),
    ] {
        let one = dir.join("one.glb");
        let two = dir.join("two.glb");
        common::bake(&input, &one, &["--threads", "1"]);
        common::bake(&input, &two, &["--threads", "2"]);
        assert!(std::fs::read(&one).expect("one") == std::fs::read(&two).expect("two"), "{} differs", input.display());
    }
}

#[test]
fn no_arguments_bakes_the_embedded_sample() {
    let dir = common::scratch("bake-default");
    let out = common::drafter().arg("bake").current_dir(&dir).output().expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let file = dir.join("sample.baked.glb");
    let doc = check_schema(&file);
    assert_eq!(doc["extensions"][drafter_format::EXTENSION]["input"]["name"], "assembly.glb");
    khronos_validate(&[file]);
}

#[test]
fn gltf_output_writes_a_bin_beside_it() {
    let dir = common::scratch("bake-gltf");
    let output = dir.join("out.gltf");
    common::bake(&repo().join("samples/gear.glb"), &output, &[]);
    assert!(dir.join("out.bin").is_file());
    khronos_validate(&[output]);
}

/// Node graphs glTF forbids (a node its own child, a node with two parents, a scene root that is
/// also a child) are baked as the importer walks them, with a note, and the written file keeps
/// only the links that walk followed: it passes the Khronos validator. Inputs whose only fault is
/// an empty accessor are refused (exit 2) instead of written out invalid.
#[test]
fn forbidden_node_graphs_bake_into_valid_files() {
    let dir = common::scratch("bake-node-graphs");
    let graphs: [(&str, serde_json::Value, serde_json::Value); 3] = [
        ("self-child", serde_json::json!([{"mesh": 0, "children": [0]}]), serde_json::json!([0])),
        (
            "two-parents",
            serde_json::json!([{"mesh": 0, "children": [1, 2]}, {"children": [2]}, {"mesh": 0}]),
            serde_json::json!([0]),
        ),
        (
            "root-and-child",
            serde_json::json!([{"mesh": 0, "children": [1]}, {"mesh": 0, "children": [0]}]),
            serde_json::json!([0, 1]),
        ),
    ];
    let mut outputs = Vec::new();
    for (name, nodes, roots) in graphs {
        let input = dir.join(format!("{name}.gltf"));
        std::fs::write(
            &input,
            common::gltf_triangle(|j| {
                j["nodes"] = nodes;
                j["scenes"][0]["nodes"] = roots;
            }),
        )
        .expect("input");
        let output = dir.join(format!("{name}.glb"));
        let out = common::run(&["bake", input.to_str().expect("utf-8"), "-o", output.to_str().expect("utf-8")]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stderr).contains("node cycles"), "{name}: no note");
        outputs.push(output);
    }
    khronos_validate(&outputs);
    let empty = dir.join("empty-accessor.gltf");
    std::fs::write(&empty, common::gltf_triangle(|j| j["accessors"][1]["count"] = 0.into())).expect("input");
    let out =
        common::run(&["bake", empty.to_str().expect("utf-8"), "-o", dir.join("never.glb").to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/accessors/1/count"));
    assert!(!dir.join("never.glb").exists());
}

/// A source mesh whose every position is NaN loses all its faces on import: the baked file leaves
/// it out (and its accessors), where it used to keep them with an empty index accessor, both
/// invalid glTF.
#[test]
fn a_mesh_without_finite_positions_is_left_out_of_a_valid_file() {
    use base64::Engine as _;
    let dir = common::scratch("bake-nan-mesh");
    let nan: Vec<u8> = (0..9).flat_map(|_| f32::NAN.to_le_bytes()).collect();
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&nan));
    let input = dir.join("nan.gltf");
    let gltf = common::gltf_triangle(|j| {
        j["buffers"].as_array_mut().expect("buffers").push(serde_json::json!({"byteLength": 36, "uri": uri}));
        j["bufferViews"].as_array_mut().expect("views").push(serde_json::json!({"buffer": 1, "byteLength": 36}));
        j["accessors"].as_array_mut().expect("accessors").push(
            serde_json::json!({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}),
        );
        j["meshes"] = serde_json::json!([
            {"primitives": [{"attributes": {"POSITION": 2}, "indices": 1}]},
            {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}
        ]);
        j["nodes"] = serde_json::json!([{"mesh": 0}, {"mesh": 1}]);
        j["scenes"][0]["nodes"] = serde_json::json!([0, 1]);
    });
    std::fs::write(&input, gltf).expect("input");
    let output = dir.join("nan.glb");
    common::bake(&input, &output, &[]);
    khronos_validate(std::slice::from_ref(&output));
    let out = common::run(&["inspect", "--json", output.to_str().expect("utf-8")]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!((report["meshes"].as_u64(), report["triangles"].as_u64()), (Some(1), Some(1)), "{report}");
}

/// An image the source names by a file beside it is taken into the baked file (which is written
/// elsewhere), so the output does not point at a file its folder lacks.
#[test]
fn image_files_beside_a_gltf_are_embedded() {
    use base64::Engine as _;
    let dir = common::scratch("bake-image-files");
    let png = base64::engine::general_purpose::STANDARD
        .decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNkYPhfDwAChwGA60e6kgAAAABJRU5ErkJggg==")
        .expect("png");
    std::fs::write(dir.join("tex.png"), &png).expect("image");
    let input = dir.join("textured.gltf");
    let gltf = common::gltf_triangle(|j| {
        j["images"] = serde_json::json!([{"uri": "tex.png"}]);
        j["textures"] = serde_json::json!([{"source": 0}]);
    });
    std::fs::write(&input, gltf).expect("input");
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).expect("dir");
    let outputs = [out_dir.join("t.glb"), out_dir.join("t.gltf")];
    for output in &outputs {
        common::bake(&input, output, &[]);
    }
    khronos_validate(&outputs);
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(&outputs[1]).expect("gltf")).expect("json");
    assert_eq!(json["images"][0]["mimeType"], "image/png", "{}", json["images"]);
    assert!(json["images"][0].get("uri").is_none());
}

#[test]
fn failures_leave_no_output_and_exit_2() {
    let dir = common::scratch("bake-failures");
    let config = dir.join("bad.toml");
    std::fs::write(&config, "[gradient]\nq = 0\n").expect("config");
    let output = dir.join("never.glb");
    for args in [
        vec!["--config", config.to_str().expect("utf-8")],
        vec!["--config", "missing.toml"],
        vec!["--segment", "nodes", "--threads", "0"],
        vec!["--threads", "100000"],
    ] {
        let out = common::drafter()
            .arg("bake")
            .arg(repo().join("samples/gear.glb"))
            .arg("-o")
            .arg(&output)
            .args(&args)
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(String::from_utf8_lossy(&out.stderr).lines().count(), 1, "{args:?}");
    }
    // `bake INPUT -o OUTPUT --config bad.toml`.
    let with_config = |input: &Path, output: &Path| {
        common::run(&[
            "bake",
            input.to_str().expect("utf-8"),
            "-o",
            output.to_str().expect("utf-8"),
            "--config",
            config.to_str().expect("utf-8"),
        ])
    };
    let gear = repo().join("samples/gear.glb");
    // A part override that matches nothing is bad input too.
    std::fs::write(&config, "[[part]]\nname = \"no such part\"\nstyle = \"metal\"\n").expect("config");
    let out = with_config(&gear, &output);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no such part"));
    // An anchor or scale that leaves no gradient (it used to be written as an all-zero projector).
    for bad in [
        "anchor = [1e300, 0.0, 0.0]",
        "scale = 1e-300",
        "anchor = [0.0, 1e39, 0.0]",
        "anchor = [1.0, 0.0, 0.0]\nscale = 1e39",
    ] {
        std::fs::write(&config, format!("[[part]]\nid = 0\n{bad}\n")).expect("config");
        let out = with_config(&gear, &output);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad}: {stderr}");
        assert!(stderr.contains("gives no gradient") && stderr.lines().count() == 1, "{bad}: {stderr}");
    }
    // A point-like part has no gradient of its own: the anchor and scale that `drafter view`
    // exports for it (its own) still bake.
    let point = dir.join("point.obj");
    std::fs::write(&point, "v 1e6 1e6 1e6\nv 1e6 1e6 1e6\nv 1e6 1e6 1e6\nf 1 2 3\n").expect("obj");
    std::fs::write(&config, "[[part]]\nid = 0\nanchor = [1e6, 1e6, 1e6]\nscale = 0.0000001\n").expect("config");
    let baked = dir.join("point.glb");
    let out = with_config(&point, &baked);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_file(&baked).expect("baked");
    // Unreadable input.
    let garbage = dir.join("garbage.stl");
    std::fs::write(&garbage, b"solid x\nfacet normal\n").expect("garbage");
    let out = common::run(&["bake", garbage.to_str().expect("utf-8"), "-o", output.to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(2));
    let leftovers: Vec<_> = std::fs::read_dir(&dir).expect("dir").map(|e| e.expect("e").file_name()).collect();
    assert!(!output.exists(), "partial output left");
    assert!(leftovers.iter().all(|n| !n.to_string_lossy().ends_with(".tmp")), "temp file left: {leftovers:?}");
}

#[test]
fn overrides_reach_the_file() {
    let dir = common::scratch("bake-overrides");
    let config = dir.join("c.toml");
    std::fs::write(
        &config,
        "[gradient]\nq = 7\nf = 0.715\np = 1.4\n[[part]]\nid = 0\nstyle = \"metal\"\ndirection = [0.0, 0.0, 2.0]\nscale = 3.0\nmethod = \"optimal\"\n",
    )
    .expect("config");
    let output = dir.join("o.glb");
    common::bake(&repo().join("samples/assembly.glb"), &output, &["--config", config.to_str().expect("utf-8")]);
    let baked = drafter_format::read(&std::fs::read(&output).expect("read"), &|_| None).expect("reads");
    let parts = baked.parts();
    assert_eq!(parts[0].style, Some(drafter_format::PartStyle::Metal));
    assert_eq!(parts[0].projector.direction, [0.0, 0.0, 1.0]);
    assert_eq!(parts[0].projector.scale, 3.0);
    assert_eq!(parts[0].obb.method, drafter_format::ObbMethod::Optimal);
    assert_eq!((parts[1].gradient.q, parts[1].gradient.p), (7.0, f64::from(1.4f32)));
    assert_eq!(parts[1].style, None);
}

/// The edge-visibility bitfields of baked files obey the draft's encode-once rules, checked by
/// drafter-lines' independent decoder against the baked geometry (welded again here).
#[test]
fn edge_visibility_decodes_and_recounts() {
    let dir = common::scratch("bake-edges");
    let models = common::shared_models();
    for input in [
        repo().join("samples/assembly.glb"),
        models.join("obj/common-3d-test-models/fandisk.obj"),
        models.join("obj/occt/motor.stl"),
        models.join("gltf/RodAssembly/rod.glb"),
    ] {
        let output = dir.join("e.glb");
        common::bake(&input, &output, &[]);
        let bytes = std::fs::read(&output).expect("baked");
        // The edges as drafter-format reads them (the one accessor decoder), the geometry as
        // drafter-io imports the file.
        let file = drafter_format::read(&bytes, &|_| None).expect("reads");
        let scene = drafter_io::import_bytes(&output, &bytes).expect("imports").scene;
        let mut decoded = 0;
        for (m, p, edges) in &file.primitive_edges {
            let mesh = &scene.meshes[*m as usize];
            let topology = drafter_core::Topology::build(mesh, drafter_core::Weld::default());
            let group = mesh.groups.iter().find(|g| g.primitive == Some(*p)).expect("primitive imported");
            let triangles = &mesh.triangles[group.start as usize..(group.start + group.count) as usize];
            drafter_lines::decode_edge_visibility(
                triangles,
                &topology.welded_of_vertex,
                &edges.visibility,
                &edges.silhouette_normals.decoded_all(),
            )
            .unwrap_or_else(|e| panic!("{}: mesh {m} primitive {p}: {e}", input.display()));
            decoded += 1;
        }
        assert!(decoded > 0, "{}: no primitive carried edge visibility", input.display());
    }
}

/// Bakes `input` with the extra args into `dir/name.glb`, textures into `dir/name/`; returns the
/// file's bytes and the report.
fn bake_with_textures(input: &Path, dir: &Path, name: &str, extra: &[&str]) -> (Vec<u8>, Value) {
    let output = dir.join(format!("{name}.glb"));
    let report = dir.join(format!("{name}.json"));
    let textures = dir.join(name);
    let mut args =
        vec!["--report", report.to_str().expect("utf-8"), "--textures-out", textures.to_str().expect("utf-8")];
    args.extend_from_slice(extra);
    common::bake(input, &output, &args);
    let report: Value = serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("report json");
    (std::fs::read(&output).expect("baked"), report)
}

/// Image names of the textures record, in record order.
fn texture_names(glb: &[u8]) -> Vec<String> {
    drafter_format::read_textures(glb, &|_| None).expect("reads textures").into_iter().map(|t| t.name).collect()
}

/// The embedded PNGs are exactly the files of `--textures-out` and the report's list; only what the
/// scene uses is embedded: metal textures for a scene with metallic materials (listing its metal
/// parts), none for one without, and again when a part is marked metal in the config.
#[test]
fn textures_are_embedded_only_as_the_scene_needs() {
    let dir = common::scratch("bake-textures");
    let (glb, report) = bake_with_textures(&repo().join("samples/assembly.glb"), &dir, "assembly", &[]);
    let baked = drafter_format::read(&glb, &|_| None).expect("reads");
    let record = baked.root.textures.clone().expect("a textures record");
    let pngs = drafter_format::read_textures(&glb, &|_| None).expect("reads textures");
    let names: Vec<&str> = pngs.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "gamma_atlas",
            "cel_atlas",
            "cool_to_warm_0",
            "hatching",
            "hatching_mip1",
            "hatching_mip2",
            "hatching_mip3",
            "metal_bands",
            "metal_highlights"
        ]
    );
    // The sample's steel and brass parts (metallicFactor 1) are metal, the painted ones are not.
    let metal = record.metal.as_ref().expect("metal textures");
    assert!(!metal.parts.is_empty());
    let doc: Value = serde_json::from_slice(drafter_format::split_container(&glb).expect("glb").0).expect("json");
    let parts = baked.parts();
    for p in &parts {
        let node = doc["nodes"]
            .as_array()
            .expect("nodes")
            .iter()
            .find(|n| {
                n["extensions"][drafter_format::EXTENSION]["parts"]
                    .as_array()
                    .is_some_and(|a| a.iter().any(|q| q["id"] == p.id))
            })
            .expect("the part's node");
        let material = doc["meshes"][node["mesh"].as_u64().expect("mesh") as usize]["primitives"][0]["material"]
            .as_u64()
            .expect("material");
        let metallic =
            doc["materials"][material as usize]["pbrMetallicRoughness"]["metallicFactor"].as_f64().unwrap_or(1.0);
        assert_eq!(metal.parts.contains(&p.id), metallic >= 0.5, "part {} ({})", p.id, p.name);
    }
    assert_eq!(record.gradient.as_ref().expect("gradient").curves, [drafter_format::TransferCurve::Identity]);
    assert_eq!(record.hatching.as_ref().expect("hatching").levels.len(), 4);
    // Record, report and files agree byte for byte.
    let listed = report["textures"]["images"].as_array().expect("report lists textures");
    assert_eq!(listed.len(), pngs.len());
    let mut total = 0;
    for png in &pngs {
        let file = std::fs::read(dir.join("assembly").join(format!("{}.png", png.name))).expect("texture file");
        assert!(file == png.png, "{} differs from the embedded image", png.name);
        let entry = listed.iter().find(|e| e["name"] == png.name.as_str()).expect("listed in the report");
        assert_eq!(entry["bytes"].as_u64(), Some(png.png.len() as u64));
        total += png.png.len();
        assert!(png.png.starts_with(b"\x89PNG\r\n\x1a\n"));
    }
    assert_eq!(report["textures"]["total_bytes"].as_u64(), Some(total as u64));
    assert_eq!(std::fs::read_dir(dir.join("assembly")).expect("dir").count(), pngs.len());

    // No metallic material: no metal textures.
    let bracket = repo().join("samples/bracket.glb");
    let (plain, plain_report) = bake_with_textures(&bracket, &dir, "bracket", &[]);
    let plain_names = texture_names(&plain);
    assert!(!plain_names.iter().any(|n| n.starts_with("metal")), "{plain_names:?}");
    assert_eq!(plain_names.len(), 7);
    assert!(drafter_format::read(&plain, &|_| None).expect("reads").root.textures.expect("record").metal.is_none());
    assert_eq!(plain_report["textures"]["metal_parts"], serde_json::json!([]));
    // The same part marked metal in the config: metal textures, listing it.
    let config = dir.join("metal.toml");
    std::fs::write(&config, "[[part]]\nid = 0\nstyle = \"metal\"\n").expect("config");
    let (marked, _) = bake_with_textures(&bracket, &dir, "marked", &["--config", config.to_str().expect("utf-8")]);
    assert_eq!(texture_names(&marked)[7..], ["metal_bands", "metal_highlights"]);
    let marked_record = drafter_format::read(&marked, &|_| None).expect("reads").root.textures.expect("record");
    assert_eq!(marked_record.metal.expect("metal").parts, [0]);
    // A threshold above 1 turns detection from materials off; only the configured styles remain.
    std::fs::write(&config, "[textures]\nstyles = [\"gradient\"]\nmetallic_threshold = 1.5\n").expect("config");
    let (only_gamma, _) = bake_with_textures(
        &repo().join("samples/assembly.glb"),
        &dir,
        "gamma",
        &["--config", config.to_str().expect("utf-8")],
    );
    assert_eq!(texture_names(&only_gamma), ["gamma_atlas"]);

    for name in ["assembly", "bracket", "marked", "gamma"] {
        check_schema(&dir.join(format!("{name}.glb")));
    }
    khronos_validate(&["assembly", "bracket", "marked", "gamma"].map(|n| dir.join(format!("{n}.glb"))));
}

/// Textures add exactly their PNG bytes (each padded to 4) to the binary chunk, and the output with
/// them is byte-identical across runs and thread counts, as are the PNG files.
#[test]
fn textures_add_exactly_their_bytes_and_are_deterministic() {
    let dir = common::scratch("bake-texture-bytes");
    let input = repo().join("samples/assembly.glb");
    let off = dir.join("off.toml");
    std::fs::write(&off, "[textures]\nenabled = false\n").expect("config");
    let (without, report_without) =
        bake_with_textures(&input, &dir, "without", &["--config", off.to_str().expect("utf-8")]);
    assert!(report_without.get("textures").is_none());
    assert!(drafter_format::read(&without, &|_| None).expect("reads").root.textures.is_none());
    let (with, _) = bake_with_textures(&input, &dir, "with", &["--threads", "1"]);
    let pngs = drafter_format::read_textures(&with, &|_| None).expect("reads textures");
    let padded: usize = pngs.iter().map(|p| p.png.len().next_multiple_of(4)).sum();
    let bin = |glb: &[u8]| drafter_format::split_container(glb).expect("glb").1.expect("bin").len();
    let json = |glb: &[u8]| drafter_format::split_container(glb).expect("glb").0.len();
    assert_eq!(bin(&with) - bin(&without), padded);
    assert_eq!(with.len() - without.len(), padded + json(&with) - json(&without));
    eprintln!(
        "assembly: {} B without textures, {} B with ({} B of PNG, {} B of JSON)",
        without.len(),
        with.len(),
        padded,
        json(&with) - json(&without)
    );

    // `--json` prints the same report, textures listed, on stdout.
    let printed = common::bake(&input, &dir.join("json.glb"), &["--json"]);
    let printed: Value = serde_json::from_slice(&printed.stdout).expect("--json prints the report");
    let total: usize = pngs.iter().map(|p| p.png.len()).sum();
    assert_eq!(printed["textures"]["total_bytes"].as_u64(), Some(total as u64));
    assert_eq!(printed["textures"]["images"].as_array().map(Vec::len), Some(pngs.len()));

    let (again, _) = bake_with_textures(&input, &dir, "again", &["--threads", "2"]);
    let (default_threads, _) = bake_with_textures(&input, &dir, "default", &[]);
    assert!(with == again, "textured output differs between 1 and 2 threads");
    assert!(with == default_threads, "textured output differs between runs");
    for png in &pngs {
        let file = |d: &str| std::fs::read(dir.join(d).join(format!("{}.png", png.name))).expect("png");
        assert!(file("with") == file("again") && file("with") == file("default"), "{} differs", png.name);
    }
}
