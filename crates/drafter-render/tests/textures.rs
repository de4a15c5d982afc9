//! The G-buffer uses the lookup textures a baked file embeds ("uses lines, normals and
//! textures as they land"): the loader decodes exactly the texels drafter-textures generates for the
//! bake's options, every baked lookup changes the image when its texels change, and a file without
//! textures falls back to the procedural lookups with a notice.

mod common;

use std::path::Path;

use drafter_bake::BakeConfig;
use drafter_render::lookups::{BakedLookups, LookupImage};
use drafter_render::{Model, RenderOptions, Style};

const SIZE: (u32, u32) = (160, 120);

fn options(style: Style) -> RenderOptions {
    RenderOptions { size: SIZE, supersample: 1, style, use_part_styles: false, ..RenderOptions::default() }
}

/// The sample assembly baked with `config`, loaded from the bytes as `drafter render` loads the file.
fn sample_with(config: &BakeConfig) -> Model {
    let path = common::repo_path("samples/assembly.glb");
    let imported = drafter_io::import(&path).expect("sample imports");
    let baked = drafter_bake::bake(&imported.scene, config).expect("sample bakes");
    Model::load_bytes(Path::new("assembly.baked.glb"), &baked.written.main).expect("baked sample loads")
}

fn level0(t: &drafter_textures::Texture) -> &[u8] {
    &t.mip_levels[0]
}

#[test]
fn the_loader_returns_the_texels_drafter_textures_generates() {
    let config = BakeConfig::default();
    let model = sample_with(&config);
    let lookups = model.lookups();
    let t = &config.textures;

    // The sample has metallic parts, so every lookup is baked.
    let notice = model.notices.iter().find(|n| n.starts_with("textures: ")).expect("a textures notice");
    assert_eq!(
        notice,
        "textures: baked (gamma_atlas, cel_atlas, cool_to_warm_0, hatching (4 levels), metal_bands, metal_highlights)"
    );

    let metal = lookups.metal.as_ref().expect("metal textures");
    assert_eq!(metal.bands.levels[0], level0(&drafter_textures::metal_bands(&t.metal)));
    assert_eq!(metal.highlights.levels[0], level0(&drafter_textures::metal_highlights(&t.metal)));

    let hatching = lookups.hatching.as_ref().expect("hatching");
    let halftone = drafter_textures::hatching_halftone(&t.hatching);
    assert_eq!(hatching.image.levels, halftone.mip_levels, "every stored mip level");
    assert_eq!(hatching.contrast, t.hatching.contrast);

    let cool = lookups.cool_to_warm.as_ref().expect("cool-to-warm map");
    let map = drafter_textures::cool_to_warm_map(&t.cool_to_warm, "cool_to_warm_0");
    assert_eq!(cool.image.levels[0], level0(&map));
    assert!(cool.factored && !cool.splash_back);

    let cel = lookups.cel.as_ref().expect("cel atlas");
    assert_eq!(cel.image.levels[0], level0(&drafter_textures::cel_atlas(&[t.cel])));

    // The γ atlas holds the parts' curves; its rows are the procedural atlas's rows to 8 bits.
    let gamma = lookups.gamma.as_ref().expect("γ atlas");
    assert_eq!(gamma.image.levels[0], level0(&drafter_textures::gamma_atlas(&gamma.curves)));
    let procedural = drafter_render::lookups::procedural_gamma();
    for (r, &curve) in gamma.curves.iter().enumerate() {
        let p = procedural.row(curve).expect("every curve has a procedural row");
        for k in 0..128 {
            let (baked, exact) = (gamma.image.texel(0, k, r as u32, 0), procedural.image.texel(0, k, p, 0));
            assert!((baked - exact).abs() <= 0.5 / 255.0 + 1e-6, "{curve:?} texel {k}: {baked} vs {exact}");
        }
    }
}

/// `lookups` with the image `pick` selects replaced by a constant.
fn with_constant(model: &Model, value: u8, pick: impl Fn(&mut BakedLookups) -> &mut LookupImage) -> Model {
    let mut lookups = model.lookups().clone();
    let image = pick(&mut lookups);
    for level in &mut image.levels {
        level.fill(value);
    }
    let mut altered = model.clone();
    altered.set_lookups(lookups);
    altered
}

#[test]
fn rendering_reads_every_baked_lookup() {
    let model = sample_with(&BakeConfig::default());
    let mut renderer = common::renderer();
    let mut render = |model: &Model, style: Style| {
        renderer.set_model(model).expect("upload");
        renderer.render(&options(style)).expect("render")
    };
    type Pick = fn(&mut BakedLookups) -> &mut LookupImage;
    let cases: [(Style, &str, u8, Pick); 6] = [
        (Style::Metal, "metal_bands", 255, |l| &mut l.metal.as_mut().expect("metal").bands),
        (Style::Metal, "metal_highlights", 0, |l| &mut l.metal.as_mut().expect("metal").highlights),
        (Style::Hatch, "hatching", 0, |l| &mut l.hatching.as_mut().expect("hatching").image),
        (Style::Gooch, "cool_to_warm_0", 128, |l| &mut l.cool_to_warm.as_mut().expect("map").image),
        (Style::Cel, "cel_atlas", 255, |l| &mut l.cel.as_mut().expect("cel").image),
        (Style::Gradient, "gamma_atlas", 0, |l| &mut l.gamma.as_mut().expect("γ").image),
    ];
    for (style, name, value, pick) in cases {
        let reference = render(&model, style);
        let altered = render(&with_constant(&model, value, pick), style);
        let d = reference.diff(&altered, 8).expect("same size");
        assert!(
            d.fraction_over > 0.05,
            "{style} with a constant {name}: only {:.3} of the pixels changed",
            d.fraction_over
        );
    }
}

#[test]
fn the_gradient_looks_the_same_from_the_baked_or_the_procedural_atlas() {
    // The same curves, 8-bit or float: only band edges may move, by under a pixel.
    let model = sample_with(&BakeConfig::default());
    assert!(model.lookups().gamma.is_some());
    let mut procedural = model.clone();
    procedural.set_lookups(BakedLookups { gamma: None, ..model.lookups().clone() });
    let mut renderer = common::renderer();
    renderer.set_model(&model).expect("upload");
    let baked = renderer.render(&options(Style::Gradient)).expect("render");
    renderer.set_model(&procedural).expect("upload");
    let d = renderer.render(&options(Style::Gradient)).expect("render").diff(&baked, 8).expect("same size");
    assert!(d.mean_abs < 0.002 && d.fraction_over < 0.005, "{d:?}");
}

#[test]
fn a_file_without_textures_renders_procedurally_with_a_notice() {
    let mut config = BakeConfig::default();
    config.textures.enabled = false;
    let model = sample_with(&config);
    assert_eq!(*model.lookups(), BakedLookups::default());
    assert!(model.notices.iter().any(|n| n == "textures: procedural (file has none)"), "{:?}", model.notices);
    let mut renderer = common::renderer();
    renderer.set_model(&model).expect("upload");
    for style in Style::ALL {
        renderer.render(&options(style)).unwrap_or_else(|e| panic!("{style}: {e}"));
    }
    // Only the metal parts (hint-free, metallic materials) would have brought metal textures.
    let mut metal_only = BakeConfig::default();
    metal_only.textures.styles = vec!["phong".parse().expect("a style name")];
    let model = sample_with(&metal_only);
    let names = model.lookups().names();
    assert_eq!(names, ["metal_bands", "metal_highlights"], "{:?}", model.notices);
    assert!(model.notices.iter().any(|n| n.contains("procedural for gradient, cel, gooch, hatch")));
}
