//! Gradient parameters (Lux et al. 2013, §3 "Gradient Parametrization", Eqn. 1 and Listing 1;
//! ../shared/papers/000_*).
//!
//! A fragment's projector coordinate `p ∈ [0, 1]` (see `drafter_bounds::Projector`) becomes an intensity in two
//! steps: the intensity transfer `i = γ(p)`, a 128-texel 1D table ([`IntensityTransfer`], identity by
//! default), then the gradient function `i' = ω(i, q, f, p)` ([`omega`]) with quantisation `q`, fade-step
//! `f` and power `p` ([`GradientParams`]).
//!
//! # ω, reconstructed
//! Listing 1 of the paper (GLSL) is taken as the definition:
//! ```text
//! r  = 0.5 / (q + 1)
//! ip = i^p
//! iq = floor(ip·q)/q + r
//! mf = mod(ip, 1/q)·q                      // position inside the band, [0, 1)
//! mf = step(f, mf) · (mf − f) / (1 − f)    // fade only in the last (1 − f) of the band
//! ω  = mix(iq − r, iq + r, mf) = (iq − r)(1 − mf) + (iq + r)·mf
//! ```
//! Where the printed Eqn. 1 differs, the listing wins, for these reasons:
//! * Eqn. 1 prints `(iq − r)·m_f + (iq + r)·(1 − m_f)`, the weights of GLSL `mix` swapped. Read that way
//!   every band would fall from `iq + r` to `iq − r` as the fade progresses, a sawtooth running against the
//!   gradient; the listing's order gives the rising staircase of Figs. 5 and 6.
//! * Eqn. 1's `m_f = (i^p mod 1/q)·q` omits the fade-step; the listing applies it (the `step` line).
//! * `r := 1/(2(q+1))` in the text (garbled in the OCR) and `0.5/(q+1)` in the listing agree.
//! * The text gives `p ∈ [−1, 1]`, yet Fig. 6(d) uses `p = 1.4`, and a negative power sends (0, 1] to
//!   [1, ∞). Accepted here: `p ∈ [`[`MIN_POWER`]`, `[`MAX_POWER`]`]`.
//!
//! Two numerical details differ from a literal transcription, both equal in exact arithmetic:
//! * `f = 1` makes the listing divide by `1 − f = 0` (0·∞ = NaN in IEEE arithmetic). Its limit is "no
//!   fade": hard steps. That is what [`omega`] returns.
//! * In floating point `mod(ip, 1/q)·q` and `floor(ip·q)` disagree near band edges (`1/q` is not exact:
//!   for `i = 0.3, q = 10` in f32 the floor says band 3 while `mod·q ≈ 1.0` says "end of band 2"),
//!   which shows as isolated bright texels. Both are derived here from one product `t = ip·q`:
//!   `floor(t)` and `t − floor(t)`. A shader should do the same (`fract(ip * q)`).
//!
//! Faithful to the paper, the fade of band `k` rises from `k/q` to `k/q + 1/(q+1)` and the next band
//! starts at `(k+1)/q`: with `f < 1` there is a step of `1/(q(q+1))` at each band edge. `ω(1) = 1`.

use serde::{Deserialize, Serialize};

use crate::ParamError;

/// Default of [`GradientParams::q`]: ten bands (as Fig. 6(b)).
pub const DEFAULT_QUANTIZATION: u32 = 10;
/// Default of [`GradientParams::f`]: the second half of each band fades into the next.
pub const DEFAULT_FADE_STEP: f32 = 0.5;
/// Default of [`GradientParams::p`]: linear.
pub const DEFAULT_POWER: f32 = 1.0;
/// Largest accepted `q` (an 8-bit intensity cannot show more bands).
pub const MAX_QUANTIZATION: u32 = 255;
/// Smallest accepted `p`.
pub const MIN_POWER: f32 = 0.01;
/// Largest accepted `p`.
pub const MAX_POWER: f32 = 10.0;
/// Texels of an intensity transfer table (the paper: "a texture resolution of 128 pixels").
pub const INTENSITY_TABLE_LEN: usize = 128;

