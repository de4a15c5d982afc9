//! Cel step tables (ten Bosch 2005, "Celshading" and "Goochel shading"; ../shared/papers/003_*).
//!
//! "This 1D texture contains the step function that defines the celshaded areas. This maps the
//! continuous amount of light (as the dot product between the normal to the surface and the light
//! vector) to a set of fixed values (usually between 2 and 4)."
//!
//! A table has [`CEL_TABLE_LEN`] texels; texel `k` holds the value at `x = k/127` (the same
//! convention as the γ tables of drafter-bounds, so both atlases are sampled alike). With `s` steps
//! ([`CelOptions::steps`], 2–4) band `j = min(⌊x·s⌋, s − 1)` has the value
//! `lo + (hi − lo)·j/(s − 1)`, `lo` = [`CelOptions::min_level`], `hi` = 1, or
//! [`CelOptions::diffuse_max`] when a specular band is present; the specular band
//! `x ≥` [`CelOptions::specular_threshold`] is 1 (white).
//!
//! **Index.** Cel: `x = max(n·l, 0)`; Goochel (ten Bosch: "applies the celshading step function to
//! the full range lighting dot product"): `x = (1 + n·l)/2`. A specular band read with the same `x`
//! is a highlight centred where the normal points at the light; for a view-dependent band read the
//! same row with `x = max(n·h, 0)` and keep only values above `hi`. The shader samples at
//! `u = (0.5 + 127·x)/128`, `v = (row + 0.5)/rows`, linear filtering (a one-texel, 1/128-wide ramp
//! softens each step edge) and clamp-to-edge.

use serde::{Deserialize, Serialize};

use crate::error::OptionError;
use crate::texture::{SamplerHint, Texture, TextureFormat, TextureKind, unorm8};

/// Texels of a cel table (as the γ tables).
pub const CEL_TABLE_LEN: usize = 128;
/// Default of [`CelOptions::steps`].
pub const DEFAULT_CEL_STEPS: u32 = 3;
/// Default of [`CelOptions::min_level`].
pub const DEFAULT_CEL_MIN_LEVEL: f32 = 0.3;
/// Default of [`CelOptions::specular_threshold`].
pub const DEFAULT_CEL_SPECULAR_THRESHOLD: f32 = 0.95;
/// Default of [`CelOptions::diffuse_max`].
pub const DEFAULT_CEL_DIFFUSE_MAX: f32 = 0.8;
/// Name of the cel atlas.
pub const CEL_ATLAS_NAME: &str = "cel_atlas";

/// One cel step table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CelOptions {
    /// Number of diffuse steps. Default [`DEFAULT_CEL_STEPS`] (3); range [2, 4].
    pub steps: u32,
    /// Add a white specular band above [`Self::specular_threshold`]. Default `false`.
    pub specular: bool,
    /// Value of the darkest step. Default [`DEFAULT_CEL_MIN_LEVEL`] (0.3); range [0, 1).
    pub min_level: f32,
    /// Start of the specular band. Default [`DEFAULT_CEL_SPECULAR_THRESHOLD`] (0.95); range (0, 1).
    pub specular_threshold: f32,
    /// Value of the brightest diffuse step when a specular band is present (below the band's 1).
    /// Default [`DEFAULT_CEL_DIFFUSE_MAX`] (0.8); range (`min_level`, 1).
    pub diffuse_max: f32,
}

impl Default for CelOptions {
    fn default() -> Self {
        Self {
            steps: DEFAULT_CEL_STEPS,
            specular: false,
            min_level: DEFAULT_CEL_MIN_LEVEL,
            specular_threshold: DEFAULT_CEL_SPECULAR_THRESHOLD,
            diffuse_max: DEFAULT_CEL_DIFFUSE_MAX,
        }
    }
}

impl CelOptions {
    /// Checks every field against its documented range; `prefix` names the options in the error.
    pub fn validate(&self, prefix: &str) -> Result<(), OptionError> {
        let bad = |field: &str, value: String, expected| {
            Err(OptionError { name: format!("{prefix}{field}"), value, expected })
        };
        if !(2..=4).contains(&self.steps) {
            return bad("steps", self.steps.to_string(), "an integer in [2, 4]");
        }
        if !(0.0..1.0).contains(&self.min_level) {
            return bad("min_level", self.min_level.to_string(), "a number in [0, 1)");
        }
        if !(self.specular_threshold > 0.0 && self.specular_threshold < 1.0) {
            return bad("specular_threshold", self.specular_threshold.to_string(), "a number in (0, 1)");
        }
        if !(self.diffuse_max > self.min_level && self.diffuse_max < 1.0) {
            return bad("diffuse_max", self.diffuse_max.to_string(), "a number in (min_level, 1)");
        }
        Ok(())
    }

