//! Names the commit this crate was built from (`DRAFTER_BUILD_COMMIT`), for the cache key: outputs
//! may change between commits of one package version. `unknown` outside a git checkout (a source
//! archive), where the package version alone keys the build.
//!
//! The commit is read from the checkout's files (`.git/HEAD`, the branch's ref or `packed-refs`),
//! not by running git: a build as another user (a Python wheel built by pip, a container) finds
//! git refusing the checkout as not its own, and the build then kept `unknown` for good, because
//! nothing told cargo to look again.

use std::fs;
use std::path::{Path, PathBuf};

/// The git directory of the checkout holding `start`: a `.git` folder, or the folder a `.git`
/// file names (a worktree).
fn git_dir(start: &Path) -> Option<PathBuf> {
    for dir in start.ancestors() {
        let dot = dir.join(".git");
        if dot.is_dir() {
            return Some(dot);
        }
        if let Ok(text) = fs::read_to_string(&dot) {
            let target = text.strip_prefix("gitdir:")?.trim();
            return Some(dir.join(target));
        }
    }
    None
}

/// The common git directory (where branches live) of a worktree's git directory.
fn common_dir(git: &Path) -> PathBuf {
    match fs::read_to_string(git.join("commondir")) {
        Ok(text) => git.join(text.trim()),
        Err(_) => git.to_path_buf(),
    }
}

/// `branch`'s commit from a `packed-refs` file's text.
fn packed(text: &str, branch: &str) -> Option<String> {
    text.lines().find_map(|line| {
        let (hash, name) = line.split_once(' ')?;
        (name.trim() == branch).then(|| hash.to_owned())
    })
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let Some(git) = git_dir(Path::new(env!("CARGO_MANIFEST_DIR"))) else {
        println!("cargo:rustc-env=DRAFTER_BUILD_COMMIT=unknown");
        return;
    };
    let common = common_dir(&git);
    // Rebuilt when HEAD moves: HEAD itself (a checkout), the branch it points at (a commit) and
    // packed-refs (a branch packed by `git gc`).
    println!("cargo:rerun-if-changed={}", git.join("HEAD").display());
    let head = fs::read_to_string(git.join("HEAD")).unwrap_or_default();
    let commit = match head.trim().strip_prefix("ref:") {
        Some(branch) => {
            let branch = branch.trim();
            let loose = common.join(branch);
            // Only paths that exist (cargo reruns every build for a missing one); the folder of
            // the branch catches a loose ref written after `git gc` packed it.
            for watched in
                [loose.parent().map(Path::to_path_buf), Some(common.join("packed-refs"))].into_iter().flatten()
            {
                if watched.exists() {
                    println!("cargo:rerun-if-changed={}", watched.display());
                }
            }
            fs::read_to_string(&loose)
                .ok()
                .map(|s| s.trim().to_owned())
                .or_else(|| packed(&fs::read_to_string(common.join("packed-refs")).ok()?, branch))
        }
        None => Some(head.trim().to_owned()),
    };
    let commit = commit.filter(|c| c.len() >= 40 && c.bytes().all(|b| b.is_ascii_hexdigit()));
    println!("cargo:rustc-env=DRAFTER_BUILD_COMMIT={}", commit.as_deref().unwrap_or("unknown"));
}
