//! The fuzzer's regression files (the repository's `tests/regressions/`) through the binary: what
//! `tests/regressions/outcomes.txt` calls accepted bakes (exit 0; a baked file is inspected), what
//! it calls rejected exits 2 with one line on stderr that names the file. drafter-fuzz's own test
//! (`fuzz/tests/regressions.rs`) checks the libraries' typed errors; this one checks the exit codes
//! the README documents.

mod common;

use std::path::Path;

#[test]
fn regression_files_exit_as_documented() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/regressions");
    let listing = std::fs::read_to_string(root.join("outcomes.txt")).expect("tests/regressions/outcomes.txt");
    let scratch = common::scratch("regressions");
    let mut checked = 0;
    for line in listing.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let (file, rest) = line.split_once(char::is_whitespace).expect("a file and an outcome");
        let accepted = match rest.split_whitespace().next() {
            Some("accepted") => true,
            Some("rejected") => false,
            other => panic!("{file}: unknown outcome {other:?}"),
        };
        let input = root.join(file);
        let name = input.file_name().expect("name").to_string_lossy().into_owned();
        let out = if file.starts_with("baked/") {
            common::drafter().arg("inspect").arg(&input).output().expect("runs")
        } else {
            let output = scratch.join("out.glb");
            common::drafter().arg("bake").arg(&input).arg("-o").arg(&output).arg("--quiet").output().expect("runs")
        };
        let stderr = String::from_utf8_lossy(&out.stderr);
        if accepted {
            assert_eq!(out.status.code(), Some(0), "{file}: {stderr}");
        } else {
            assert_eq!(out.status.code(), Some(2), "{file}: {stderr}");
            assert_eq!(stderr.lines().count(), 1, "{file}: stderr must be one line: {stderr}");
            assert!(stderr.contains(&name), "{file}: the message does not name the file: {stderr}");
        }
        checked += 1;
    }
    assert!(checked > 0, "no regression file listed");
}
