//! The NPR lookup textures the G-buffer pass samples: the ones a baked file embeds
//! (`DRAFTER_illustration.textures`, drafter-textures' images), decoded and checked on the CPU, with
//! the viewer's procedural tables where the file has none.
//!
//! # What comes from where
//! | lookup | baked (the file's PNG) | procedural fallback (any glTF) |
//! |---|---|---|
//! | γ transfer tables (`gradient`) | `gamma_atlas` (8 bits), one row per distinct curve; a part reads the row of its `gradient.transfer` | every [`TransferCurve::ALL`] as a 128-texel row in 32-bit float, exactly as drafter-core's `IntensityTransfer::sample` interpolates |
//! | cel steps (`cel`, `goochel`) | `cel_atlas`: the row whose `steps` and `specular` equal the frame's options | the step function in the shader |
//! | cool-to-warm (`gooch`, `goochel`) | `cool_to_warm_0` | the Gooch et al. 1998 formula in the shader |
//! | halftone (`hatch`) | `hatching` + `hatching_mipN`, uploaded as the mip chain | screen-space strokes in the shader |
//! | metal (`metal`) | `metal_bands`, `metal_highlights` | the bake's band table ([`crate::style::metal_table`]) and six lights in the shader |
//!
//! The γ atlas is always a texture (procedural or baked, same slot, same lookup); for the others the
//! G-buffer binds a 1 × 1 placeholder and a flag tells the shader to compute instead. Every lookup is
//! independent: a file without a metal part still has its γ atlas and halftone used.
//!
//! # Flawed files
//! A texture that cannot be decoded, or whose size or record does not fit (a γ atlas whose rows do
//! not match its `curves`, a mip level of the wrong size, a curve some part needs but the atlas
//! lacks), is left out with a notice, and that lookup falls back to the procedural one: a file
//! renders whatever its textures hold. Images are 8-bit; a PNG with another channel count is
//! converted (grey → RGBA, or the first channel of RGBA as R).
//!
//! [`BakedLookups::notice`] is the one line `drafter render` prints: `textures: baked (gamma_atlas,
//! …)` or `textures: procedural (file has none)`.

use std::io::Cursor;

use drafter_core::gradient::TransferCurve;
use drafter_format::{
    CelTableRecord, CelTexture, CoolToWarmTexture, EmbeddedPng, GradientTexture, HatchingTexture, MetalTexture,
    TexturesRecord,
};
use glam::Vec3;

/// The start of [`BakedLookups::notice`] (so a model can replace its line).
pub const NOTICE_PREFIX: &str = "textures: ";

/// Largest side of a lookup texture the viewer uploads (the bake writes at most 4096).
pub const MAX_LOOKUP_SIDE: u32 = 4096;

/// Texel format of a lookup image: the file's are 8-bit UNORM, uploaded as `R8Unorm` /
/// `Rgba8Unorm` (the values are data, never sRGB); the procedural γ atlas is 32-bit float.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LookupFormat {
    R8,
    Rgba8,
    /// One little-endian `f32` per texel.
    R32Float,
}

impl LookupFormat {
    /// Bytes per texel.
    pub const fn texel_bytes(self) -> usize {
        match self {
            LookupFormat::R8 => 1,
            LookupFormat::Rgba8 | LookupFormat::R32Float => 4,
        }
    }
}

/// A decoded lookup image: level 0 first, rows top to bottom (glTF's `v` down).
#[derive(Clone, Debug, PartialEq)]
pub struct LookupImage {
    /// The image's name in the file (`gamma_atlas`, …), or `procedural …`; also the GPU label.
    pub name: String,
    /// Width of level 0.
    pub width: u32,
    /// Height of level 0.
    pub height: u32,
    pub format: LookupFormat,
    /// Texel bytes of each mip level; level `m` is `max(1, width >> m) × max(1, height >> m)`.
    pub levels: Vec<Vec<u8>>,
}

impl LookupImage {
    /// A one-level image; `None` when `texels` does not hold `width × height` texels.
    pub fn new(name: &str, width: u32, height: u32, format: LookupFormat, texels: Vec<u8>) -> Option<LookupImage> {
        (texels.len() == width as usize * height as usize * format.texel_bytes() && width > 0 && height > 0)
            .then(|| LookupImage { name: name.to_owned(), width, height, format, levels: vec![texels] })
    }

