//! Cool-to-warm shading maps (Gooch et al. 1999, §3.2, §5.2 and Fig. 10; ../shared/papers/001_*;
//! the diffuse model of Gooch et al. 1998, which that paper extends; ten Bosch 2005, 003_*).
//!
//! # The model
//! With `t = (1 + n·l)/2` (the full-range dot product remapped to [0, 1], so the unlit side still
//! varies — ten Bosch: "to retain the maximum amount of information"):
//! ```text
//! k_cool = (0, 0, b) + α·k_d          k_warm = (y, y, 0) + β·k_d
//! I      = t·k_warm + (1 − t)·k_cool  (clamped to [0, 1] per channel)
//! ```
//! `k_d` is the object colour; `b = y = 0.4`, `α = 0.2`, `β = 0.6` are the 1998 paper's values. The
//! 1998 paper prints the weights the other way round with its own sign of `l`; here `l` points
//! *towards* the light, and the side facing the light is warm (Fig. 10(a), Fig. 5).
//!
//! **Splash-back** (§3.2, Fig. 4(b), Fig. 10(b)): `I` is multiplied by `(α_s cos θ + (1 − α_s))^β_s`
//! with `cos θ = n·l`, `α_s = 0.76`, `β_s = 0.78`. For `cos θ < −(1 − α_s)/α_s` the printed base is
//! negative and a fractional power undefined; the base is taken in absolute value,
//! `|α_s cos θ + (1 − α_s)|^β_s`, which gives the figure's dark band (the multiplier is 0 on the
//! circle `cos θ = −0.316`) and the light that "splashes back" from the side opposite the light
//! (up to `0.52^0.78 ≈ 0.60` at `cos θ = −1`).
//!
//! # The maps
//! Indexed by the **eye-space** normal through [`CoolToWarmOptions::mapping`] (`crate::envmap`), for a
//! light direction fixed in eye space (the paper rotates the object, "leaving the background, light,
//! and viewer in place", §4.1). Two encodings ([`CoolToWarmEncoding`]):
//! * `Colour` (when [`CoolToWarmOptions::object_colour`] is set): RGB = `I` for that `k_d`, A = 1.
//! * `Factored` (no object colour): `I` is affine in `k_d`, `I = base(t) + weight(t)·k_d` with
//!   `base = t·(y, y, 0) + (1 − t)·(0, 0, b)` and `weight = t·β + (1 − t)·α` (times the splash-back
//!   multiplier when enabled). RGB = `base`, A = `weight`; a shader computes
//!   `clamp(rgb + a·k_d, 0, 1)`. One map serves every part colour.
//!
//! Values are display values as in the paper (no sRGB decoding, see `crate::texture`).

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use drafter_core::env_map::CoolToWarmEncoding;

use crate::envmap::{EnvMapping, bake_env_map};
use crate::error::OptionError;
use crate::texture::{SamplerHint, Texture, TextureFormat, TextureKind};

/// Default of [`CoolToWarmOptions::blue`]: the 1998 paper's b.
pub const DEFAULT_COOL_BLUE: f32 = 0.4;
/// Default of [`CoolToWarmOptions::yellow`]: the 1998 paper's y.
pub const DEFAULT_WARM_YELLOW: f32 = 0.4;
/// Default of [`CoolToWarmOptions::alpha`]: the 1998 paper's α.
pub const DEFAULT_COOL_MIX: f32 = 0.2;
/// Default of [`CoolToWarmOptions::beta`]: the 1998 paper's β.
pub const DEFAULT_WARM_MIX: f32 = 0.6;
/// Default of [`CoolToWarmOptions::splash_alpha`]: §3.2's α = 0.76.
pub const DEFAULT_SPLASH_ALPHA: f32 = 0.76;
/// Default of [`CoolToWarmOptions::splash_beta`]: §3.2's β = 0.78.
pub const DEFAULT_SPLASH_BETA: f32 = 0.78;
/// Default of [`CoolToWarmOptions::light_in_eye`]: up and to the right (Fig. 5's "lights positioned
/// up and to the right"), a little towards the viewer, grazing enough that the splash-back shows on
/// the lower left; normalised before use.
pub const DEFAULT_LIGHT_IN_EYE: [f32; 3] = [1.0, 1.0, 0.5];
/// Default of [`CoolToWarmOptions::size`].
pub const DEFAULT_COOL_TO_WARM_SIZE: u32 = 128;

