//! A batch writes nothing outside its output folder and its cache, whatever the paths it is given:
//! manifest entries through `..` and `../..`, absolute entries, a folder reached through
//! a symbolic link, a symbolic link planted inside the output folder or the cache, an output folder
//! whose parent is a link, and outputs whose names collide. Each run compares a snapshot of the
//! whole tree (every file's bytes, every link's target) before and after, the output folder and the
//! cache left out.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

/// A small closed mesh as OFF text, its first vertex moved by `k` so each file differs.
fn tetrahedron(k: usize) -> String {
    format!("OFF\n4 4 0\n{} 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", -(k as f64) * 1e-3)
}

fn bake_in(cwd: &Path, args: &[&str]) -> Output {
    common::drafter().current_dir(cwd).arg("bake").args(args).output().expect("drafter runs")
}

/// Runs `args` in `t` and asserts that nothing changed in `t` outside `allowed` (paths relative
/// to `t`) but the folders leading to them.
fn confined_run(t: &Path, args: &[&str], allowed: &[&str]) -> Output {
    let allowed: Vec<PathBuf> = allowed.iter().map(|a| t.join(a)).collect();
    let before = common::snapshot(t, &allowed);
    let out = bake_in(t, args);
    let after = common::snapshot(t, &allowed);
    let changed: Vec<_> = before
        .keys()
        .chain(after.keys())
        .filter(|p| before.get(*p) != after.get(*p))
        // The folders on the way to `-o` are created as the user asked.
        .filter(|p| {
            !(!before.contains_key(*p)
                && after.get(*p) == Some(&common::TreeNode::Folder)
                && allowed.iter().any(|a| a.starts_with(p)))
        })
        .map(|p| p.strip_prefix(t).unwrap_or(p).to_path_buf())
        .collect();
    assert!(
        changed.is_empty(),
        "drafter bake {args:?} wrote outside {allowed:?}: {changed:?}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn outputs_below(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if e.file_type().expect("type").is_dir() {
                stack.push(p);
            } else {
                out.push(p.strip_prefix(dir).unwrap_or(&p).display().to_string());
            }
        }
    }
    out.sort();
    out
}

