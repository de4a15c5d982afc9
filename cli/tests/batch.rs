//! `drafter bake` of folders and manifests (issue 48): every output byte-identical to a single bake,
//! hostile inputs mixed in reported one by one with exit 4, the cache's hits, misses and damaged
//! entries, and Ctrl-C at random points of a 200-file batch leaving no partial file and a
//! consistent cache.
#![allow(unsafe_code)] // kill(2) sends the test's SIGINT.

mod common;

use std::path::{Path, PathBuf};
use std::time::Duration;

fn files_below(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() { stack.push(p) } else { out.push(p) }
        }
    }
    out.sort();
    out
}

fn hidden_or_temporary(dir: &Path) -> Vec<PathBuf> {
    files_below(dir)
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            name.starts_with('.') || name.ends_with(".tmp")
        })
        .collect()
}

fn report(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("report")).expect("report JSON")
}

/// A small closed mesh as OFF text, its first vertex moved by `k` so each file differs.
fn tetrahedron(k: usize) -> String {
    format!("OFF\n4 4 0\n{} 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", -(k as f64) * 1e-3)
}

#[test]
fn a_folder_with_hostile_inputs_bakes_every_good_file_and_lists_each_bad_one() {
    let dir = common::scratch("batch-hostile");
    let input = dir.join("in");
    let models = common::shared_models();
    let good = [
        ("parts/fandisk.obj", models.join("obj/common-3d-test-models/fandisk.obj")),
        ("parts/blade.off", models.join("obj/cgal/blade.off")),
        ("rod.glb", models.join("gltf/RodAssembly/rod.glb")),
        ("sample.glb", Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb")),
    ];
    for (name, source) in &good {
        let target = input.join(name);
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        std::fs::copy(source, target).unwrap();
    }
    let sample = std::fs::read(&good[3].1).unwrap();
    let mut huge_stl = vec![0u8; 80];
    huge_stl.extend_from_slice(&u32::MAX.to_le_bytes());
    huge_stl.extend_from_slice(&[0u8; 50]);
    let bad: [(&str, Vec<u8>, &str); 5] = [
        ("truncated.glb", sample[..sample.len() / 3].to_vec(), "truncated.glb"),
        ("garbage.ply", b"ply\nformat ascii 1.0\nelement vertex 4294967295\n".to_vec(), "garbage.ply"),
        ("huge.stl", huge_stl, "huge.stl"),
        ("parts/noise.obj", b"\x00\x01\x02 this is not a model".to_vec(), "noise.obj"),
        (
            "many.gltf",
            common::gltf_triangle(|j| j["accessors"][1]["count"] = serde_json::json!(3_000_000_000u64)),
            "many.gltf",
        ),
    ];
    for (name, bytes, _) in &bad {
        std::fs::write(input.join(name), bytes).unwrap();
    }
    let out = dir.join("out");
    let run = common::drafter()
        .args(["bake", "--jobs", "3", "--report"])
        .arg(dir.join("report.json"))
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(4), "{stderr}");
    for (_, _, needle) in &bad {
        let line = stderr.lines().find(|l| l.contains("failed:") && l.contains(needle));
        assert!(line.is_some(), "{needle} is listed with its reason: {stderr}");
    }
    assert!(stderr.contains("5 of 9 inputs failed"), "{stderr}");
    // Every good file baked, byte-identical to its single bake.
    for (name, _) in &good {
        let single = dir.join("single.glb");
        common::bake(&input.join(name), &single, &[]);
        let relative = Path::new(name).with_extension("glb");
        assert!(std::fs::read(out.join(&relative)).unwrap() == std::fs::read(&single).unwrap(), "{name}");
    }
    let written: Vec<_> = files_below(&out);
    assert_eq!(written.len(), good.len(), "no output for a bad input: {written:?}");
    assert!(hidden_or_temporary(&out).is_empty());
    let report = report(&dir.join("report.json"));
    assert_eq!((report["baked"].as_u64(), report["failed"].as_u64()), (Some(4), Some(5)));
    for file in report["files"].as_array().unwrap() {
        let failed = file["status"] == "failed";
        assert_eq!(failed, file["error"].is_string(), "{file}");
        if failed {
            assert!([2, 3].contains(&file["exit_code"].as_u64().unwrap()), "{file}");
        } else {
            assert!(file["bytes_out"].as_u64().unwrap() > 0 && file["bytes_in"].as_u64().unwrap() > 0);
        }
    }
}

