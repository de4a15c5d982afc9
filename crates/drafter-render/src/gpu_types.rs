//! Every struct the shaders read, laid out for WGSL (`#[repr(C)]`, 16-byte aligned members).
//!
//! Keep in sync with the declarations of the same names in `passes/gbuffer.wgsl`,
//! `passes/shadow.wgsl`, `passes/enhance.wgsl`, `passes/display.wgsl` and `passes/lines.wgsl`; the size assertions at the
//! bottom catch a field added on one side only. The model's own records (vertices, instances, parts,
//! materials, line segments) are drafter-scene's [`drafter_scene::layout`], re-exported here.

use bytemuck::{Pod, Zeroable};

pub use drafter_scene::layout::{
    InstanceGpu, LineSegmentGpu, MaterialGpu, NO_STYLE, NOT_FLAT, PART_REFERENCE, PART_SELECTED, PartGpu, Vertex,
};

/// Per-frame uniforms of the geometry passes (`gbuffer.wgsl`, `shadow.wgsl`: `Frame`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameUniforms {
    pub clip_from_render: [[f32; 4]; 4],
    pub view_from_render: [[f32; 4]; 4],
    /// Camera position in render space; w = 1 for an orthographic camera.
    pub camera_position: [f32; 4],
    /// Unit vector towards the key light, in view space (fixed to the viewer: the object turns,
    /// not the light; Gooch et al. 1999, §4.1).
    pub light_in_view: [f32; 4],
    /// Width, height, 1/width, 1/height of the render target in pixels.
    pub viewport: [f32; 4],
    /// Scene style ([`crate::Style::index`]).
    pub scene_style: u32,
    /// 1: part style hints apply; 0: every part takes the scene style.
    pub use_part_styles: u32,
    /// Cel / Goochel steps (2–4).
    pub cel_steps: u32,
    /// Bit 0: cel specular band; bit 1: Gooch splash-back; bit 2: object-space hatching.
    pub flags: u32,
    /// Gooch splash-back α, β; hatch stroke period in pixels; hatch sharpness c.
    pub style_params: [f32; 4],
}

/// `FrameUniforms::flags` bit: a specular band on cel shading.
pub const FLAG_CEL_SPECULAR: u32 = 1;
/// `FrameUniforms::flags` bit: Gooch's splash-back multiplier.
pub const FLAG_SPLASH_BACK: u32 = 2;
/// `FrameUniforms::flags` bit: hatch strokes fixed to the object instead of the screen.
pub const FLAG_HATCH_OBJECT_SPACE: u32 = 4;

/// The G-buffer's lookup textures (`gbuffer.wgsl`: `Lookups`): which are baked and how they are
/// indexed. One per scene, rewritten each frame (the cel row and the hatching tile follow the
/// frame's options).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LookupUniforms {
    /// `LOOKUP_*` bits.
    pub flags: u32,
    /// `v` of the centre of the cel atlas row in use.
    pub cel_row_v: f32,
    /// The row's darkest step.
    pub cel_min_level: f32,
    /// The row's brightest diffuse step (1 without a specular band).
    pub cel_diffuse_max: f32,
    /// Hatching: the halftone tile's side in target pixels, the soft threshold's `c`; zw unused.
    pub hatch: [f32; 4],
    /// Cool-to-warm: the unit direction towards the light the map was baked for (eye space).
    pub map_light: [f32; 4],
    /// A unit vector orthogonal to `map_light`, leaning towards the viewer.
    pub map_across: [f32; 4],
    /// Metal: the stripe scale `s` of `u = s·(1 + n·w)/2`; yzw unused.
    pub metal: [f32; 4],
}

/// `LookupUniforms::flags` bit: cel steps from the baked cel atlas.
pub const LOOKUP_CEL: u32 = 1;
/// `LookupUniforms::flags` bit: cool-to-warm from the baked map.
pub const LOOKUP_COOL_TO_WARM: u32 = 2;
/// `LookupUniforms::flags` bit: hatching from the baked halftone.
pub const LOOKUP_HATCH: u32 = 4;
/// `LookupUniforms::flags` bit: metal bands and highlights from the baked textures.
pub const LOOKUP_METAL: u32 = 8;
/// `LookupUniforms::flags` bit: the cel row ends in a specular band (values above `cel_diffuse_max`).
pub const LOOKUP_CEL_SPECULAR: u32 = 16;
/// `LookupUniforms::flags` bit: the cool-to-warm map is factored (`clamp(rgb + a·k_d)`), not a colour.
pub const LOOKUP_COOL_TO_WARM_FACTORED: u32 = 32;
/// `LookupUniforms::flags` bit: the cool-to-warm map includes the splash-back multiplier.
pub const LOOKUP_COOL_TO_WARM_SPLASH: u32 = 64;
/// `LookupUniforms::flags` bit: the cool-to-warm map is a normal sphere (else octahedral).
pub const LOOKUP_COOL_TO_WARM_SPHERE: u32 = 128;
/// `LookupUniforms::flags` bit: the metal highlight map is a normal sphere (else octahedral).
pub const LOOKUP_METAL_SPHERE: u32 = 256;

