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

/// Every importable model of the corpus (Draco originals excluded: they are refused by design).
fn corpus_models() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).expect("read dir").map(|e| e.expect("entry").path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n != "draco") {
                    walk(&p, out);
                }
            } else if let Some(ext) = p.extension().map(|e| e.to_string_lossy().to_ascii_lowercase())
                && ["gltf", "glb", "obj", "stl", "off", "ply"].contains(&ext.as_str())
            {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(&common::shared_models(), &mut out);
    assert!(out.len() >= 40, "only {} models found", out.len());
    out
}

fn bake(input: &Path, output: &Path, extra: &[&str]) -> std::process::Output {
    let out = common::drafter()
        .arg("bake")
        .arg(input)
        .arg("-o")
        .arg(output)
        .arg("--quiet")
        .args(extra)
        .output()
        .expect("drafter runs");
    assert!(out.status.success(), "{}: {}", input.display(), String::from_utf8_lossy(&out.stderr));
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
        bake(input, &output, &["--report", report.to_str().expect("utf-8")]);
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
        bake(&input, &one, &["--threads", "1"]);
        bake(&input, &two, &["--threads", "2"]);
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
    bake(&repo().join("samples/gear.glb"), &output, &[]);
    assert!(dir.join("out.bin").is_file());
    khronos_validate(&[output]);
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
    // A part override that matches nothing is bad input too.
    std::fs::write(&config, "[[part]]\nname = \"no such part\"\nstyle = \"metal\"\n").expect("config");
    let out = common::run(&[
        "bake",
        repo().join("samples/gear.glb").to_str().expect("utf-8"),
        "-o",
        output.to_str().expect("utf-8"),
        "--config",
        config.to_str().expect("utf-8"),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no such part"));
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
    bake(&repo().join("samples/assembly.glb"), &output, &["--config", config.to_str().expect("utf-8")]);
    let baked = drafter_format::read(&std::fs::read(&output).expect("read"), &|_| None).expect("reads");
    let parts = baked.parts();
    assert_eq!(parts[0].style.as_deref(), Some("metal"));
    assert_eq!(parts[0].projector.direction, [0.0, 0.0, 1.0]);
    assert_eq!(parts[0].projector.scale, 3.0);
    assert_eq!(parts[0].obb.method, "optimal");
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
        bake(&input, &output, &[]);
        let bytes = std::fs::read(&output).expect("baked");
        let (json, bin) = drafter_format::split_container(&bytes).expect("container");
        let doc: Value = serde_json::from_slice(json).expect("json");
        let bin = bin.expect("bin");
        let scene = drafter_io::import_bytes(&output, &bytes).expect("imports").scene;
        let mut decoded = 0;
        for (m, mesh) in scene.meshes.iter().enumerate() {
            let topology = drafter_core::Topology::build(mesh, drafter_core::Weld::default());
            for group in &mesh.groups {
                let p = group.primitive.expect("glTF primitive") as usize;
                let Some(ext) =
                    doc["meshes"][m]["primitives"][p]["extensions"].get(drafter_format::EDGE_VISIBILITY_EXTENSION)
                else {
                    continue;
                };
                let visibility: Vec<u8> =
                    drafter_format::read_scalars(&doc, ext["visibility"].as_u64().expect("acc") as usize, bin)
                        .expect("visibility")
                        .into_iter()
                        .map(|v| v as u8)
                        .collect();
                let normals: Vec<u16> = match ext.get("silhouetteNormals").and_then(Value::as_u64) {
                    Some(a) => drafter_format::read_scalars(&doc, a as usize, bin)
                        .expect("normals")
                        .into_iter()
                        .map(|v| v as u16)
                        .collect(),
                    None => Vec::new(),
                };
                let triangles = &mesh.triangles[group.start as usize..(group.start + group.count) as usize];
                let counts =
                    drafter_lines::decode_edge_visibility(triangles, &topology.welded_of_vertex, &visibility, &normals)
                        .unwrap_or_else(|e| panic!("{}: mesh {m} primitive {p}: {e}", input.display()));
                let _ = counts;
                decoded += 1;
            }
        }
        assert!(decoded > 0, "{}: no primitive carried edge visibility", input.display());
    }
}
