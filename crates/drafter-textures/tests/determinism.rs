//! Whole-crate properties: PNG bytes identical across runs and thread counts, PNG round trip and
//! layout, every texture well formed and every value finite and in range.

use drafter_core::gradient::TransferCurve;
use drafter_textures::preview::{preview, preview_hatching_levels, preview_metal};
use drafter_textures::{
    CelOptions, CoolToWarmOptions, EnvMapping, HatchingOptions, MetalOptions, Texture, TextureFormat, TextureKind,
    TextureRequest, bake_textures, cool_to_warm_colour, encode_png, encode_png_levels, hatching_ink,
    hatching_tone_layers, splash_back,
};
use glam::Vec3;

fn full_request() -> TextureRequest {
    TextureRequest {
        metal: Some(MetalOptions::default()),
        cool_to_warm: vec![
            CoolToWarmOptions::default(),
            CoolToWarmOptions { splash_back: true, ..Default::default() },
            CoolToWarmOptions {
                object_colour: Some([0.8, 0.3, 0.2]),
                mapping: EnvMapping::NormalSphere,
                size: 32,
                ..Default::default()
            },
        ],
        hatching: Some(HatchingOptions::default()),
        gamma_curves: TransferCurve::ALL.to_vec(),
        cel_tables: vec![CelOptions::default(), CelOptions { steps: 4, specular: true, ..Default::default() }],
    }
}

fn pngs(textures: &[Texture]) -> Vec<Vec<Vec<u8>>> {
    textures.iter().map(|t| encode_png_levels(t).expect("encodes")).collect()
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("thread pool").install(f)
}

#[test]
fn png_bytes_are_identical_across_runs_and_thread_counts() {
    let request = full_request();
    let one = in_pool(1, || pngs(&bake_textures(&request)));
    let four = in_pool(4, || pngs(&bake_textures(&request)));
    let again = pngs(&bake_textures(&request));
    assert_eq!(one.len(), 8);
    assert_eq!(one, four);
    assert_eq!(one, again);
    // The previews too.
    let previews =
        |t: &[Texture]| -> Vec<Vec<u8>> { t.iter().map(|t| encode_png(&preview(t, 48), 0).unwrap()).collect() };
    let p1 = in_pool(1, || previews(&bake_textures(&request)));
    let p3 = in_pool(3, || previews(&bake_textures(&request)));
    assert_eq!(p1, p3);
}

fn chunks(png: &[u8]) -> Vec<String> {
    let mut out = Vec::new();
    let mut i = 8;
    while i + 8 <= png.len() {
        let n = u32::from_be_bytes([png[i], png[i + 1], png[i + 2], png[i + 3]]) as usize;
        out.push(String::from_utf8_lossy(&png[i + 4..i + 8]).into_owned());
        i += 12 + n;
    }
    out
}

#[test]
fn png_round_trips_with_layers_stacked_vertically() {
    let mut textures = bake_textures(&full_request());
    let halftone = textures.iter().find(|t| t.name == "hatching").unwrap().clone();
    textures.push(hatching_tone_layers(&halftone, &[0.2, 0.5, 0.8], 4.0).unwrap());
    for t in &textures {
        for (m, png) in encode_png_levels(t).unwrap().iter().enumerate() {
            let kinds = chunks(png);
            assert_eq!(kinds.first().map(String::as_str), Some("IHDR"));
            assert_eq!(kinds.last().map(String::as_str), Some("IEND"));
            assert!(kinds[1..kinds.len() - 1].iter().all(|k| k == "IDAT"), "{}: {kinds:?}", t.name);
            let mut reader = png::Decoder::new(std::io::Cursor::new(png)).read_info().unwrap();
            let mut buf = vec![0; reader.output_buffer_size().unwrap()];
            let info = reader.next_frame(&mut buf).unwrap();
            let (w, h) = t.level_size(m);
            assert_eq!((info.width, info.height), (w, h * t.layers), "{} level {m}", t.name);
            assert_eq!(info.bit_depth, png::BitDepth::Eight);
            assert_eq!(
                info.color_type,
                match t.format {
                    TextureFormat::R8 => png::ColorType::Grayscale,
                    TextureFormat::Rgba8 => png::ColorType::Rgba,
                }
            );
            assert_eq!(&buf[..info.buffer_size()], &t.mip_levels[m][..], "{} level {m}", t.name);
        }
    }
    // An out-of-range level is an error, not a panic.
    assert!(encode_png(&textures[0], 7).is_err());
}

