//! Upscale pass: the last step of an interactive frame ([`crate::RenderOptions::interactive`]).
//!
//! # Why
//! On lavapipe nearly all of a frame's time is per pixel: a perf profile puts over 95 % of it in
//! the JIT-compiled shader and rasteriser code of llvmpipe (and before the G-buffer and display
//! pipelines were specialised, every style cost the same as Phong: the CPU ran every style's
//! code). So a frame drawn while the user drags is drawn with every pass at
//! 1/[`crate::RenderOptions::interactive_scale`] of the resolution in each direction (2 on a GPU,
//! 3 on a CPU rasteriser), then this pass filters it up to the output with one bilinear tap per
//! pixel. Still frames are drawn at full resolution as before.
//!
//! # Limits
//! The dragged image is softer and its one-pixel lines are drawn at the reduced resolution (so
//! `interactive_scale` times as wide after upscaling).

use crate::passes::{FILTERABLE, color_attachment, fullscreen_pipeline, sampler_entry, texture_entry};

pub const LABEL: &str = "upscale";

#[derive(Debug)]
pub struct UpscalePass {
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
    /// Compiled by [`Self::ensure_pipeline`] at the first interactive frame (a still view never
    /// needs it), its shader module with it.
    pipeline: Option<wgpu::RenderPipeline>,
    sampler: wgpu::Sampler,
}

impl UpscalePass {
    /// An upscale pass writing `format` (the display pass's).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> UpscalePass {
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("upscale bind group layout"),
            entries: &[texture_entry(0, FILTERABLE), sampler_entry(1)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("upscale pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("upscale sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            ..Default::default()
        });
        UpscalePass { layout, pipeline_layout, format, pipeline: None, sampler }
    }

    /// Compiles the pipeline the first time an interactive frame is drawn.
    /// How many pipelines this pass has compiled (0 or 1).
    pub fn compiled(&self) -> usize {
        usize::from(self.pipeline.is_some())
    }

    pub fn ensure_pipeline(&mut self, device: &wgpu::Device) {
        if self.pipeline.is_none() {
            let module = device.create_shader_module(super::shader_source!("upscale.wgsl", "fullscreen.wgsl"));
            self.pipeline = Some(fullscreen_pipeline(
                device,
                "upscale pipeline",
                &self.pipeline_layout,
                &module,
                "fs_main",
                self.format,
                None,
                &[],
            ));
        }
    }

    /// The bind group reading `source` (the reduced frame's display output).
    pub fn bind_group(&self, device: &wgpu::Device, source: &wgpu::TextureView) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("upscale bind group"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(source) },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&self.sampler) },
            ],
        })
    }

    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, bind_group: &wgpu::BindGroup, output: &wgpu::TextureView) {
        let Some(pipeline) = &self.pipeline else { return };
        encoder.push_debug_group(LABEL);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("upscale pass"),
                color_attachments: &[color_attachment(output, None)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
        encoder.pop_debug_group();
    }
}
