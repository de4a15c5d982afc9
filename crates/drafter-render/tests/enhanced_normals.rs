//! The paper's toggle (Cignoni et al. 2005): a baked file carries the crease-aware normals in `NORMAL`
//! and the enhanced ones in `_ENHANCED_NORMAL`; `RenderOptions::enhanced_normals` shades with the
//! latter. Checked on fandisk (sharp CAD features, where the enhancement is visible): the two sets
//! differ, a bake with `enhanced_in_normal` (sets swapped in the file) reads back to the same sets,
//! the toggle changes the image (plus a golden image of the enhanced frame), and a file without the
//! attribute falls back to its own normals with an identical image.

mod common;

use std::path::Path;

use drafter_render::{Model, RenderOptions, Style, View};

const SIZE: (u32, u32) = (256, 192);

fn fandisk() -> std::path::PathBuf {
    common::corpus_path("obj/common-3d-test-models/fandisk.obj")
}

fn options(enhanced_normals: bool) -> RenderOptions {
    RenderOptions {
        size: SIZE,
        supersample: 1,
        style: Style::Gooch,
        use_part_styles: false,
        view: View { azimuth_deg: -145.0, elevation_deg: 30.0 },
        enhanced_normals,
        ..RenderOptions::default()
    }
}

/// Bakes `path` in memory with `config` and loads the bytes as the viewer loads a baked file.
fn baked_with(path: &Path, config: &drafter_bake::BakeConfig) -> Model {
    let imported = drafter_io::import(path).expect("import");
    let baked = drafter_bake::bake(&imported.scene, config).expect("bake");
    Model::load_bytes(Path::new("fandisk.baked.glb"), &baked.written.main).expect("baked file loads")
}

fn angle_deg(a: [f32; 3], b: [f32; 3]) -> f64 {
    let (a, b) = (glam::Vec3::from(a).normalize(), glam::Vec3::from(b).normalize());
    (a.dot(b).clamp(-1.0, 1.0) as f64).acos().to_degrees()
}

#[test]
fn baked_file_carries_both_normal_sets() {
    let model = common::baked(&fandisk());
    assert!(model.has_enhanced_normals());
    let batch = &model.batches[0];
    let enhanced = batch.enhanced_normals.as_ref().expect("enhanced normals of the batch");
    assert_eq!(enhanced.len(), batch.vertices.len());
    let angles: Vec<f64> =
        batch.vertices.iter().zip(enhanced).map(|(v, &e)| angle_deg(v.normal_in_object, e)).collect();
    for &e in enhanced {
        let length = glam::Vec3::from(e).length();
        assert!((length - 1.0).abs() < 1e-3, "enhanced normal of length {length}");
    }
    // The enhancement tilts normals near features and leaves the middle of large flat areas alone.
    let mean = angles.iter().sum::<f64>() / angles.len() as f64;
    let changed = angles.iter().filter(|&&a| a > 1.0).count();
    assert!(mean > 0.5 && mean < 20.0, "mean change {mean:.3}°");
    assert!(changed > angles.len() / 20, "only {changed} of {} vertices changed by > 1°", angles.len());
    assert!(changed < angles.len(), "every vertex changed");

    // A bake that swaps the sets in the file (for plain viewers) reads back to the same two sets.
    let mut config = drafter_bake::BakeConfig::default();
    config.normals.enhanced_in_normal = true;
    let swapped = baked_with(&fandisk(), &config);
    let swapped_batch = &swapped.batches[0];
    // `_ENHANCED_NORMAL` is stored as normalized bytes and NORMAL as FLOAT, so each set comes back
    // within the bytes' half a degree of the other file's.
    assert_eq!(swapped_batch.vertices.len(), batch.vertices.len());
    for (s, v) in swapped_batch.vertices.iter().zip(&batch.vertices) {
        assert_eq!(s.position_in_object, v.position_in_object);
        assert!(angle_deg(s.normal_in_object, v.normal_in_object) < 0.5);
    }
    let swapped_enhanced = swapped_batch.enhanced_normals.as_ref().expect("enhanced normals");
    for (&s, &e) in swapped_enhanced.iter().zip(enhanced) {
        assert!(angle_deg(s, e) < 0.5);
    }
}

#[test]
fn toggle_changes_the_image_and_falls_back_without_the_attribute() {
    let mut renderer = common::renderer();
    let model = common::baked(&fandisk());
    renderer.set_model(&model).expect("upload");
    let before = renderer.render(&options(false)).expect("render");
    let after = renderer.render(&options(true)).expect("render");
    let diff = before.diff(&after, common::LEVEL_THRESHOLD).expect("same size");
    assert!(
        diff.mean_abs > 0.002 && diff.fraction_over > 0.02,
        "the toggle barely changed the image: mean |Δ| {:.4}, {:.2} % of pixels",
        diff.mean_abs,
        diff.fraction_over * 100.0
    );
    let failures: Vec<String> = common::check_golden("fandisk_gooch_enhanced", &after).into_iter().collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));

    // The unbaked file has no enhanced normals: the toggle draws it exactly as without.
    let plain = Model::load(&fandisk()).expect("load");
    assert!(!plain.has_enhanced_normals());
    renderer.set_model(&plain).expect("upload");
    let off = renderer.render(&options(false)).expect("render");
    let on = renderer.render(&options(true)).expect("render");
    assert_eq!(off.rgba, on.rgba);
}
