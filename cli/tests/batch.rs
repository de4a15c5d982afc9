//! `drafter bake` of folders and manifests: every output byte-identical to a single bake,
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
    let mut rng = drafter_core::rng::Rng::new(0x2545_f491_4f6c_dd1du64);
    let mut next = || rng.next_u64();
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
        // A signal that comes before the handler is installed (the process still starting, on a
        // loaded machine) ends it as the signal does by default: nothing written, which the
        // checks below hold too; to a shell that is 130 as well.
        let killed = std::os::unix::process::ExitStatusExt::signal(&status) == Some(libc::SIGINT);
        match status.code() {
            Some(130) => interrupted += 1,
            None if killed => interrupted += 1,
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

/// `drafter bake INPUT -o OUT EXTRA...`, its outcome not checked.
fn batch(input: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    common::drafter().arg("bake").arg(input).arg("-o").arg(out).args(extra).output().expect("drafter runs")
}

fn utf8(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 path")
}

/// `[k/n] name: ...` lines on a pipe, and the notes a single bake prints.
#[test]
fn a_batch_on_a_pipe_prints_a_line_per_file_with_the_bakes_notes() {
    let dir = common::scratch("batch-pipe");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::write(input.join("a.off"), tetrahedron(1)).unwrap();
    // One vertex that is not a number: its face is dropped with a note.
    std::fs::write(
        input.join("nan.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv nan 0 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\nf 1 2 5\n",
    )
    .unwrap();
    let single = common::drafter().arg("bake").arg(input.join("nan.obj")).arg("-o").arg(dir.join("one.glb")).output();
    let single = String::from_utf8_lossy(&single.unwrap().stderr).into_owned();
    assert!(single.contains("non-finite positions: 1"), "{single}");
    let out = batch(&input, &dir.join("out"), &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains('\r'), "no carriage returns on a pipe: {stderr:?}");
    let lines: Vec<&str> = stderr.lines().filter(|l| l.starts_with('[')).collect();
    assert_eq!(lines.len(), 2, "{stderr}");
    assert!(lines.iter().any(|l| l.starts_with("[1/2] ")) && lines.iter().any(|l| l.starts_with("[2/2] ")), "{stderr}");
    assert!(lines.iter().all(|l| l.contains(": baked ")), "{stderr}");
    assert!(stderr.contains("note: non-finite positions: 1"), "{stderr}");
    // --quiet: nothing but failures.
    let quiet = batch(&input, &dir.join("q"), &["--quiet"]);
    assert!(quiet.stderr.is_empty(), "{}", String::from_utf8_lossy(&quiet.stderr));
}

/// An output found up to date by its receipt still counts as a use of its cache entry, so
/// eviction keeps the set in use (bake A, bake B, rebake A, evict: A was gone).
#[test]
fn eviction_keeps_an_entry_whose_output_was_up_to_date() {
    let dir = common::scratch("batch-evict-lru");
    let cache = dir.join("cache");
    for (name, k) in [("a", 1), ("b", 2)] {
        std::fs::create_dir_all(dir.join(name)).unwrap();
        std::fs::write(dir.join(name).join(format!("{name}.off")), tetrahedron(k)).unwrap();
    }
    let bake = |name: &str, out: &str| -> serde_json::Value {
        let output = batch(&dir.join(name), &dir.join(out), &["--cache", utf8(&cache), "--json", "--quiet"]);
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
        serde_json::from_slice(&output.stdout).unwrap()
    };
    bake("a", "out");
    std::thread::sleep(Duration::from_millis(50));
    bake("b", "out");
    std::thread::sleep(Duration::from_millis(50));
    let again = bake("a", "out");
    assert_eq!(again["files"][0]["up_to_date"], true, "{again}");
    let stats = common::run(&["cache", "stats", "--cache", cache.to_str().unwrap(), "--json"]);
    let stats: serde_json::Value = serde_json::from_slice(&stats.stdout).unwrap();
    assert_eq!(stats["entries"], 2);
    // Room for one entry: the least recently used goes, which is b.
    let one = stats["bytes"].as_u64().unwrap() * 2 / 3;
    let evicted = common::run(&["cache", "evict", &one.to_string(), "--cache", cache.to_str().unwrap()]);
    assert!(evicted.status.success(), "{}", String::from_utf8_lossy(&evicted.stderr));
    // Fresh output folders (no receipts): a is served from the cache, b is baked again.
    assert_eq!(bake("a", "fresh")["files"][0]["cache"], "hit");
    assert_eq!(bake("b", "fresh")["files"][0]["cache"], "miss");
}

/// A file over the whole memory budget runs alone, and the summary and the report say so
/// (the summary said "at most 50 MB estimated at once" of a 579 MB file).
#[test]
fn a_file_over_the_memory_budget_runs_alone_and_the_report_says_so() {
    let dir = common::scratch("batch-over-budget");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb"), input.join("s.glb")).unwrap();
    std::fs::write(input.join("a.off"), tetrahedron(1)).unwrap();
    let report_path = dir.join("r.json");
    let out = batch(&input, &dir.join("out"), &["--memory", "1M", "--report", utf8(&report_path)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let r = report(&report_path);
    let over = r["over_budget"].as_u64().unwrap();
    assert!(over >= 1, "{r}");
    assert!(r["peak_admitted_bytes"].as_u64().unwrap() > r["memory_budget"].as_u64().unwrap(), "{r}");
    assert!(stderr.contains("over the budget ran alone"), "{stderr}");
    assert!(stderr.contains("over the memory budget: ran alone"), "{stderr}");
    let flagged = r["files"].as_array().unwrap().iter().filter(|f| f["over_budget"] == true).count() as u64;
    assert_eq!(flagged, over);
}

/// A refusal replayed from a cache names the input of this run, not the path of the machine (or
/// folder) that first refused it.
#[test]
fn a_cached_refusal_names_this_runs_path() {
    let dir = common::scratch("batch-refusal-path");
    let cache = dir.join("cache");
    let sample = std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples/assembly.glb")).unwrap();
    let mut errors = Vec::new();
    for runner in ["runner-one", "runner-two"] {
        let input = dir.join(runner).join("models");
        std::fs::create_dir_all(&input).unwrap();
        std::fs::write(input.join("truncated.glb"), &sample[..sample.len() / 3]).unwrap();
        let out = batch(&input, &dir.join(runner).join("out"), &["--cache", utf8(&cache), "--json"]);
        assert_eq!(out.status.code(), Some(4));
        let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        errors.push((r["files"][0]["cache"].clone(), r["files"][0]["error"].as_str().unwrap().to_owned()));
    }
    assert_eq!(errors[0].0, "miss");
    assert_eq!(errors[1].0, "hit");
    assert!(errors[1].1.contains("runner-two") && !errors[1].1.contains("runner-one"), "{errors:?}");
    assert_eq!(errors[0].1.replace("runner-one", "runner-two"), errors[1].1);
}

/// The report counts a .gltf with its buffers, and names the build and the configuration that
/// made the files.
#[test]
fn the_report_counts_a_gltfs_buffers_and_names_the_build_and_config() {
    let dir = common::scratch("batch-report-bytes");
    let input = dir.join("in");
    std::fs::create_dir_all(&input).unwrap();
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(input.join("tri.bin"), &bin).unwrap();
    let json = serde_json::json!({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"uri": "tri.bin", "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]}]
    });
    let text = serde_json::to_vec(&json).unwrap();
    std::fs::write(input.join("tri.gltf"), &text).unwrap();
    let report_path = dir.join("r.json");
    let out = batch(&input, &dir.join("out"), &["--report", utf8(&report_path), "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let r = report(&report_path);
    assert_eq!(r["files"][0]["bytes_in"].as_u64().unwrap(), (text.len() + bin.len()) as u64, "{r}");
    assert_eq!(r["bytes_total"].as_u64().unwrap(), (text.len() + bin.len()) as u64);
    let build = r["build"].as_str().unwrap();
    assert!(build.starts_with(env!("CARGO_PKG_VERSION")), "{build}");
    assert_eq!(r["config"]["lines"]["crease_angle_deg"], 30.0, "{}", r["config"]);
    assert!(r["config"].get("input").is_none(), "the input is in the file's record, not the config");
}

/// Checks that run as a user the output folder does not let write, and a subfolder that user
/// cannot list; as root (CI) through `setpriv` as `nobody`, since root may write anywhere.
fn as_unprivileged(cmd: &mut std::process::Command) -> std::process::Command {
    let root = std::process::Command::new("id").arg("-u").output().is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    if !root {
        return std::mem::replace(cmd, std::process::Command::new("true"));
    }
    let mut wrapped = std::process::Command::new("setpriv");
    wrapped.args(["--reuid=65534", "--regid=65534", "--clear-groups", "--"]);
    wrapped.arg(cmd.get_program()).args(cmd.get_args());
    wrapped
}

/// A read-only output folder is refused before any bake, with one line and exit 3; a subfolder
/// that cannot be listed fails alone, by its own path, and the others are baked.
#[test]
fn a_read_only_output_and_an_unreadable_subfolder_are_named_up_front() {
    use std::os::unix::fs::PermissionsExt;
    let dir = common::scratch("batch-permissions");
    let input = dir.join("in");
    for (name, k) in [("a.off", 1), ("sub/b.off", 2), ("locked/c.off", 3)] {
        let path = input.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, tetrahedron(k)).unwrap();
    }
    let read_only = dir.join("read-only");
    std::fs::create_dir_all(&read_only).unwrap();
    std::fs::set_permissions(&read_only, std::fs::Permissions::from_mode(0o555)).unwrap();
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).unwrap();
    let mut ro = common::drafter();
    ro.arg("bake").arg(input.join("a.off")).arg(input.join("sub")).arg("-o").arg(&read_only);
    let started = std::time::Instant::now();
    let out = as_unprivileged(&mut ro).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("cannot write in the output folder"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(started.elapsed() < Duration::from_secs(60));
    assert_eq!(std::fs::read_dir(&read_only).unwrap().count(), 0);

    std::fs::set_permissions(input.join("locked"), std::fs::Permissions::from_mode(0o000)).unwrap();
    let out_dir = dir.join("out");
    let mut unreadable = common::drafter();
    unreadable.arg("bake").arg(&input).arg("-o").arg(&out_dir).arg("--json");
    let out = as_unprivileged(&mut unreadable).output().unwrap();
    std::fs::set_permissions(input.join("locked"), std::fs::Permissions::from_mode(0o755)).unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(4), "{stderr}");
    assert!(stderr.contains(&format!("{}: cannot list", input.join("locked").display())), "{stderr}");
    assert!(stderr.contains("1 of 3 inputs failed (listed above); the others were baked"), "{stderr}");
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!((r["baked"].as_u64(), r["failed"].as_u64()), (Some(2), Some(1)), "{r}");
    assert!(out_dir.join("a.glb").is_file() && out_dir.join("sub/b.glb").is_file());
}
