//! The γ atlas: the intensity transfer tables of the gradient shading (Lux et al. 2013, §3:
//! "intensity transfer functions [...] are stored using 1D texture arrays. A texture resolution of
//! 128 pixels"; ../shared/papers/000_*), one row per distinct curve.
//!
//! Row `r` holds `drafter_core::gradient::IntensityTransfer::from_curve(curves[r])` quantised to 8 bits:
//! texel `k` = `γ(k/127)`. The shader samples at `u = (0.5 + 127·p)/128`, `v = (row + 0.5)/rows`,
//! linear, clamp-to-edge (drafter-bounds' documented lookup), then applies ω. Eight bits resolve γ to
//! 1/255, below what ω's at most 255 bands can show.

use drafter_core::gradient::{INTENSITY_TABLE_LEN, IntensityTransfer, TransferCurve};

use crate::texture::{SamplerHint, Texture, TextureFormat, TextureKind, unorm8};

/// Name of the γ atlas.
pub const GAMMA_ATLAS_NAME: &str = "gamma_atlas";

/// The γ atlas: `R8`, 128 × `curves.len()`, row `r` = `curves[r]` (at least one row: an empty list
/// gives the identity).
pub fn gamma_atlas(curves: &[TransferCurve]) -> Texture {
    let curves: Vec<TransferCurve> = if curves.is_empty() { vec![TransferCurve::Identity] } else { curves.to_vec() };
    let data = curves.iter().flat_map(|&c| IntensityTransfer::from_curve(c).texels().to_vec()).map(unorm8).collect();
    Texture {
        name: GAMMA_ATLAS_NAME.into(),
        width: INTENSITY_TABLE_LEN as u32,
        height: curves.len() as u32,
        kind: TextureKind::GammaAtlas { curves },
        layers: 1,
        format: TextureFormat::R8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    #[test]
    fn rows_are_exactly_the_configured_curves() {
        let atlas = gamma_atlas(&TransferCurve::ALL);
        atlas.check().unwrap();
        assert_eq!((atlas.width, atlas.height), (128, 5));
        for (r, &curve) in TransferCurve::ALL.iter().enumerate() {
            let table = IntensityTransfer::from_curve(curve);
            for k in 0..128 {
                let stored = atlas.mip_levels[0][r * 128 + k];
                assert_eq!(stored, unorm8(table.texels()[k]), "{curve:?} texel {k}");
                let exact = curve.eval(k as f64 / 127.0);
                assert!((f64::from(stored) / 255.0 - exact).abs() <= 0.5 / 255.0 + 1e-9);
            }
            // The documented lookup reproduces γ(p) to 8-bit precision between texels too.
            for j in 0..=100 {
                let p = j as f32 / 100.0;
                let uv = Vec2::new((0.5 + 127.0 * p) / 128.0, (r as f32 + 0.5) / 5.0);
                let got = atlas.sample(0, 0, uv).x;
                assert!((got - table.sample(p)).abs() <= 0.5 / 255.0 + 1e-5, "{curve:?} p = {p}");
            }
        }
    }
}
