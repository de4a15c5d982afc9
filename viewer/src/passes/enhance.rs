//! Enhancement pass (Lux et al. 2013, §5 "Enhancement Pass"; Algorithm 1, line 12): image-space
//! edges from discontinuities in part id, depth and normal (the [IFH03] edge enhancement) and an
//! unsharp mask of the depth buffer for depth cues (Luft, Colditz, Deussen 2006).
//!
//! # How it works
//! Three full-screen draws over the G-buffer:
//! 1. `fs_blur` horizontally, then 2. vertically: a separable Gaussian of the linear depth
//!    (σ = [`BLUR_SIGMA_FRACTION`] of the image height, every second tap), background pixels filled
//!    with a depth just beyond the model;
//! 3. `fs_edges` writes, per pixel: **outline** (part id differs from a neighbour — drawn on the
//!    nearer side; against the background on both sides, hence heavier, as Gooch et al. draw
//!    outer lines; plus depth jumps inside a part, found by the second difference of the depth in
//!    the quantity that is affine on planes, 1/z or z), **crease** (the normal turns by more than
//!    [`CREASE_ANGLE_DEG`] to the next pixel of the same part) and **darkening** (`−ΔD` where the
//!    unsharp mask `ΔD = G∗D − D` is negative, i.e. the pixel lies behind its surroundings).
//!
//! The display pass turns these into black outlines, crease lines and darker recesses.
//!
//! # Limits
//! Image-space lines are as wide as [`crate::RenderOptions::supersample`] pixels (before
//! down-sampling) and only as exact as the pixel grid; the lines pass will draw baked edges as
//! geometry when they are in the file.

use crate::gpu_types::EnhanceUniforms;
use crate::passes::{FLOAT, UINT, color_attachment, fullscreen_pipeline, texture_entry, uniform_entry};
use crate::targets::{BLUR_FORMAT, ENHANCE_FORMAT, Targets};

pub const LABEL: &str = "enhance";

/// Normal angle counted as a crease (Gooch et al. draw creases sharper than about this).
pub const CREASE_ANGLE_DEG: f32 = 35.0;
/// Relative second difference of the affine depth that counts as a depth edge.
pub const DEPTH_EDGE_THRESHOLD: f32 = 0.02;
/// Gaussian σ of the depth unsharp mask, as a fraction of the target height.
pub const BLUR_SIGMA_FRACTION: f32 = 0.012;
/// Scale of the darkening per unit of `−ΔD / scene radius`.
pub const UNSHARP_STRENGTH: f32 = 6.0;

/// What the edge pass needs to know about the camera and scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnhanceSetup {
    /// Target height in pixels.
    pub height: u32,
    /// Pixels per output pixel (the supersampling factor): the line radius.
    pub pixel_scale: f32,
    /// A depth beyond every model point (view units).
    pub far_depth: f32,
    /// Scene radius (view units).
    pub scene_radius: f32,
    pub orthographic: bool,
}

#[derive(Debug)]
pub struct EnhancePass {
    layout: wgpu::BindGroupLayout,
    blur: wgpu::RenderPipeline,
    edges: wgpu::RenderPipeline,
    uniforms: [wgpu::Buffer; 3],
}

/// Bind groups of one set of targets.
#[derive(Debug)]
pub struct EnhanceBindings {
    blur_h: wgpu::BindGroup,
    blur_v: wgpu::BindGroup,
    edges: wgpu::BindGroup,
}

impl EnhancePass {
    pub fn new(device: &wgpu::Device) -> EnhancePass {
        let module = device.create_shader_module(wgpu::include_wgsl!("enhance.wgsl"));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("enhance bind group layout"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT, false),
                texture_entry(1, FLOAT),
                texture_entry(2, UINT),
                texture_entry(3, FLOAT),
                texture_entry(4, FLOAT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("enhance pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let blur = fullscreen_pipeline(
            device,
            "enhance blur pipeline",
            &pipeline_layout,
            &module,
            "fs_blur",
            BLUR_FORMAT,
            None,
        );
        let edges = fullscreen_pipeline(
            device,
            "enhance edges pipeline",
            &pipeline_layout,
            &module,
            "fs_edges",
            ENHANCE_FORMAT,
            None,
        );
        let uniform = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size_of::<EnhanceUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniforms =
            [uniform("enhance blur h uniforms"), uniform("enhance blur v uniforms"), uniform("enhance edges uniforms")];
        EnhancePass { layout, blur, edges, uniforms }
    }

    pub fn bindings(&self, device: &wgpu::Device, targets: &Targets) -> EnhanceBindings {
        let group = |label, uniforms: &wgpu::Buffer, depth: &wgpu::TextureView, blurred: &wgpu::TextureView| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(label),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(depth) },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: wgpu::BindingResource::TextureView(&targets.part_id.view),
                    },
                    wgpu::BindGroupEntry {
                        binding: 3,
                        resource: wgpu::BindingResource::TextureView(&targets.normal.view),
                    },
                    wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(blurred) },
                ],
            })
        };
        EnhanceBindings {
            // Binding 4 is unused by the blur; any texture the draw does not write will do.
            blur_h: group(
                "enhance blur h bind group",
                &self.uniforms[0],
                &targets.linear_depth.view,
                &targets.blur_b.view,
            ),
            blur_v: group(
                "enhance blur v bind group",
                &self.uniforms[1],
                &targets.blur_a.view,
                &targets.linear_depth.view,
            ),
            edges: group(
                "enhance edges bind group",
                &self.uniforms[2],
                &targets.linear_depth.view,
                &targets.blur_b.view,
            ),
        }
    }

    pub fn prepare(&self, queue: &wgpu::Queue, setup: &EnhanceSetup) {
        let sigma = (BLUR_SIGMA_FRACTION * setup.height as f32).max(1.0);
        let base = EnhanceUniforms {
            blur: [0.0, 0.0, sigma, (3.0 * sigma).ceil()],
            far_depth: setup.far_depth,
            depth_threshold: DEPTH_EDGE_THRESHOLD,
            crease_cos: CREASE_ANGLE_DEG.to_radians().cos(),
            line_radius: setup.pixel_scale.max(1.0),
            unsharp_strength: UNSHARP_STRENGTH,
            ortho: if setup.orthographic { 1.0 } else { 0.0 },
            scene_radius: setup.scene_radius.max(1e-12),
            background_fill: 0.0,
        };
        let h = EnhanceUniforms { blur: [1.0, 0.0, base.blur[2], base.blur[3]], background_fill: 1.0, ..base };
        let v = EnhanceUniforms { blur: [0.0, 1.0, base.blur[2], base.blur[3]], ..base };
        queue.write_buffer(&self.uniforms[0], 0, bytemuck::bytes_of(&h));
        queue.write_buffer(&self.uniforms[1], 0, bytemuck::bytes_of(&v));
        queue.write_buffer(&self.uniforms[2], 0, bytemuck::bytes_of(&base));
    }

    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &Targets, bindings: &EnhanceBindings) {
        encoder.push_debug_group(LABEL);
        let draws = [
            ("enhance blur h pass", &self.blur, &bindings.blur_h, &targets.blur_a.view),
            ("enhance blur v pass", &self.blur, &bindings.blur_v, &targets.blur_b.view),
            ("enhance edges pass", &self.edges, &bindings.edges, &targets.enhance.view),
        ];
        for (label, pipeline, group, view) in draws {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[color_attachment(view, Some(wgpu::Color::TRANSPARENT))],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder.pop_debug_group();
    }
}