#[test]
fn outputs_match_single_bakes_at_any_file_and_thread_count_and_the_cache_serves_them() {
    let dir = common::scratch("batch-cache");
    let models = common::shared_models();
    let folder = models.join("obj/cgal");
    let list = dir.join("list.txt");
    std::fs::write(
        &list,
        format!(
            "# two files of a manifest\n{}\n{}\n",
            models.join("gltf/RodAssembly/rod.glb").display(),
            models.join("obj/common-3d-test-models/fandisk.obj").display()
        ),
    )
    .unwrap();
    let reference = dir.join("ref");
    let single = |input: &Path, relative: &Path| {
        let target = reference.join(relative).with_extension("glb");
        std::fs::create_dir_all(target.parent().unwrap()).unwrap();
        common::bake(input, &target, &[]);
    };
    for file in files_below(&folder).into_iter().filter(|f| drafter_catalog::discover::is_supported(f)) {
        single(&file, file.strip_prefix(&folder).unwrap());
    }
    single(&models.join("gltf/RodAssembly/rod.glb"), Path::new("rod"));
    single(&models.join("obj/common-3d-test-models/fandisk.obj"), Path::new("fandisk"));
    let expected: Vec<(PathBuf, Vec<u8>)> = files_below(&reference)
        .into_iter()
        .map(|p| (p.strip_prefix(&reference).unwrap().to_path_buf(), std::fs::read(&p).unwrap()))
        .collect();
    let same_as_reference = |out: &Path| {
        let got: Vec<(PathBuf, Vec<u8>)> = files_below(out)
            .into_iter()
            .map(|p| (p.strip_prefix(out).unwrap().to_path_buf(), std::fs::read(&p).unwrap()))
            .collect();
        assert_eq!(got.len(), expected.len());
        for ((a, x), (b, y)) in got.iter().zip(&expected) {
            assert_eq!(a, b);
            assert!(x == y, "{} differs from its single bake", a.display());
        }
    };
    let cache = dir.join("cache");
    for (k, extra) in
        [vec!["--jobs", "1"], vec!["--jobs", "4", "--threads", "1"], vec!["--memory", "1M"]].iter().enumerate()
    {
        let out = dir.join(format!("out{k}"));
        let run = common::drafter()
            .arg("bake")
            .arg(&folder)
            .arg("--manifest")
            .arg(&list)
            .arg("-o")
            .arg(&out)
            .arg("--cache")
            .arg(&cache)
            .arg("--report")
            .arg(dir.join("r.json"))
            .args(extra)
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        same_as_reference(&out);
        let r = report(&dir.join("r.json"));
        let n = expected.len() as u64;
        // The first run bakes every file into the cache, the later ones are served from it.
        let (baked, cached) = if k == 0 { (n, 0) } else { (0, n) };
        assert_eq!((r["baked"].as_u64(), r["cached"].as_u64()), (Some(baked), Some(cached)), "run {k}");
        if k == 2 {
            assert!(r["peak_admitted_bytes"].as_u64().unwrap() <= 1 << 20);
        }
    }
    // A damaged entry is rebuilt (never served), the others are hits.
    let entries: Vec<PathBuf> = files_below(&cache.join("entries"));
    assert_eq!(entries.len(), expected.len());
    let mut damaged = std::fs::read(&entries[0]).unwrap();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 1;
    std::fs::write(&entries[0], &damaged).unwrap();
    let truncated = std::fs::read(&entries[1]).unwrap();
    std::fs::write(&entries[1], &truncated[..truncated.len() - 1]).unwrap();
    let out = dir.join("out-damaged");
    let run = common::drafter()
        .arg("bake")
        .arg(&folder)
        .arg("--manifest")
        .arg(&list)
        .arg("-o")
        .arg(&out)
        .arg("--cache")
        .arg(&cache)
        .arg("--json")
        .output()
        .unwrap();
    assert!(run.status.success());
    same_as_reference(&out);
    let r: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    let rebuilt = r["files"].as_array().unwrap().iter().filter(|f| f["cache"] == "rebuilt").count();
    assert_eq!(rebuilt, 2);
    // Eviction to a bound, then stats and clear.
    let stats = common::run(&["cache", "stats", "--json", "--cache", cache.to_str().unwrap()]);
    let stats: serde_json::Value = serde_json::from_slice(&stats.stdout).unwrap();
    assert_eq!(stats["entries"].as_u64(), Some(expected.len() as u64));
    let evict = common::run(&["cache", "evict", "1K", "--cache", cache.to_str().unwrap()]);
    assert!(evict.status.success());
    let stats = common::run(&["cache", "stats", "--json", "--cache", cache.to_str().unwrap()]);
    let stats: serde_json::Value = serde_json::from_slice(&stats.stdout).unwrap();
    assert_eq!(stats["entries"].as_u64(), Some(0), "every entry is larger than 1 KiB");
}

