//! Gooch metal shading (Gooch et al. 1999, §5.2.1; ../shared/papers/001_*).
//!
//! # Bands
//! "We first compute a table of random intensities where sample = b + r^e, where the base b is −0.1,
//! r is a random number in [0, 1] and e is 1.4. [...] We then filter each element in the table with
//! each of its neighbours using a 1-5-1 weighting scheme and clamp it to be in the range of [0, 1].
//! We make it periodic [...]. The table is then resampled into a 1D texture map. The texture map is
//! used as a cosine distribution because it is indexed via a dot product. The resampling makes sure
//! the bands are uniformly distributed on a cylinder."
//!
//! Here:
//! 1. `raw[i] = b + r_i^e`, `i < N` ([`MetalOptions::table_len`]), `r_i` from [`crate::Pcg32`] seeded
//!    with [`MetalOptions::seed`] (stream [`METAL_RNG_STREAM`]).
//! 2. `table[i] = clamp((raw[i−1] + 5·raw[i] + raw[i+1]) / 7, 0, 1)`, indices modulo `N` (periodic).
//! 3. The table is a periodic function of `t ∈ [0, 1)` (linear interpolation between entries, entry
//!    `i` at `t = i/N`). Texel `k` of the `W`-texel band texture ([`MetalOptions::band_texels`]) has
//!    centre `u_k = (k + 0.5)/W` and holds `table(φ_k / π)` with `cos φ_k = 2u_k − 1`.
//!
//! **Mapping.** A shader computes `u = s·(1 + n·w)/2` with `w` a fixed unit axis orthogonal to the
//! part's principal (cylinder) axis, both in object space so the bands stick to the part, `s ≥ 1`
//! the stripe scale, and samples with `REPEAT`. On a cylinder around that axis `n·w = cos φ`, so
//! the band value is `table(φ/π)`: uniform in the angle φ, a half turn (0 to π) covering the table
//! once (the other half mirrors it, as any dot-product index does). `u = 0` (φ = π) and `u = 1`
//! (φ = 0) both read `table(0)`, so with `s > 1` the repeats join without a seam.
//!
//! # Highlights
//! "We add Phong highlights computed by lighting a texture map in eye space with several Phong
//! light sources oriented in the directions of a icosahedron's vertices. A fairly large specular
//! power, empirically around 30-50, seemed to work best with a specular coefficient of about 0.3."
//!
//! The twelve lights point along `(0, ±1, ±φ)`, `(±1, ±φ, 0)`, `(±φ, 0, ±1)` (normalised, φ the golden
//! ratio) in eye space; the viewer looks along −z (`v = (0, 0, 1)`, orthographic). The map stores
//! `k_s · Σ_l [n·l > 0] · max(r_l·v, 0)^p` with `r_l = 2(n·l)n − l`, clamped to [0, 1], indexed by the
//! eye-space normal through [`MetalOptions::mapping`] (see `crate::envmap`). A shader composes
//! `colour = base_colour · band(u) + highlight(n_eye)`.
//!
//! # Defaults
//! The paper's `b = −0.1`, `e = 1.4`, specular power 40 (the middle of 30–50), coefficient 0.3. The
//! paper gives no table length or texture size: 16 entries (about sixteen streaks per half turn,
//! each a few entries wide after filtering) and 256 texels are this crate's choice.

use std::f32::consts::PI;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::envmap::{EnvMapping, bake_env_map};
use crate::error::OptionError;
use crate::rng::Pcg32;
use crate::texture::{SamplerHint, Texture, TextureFormat, TextureKind, Wrap, unorm8};

