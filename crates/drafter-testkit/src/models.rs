//! The shared model corpus and the input files below a folder, as the corpus tests and the survey
//! examples walk them.

use std::path::{Path, PathBuf};

/// `../shared/models` beside the checkout. A test must not skip its data: panics if the corpus is
/// missing (it has a README.md).
pub fn shared_models() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/models");
    assert!(dir.join("README.md").is_file(), "the shared model corpus is missing at {}", dir.display());
    dir
}

/// The files below `dir` that `is_input` accepts (pass `drafter_io::has_input_extension`), in sorted
/// path order, each folder's entries sorted; `draco` folders are left out (the same models again,
/// compressed). A folder that cannot be read is passed over.
pub fn input_files(dir: &Path, is_input: impl Fn(&Path) -> bool + Copy) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, is_input, &mut out);
    out
}

fn walk(dir: &Path, is_input: impl Fn(&Path) -> bool + Copy, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).into_iter().flatten().flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "draco") {
                walk(&p, is_input, out);
            }
        } else if is_input(&p) {
            out.push(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_corpus_has_inputs_and_no_draco_copies() {
        let is_model = |p: &Path| p.extension().is_some_and(|e| e == "glb" || e == "gltf" || e == "obj" || e == "stl");
        let files = input_files(&shared_models(), is_model);
        assert!(files.len() >= 5, "{} model files", files.len());
        assert!(files.iter().all(|p| !p.components().any(|c| c.as_os_str() == "draco")));
        assert!(files.windows(2).all(|w| w[0] < w[1]), "sorted");
    }
}
