//! `drafter bench FILE`: writes the five charts and the JSON, redraws them from the JSON, and
//! reports bad input with exit code 2.

mod common;

use std::path::Path;

use common::*;

fn repo() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

#[test]
fn bench_writes_charts_and_json_and_replots() {
    let out = scratch("bench_sweep");
    let model = repo().join("samples/bracket.glb");
    let output = run(&[
        "bench",
        model.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
        "--views",
        "8",
        "--quiet",
        "--json",
    ]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let printed: serde_json::Value = serde_json::from_slice(&output.stdout).expect("--json prints JSON");
    let saved: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("bench.json")).expect("bench.json")).expect("JSON");
    assert_eq!(printed, saved);
    assert_eq!(saved["model"]["name"], "bracket.glb");
    assert_eq!(saved["silhouettes"]["mismatches"], 0);
    for stem in ["obb", "normals", "silhouettes", "segmentation", "bake"] {
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).expect("chart written");
        assert!(svg.starts_with("<svg") && svg.contains("bracket.glb"), "{stem}.svg");
    }

    // Redraw from the saved numbers: the same charts, byte for byte.
    let again = scratch("bench_sweep_replot");
    let json = out.join("bench.json");
    let output = run(&["bench", json.to_str().expect("utf-8"), "--replot", "--out", again.to_str().expect("utf-8")]);
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    for stem in ["obb", "normals", "silhouettes", "segmentation", "bake"] {
        let a = std::fs::read(out.join(format!("{stem}.svg"))).expect("first");
        let b = std::fs::read(again.join(format!("{stem}.svg"))).expect("replotted");
        assert!(a == b, "{stem}.svg differs after --replot");
    }
}

#[test]
fn bench_of_a_missing_file_is_bad_input() {
    let out = scratch("bench_sweep_missing");
    let output = run(&["bench", "no-such-file.obj", "--out", out.to_str().expect("utf-8"), "--quiet"]);
    assert_eq!(output.status.code(), Some(2), "{}", String::from_utf8_lossy(&output.stderr));
}
