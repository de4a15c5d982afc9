//! `drafter draw INPUT... -o DIR`: a catalog of drawings through the batch, its cache and
//! its report. Several inputs, a folder and a manifest entry through `..`, one bad file among them:
//! exit 4, every good file drawn in each format with the bytes of a single `drafter draw`, nothing
//! written outside `-o` and the cache, an input never replaced; a second run all cache hits with the
//! same bytes, a third leaving the outputs alone by their receipts.

mod common;

use std::collections::BTreeMap;
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};

fn samples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../samples")
}

fn report(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).expect("report written")).expect("report is JSON")
}

fn by_input(report: &serde_json::Value) -> BTreeMap<String, serde_json::Value> {
    let files = report["files"].as_array().expect("files");
    files.iter().map(|r| (r["input"].as_str().expect("input").to_owned(), r.clone())).collect()
}

/// `drafter draw ARGS...`, returning the exit code and stderr.
fn draw<A: AsRef<OsStr>>(args: impl IntoIterator<Item = A>) -> (Option<i32>, String) {
    let run = common::drafter().arg("draw").args(args).output().expect("drafter runs");
    (run.status.code(), String::from_utf8_lossy(&run.stderr).into_owned())
}

#[test]
fn a_catalog_of_sheets_draws_the_good_files_confined_and_a_rerun_is_all_cache_hits() {
    let root = common::scratch("draw-catalog");
    let models = root.join("models");
    std::fs::create_dir_all(models.join("sub")).unwrap();
    std::fs::copy(samples().join("gear.glb"), models.join("gear.glb")).unwrap();
    std::fs::copy(samples().join("bracket.glb"), models.join("sub/bracket.glb")).unwrap();
    std::fs::write(models.join("broken.stl"), b"solid x\n facet nonsense\n").unwrap();
    let elsewhere = root.join("elsewhere");
    std::fs::create_dir_all(&elsewhere).unwrap();
    std::fs::copy(samples().join("shaft.glb"), elsewhere.join("shaft.glb")).unwrap();
    // A manifest one folder down naming `../elsewhere`: written as `out/elsewhere/...`.
    let lists = root.join("lists");
    std::fs::create_dir_all(&lists).unwrap();
    std::fs::write(lists.join("more.txt"), "../elsewhere\n").unwrap();
    let (out, cache) = (root.join("out"), root.join("cache"));
    let sheet = ["--sheet", "A3", "--views", "front,top,right,iso", "--projection", "third", "--hidden", "dashed"];
    let catalog = |out: &Path, report: &Path| {
        let mut args: Vec<OsString> = vec![models.clone().into(), "--manifest".into(), lists.join("more.txt").into()];
        args.extend(sheet.iter().map(OsString::from));
        args.extend(["--format".into(), "svg,dxf".into(), "-o".into(), out.into()]);
        args.extend(["--cache".into(), cache.clone().into(), "--report".into(), report.into()]);
        draw(args)
    };
    let allowed = [out.clone(), cache.clone(), root.join("out2"), root.join("r1.json"), root.join("r2.json")];
    let before = common::snapshot(&root, &allowed);

    let (code, stderr) = catalog(&out, &root.join("r1.json"));
    assert_eq!(code, Some(4), "{stderr}");
    assert!(stderr.contains("broken.stl") && stderr.contains("the others were drawn"), "{stderr}");
    let first = report(&root.join("r1.json"));
    assert_eq!(
        (first["drawn"].as_u64(), first["failed"].as_u64(), first["cached"].as_u64()),
        (Some(3), Some(1), Some(0))
    );
    let records = by_input(&first);
    let broken = &records[&models.join("broken.stl").display().to_string()];
    assert_eq!((broken["status"].as_str(), broken["exit_code"].as_u64()), (Some("failed"), Some(2)));
    let written = ["gear", "sub/bracket", "elsewhere/shaft"];
    for name in written {
        for ext in ["svg", "dxf"] {
            assert!(out.join(format!("{name}.{ext}")).is_file(), "{name}.{ext} missing");
        }
    }
    assert!(!out.join("broken.svg").exists() && !out.join("broken.dxf").exists());
    assert_eq!(common::snapshot(&root, &allowed), before, "written outside -o and the cache");

    // The bytes of single drawings, the same options.
    for (input, name) in [(models.join("gear.glb"), "gear"), (elsewhere.join("shaft.glb"), "elsewhere/shaft")] {
        for ext in ["svg", "dxf"] {
            let single = root.join(format!("single.{ext}"));
            let mut args: Vec<OsString> = vec![input.clone().into(), "-q".into(), "-o".into(), single.clone().into()];
            args.extend(sheet.iter().map(OsString::from));
            let (code, stderr) = draw(args);
            assert_eq!(code, Some(0), "{stderr}");
            assert!(
                std::fs::read(&single).unwrap() == std::fs::read(out.join(format!("{name}.{ext}"))).unwrap(),
                "{name}.{ext}"
            );
            std::fs::remove_file(&single).unwrap();
        }
    }

    // Into a fresh folder: every good file from the cache, the refusal replayed, the same bytes.
    let out2 = root.join("out2");
    let (code, stderr) = catalog(&out2, &root.join("r2.json"));
    assert_eq!(code, Some(4), "{stderr}");
    let second = report(&root.join("r2.json"));
    assert_eq!(
        (second["drawn"].as_u64(), second["cached"].as_u64(), second["failed"].as_u64()),
        (Some(0), Some(3), Some(1))
    );
    assert!(second["files"].as_array().unwrap().iter().all(|r| r["cache"] == "hit"), "{second}");
    for name in written {
        for ext in ["svg", "dxf"] {
            let a = std::fs::read(out.join(format!("{name}.{ext}"))).unwrap();
            assert!(
                a == std::fs::read(out2.join(format!("{name}.{ext}"))).unwrap(),
                "{name}.{ext}: a hit's bytes differ"
            );
        }
    }
    // Into the first folder again: the outputs are up to date, left as they were.
    let (code, _) = catalog(&out, &root.join("r1.json"));
    assert_eq!(code, Some(4));
    let third = report(&root.join("r1.json"));
    let up_to_date = third["files"].as_array().unwrap().iter().filter(|r| r["up_to_date"] == true).count();
    assert_eq!(up_to_date, 3, "{third}");
    assert_eq!(common::snapshot(&root, &allowed), before, "written outside -o and the cache");

    // An option changed: drawn again.
    let gear = models.join("gear.glb");
    let (out3, r3) = (root.join("out3"), root.join("r3.json"));
    let (code, _) = draw([
        gear.as_os_str(),
        "--format".as_ref(),
        "svg".as_ref(),
        "--sheet".as_ref(),
        "A4".as_ref(),
        "-o".as_ref(),
        out3.as_os_str(),
        "--cache".as_ref(),
        cache.as_os_str(),
        "--report".as_ref(),
        r3.as_os_str(),
    ]);
    assert_eq!(code, Some(0));
    assert_eq!(report(&root.join("r3.json"))["drawn"].as_u64(), Some(1));

    // A manifest alone names the inputs (as `drafter bake --manifest` takes it): from the cache,
    // the same bytes.
    let out4 = root.join("out4");
    let mut args: Vec<OsString> = vec!["--manifest".into(), lists.join("more.txt").into()];
    args.extend(sheet.iter().map(OsString::from));
    args.extend(["--format".into(), "svg".into(), "-o".into(), out4.clone().into()]);
    args.extend(["--cache".into(), cache.clone().into(), "-q".into()]);
    let (code, stderr) = draw(args);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(
        std::fs::read(out4.join("elsewhere/shaft.svg")).unwrap()
            == std::fs::read(out.join("elsewhere/shaft.svg")).unwrap()
    );
}

