//! The image type every generator returns, and a CPU sampler that is the reference for the viewer's
//! texture reads.
//!
//! # Layout
//! * `mip_levels[0]` is the full-size level; level `m` is `max(1, width >> m) × max(1, height >> m)`.
//!   Only hatching stores more than one level (its strokes are regenerated per level, see
//!   `crate::hatching`); a viewer must upload the stored levels rather than generate its own.
//! * Inside a level the bytes are layer-major, then rows top to bottom, then texels left to right,
//!   channels interleaved (`R` or `RGBA`, 8 bits each, UNORM: byte `b` means `b / 255`).
//! * Texture coordinates follow glTF: `uv = (0, 0)` is the top-left corner of row 0 (the first PNG
//!   row), texel `(i, j)` has its centre at `((i + 0.5) / w, (j + 0.5) / h)`.
//! * Values are stored as they are (no sRGB transfer): the lookups are data, and the colours are the
//!   papers' display values. Upload as `*Unorm`, not `*UnormSrgb`.

use glam::{Vec2, Vec4};
use serde::{Deserialize, Serialize};

use drafter_core::gradient::TransferCurve;

use crate::cel::CelOptions;
use crate::cool_warm::CoolToWarmEncoding;
use crate::envmap::EnvMapping;

/// Texel format: 8-bit UNORM channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TextureFormat {
    /// One channel (PNG greyscale).
    R8,
    /// Four channels (PNG RGBA, straight alpha).
    Rgba8,
}

impl TextureFormat {
    /// Bytes per texel.
    pub const fn channels(self) -> usize {
        match self {
            TextureFormat::R8 => 1,
            TextureFormat::Rgba8 => 4,
        }
    }
}

/// Addressing outside `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Wrap {
    /// Periodic (glTF `REPEAT`).
    Repeat,
    /// Edge texel extends (glTF `CLAMP_TO_EDGE`).
    ClampToEdge,
}

/// Texel filter (magnification and minification within a level).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Filter {
    /// Nearest texel.
    Nearest,
    /// Bilinear.
    Linear,
}

/// How the texture is meant to be sampled (the lead maps this onto a glTF sampler).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SamplerHint {
    /// Addressing in `u`.
    pub wrap_u: Wrap,
    /// Addressing in `v`.
    pub wrap_v: Wrap,
    /// Filter within a level.
    pub filter: Filter,
    /// `true`: sample with trilinear filtering over the stored mip levels (`LINEAR_MIPMAP_LINEAR`);
    /// `false`: the texture has one level and is sampled from it only.
    pub mipmaps: bool,
}

impl SamplerHint {
    /// Linear, clamped, no mips: every lookup table and environment map.
    pub const CLAMPED: SamplerHint =
        SamplerHint { wrap_u: Wrap::ClampToEdge, wrap_v: Wrap::ClampToEdge, filter: Filter::Linear, mipmaps: false };
}

/// What a texture holds and how a shader indexes it (the metadata the viewer needs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum TextureKind {
    /// Gooch metal bands, `R8`, `n × 1`: sampled at `u = s·(1 + n_obj·w)/2`, repeat (see `crate::metal`).
    MetalBands,
    /// Gooch metal Phong highlights (already scaled by the specular coefficient), `R8`, indexed by the
    /// eye-space normal through `mapping`; added to the banded colour.
    MetalHighlights {
        /// Parameterisation of the normal.
        mapping: EnvMapping,
    },
    /// Cool-to-warm shading, `Rgba8`, indexed by the eye-space normal through `mapping`.
    CoolToWarm {
        /// Parameterisation of the normal.
        mapping: EnvMapping,
        /// What the channels hold.
        encoding: CoolToWarmEncoding,
        /// The light direction the map was baked for (eye space, unit, towards the light).
        light_in_eye: [f32; 3],
        /// Whether the splash-back multiplier is included.
        splash_back: bool,
    },
    /// Hatching halftone `T`, `R8`, tileable, mip levels stored: ink = `clamp(c·(1 − (T + I)), 0, 1)`.
    Hatching {
        /// The recommended `c` (> 1).
        contrast: f32,
    },
    /// Tonal art map layers rendered from the halftone (`layers` = tones, layers stacked vertically
    /// in the PNG), `R8` paper brightness, tileable, mip levels stored.
    HatchingToneLayers {
        /// The intensity `I` each layer was rendered at, layer order.
        tones: Vec<f32>,
    },
    /// γ transfer tables, `R8`, 128 × rows, row `r` = `curves[r]`.
    GammaAtlas {
        /// The curve of each row.
        curves: Vec<TransferCurve>,
    },
    /// Cel step tables, `R8`, 128 × rows, row `r` = `tables[r]`.
    CelAtlas {
        /// The table of each row.
        tables: Vec<CelOptions>,
    },
    /// A picture for people (a `crate::preview`), not a lookup.
    Picture,
}

/// A baked image: 1D (height 1), 2D, or a layered array; 8-bit UNORM; level 0 first.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Stable name (`metal_bands`, `cool_to_warm_0`, …), used for file names and labels.
    pub name: String,
    /// What it holds and how it is indexed.
    pub kind: TextureKind,
    /// Width of level 0 in texels.
    pub width: u32,
    /// Height of level 0 in texels (of one layer).
    pub height: u32,
    /// Number of layers (1 for 1D and 2D textures).
    pub layers: u32,
    /// Texel format.
    pub format: TextureFormat,
    /// How to sample it.
    pub sampler: SamplerHint,
    /// Texel bytes per mip level, level 0 first (layout in the module docs).
    pub mip_levels: Vec<Vec<u8>>,
}

