//! What a new user sees from `drafter bake`: one line per kind of finding (all of them with
//! `--verbose`, none with `--quiet`), a progress bar on a terminal and never escape codes in
//! redirected output, and a neutral default material for mesh inputs.

mod common;

use std::collections::BTreeSet;
use std::process::Command;

use serde_json::Value;

fn stderr_of(args: &[&str]) -> String {
    let out = common::drafter().args(args).output().expect("drafter runs");
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stderr).expect("utf-8 stderr")
}

fn notes(stderr: &str) -> Vec<&str> {
    stderr.lines().filter(|l| l.trim_start().starts_with("note:")).collect()
}

/// The kind label of a note line: the text between `note: ` and the first `:`.
fn kind_of(line: &str) -> &str {
    let rest = line.trim_start().trim_start_matches("note: ");
    rest.split(':').next().unwrap_or(rest)
}

#[test]
fn findings_are_one_line_per_kind_by_default() {
    let engine = common::shared_models().join("gltf/2CylinderEngine/2CylinderEngine.gltf");
    let engine = engine.to_str().expect("utf-8 path");
    let dir = common::scratch("newcomer-notes");
    let out = dir.join("engine.glb");
    let out = out.to_str().expect("utf-8 path");
    let report = dir.join("report.json");

    let default = stderr_of(&["bake", engine, "-o", out, "--report", report.to_str().expect("utf-8")]);
    let lines = notes(&default);
    let kinds: BTreeSet<&str> = lines.iter().map(|l| kind_of(l)).collect();
    assert_eq!(kinds.len(), lines.len(), "more than one line for a kind:\n{default}");
    assert!(!lines.is_empty(), "2CylinderEngine has findings (degenerate triangles):\n{default}");
    assert!(!default.contains("Other"), "a finding without a telling kind:\n{default}");
    let degenerate = lines.iter().find(|l| kind_of(l) == "degenerate triangles").expect("degenerate triangles line");
    // The total is the sum of the report's entries of that kind.
    let json: Value = serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("report json");
    let entries: Vec<&Value> = json["diagnostics"]
        .as_array()
        .expect("diagnostics")
        .iter()
        .filter(|d| d["kind"] == "degenerate_triangle")
        .collect();
    assert!(entries.len() > 1, "2CylinderEngine has degenerate triangles in several meshes");
    let total: u64 = entries.iter().map(|d| d["count"].as_u64().expect("count")).sum();
    let total = drafter_core::thousands(total as usize);
    assert!(degenerate.contains(&format!(": {total} in {} places", entries.len())), "{degenerate}");
    assert!(default.contains("--verbose"), "the summary points at --verbose:\n{default}");

    let verbose = stderr_of(&["bake", engine, "-o", out, "--verbose"]);
    assert_eq!(notes(&verbose).len(), json["diagnostics"].as_array().map_or(0, Vec::len), "{verbose}");

    let quiet = stderr_of(&["bake", engine, "-o", out, "--quiet"]);
    assert!(quiet.is_empty(), "--quiet printed: {quiet}");
}

/// Runs `drafter ARGS` under a pseudo-terminal (util-linux `script`), returning what the terminal
/// received.
fn under_pty(args: &[&str], env: &[(&str, &str)]) -> String {
    let exe = env!("CARGO_BIN_EXE_drafter");
    let quoted: Vec<String> = std::iter::once(exe).chain(args.iter().copied()).map(|a| format!("'{a}'")).collect();
    let mut cmd = Command::new("script");
    cmd.args(["-qec", &quoted.join(" "), "/dev/null"]);
    // A terminal has a TERM; indicatif draws nothing without one (or with TERM=dumb), as on a bare
    // CI machine's environment.
    cmd.env("TERM", "xterm-256color");
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("util-linux `script` runs (Debian's bsdutils)");
    assert!(out.status.success(), "{args:?} under a pty: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn a_terminal_gets_a_progress_bar_and_a_pipe_gets_no_escape_codes() {
    let dragonish = common::shared_models().join("obj/common-3d-test-models/stanford-bunny.obj");
    let input = dragonish.to_str().expect("utf-8 path");
    let dir = common::scratch("newcomer-progress");
    let out = dir.join("bunny.glb");
    let out = out.to_str().expect("utf-8 path");

    // The bar shows after DRAFTER_PROGRESS_DELAY_MS (1 s by default; 0 here, so a fast bake shows it).
    let tty = under_pty(&["bake", input, "-o", out], &[("DRAFTER_PROGRESS_DELAY_MS", "0")]);
    assert!(tty.contains('\u{1b}'), "no escape codes on a terminal: {tty:?}");
    assert!(tty.contains("/9 "), "no step counter on a terminal: {tty:?}");
    assert!(tty.contains("baked "), "{tty:?}");

    // The default delay hides the bar of a short bake, and --quiet hides everything.
    let quiet = under_pty(&["bake", input, "-o", out, "--quiet"], &[("DRAFTER_PROGRESS_DELAY_MS", "0")]);
    assert!(quiet.trim().is_empty(), "--quiet on a terminal printed {quiet:?}");

    // Redirected: no escape codes at all.
    let out = common::drafter()
        .args(["bake", input, "-o", out])
        .env("DRAFTER_PROGRESS_DELAY_MS", "0")
        .output()
        .expect("drafter runs");
    assert!(out.status.success());
    let all = [out.stdout, out.stderr].concat();
    assert!(!all.contains(&0x1b), "escape codes in redirected output: {:?}", String::from_utf8_lossy(&all));
}

#[test]
fn mesh_inputs_get_a_neutral_default_material() {
    let dir = common::scratch("newcomer-material");
    for rel in ["obj/common-3d-test-models/fandisk.obj", "obj/occt/bearing.stl", "obj/cgal/joint.off"] {
        let input = common::shared_models().join(rel);
        let out = dir.join("out.glb");
        stderr_of(&["bake", input.to_str().expect("utf-8"), "-o", out.to_str().expect("utf-8"), "--quiet"]);
        let bytes = std::fs::read(&out).expect("baked");
        let (json, _) = drafter_format::split_container(&bytes).expect("container");
        let doc: Value = serde_json::from_slice(json).expect("json");
        for mesh in doc["meshes"].as_array().expect("meshes") {
            for prim in mesh["primitives"].as_array().expect("primitives") {
                let m = prim["material"].as_u64().expect("every primitive has a material") as usize;
                let pbr = &doc["materials"][m]["pbrMetallicRoughness"];
                assert_eq!(doc["materials"][m]["name"], drafter_format::DEFAULT_MATERIAL_NAME, "{rel}");
                assert_eq!(pbr["metallicFactor"].as_f64(), Some(0.0), "{rel}");
                assert_eq!(pbr["baseColorFactor"][0].as_f64(), Some(f64::from(0.8f32)), "{rel}");
            }
        }
    }
}