/// Default of [`MetalOptions::bias`]: the paper's base b.
pub const DEFAULT_METAL_BIAS: f32 = -0.1;
/// Default of [`MetalOptions::exponent`]: the paper's e.
pub const DEFAULT_METAL_EXPONENT: f32 = 1.4;
/// Default of [`MetalOptions::table_len`].
pub const DEFAULT_METAL_TABLE_LEN: u32 = 16;
/// Default of [`MetalOptions::seed`].
pub const DEFAULT_METAL_SEED: u64 = 1999;
/// Default of [`MetalOptions::band_texels`].
pub const DEFAULT_METAL_BAND_TEXELS: u32 = 256;
/// Default of [`MetalOptions::specular_power`]: the middle of the paper's 30–50.
pub const DEFAULT_SPECULAR_POWER: f32 = 40.0;
/// Default of [`MetalOptions::specular_coefficient`]: the paper's "about 0.3".
pub const DEFAULT_SPECULAR_COEFFICIENT: f32 = 0.3;
/// Default of [`MetalOptions::highlight_size`].
pub const DEFAULT_HIGHLIGHT_SIZE: u32 = 128;
/// The PCG stream of the metal table (so other tables seeded alike draw different numbers).
pub const METAL_RNG_STREAM: u64 = 0x006d_6574_616c;
/// Name of the band texture.
pub const METAL_BANDS_NAME: &str = "metal_bands";
/// Name of the highlight map.
pub const METAL_HIGHLIGHTS_NAME: &str = "metal_highlights";

/// Parameters of the metal textures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MetalOptions {
    /// Base `b` of `b + r^e`. Default [`DEFAULT_METAL_BIAS`] (−0.1); range [−1, 1].
    pub bias: f32,
    /// Exponent `e` of `b + r^e`. Default [`DEFAULT_METAL_EXPONENT`] (1.4); range [0.1, 10].
    pub exponent: f32,
    /// Entries `N` of the periodic table (streaks per half turn). Default [`DEFAULT_METAL_TABLE_LEN`]
    /// (16); range [3, 4096].
    pub table_len: u32,
    /// Seed of the random table. Default [`DEFAULT_METAL_SEED`]; any value.
    pub seed: u64,
    /// Width of the band texture. Default [`DEFAULT_METAL_BAND_TEXELS`] (256); range [8, 4096].
    pub band_texels: u32,
    /// Phong exponent of the highlights. Default [`DEFAULT_SPECULAR_POWER`] (40); range [1, 1000].
    pub specular_power: f32,
    /// Specular coefficient `k_s`. Default [`DEFAULT_SPECULAR_COEFFICIENT`] (0.3); range [0, 1].
    pub specular_coefficient: f32,
    /// Edge of the square highlight map. Default [`DEFAULT_HIGHLIGHT_SIZE`] (128); range [8, 2048].
    pub highlight_size: u32,
    /// Parameterisation of the highlight map. Default octahedral.
    pub mapping: EnvMapping,
}

impl Default for MetalOptions {
    fn default() -> Self {
        Self {
            bias: DEFAULT_METAL_BIAS,
            exponent: DEFAULT_METAL_EXPONENT,
            table_len: DEFAULT_METAL_TABLE_LEN,
            seed: DEFAULT_METAL_SEED,
            band_texels: DEFAULT_METAL_BAND_TEXELS,
            specular_power: DEFAULT_SPECULAR_POWER,
            specular_coefficient: DEFAULT_SPECULAR_COEFFICIENT,
            highlight_size: DEFAULT_HIGHLIGHT_SIZE,
            mapping: EnvMapping::Octahedral,
        }
    }
}

impl MetalOptions {
    /// Checks every field against its documented range; `prefix` names the options in the error.
    pub fn validate(&self, prefix: &str) -> Result<(), OptionError> {
        let bad = |field: &str, value: String, expected| {
            Err(OptionError { name: format!("{prefix}{field}"), value, expected })
        };
        if !(-1.0..=1.0).contains(&self.bias) {
            return bad("bias", self.bias.to_string(), "a number in [-1, 1]");
        }
        if !(0.1..=10.0).contains(&self.exponent) {
            return bad("exponent", self.exponent.to_string(), "a number in [0.1, 10]");
        }
        if !(3..=4096).contains(&self.table_len) {
            return bad("table_len", self.table_len.to_string(), "an integer in [3, 4096]");
        }
        if !(8..=4096).contains(&self.band_texels) {
            return bad("band_texels", self.band_texels.to_string(), "an integer in [8, 4096]");
        }
        if !(1.0..=1000.0).contains(&self.specular_power) {
            return bad("specular_power", self.specular_power.to_string(), "a number in [1, 1000]");
        }
        if !(0.0..=1.0).contains(&self.specular_coefficient) {
            return bad("specular_coefficient", self.specular_coefficient.to_string(), "a number in [0, 1]");
        }
        if !(8..=2048).contains(&self.highlight_size) {
            return bad("highlight_size", self.highlight_size.to_string(), "an integer in [8, 2048]");
        }
        Ok(())
    }

