//! `Renderer::warm_pipelines` compiles, before any model is loaded, exactly the pipelines the first
//! frame of a model without style hints then draws with: the frame compiles none of its own.

mod common;

use drafter_render::{RenderOptions, Renderer, ShadowMode, Style};

fn first_frame_compiles(options: &RenderOptions) -> (usize, usize) {
    let mut renderer: Renderer = common::renderer();
    assert_eq!(renderer.compiled_pipelines(), 0, "a new renderer compiles nothing until asked");
    renderer.warm_pipelines(options);
    let warmed = renderer.compiled_pipelines();
    renderer.set_model(&common::sample()).expect("the sample uploads");
    renderer.render(options).expect("the frame renders");
    (warmed, renderer.compiled_pipelines() - warmed)
}

#[test]
fn warmed_pipelines_are_the_first_frames() {
    let plain = RenderOptions { style: Style::Phong, supersample: 1, size: (64, 48), ..Default::default() };
    let mut default_view = RenderOptions { style: Style::Gradient, lines: true, ..plain.clone() };
    default_view.enhancements = drafter_render::Enhancements::ALL;
    let shadowed = RenderOptions { style: Style::Gooch, shadow: ShadowMode::Soft, ..default_view.clone() };
    for (name, options, pipelines) in [("plain", &plain, 2), ("default", &default_view, 4), ("shadow", &shadowed, 5)] {
        let (warmed, more) = first_frame_compiles(options);
        assert_eq!(more, 0, "{name}: the first frame compiled {more} pipelines the warm-up did not");
        assert_eq!(warmed, pipelines, "{name}: the warm-up compiled {warmed} pipelines");
    }
}