/// Parameters of one cool-to-warm map.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CoolToWarmOptions {
    /// Blue of the cool colour `(0, 0, b)`. Default [`DEFAULT_COOL_BLUE`] (0.4); range [0, 1].
    pub blue: f32,
    /// Yellow of the warm colour `(y, y, 0)`. Default [`DEFAULT_WARM_YELLOW`] (0.4); range [0, 1].
    pub yellow: f32,
    /// Object-colour share `α` of the cool colour. Default [`DEFAULT_COOL_MIX`] (0.2); range [0, 1].
    pub alpha: f32,
    /// Object-colour share `β` of the warm colour. Default [`DEFAULT_WARM_MIX`] (0.6); range [0, 1].
    pub beta: f32,
    /// The object colour `k_d` (RGB in [0, 1]): `Some` bakes the final colour, `None` (default) the
    /// factored encoding that serves every colour.
    pub object_colour: Option<[f32; 3]>,
    /// Multiply by the splash-back term. Default `false` (Fig. 10(a)); `true` is Fig. 10(b).
    pub splash_back: bool,
    /// Splash-back `α_s`. Default [`DEFAULT_SPLASH_ALPHA`] (0.76); range [0, 1].
    pub splash_alpha: f32,
    /// Splash-back exponent `β_s`. Default [`DEFAULT_SPLASH_BETA`] (0.78); range [0.05, 10].
    pub splash_beta: f32,
    /// Direction towards the light in eye space (x right, y up, z towards the viewer); normalised
    /// before use. Default [`DEFAULT_LIGHT_IN_EYE`]; must be finite and non-zero.
    pub light_in_eye: [f32; 3],
    /// Edge of the square map. Default [`DEFAULT_COOL_TO_WARM_SIZE`] (128); range [8, 2048].
    pub size: u32,
    /// Parameterisation of the normal. Default octahedral.
    pub mapping: EnvMapping,
}

impl Default for CoolToWarmOptions {
    fn default() -> Self {
        Self {
            blue: DEFAULT_COOL_BLUE,
            yellow: DEFAULT_WARM_YELLOW,
            alpha: DEFAULT_COOL_MIX,
            beta: DEFAULT_WARM_MIX,
            object_colour: None,
            splash_back: false,
            splash_alpha: DEFAULT_SPLASH_ALPHA,
            splash_beta: DEFAULT_SPLASH_BETA,
            light_in_eye: DEFAULT_LIGHT_IN_EYE,
            size: DEFAULT_COOL_TO_WARM_SIZE,
            mapping: EnvMapping::Octahedral,
        }
    }
}

impl CoolToWarmOptions {
    /// Checks every field against its documented range; `prefix` names the options in the error.
    pub fn validate(&self, prefix: &str) -> Result<(), OptionError> {
        let unit = [
            ("blue", self.blue),
            ("yellow", self.yellow),
            ("alpha", self.alpha),
            ("beta", self.beta),
            ("splash_alpha", self.splash_alpha),
        ];
        for (field, v) in unit {
            if !(0.0..=1.0).contains(&v) {
                return Err(OptionError {
                    name: format!("{prefix}{field}"),
                    value: v.to_string(),
                    expected: "a number in [0, 1]",
                });
            }
        }
        if let Some(c) = self.object_colour
            && !c.iter().all(|v| (0.0..=1.0).contains(v))
        {
            return Err(OptionError {
                name: format!("{prefix}object_colour"),
                value: format!("{c:?}"),
                expected: "RGB components in [0, 1]",
            });
        }
        if !(0.05..=10.0).contains(&self.splash_beta) {
            return Err(OptionError {
                name: format!("{prefix}splash_beta"),
                value: self.splash_beta.to_string(),
                expected: "a number in [0.05, 10]",
            });
        }
        let l = Vec3::from_array(self.light_in_eye);
        if !l.is_finite() || l.length_squared() == 0.0 {
            return Err(OptionError {
                name: format!("{prefix}light_in_eye"),
                value: format!("{:?}", self.light_in_eye),
                expected: "a finite, non-zero direction",
            });
        }
        if !(8..=2048).contains(&self.size) {
            return Err(OptionError {
                name: format!("{prefix}size"),
                value: self.size.to_string(),
                expected: "an integer in [8, 2048]",
            });
        }
        Ok(())
    }

