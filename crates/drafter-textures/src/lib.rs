//! Baked NPR lookup textures for drafter: the shading styles of the papers are 1D and 2D
//! lookups that are cheap at run time once baked. Plain data in, images out; no files (except the
//! explicit [`write_png`]), no globals, deterministic at any thread count.
//!
//! | texture | module | format, size | indexed by | paper |
//! |---|---|---|---|---|
//! | `metal_bands` | [`metal`] | R8, 256 × 1, repeat | `u = s·(1 + n_obj·w)/2` | Gooch et al. 1999 §5.2.1 (`../shared/papers/001_*`) |
//! | `metal_highlights` | [`metal`] | R8, 128², clamp | eye-space normal ([`EnvMapping`]) | same |
//! | `cool_to_warm_<i>` | [`cool_warm`] | RGBA8, 128², clamp | eye-space normal ([`EnvMapping`]) | same, §3.2, §5.2, Fig. 10; ten Bosch (`003_*`) |
//! | `hatching` | [`hatching`] | R8, 128², repeat, 4 stored mips | screen or object uv; ink = `clamp(c·(1 − (T + I)))` | Freudenberg (`002_*`); ten Bosch |
//! | `hatching_tones` (optional) | [`hatching`] | R8, 128² × layers | as `hatching`, one layer per tone | ten Bosch |
//! | `gamma_atlas` | [`gamma`] | R8, 128 × curves | `u = (0.5 + 127·p)/128`, `v = (row + 0.5)/rows` | Lux et al. 2013 §3 (`000_*`) |
//! | `cel_atlas` | [`cel`] | R8, 128 × tables | `u = (0.5 + 127·x)/128`, `x = max(n·l, 0)` or `(1 + n·l)/2` | ten Bosch |
//!
//! [`bake_textures`] bakes exactly what a [`TextureRequest`] lists — "only what the scene uses is
//! baked": no metal part, no metal textures; one γ row per distinct curve; one cool-to-warm map per
//! distinct light/colour variant. Every option struct has documented defaults (`DEFAULT_*`
//! constants, the papers' values where they give one) and a `validate` method; `bake_textures`
//! itself never fails and clamps out-of-range options.
//!
//! Images ([`Texture`]) are 8-bit UNORM, level 0 first, layers stacked vertically; [`encode_png`]
//! writes one deterministic PNG per mip level (layout and conventions in `texture` and `encode`).
//! [`preview`] renders each lookup on a sphere (CPU), the pictures in the README.
//!
//! ```
//! use drafter_textures::{bake_textures, encode_png, MetalOptions, TextureRequest};
//! use drafter_core::gradient::TransferCurve;
//!
//! let request = TextureRequest {
//!     metal: Some(MetalOptions::default()),
//!     gamma_curves: vec![TransferCurve::Identity, TransferCurve::Smoothstep, TransferCurve::Identity],
//!     ..TextureRequest::default()
//! };
//! let textures = bake_textures(&request);
//! let names: Vec<&str> = textures.iter().map(|t| t.name.as_str()).collect();
//! assert_eq!(names, ["metal_bands", "metal_highlights", "gamma_atlas"]);
//! assert_eq!(textures[2].height, 2); // two distinct curves
//! let png = encode_png(&textures[0], 0)?;
//! assert_eq!(&png[1..4], b"PNG");
//! # Ok::<(), drafter_textures::PngError>(())
//! ```

pub mod cel;
pub mod cool_warm;
mod encode;
pub mod envmap;
mod error;
pub mod gamma;
pub mod hatching;
pub mod metal;
pub mod preview;
mod rng;
mod texture;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use drafter_core::gradient::TransferCurve;

pub use cel::{CEL_ATLAS_NAME, CEL_TABLE_LEN, CelOptions, cel_atlas};
pub use cool_warm::{
    CoolToWarmEncoding, CoolToWarmOptions, cool_to_warm_colour, cool_to_warm_factored, cool_to_warm_map, splash_back,
};
pub use encode::{PNG_ZLIB_LEVEL, encode_png, encode_png_levels, write_png};
pub use envmap::EnvMapping;
pub use error::{OptionError, PngError};
pub use gamma::{GAMMA_ATLAS_NAME, gamma_atlas};
pub use hatching::{
    HATCHING_NAME, HATCHING_TONES_NAME, HatchingOptions, StrokeFamily, hatching_halftone, hatching_ink,
    hatching_tone_layers,
};
pub use metal::{METAL_BANDS_NAME, METAL_HIGHLIGHTS_NAME, MetalOptions, metal_bands, metal_highlights, metal_table};
pub use rng::Pcg32;
pub use texture::{Filter, SamplerHint, Texture, TextureFormat, TextureKind, Wrap, unorm8};

/// Prefix of the cool-to-warm maps' names: map `i` is `cool_to_warm_<i>`.
pub const COOL_TO_WARM_NAME_PREFIX: &str = "cool_to_warm_";

/// What a scene needs baked. The default requests nothing.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureRequest {
    /// Metal bands and highlights: `Some` when at least one part is metal (style hint `metal`, or a
    /// material's metallic factor), `None` otherwise.
    pub metal: Option<MetalOptions>,
    /// One cool-to-warm map per entry (styles `gooch`, `goochel`); duplicates are baked once.
    pub cool_to_warm: Vec<CoolToWarmOptions>,
    /// The hatching halftone: `Some` when some part uses the `hatch` style.
    pub hatching: Option<HatchingOptions>,
    /// The γ curves the gradient-shaded parts use; one atlas row per distinct curve, first-seen
    /// order. Empty: no atlas.
    pub gamma_curves: Vec<TransferCurve>,
    /// The cel tables the `cel` / `goochel` parts use; one atlas row per distinct table, first-seen
    /// order. Empty: no atlas.
    pub cel_tables: Vec<CelOptions>,
}