    /// The options with every field clamped into its range (NaN → the default).
    pub fn sanitized(&self) -> Self {
        let d = Self::default();
        let f = |x: f32, lo: f32, hi: f32, def: f32| if x.is_nan() { def } else { x.clamp(lo, hi) };
        Self {
            bias: f(self.bias, -1.0, 1.0, d.bias),
            exponent: f(self.exponent, 0.1, 10.0, d.exponent),
            table_len: self.table_len.clamp(3, 4096),
            seed: self.seed,
            band_texels: self.band_texels.clamp(8, 4096),
            specular_power: f(self.specular_power, 1.0, 1000.0, d.specular_power),
            specular_coefficient: f(self.specular_coefficient, 0.0, 1.0, d.specular_coefficient),
            highlight_size: self.highlight_size.clamp(8, 2048),
            mapping: self.mapping,
        }
    }
}

/// The unfiltered table `b + r^e` (step 1 of the module docs).
pub fn metal_raw_table(options: &MetalOptions) -> Vec<f32> {
    let o = options.sanitized();
    let mut rng = Pcg32::new(o.seed, METAL_RNG_STREAM);
    (0..o.table_len).map(|_| (f64::from(o.bias) + rng.next_unit().powf(f64::from(o.exponent))) as f32).collect()
}

/// The periodic 1-5-1 filter `(x[i−1] + 5·x[i] + x[i+1]) / 7`, indices modulo the length, unclamped.
pub fn filter_1_5_1_periodic(values: &[f32]) -> Vec<f32> {
    let n = values.len();
    (0..n).map(|i| (values[(i + n - 1) % n] + 5.0 * values[i] + values[(i + 1) % n]) / 7.0).collect()
}

/// The filtered, clamped periodic table (steps 1 and 2 of the module docs).
pub fn metal_table(options: &MetalOptions) -> Vec<f32> {
    filter_1_5_1_periodic(&metal_raw_table(options)).into_iter().map(|x| x.clamp(0.0, 1.0)).collect()
}

/// The periodic table at `t` (entry `i` at `t = i/N`, linear in between, `t` taken modulo 1).
pub fn sample_periodic(table: &[f32], t: f32) -> f32 {
    let n = table.len();
    if n == 0 {
        return 0.0;
    }
    let x = t.rem_euclid(1.0) * n as f32;
    let i = (x.floor() as usize).min(n - 1);
    let w = x - i as f32;
    table[i] * (1.0 - w) + table[(i + 1) % n] * w
}

/// The band value at texture coordinate `u ∈ [0, 1]`: `table(acos(2u − 1)/π)` (step 3).
pub fn metal_band(table: &[f32], u: f32) -> f32 {
    let phi = (2.0 * u.clamp(0.0, 1.0) - 1.0).clamp(-1.0, 1.0).acos();
    sample_periodic(table, phi / PI)
}

/// The band texture: `R8`, `band_texels × 1`, `REPEAT` in `u`.
pub fn metal_bands(options: &MetalOptions) -> Texture {
    let o = options.sanitized();
    let table = metal_table(&o);
    let w = o.band_texels;
    let data = (0..w).map(|k| unorm8(metal_band(&table, (k as f32 + 0.5) / w as f32))).collect();
    Texture {
        name: METAL_BANDS_NAME.into(),
        kind: TextureKind::MetalBands,
        width: w,
        height: 1,
        layers: 1,
        format: TextureFormat::R8,
        sampler: SamplerHint { wrap_u: Wrap::Repeat, ..SamplerHint::CLAMPED },
        mip_levels: vec![data],
    }
}