    /// Size of mip level `level`.
    pub fn level_size(&self, level: usize) -> (u32, u32) {
        let shift = level.min(31) as u32;
        ((self.width >> shift).max(1), (self.height >> shift).max(1))
    }

    /// Channel `c` of texel (`x`, `y`) of `level` (UNORM in [0, 1]; 0 outside the image).
    pub fn texel(&self, level: usize, x: u32, y: u32, c: usize) -> f32 {
        let (w, _) = self.level_size(level);
        let texel = (y as usize * w as usize + x as usize) * self.format.texel_bytes();
        let Some(data) = self.levels.get(level) else { return 0.0 };
        match self.format {
            LookupFormat::R8 | LookupFormat::Rgba8 => {
                let c = if self.format == LookupFormat::R8 { 0 } else { c.min(3) };
                data.get(texel + c).map_or(0.0, |&b| f32::from(b) / 255.0)
            }
            LookupFormat::R32Float => {
                data.get(texel..texel + 4).map_or(0.0, |b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            }
        }
    }
}

/// How an environment map is indexed by the eye-space normal: the shared rule, which the
/// bake writes (the spec's `mapping` / `highlightMapping`).
pub use drafter_core::env_map::EnvMapping;

/// The γ atlas: row `r` holds `curves[r]`.
#[derive(Clone, Debug, PartialEq)]
pub struct GammaLookup {
    pub image: LookupImage,
    pub curves: Vec<TransferCurve>,
}

impl GammaLookup {
    /// The atlas row of `curve`.
    pub fn row(&self, curve: TransferCurve) -> Option<u32> {
        self.curves.iter().position(|&c| c == curve).map(|r| r as u32)
    }
}

/// The cel atlas: row `r` holds `tables[r]`.
#[derive(Clone, Debug, PartialEq)]
pub struct CelLookup {
    pub image: LookupImage,
    pub tables: Vec<CelTableRecord>,
}

/// A cool-to-warm map (Gooch et al. 1999, Fig. 10).
#[derive(Clone, Debug, PartialEq)]
pub struct CoolToWarmLookup {
    pub image: LookupImage,
    pub mapping: EnvMapping,
    /// RGB = base, A = object-colour weight (`clamp(rgb + a·k_d)`); `false`: RGB is the colour.
    pub factored: bool,
    /// Unit direction towards the light the map was baked for (eye space).
    pub light_in_eye: Vec3,
    /// Whether the splash-back multiplier is in the map.
    pub splash_back: bool,
}

/// The hatching halftone T with its stored mip levels.
#[derive(Clone, Debug, PartialEq)]
pub struct HatchingLookup {
    pub image: LookupImage,
    /// The soft threshold's `c` the file recommends.
    pub contrast: f32,
}

/// Gooch metal: bands (`n × 1`, repeat) and highlights (indexed by the eye-space normal).
#[derive(Clone, Debug, PartialEq)]
pub struct MetalLookup {
    pub bands: LookupImage,
    pub highlights: LookupImage,
    pub mapping: EnvMapping,
}

/// The lookups a file carries, each `None` when absent or unusable (the shader then computes it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BakedLookups {
    pub gamma: Option<GammaLookup>,
    pub cel: Option<CelLookup>,
    pub cool_to_warm: Option<CoolToWarmLookup>,
    pub hatching: Option<HatchingLookup>,
    pub metal: Option<MetalLookup>,
}

impl BakedLookups {
    /// Reads and decodes the textures of a baked glTF/GLB (`record`: the root extension's
    /// `textures`; `external` loads a .gltf's buffer). Problems come back as notices, never as an
    /// error: the lookups concerned are left out.
    pub fn read(
        record: Option<&TexturesRecord>,
        bytes: &[u8],
        external: &dyn Fn(&str) -> Option<Vec<u8>>,
    ) -> (BakedLookups, Vec<String>) {
        let Some(record) = record else { return (BakedLookups::default(), Vec::new()) };
        match drafter_format::read_textures(bytes, external) {
            Ok(pngs) => Self::from_record(record, &pngs),
            Err(e) => (BakedLookups::default(), vec![format!("textures unreadable ({e}): procedural lookups used")]),
        }
    }