/// The gradient function's parameters `(q, f, p)`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GradientParams {
    /// Quantisation level: number of bands. Default [`DEFAULT_QUANTIZATION`] (10); range
    /// 1..=[`MAX_QUANTIZATION`] (255). Large `q` with `f = 0` approaches a smooth gradient.
    pub q: u32,
    /// Fade-step position inside a band, where the fade to the next band begins. Default
    /// [`DEFAULT_FADE_STEP`] (0.5); range [0, 1]; 1 = hard steps, 0 = fade across the whole band.
    pub f: f32,
    /// Power applied to the intensity before quantisation (`i^p`). Default [`DEFAULT_POWER`] (1.0);
    /// range [[`MIN_POWER`], [`MAX_POWER`]]; < 1 brightens, > 1 darkens.
    pub p: f32,
}

impl Default for GradientParams {
    fn default() -> Self {
        Self { q: DEFAULT_QUANTIZATION, f: DEFAULT_FADE_STEP, p: DEFAULT_POWER }
    }
}

impl GradientParams {
    /// Checks every field against its documented range.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(1..=MAX_QUANTIZATION).contains(&self.q) {
            return Err(ParamError { name: "q", value: self.q.to_string(), expected: "an integer in [1, 255]" });
        }
        if !(0.0..=1.0).contains(&self.f) {
            return Err(ParamError { name: "f", value: self.f.to_string(), expected: "a number in [0, 1]" });
        }
        if !(MIN_POWER..=MAX_POWER).contains(&self.p) {
            return Err(ParamError { name: "p", value: self.p.to_string(), expected: "a number in [0.01, 10]" });
        }
        Ok(())
    }

    /// `ω(i, q, f, p)` for these parameters.
    pub fn eval(&self, i: f32) -> f32 {
        omega(f64::from(i), self.q, f64::from(self.f), f64::from(self.p)) as f32
    }

    /// The full shading chain for a projector coordinate: `ω(γ(p))`.
    pub fn shade(&self, p: f32, transfer: &IntensityTransfer) -> f32 {
        self.eval(transfer.sample(p))
    }
}

/// The gradient function ω of Lux et al. (Listing 1; see the module docs for the reconstruction).
/// `i` is clamped to [0, 1] (NaN → 0), `q` to ≥ 1, `f` to [0, 1], `p` to ≥ [`MIN_POWER`].
pub fn omega(i: f64, q: u32, f: f64, p: f64) -> f64 {
    let i = if i.is_nan() { 0.0 } else { i.clamp(0.0, 1.0) };
    let q = f64::from(q.max(1));
    let f = if f.is_nan() { 1.0 } else { f.clamp(0.0, 1.0) };
    let p = if p.is_nan() { 1.0 } else { p.max(f64::from(MIN_POWER)) };
    let r = 0.5 / (q + 1.0);
    let ip = i.powf(p);
    let t = ip * q;
    let band = t.floor();
    let iq = band / q + r;
    let within = t - band; // = mod(ip, 1/q)·q
    let mf = if f < 1.0 && within >= f { (within - f) / (1.0 - f) } else { 0.0 };
    (iq - r) * (1.0 - mf) + (iq + r) * mf
}

/// Named intensity transfer curves γ.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum TransferCurve {
    /// `γ(x) = x` (the paper's default: "the intensity equals the incoming linear distance").
    #[default]
    Identity,
    /// `3x² − 2x³`: flat ends, steeper middle.
    Smoothstep,
    /// `x²`: darker start.
    EaseIn,
    /// `1 − (1 − x)²`: brighter start.
    EaseOut,
    /// `1 − x`: reversed gradient.
    Invert,
}

impl TransferCurve {
    /// Every curve.
    pub const ALL: [TransferCurve; 5] = [
        TransferCurve::Identity,
        TransferCurve::Smoothstep,
        TransferCurve::EaseIn,
        TransferCurve::EaseOut,
        TransferCurve::Invert,
    ];

    /// The name written in baked files and configuration (its serde spelling).
    pub fn name(self) -> &'static str {
        match self {
            TransferCurve::Identity => "identity",
            TransferCurve::Smoothstep => "smoothstep",
            TransferCurve::EaseIn => "ease_in",
            TransferCurve::EaseOut => "ease_out",
            TransferCurve::Invert => "invert",
        }
    }

    /// γ(x) for `x ∈ [0, 1]`.
    pub fn eval(self, x: f64) -> f64 {
        let x = x.clamp(0.0, 1.0);
        match self {
            TransferCurve::Identity => x,
            TransferCurve::Smoothstep => x * x * (3.0 - 2.0 * x),
            TransferCurve::EaseIn => x * x,
            TransferCurve::EaseOut => 1.0 - (1.0 - x) * (1.0 - x),
            TransferCurve::Invert => 1.0 - x,
        }
    }
}

