//! Shading styles and the options of a frame, with their documented defaults.
//!
//! The styles are the ones the `DRAFTER_illustration` spec names as part style hints; see
//! `passes/gbuffer.wgsl` for the formulas and the papers they come from. The style enum, the
//! [`View`], its defaults and the procedural tables are drafter-scene's (the drawings read them
//! too), re-exported here.

pub use drafter_scene::style::{
    DEFAULT_AZIMUTH_DEG, DEFAULT_CEL_STEPS, DEFAULT_ELEVATION_DEG, DEFAULT_FOV_Y_DEG, HATCH_SHARPNESS, METAL_TABLE_LEN,
    Style, UnknownStyle, View, metal_table, shader_index, transfer_index, transfer_tables,
};

/// The drop shadow under the model (Gooch et al. 1999, §5.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum ShadowMode {
    /// No shadow (the default).
    #[default]
    None,
    /// One hard shadow from the centre of the light.
    Hard,
    /// A hard umbra and a hard penumbra: two hard shadows, from the back and the front of a
    /// spherical light along its direction.
    Penumbra,
    /// A soft shadow: the shadow projected onto a stack of planes below the ground, each moved up
    /// to the ground and accumulated.
    Soft,
}

impl ShadowMode {
    pub const ALL: [ShadowMode; 4] = [ShadowMode::None, ShadowMode::Hard, ShadowMode::Penumbra, ShadowMode::Soft];

    pub fn name(self) -> &'static str {
        match self {
            ShadowMode::None => "none",
            ShadowMode::Hard => "hard",
            ShadowMode::Penumbra => "penumbra",
            ShadowMode::Soft => "soft",
        }
    }
}

/// Default of [`RenderOptions::size`].
pub const DEFAULT_SIZE: (u32, u32) = (800, 600);
/// Splash-back α of Gooch et al. 1999, §3.2.
pub const SPLASH_BACK_ALPHA: f32 = 0.76;
/// Splash-back β of Gooch et al. 1999, §3.2.
pub const SPLASH_BACK_BETA: f32 = 0.78;
/// Default of [`RenderOptions::hatch_period_px`].
pub const DEFAULT_HATCH_PERIOD_PX: f32 = 5.0;
/// Level-0 texels between neighbouring strokes of one family in drafter-textures' default halftone
/// (`128 / (8·√2)`: 8 diagonal lines per 128-texel tile). A baked halftone's tile is drawn so that
/// this many texels span [`RenderOptions::hatch_period_px`], as far as its mip chain allows.
pub const HALFTONE_STROKE_SPACING_TEXELS: f32 = 11.313_708;
/// The stripe scale `s ≥ 1` of the baked metal bands, `u = s·(1 + n·w)/2`: 1 spreads the band table
/// once over each half turn around the axis (16 streaks with drafter-textures' defaults).
pub const METAL_STRIPE_SCALE: f32 = 1.0;
/// Default of [`RenderOptions::background`]: near-white paper.
pub const DEFAULT_BACKGROUND: [f32; 3] = [1.0, 1.0, 1.0];
/// Default of [`RenderOptions::shadow_color`]: a cool grey-blue, as illustrators colour shadows.
pub const DEFAULT_SHADOW_COLOR: [f32; 3] = [0.62, 0.66, 0.74];

/// Which image-space enhancements the enhancement pass draws (Lux et al. 2013, §5: edges after
/// [IFH03] and the depth unsharp mask of Luft et al. 2006).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Enhancements {
    /// Black lines where the part id or depth jumps: part borders, silhouettes, and a heavier
    /// outer outline against the background. Default off.
    pub outlines: bool,
    /// Lines where the normal turns by more than the crease angle inside a part (white on the Gooch
    /// styles, as Gooch et al. draw creases; dark grey otherwise). Default off.
    pub creases: bool,
    /// Darken pixels that lie behind their surroundings (unsharp mask of the depth buffer).
    /// Default off.
    pub unsharp_mask: bool,
}

impl Enhancements {
    /// Everything on: what `--edges` asks for.
    pub const ALL: Enhancements = Enhancements { outlines: true, creases: true, unsharp_mask: true };

    pub fn any(self) -> bool {
        self.outlines || self.creases || self.unsharp_mask
    }
}