    /// Decodes `pngs` (from [`drafter_format::read_textures`]) as `record` describes them.
    pub fn from_record(record: &TexturesRecord, pngs: &[EmbeddedPng]) -> (BakedLookups, Vec<String>) {
        let mut d = Decoder { pngs, notices: Vec::new() };
        if record.cool_to_warm.len() > 1 {
            d.notices.push(format!("{} cool-to-warm maps: the first is used", record.cool_to_warm.len()));
        }
        let lookups = BakedLookups {
            gamma: record.gradient.as_ref().and_then(|g| d.gamma(g)),
            cel: record.cel.as_ref().and_then(|c| d.cel(c)),
            cool_to_warm: record.cool_to_warm.first().and_then(|c| d.cool_to_warm(c)),
            hatching: record.hatching.as_ref().and_then(|h| d.hatching(h)),
            metal: record.metal.as_ref().and_then(|m| d.metal(m)),
        };
        (lookups, d.notices)
    }

    /// Names of the baked images in use, in the spec's order.
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::new();
        names.extend(self.gamma.as_ref().map(|g| g.image.name.clone()));
        names.extend(self.cel.as_ref().map(|c| c.image.name.clone()));
        names.extend(self.cool_to_warm.as_ref().map(|c| c.image.name.clone()));
        if let Some(h) = &self.hatching {
            names.push(format!("{} ({} levels)", h.image.name, h.image.levels.len()));
        }
        if let Some(m) = &self.metal {
            names.extend([m.bands.name.clone(), m.highlights.name.clone()]);
        }
        names
    }

    /// The lookups computed by the viewer instead (style names).
    fn procedural(&self) -> Vec<&'static str> {
        let mut out = Vec::new();
        if self.gamma.is_none() {
            out.push("gradient");
        }
        if self.cel.is_none() {
            out.push("cel");
        }
        if self.cool_to_warm.is_none() {
            out.push("gooch");
        }
        if self.hatching.is_none() {
            out.push("hatch");
        }
        if self.metal.is_none() {
            out.push("metal");
        }
        out
    }

    /// One line: which lookups are baked and which procedural.
    pub fn notice(&self) -> String {
        let names = self.names();
        if names.is_empty() {
            return format!("{NOTICE_PREFIX}procedural (file has none)");
        }
        let procedural = self.procedural();
        let rest = if procedural.is_empty() {
            String::new()
        } else {
            format!("; procedural for {} (not in the file)", procedural.join(", "))
        };
        format!("{NOTICE_PREFIX}baked ({}){rest}", names.join(", "))
    }

    /// Drops the γ atlas when a part needs a curve it lacks (`curves`: every part's curve); the
    /// notice, if any.
    pub fn require_curves(&mut self, curves: impl IntoIterator<Item = TransferCurve>) -> Option<String> {
        let gamma = self.gamma.as_ref()?;
        let missing: Vec<TransferCurve> = curves.into_iter().filter(|&c| gamma.row(c).is_none()).collect();
        let first = missing.first()?;
        let name = gamma.image.name.clone();
        self.gamma = None;
        Some(format!("{name} lacks the curve {first:?} that {} parts use: procedural lookup used", missing.len()))
    }
}

/// Decodes the images a record refers to, collecting what does not fit as notices.
struct Decoder<'a> {
    pngs: &'a [EmbeddedPng],
    notices: Vec<String>,
}

