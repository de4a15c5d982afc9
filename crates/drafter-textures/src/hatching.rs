//! Hatching halftones (Freudenberg, "Real-Time Stroke Textures", ../shared/papers/002_*; ten Bosch
//! 2005, simple and blended hatching, 003_*).
//!
//! # How it works
//! Freudenberg: "a 3D halftone pattern is created as texture T and compared at every pixel with the
//! target intensity I [...] To smooth the harsh transition from white to black we instead take the
//! inverted sum of T and I and scale it by some constant c > 1. After clamping the result to the
//! range (0…1) we get a mostly black and white output while still preserving a few gray levels."
//!
//! The halftone `T` baked here is a *threshold field*: a pixel is inked once the darkness `1 − I`
//! exceeds `T`, so the shader computes
//! ```text
//! ink    = clamp(c · (1 − (T + I)), 0, 1)        // c > 1: [`HatchingOptions::contrast`]
//! colour = mix(paper, pen, ink)
//! ```
//! `T` is built from stroke families ([`StrokeFamily`]): parallel, tileable lines whose normal is an
//! integer vector `(a, b)` in tile coordinates (`u` right, `v` down), `n` lines per tile. For a texel
//! at `(u, v)` the phase `n·(a·u + b·v)` is integral on a line; with `d ∈ [0, 1]` the distance to the
//! nearest line in half-spacings (0 on the line, 1 midway) and `k` the flat core
//! ([`STROKE_CORE_TEXELS`] in half-spacings),
//! ```text
//! T = min over families f of  onset_f + growth_f · max(d_f − k, 0)/(1 − k) / width_(f, line)
//! ```
//! so family `f` starts to draw when the darkness passes `onset_f` and its strokes widen as it grows
//! — variable-width strokes (Freudenberg's Fig. 1) that cross-hatch in darker tones (the default
//! families: `/` strokes from darkness 0.05, `\` from 0.35, horizontal from 0.65). Each line carries a
//! seeded offset, width factor and a gentle periodic waviness so the strokes look drawn. Since `T`
//! is a smooth field and `c` is finite, a stroke's edge spans about `1/(c·|∇T|)` texels (≈1.3 with
//! the defaults): no stair-stepping at 1:1 and under bilinear magnification.
//!
//! # Tiling and mip levels
//! Everything is periodic in the tile (integer normals and integer line counts; the waviness
//! repeats an integer number of times), so `T` tiles with `REPEAT`. Box-filtering a threshold field
//! would average stroke positions into a flat grey that flips from white to black at once; instead
//! each level is *regenerated*: level `m` (edge `size/2^m`) keeps every `2^m`-th line of level 0 at
//! the same place in the tile with the same width in texels, so the strokes keep their screen
//! density and width (as Praun et al.'s tonal art maps) and trilinear blending between levels fades
//! lines in and out instead of blurring them. Levels stop where a family would have fewer than one
//! line per tile (with the defaults, 128 → 16 texels: 4 levels); a viewer creates the texture with
//! exactly the stored levels (`mip_level_count = mip_levels.len()`), so coarser views clamp to the
//! last one.
//!
//! # Tonal art map layers
//! [`hatching_tone_layers`] renders `1 − ink` at a list of intensities (every level), for ten Bosch's
//! "simple" (pick a layer per intensity band) and "blended" (interpolate between layers) hatching.
//! Their mean brightness falls monotonically with the tone (tested).
//!
//! Texture coordinates: screen space as ten Bosch (`uv = pixel / tile_pixels`), or object
//! coordinates; `REPEAT` in both directions, `LINEAR_MIPMAP_LINEAR`.

use std::f32::consts::TAU;

use glam::Vec2;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::OptionError;
use crate::rng::Pcg32;
use crate::texture::{Filter, SamplerHint, Texture, TextureFormat, TextureKind, Wrap, unorm8};

