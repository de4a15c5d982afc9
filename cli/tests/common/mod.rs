//! Helpers shared by the CLI's end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use base64::Engine as _;
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

/// A valid one-triangle glTF with an embedded buffer; `edit` mutates its JSON before writing.
pub fn gltf_triangle(edit: impl FnOnce(&mut serde_json::Value)) -> Vec<u8> {
    let mut bin = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bin));
    let mut json = serde_json::json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len(), "uri": uri}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 36},
            {"buffer": 0, "byteOffset": 36, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
            {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    });
    edit(&mut json);
    serde_json::to_vec_pretty(&json).expect("json")
}

/// What [`snapshot`] records of a path.
#[derive(Debug, PartialEq, Eq)]
pub enum TreeNode {
    Folder,
    File(Vec<u8>),
    Link(PathBuf),
}

/// Everything below `root`, links not followed, leaving out the paths in `allowed` (and what lies
/// below them).
pub fn snapshot(root: &Path, allowed: &[PathBuf]) -> std::collections::BTreeMap<PathBuf, TreeNode> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).expect("listed").flatten() {
            let path = entry.path();
            if allowed.iter().any(|a| path.starts_with(a)) {
                continue;
            }
            let kind = entry.file_type().expect("type");
            let node = if kind.is_symlink() {
                TreeNode::Link(std::fs::read_link(&path).expect("link"))
            } else if kind.is_dir() {
                stack.push(path.clone());
                TreeNode::Folder
            } else {
                TreeNode::File(std::fs::read(&path).expect("read"))
            };
            out.insert(path, node);
        }
    }
    out
}