/// The twelve unit vertices of the icosahedron `(0, ±1, ±φ)`, `(±1, ±φ, 0)`, `(±φ, 0, ±1)`.
pub fn icosahedron_vertices() -> [Vec3; 12] {
    let phi = (1.0 + 5f32.sqrt()) / 2.0;
    let mut out = [Vec3::ZERO; 12];
    let mut k = 0;
    for a in [-1.0f32, 1.0] {
        for b in [-phi, phi] {
            for v in [Vec3::new(0.0, a, b), Vec3::new(a, b, 0.0), Vec3::new(b, 0.0, a)] {
                out[k] = v.normalize();
                k += 1;
            }
        }
    }
    out
}

/// The highlight term at an eye-space unit normal (module docs), before 8-bit quantisation.
pub fn metal_highlight(normal_in_eye: Vec3, options: &MetalOptions) -> f32 {
    let o = options.sanitized();
    let n = normal_in_eye.normalize_or_zero();
    let sum: f32 = icosahedron_vertices()
        .iter()
        .map(|&l| {
            let ndl = n.dot(l);
            if ndl <= 0.0 {
                return 0.0;
            }
            let r = 2.0 * ndl * n - l;
            r.z.max(0.0).powf(o.specular_power)
        })
        .sum();
    (o.specular_coefficient * sum).clamp(0.0, 1.0)
}