/// Default of [`HatchingOptions::size`].
pub const DEFAULT_HATCHING_SIZE: u32 = 128;
/// Default of [`HatchingOptions::contrast`]: the `c` of `clamp(c·(1 − (T + I)))`.
pub const DEFAULT_HATCHING_CONTRAST: f32 = 4.0;
/// Default of [`HatchingOptions::jitter`].
pub const DEFAULT_STROKE_JITTER: f32 = 0.12;
/// Default of [`HatchingOptions::width_jitter`].
pub const DEFAULT_STROKE_WIDTH_JITTER: f32 = 0.15;
/// Default of [`HatchingOptions::waviness`].
pub const DEFAULT_STROKE_WAVINESS: f32 = 0.04;
/// Default of [`HatchingOptions::waves`].
pub const DEFAULT_STROKE_WAVES: u32 = 1;
/// Default of [`HatchingOptions::seed`].
pub const DEFAULT_HATCHING_SEED: u64 = 2002;
/// Half-width in texels of a stroke's flat core (where `T` equals the family's onset): strokes
/// appear about one texel wide and darken before they widen.
pub const STROKE_CORE_TEXELS: f32 = 0.5;
/// The PCG stream of family 0 (family `f` uses this + `f`).
pub const HATCHING_RNG_STREAM: u64 = 0x6861_7463_6800;
/// Name of the halftone texture.
pub const HATCHING_NAME: &str = "hatching";
/// Name of the tonal art map layers.
pub const HATCHING_TONES_NAME: &str = "hatching_tones";

/// One set of parallel, tileable strokes.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StrokeFamily {
    /// Integer normal `(a, b)` of the lines in tile coordinates (`u` right, `v` down): `(1, 1)` draws
    /// `/` strokes, `(1, −1)` `\` strokes, `(0, 1)` horizontal ones. Not `(0, 0)`; components in [−4, 4].
    pub normal: [i32; 2],
    /// Lines per tile at level 0: a power of two in [1, size/2]. The spacing is
    /// `size / (lines·|normal|)` texels at every level.
    pub lines: u32,
    /// Darkness `1 − I` at which the family starts to draw (`T` on a line's centre); [0, 1].
    pub onset: f32,
    /// Rise of `T` from a line's centre to midway between lines; [0.001, 1].
    pub growth: f32,
}

/// Default of [`HatchingOptions::families`]: `/` from darkness 0.05, `\` from 0.35, `—` from 0.65.
pub const DEFAULT_STROKE_FAMILIES: [StrokeFamily; 3] = [
    StrokeFamily { normal: [1, 1], lines: 8, onset: 0.05, growth: 1.0 },
    StrokeFamily { normal: [1, -1], lines: 8, onset: 0.35, growth: 0.9 },
    StrokeFamily { normal: [0, 1], lines: 8, onset: 0.65, growth: 0.7 },
];

/// Parameters of the hatching halftone.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HatchingOptions {
    /// Edge of level 0 (square tile). Default [`DEFAULT_HATCHING_SIZE`] (128); a power of two in
    /// [8, 1024].
    pub size: u32,
    /// Stroke families. Default [`DEFAULT_STROKE_FAMILIES`]; 1 to 8 families.
    pub families: Vec<StrokeFamily>,
    /// The recommended `c` (> 1), recorded in the texture's kind. Default
    /// [`DEFAULT_HATCHING_CONTRAST`] (4); range [1.01, 64].
    pub contrast: f32,
    /// Random offset of each line, in line spacings. Default [`DEFAULT_STROKE_JITTER`] (0.12);
    /// range [0, 0.3].
    pub jitter: f32,
    /// Random width factor of each line is `1 ± width_jitter`. Default
    /// [`DEFAULT_STROKE_WIDTH_JITTER`] (0.15); range [0, 0.5].
    pub width_jitter: f32,
    /// Amplitude of each line's sideways waviness, in line spacings. Default
    /// [`DEFAULT_STROKE_WAVINESS`] (0.04); range [0, 0.2].
    pub waviness: f32,
    /// Waves per tile along a line (an integer keeps the tile periodic). Default
    /// [`DEFAULT_STROKE_WAVES`] (1); range [0, 16].
    pub waves: u32,
    /// Seed of the per-line randomness. Default [`DEFAULT_HATCHING_SEED`]; any value.
    pub seed: u64,
}

