//! Shared by the drawing's tests and the viewer's (which include this file): models baked in
//! memory, as `drafter bake` writes them.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use drafter_scene::Model;

/// `relative` in the repository: the folder above the including crate that holds Cargo.lock.
pub fn repo_path(relative: &str) -> PathBuf {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = crate_dir.ancestors().find(|p| p.join("Cargo.lock").is_file()).unwrap_or(crate_dir);
    root.join(relative)
}

/// A model from ../shared/models, failing loudly when the corpus is missing.
pub fn corpus_path(relative: &str) -> PathBuf {
    let path = repo_path("../shared/models").join(relative);
    assert!(
        path.is_file(),
        "test model {} is missing: the tests need ../shared/models beside the repository",
        path.display()
    );
    path
}

/// Imports `path`, bakes it in memory with the default config and loads the result as `drafter
/// draw` would load the file `drafter bake` writes.
pub fn baked(path: &Path) -> Model {
    let imported = drafter_io::import(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let baked = drafter_bake::bake(&imported.scene, &drafter_bake::BakeConfig::default())
        .unwrap_or_else(|e| panic!("{}: bake failed: {e}", path.display()));
    assert!(baked.written.bin.is_none(), "the default container is .glb");
    let name = format!("{}.baked.glb", path.file_stem().map(|s| s.to_string_lossy()).unwrap_or_default());
    let model = Model::load_bytes(Path::new(&name), &baked.written.main).expect("baked file loads");
    assert!(model.baked, "{name}: the extension was read");
    model
}

/// The sample assembly, baked.
pub fn sample() -> Model {
    baked(&repo_path("samples/assembly.glb"))
}