/// Everything that shapes one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// Output size in pixels. Default [`DEFAULT_SIZE`] (800×600); each side 1..=8192.
    pub size: (u32, u32),
    /// Supersampling factor: the frame is drawn at `size × supersample` and box-filtered down
    /// (anti-aliasing for headless output). Default 1; range 1..=4.
    pub supersample: u32,
    /// The scene's style. Default [`Style::Gradient`].
    pub style: Style,
    /// Whether the parts' baked style hints override [`Self::style`]. Default true.
    pub use_part_styles: bool,
    pub view: View,
    /// Orthographic instead of perspective projection. Default false.
    pub orthographic: bool,
    /// Vertical field of view of the perspective camera, degrees. Default [`DEFAULT_FOV_Y_DEG`] (30).
    pub fov_y_deg: f32,
    /// Magnification of the fitted frame about its centre (the window's wheel). Default 1; range
    /// [`ZOOM_RANGE`].
    pub zoom: f32,
    /// Shift of the image in normalised device units (x right, y up; 2 = the frame's width or
    /// height), applied after the zoom (the window's right/middle drag). Default (0, 0).
    pub pan: [f32; 2],
    pub enhancements: Enhancements,
    /// Draw the baked edges and this view's silhouettes (the lines pass). Default false.
    pub lines: bool,
    pub shadow: ShadowMode,
    /// Shadow colour (display values). Default [`DEFAULT_SHADOW_COLOR`].
    pub shadow_color: [f32; 3],
    /// Background colour (display values). Default [`DEFAULT_BACKGROUND`] (white).
    pub background: [f32; 3],
    /// Steps of cel and Goochel shading. Default [`DEFAULT_CEL_STEPS`] (3); range 2..=4.
    pub cel_steps: u32,
    /// A white specular band on cel shading. Default true.
    pub cel_specular: bool,
    /// Gooch's splash-back multiplier (α = 0.76, β = 0.78): `(α|cos θ| + (1 − α))^β` procedurally,
    /// the paper's `|α cos θ + (1 − α)|^β` with a baked cool-to-warm map (unless the map has it
    /// already). Default false.
    pub splash_back: bool,
    /// Hatch stroke period in output pixels. Default [`DEFAULT_HATCH_PERIOD_PX`] (5). A baked
    /// halftone keeps its strokes' spacing in target pixels at each mip level, so below about 11
    /// target pixels (supersampling 1) the strokes stay that far apart rather than alias.
    pub hatch_period_px: f32,
    /// Part id to highlight (the display pass tints it). Default none.
    pub selected_part: Option<u32>,
    /// Shade with the baked enhanced normals (Cignoni et al. 2005, `_ENHANCED_NORMAL`) instead of
    /// the crease-aware `NORMAL`: the paper's toggle. Every normal-based style (all but gradient,
    /// whose shade comes from the projector) and the image-space crease edges see it; batches without enhanced
    /// normals keep theirs ([`crate::Model::has_enhanced_normals`]). Default false.
    pub enhanced_normals: bool,
    /// A cheaper frame for while the user drags (the window sets it during a drag and clears it
    /// when the mouse is still): every pass runs at 1/[`Self::interactive_scale`] of the
    /// resolution in each direction and [`crate::passes::upscale`] filters the result up to the
    /// output size; the depth unsharp mask is left out ([`Self::drawn_enhancements`]). The frame
    /// keeps its size, camera and content; picking reads the reduced part ids. Default false (full
    /// quality).
    pub interactive: bool,
    /// Divisor of the resolution of an interactive frame, in each direction, 1 to 4. Default
    /// [`INTERACTIVE_SCALE`]; the window and `drafter bench render` take
    /// [`crate::Gpu::interactive_scale`], which is larger on a CPU rasteriser.
    pub interactive_scale: u32,
    /// Drawn pixels per logical pixel of the widths of lines and image-space edges: the
    /// browser's `devicePixelRatio`, so that the page's lines keep their width in CSS pixels on a
    /// high-density screen. Default 1; range [0.25, 8].
    pub line_scale: f32,
}

/// Divisor of the resolution of an [`RenderOptions::interactive`] frame on a GPU, in each direction.
pub const INTERACTIVE_SCALE: u32 = 2;

/// The same on a CPU rasteriser (lavapipe): measured dragging the sample assembly at 1024×768 with
/// edges, lines and a soft shadow on a 2-core VM, 9.1–11.2 frames/s at 2 and 12.1–13.1 at 3 (the
/// upscale, the window's present and the overlay cost the same at any scale).
pub const CPU_INTERACTIVE_SCALE: u32 = 3;

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            size: DEFAULT_SIZE,
            supersample: 1,
            style: Style::default(),
            use_part_styles: true,
            view: View::default(),
            orthographic: false,
            fov_y_deg: DEFAULT_FOV_Y_DEG,
            zoom: 1.0,
            pan: [0.0, 0.0],
            enhancements: Enhancements::default(),
            lines: false,
            shadow: ShadowMode::default(),
            shadow_color: DEFAULT_SHADOW_COLOR,
            background: DEFAULT_BACKGROUND,
            cel_steps: DEFAULT_CEL_STEPS,
            cel_specular: true,
            splash_back: false,
            hatch_period_px: DEFAULT_HATCH_PERIOD_PX,
            selected_part: None,
            enhanced_normals: false,
            interactive: false,
            interactive_scale: INTERACTIVE_SCALE,
            line_scale: 1.0,
        }
    }
}