#[test]
fn sigint_at_random_points_of_a_200_file_batch_leaves_no_partial_file_and_a_consistent_cache() {
    let dir = common::scratch("batch-sigint");
    let input = dir.join("in");
    for k in 0..200 {
        let path = input.join(format!("group{}/t{k:03}.off", k % 7));
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, tetrahedron(k)).unwrap();
    }
    let reference = dir.join("ref");
    let started = std::time::Instant::now();
    let full = common::drafter().arg("bake").arg(&input).arg("-o").arg(&reference).arg("-q").output().unwrap();
    let whole = started.elapsed();
    assert!(full.status.success());
    assert_eq!(files_below(&reference).len(), 200);

    // Random points of the batch (a fixed seed), each trial on a fresh output folder and cache: one
    // signal lets the running files finish, two exit at once.
    let mut rng = drafter_core::rng::XorShift64::new(0x2545_f491_4f6c_dd1du64);
    let mut next = || rng.next();
    let mut interrupted = 0;
    for trial in 0..8 {
        let out = dir.join(format!("out{trial}"));
        let cache = dir.join(format!("cache{trial}"));
        let span = whole.as_micros() as u64;
        let delay = Duration::from_micros(span / 50 + next() % (span * 9 / 10));
        let twice = trial % 2 == 1;
        let mut child = common::drafter()
            .arg("bake")
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .arg("--cache")
            .arg(&cache)
            .arg("-q")
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(delay);
        let pid = child.id() as libc::pid_t;
        // SAFETY: kill(2) on our own child's pid.
        unsafe {
            libc::kill(pid, libc::SIGINT);
            if twice {
                std::thread::sleep(Duration::from_millis(next() % 30));
                libc::kill(pid, libc::SIGINT);
            }
        }
        let status = child.wait().unwrap();
        match status.code() {
            Some(130) => interrupted += 1,
            Some(0) => {}
            other => panic!("trial {trial}: exit {other:?}"),
        }
        // No partial output, no temporary file anywhere; every output written is whole.
        assert!(hidden_or_temporary(&out).is_empty(), "trial {trial}: {:?}", hidden_or_temporary(&out));
        assert!(files_below(&cache.join("tmp")).is_empty(), "trial {trial}: cache temporary files left");
        let written = files_below(&out);
        for file in &written {
            let twin = reference.join(file.strip_prefix(&out).unwrap());
            assert!(std::fs::read(file).unwrap() == std::fs::read(&twin).unwrap(), "trial {trial}: {}", file.display());
        }
        // The cache is consistent: a rerun serves every entry it holds (none damaged), bakes the
        // rest, and leaves every output as a full bake would.
        let stats = common::run(&["cache", "stats", "--json", "--cache", cache.to_str().unwrap()]);
        let stats: serde_json::Value = serde_json::from_slice(&stats.stdout).unwrap();
        let entries = stats["entries"].as_u64().unwrap();
        let rerun = common::drafter()
            .arg("bake")
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .arg("--cache")
            .arg(&cache)
            .arg("--json")
            .output()
            .unwrap();
        assert!(rerun.status.success(), "trial {trial}");
        let r: serde_json::Value = serde_json::from_slice(&rerun.stdout).unwrap();
        let count = |value: &str| r["files"].as_array().unwrap().iter().filter(|f| f["cache"] == value).count() as u64;
        assert_eq!(count("rebuilt"), 0, "trial {trial}: no entry was damaged");
        assert_eq!(count("hit"), entries, "trial {trial}: every entry served");
        assert_eq!(count("miss"), 200 - entries, "trial {trial}: the rest baked");
        let all = files_below(&out);
        assert_eq!(all.len(), 200);
        for file in all {
            let twin = reference.join(file.strip_prefix(&out).unwrap());
            assert!(std::fs::read(&file).unwrap() == std::fs::read(&twin).unwrap(), "trial {trial}");
        }
    }
    assert!(interrupted >= 4, "the signals arrived mid-batch ({interrupted} of 8)");
}