impl Decoder<'_> {
    /// Leaves a lookup out, saying why.
    fn reject<T>(&mut self, what: &str, why: impl std::fmt::Display) -> Option<T> {
        self.notices.push(format!("{what}: {why}: procedural lookup used"));
        None
    }

    fn image(&mut self, index: u32, format: LookupFormat) -> Option<LookupImage> {
        let Some(png) = self.pngs.iter().find(|p| p.texture == index) else {
            return self.reject(&format!("texture {index}"), "not in the file");
        };
        match decode_png(&png.name, &png.png, format) {
            Ok(image) => Some(image),
            Err(e) => self.reject(&format!("texture {index} ({})", png.name), e),
        }
    }

    fn gamma(&mut self, g: &GradientTexture) -> Option<GammaLookup> {
        let image = self.image(g.index, LookupFormat::R8)?;
        let curves = g.curves.clone();
        if curves.len() != image.height as usize {
            return self.reject(&image.name, format!("{} rows for {} curves", image.height, curves.len()));
        }
        Some(GammaLookup { image, curves })
    }

    fn cel(&mut self, c: &CelTexture) -> Option<CelLookup> {
        let image = self.image(c.index, LookupFormat::R8)?;
        if c.tables.len() != image.height as usize {
            return self.reject(&image.name, format!("{} rows for {} tables", image.height, c.tables.len()));
        }
        Some(CelLookup { image, tables: c.tables.clone() })
    }

    fn cool_to_warm(&mut self, c: &CoolToWarmTexture) -> Option<CoolToWarmLookup> {
        let image = self.image(c.index, LookupFormat::Rgba8)?;
        let light = Vec3::new(c.light_in_eye[0] as f32, c.light_in_eye[1] as f32, c.light_in_eye[2] as f32);
        let factored = c.encoding == drafter_format::CoolToWarmEncoding::Factored;
        match light.try_normalize() {
            Some(light_in_eye) => {
                Some(CoolToWarmLookup { image, mapping: c.mapping, factored, light_in_eye, splash_back: c.splash_back })
            }
            None => self.reject(&image.name, format!("light {light} is not a direction")),
        }
    }

    fn hatching(&mut self, h: &HatchingTexture) -> Option<HatchingLookup> {
        let levels: Vec<LookupImage> = h.levels.iter().map_while(|l| self.image(l.index, LookupFormat::R8)).collect();
        let image = match mip_chain(levels) {
            Ok(image) => image,
            Err(why) => return self.reject("hatching", why),
        };
        if image.levels.len() < h.levels.len() {
            self.notices.push(format!(
                "hatching: {} of {} mip levels usable: the coarser ones are left out",
                image.levels.len(),
                h.levels.len()
            ));
        }
        let contrast =
            if h.contrast.is_finite() && h.contrast > 1.0 { h.contrast as f32 } else { crate::style::HATCH_SHARPNESS };
        Some(HatchingLookup { image, contrast })
    }

    fn metal(&mut self, m: &MetalTexture) -> Option<MetalLookup> {
        let bands = self.image(m.bands.index, LookupFormat::R8)?;
        let highlights = self.image(m.highlights.index, LookupFormat::R8)?;
        Some(MetalLookup { bands, highlights, mapping: m.highlight_mapping })
    }
}

/// The levels as one mip chain: level `m` must be `max(1, w >> m) × max(1, h >> m)`; the chain
/// stops at the first level that is not.
fn mip_chain(levels: Vec<LookupImage>) -> Result<LookupImage, String> {
    let mut levels = levels.into_iter();
    let mut chain = levels.next().ok_or_else(|| "no level decodes".to_owned())?;
    for (m, level) in levels.enumerate() {
        if (level.width, level.height) != chain.level_size(m + 1) {
            break;
        }
        chain.levels.extend(level.levels);
    }
    Ok(chain)
}

/// Why a texture PNG cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum LookupError {
    #[error(transparent)]
    Png(#[from] png::DecodingError),
    #[error("{0}")]
    Layout(String),
}

