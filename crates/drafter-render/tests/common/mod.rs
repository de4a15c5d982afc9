//! Shared by the renderer's integration tests and drafter-app's (which include this file): the
//! renderer (which must exist: no GPU adapter is a failure, not a skip), the baked sample, and
//! golden-image comparison.

#![allow(dead_code)]

use std::path::Path;

use drafter_render::{Image, Renderer};

/// Mean absolute difference (RGB, in [0, 1]) a golden image may show.
pub const MAX_MEAN_ABS: f64 = 0.02;
/// Fraction of pixels allowed to differ by more than [`LEVEL_THRESHOLD`] levels.
pub const MAX_FRACTION_OVER: f64 = 0.01;
pub const LEVEL_THRESHOLD: u8 = 8;

/// Set to `1` to rewrite the reference images instead of comparing with them.
pub const UPDATE_ENV: &str = "DRAFTER_UPDATE_GOLDEN";

pub fn renderer() -> Renderer {
    match Renderer::new() {
        Ok(r) => r,
        Err(e) => panic!(
            "the renderer tests need a GPU adapter and found none: {e}\n\
             (CI installs lavapipe: apt-get install -y mesa-vulkan-drivers libvulkan1)"
        ),
    }
}

// The baked models come from the drawing's test helpers, one copy for both crates.
#[path = "../../../drafter-draw/tests/common/mod.rs"]
mod baking;
#[allow(unused_imports)] // each test binary uses some of them
pub use baking::{baked, corpus_path, repo_path, sample};

/// Compares `image` with `golden/<name>.png` (or rewrites it when [`UPDATE_ENV`] is 1). Returns a
/// description of the failure, if any; the actual image is then saved beside the test's temp dir.
pub fn check_golden(name: &str, image: &Image) -> Option<String> {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(format!("{name}.png"));
    let png = image.to_png().expect("PNG encoding");
    if std::env::var(UPDATE_ENV).is_ok_and(|v| v == "1") {
        std::fs::write(&golden, &png).expect("write golden image");
        return None;
    }
    let Ok(bytes) = std::fs::read(&golden) else {
        return Some(format!("{name}: no reference image {} (run with {UPDATE_ENV}=1)", golden.display()));
    };
    let reference = Image::from_png(&bytes).expect("reference PNG decodes");
    let verdict = match image.diff(&reference, LEVEL_THRESHOLD) {
        None => Some(format!(
            "{name}: size {}x{} differs from the reference's {}x{}",
            image.width, image.height, reference.width, reference.height
        )),
        Some(d) if d.mean_abs > MAX_MEAN_ABS || d.fraction_over > MAX_FRACTION_OVER => Some(format!(
            "{name}: mean |Δ| {:.4} (max {MAX_MEAN_ABS}), {:.2} % of pixels off by > {LEVEL_THRESHOLD} levels (max {:.0} %), max Δ {}",
            d.mean_abs,
            d.fraction_over * 100.0,
            MAX_FRACTION_OVER * 100.0,
            d.max_levels
        )),
        Some(_) => None,
    };
    if verdict.is_some() {
        let actual = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}.actual.png"));
        let _ = std::fs::write(&actual, &png);
        return verdict.map(|v| format!("{v}; actual image: {}", actual.display()));
    }
    None
}