impl std::fmt::Display for TransferCurve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The intensity transfer γ as a 1D table of [`INTENSITY_TABLE_LEN`] texels.
///
/// Texel `k` holds `γ(k / 127)`, so both ends are exact. [`Self::sample`] interpolates linearly; on the
/// GPU the same lookup is a linearly filtered, clamped 1D texture read at `u = (0.5 + 127·p) / 128`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntensityTransfer {
    texels: Vec<f32>,
}

impl Default for IntensityTransfer {
    fn default() -> Self {
        Self::from_curve(TransferCurve::Identity)
    }
}

impl IntensityTransfer {
    /// The table of a named curve.
    pub fn from_curve(curve: TransferCurve) -> Self {
        Self::from_fn(|x| curve.eval(x))
    }

    /// The table of any γ, sampled at `k / 127` and clamped to [0, 1].
    pub fn from_fn(gamma: impl Fn(f64) -> f64) -> Self {
        let n = INTENSITY_TABLE_LEN;
        let texels = (0..n)
            .map(|k| gamma(k as f64 / (n - 1) as f64))
            .map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) } as f32)
            .collect();
        Self { texels }
    }

    /// A table from explicit texels: exactly [`INTENSITY_TABLE_LEN`] values in [0, 1].
    pub fn from_texels(texels: Vec<f32>) -> Result<Self, ParamError> {
        if texels.len() != INTENSITY_TABLE_LEN {
            return Err(ParamError {
                name: "intensity table length",
                value: texels.len().to_string(),
                expected: "128 texels",
            });
        }
        if let Some(bad) = texels.iter().find(|t| !(0.0..=1.0).contains(*t)) {
            return Err(ParamError { name: "intensity texel", value: bad.to_string(), expected: "a number in [0, 1]" });
        }
        Ok(Self { texels })
    }

    /// The texels (for upload as a 1D texture).
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// γ(p) by linear interpolation, `p` clamped to [0, 1].
    pub fn sample(&self, p: f32) -> f32 {
        let n = self.texels.len();
        if n == 0 {
            return p.clamp(0.0, 1.0);
        }
        let x = if p.is_nan() { 0.0 } else { p.clamp(0.0, 1.0) } * (n - 1) as f32;
        let k = (x.floor() as usize).min(n - 1);
        let next = (k + 1).min(n - 1);
        let w = x - k as f32;
        self.texels[k] * (1.0 - w) + self.texels[next] * w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate_and_ranges_reject() {
        GradientParams::default().validate().unwrap();
        for bad in [
            GradientParams { q: 0, ..Default::default() },
            GradientParams { q: 256, ..Default::default() },
            GradientParams { f: -0.1, ..Default::default() },
            GradientParams { f: 1.5, ..Default::default() },
            GradientParams { f: f32::NAN, ..Default::default() },
            GradientParams { p: 0.0, ..Default::default() },
            GradientParams { p: -1.0, ..Default::default() },
            GradientParams { p: 11.0, ..Default::default() },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        let e = GradientParams { q: 0, ..Default::default() }.validate().unwrap_err();
        assert_eq!(e.to_string(), "q = 0 is out of range; expected an integer in [1, 255]");
    }

    #[test]
    fn identity_table_is_exact_at_texels_and_ends() {
        let t = IntensityTransfer::default();
        assert_eq!(t.texels().len(), 128);
        assert_eq!(t.sample(0.0), 0.0);
        assert_eq!(t.sample(1.0), 1.0);
        for k in 0..=200 {
            let p = k as f32 / 200.0;
            assert!((t.sample(p) - p).abs() < 1e-6);
        }
        let inv = IntensityTransfer::from_curve(TransferCurve::Invert);
        assert!((inv.sample(0.25) - 0.75).abs() < 1e-6);
        assert!(IntensityTransfer::from_texels(vec![0.5; 127]).is_err());
        assert!(IntensityTransfer::from_texels(vec![1.5; 128]).is_err());
        for c in TransferCurve::ALL {
            assert_eq!(c.eval(0.0), if c == TransferCurve::Invert { 1.0 } else { 0.0 });
        }
    }
}