impl TextureRequest {
    /// `true` when nothing is requested.
    pub fn is_empty(&self) -> bool {
        self.metal.is_none()
            && self.cool_to_warm.is_empty()
            && self.hatching.is_none()
            && self.gamma_curves.is_empty()
            && self.cel_tables.is_empty()
    }

    /// Checks every option against its documented range (the first problem found).
    pub fn validate(&self) -> Result<(), OptionError> {
        if let Some(m) = &self.metal {
            m.validate("metal.")?;
        }
        for (i, c) in self.cool_to_warm.iter().enumerate() {
            c.validate(&format!("cool_to_warm[{i}]."))?;
        }
        if let Some(h) = &self.hatching {
            h.validate("hatching.")?;
        }
        for (i, c) in self.cel_tables.iter().enumerate() {
            c.validate(&format!("cel_tables[{i}]."))?;
        }
        Ok(())
    }

    /// The distinct cool-to-warm variants (after clamping), first-seen order.
    pub fn distinct_cool_to_warm(&self) -> Vec<CoolToWarmOptions> {
        distinct(self.cool_to_warm.iter().map(CoolToWarmOptions::sanitized))
    }

    /// The distinct γ curves, first-seen order (the γ atlas's rows).
    pub fn distinct_gamma_curves(&self) -> Vec<TransferCurve> {
        distinct(self.gamma_curves.iter().copied())
    }

    /// The distinct cel tables (after clamping), first-seen order (the cel atlas's rows).
    pub fn distinct_cel_tables(&self) -> Vec<CelOptions> {
        distinct(self.cel_tables.iter().map(CelOptions::sanitized))
    }
}

fn distinct<T: PartialEq>(items: impl Iterator<Item = T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::new();
    for item in items {
        if !out.contains(&item) {
            out.push(item);
        }
    }
    out
}

enum Job {
    Metal(MetalOptions),
    CoolToWarm(usize, CoolToWarmOptions),
    Hatching(HatchingOptions),
    Gamma(Vec<TransferCurve>),
    Cel(Vec<CelOptions>),
}

/// Bakes what `request` lists, in this order: `metal_bands`, `metal_highlights`, `cool_to_warm_<i>`
/// (one per distinct variant), `hatching`, `gamma_atlas`, `cel_atlas`. Out-of-range options are
/// clamped (see [`TextureRequest::validate`] to report them instead). Textures are baked in
/// parallel; the result does not depend on the thread count.
pub fn bake_textures(request: &TextureRequest) -> Vec<Texture> {
    let mut jobs = Vec::new();
    if let Some(m) = &request.metal {
        jobs.push(Job::Metal(m.sanitized()));
    }
    for (i, c) in request.distinct_cool_to_warm().into_iter().enumerate() {
        jobs.push(Job::CoolToWarm(i, c));
    }
    if let Some(h) = &request.hatching {
        jobs.push(Job::Hatching(h.sanitized()));
    }
    let curves = request.distinct_gamma_curves();
    if !curves.is_empty() {
        jobs.push(Job::Gamma(curves));
    }
    let cels = request.distinct_cel_tables();
    if !cels.is_empty() {
        jobs.push(Job::Cel(cels));
    }
    let baked: Vec<Vec<Texture>> = jobs
        .into_par_iter()
        .map(|job| match job {
            Job::Metal(m) => metal::metal_textures(&m).to_vec(),
            Job::CoolToWarm(i, c) => vec![cool_to_warm_map(&c, &format!("{COOL_TO_WARM_NAME_PREFIX}{i}"))],
            Job::Hatching(h) => vec![hatching_halftone(&h)],
            Job::Gamma(curves) => vec![gamma_atlas(&curves)],
            Job::Cel(tables) => vec![cel_atlas(&tables)],
        })
        .collect();
    baked.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_what_is_requested_is_baked() {
        assert!(bake_textures(&TextureRequest::default()).is_empty());
        let request = TextureRequest {
            cool_to_warm: vec![
                CoolToWarmOptions::default(),
                CoolToWarmOptions { splash_back: true, ..Default::default() },
                CoolToWarmOptions::default(),
            ],
            cel_tables: vec![
                CelOptions::default(),
                CelOptions { steps: 2, ..Default::default() },
                CelOptions::default(),
            ],
            gamma_curves: vec![TransferCurve::EaseIn, TransferCurve::EaseIn],
            ..Default::default()
        };
        let t = bake_textures(&request);
        let names: Vec<&str> = t.iter().map(|t| t.name.as_str()).collect();
        assert_eq!(names, ["cool_to_warm_0", "cool_to_warm_1", "gamma_atlas", "cel_atlas"]);
        assert_eq!(t[2].height, 1);
        assert_eq!(t[3].height, 2);
        assert!(matches!(&t[2].kind, TextureKind::GammaAtlas { curves } if curves == &[TransferCurve::EaseIn]));
    }

    #[test]
    fn validate_names_the_bad_option() {
        let request = TextureRequest {
            cel_tables: vec![CelOptions::default(), CelOptions { steps: 7, ..Default::default() }],
            ..Default::default()
        };
        let e = request.validate().unwrap_err();
        assert_eq!(e.to_string(), "cel_tables[1].steps = 7 is out of range; expected an integer in [2, 4]");
        // bake_textures clamps instead of failing.
        let t = bake_textures(&request);
        assert!(matches!(&t[0].kind, TextureKind::CelAtlas { tables } if tables[1].steps == 4));
    }
}
