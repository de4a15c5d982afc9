//! Display pass (Lux et al. 2013, §5 "Display Pass"; Algorithm 1, line 13): one full-screen draw that
//! detects the image-space edges (see [`crate::passes::enhance`] for the tests and why they run
//! here), darkens recesses by the depth unsharp mask, composites the G-buffer colour with black
//! outlines and crease lines, puts the coloured drop shadow on the background, and tints the
//! selected part.
//!
//! Colours are display values end to end (no sRGB conversion): the output is written to an
//! `Rgba8Unorm` texture (or a non-sRGB window surface) and saved as is.

use crate::gpu_types::{DISPLAY_CREASES, DISPLAY_OUTLINES, DISPLAY_SHADOW, DISPLAY_UNSHARP, DisplayUniforms};
use crate::passes::enhance::{CREASE_ANGLE_DEG, DEPTH_EDGE_THRESHOLD, UNSHARP_STRENGTH};
use crate::passes::{FLOAT, UINT, color_attachment, fullscreen_pipeline, texture_entry, uniform_entry};
use crate::style::{RenderOptions, ShadowMode, Style};
use crate::targets::Targets;

pub const LABEL: &str = "display";

/// Outline colour: black, as every convention draws silhouettes and part borders.
pub const LINE_COLOR: [f32; 4] = [0.0, 0.0, 0.0, 1.0];
/// Image-space creases (pixels where the G-buffer normal turns, found here) on the Gooch styles:
/// white (Gooch et al. 1999, §3.1, Fig. 9). Mixed into whole pixels with no coverage, so the alpha
/// is the line's only softening; the baked crease lines of the lines pass have their own colours
/// ([`crate::passes::lines::BAKED_CREASE_WHITE`]).
pub const IMAGE_SPACE_CREASE_WHITE: [f32; 4] = [1.0, 1.0, 1.0, 0.9];
/// Image-space creases on the other styles: dark grey, lighter than outlines ([IFH03]-style edge
/// enhancement).
pub const IMAGE_SPACE_CREASE_DARK: [f32; 4] = [0.1, 0.1, 0.1, 0.6];
/// Selection tint (orange, 45 %).
pub const HIGHLIGHT_COLOR: [f32; 4] = [1.0, 0.55, 0.1, 0.45];

/// The display uniforms of `options`, for a scene of `scene_radius` (view units) seen through an
/// orthographic camera or not.
pub fn uniforms(options: &RenderOptions, scene_radius: f32, orthographic: bool) -> DisplayUniforms {
    let e = options.drawn_enhancements();
    let mut flags = 0;
    if e.outlines {
        flags |= DISPLAY_OUTLINES;
    }
    if e.creases {
        flags |= DISPLAY_CREASES;
    }
    if e.unsharp_mask {
        flags |= DISPLAY_UNSHARP;
    }
    if options.shadow != ShadowMode::None {
        flags |= DISPLAY_SHADOW;
    }
    let gooch = matches!(options.style, Style::Gooch | Style::Goochel | Style::Metal);
    DisplayUniforms {
        background: [options.background[0], options.background[1], options.background[2], 1.0],
        shadow_color: [options.shadow_color[0], options.shadow_color[1], options.shadow_color[2], 1.0],
        line_color: LINE_COLOR,
        crease_color: if gooch { IMAGE_SPACE_CREASE_WHITE } else { IMAGE_SPACE_CREASE_DARK },
        highlight_color: HIGHLIGHT_COLOR,
        selected: options.selected_part.map_or(0, |p| p.saturating_add(1)),
        flags,
        _pad: [0; 2],
        depth_threshold: DEPTH_EDGE_THRESHOLD,
        crease_cos: CREASE_ANGLE_DEG.to_radians().cos(),
        line_radius: options.line_pixel_scale().max(1.0),
        unsharp_strength: UNSHARP_STRENGTH,
        ortho: if orthographic { 1.0 } else { 0.0 },
        scene_radius: scene_radius.max(1e-12),
        _pad2: [0.0; 2],
    }
}

#[derive(Debug)]
pub struct DisplayPass {
    layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
    /// The pipelines compiled so far, by their `FLAGS` constant: each frame draws with the one
    /// that has exactly its flags (see `display.wgsl`; the G-buffer pass's docs say why).
    pipelines: std::collections::BTreeMap<u32, wgpu::RenderPipeline>,
    flags: u32,
    uniforms: wgpu::Buffer,
    sampler: wgpu::Sampler,
}

impl DisplayPass {
    /// A display pass writing `format` (the output texture's, or a window surface's).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> DisplayPass {
        let module = device.create_shader_module(super::shader_source!("display.wgsl", "fullscreen.wgsl"));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("display bind group layout"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT, false),
                texture_entry(1, FLOAT),
                texture_entry(2, UINT),
                texture_entry(3, FLOAT),
                texture_entry(4, FLOAT),
                texture_entry(5, FLOAT),
                texture_entry(6, wgpu::TextureSampleType::Float { filterable: true }),
                wgpu::BindGroupLayoutEntry {
                    binding: 7,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("display uniforms"),
            size: size_of::<DisplayUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("display linear sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        // No pipeline yet: [`Self::prepare`] compiles the one a frame's flags ask for (as the
        // G-buffer pass does).
        DisplayPass {
            layout,
            module,
            pipeline_layout,
            format,
            pipelines: std::collections::BTreeMap::new(),
            flags: 0,
            uniforms,
            sampler,
        }
    }

    /// Compiles (once) and selects the pipeline for `flags`.
    fn specialise(&mut self, device: &wgpu::Device, flags: u32) {
        self.flags = flags;
        self.compile(device, flags);
    }

    /// How many pipelines this pass has compiled.
    pub fn compiled(&self) -> usize {
        self.pipelines.len()
    }

    /// Compiles the pipeline for `flags` if it is not yet, without selecting it.
    pub fn compile(&mut self, device: &wgpu::Device, flags: u32) {
        self.pipelines.entry(flags).or_insert_with(|| {
            fullscreen_pipeline(
                device,
                "display pipeline",
                &self.pipeline_layout,
                &self.module,
                "fs_main",
                self.format,
                None,
                &[("FLAGS", f64::from(flags))],
            )
        });
    }

    pub fn bind_group(&self, device: &wgpu::Device, targets: &Targets) -> wgpu::BindGroup {
        fn view(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("display bind group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.uniforms.as_entire_binding() },
                view(1, &targets.color.view),
                view(2, &targets.part_id.view),
                view(3, &targets.normal.view),
                view(4, &targets.linear_depth.view),
                view(5, &targets.blur_b.view),
                view(6, &targets.shadow_mask.view),
                wgpu::BindGroupEntry { binding: 7, resource: wgpu::BindingResource::Sampler(&self.sampler) },
            ],
        })
    }

    pub fn prepare(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, uniforms: &DisplayUniforms) {
        self.specialise(device, uniforms.flags);
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
    }

    /// Composites into `output` (same size as the targets).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, bind_group: &wgpu::BindGroup, output: &wgpu::TextureView) {
        encoder.push_debug_group(LABEL);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("display pass"),
                color_attachments: &[color_attachment(output, Some(wgpu::Color::WHITE))],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let Some(pipeline) = self.pipelines.get(&self.flags) else { return };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder.pop_debug_group();
    }
}
