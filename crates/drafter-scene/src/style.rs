//! The shading styles and the view: what the viewer's frames and the drawings share, with the
//! documented defaults, and the procedural lookup tables a file without baked ones falls back on.
//! The options of a GPU frame are the renderer's (`drafter_render::RenderOptions`).

use drafter_core::gradient::{IntensityTransfer, TransferCurve};

/// A shading style of the G-buffer pass: the format's type, so that the file's style hints, the
/// frame's style and the CLI's `--style` are one enum.
pub use drafter_format::{PartStyle as Style, UnknownStyle};

/// The value the shaders switch on for `style` (keep in sync with `STYLE_*` in
/// `passes/gbuffer.wgsl`).
pub fn shader_index(style: Style) -> u32 {
    match style {
        Style::Phong => 0,
        Style::Gradient => 1,
        Style::Cel => 2,
        Style::Gooch => 3,
        Style::Goochel => 4,
        Style::Metal => 5,
        Style::Hatch => 6,
    }
}

/// Default steps of cel and Goochel shading (the viewer's `RenderOptions::cel_steps`): the bake's
/// default cel table's, so that a default frame finds its row in a baked cel atlas.
pub use drafter_textures::cel::DEFAULT_CEL_STEPS;

/// Default of [`View::azimuth_deg`].
pub const DEFAULT_AZIMUTH_DEG: f32 = 35.0;
/// Default of [`View::elevation_deg`].
pub const DEFAULT_ELEVATION_DEG: f32 = 25.0;
/// Default vertical field of view, degrees (the viewer's `RenderOptions::fov_y_deg`, the drawings').
pub const DEFAULT_FOV_Y_DEG: f32 = 30.0;
/// Freudenberg's scale `c > 1` of the soft threshold `clamp(c·(1 − (T + I)))` of the procedural
/// strokes (a baked halftone brings its own `c`).
pub const HATCH_SHARPNESS: f32 = 6.0;

/// Where the camera looks from: angles around the model's centre, world +y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Rotation about +y, degrees, from +z towards +x. Default [`DEFAULT_AZIMUTH_DEG`] (35).
    pub azimuth_deg: f32,
    /// Angle above the horizontal plane, degrees, in (−90, 90). Default [`DEFAULT_ELEVATION_DEG`] (25).
    pub elevation_deg: f32,
}

impl Default for View {
    fn default() -> Self {
        Self { azimuth_deg: DEFAULT_AZIMUTH_DEG, elevation_deg: DEFAULT_ELEVATION_DEG }
    }
}

/// Every transfer curve γ as 128 texels `γ(k / 127)`, one row per curve in the order of
/// [`TransferCurve::ALL`] (a curve's row is its index there), as
/// [`drafter_core::gradient::IntensityTransfer::sample`] interpolates them: the procedural γ atlas
/// ([`crate::lookups::procedural_gamma`]).
pub fn transfer_tables() -> Vec<f32> {
    TransferCurve::ALL.iter().flat_map(|&c| IntensityTransfer::from_curve(c).texels().to_vec()).collect()
}

/// The row of `curve` in [`transfer_tables`].
pub fn transfer_index(curve: TransferCurve) -> usize {
    TransferCurve::ALL.iter().position(|&c| c == curve).unwrap_or(0)
}

/// Entries of the metal band table: the bake's ([`drafter_textures::MetalOptions`]' default).
pub const METAL_TABLE_LEN: usize = drafter_textures::metal::DEFAULT_METAL_TABLE_LEN as usize;

/// Gooch et al. 1999, §5.2.1: the periodic table of filtered random intensities the G-buffer pass
/// wraps around each part's principal axis when the file has no baked `metal_bands` (procedural
/// fallback). It is drafter-textures' table with the bake's default options, the rule and seed
/// the baked texture comes from, so a plain file's metal matches a baked one's.
pub fn metal_table() -> Vec<f32> {
    drafter_textures::metal_table(&drafter_textures::MetalOptions::default())
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::gradient::INTENSITY_TABLE_LEN;

    #[test]
    fn names_round_trip() {
        for s in Style::ALL {
            assert_eq!(s.name().parse::<Style>(), Ok(s));
        }
        assert!("toon".parse::<Style>().is_err());
        let mut indices: Vec<u32> = Style::ALL.iter().map(|&s| shader_index(s)).collect();
        indices.sort_unstable();
        assert_eq!(indices, (0..7).collect::<Vec<_>>());
    }

    #[test]
    fn tables_are_in_range() {
        let t = transfer_tables();
        assert_eq!(t.len(), TransferCurve::ALL.len() * INTENSITY_TABLE_LEN);
        assert!(t.iter().all(|v| (0.0..=1.0).contains(v)));
        // Rows in the order of the curves.
        for (k, &curve) in TransferCurve::ALL.iter().enumerate() {
            assert_eq!(transfer_index(curve), k);
            let row = &t[k * INTENSITY_TABLE_LEN..(k + 1) * INTENSITY_TABLE_LEN];
            assert!((f64::from(row[64]) - TransferCurve::ALL[k].eval(64.0 / 127.0)).abs() < 1e-6);
        }
        let m = metal_table();
        assert_eq!(m.len(), METAL_TABLE_LEN);
        assert!(m.iter().all(|v| (0.0..=1.0).contains(v)));
        // Not constant: bands are visible.
        let (lo, hi) = m.iter().fold((1.0f32, 0.0f32), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(hi - lo > 0.3, "{lo}..{hi}");
    }
}