/// Decodes an 8-bit PNG into `format` (see the module docs for conversions).
pub fn decode_png(name: &str, bytes: &[u8], format: LookupFormat) -> Result<LookupImage, LookupError> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info()?;
    let (width, height) = (reader.info().width, reader.info().height);
    if width == 0 || height == 0 || width > MAX_LOOKUP_SIDE || height > MAX_LOOKUP_SIDE {
        return Err(LookupError::Layout(format!("{width}×{height} is outside 1..={MAX_LOOKUP_SIDE} a side")));
    }
    let size = reader.output_buffer_size().ok_or_else(|| LookupError::Layout("image too large".into()))?;
    let mut buffer = vec![0; size];
    let info = reader.next_frame(&mut buffer)?;
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        other => return Err(LookupError::Layout(format!("unsupported colour type {other:?}"))),
    };
    let pixels = width as usize * height as usize;
    let texels = buffer.get(..pixels * channels).ok_or_else(|| LookupError::Layout("short image".into()))?;
    let data: Vec<u8> = match (format, channels) {
        (LookupFormat::R8, _) => texels.chunks_exact(channels).map(|p| p[0]).collect(),
        (LookupFormat::Rgba8, 4) => texels.to_vec(),
        (LookupFormat::Rgba8, 3) => texels.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect(),
        (LookupFormat::Rgba8, 2) => texels.chunks_exact(2).flat_map(|p| [p[0], p[0], p[0], p[1]]).collect(),
        (LookupFormat::Rgba8, _) => texels.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        (LookupFormat::R32Float, _) => return Err(LookupError::Layout("PNG textures are 8-bit".into())),
    };
    LookupImage::new(name, width, height, format, data).ok_or_else(|| LookupError::Layout("short image".into()))
}
/// The procedural γ atlas: row `k` is `TransferCurve::ALL[k]`, texel `j` = γ(j/127) in `f32`
/// ([`crate::style::transfer_tables`]).
pub fn procedural_gamma() -> GammaLookup {
    let curves = TransferCurve::ALL.to_vec();
    let texels: Vec<u8> = crate::style::transfer_tables().iter().flat_map(|v| v.to_le_bytes()).collect();
    let width = drafter_core::gradient::INTENSITY_TABLE_LEN as u32;
    let image = LookupImage {
        name: "procedural gamma atlas".into(),
        width,
        height: curves.len() as u32,
        format: LookupFormat::R32Float,
        levels: vec![texels],
    };
    GammaLookup { image, curves }
}

/// The procedural metal table ([`crate::style::metal_table`]) as an `n × 1` image (entry `k` at
/// texel `k`; the shader reads it by the angle around the axis).
pub fn procedural_metal_bands() -> LookupImage {
    let table = crate::style::metal_table();
    LookupImage {
        name: "procedural metal table".into(),
        width: table.len() as u32,
        height: 1,
        format: LookupFormat::R8,
        levels: vec![table.into_iter().map(drafter_textures::unorm8).collect()],
    }
}