impl Default for HatchingOptions {
    fn default() -> Self {
        Self {
            size: DEFAULT_HATCHING_SIZE,
            families: DEFAULT_STROKE_FAMILIES.to_vec(),
            contrast: DEFAULT_HATCHING_CONTRAST,
            jitter: DEFAULT_STROKE_JITTER,
            width_jitter: DEFAULT_STROKE_WIDTH_JITTER,
            waviness: DEFAULT_STROKE_WAVINESS,
            waves: DEFAULT_STROKE_WAVES,
            seed: DEFAULT_HATCHING_SEED,
        }
    }
}

impl HatchingOptions {
    /// Checks every field against its documented range; `prefix` names the options in the error.
    pub fn validate(&self, prefix: &str) -> Result<(), OptionError> {
        let bad = |field: String, value: String, expected| {
            Err(OptionError { name: format!("{prefix}{field}"), value, expected })
        };
        if !(8..=1024).contains(&self.size) || !self.size.is_power_of_two() {
            return bad("size".into(), self.size.to_string(), "a power of two in [8, 1024]");
        }
        if !(1..=8).contains(&self.families.len()) {
            return bad("families".into(), self.families.len().to_string(), "1 to 8 stroke families");
        }
        for (i, f) in self.families.iter().enumerate() {
            if f.normal == [0, 0] || f.normal.iter().any(|c| !(-4..=4).contains(c)) {
                return bad(
                    format!("families[{i}].normal"),
                    format!("{:?}", f.normal),
                    "a non-zero integer vector with components in [-4, 4]",
                );
            }
            if !f.lines.is_power_of_two() || f.lines > self.size / 2 {
                return bad(format!("families[{i}].lines"), f.lines.to_string(), "a power of two in [1, size/2]");
            }
            if !(0.0..=1.0).contains(&f.onset) {
                return bad(format!("families[{i}].onset"), f.onset.to_string(), "a number in [0, 1]");
            }
            if !(0.001..=1.0).contains(&f.growth) {
                return bad(format!("families[{i}].growth"), f.growth.to_string(), "a number in [0.001, 1]");
            }
        }
        let ranges = [
            ("contrast", self.contrast, 1.01, 64.0, "a number in [1.01, 64]"),
            ("jitter", self.jitter, 0.0, 0.3, "a number in [0, 0.3]"),
            ("width_jitter", self.width_jitter, 0.0, 0.5, "a number in [0, 0.5]"),
            ("waviness", self.waviness, 0.0, 0.2, "a number in [0, 0.2]"),
        ];
        for (field, v, lo, hi, expected) in ranges {
            if !(lo..=hi).contains(&v) {
                return bad(field.into(), v.to_string(), expected);
            }
        }
        if self.waves > 16 {
            return bad("waves".into(), self.waves.to_string(), "an integer in [0, 16]");
        }
        Ok(())
    }

    /// The options with every field forced into its range (NaN → default; invalid families dropped,
    /// none left → the defaults).
    pub fn sanitized(&self) -> Self {
        let d = Self::default();
        let f = |x: f32, lo: f32, hi: f32, def: f32| if x.is_nan() { def } else { x.clamp(lo, hi) };
        let size = self.size.clamp(8, 1024).next_power_of_two().min(1024);
        let mut families: Vec<StrokeFamily> = self
            .families
            .iter()
            .filter(|f| f.normal != [0, 0])
            .take(8)
            .map(|f| StrokeFamily {
                normal: f.normal.map(|c| c.clamp(-4, 4)),
                lines: f.lines.clamp(1, size / 2).next_power_of_two().min(size / 2),
                onset: if f.onset.is_nan() { 0.0 } else { f.onset.clamp(0.0, 1.0) },
                growth: if f.growth.is_nan() { 1.0 } else { f.growth.clamp(0.001, 1.0) },
            })
            .collect();
        if families.is_empty() {
            families = d.families.clone();
        }
        Self {
            size,
            families,
            contrast: f(self.contrast, 1.01, 64.0, d.contrast),
            jitter: f(self.jitter, 0.0, 0.3, d.jitter),
            width_jitter: f(self.width_jitter, 0.0, 0.5, d.width_jitter),
            waviness: f(self.waviness, 0.0, 0.2, d.waviness),
            waves: self.waves.min(16),
            seed: self.seed,
        }
    }
}