#[test]
fn two_processes_filling_one_cache_at_once_agree() {
    let dir = common::scratch("batch-two-processes");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    for k in 0..60 {
        std::fs::write(input.join(format!("t{k:02}.off")), tetrahedron(k)).unwrap();
    }
    let reference = dir.join("ref");
    assert!(common::drafter().arg("bake").arg(&input).arg("-o").arg(&reference).arg("-q").status().unwrap().success());
    let cache = dir.join("cache");
    let spawn = |out: &str| {
        common::drafter()
            .arg("bake")
            .arg(&input)
            .arg("-o")
            .arg(dir.join(out))
            .arg("--cache")
            .arg(&cache)
            .arg("-q")
            .spawn()
            .unwrap()
    };
    let (mut a, mut b) = (spawn("a"), spawn("b"));
    assert!(a.wait().unwrap().success() && b.wait().unwrap().success());
    for out in ["a", "b"] {
        for file in files_below(&dir.join(out)) {
            let twin = reference.join(file.file_name().unwrap());
            assert!(std::fs::read(&file).unwrap() == std::fs::read(&twin).unwrap(), "{}", file.display());
        }
    }
    assert!(files_below(&cache.join("tmp")).is_empty());
    // Every entry is whole: a third run into a fresh folder serves all 60 from the cache.
    let third = common::drafter()
        .arg("bake")
        .arg(&input)
        .arg("-o")
        .arg(dir.join("c"))
        .arg("--cache")
        .arg(&cache)
        .arg("--json")
        .output()
        .unwrap();
    let r: serde_json::Value = serde_json::from_slice(&third.stdout).unwrap();
    assert_eq!(r["cached"].as_u64(), Some(60), "{r}");
}

#[test]
fn a_batch_refuses_what_it_cannot_do_before_baking() {
    let dir = common::scratch("batch-refusals");
    let models = common::shared_models();
    let folder = models.join("obj/cgal");
    let no_output = common::drafter().arg("bake").arg(&folder).output().unwrap();
    assert_eq!(no_output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&no_output.stderr).contains("-o DIR"));
    std::fs::write(dir.join("a.obj"), "v 0 0 0\n").unwrap();
    std::fs::write(dir.join("a.stl"), "solid a\nendsolid a\n").unwrap();
    let clash = common::drafter().arg("bake").arg(&dir).arg("-o").arg(dir.join("out")).output().unwrap();
    assert_eq!(clash.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&clash.stderr).contains("would both be written to a.glb"));
    let textures = common::drafter()
        .arg("bake")
        .arg(&folder)
        .arg("-o")
        .arg(dir.join("o"))
        .arg("--textures-out")
        .arg(dir.join("t"))
        .output()
        .unwrap();
    assert_eq!(textures.status.code(), Some(2));
    let missing = common::drafter()
        .arg("bake")
        .arg(&folder)
        .arg(dir.join("missing"))
        .arg("-o")
        .arg(dir.join("o"))
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("missing"));
}

/// An input refused for its content is refused again by the same build, options and limits: the
/// cache replays its one-line reason instead of parsing the file again, and other limits miss.
#[test]
fn refusals_are_replayed_from_the_cache_with_the_same_reason() {
    let dir = common::scratch("batch-refusals");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let sample = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb")).unwrap();
    std::fs::write(input.join("good.glb"), &sample).unwrap();
    std::fs::write(input.join("truncated.glb"), &sample[..sample.len() / 3]).unwrap();
    let many = common::gltf_triangle(|j| j["accessors"][1]["count"] = serde_json::json!(3_000_000_000u64));
    std::fs::write(input.join("many.gltf"), many).unwrap();
    let cache = dir.join("cache");
    let run = |extra: &[&str]| {
        let output = common::drafter()
            .arg("bake")
            .arg(&input)
            .arg("-o")
            .arg(dir.join("out"))
            .arg("--cache")
            .arg(&cache)
            .arg("--json")
            .args(extra)
            .output()
            .unwrap();
        assert_eq!(output.status.code(), Some(4), "{}", String::from_utf8_lossy(&output.stderr));
        let r: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
        let mut files: Vec<(String, String, String, u64)> = r["files"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|f| f["status"] == "failed")
            .map(|f| {
                let name = f["input"].as_str().unwrap().rsplit('/').next().unwrap().to_string();
                (
                    name,
                    f["cache"].as_str().unwrap().to_string(),
                    f["error"].as_str().unwrap().to_string(),
                    f["exit_code"].as_u64().unwrap(),
                )
            })
            .collect();
        files.sort();
        files
    };
    let first = run(&[]);
    assert_eq!(first.len(), 2);
    assert!(first.iter().all(|f| f.1 == "miss" && f.3 == 2), "{first:?}");
    let second = run(&[]);
    for (a, b) in first.iter().zip(&second) {
        assert_eq!(b.1, "hit", "{b:?}");
        assert_eq!((&a.0, &a.2, a.3), (&b.0, &b.2, b.3), "the same reason and exit code");
    }
    // The triangle limit decides a refusal too: other limits are other keys.
    let other = run(&["--max-triangles", "1000000"]);
    assert!(other.iter().all(|f| f.1 == "miss"), "{other:?}");
}
