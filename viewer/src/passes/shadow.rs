//! Shadow pass: a drop shadow on a ground plane under the model (Gooch et al. 1999, §3.3, §5.3).
//!
//! # How it works
//! Illustrators draw only the shadow on the ground, never shadows on the object, so the shadow is
//! the model flattened onto the plane `y = ground` (just under the model's world bounds; world +y
//! is up, as in glTF) by a central projection from a point light. The light sits at
//! [`LIGHT_DISTANCE`] scene radii from the model's centre in the direction of the key light (made
//! at least [`MIN_LIGHT_ELEVATION`] steep so that the shadow falls under the model).
//!
//! Every mode is a list of *layers*, each the whole model projected once and added to a coverage
//! mask with a weight; a stencil lets every layer cover a pixel once however many triangles
//! overlap there:
//! * `hard`: one layer from the light's centre, weight 1;
//! * `penumbra`: a spherical light of radius [`LIGHT_RADIUS`] (scene radii) approximated by two hard
//!   shadows, from the back and from the front of the sphere along the light direction, weight ½
//!   each: the nearer point casts the larger shadow, so pixels in both are umbra (1) and pixels in
//!   one are penumbra (½);
//! * `soft`: the shadow projected onto a stack of [`SOFT_LAYERS`] planes at and below the ground
//!   and each moved up to the ground, weight 1/n each (Gooch's "stack of planes"). Only planes at
//!   and below the receiver are used, the variant Gooch recommends when the object touches the
//!   ground: no shadow spills over the contact.
//!
//! The display pass composites the mask (coloured) where the G-buffer shows background only.
//!
//! # Limits
//! Points at or above the light's height cast no meaningful shadow (the light is far above any
//! model, so this does not happen with the default distance). The shadow is as seen from the
//! camera; looking from below the ground it shows through the plane.

use glam::Vec3;

use crate::gpu_types::ShadowLayerGpu;
use crate::passes::{color_attachment, storage_entry, uniform_entry};
use crate::scene::SceneGpu;
use crate::style::ShadowMode;
use crate::targets::{SHADOW_MASK_FORMAT, SHADOW_STENCIL_FORMAT, Targets};

pub const LABEL: &str = "shadow";

/// Distance of the light's centre from the model's centre, in scene radii (half the bounds'
/// diagonal).
pub const LIGHT_DISTANCE: f32 = 4.0;
/// Radius of the spherical light of `penumbra` and `soft`, in scene radii.
pub const LIGHT_RADIUS: f32 = 0.8;
/// Smallest sine of the light's elevation above the ground.
pub const MIN_LIGHT_ELEVATION: f32 = 0.9;
/// Planes of a `soft` shadow.
pub const SOFT_LAYERS: usize = 8;
/// Depth of the stack of planes of a `soft` shadow below the ground, in model heights.
pub const SOFT_STACK_DEPTH: f32 = 0.4;
/// Most layers of any mode.
pub const MAX_LAYERS: usize = SOFT_LAYERS;

/// The layers of `mode` for a model with render-space bounds `min..max` lit from `light_dir`
/// (render space, towards the light).
pub fn layers(mode: ShadowMode, min: Vec3, max: Vec3, light_dir: Vec3) -> Vec<ShadowLayerGpu> {
    let radius = ((max - min).length() * 0.5).max(1e-12);
    let center = (min + max) * 0.5;
    let dir = steep(light_dir);
    let light = center + dir * (LIGHT_DISTANCE * radius);
    let ground = min.y - 1e-3 * radius;
    let layer = |position: Vec3, plane: f32, weight: f32| ShadowLayerGpu {
        light_position: position.extend(1.0).to_array(),
        plane: [plane, ground, weight, 0.0],
    };
    match mode {
        ShadowMode::None => Vec::new(),
        ShadowMode::Hard => vec![layer(light, ground, 1.0)],
        ShadowMode::Penumbra => {
            let r = LIGHT_RADIUS * radius;
            vec![layer(light - dir * r, ground, 0.5), layer(light + dir * r, ground, 0.5)]
        }
        ShadowMode::Soft => {
            let height = (max.y - min.y).max(1e-3 * radius);
            let step = SOFT_STACK_DEPTH * height / SOFT_LAYERS as f32;
            (0..SOFT_LAYERS).map(|k| layer(light, ground - step * k as f32, 1.0 / SOFT_LAYERS as f32)).collect()
        }
    }
}

/// Where `layer` puts render-space point `p` on the ground (as the vertex shader does).
pub fn project(layer: &ShadowLayerGpu, p: Vec3) -> Vec3 {
    let light = Vec3::from_slice(&layer.light_position[..3]);
    let h = layer.plane[0];
    let drop = (light.y - p.y).max(1e-6 * (light.y - h).abs().max(1e-12));
    let mut q = light + (p - light) * ((light.y - h) / drop);
    q.y = layer.plane[1];
    q
}

/// `light_dir` turned up, if needed, to at least [`MIN_LIGHT_ELEVATION`].
fn steep(light_dir: Vec3) -> Vec3 {
    let d = light_dir.normalize_or(Vec3::Y);
    if d.y >= MIN_LIGHT_ELEVATION {
        return d;
    }
    let horizontal = Vec3::new(d.x, 0.0, d.z).normalize_or(Vec3::X);
    horizontal * (1.0 - MIN_LIGHT_ELEVATION * MIN_LIGHT_ELEVATION).sqrt() + Vec3::Y * MIN_LIGHT_ELEVATION
}