/// Accepted range of [`RenderOptions::zoom`].
pub const ZOOM_RANGE: (f32, f32) = (0.05, 100.0);

/// Largest accepted side of [`RenderOptions::size`] times the supersampling factor.
pub const MAX_TARGET_SIDE: u32 = 8192;

impl RenderOptions {
    /// Checks every field against its documented range.
    pub fn validate(&self) -> Result<(), String> {
        let (w, h) = self.size;
        if w == 0 || h == 0 {
            return Err(format!("size {w}x{h}: both sides must be at least 1"));
        }
        if !(1..=4).contains(&self.interactive_scale) {
            return Err(format!("interactive scale {}: 1 to 4", self.interactive_scale));
        }
        if !(1..=4).contains(&self.supersample) {
            return Err(format!("supersample {} is out of range 1..=4", self.supersample));
        }
        if w.max(h).saturating_mul(self.supersample) > MAX_TARGET_SIDE {
            return Err(format!(
                "size {w}x{h} × supersample {} exceeds {MAX_TARGET_SIDE} pixels a side",
                self.supersample
            ));
        }
        if !(2..=4).contains(&self.cel_steps) {
            return Err(format!("cel steps {} is out of range 2..=4", self.cel_steps));
        }
        let el = self.view.elevation_deg;
        if !(el > -90.0 && el < 90.0 && self.view.azimuth_deg.is_finite()) {
            return Err(format!(
                "view {},{}: azimuth must be finite and elevation in (-90, 90)",
                self.view.azimuth_deg, el
            ));
        }
        if !(self.fov_y_deg > 1.0 && self.fov_y_deg < 150.0) {
            return Err(format!("field of view {} is out of range (1, 150) degrees", self.fov_y_deg));
        }
        if !(self.zoom >= ZOOM_RANGE.0 && self.zoom <= ZOOM_RANGE.1) {
            return Err(format!("zoom {} is out of range [{}, {}]", self.zoom, ZOOM_RANGE.0, ZOOM_RANGE.1));
        }
        if !self.pan.iter().all(|p| p.is_finite() && p.abs() <= 100.0) {
            return Err(format!("pan {:?}: each component must be finite and within ±100", self.pan));
        }
        if !(self.line_scale >= 0.25 && self.line_scale <= 8.0) {
            return Err(format!("line scale {} is out of range [0.25, 8]", self.line_scale));
        }
        if !(self.hatch_period_px >= 1.0 && self.hatch_period_px <= 256.0) {
            return Err(format!("hatch period {} is out of range [1, 256] pixels", self.hatch_period_px));
        }
        Ok(())
    }

    /// Size of the render targets: the output size times the supersampling factor.
    pub fn target_size(&self) -> (u32, u32) {
        (self.size.0 * self.supersample, self.size.1 * self.supersample)
    }

    /// The enhancements the passes draw: [`Self::enhancements`], less the depth unsharp mask in an
    /// interactive frame (its blur is the costliest of them on a CPU rasteriser, and the
    /// darkening of recesses is the least missed while the view moves; still frames have it).
    pub fn drawn_enhancements(&self) -> Enhancements {
        Enhancements { unsharp_mask: self.enhancements.unsharp_mask && !self.interactive, ..self.enhancements }
    }

    /// The size the passes draw at: [`Self::target_size`], divided by
    /// [`Self::interactive_scale`] (rounded up) for an interactive frame.
    pub fn drawn_size(&self) -> (u32, u32) {
        let (w, h) = self.target_size();
        let k = self.interactive_scale.clamp(1, 4);
        if self.interactive { (w.div_ceil(k), h.div_ceil(k)) } else { (w, h) }
    }

    /// Drawn pixels per output pixel: what line widths and hatching periods are multiplied by.
    pub fn pixel_scale(&self) -> f32 {
        let scale = self.supersample.max(1) as f32;
        if self.interactive { scale / self.interactive_scale.clamp(1, 4) as f32 } else { scale }
    }

    /// Drawn pixels per pixel of a line's width: [`Self::pixel_scale`] times [`Self::line_scale`].
    pub fn line_pixel_scale(&self) -> f32 {
        self.pixel_scale() * self.line_scale.clamp(0.25, 8.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_validate() {
        assert!(RenderOptions::default().validate().is_ok());
        let bad = [
            RenderOptions { size: (0, 10), ..Default::default() },
            RenderOptions { supersample: 0, ..Default::default() },
            RenderOptions { size: (5000, 10), supersample: 2, ..Default::default() },
            RenderOptions { cel_steps: 5, ..Default::default() },
            RenderOptions { view: View { azimuth_deg: 0.0, elevation_deg: 90.0 }, ..Default::default() },
        ];
        for o in bad {
            assert!(o.validate().is_err(), "{o:?}");
        }
    }
}
