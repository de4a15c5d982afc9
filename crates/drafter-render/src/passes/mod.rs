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
/// `fullscreen.wgsl` the full-screen triangle of the image passes. So each is written once. The
/// sources embedded are build.rs's copies without comments (same lines).
macro_rules! shader_source {
    ($file:literal $(, $shared:literal)*) => {
        wgpu::ShaderModuleDescriptor {
            label: Some($file),
            source: wgpu::ShaderSource::Wgsl(std::borrow::Cow::Borrowed(concat!(
                $(include_str!(concat!(env!("OUT_DIR"), "/", $shared)), "\n",)*
                include_str!(concat!(env!("OUT_DIR"), "/", $file))
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
    use std::collections::BTreeMap;

    /// Every WGSL file of the passes, as the shaders are assembled from them.
    const WGSL: [(&str, &str); 8] = [
        ("shared.wgsl", include_str!("shared.wgsl")),
        ("fullscreen.wgsl", include_str!("fullscreen.wgsl")),
        ("gbuffer.wgsl", include_str!("gbuffer.wgsl")),
        ("lines.wgsl", include_str!("lines.wgsl")),
        ("shadow.wgsl", include_str!("shadow.wgsl")),
        ("display.wgsl", include_str!("display.wgsl")),
        ("enhance.wgsl", include_str!("enhance.wgsl")),
        ("upscale.wgsl", include_str!("upscale.wgsl")),
    ];

    /// WGSL constants with nothing on the Rust side to agree with.
    const WGSL_ONLY: [&str; 3] = ["PI", "SELECTED_TINT", "REFERENCE_TINT"];

    /// The module-scope `const` and `override` declarations of every file: name → (file, value).
    fn wgsl_constants() -> BTreeMap<&'static str, (&'static str, &'static str)> {
        let mut found = BTreeMap::new();
        for (file, source) in WGSL {
            for line in source.lines() {
                let Some(rest) = line.strip_prefix("const ").or_else(|| line.strip_prefix("override ")) else {
                    continue;
                };
                let (name, rest) = rest.split_once(':').unwrap_or_else(|| panic!("{file}: {line}"));
                let (_, value) = rest.split_once('=').unwrap_or_else(|| panic!("{file}: {line} has no value"));
                let value = value.split("//").next().unwrap_or("").trim().trim_end_matches(';').trim();
                if let Some((other, _)) = found.insert(name.trim(), (file, value)) {
                    panic!("{} is declared in both {other} and {file}", name.trim());
                }
            }
        }
        found
    }

    /// A WGSL `u32` literal: decimal or hexadecimal, with its `u` suffix.
    fn wgsl_u32(value: &str) -> u32 {
        let digits = value.strip_suffix('u').unwrap_or_else(|| panic!("{value} is not a u32 literal"));
        match digits.strip_prefix("0x") {
            Some(hex) => u32::from_str_radix(hex, 16),
            None => digits.parse(),
        }
        .unwrap_or_else(|e| panic!("{value}: {e}"))
    }

    /// The shaders restate the Rust side's flags, codes and sizes, which they cannot import: each
    /// must equal its Rust constant, and every constant a shader declares must be here or in
    /// [`WGSL_ONLY`], so a new one cannot be added unchecked.
    #[test]
    fn the_shaders_constants_are_the_rust_values() {
        use crate::gpu_types as g;
        use crate::style::{Style, shader_index};
        let display_flags = [
            ("DISPLAY_OUTLINES", g::DISPLAY_OUTLINES),
            ("DISPLAY_CREASES", g::DISPLAY_CREASES),
            ("DISPLAY_UNSHARP", g::DISPLAY_UNSHARP),
            ("DISPLAY_SHADOW", g::DISPLAY_SHADOW),
        ];
        let mut expected: Vec<(String, u32)> = display_flags.iter().map(|&(n, v)| (n.to_string(), v)).collect();
        expected.extend(
            [
                // The default pipeline constants: every display flag, every style.
                ("FLAGS", display_flags.iter().fold(0, |all, &(_, flag)| all | flag)),
                ("STYLES", super::gbuffer::ALL_STYLES),
                ("PART_SELECTED", g::PART_SELECTED),
                ("PART_REFERENCE", g::PART_REFERENCE),
                ("NO_STYLE", g::NO_STYLE),
                ("FLAG_CEL_SPECULAR", g::FLAG_CEL_SPECULAR),
                ("FLAG_SPLASH_BACK", g::FLAG_SPLASH_BACK),
                ("LOOKUP_CEL", g::LOOKUP_CEL),
                ("LOOKUP_COOL_TO_WARM", g::LOOKUP_COOL_TO_WARM),
                ("LOOKUP_HATCH", g::LOOKUP_HATCH),
                ("LOOKUP_METAL", g::LOOKUP_METAL),
                ("LOOKUP_CEL_SPECULAR", g::LOOKUP_CEL_SPECULAR),
                ("LOOKUP_COOL_TO_WARM_FACTORED", g::LOOKUP_COOL_TO_WARM_FACTORED),
                ("LOOKUP_COOL_TO_WARM_SPLASH", g::LOOKUP_COOL_TO_WARM_SPLASH),
                ("LOOKUP_COOL_TO_WARM_SPHERE", g::LOOKUP_COOL_TO_WARM_SPHERE),
                ("LOOKUP_METAL_SPHERE", g::LOOKUP_METAL_SPHERE),
                ("CLASS_CREASE", crate::edges::LineClass::Crease.gpu_kind()),
                ("TABLE_WIDTH", crate::table::TABLE_WIDTH),
            ]
            .map(|(n, v)| (n.to_string(), v)),
        );
        expected.extend(Style::ALL.map(|s| (format!("STYLE_{}", s.name().to_uppercase()), shader_index(s))));

        let mut declared = wgsl_constants();
        for (name, value) in &expected {
            let (file, literal) =
                declared.remove(name.as_str()).unwrap_or_else(|| panic!("no shader declares {name} (= {value})"));
            assert_eq!(wgsl_u32(literal), *value, "{file}: {name} = {literal}, the Rust side has {value}");
        }
        let (file, literal) = declared.remove("CONTOUR_DEPTH_JUMP").expect("lines.wgsl declares CONTOUR_DEPTH_JUMP");
        assert_eq!(literal.parse::<f32>().ok(), Some(super::lines::CONTOUR_DEPTH_JUMP), "{file}: CONTOUR_DEPTH_JUMP");
        for name in WGSL_ONLY {
            assert!(declared.remove(name).is_some(), "no shader declares {name}: drop it from WGSL_ONLY");
        }
        assert!(
            declared.is_empty(),
            "shader constants this test does not know: {declared:?}; check each against its Rust value here, or \
             list it in WGSL_ONLY"
        );
    }

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
        let passes = WGSL.into_iter().filter(|(file, _)| !["shared.wgsl", "fullscreen.wgsl"].contains(file));
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