/// One shadow layer (`shadow.wgsl`: `ShadowLayer`), bound with a dynamic offset.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ShadowLayerGpu {
    /// Where the projected points go: the camera's clip space for a screen-space layer, the
    /// ground map's for the soft shadow's map.
    pub clip_from_render: [[f32; 4]; 4],
    /// Point light position, render space; w unused.
    pub light_position: [f32; 4],
    /// x: height of the plane the shadow is projected onto; y: height of the ground it is moved
    /// to; z: weight added per covered pixel.
    pub plane: [f32; 4],
}

/// Most planes of a soft shadow ([`ShadowResolveGpu::inverse_scales`]).
pub const MAX_SOFT_PLANES: usize = 16;

/// The soft shadow's resolve (`shadow.wgsl`: `Resolve`): every plane of the stack is the ground
/// shadow scaled about the light's foot point, so the mask is an average of map lookups.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct ShadowResolveGpu {
    pub render_from_clip: [[f32; 4]; 4],
    /// The ground rectangle the map covers: min x, min z, width, depth (render space).
    pub map_rect: [f32; 4],
    /// The light's foot point (x, z), the ground height, and the number of planes.
    pub foot_ground_count: [f32; 4],
    /// Width and height of the mask being written.
    pub target_size: [f32; 4],
    /// 1 / scale of each plane's shadow about the foot point, four per vector.
    pub inverse_scales: [[f32; 4]; 4],
}

/// Uniforms of one blur direction of the enhancement pass (`enhance.wgsl`: `Enhance`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct EnhanceUniforms {
    /// Blur direction (1,0) or (0,1); z: Gaussian sigma and w: kernel radius, in target texels.
    pub blur: [f32; 4],
    /// Depth given to background pixels (beyond the farthest model point), in view units.
    pub far_depth: f32,
    /// 1: read the full-resolution depth (every `source_step` texels) and fill the background.
    pub background_fill: f32,
    /// Full-resolution texels per blur texel when reading the source (first direction), else 1.
    pub source_step: f32,
    pub _pad: f32,
}

/// Uniforms of the display pass (`display.wgsl`: `Display`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct DisplayUniforms {
    pub background: [f32; 4],
    pub shadow_color: [f32; 4],
    pub line_color: [f32; 4],
    pub crease_color: [f32; 4],
    pub highlight_color: [f32; 4],
    /// Part id + 1 of the selected part, 0 for none.
    pub selected: u32,
    /// Bit 0: outlines; bit 1: creases; bit 2: depth unsharp mask; bit 3: shadow.
    pub flags: u32,
    pub _pad: [u32; 2],
    /// Relative second difference of the affine depth that counts as a depth edge.
    pub depth_threshold: f32,
    /// Cosine of the normal angle that counts as a crease.
    pub crease_cos: f32,
    /// Line half-width in pixels (1 at 1× supersampling).
    pub line_radius: f32,
    /// Scale of the depth unsharp mask (Luft et al. 2006), per unit of scene radius.
    pub unsharp_strength: f32,
    /// 1 for an orthographic camera (depth affine on planes), 0 for perspective (1/depth affine).
    pub ortho: f32,
    /// Scene radius in view units (normalises depth differences).
    pub scene_radius: f32,
    pub _pad2: [f32; 2],
}

/// `DisplayUniforms::flags` bit: draw outlines (part borders, silhouettes).
pub const DISPLAY_OUTLINES: u32 = 1;
/// `DisplayUniforms::flags` bit: draw creases.
pub const DISPLAY_CREASES: u32 = 2;
/// `DisplayUniforms::flags` bit: apply the depth unsharp mask.
pub const DISPLAY_UNSHARP: u32 = 4;
/// `DisplayUniforms::flags` bit: composite the drop shadow.
pub const DISPLAY_SHADOW: u32 = 8;

/// Uniforms of the lines pass (`lines.wgsl`: `Lines`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct LinesUniforms {
    pub clip_from_view: [[f32; 4]; 4],
    /// Colour of silhouettes, boundaries, part borders and non-manifold edges.
    pub outline_color: [f32; 4],
    /// Colour of creases (a: opacity).
    pub crease_color: [f32; 4],
    /// Half-widths in target pixels: outlines, creases, and the extra of the outer outline
    /// (drawn only over the background); w: the camera's near plane (view units).
    pub half_widths: [f32; 4],
    /// Depth tolerance: relative to the line's view depth, and in pixel footprints; the pixel
    /// footprint at view depth d is `x·d + y` (x for perspective, y for orthographic cameras).
    pub depth_tolerance: [f32; 4],
}

const _: () = {
    assert!(size_of::<FrameUniforms>() == 128 + 48 + 16 + 16);
    assert!(size_of::<LookupUniforms>() == 80);
    assert!(size_of::<ShadowLayerGpu>() == 96);
    assert!(size_of::<ShadowResolveGpu>() == 176);
    assert!(size_of::<EnhanceUniforms>() == 32);
    assert!(size_of::<DisplayUniforms>() == 128);
    assert!(size_of::<LinesUniforms>() == 128);
};
