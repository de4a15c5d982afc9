//! Golden images: the baked sample assembly in every style (with edges and a shadow; the styles read
//! the file's lookup textures), a few option variants, and models from ../shared/models (an unbaked
//! one in the procedural metal), compared with the committed references in
//! `tests/golden/` within the tolerance of `common` (mean |Δ| ≤ 0.02, ≤ 1 % of pixels off by more
//! than 8 levels). `DRAFTER_UPDATE_GOLDEN=1 cargo test -p drafter-render --test golden` rewrites
//! them; look at every one before committing.

mod common;

use drafter_render::{Enhancements, RenderOptions, ShadowMode, Style, View};

/// Small images keep the suite fast on lavapipe.
const SIZE: (u32, u32) = (256, 192);

fn options(style: Style) -> RenderOptions {
    RenderOptions {
        size: SIZE,
        supersample: 1,
        style,
        enhancements: Enhancements::ALL,
        shadow: ShadowMode::Hard,
        ..RenderOptions::default()
    }
}

fn run_cases(model: &drafter_render::Model, cases: &[(String, RenderOptions)]) {
    let mut renderer = common::renderer();
    renderer.set_model(model).expect("upload");
    let mut failures = Vec::new();
    for (name, options) in cases {
        let image = renderer.render(options).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!((image.width, image.height), options.size, "{name}");
        // Something was drawn: not a blank background.
        let background = image.pixel(0, 0);
        let drawn = image.rgba.chunks_exact(4).filter(|p| p[..3] != background).count();
        assert!(drawn > (SIZE.0 * SIZE.1 / 20) as usize, "{name}: only {drawn} pixels differ from the background");
        failures.extend(common::check_golden(name, &image));
    }
    assert!(failures.is_empty(), "golden images differ:\n{}", failures.join("\n"));
}

#[test]
fn sample_assembly_in_every_style() {
    let model = common::sample();
    assert_eq!(model.parts.len(), 15);
    // Every style reads the baked lookup textures (the sample's metallic parts bring the metal ones),
    // except cel_ortho_top's 4 steps, which the baked 3-step table does not have.
    let l = model.lookups();
    let baked = [l.gamma.is_some(), l.cel.is_some(), l.cool_to_warm.is_some(), l.hatching.is_some(), l.metal.is_some()];
    assert_eq!(baked, [true; 5], "{:?}", model.notices);
    let mut cases: Vec<(String, RenderOptions)> =
        Style::ALL.iter().map(|&s| (format!("assembly_{s}"), options(s))).collect();
    cases.push((
        "assembly_phong_plain".into(),
        RenderOptions { enhancements: Enhancements::default(), shadow: ShadowMode::None, ..options(Style::Phong) },
    ));
    cases.push((
        "assembly_gradient_plain".into(),
        RenderOptions { enhancements: Enhancements::default(), shadow: ShadowMode::None, ..options(Style::Gradient) },
    ));
    cases.push((
        "assembly_gooch_penumbra".into(),
        RenderOptions { shadow: ShadowMode::Penumbra, ..options(Style::Gooch) },
    ));
    cases.push((
        "assembly_gooch_soft_splash".into(),
        RenderOptions { shadow: ShadowMode::Soft, splash_back: true, ..options(Style::Gooch) },
    ));
    cases.push((
        "assembly_cel_ortho_top".into(),
        RenderOptions {
            orthographic: true,
            view: View { azimuth_deg: -60.0, elevation_deg: 60.0 },
            cel_steps: 4,
            selected_part: Some(1),
            ..options(Style::Cel)
        },
    ));
    run_cases(&model, &cases);
}

#[test]
fn corpus_models() {
    // A real assembly (no normals in the file: face normals), baked in memory.
    let rod = common::baked(&common::corpus_path("gltf/RodAssembly/rod.glb"));
    run_cases(
        &rod,
        &[
            ("rod_gradient".into(), options(Style::Gradient)),
            (
                "rod_gooch".into(),
                RenderOptions { view: View { azimuth_deg: 120.0, elevation_deg: 20.0 }, ..options(Style::Gooch) },
            ),
        ],
    );
    // A single-mesh CAD part, unbaked: one part, a bounding-box projector, and a notice.
    let fandisk = drafter_render::Model::load(&common::corpus_path("obj/common-3d-test-models/fandisk.obj"))
        .expect("fandisk loads");
    assert!(!fandisk.baked && !fandisk.notices.is_empty());
    assert_eq!(*fandisk.lookups(), drafter_render::lookups::BakedLookups::default(), "procedural metal");
    run_cases(&fandisk, &[("fandisk_unbaked_metal".into(), options(Style::Metal))]);
}

#[test]
fn lines_on_the_sample_and_a_corpus_part() {
    // The lines pass alone (no image-space edges) and in the full illustration.
    let model = common::sample();
    run_cases(
        &model,
        &[
            (
                "assembly_gooch_lines".into(),
                RenderOptions { enhancements: Enhancements::default(), lines: true, ..options(Style::Gooch) },
            ),
            (
                "assembly_illustration_lines".into(),
                RenderOptions { lines: true, shadow: ShadowMode::Soft, ..options(Style::Gradient) },
            ),
            (
                "assembly_cel_lines_ortho".into(),
                RenderOptions {
                    enhancements: Enhancements::default(),
                    lines: true,
                    orthographic: true,
                    view: View { azimuth_deg: -60.0, elevation_deg: 60.0 },
                    ..options(Style::Cel)
                },
            ),
        ],
    );
    // A CAD part from ../shared/models, baked: creases white, silhouettes and boundaries black.
    let fandisk = common::baked(&common::corpus_path("obj/common-3d-test-models/fandisk.obj"));
    assert!(!fandisk.lines.is_empty());
    run_cases(
        &fandisk,
        &[(
            "fandisk_gooch_lines".into(),
            RenderOptions {
                enhancements: Enhancements::default(),
                lines: true,
                view: View { azimuth_deg: 150.0, elevation_deg: 30.0 },
                ..options(Style::Gooch)
            },
        )],
    );
}

/// A window renders in its surface's format (BGRA on X11 and Windows); screenshots render the
/// same frame offscreen in that format and read it back. The image must equal the headless RGBA
/// render pixel for pixel (this failed with a validation error that closed the window).
#[test]
fn bgra_output_reads_back_as_the_rgba_render() {
    let model = common::sample();
    let options = options(Style::Gooch);
    let mut rgba = common::renderer();
    rgba.set_model(&model).expect("upload");
    let expected = rgba.render(&options).expect("rgba render");
    let gpu = drafter_render::context::Gpu::headless().expect("adapter");
    let mut bgra =
        drafter_render::renderer::Renderer::with_gpu(gpu, wgpu::TextureFormat::Bgra8Unorm).expect("bgra renderer");
    bgra.set_model(&model).expect("upload");
    let image = bgra.render(&options).expect("bgra render");
    assert_eq!((image.width, image.height), (expected.width, expected.height));
    let differing = image.rgba.iter().zip(&expected.rgba).filter(|(a, b)| a.abs_diff(**b) > 1).count();
    assert_eq!(differing, 0, "{differing} channel values differ between the BGRA and RGBA renders");
}