    /// The options with every field clamped into its range (NaN → default; a zero or non-finite
    /// light → the default light).
    pub fn sanitized(&self) -> Self {
        let d = Self::default();
        let f = |x: f32, lo: f32, hi: f32, def: f32| if x.is_nan() { def } else { x.clamp(lo, hi) };
        let l = Vec3::from_array(self.light_in_eye);
        let light = if l.is_finite() && l.length_squared() > 0.0 { l } else { Vec3::from_array(d.light_in_eye) };
        Self {
            blue: f(self.blue, 0.0, 1.0, d.blue),
            yellow: f(self.yellow, 0.0, 1.0, d.yellow),
            alpha: f(self.alpha, 0.0, 1.0, d.alpha),
            beta: f(self.beta, 0.0, 1.0, d.beta),
            object_colour: self.object_colour.map(|c| c.map(|v| f(v, 0.0, 1.0, 0.0))),
            splash_back: self.splash_back,
            splash_alpha: f(self.splash_alpha, 0.0, 1.0, d.splash_alpha),
            splash_beta: f(self.splash_beta, 0.05, 10.0, d.splash_beta),
            light_in_eye: light.normalize().to_array(),
            size: self.size.clamp(8, 2048),
            mapping: self.mapping,
        }
    }

    /// The encoding these options bake.
    pub fn encoding(&self) -> CoolToWarmEncoding {
        if self.object_colour.is_some() { CoolToWarmEncoding::Colour } else { CoolToWarmEncoding::Factored }
    }
}

/// The splash-back multiplier `|α cos θ + (1 − α)|^β` (module docs).
pub fn splash_back(cos_theta: f32, alpha: f32, beta: f32) -> f32 {
    (alpha * cos_theta.clamp(-1.0, 1.0) + (1.0 - alpha)).abs().powf(beta)
}

/// The factored model at `n·l`: `(base, weight)` with `I = base + weight·k_d` (splash-back included
/// when enabled), unclamped.
pub fn cool_to_warm_factored(n_dot_l: f32, options: &CoolToWarmOptions) -> (Vec3, f32) {
    let c = n_dot_l.clamp(-1.0, 1.0);
    let t = (1.0 + c) / 2.0;
    let warm = Vec3::new(options.yellow, options.yellow, 0.0);
    let cool = Vec3::new(0.0, 0.0, options.blue);
    let base = t * warm + (1.0 - t) * cool;
    let weight = t * options.beta + (1.0 - t) * options.alpha;
    let m = if options.splash_back { splash_back(c, options.splash_alpha, options.splash_beta) } else { 1.0 };
    (base * m, weight * m)
}

/// The shaded colour at `n·l` for object colour `k_d`, clamped to [0, 1].
pub fn cool_to_warm_colour(n_dot_l: f32, object_colour: Vec3, options: &CoolToWarmOptions) -> Vec3 {
    let (base, weight) = cool_to_warm_factored(n_dot_l, options);
    (base + weight * object_colour).clamp(Vec3::ZERO, Vec3::ONE)
}

/// The map's four channel values at an eye-space unit normal (before 8-bit quantisation).
pub fn cool_to_warm_texel(normal_in_eye: Vec3, options: &CoolToWarmOptions) -> [f32; 4] {
    let o = options;
    let n_dot_l = normal_in_eye.normalize_or_zero().dot(Vec3::from_array(o.light_in_eye).normalize_or_zero());
    match o.object_colour {
        Some(kd) => cool_to_warm_colour(n_dot_l, Vec3::from_array(kd), o).extend(1.0).to_array(),
        None => {
            let (base, weight) = cool_to_warm_factored(n_dot_l, o);
            base.clamp(Vec3::ZERO, Vec3::ONE).extend(weight.clamp(0.0, 1.0)).to_array()
        }
    }
}