#[test]
fn textures_are_well_formed_and_sized_as_documented() {
    let textures = bake_textures(&full_request());
    let names: Vec<&str> = textures.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "metal_bands",
            "metal_highlights",
            "cool_to_warm_0",
            "cool_to_warm_1",
            "cool_to_warm_2",
            "hatching",
            "gamma_atlas",
            "cel_atlas"
        ]
    );
    for t in &textures {
        t.check().unwrap();
        let mips = t.mip_levels.len();
        assert_eq!(t.sampler.mipmaps, mips > 1, "{}", t.name);
        match &t.kind {
            TextureKind::MetalBands => assert_eq!((t.width, t.height, t.format), (256, 1, TextureFormat::R8)),
            TextureKind::MetalHighlights { .. } => assert_eq!((t.width, t.height), (128, 128)),
            TextureKind::CoolToWarm { .. } => assert_eq!(t.format, TextureFormat::Rgba8),
            TextureKind::Hatching { contrast } => {
                assert!(*contrast > 1.0);
                assert_eq!(mips, 4);
            }
            TextureKind::GammaAtlas { curves } => assert_eq!((t.width, t.height as usize), (128, curves.len())),
            TextureKind::CelAtlas { tables } => assert_eq!((t.width, t.height as usize), (128, tables.len())),
            TextureKind::HatchingToneLayers { .. } | TextureKind::Picture => unreachable!(),
        }
        // Previews render for every kind.
        preview(t, 24).check().unwrap();
    }
    preview_metal(&textures[0], &textures[1], 24).check().unwrap();
    preview_hatching_levels(&textures[5], 0.5).check().unwrap();
}

#[test]
fn shading_functions_are_finite_and_in_range_for_any_input() {
    let mut rng = drafter_core::rng::Rng::new(991);
    let mut specials = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -2.0, 2.0, 0.0, 1.0, -1.0];
    specials.extend((0..2000).map(|_| 3.0 * rng.signed_f32()));
    let o = CoolToWarmOptions { splash_back: true, ..Default::default() };
    for &x in &specials {
        for &y in specials.iter().step_by(97) {
            let ink = hatching_ink(x, y, 4.0);
            let c = cool_to_warm_colour(x, Vec3::splat(y.clamp(0.0, 1.0)), &o);
            assert!(ink.is_nan() || (0.0..=1.0).contains(&ink), "{x}, {y}: {ink}");
            if x.is_finite() {
                assert!(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0, "{x}: {c}");
                let s = splash_back(x, 0.76, 0.78);
                assert!(s.is_finite() && (0.0..=1.0).contains(&s), "{x}: {s}");
            }
        }
    }
    // NaN-bearing options are clamped, never propagated into texels.
    let bad = TextureRequest {
        metal: Some(MetalOptions { exponent: f32::NAN, specular_power: f32::INFINITY, ..Default::default() }),
        cool_to_warm: vec![CoolToWarmOptions { light_in_eye: [0.0; 3], blue: f32::NAN, size: 1, ..Default::default() }],
        hatching: Some(HatchingOptions { contrast: f32::NAN, size: 3, families: vec![], ..Default::default() }),
        ..Default::default()
    };
    assert!(bad.validate().is_err());
    for t in bake_textures(&bad) {
        t.check().unwrap();
    }
}