/// Freudenberg's soft threshold: `clamp(c·(1 − (T + I)), 0, 1)`, the ink coverage.
pub fn hatching_ink(halftone: f32, intensity: f32, contrast: f32) -> f32 {
    (contrast * (1.0 - (halftone + intensity))).clamp(0.0, 1.0)
}

/// Per-line randomness of one family, indexed by the level-0 line.
struct Lines {
    offset: Vec<f32>,
    width: Vec<f32>,
    wave_phase: Vec<f32>,
}

fn family_lines(o: &HatchingOptions, f: usize) -> Lines {
    let fam = &o.families[f];
    let mut rng = Pcg32::new(o.seed, HATCHING_RNG_STREAM + f as u64);
    let n = fam.lines as usize;
    let mut lines =
        Lines { offset: Vec::with_capacity(n), width: Vec::with_capacity(n), wave_phase: Vec::with_capacity(n) };
    for _ in 0..n {
        lines.offset.push(o.jitter * rng.next_signed() as f32);
        lines.width.push(1.0 + o.width_jitter * rng.next_signed() as f32);
        lines.wave_phase.push(rng.next_unit() as f32);
    }
    lines
}

/// Number of levels stored for these (sanitised) options: down to the level where some family has
/// one line per tile.
pub fn hatching_level_count(options: &HatchingOptions) -> usize {
    let o = options.sanitized();
    let min_lines = o.families.iter().map(|f| f.lines).min().unwrap_or(1);
    min_lines.trailing_zeros() as usize + 1
}

/// `T` at tile coordinates `(u, v)` for level `level` (periodic in `u` and `v` with period 1).
fn halftone_at(o: &HatchingOptions, lines: &[Lines], level: usize, u: f32, v: f32) -> f32 {
    let mut t = 1.0f32;
    for (fam, rand) in o.families.iter().zip(lines) {
        let n0 = fam.lines;
        let n = (n0 >> level).max(1);
        let ratio = (n0 / n) as f32;
        let [a, b] = fam.normal.map(|c| c as f32);
        let phase = n as f32 * (a * u + b * v);
        let along = -b * u + a * v;
        let centre = phase.round() as i64;
        let mut best = f32::INFINITY;
        let mut width = 1.0;
        for j in centre - 1..=centre + 1 {
            let j0 = (j * i64::from(n0 / n)).rem_euclid(i64::from(n0)) as usize;
            let wave = o.waviness * (TAU * (o.waves as f32 * along + rand.wave_phase[j0])).sin();
            let pos = j as f32 + (rand.offset[j0] + wave) / ratio;
            let dist = (phase - pos).abs();
            if dist < best {
                best = dist;
                width = rand.width[j0];
            }
        }
        // Flat core: a line is at least `2·STROKE_CORE_TEXELS` texels wide when it appears, so thin
        // strokes fade in as grey lines instead of breaking into dots.
        let spacing_texels = o.size as f32 / (n0 as f32 * Vec2::new(a, b).length());
        let core = (2.0 * STROKE_CORE_TEXELS / spacing_texels).min(0.5);
        let d = ((2.0 * best - core) / (1.0 - core)).max(0.0);
        t = t.min(fam.onset + fam.growth * d / width);
    }
    t.clamp(0.0, 1.0)
}

