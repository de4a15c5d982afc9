//! `drafter render` framing, measured on the rendered image: the sample assembly, with and without
//! its drop shadow, from several views and at several aspects, is centred and its larger relative
//! side spans `1 − FIT_MARGIN` of the frame (the camera's unit tests check the same on points; this
//! checks that the points the model hands the camera are the drawn geometry and its shadow).

mod common;

use drafter_render::camera::FIT_MARGIN;
use drafter_render::{Image, RenderOptions, ShadowMode, Style, View};

/// The drawn content's box (left, right, top, bottom margins in pixels): every pixel that differs
/// from the background corner by more than a few levels.
fn margins(image: &Image) -> [u32; 4] {
    let background = image.pixel(0, 0);
    let (mut x0, mut x1, mut y0, mut y1) = (u32::MAX, 0, u32::MAX, 0);
    for y in 0..image.height {
        for x in 0..image.width {
            let p = image.pixel(x, y);
            let diff: u32 = (0..3).map(|c| u32::from(p[c].abs_diff(background[c]))).sum();
            if diff > 6 {
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
        }
    }
    assert!(x0 <= x1, "nothing drawn");
    [x0, image.width - 1 - x1, y0, image.height - 1 - y1]
}

#[test]
fn the_sample_and_its_shadow_are_centred_and_fill_the_frame() {
    let model = common::sample();
    let mut renderer = common::renderer();
    renderer.set_model(&model).expect("upload");
    let mut failures = Vec::new();
    for (size, view) in [
        ((400, 300), View { azimuth_deg: 35.0, elevation_deg: 25.0 }),
        ((240, 400), View { azimuth_deg: -120.0, elevation_deg: 40.0 }),
        ((480, 160), View { azimuth_deg: 200.0, elevation_deg: 10.0 }),
        ((320, 320), View { azimuth_deg: 80.0, elevation_deg: 70.0 }),
    ] {
        for shadow in [ShadowMode::None, ShadowMode::Hard, ShadowMode::Soft] {
            for orthographic in [false, true] {
                let options = RenderOptions {
                    size,
                    supersample: 1,
                    style: Style::Phong,
                    view,
                    shadow,
                    orthographic,
                    ..RenderOptions::default()
                };
                let image = renderer.render(&options).expect("render");
                let [left, right, top, bottom] = margins(&image);
                let fill_w = (size.0 - left - right) as f32 / size.0 as f32;
                let fill_h = (size.1 - top - bottom) as f32 / size.1 as f32;
                let fill = fill_w.max(fill_h);
                // Within 3 pixels: rounding, and the shadow mask's half resolution filtered up
                // (its edge spreads by a pixel or two; a soft shadow's faintest edge may fall under
                // the threshold).
                let slack = 3;
                let centred = left.abs_diff(right) <= slack && top.abs_diff(bottom) <= slack;
                let fill_slack = 0.01 + 2.0 * slack as f32 / size.0.min(size.1) as f32;
                let fills = (fill - (1.0 - FIT_MARGIN)).abs() <= fill_slack;
                if !centred || !fills {
                    failures.push(format!(
                        "{size:?} {view:?} {shadow:?} ortho {orthographic}: margins l {left} r {right} t {top} b \
                         {bottom}, fills {fill_w:.3} × {fill_h:.3}"
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "badly framed:\n{}", failures.join("\n"));
}

#[test]
fn an_interactive_frame_is_the_still_frame_at_a_lower_resolution() {
    let model = common::sample();
    let mut renderer = common::renderer();
    renderer.set_model(&model).expect("upload");
    let still = RenderOptions {
        size: (320, 240),
        style: Style::Gradient,
        enhancements: drafter_render::Enhancements::ALL,
        lines: true,
        shadow: ShadowMode::Soft,
        ..RenderOptions::default()
    };
    let before = renderer.render(&still).expect("still frame");
    let dragged = renderer.render(&RenderOptions { interactive: true, ..still.clone() }).expect("interactive frame");
    let info = renderer.last_frame().expect("a frame");
    assert_eq!((info.target_size, info.drawn_size), ((320, 240), (160, 120)));
    assert_eq!((dragged.width, dragged.height), (320, 240));
    // Half a part-id texel away from the centre of the drawn image: the same part as the still frame.
    let picked_dragged = renderer.pick(160, 120).expect("pick");
    let after = renderer.render(&still).expect("still frame again");
    assert_eq!(before, after, "a still frame after an interactive one is unchanged");
    assert_eq!(renderer.pick(160, 120).expect("pick"), picked_dragged);
    // The same picture, softer: edges and lines move by a pixel or so and are drawn twice as wide.
    let diff = before.diff(&dragged, 64).expect("same size");
    if !(diff.mean_abs < 0.05 && diff.fraction_over < 0.08) {
        let path = std::env::temp_dir().join("drafter_interactive_frame.png");
        std::fs::write(&path, dragged.to_png().expect("PNG")).expect("write the interactive frame");
        panic!("{diff:?}: the interactive frame is at {}", path.display());
    }
}