impl Texture {
    /// Width and height of mip level `level`.
    pub fn level_size(&self, level: usize) -> (u32, u32) {
        let shift = level.min(31) as u32;
        ((self.width >> shift).max(1), (self.height >> shift).max(1))
    }

    /// Expected byte count of mip level `level`.
    pub fn level_len(&self, level: usize) -> usize {
        let (w, h) = self.level_size(level);
        w as usize * h as usize * self.layers as usize * self.format.channels()
    }

    /// Total bytes of texel data over all levels.
    pub fn byte_len(&self) -> usize {
        self.mip_levels.iter().map(Vec::len).sum()
    }

    /// Checks the byte counts of every level (an internal invariant: every generator satisfies it).
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 || self.layers == 0 {
            return Err(format!("empty extent {}×{}×{}", self.width, self.height, self.layers));
        }
        if self.mip_levels.is_empty() {
            return Err("no mip levels".into());
        }
        for (m, data) in self.mip_levels.iter().enumerate() {
            if data.len() != self.level_len(m) {
                return Err(format!("level {m} has {} bytes, expected {}", data.len(), self.level_len(m)));
            }
        }
        Ok(())
    }

    /// Channel `c` of texel `(x, y)` of `layer` at `level`, as a value in `[0, 1]`. Out-of-range
    /// indices are clamped.
    pub fn texel(&self, level: usize, layer: u32, x: u32, y: u32, c: usize) -> f32 {
        let level = level.min(self.mip_levels.len().saturating_sub(1));
        let (w, h) = self.level_size(level);
        let ch = self.format.channels();
        let (x, y, layer, c) = (x.min(w - 1), y.min(h - 1), layer.min(self.layers - 1), c.min(ch - 1));
        let index = ((layer as usize * h as usize + y as usize) * w as usize + x as usize) * ch + c;
        self.mip_levels.get(level).and_then(|d| d.get(index)).map_or(0.0, |&b| f32::from(b) / 255.0)
    }

    /// Samples `layer` of `level` at `uv` with this texture's wrap modes and filter (the CPU reference
    /// of a GPU texture read; glTF convention, see the module docs). Channels a format lacks read 0,
    /// except alpha, which reads 1.
    pub fn sample(&self, level: usize, layer: u32, uv: Vec2) -> Vec4 {
        let (w, h) = self.level_size(level.min(self.mip_levels.len().saturating_sub(1)));
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let fetch = |xi: i64, yi: i64| -> Vec4 {
            let xi = wrap_index(xi, w, self.sampler.wrap_u);
            let yi = wrap_index(yi, h, self.sampler.wrap_v);
            match self.format {
                TextureFormat::R8 => Vec4::new(self.texel(level, layer, xi, yi, 0), 0.0, 0.0, 1.0),
                TextureFormat::Rgba8 => Vec4::from_array(std::array::from_fn(|c| self.texel(level, layer, xi, yi, c))),
            }
        };
        match self.sampler.filter {
            Filter::Nearest => fetch((x + 0.5).floor() as i64, (y + 0.5).floor() as i64),
            Filter::Linear => {
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let (xi, yi) = (x0 as i64, y0 as i64);
                let top = fetch(xi, yi).lerp(fetch(xi + 1, yi), fx);
                let bottom = fetch(xi, yi + 1).lerp(fetch(xi + 1, yi + 1), fx);
                top.lerp(bottom, fy)
            }
        }
    }
}

fn wrap_index(i: i64, n: u32, wrap: Wrap) -> u32 {
    let n = i64::from(n.max(1));
    match wrap {
        Wrap::Repeat => i.rem_euclid(n) as u32,
        Wrap::ClampToEdge => i.clamp(0, n - 1) as u32,
    }
}

/// `x ∈ [0, 1]` → the nearest 8-bit UNORM value (NaN → 0).
pub fn unorm8(x: f32) -> u8 {
    if x.is_nan() {
        return 0;
    }
    (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Texture {
        Texture {
            name: "ramp".into(),
            kind: TextureKind::MetalBands,
            width: 4,
            height: 1,
            layers: 1,
            format: TextureFormat::R8,
            sampler: SamplerHint { wrap_u: Wrap::Repeat, ..SamplerHint::CLAMPED },
            mip_levels: vec![vec![0, 85, 170, 255]],
        }
    }

    #[test]
    fn sampling_follows_the_gltf_texel_centres() {
        let t = ramp();
        t.check().unwrap();
        for (i, want) in [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0].into_iter().enumerate() {
            let u = (i as f32 + 0.5) / 4.0;
            assert!((t.sample(0, 0, Vec2::new(u, 0.5)).x - want).abs() < 1e-6);
        }
        // Halfway between the last and (wrapped) first texel.
        assert!((t.sample(0, 0, Vec2::new(1.0, 0.5)).x - 0.5).abs() < 1e-6);
        let clamped = Texture { sampler: SamplerHint::CLAMPED, ..ramp() };
        assert!((clamped.sample(0, 0, Vec2::new(1.0, 0.5)).x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn unorm8_rounds_and_clamps() {
        assert_eq!(unorm8(0.0), 0);
        assert_eq!(unorm8(1.0), 255);
        assert_eq!(unorm8(2.0), 255);
        assert_eq!(unorm8(-1.0), 0);
        assert_eq!(unorm8(f32::NAN), 0);
        assert_eq!(unorm8(0.5), 128);
        assert_eq!(unorm8(0.5 / 255.0 - 1e-4), 0);
    }

    #[test]
    fn check_finds_wrong_byte_counts() {
        let mut t = ramp();
        t.mip_levels[0].pop();
        assert!(t.check().is_err());
    }
}