/// The highlight map: `R8`, `highlight_size²`, indexed by the eye-space normal.
pub fn metal_highlights(options: &MetalOptions) -> Texture {
    let o = options.sanitized();
    let data = bake_env_map(o.highlight_size, o.mapping, 1, |n| [metal_highlight(n, &o), 0.0, 0.0, 0.0]);
    Texture {
        name: METAL_HIGHLIGHTS_NAME.into(),
        kind: TextureKind::MetalHighlights { mapping: o.mapping },
        width: o.highlight_size,
        height: o.highlight_size,
        layers: 1,
        format: TextureFormat::R8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

/// Both metal textures, bands first (rayon runs them side by side).
pub(crate) fn metal_textures(options: &MetalOptions) -> [Texture; 2] {
    let (bands, highlights) = rayon::join(|| metal_bands(options), || metal_highlights(options));
    [bands, highlights]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mean(values: &[f32]) -> f64 {
        values.iter().map(|&x| f64::from(x)).sum::<f64>() / values.len().max(1) as f64
    }

    fn long_table(seed: u64) -> MetalOptions {
        MetalOptions { table_len: 4096, seed, ..MetalOptions::default() }
    }

    #[test]
    fn raw_mean_matches_b_plus_one_over_one_plus_e() {
        // E[r^e] = 1/(1+e) for r uniform in [0, 1]: mean = −0.1 + 1/2.4 = 0.3167, σ ≈ 0.30.
        let raw = metal_raw_table(&long_table(1));
        let expected = -0.1 + 1.0 / 2.4;
        let tolerance = 4.0 * 0.30 / (raw.len() as f64).sqrt();
        assert!((mean(&raw) - expected).abs() < tolerance, "{} vs {expected}", mean(&raw));
        assert!(raw.iter().all(|&x| (-0.1..=0.9 + 1e-6).contains(&x)));
    }

    #[test]
    fn filter_keeps_the_mean_and_the_table_is_clamped() {
        let o = long_table(2);
        let raw = metal_raw_table(&o);
        let filtered = filter_1_5_1_periodic(&raw);
        assert!((mean(&raw) - mean(&filtered)).abs() < 1e-6);
        let table = metal_table(&o);
        assert!(table.iter().all(|x| (0.0..=1.0).contains(x)));
        // Clamping only lifts negative values: the mean rises a little, stays well inside [0.30, 0.36].
        let m = mean(&table);
        assert!(m >= mean(&filtered) - 1e-9 && (0.30..0.36).contains(&m), "{m}");
        // The paper's default table (16 entries) has a plausible mean too.
        let small = metal_table(&MetalOptions::default());
        assert_eq!(small.len(), 16);
        assert!((0.1..0.6).contains(&mean(&small)), "{}", mean(&small));
    }

    #[test]
    fn filter_is_periodic_first_and_last_continuous() {
        let o = MetalOptions::default();
        let raw = metal_raw_table(&o);
        let table = metal_table(&o);
        let n = raw.len();
        let first = ((raw[n - 1] + 5.0 * raw[0] + raw[1]) / 7.0).clamp(0.0, 1.0);
        let last = ((raw[n - 2] + 5.0 * raw[n - 1] + raw[0]) / 7.0).clamp(0.0, 1.0);
        assert_eq!(table[0], first);
        assert_eq!(table[n - 1], last);
        // Statistically, the wrap-around step is an ordinary neighbour step: over many seeds the
        // mean |table[0] − table[N−1]| equals the mean interior step.
        let (mut wrap, mut inner, mut count) = (0.0, 0.0, 0.0);
        for seed in 0..2000 {
            let t = metal_table(&MetalOptions { seed, ..MetalOptions::default() });
            wrap += f64::from((t[0] - t[n - 1]).abs());
            inner += t.windows(2).map(|w| f64::from((w[1] - w[0]).abs())).sum::<f64>() / (n - 1) as f64;
            count += 1.0;
        }
        let (wrap, inner) = (wrap / count, inner / count);
        assert!((wrap - inner).abs() < 0.1 * inner, "wrap {wrap} vs interior {inner}");
        // The resampled band function joins itself under REPEAT: u = 0 and u = 1 both read table(0),
        // and it is continuous across the seam.
        assert_eq!(metal_band(&table, 0.0), table[0]);
        assert_eq!(metal_band(&table, 1.0), table[0]);
        for eps in [1e-3f32, 1e-4, 1e-5] {
            let jump = (metal_band(&table, eps) - metal_band(&table, 1.0 - eps)).abs();
            assert!(jump < 100.0 * eps.sqrt(), "ε = {eps}: {jump}");
        }
        // In the texture, the two texels beside the seam both lie within one table entry of table(0).
        let tex = metal_bands(&o);
        let (first, last) = (tex.texel(0, 0, 0, 0, 0), tex.texel(0, 0, tex.width - 1, 0, 0));
        let spread = table.iter().fold(0.0f32, |m, &x| m.max((x - table[0]).abs()));
        let near = (table[0] - table[1]).abs().max((table[0] - table[n - 1]).abs()) + 1.0 / 255.0;
        assert!((first - table[0]).abs() <= near && (last - table[0]).abs() <= near, "{first} {last} {spread}");
    }

    #[test]
    fn bands_are_uniform_in_the_cylinder_angle() {
        let o = MetalOptions::default();
        let table = metal_table(&o);
        let tex = metal_bands(&o);
        for k in 1..100 {
            let phi = PI * k as f32 / 100.0;
            let u = (1.0 + phi.cos()) / 2.0;
            let want = sample_periodic(&table, phi / PI);
            let got = tex.sample(0, 0, glam::Vec2::new(u, 0.5)).x;
            // Resampling error grows where dφ/du is large (near u = 0, 1): allow a few texels there.
            let slope = 1.0 / (PI * phi.sin()) * 16.0 / 256.0; // table entries per texel
            let tol = 2.0 / 255.0 + slope * 0.5;
            assert!((got - want).abs() <= tol, "φ = {phi}: {got} vs {want}");
        }
    }

    #[test]
    fn highlights_sit_at_the_half_vectors() {
        let o = MetalOptions::default();
        for l in icosahedron_vertices() {
            assert!((l.length() - 1.0).abs() < 1e-6);
            let h = (l + Vec3::Z).normalize();
            if l.z > -0.9 {
                let v = metal_highlight(h, &o);
                assert!((0.3 - 1e-4..=1.0).contains(&v), "{l}: {v}");
            }
        }
        // Between highlights the map is dark; everything is in range.
        assert!(metal_highlight(Vec3::new(0.0, 0.0, 1.0), &o) < 0.05);
        let map = metal_highlights(&o);
        map.check().unwrap();
        let max = *map.mip_levels[0].iter().max().unwrap();
        assert!((unorm8(0.25)..=unorm8(0.6)).contains(&max), "{max}");
        // The icosahedron's vertices: twelve, pairwise 63.4° or 116.6° or 180° apart.
        let v = icosahedron_vertices();
        for a in &v {
            let near = v.iter().filter(|b| (a.dot(**b) - 1.0 / 5f32.sqrt()).abs() < 1e-5).count();
            assert_eq!(near, 5);
        }
    }
}
