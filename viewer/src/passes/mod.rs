//! The render passes, in frame order (Lux et al. 2013, Algorithm 1, extended with Gooch et al.'s
//! drop shadow): [`gbuffer`] → [`shadow`] → [`enhance`] → [`display`] → [`lines`] (→ [`upscale`]
//! for an interactive frame). Each pass is one module with its WGSL beside it, owns its pipelines,
//! and records its work inside a debug group named after it.

pub mod display;
pub mod enhance;
pub mod gbuffer;
pub mod lines;
pub mod shadow;
pub mod upscale;

/// The WGSL of a pass: the shared files it names, then its own source. `shared.wgsl` holds what
/// every pass that draws the scene declares (the `Frame` and `Instance` structs, the tables);
/// `fullscreen.wgsl` the full-screen triangle of the image passes. So each is written once.
macro_rules! shader_source {
    ($file:literal $(, $shared:literal)*) => {
        wgpu::ShaderModuleDescriptor {
            label: Some($file),
            source: wgpu::ShaderSource::Wgsl(std::borrow::Cow::Borrowed(concat!(
                $(include_str!($shared), "\n",)*
                include_str!($file)
            ))),
        }
    };
}
pub(crate) use shader_source;

/// A bind group layout entry for a uniform buffer.
pub(crate) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages, dynamic: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: dynamic,
            min_binding_size: None,
        },
        count: None,
    }
}

/// A bind group layout entry for a 2D texture read in a fragment shader.
pub(crate) fn texture_entry(binding: u32, sample_type: wgpu::TextureSampleType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

/// A bind group layout entry for a filtering sampler in a fragment shader.
pub(crate) fn sampler_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::FRAGMENT,
        ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
        count: None,
    }
}

/// Filterable float texture (`texture_2d<f32>` read with a filtering sampler).
pub(crate) const FILTERABLE: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: true };
/// Unfilterable float texture (`texture_2d<f32>` read with `textureLoad`).
pub(crate) const FLOAT: wgpu::TextureSampleType = wgpu::TextureSampleType::Float { filterable: false };
/// Unsigned integer texture (`texture_2d<u32>`).
pub(crate) const UINT: wgpu::TextureSampleType = wgpu::TextureSampleType::Uint;

/// A colour attachment that clears to `clear` (or loads when `None`) and stores.
pub(crate) fn color_attachment(
    view: &wgpu::TextureView,
    clear: Option<wgpu::Color>,
) -> Option<wgpu::RenderPassColorAttachment<'_>> {
    Some(wgpu::RenderPassColorAttachment {
        view,
        depth_slice: None,
        resolve_target: None,
        ops: wgpu::Operations {
            load: clear.map_or(wgpu::LoadOp::Load, wgpu::LoadOp::Clear),
            store: wgpu::StoreOp::Store,
        },
    })
}

/// Pipeline state of a full-screen triangle (the `vs_fullscreen` entry point of a pass's WGSL),
/// with the fragment shader's pipeline constants (`override`s) set.
#[allow(clippy::too_many_arguments)]
pub(crate) fn fullscreen_pipeline(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    fragment_entry: &str,
    format: wgpu::TextureFormat,
    blend: Option<wgpu::BlendState>,
    constants: &[(&str, f64)],
) -> wgpu::RenderPipeline {
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_fullscreen"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: None,
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            targets: &[Some(wgpu::ColorTargetState { format, blend, write_mask: wgpu::ColorWrites::ALL })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

#[cfg(test)]
mod tests {
    /// Bytes of a WGSL struct of the shared file, from its members' types (the types it uses:
    /// `mat4x4<f32>`, `vec4<f32>`, `u32`; their uniform/storage layout needs no padding here).
    fn wgsl_struct_size(name: &str) -> usize {
        let source = include_str!("shared.wgsl");
        let start = source.find(&format!("struct {name} {{")).unwrap_or_else(|| panic!("struct {name} in shared.wgsl"));
        let body = &source[start..];
        let body = &body[body.find('{').unwrap_or(0) + 1..body.find('}').unwrap_or(0)];
        body.lines()
            .filter_map(|line| {
                line.split("//").next()?.split_once(':').map(|(_, t)| t.trim().trim_end_matches(',').to_string())
            })
            .map(|t| match t.as_str() {
                "mat4x4<f32>" => 64,
                "vec4<f32>" => 16,
                "u32" | "f32" => 4,
                other => panic!("{name}: member type {other} not known to this test"),
            })
            .sum()
    }

    #[test]
    fn the_shared_structs_match_the_rust_side() {
        assert_eq!(wgsl_struct_size("Frame"), std::mem::size_of::<crate::gpu_types::FrameUniforms>());
        assert_eq!(wgsl_struct_size("Instance"), std::mem::size_of::<crate::gpu_types::InstanceGpu>());
    }

    /// Each shared declaration exists once: no pass declares them again.
    #[test]
    fn no_pass_declares_the_shared_structs_again() {
        let passes = [
            ("gbuffer.wgsl", include_str!("gbuffer.wgsl")),
            ("lines.wgsl", include_str!("lines.wgsl")),
            ("shadow.wgsl", include_str!("shadow.wgsl")),
            ("display.wgsl", include_str!("display.wgsl")),
            ("enhance.wgsl", include_str!("enhance.wgsl")),
            ("upscale.wgsl", include_str!("upscale.wgsl")),
        ];
        for (file, source) in passes {
            for name in ["Frame", "Instance"] {
                assert!(
                    !source.contains(&format!("struct {name} {{")),
                    "{file} declares {name} again: use shared.wgsl"
                );
            }
            assert!(
                !source.contains("fn vs_fullscreen"),
                "{file} writes the full-screen triangle again: use fullscreen.wgsl"
            );
        }
    }
}