/// The halftone `T`: `R8`, `size²`, [`hatching_level_count`] regenerated mip levels, `REPEAT`.
pub fn hatching_halftone(options: &HatchingOptions) -> Texture {
    let o = options.sanitized();
    let lines: Vec<Lines> = (0..o.families.len()).map(|f| family_lines(&o, f)).collect();
    let levels = hatching_level_count(&o);
    let mip_levels = (0..levels)
        .map(|m| {
            let size = (o.size >> m).max(1) as usize;
            let mut data = vec![0u8; size * size];
            data.par_chunks_mut(size).enumerate().for_each(|(y, row)| {
                let v = (y as f32 + 0.5) / size as f32;
                for (x, texel) in row.iter_mut().enumerate() {
                    let u = (x as f32 + 0.5) / size as f32;
                    *texel = unorm8(halftone_at(&o, &lines, m, u, v));
                }
            });
            data
        })
        .collect();
    Texture {
        name: HATCHING_NAME.into(),
        kind: TextureKind::Hatching { contrast: o.contrast },
        width: o.size,
        height: o.size,
        layers: 1,
        format: TextureFormat::R8,
        sampler: SamplerHint { wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, filter: Filter::Linear, mipmaps: true },
        mip_levels,
    }
}

/// Tonal art map layers from a halftone: layer `k` of every level is the paper brightness
/// `1 − ink(T, tones[k], contrast)`. Returns `None` if `halftone` is not an `R8` single-layer texture
/// or `tones` is empty.
pub fn hatching_tone_layers(halftone: &Texture, tones: &[f32], contrast: f32) -> Option<Texture> {
    if halftone.format != TextureFormat::R8 || halftone.layers != 1 || tones.is_empty() {
        return None;
    }
    let tones: Vec<f32> = tones.iter().map(|t| if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }).collect();
    let mip_levels = halftone
        .mip_levels
        .iter()
        .map(|level| {
            let mut out = Vec::with_capacity(level.len() * tones.len());
            for &tone in &tones {
                out.extend(level.iter().map(|&t| unorm8(1.0 - hatching_ink(f32::from(t) / 255.0, tone, contrast))));
            }
            out
        })
        .collect();
    Some(Texture {
        name: HATCHING_TONES_NAME.into(),
        kind: TextureKind::HatchingToneLayers { tones: tones.clone() },
        width: halftone.width,
        height: halftone.height,
        layers: tones.len() as u32,
        format: TextureFormat::R8,
        sampler: halftone.sampler,
        mip_levels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mean_brightness(t: &Texture, level: usize, intensity: f32, c: f32) -> f64 {
        let d = &t.mip_levels[level];
        d.iter().map(|&b| f64::from(1.0 - hatching_ink(f32::from(b) / 255.0, intensity, c))).sum::<f64>()
            / d.len() as f64
    }

    #[test]
    fn mean_intensity_is_monotone_in_the_tone() {
        let t = hatching_halftone(&HatchingOptions::default());
        t.check().unwrap();
        let c = DEFAULT_HATCHING_CONTRAST;
        let tones: Vec<f32> = (0..=20).map(|k| k as f32 / 20.0).collect();
        for level in 0..t.mip_levels.len() {
            let means: Vec<f64> = tones.iter().map(|&i| mean_brightness(&t, level, i, c)).collect();
            // Strictly brighter with every step of intensity while strokes remain (darkness above
            // the first family's onset 0.05, i.e. I < 0.95); blank paper from there on.
            for (k, w) in means.windows(2).enumerate() {
                if tones[k + 1] < 0.95 - 1e-6 {
                    assert!(w[1] > w[0], "level {level}: {means:?}");
                } else {
                    assert!(w[1] >= w[0], "level {level}: {means:?}");
                }
            }
            assert!(means[0] < 0.15, "the darkest tone is nearly black: {}", means[0]);
            assert_eq!(*means.last().unwrap(), 1.0, "full light is blank paper");
        }
        // The same through the tone layers.
        let layers = hatching_tone_layers(&t, &tones, c).unwrap();
        layers.check().unwrap();
        let n = (t.width * t.height) as usize;
        let layer_means: Vec<f64> = (0..tones.len())
            .map(|k| layers.mip_levels[0][k * n..(k + 1) * n].iter().map(|&b| f64::from(b)).sum::<f64>() / n as f64)
            .collect();
        for (k, w) in layer_means.windows(2).enumerate() {
            assert!(w[1] > w[0] || tones[k + 1] >= 0.95 - 1e-6, "{layer_means:?}");
        }
    }

    #[test]
    fn levels_keep_the_tone_and_the_stroke_spacing() {
        let o = HatchingOptions::default();
        let t = hatching_halftone(&o);
        assert_eq!(t.mip_levels.len(), 4); // 128, 64, 32, 16
        for i in [0.2, 0.4, 0.6, 0.8] {
            let base = mean_brightness(&t, 0, i, o.contrast);
            for level in 1..t.mip_levels.len() {
                let m = mean_brightness(&t, level, i, o.contrast);
                assert!((m - base).abs() < 0.06, "I = {i}, level {level}: {m} vs {base}");
            }
        }
        // Stroke density in texels is kept: a row crosses the same number of strokes per texel at
        // every level (count dark runs along a row at a light tone where only "/" strokes draw).
        let runs_per_texel = |level: usize| {
            let (w, _) = t.level_size(level);
            let mut total = 0.0;
            for y in 0..w {
                let row: Vec<bool> =
                    (0..w).map(|x| hatching_ink(t.texel(level, 0, x, y, 0), 0.7, o.contrast) > 0.5).collect();
                total += (0..w as usize).filter(|&x| row[x] && !row[(x + w as usize - 1) % w as usize]).count() as f64;
            }
            total / f64::from(w * w)
        };
        let r0 = runs_per_texel(0);
        assert!(r0 > 0.05, "{r0}");
        for level in 1..4 {
            let r = runs_per_texel(level);
            assert!((r - r0).abs() < 0.25 * r0, "level {level}: {r} vs {r0}");
        }
    }

    #[test]
    fn the_tile_is_periodic() {
        let o = HatchingOptions::default().sanitized();
        let lines: Vec<Lines> = (0..o.families.len()).map(|f| family_lines(&o, f)).collect();
        for k in 0..200 {
            let (u, v) = (k as f32 * 0.0137, k as f32 * 0.0291);
            for level in 0..3 {
                let a = halftone_at(&o, &lines, level, u, v);
                for (du, dv) in [(1.0, 0.0), (0.0, 1.0), (-1.0, 2.0)] {
                    let b = halftone_at(&o, &lines, level, u + du, v + dv);
                    assert!((a - b).abs() < 2e-3, "({u}, {v}) + ({du}, {dv}): {a} vs {b}");
                }
            }
        }
        // In the texture: the wrap-around steps are no larger than the largest interior step.
        let t = hatching_halftone(&o);
        let s = t.width;
        let step = |x0: u32, y0: u32, x1: u32, y1: u32| (t.texel(0, 0, x0, y0, 0) - t.texel(0, 0, x1, y1, 0)).abs();
        let mut interior: f32 = 0.0;
        let mut wrap: f32 = 0.0;
        for y in 0..s {
            for x in 0..s - 1 {
                interior = interior.max(step(x, y, x + 1, y));
            }
            wrap = wrap.max(step(s - 1, y, 0, y)).max(step(y, s - 1, y, 0));
        }
        assert!(wrap <= interior + 1e-6, "wrap {wrap} vs interior {interior}");
    }

    #[test]
    fn options_validate_and_sanitize() {
        HatchingOptions::default().validate("hatching.").unwrap();
        let bad = HatchingOptions { size: 100, ..Default::default() };
        assert_eq!(bad.validate("hatching.").unwrap_err().name, "hatching.size");
        assert_eq!(bad.sanitized().size, 128);
        let none = HatchingOptions { families: vec![], contrast: f32::NAN, ..Default::default() }.sanitized();
        assert_eq!(none.families.len(), 3);
        assert_eq!(none.contrast, DEFAULT_HATCHING_CONTRAST);
    }
}