/// One cool-to-warm map, `Rgba8`, `size²`, named `name`.
pub fn cool_to_warm_map(options: &CoolToWarmOptions, name: &str) -> Texture {
    let o = options.sanitized();
    let data = bake_env_map(o.size, o.mapping, 4, |n| cool_to_warm_texel(n, &o));
    Texture {
        name: name.into(),
        kind: TextureKind::CoolToWarm {
            mapping: o.mapping,
            encoding: o.encoding(),
            light_in_eye: o.light_in_eye,
            splash_back: o.splash_back,
        },
        width: o.size,
        height: o.size,
        layers: 1,
        format: TextureFormat::Rgba8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn splash_back_is_the_formula() {
        let (a, b) = (DEFAULT_SPLASH_ALPHA, DEFAULT_SPLASH_BETA);
        for k in 0..=200 {
            let c = -1.0 + k as f32 / 100.0;
            let base = a * c + (1.0 - a);
            let want = if base >= 0.0 { base.powf(b) } else { (-base).powf(b) };
            assert!((splash_back(c, a, b) - want).abs() < 1e-6);
        }
        assert!((splash_back(1.0, a, b) - 1.0).abs() < 1e-6);
        assert!(splash_back(-(1.0 - a) / a, a, b) < 1e-4, "the dark band");
        assert!((splash_back(-1.0, a, b) - 0.52f32.powf(0.78)).abs() < 1e-6, "the splash");
    }

    #[test]
    fn warm_faces_the_light_cool_faces_away() {
        let o = CoolToWarmOptions::default();
        let kd = Vec3::new(0.5, 0.5, 0.5);
        let lit = cool_to_warm_colour(1.0, kd, &o);
        let unlit = cool_to_warm_colour(-1.0, kd, &o);
        assert!((lit - (Vec3::new(0.4, 0.4, 0.0) + 0.6 * kd)).abs().max_element() < 1e-6);
        assert!((unlit - (Vec3::new(0.0, 0.0, 0.4) + 0.2 * kd)).abs().max_element() < 1e-6);
        // Factored: rgb + a·k_d = the colour, for any k_d.
        for kd in [Vec3::ZERO, Vec3::ONE, Vec3::new(0.8, 0.1, 0.3)] {
            for c in [-1.0, -0.3, 0.0, 0.4, 1.0] {
                let (base, w) = cool_to_warm_factored(c, &o);
                let direct = cool_to_warm_colour(c, kd, &o);
                assert!(((base + w * kd).clamp(Vec3::ZERO, Vec3::ONE) - direct).abs().max_element() < 1e-6);
            }
        }
    }

    #[test]
    fn splash_map_texels_match_the_formula() {
        for mapping in [EnvMapping::Octahedral, EnvMapping::NormalSphere] {
            let o = CoolToWarmOptions {
                splash_back: true,
                object_colour: Some([0.9, 0.2, 0.1]),
                size: 64,
                mapping,
                ..Default::default()
            };
            let map = cool_to_warm_map(&o, "t");
            map.check().unwrap();
            let l = Vec3::from_array(DEFAULT_LIGHT_IN_EYE).normalize();
            for y in 0..64 {
                for x in 0..64 {
                    let uv = Vec2::new((x as f32 + 0.5) / 64.0, (y as f32 + 0.5) / 64.0);
                    let n = mapping.normal_from_uv(uv);
                    let c = n.dot(l);
                    let m = splash_back(c, 0.76, 0.78);
                    let t = (1.0 + c) / 2.0;
                    let kd = Vec3::new(0.9, 0.2, 0.1);
                    let want = ((t * Vec3::new(0.4, 0.4, 0.0) + (1.0 - t) * Vec3::new(0.0, 0.0, 0.4))
                        + (t * 0.6 + (1.0 - t) * 0.2) * kd)
                        * m;
                    for ch in 0..3 {
                        let got = map.texel(0, 0, x, y, ch);
                        assert!((got - want[ch].clamp(0.0, 1.0)).abs() <= 0.5 / 255.0 + 1e-5, "{x},{y}");
                    }
                    assert_eq!(map.texel(0, 0, x, y, 3), 1.0);
                }
            }
        }
    }
}
