//! What the segmentation tests share: the corpus loader, which fails loudly when ../shared/models
//! is missing.
#![allow(dead_code)]

use std::path::PathBuf;

use drafter_core::Scene;

pub const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/models/");

/// Loads a model, failing loudly when the corpus is missing: a test that skips its data tests
/// nothing.
pub fn load(relative: &str) -> Scene {
    let path = PathBuf::from(MODELS).join(relative);
    assert!(
        path.is_file(),
        "test model {} is missing: ../shared/models must sit next to the repository",
        path.display()
    );
    match drafter_io::import(&path) {
        Ok(imported) => imported.scene,
        Err(e) => panic!("cannot import {}: {e}", path.display()),
    }
}