#[test]
fn one_view_catalogs_and_one_cached_drawing_have_the_bytes_of_a_single_drawing() {
    let root = common::scratch("draw-catalog-view");
    let gear = samples().join("gear.glb");
    let single = root.join("gear.pdf");
    let (code, stderr) = draw([
        gear.as_os_str(),
        "-q".as_ref(),
        "--hidden".as_ref(),
        "solid".as_ref(),
        "-o".as_ref(),
        single.as_os_str(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    let expected = std::fs::read(&single).unwrap();
    // One file with --format is a catalog of one.
    let out = root.join("out");
    let (code, stderr) = draw([
        gear.as_os_str(),
        "--hidden".as_ref(),
        "solid".as_ref(),
        "--format".as_ref(),
        "pdf".as_ref(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(std::fs::read(out.join("gear.pdf")).unwrap() == expected);
    // One drawing through the cache: a miss, then a hit, the same bytes.
    let cache = root.join("cache");
    for (k, how) in [(1, "drawn"), (2, "from the cache")] {
        let cached = root.join(format!("cached{k}.pdf"));
        let args = [
            gear.as_os_str(),
            "--hidden".as_ref(),
            "solid".as_ref(),
            "-o".as_ref(),
            cached.as_os_str(),
            "--cache".as_ref(),
            cache.as_os_str(),
        ];
        let (code, stderr) = draw(args);
        assert_eq!(code, Some(0), "{stderr}");
        assert!(stderr.contains(how), "{stderr}");
        assert!(std::fs::read(&cached).unwrap() == expected);
    }
}

#[test]
fn a_catalog_never_replaces_an_input_and_refuses_bad_options_before_any_file() {
    let root = common::scratch("draw-catalog-input");
    // A model named .svg, drawn into its own folder as svg: its output would be the input.
    let odd = root.join("odd.svg");
    std::fs::copy(samples().join("gear.glb"), &odd).unwrap();
    let (code, stderr) = draw([odd.as_os_str(), "--format".as_ref(), "svg".as_ref(), "-o".as_ref(), root.as_os_str()]);
    assert_eq!(code, Some(4), "{stderr}");
    assert!(stderr.contains("is the input; not replaced"), "{stderr}");
    assert!(std::fs::read(&odd).unwrap() == std::fs::read(samples().join("gear.glb")).unwrap());
    // A mistake in the options: one line, exit 2, no folder made.
    let out = root.join("never");
    for extra in [&["--sheet", "A9"][..], &["--format", "png"], &["--sheet", "A3", "--views", "frnt"]] {
        let mut args: Vec<OsString> = vec![samples().into(), "-o".into(), out.clone().into()];
        args.extend(extra.iter().map(OsString::from));
        let (code, stderr) = draw(args);
        assert_eq!(code, Some(2), "{extra:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{extra:?}: {stderr}");
        assert!(!out.exists(), "{extra:?}");
    }
}