#[derive(Debug)]
pub struct ShadowPass {
    scene_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    layers: wgpu::Buffer,
    layers_bind_group: wgpu::BindGroup,
    stride: u64,
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device) -> ShadowPass {
        use wgpu::ShaderStages as S;
        let module = device.create_shader_module(wgpu::include_wgsl!("shadow.wgsl"));
        let scene_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow scene bind group layout"),
            entries: &[uniform_entry(0, S::VERTEX, false), storage_entry(1, S::VERTEX)],
        });
        let layer_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow layer bind group layout"),
            entries: &[uniform_entry(0, S::VERTEX_FRAGMENT, true)],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow pipeline layout"),
            bind_group_layouts: &[Some(&scene_layout), Some(&layer_layout)],
            immediate_size: 0,
        });
        let once = wgpu::StencilFaceState {
            compare: wgpu::CompareFunction::Equal,
            fail_op: wgpu::StencilOperation::Keep,
            depth_fail_op: wgpu::StencilOperation::Keep,
            pass_op: wgpu::StencilOperation::IncrementClamp,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("shadow pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(crate::passes::gbuffer::vertex_layout())],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: SHADOW_STENCIL_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState { front: once, back: once, read_mask: 0xff, write_mask: 0xff },
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: SHADOW_MASK_FORMAT,
                    blend: Some(wgpu::BlendState {
                        color: wgpu::BlendComponent {
                            src_factor: wgpu::BlendFactor::One,
                            dst_factor: wgpu::BlendFactor::One,
                            operation: wgpu::BlendOperation::Add,
                        },
                        alpha: wgpu::BlendComponent::REPLACE,
                    }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let alignment = u64::from(device.limits().min_uniform_buffer_offset_alignment);
        let stride = (size_of::<ShadowLayerGpu>() as u64).div_ceil(alignment) * alignment;
        let layers = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow layers"),
            size: stride * MAX_LAYERS as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layers_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow layer bind group"),
            layout: &layer_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &layers,
                    offset: 0,
                    size: wgpu::BufferSize::new(size_of::<ShadowLayerGpu>() as u64),
                }),
            }],
        });
        ShadowPass { scene_layout, pipeline, layers, layers_bind_group, stride }
    }

    /// The bind group of a scene: frame uniforms and instances.
    pub fn scene_bind_group(
        &self,
        device: &wgpu::Device,
        frame: &wgpu::Buffer,
        scene: &crate::scene::SceneBuffers,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow scene bind group"),
            layout: &self.scene_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: frame.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.instances.as_entire_binding() },
            ],
        })
    }

    /// Uploads `layers` (at most [`MAX_LAYERS`]) for the next [`Self::encode`].
    pub fn prepare(&self, queue: &wgpu::Queue, layers: &[ShadowLayerGpu]) {
        for (k, layer) in layers.iter().take(MAX_LAYERS).enumerate() {
            queue.write_buffer(&self.layers, k as u64 * self.stride, bytemuck::bytes_of(layer));
        }
    }

    /// Clears the mask, then accumulates each layer (one render pass per layer, stencil cleared).
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &Targets, scene: &SceneGpu, layer_count: usize) {
        encoder.push_debug_group(LABEL);
        for k in 0..layer_count.clamp(1, MAX_LAYERS) {
            let clear = (k == 0).then_some(wgpu::Color::TRANSPARENT);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow layer pass"),
                color_attachments: &[color_attachment(&targets.shadow_mask.view, clear)],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.shadow_stencil.view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
                    stencil_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0), store: wgpu::StoreOp::Discard }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if layer_count == 0 {
                break; // mode `none`: the mask is only cleared
            }
            pass.set_pipeline(&self.pipeline);
            pass.set_stencil_reference(0);
            pass.set_bind_group(0, &scene.shadow_bind_group, &[]);
            pass.set_bind_group(1, &self.layers_bind_group, &[(k as u64 * self.stride) as u32]);
            for batch in &scene.batches {
                pass.set_vertex_buffer(0, batch.vertices.slice(..));
                pass.set_index_buffer(batch.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..batch.index_count, 0, batch.instances.clone());
            }
        }
        encoder.pop_debug_group();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_fall_on_the_ground_under_the_light() {
        let (min, max) = (Vec3::new(-1.0, -0.5, -1.0), Vec3::new(1.0, 0.5, 1.0));
        for mode in [ShadowMode::Hard, ShadowMode::Penumbra, ShadowMode::Soft] {
            let ls = layers(mode, min, max, Vec3::new(0.3, 0.2, 0.4));
            assert!(!ls.is_empty() && ls.len() <= MAX_LAYERS);
            let total: f32 = ls.iter().map(|l| l.plane[2]).sum();
            assert!((total - 1.0).abs() < 1e-5, "{mode:?}: weights sum to {total}");
            for l in &ls {
                // A point on the ground projects onto itself (moved by at most the stack's offset).
                let q = project(l, Vec3::new(0.2, l.plane[0], 0.1));
                assert!((q - Vec3::new(0.2, l.plane[1], 0.1)).length() < 1e-4, "{q}");
                assert!(l.light_position[1] > max.y * 2.0);
            }
        }
        // The nearer penumbra light casts the larger shadow.
        let ls = layers(ShadowMode::Penumbra, min, max, Vec3::Y);
        let top = Vec3::new(1.0, 0.5, 0.0);
        assert!(project(&ls[0], top).x > project(&ls[1], top).x);
        assert!(layers(ShadowMode::None, min, max, Vec3::Y).is_empty());
    }
}