#[test]
fn no_batch_writes_outside_its_output_folder_and_cache() {
    let scratch = common::scratch("confined");
    let t = scratch.join("t");
    for (name, k) in [("models/a.off", 1), ("models/sub/b.off", 2), ("outside/c.off", 3)] {
        let path = t.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, tetrahedron(k)).unwrap();
    }
    let manifests = t.join("manifests");
    std::fs::create_dir_all(&manifests).unwrap();
    let models = t.join("models").canonicalize().unwrap();
    std::fs::write(manifests.join("up.txt"), "../models\n").unwrap();
    std::fs::write(manifests.join("upup.txt"), "../../t/models\n").unwrap();
    std::fs::write(manifests.join("abs.txt"), format!("{}\n", models.display())).unwrap();
    std::fs::write(manifests.join("files.txt"), "../models/a.off\n../../t/models/sub/b.off\n").unwrap();
    std::os::unix::fs::symlink("../outside", manifests.join("link")).unwrap();
    std::fs::write(manifests.join("linked.txt"), "link\n").unwrap();
    std::fs::write(manifests.join("collide.txt"), "../models\n../models/sub\n").unwrap();

    // The report: `../models` once replaced models/a.off's neighbour a.glb in place.
    let out = confined_run(&t, &["--manifest", "manifests/up.txt", "-o", "baked"], &["baked"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("baked")), ["models/a.glb", "models/sub/b.glb"]);
    // `-o out/deep` once wrote to out/models.
    let out = confined_run(&t, &["--manifest", "manifests/up.txt", "-o", "out/deep"], &["out/deep"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("out/deep")), ["models/a.glb", "models/sub/b.glb"]);
    assert!(!t.join("out/models").exists());
    let out = confined_run(&t, &["--manifest", "manifests/upup.txt", "-o", "up2"], &["up2"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("up2")), ["t/models/a.glb", "t/models/sub/b.glb"]);
    let out = confined_run(&t, &["--manifest", "manifests/abs.txt", "-o", "abs"], &["abs"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("abs")), ["a.glb", "sub/b.glb"]);
    let out = confined_run(&t, &["--manifest", "manifests/files.txt", "-o", "files"], &["files"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("files")), ["models/a.glb", "t/models/sub/b.glb"]);
    // A folder reached through a link is read through it; its outputs stay below -o.
    let out = confined_run(&t, &["--manifest", "manifests/linked.txt", "-o", "linked"], &["linked"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("linked")), ["link/c.glb"]);
    // Absolute inputs on the command line.
    let abs_input = models.join("a.off");
    let out =
        confined_run(&t, &[abs_input.to_str().unwrap(), models.join("sub").to_str().unwrap(), "-o", "cli"], &["cli"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("cli")), ["a.glb", "b.glb"]);

    // A link planted inside the output folder, pointing out: refused, not followed (exit 4, each
    // file failed naming the link).
    std::fs::create_dir_all(t.join("planted")).unwrap();
    std::os::unix::fs::symlink("../outside", t.join("planted/models")).unwrap();
    let out = confined_run(&t, &["--manifest", "manifests/up.txt", "-o", "planted"], &[]);
    assert_eq!(out.status.code(), Some(4), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("a symbolic link inside the output folder"));
    // A link planted as an output file: refused too.
    std::fs::create_dir_all(t.join("planted2")).unwrap();
    std::os::unix::fs::symlink("../outside/c.off", t.join("planted2/a.glb")).unwrap();
    let out = confined_run(&t, &["models/a.off", "models/sub/b.off", "-o", "planted2"], &["planted2/b.glb"]);
    assert_eq!(out.status.code(), Some(4), "{}", String::from_utf8_lossy(&out.stderr));

    // -o whose parent is a link: the folder the user named, through the link, is written and
    // nothing else.
    std::fs::create_dir_all(t.join("real")).unwrap();
    std::os::unix::fs::symlink("real", t.join("lp")).unwrap();
    let out = confined_run(&t, &["--manifest", "manifests/up.txt", "-o", "lp/out"], &["real/out"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(outputs_below(&t.join("real/out")), ["models/a.glb", "models/sub/b.glb"]);

    // Colliding outputs: refused before anything is written (not even -o is created).
    let out = confined_run(&t, &["--manifest", "manifests/collide.txt", "-o", "collide"], &["collide"]);
    assert_eq!(out.status.code(), Some(2), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("would both be written to models/sub/b.glb"));
    assert!(outputs_below(&t.join("collide")).is_empty());

    // The cache: a link planted for its entries refuses the cache; one planted for its receipts
    // only costs the receipts. Neither leads a write out.
    std::fs::create_dir_all(t.join("cache1")).unwrap();
    std::os::unix::fs::symlink("../outside", t.join("cache1/entries")).unwrap();
    let out = confined_run(&t, &["models", "-o", "c1", "--cache", "cache1"], &["c1"]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::create_dir_all(t.join("cache2")).unwrap();
    std::os::unix::fs::symlink("../outside", t.join("cache2/receipts")).unwrap();
    std::os::unix::fs::symlink("../outside", t.join("cache2/tmp")).unwrap();
    let out = confined_run(&t, &["models", "-o", "c2", "--cache", "cache2"], &["c2", "cache2/entries"]);
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    std::fs::remove_file(t.join("cache2/tmp")).unwrap();
    let out = confined_run(&t, &["models", "-o", "c2", "--cache", "cache2"], &["c2", "cache2/entries", "cache2/tmp"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let again = confined_run(&t, &["models", "-o", "c2", "--cache", "cache2", "--json"], &["c2", "cache2"]);
    let report: serde_json::Value = serde_json::from_slice(&again.stdout).unwrap();
    assert_eq!(report["cached"], 2, "served from the entries, receipts or not");
    std::fs::remove_dir_all(&scratch).unwrap();
}
