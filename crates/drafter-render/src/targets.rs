//! The textures a frame renders into, all of one size, and their formats.

/// Shaded colour of the G-buffer (display values).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// View-space normal of the G-buffer.
pub const NORMAL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Linear view depth of the G-buffer (read by the enhancement pass instead of the depth buffer,
/// which some backends cannot read back as a float texture).
pub const LINEAR_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// Part id + 1 (0 = background).
pub const PART_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
/// The depth buffer of the G-buffer pass.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The blurred linear depth of the unsharp mask.
pub const BLUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
/// The blur targets are this many times smaller than the frame on each side.
pub const BLUR_REDUCTION: u32 = 4;
/// The shadow mask and stencil are this many times smaller than the frame on each side (the
/// display pass samples the mask with bilinear filtering).
pub const SHADOW_REDUCTION: u32 = 2;
/// Accumulated shadow coverage in [0, 1].
pub const SHADOW_MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R16Float;
/// Stencil that lets each shadow layer cover a pixel once.
pub const SHADOW_STENCIL_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth24PlusStencil8;
/// The final image.
pub const OUTPUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// A texture with its default view.
#[derive(Debug)]
pub struct Target {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
}

impl Target {
    pub fn new(
        device: &wgpu::Device,
        label: &str,
        size: (u32, u32),
        format: wgpu::TextureFormat,
        usage: wgpu::TextureUsages,
    ) -> Target {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: size.0, height: size.1, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor { label: Some(label), ..Default::default() });
        Target { texture, view }
    }
}

/// Every intermediate texture of a frame.
#[derive(Debug)]
pub struct Targets {
    pub size: (u32, u32),
    pub color: Target,
    pub normal: Target,
    pub linear_depth: Target,
    pub part_id: Target,
    pub depth: Target,
    pub blur_a: Target,
    pub blur_b: Target,
    pub shadow_mask: Target,
    pub shadow_stencil: Target,
    pub output: Target,
}

impl Targets {
    /// Targets of `size`; the offscreen output (headless renders and screenshots) in `output_format`,
    /// the format the display and lines pipelines were built for.
    pub fn new(device: &wgpu::Device, size: (u32, u32), output_format: wgpu::TextureFormat) -> Targets {
        use wgpu::TextureUsages as U;
        let sampled = U::RENDER_ATTACHMENT | U::TEXTURE_BINDING;
        let reduced = |k: u32| (size.0.div_ceil(k), size.1.div_ceil(k));
        Targets {
            size,
            color: Target::new(device, "gbuffer color", size, COLOR_FORMAT, sampled),
            normal: Target::new(device, "gbuffer normal", size, NORMAL_FORMAT, sampled),
            linear_depth: Target::new(device, "gbuffer linear depth", size, LINEAR_DEPTH_FORMAT, sampled),
            // COPY_SRC: the window reads one texel back to pick a part.
            part_id: Target::new(device, "gbuffer part id", size, PART_ID_FORMAT, sampled | U::COPY_SRC),
            depth: Target::new(device, "gbuffer depth", size, DEPTH_FORMAT, U::RENDER_ATTACHMENT),
            blur_a: Target::new(device, "enhance depth blur a", reduced(BLUR_REDUCTION), BLUR_FORMAT, sampled),
            blur_b: Target::new(device, "enhance depth blur b", reduced(BLUR_REDUCTION), BLUR_FORMAT, sampled),
            shadow_mask: Target::new(device, "shadow mask", reduced(SHADOW_REDUCTION), SHADOW_MASK_FORMAT, sampled),
            shadow_stencil: Target::new(
                device,
                "shadow stencil",
                reduced(SHADOW_REDUCTION),
                SHADOW_STENCIL_FORMAT,
                U::RENDER_ATTACHMENT,
            ),
            output: Target::new(
                device,
                "display output",
                size,
                output_format,
                U::RENDER_ATTACHMENT | U::COPY_SRC | U::TEXTURE_BINDING,
            ),
        }
    }
}