/// A 1 × 1 image bound where a lookup is computed in the shader instead.
pub fn placeholder(name: &str, format: LookupFormat) -> LookupImage {
    LookupImage {
        name: format!("{name} placeholder"),
        width: 1,
        height: 1,
        format,
        levels: vec![vec![0; format.texel_bytes()]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png(width: u32, height: u32, color: png::ColorType, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut out, width, height);
            encoder.set_color(color);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().unwrap();
            writer.write_image_data(data).unwrap();
            writer.finish().unwrap();
        }
        out
    }

    #[test]
    fn pngs_decode_into_the_asked_format() {
        let grey = png(2, 1, png::ColorType::Grayscale, &[10, 200]);
        let r = decode_png("g", &grey, LookupFormat::R8).unwrap();
        assert_eq!((r.width, r.height, r.levels[0].clone()), (2, 1, vec![10, 200]));
        let rgba = decode_png("g", &grey, LookupFormat::Rgba8).unwrap();
        assert_eq!(rgba.levels[0], [10, 10, 10, 255, 200, 200, 200, 255]);
        let colour = png(1, 1, png::ColorType::Rgba, &[1, 2, 3, 4]);
        assert_eq!(decode_png("c", &colour, LookupFormat::R8).unwrap().levels[0], [1]);
        assert_eq!(decode_png("c", &colour, LookupFormat::Rgba8).unwrap().levels[0], [1, 2, 3, 4]);
        assert!(decode_png("x", b"not a png", LookupFormat::R8).is_err());
    }

    #[test]
    fn flawed_records_leave_their_lookup_out_with_a_notice() {
        use drafter_format::{GradientTexture, HatchingTexture, TextureRef};
        let embedded = |texture: u32, png: Vec<u8>| EmbeddedPng { texture, name: format!("t{texture}"), png };
        let row = png(128, 1, png::ColorType::Grayscale, &[7; 128]);
        let level = |w: u32| png(w, w, png::ColorType::Grayscale, &vec![0; (w * w) as usize]);
        let pngs = [embedded(0, row.clone()), embedded(1, level(8)), embedded(2, level(4)), embedded(3, level(3))];
        let gradient = |curves: &[TransferCurve]| GradientTexture { index: 0, curves: curves.to_vec() };
        let record = TexturesRecord {
            gradient: Some(gradient(&[TransferCurve::Smoothstep])),
            hatching: Some(HatchingTexture {
                levels: [1, 2, 3, 9].into_iter().map(|index| TextureRef { index }).collect(),
                contrast: 4.0,
            }),
            ..Default::default()
        };
        let (lookups, notices) = BakedLookups::from_record(&record, &pngs);
        let gamma = lookups.gamma.expect("one row, one curve");
        assert_eq!(
            (gamma.curves.as_slice(), gamma.image.texel(0, 5, 0, 0)),
            (&[TransferCurve::Smoothstep][..], 7.0 / 255.0)
        );
        // Level 2 is 3×3 instead of 2×2: the chain keeps levels 0 and 1.
        assert_eq!(lookups.hatching.expect("hatching").image.levels.len(), 2);
        assert_eq!(
            notices,
            [
                "texture 9: not in the file: procedural lookup used",
                "hatching: 2 of 4 mip levels usable: the coarser ones are left out"
            ]
        );
        // Two curves for one row; a texture the file lacks.
        for (curves, index, notice) in [
            (
                &[TransferCurve::Identity, TransferCurve::Invert][..],
                0,
                "t0: 1 rows for 2 curves: procedural lookup used",
            ),
            (&[TransferCurve::Identity][..], 5, "texture 5: not in the file: procedural lookup used"),
        ] {
            let record =
                TexturesRecord { gradient: Some(GradientTexture { index, ..gradient(curves) }), ..Default::default() };
            let (lookups, notices) = BakedLookups::from_record(&record, &pngs);
            assert!(lookups.gamma.is_none());
            assert_eq!(notices, [notice]);
        }
    }

    #[test]
    fn mip_chains_stop_at_a_wrong_size() {
        let level = |w: u32| LookupImage::new("h", w, w, LookupFormat::R8, vec![0; (w * w) as usize]).unwrap();
        let chain = mip_chain(vec![level(8), level(4), level(2), level(1)]).unwrap();
        assert_eq!(chain.levels.len(), 4);
        let chain = mip_chain(vec![level(8), level(4), level(3), level(1)]).unwrap();
        assert_eq!(chain.levels.len(), 2);
        assert!(mip_chain(Vec::new()).is_err());
    }

    #[test]
    fn procedural_gamma_rows_follow_the_curves() {
        let g = procedural_gamma();
        assert_eq!((g.image.width, g.image.height), (128, 5));
        for (r, &c) in TransferCurve::ALL.iter().enumerate() {
            assert_eq!(g.row(c), Some(r as u32));
            let got = g.image.texel(0, 64, r as u32, 0);
            assert!((f64::from(got) - c.eval(64.0 / 127.0)).abs() <= 1e-6, "{c:?}");
        }
        let bands = procedural_metal_bands();
        assert_eq!((bands.width, bands.height), (crate::style::METAL_TABLE_LEN as u32, 1));
    }

    #[test]
    fn the_notice_names_the_source() {
        let none = BakedLookups::default();
        assert_eq!(none.notice(), "textures: procedural (file has none)");
        let mut some = BakedLookups { gamma: Some(procedural_gamma()), ..Default::default() };
        some.gamma.as_mut().unwrap().image.name = "gamma_atlas".into();
        assert_eq!(
            some.notice(),
            "textures: baked (gamma_atlas); procedural for cel, gooch, hatch, metal (not in the file)"
        );
        // A part whose curve the atlas lacks sends the gradient back to the procedural tables.
        some.gamma.as_mut().unwrap().curves = vec![TransferCurve::Identity];
        assert!(some.require_curves([TransferCurve::Identity]).is_none());
        assert!(some.require_curves([TransferCurve::Identity, TransferCurve::EaseIn]).is_some());
        assert!(some.gamma.is_none());
    }
}