    /// The options forced into range (NaN → default).
    pub fn sanitized(&self) -> Self {
        let d = Self::default();
        let f = |x: f32, lo: f32, hi: f32, def: f32| if x.is_nan() { def } else { x.clamp(lo, hi) };
        let min_level = f(self.min_level, 0.0, 0.99, d.min_level);
        Self {
            steps: self.steps.clamp(2, 4),
            specular: self.specular,
            min_level,
            specular_threshold: f(self.specular_threshold, 0.01, 0.99, d.specular_threshold),
            diffuse_max: f(self.diffuse_max, min_level, 0.999, d.diffuse_max).max(min_level),
        }
    }

    /// The step function at `x ∈ [0, 1]` (module docs).
    pub fn eval(&self, x: f32) -> f32 {
        let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
        if self.specular && x >= self.specular_threshold {
            return 1.0;
        }
        let s = self.steps.max(2);
        let band = ((x * s as f32).floor() as u32).min(s - 1);
        let hi = if self.specular { self.diffuse_max } else { 1.0 };
        self.min_level + (hi - self.min_level) * band as f32 / (s - 1) as f32
    }

    /// The table's texels (module docs), before 8-bit quantisation.
    pub fn table(&self) -> Vec<f32> {
        let o = self.sanitized();
        (0..CEL_TABLE_LEN).map(|k| o.eval(k as f32 / (CEL_TABLE_LEN - 1) as f32)).collect()
    }
}

/// The cel atlas: `R8`, 128 × `tables.len()`, row `r` = `tables[r]` (at least one row: an empty list
/// gives the default table).
pub fn cel_atlas(tables: &[CelOptions]) -> Texture {
    let tables: Vec<CelOptions> = if tables.is_empty() {
        vec![CelOptions::default()]
    } else {
        tables.iter().map(CelOptions::sanitized).collect()
    };
    let data = tables.iter().flat_map(|t| t.table()).map(unorm8).collect();
    Texture {
        name: CEL_ATLAS_NAME.into(),
        width: CEL_TABLE_LEN as u32,
        height: tables.len() as u32,
        kind: TextureKind::CelAtlas { tables },
        layers: 1,
        format: TextureFormat::R8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distinct(row: &[u8]) -> Vec<u8> {
        let mut v = row.to_vec();
        v.dedup();
        v
    }

    #[test]
    fn tables_have_the_configured_steps() {
        let mut configs = Vec::new();
        for steps in 2..=4 {
            for specular in [false, true] {
                configs.push(CelOptions { steps, specular, ..Default::default() });
            }
        }
        let atlas = cel_atlas(&configs);
        atlas.check().unwrap();
        assert_eq!((atlas.width, atlas.height), (128, 6));
        for (r, c) in configs.iter().enumerate() {
            let row = &atlas.mip_levels[0][r * 128..(r + 1) * 128];
            let levels = distinct(row);
            let want = c.steps as usize + usize::from(c.specular);
            assert_eq!(levels.len(), want, "{c:?}: {levels:?}");
            assert!(row.windows(2).all(|w| w[0] <= w[1]), "monotone");
            assert_eq!(levels[0], unorm8(DEFAULT_CEL_MIN_LEVEL));
            assert_eq!(*levels.last().unwrap(), 255);
            if c.specular {
                assert_eq!(levels[levels.len() - 2], unorm8(DEFAULT_CEL_DIFFUSE_MAX));
                let first_white = row.iter().position(|&b| b == 255).unwrap();
                assert_eq!(first_white, (0.95f32 * 127.0).ceil() as usize);
            }
        }
    }

    #[test]
    fn options_validate() {
        CelOptions::default().validate("cel.").unwrap();
        assert!(CelOptions { steps: 5, ..Default::default() }.validate("").is_err());
        assert!(CelOptions { steps: 1, ..Default::default() }.validate("").is_err());
        assert_eq!(CelOptions { steps: 9, ..Default::default() }.sanitized().steps, 4);
    }
}
