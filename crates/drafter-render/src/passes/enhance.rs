//! Enhancement pass (Lux et al. 2013, §5 "Enhancement Pass"; Algorithm 1, line 12): image-space
//! edges from discontinuities in part id, depth and normal (the [IFH03] edge enhancement) and an
//! unsharp mask of the depth buffer for depth cues (Luft, Colditz, Deussen 2006).
//!
//! # How it works
//! * **Unsharp mask** (this module): `ΔD = G∗D − D`, with `G∗D` a Gaussian of the linear depth
//!   (σ = [`BLUR_SIGMA_FRACTION`] of the image height), computed at quarter resolution by two
//!   full-screen draws of `fs_blur` (horizontal, reading every fourth depth texel with background
//!   pixels set just beyond the model, then vertical). Where `ΔD < 0` the pixel lies behind its
//!   surroundings and the display pass darkens it in proportion ([`UNSHARP_STRENGTH`]).
//! * **Edges** are detected where they are drawn, in the display pass (`display.wgsl`), from the
//!   G-buffer: an **outline** where the part id differs from a neighbour (on the nearer side;
//!   against the background on both sides, hence heavier, as Gooch et al. draw outer lines) or the
//!   depth jumps inside a part (second difference of the depth in the quantity that is affine on
//!   planes, 1/z or z, above [`DEPTH_EDGE_THRESHOLD`]); a **crease** where the normal turns by more
//!   than [`CREASE_ANGLE_DEG`] to the next pixel of the same part.
//!
//! Why edges are not a pass of their own, as in Lux et al.: on lavapipe (the CPU Vulkan device of
//! CI and headless use) a full-screen pass costs a large part of a Phong frame whatever its shader
//! does, so a separate edge pass (and a half-resolution blur) nearly doubled the gradient + edges
//! frame; the edges are computed in the display pass, which reads the same texels anyway, and the
//! blur runs at quarter resolution (`drafter bench render` measures the frames; docs/bench.md).
//! On a GPU either layout costs well under a millisecond.
//!
//! # Limits
//! Image-space lines are as wide as [`crate::RenderOptions::supersample`] pixels (before
//! down-sampling) and only as exact as the pixel grid; the lines pass will draw baked edges as
//! geometry when they are in the file.

use crate::gpu_types::EnhanceUniforms;
use crate::passes::{FLOAT, UINT, color_attachment, fullscreen_pipeline, texture_entry, uniform_entry};
use crate::targets::{BLUR_FORMAT, BLUR_REDUCTION, Targets};

pub const LABEL: &str = "enhance";

/// Normal angle counted as a crease (Gooch et al. draw creases sharper than about this).
pub const CREASE_ANGLE_DEG: f32 = 35.0;
/// Relative second difference of the affine depth that counts as a depth edge.
pub const DEPTH_EDGE_THRESHOLD: f32 = 0.02;
/// Gaussian σ of the depth unsharp mask, as a fraction of the target height.
pub const BLUR_SIGMA_FRACTION: f32 = 0.012;
/// Scale of the darkening per unit of `−ΔD / scene radius`.
pub const UNSHARP_STRENGTH: f32 = 6.0;

/// What the blur needs to know about the frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnhanceSetup {
    /// Target height in pixels.
    pub height: u32,
    /// A depth beyond every model point (view units).
    pub far_depth: f32,
}

#[derive(Debug)]
pub struct EnhancePass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    /// Compiled, with its shader module, by [`Self::ensure_pipeline`] at the first frame with the
    /// unsharp mask (a frame without image-space edges never needs it).
    blur: Option<wgpu::RenderPipeline>,
    uniforms: [wgpu::Buffer; 2],
}

/// Bind groups of one set of targets.
#[derive(Debug)]
pub struct EnhanceBindings {
    blur_h: wgpu::BindGroup,
    blur_v: wgpu::BindGroup,
}

impl EnhancePass {
    pub fn new(device: &wgpu::Device) -> EnhancePass {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("enhance bind group layout"),
            entries: &[
                uniform_entry(0, wgpu::ShaderStages::FRAGMENT, false),
                texture_entry(1, FLOAT),
                texture_entry(2, UINT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("enhance pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let uniform = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size_of::<EnhanceUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniforms = [uniform("enhance blur h uniforms"), uniform("enhance blur v uniforms")];
        EnhancePass { layout, pipeline_layout, blur: None, uniforms }
    }

    /// Compiles the blur the first time a frame draws the unsharp mask.
    /// How many pipelines this pass has compiled (0 or 1).
    pub fn compiled(&self) -> usize {
        usize::from(self.blur.is_some())
    }

    pub fn ensure_pipeline(&mut self, device: &wgpu::Device) {
        if self.blur.is_none() {
            let module = device.create_shader_module(super::shader_source!("enhance.wgsl", "fullscreen.wgsl"));
            self.blur = Some(fullscreen_pipeline(
                device,
                "enhance blur pipeline",
                &self.pipeline_layout,
                &module,
                "fs_blur",
                BLUR_FORMAT,
                None,
                &[],
            ));
        }
    }

    pub fn bindings(&self, device: &wgpu::Device, targets: &Targets) -> EnhanceBindings {
        let group = |label, uniforms: &wgpu::Buffer, depth: &wgpu::TextureView| {
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
                ],
            })
        };
        EnhanceBindings {
            blur_h: group("enhance blur h bind group", &self.uniforms[0], &targets.linear_depth.view),
            blur_v: group("enhance blur v bind group", &self.uniforms[1], &targets.blur_a.view),
        }
    }

    pub fn prepare(&self, queue: &wgpu::Queue, setup: &EnhanceSetup) {
        // In blur texels.
        let sigma = (BLUR_SIGMA_FRACTION * setup.height as f32 / BLUR_REDUCTION as f32).max(1.0);
        let radius = (3.0 * sigma).ceil();
        let h = EnhanceUniforms {
            blur: [1.0, 0.0, sigma, radius],
            far_depth: setup.far_depth,
            background_fill: 1.0,
            source_step: BLUR_REDUCTION as f32,
            _pad: 0.0,
        };
        let v = EnhanceUniforms { blur: [0.0, 1.0, sigma, radius], background_fill: 0.0, source_step: 1.0, ..h };
        queue.write_buffer(&self.uniforms[0], 0, bytemuck::bytes_of(&h));
        queue.write_buffer(&self.uniforms[1], 0, bytemuck::bytes_of(&v));
    }

    /// Blurs the linear depth into `targets.blur_b` (via `blur_a`).
    /// Records the blur; [`Self::ensure_pipeline`] must have run (the renderer's `prepare` does).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &Targets, bindings: &EnhanceBindings) {
        let Some(blur) = self.blur.as_ref() else {
            debug_assert!(false, "the blur is encoded before its pipeline was compiled");
            return;
        };
        encoder.push_debug_group(LABEL);
        let draws = [
            ("enhance blur h pass", &bindings.blur_h, &targets.blur_a.view),
            ("enhance blur v pass", &bindings.blur_v, &targets.blur_b.view),
        ];
        for (label, group, view) in draws {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[color_attachment(view, Some(wgpu::Color::TRANSPARENT))],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(blur);
            pass.set_bind_group(0, group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder.pop_debug_group();
    }
}
