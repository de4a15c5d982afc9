//! Helpers shared by the CLI's end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The shared test corpus beside the repository. Fails (never skips) when it is missing.
pub fn shared_models() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/models");
    assert!(
        dir.join("README.md").is_file(),
        "the shared model corpus is missing at {} (expected ../shared/models beside the repository); these tests need it",
        dir.display()
    );
    dir
}

pub fn drafter() -> Command {
    Command::new(env!("CARGO_BIN_EXE_drafter"))
}

pub fn run(args: &[&str]) -> Output {
    drafter().args(args).output().expect("drafter runs")
}

/// `drafter bake INPUT -o OUTPUT --quiet EXTRA...`, asserted to succeed.
pub fn bake(input: &Path, output: &Path, extra: &[&str]) -> Output {
    let out = drafter().arg("bake").arg(input).arg("-o").arg(output).arg("--quiet").args(extra).output();
    let out = out.expect("drafter runs");
    assert!(out.status.success(), "{}: {}", input.display(), String::from_utf8_lossy(&out.stderr));
    out
}

/// A fresh scratch folder under the target directory (no extra crate needed).
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}
