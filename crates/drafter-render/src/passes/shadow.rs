//! Shadow pass: a drop shadow on a ground plane under the model (Gooch et al. 1999, §3.3, §5.3).
//!
//! # How it works
//! Illustrators draw only the shadow on the ground, never shadows on the object, so the shadow is
//! the model flattened onto the plane `y = ground` (just under the model's world bounds; world +y
//! is up, as in glTF) by a central projection from a point light. The light sits at
//! [`LIGHT_DISTANCE`] scene radii from the model's centre in the direction of the key light (made
//! at least [`MIN_LIGHT_ELEVATION`] steep so that the shadow falls under the model).
//!
//! Every mode is a list of *layers*, each the whole model projected once with a weight:
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
//! `hard` and `penumbra` draw their layers in screen space into the mask (a stencil lets each
//! layer cover a pixel once however many triangles overlap there). `soft` does what Gooch et al.
//! suggest to save the repeated projections: each plane's shadow, moved to the ground, is the
//! ground shadow scaled about the light's foot point `f` by `s_k = (L_y − h_k)/(L_y − g)` (the same
//! for every point, see [`soft_scales`]). So the model is drawn once, into a top-down map of the
//! ground ([`GROUND_MAP_SIZE`]² texels over the hard shadow's extent), and a full-screen resolve
//! intersects each pixel's camera ray with the ground at `x` and averages the map at
//! `f + (x − f)/s_k` over the planes: the cost no longer grows with triangles × planes.
//!
//! The mask is half resolution ([`crate::targets::SHADOW_REDUCTION`]): a drop shadow needs no
//! more. The display pass samples it with bilinear filtering, coloured, where the G-buffer shows
//! background only.
//!
//! # Limits
//! Points at or above the light's height cast no meaningful shadow (the light is far above any
//! model, so this does not happen with the default distance). The shadow is as seen from the
//! camera; looking from below the ground it shows through the plane.

use glam::{Mat4, Vec2, Vec3};

use crate::gpu_types::{MAX_SOFT_PLANES, ShadowLayerGpu, ShadowResolveGpu};
use crate::passes::{color_attachment, fullscreen_pipeline, texture_entry, uniform_entry};
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
/// Planes of a `soft` shadow (at most [`MAX_SOFT_PLANES`]).
pub const SOFT_LAYERS: usize = 12;
/// Side of the soft shadow's ground map, texels.
pub const GROUND_MAP_SIZE: u32 = 1024;
/// Format of the ground map (coverage 0 or 1, filtered when resolved).
pub const GROUND_MAP_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;
/// Depth of the stack of planes of a `soft` shadow below the ground, in model heights.
pub const SOFT_STACK_DEPTH: f32 = 0.3;
/// Most layers of any mode.
pub const MAX_LAYERS: usize = SOFT_LAYERS;
const _: () = assert!(SOFT_LAYERS <= MAX_SOFT_PLANES);

/// The layers of `mode` for a model with render-space bounds `min..max` lit from `light_dir`
/// (render space, towards the light).
pub fn layers(mode: ShadowMode, min: Vec3, max: Vec3, light_dir: Vec3) -> Vec<ShadowLayerGpu> {
    let radius = ((max - min).length() * 0.5).max(1e-12);
    let center = (min + max) * 0.5;
    let dir = steep(light_dir);
    let light = center + dir * (LIGHT_DISTANCE * radius);
    let ground = min.y - 1e-3 * radius;
    let layer = |position: Vec3, plane: f32, weight: f32| ShadowLayerGpu {
        clip_from_render: Mat4::IDENTITY.to_cols_array_2d(),
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

/// The scale about the light's foot point that takes the ground shadow (layer 0) to layer `k`'s
/// shadow moved to the ground: `(L_y − h_k) / (L_y − g)`.
pub fn soft_scales(layers: &[ShadowLayerGpu]) -> Vec<f32> {
    layers
        .iter()
        .map(|l| {
            let light_y = l.light_position[1];
            (light_y - l.plane[0]) / (light_y - l.plane[1]).max(1e-12)
        })
        .collect()
}

/// What the GPU draws for a shadow mode, for a camera with `clip_from_render` and a model whose
/// instance-box corners are `fit_points`.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowPlan {
    /// Screen-space layers (hard, penumbra) or the one ground-map layer (soft).
    pub layers: Vec<ShadowLayerGpu>,
    /// The soft shadow's resolve; `None` for screen-space layers.
    pub resolve: Option<ShadowResolveGpu>,
}

/// The plan of `layers` (from [`layers`]) for this camera: screen-space layers are given the camera's
/// clip transform; a soft stack becomes its ground layer drawn into a map over the hard shadow's
/// extent, plus the resolve's uniforms.
pub fn plan(
    mode: ShadowMode,
    layers: &[ShadowLayerGpu],
    clip_from_render: Mat4,
    fit_points: &[Vec3],
    mask_size: (u32, u32),
) -> ShadowPlan {
    let clip = clip_from_render.to_cols_array_2d();
    let (Some(ground_layer), ShadowMode::Soft) = (layers.first(), mode) else {
        let layers = layers.iter().map(|l| ShadowLayerGpu { clip_from_render: clip, ..*l }).collect();
        return ShadowPlan { layers, resolve: None };
    };
    // The map covers the hard shadow (and the model's footprint), with a margin of two texels.
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for &p in fit_points {
        for q in [project(ground_layer, p), Vec3::new(p.x, 0.0, p.z)] {
            lo = lo.min(Vec2::new(q.x, q.z));
            hi = hi.max(Vec2::new(q.x, q.z));
        }
    }
    if lo.x > hi.x {
        (lo, hi) = (Vec2::splat(-1.0), Vec2::splat(1.0));
    }
    let margin = (hi - lo).max(Vec2::splat(1e-6)) * (2.0 / GROUND_MAP_SIZE as f32);
    let (lo, size) = (lo - margin, (hi - lo) + 2.0 * margin);
    // Ground (x, z) → map clip space: u = (x − lo.x)/size.x → 2u − 1; v = (z − lo.y)/size.y → 1 − 2v.
    let map_from_render = Mat4::from_cols(
        glam::Vec4::new(2.0 / size.x, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 0.0, 0.0),
        glam::Vec4::new(0.0, -2.0 / size.y, 0.0, 0.0),
        glam::Vec4::new(-1.0 - 2.0 * lo.x / size.x, 1.0 + 2.0 * lo.y / size.y, 0.5, 1.0),
    );
    let map_layer = ShadowLayerGpu {
        clip_from_render: map_from_render.to_cols_array_2d(),
        plane: [ground_layer.plane[0], ground_layer.plane[1], 1.0, 0.0],
        ..*ground_layer
    };
    let mut inverse_scales = [[0.0f32; 4]; 4];
    let scales = soft_scales(layers);
    for (k, s) in scales.iter().take(MAX_SOFT_PLANES).enumerate() {
        inverse_scales[k / 4][k % 4] = 1.0 / s.max(1e-6);
    }
    let light = ground_layer.light_position;
    let resolve = ShadowResolveGpu {
        render_from_clip: clip_from_render.inverse().to_cols_array_2d(),
        map_rect: [lo.x, lo.y, size.x, size.y],
        foot_ground_count: [light[0], light[2], ground_layer.plane[1], scales.len().min(MAX_SOFT_PLANES) as f32],
        target_size: [mask_size.0 as f32, mask_size.1 as f32, 0.0, 0.0],
        inverse_scales,
    };
    ShadowPlan { layers: vec![map_layer], resolve: Some(resolve) }
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
    layout: wgpu::PipelineLayout,
    resolve_pipeline_layout: wgpu::PipelineLayout,
    /// Compiled by [`Self::ensure_pipelines`] when a frame first draws a shadow (the page's default
    /// is none: three pipeline links a first frame does not need).
    pipelines: Option<ShadowPipelines>,
    layers: wgpu::Buffer,
    layers_bind_group: wgpu::BindGroup,
    stride: u64,
    ground_map: crate::targets::Target,
    resolve_uniforms: wgpu::Buffer,
    resolve_bind_group: wgpu::BindGroup,
}

#[derive(Debug)]
struct ShadowPipelines {
    /// Screen-space layers into the mask (stencil: once per pixel, additive).
    pipeline: wgpu::RenderPipeline,
    /// The soft shadow's ground layer into the ground map.
    map_pipeline: wgpu::RenderPipeline,
    /// The soft shadow's full-screen resolve into the mask.
    resolve_pipeline: wgpu::RenderPipeline,
}

/// Each layer's stencil test: a pixel counts once per layer (the first fragment there increments).
const ONCE: wgpu::StencilFaceState = wgpu::StencilFaceState {
    compare: wgpu::CompareFunction::Equal,
    fail_op: wgpu::StencilOperation::Keep,
    depth_fail_op: wgpu::StencilOperation::Keep,
    pass_op: wgpu::StencilOperation::IncrementClamp,
};

/// The layers add up in the mask.
const ADDITIVE: wgpu::BlendState = wgpu::BlendState {
    color: wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    },
    alpha: wgpu::BlendComponent::REPLACE,
};

/// The layers' uniform buffer (one aligned slot per layer, bound at a dynamic offset) and its bind
/// group, with the slot stride.
fn layer_uniforms(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> (wgpu::Buffer, wgpu::BindGroup, u64) {
    let alignment = u64::from(device.limits().min_uniform_buffer_offset_alignment);
    let stride = (size_of::<ShadowLayerGpu>() as u64).div_ceil(alignment) * alignment;
    let layers = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("shadow layers"),
        size: stride * MAX_LAYERS as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("shadow layer bind group"),
        layout,
        entries: &[wgpu::BindGroupEntry {
            binding: 0,
            resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &layers,
                offset: 0,
                size: wgpu::BufferSize::new(size_of::<ShadowLayerGpu>() as u64),
            }),
        }],
    });
    (layers, bind_group, stride)
}

impl ShadowPass {
    pub fn new(device: &wgpu::Device) -> ShadowPass {
        use wgpu::ShaderStages as S;
        let layer_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow layer bind group layout"),
            entries: &[uniform_entry(0, S::VERTEX_FRAGMENT, true)],
        });
        let resolve_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("shadow resolve bind group layout"),
            entries: &[
                uniform_entry(0, S::FRAGMENT, false),
                texture_entry(1, wgpu::TextureSampleType::Float { filterable: true }),
                wgpu::BindGroupLayoutEntry {
                    binding: 2,
                    visibility: S::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow pipeline layout"),
            bind_group_layouts: &[Some(&layer_layout)],
            immediate_size: 0,
        });
        let resolve_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("shadow resolve pipeline layout"),
            bind_group_layouts: &[None, Some(&resolve_layout)],
            immediate_size: 0,
        });
        let (layers, layers_bind_group, stride) = layer_uniforms(device, &layer_layout);
        let ground_map = crate::targets::Target::new(
            device,
            "shadow ground map",
            (GROUND_MAP_SIZE, GROUND_MAP_SIZE),
            GROUND_MAP_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let resolve_uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shadow resolve uniforms"),
            size: size_of::<ShadowResolveGpu>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow ground map sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let resolve_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow resolve bind group"),
            layout: &resolve_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: resolve_uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&ground_map.view) },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&sampler) },
            ],
        });
        ShadowPass {
            layout,
            resolve_pipeline_layout,
            pipelines: None,
            layers,
            layers_bind_group,
            stride,
            ground_map,
            resolve_uniforms,
            resolve_bind_group,
        }
    }

    /// Uploads `plan` for the next [`Self::encode`].
    pub fn prepare(&self, queue: &wgpu::Queue, plan: &ShadowPlan) {
        for (k, layer) in plan.layers.iter().take(MAX_LAYERS).enumerate() {
            queue.write_buffer(&self.layers, k as u64 * self.stride, bytemuck::bytes_of(layer));
        }
        if let Some(resolve) = &plan.resolve {
            queue.write_buffer(&self.resolve_uniforms, 0, bytemuck::bytes_of(resolve));
        }
    }

    /// Compiles the pipelines the first time a frame draws a shadow.
    /// Whether this pass has compiled its pipelines (0 or 1).
    pub fn compiled(&self) -> usize {
        usize::from(self.pipelines.is_some())
    }

    pub fn ensure_pipelines(&mut self, device: &wgpu::Device) {
        if self.pipelines.is_some() {
            return;
        }
        let module =
            device.create_shader_module(super::shader_source!("shadow.wgsl", "shared.wgsl", "fullscreen.wgsl"));
        let layer_pipeline = |label: &str, format, blend, depth_stencil| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&self.layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &[
                        Some(crate::passes::gbuffer::vertex_layout()),
                        Some(crate::passes::gbuffer::instance_layout()),
                    ],
                },
                primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
                depth_stencil,
                multisample: wgpu::MultisampleState::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState { format, blend, write_mask: wgpu::ColorWrites::ALL })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let pipeline = layer_pipeline(
            "shadow layer pipeline",
            SHADOW_MASK_FORMAT,
            Some(ADDITIVE),
            Some(wgpu::DepthStencilState {
                format: SHADOW_STENCIL_FORMAT,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState { front: ONCE, back: ONCE, read_mask: 0xff, write_mask: 0xff },
                bias: wgpu::DepthBiasState::default(),
            }),
        );
        let map_pipeline = layer_pipeline("shadow ground map pipeline", GROUND_MAP_FORMAT, None, None);
        let resolve_pipeline = fullscreen_pipeline(
            device,
            "shadow resolve pipeline",
            &self.resolve_pipeline_layout,
            &module,
            "fs_resolve",
            SHADOW_MASK_FORMAT,
            None,
            &[],
        );

        self.pipelines = Some(ShadowPipelines { pipeline, map_pipeline, resolve_pipeline });
    }

    fn draw_batches(&self, pass: &mut wgpu::RenderPass<'_>, scene: &SceneGpu, layer: usize) {
        pass.set_bind_group(0, &self.layers_bind_group, &[(layer as u64 * self.stride) as u32]);
        pass.set_vertex_buffer(1, scene.instance_vertices.slice(..));
        for batch in &scene.batches {
            pass.set_vertex_buffer(0, batch.vertices.slice(..));
            pass.set_index_buffer(batch.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..batch.index_count, 0, batch.instances.clone());
        }
    }

    /// Writes the mask of `plan` (as prepared): screen-space layers one render pass each (stencil
    /// cleared), or the soft shadow's ground map and resolve.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, targets: &Targets, scene: &SceneGpu, plan: &ShadowPlan) {
        let Some(pipelines) = &self.pipelines else { return };
        encoder.push_debug_group(LABEL);
        if plan.resolve.is_some() {
            {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow ground map pass"),
                    color_attachments: &[color_attachment(&self.ground_map.view, Some(wgpu::Color::TRANSPARENT))],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&pipelines.map_pipeline);
                self.draw_batches(&mut pass, scene, 0);
            }
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow resolve pass"),
                color_attachments: &[color_attachment(&targets.shadow_mask.view, Some(wgpu::Color::TRANSPARENT))],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipelines.resolve_pipeline);
            pass.set_bind_group(1, &self.resolve_bind_group, &[]);
            pass.draw(0..3, 0..1);
        } else {
            for k in 0..plan.layers.len().min(MAX_LAYERS) {
                let clear = (k == 0).then_some(wgpu::Color::TRANSPARENT);
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("shadow layer pass"),
                    color_attachments: &[color_attachment(&targets.shadow_mask.view, clear)],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &targets.shadow_stencil.view,
                        depth_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(1.0),
                            store: wgpu::StoreOp::Discard,
                        }),
                        stencil_ops: Some(wgpu::Operations {
                            load: wgpu::LoadOp::Clear(0),
                            store: wgpu::StoreOp::Discard,
                        }),
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&pipelines.pipeline);
                pass.set_stencil_reference(0);
                self.draw_batches(&mut pass, scene, k);
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

    #[test]
    fn soft_planes_are_the_ground_shadow_scaled_about_the_foot_point() {
        let (min, max) = (Vec3::new(-1.0, -0.5, -1.0), Vec3::new(1.0, 0.5, 1.0));
        let ls = layers(ShadowMode::Soft, min, max, Vec3::new(0.3, 0.2, 0.4));
        let scales = soft_scales(&ls);
        assert_eq!(scales.len(), SOFT_LAYERS);
        assert!((scales[0] - 1.0).abs() < 1e-6 && scales.windows(2).all(|w| w[1] > w[0]));
        let foot = Vec3::new(ls[0].light_position[0], 0.0, ls[0].light_position[2]);
        for p in [Vec3::new(0.3, 0.4, -0.2), Vec3::new(-0.9, -0.1, 0.7), Vec3::new(1.0, 0.5, 1.0)] {
            let ground = project(&ls[0], p);
            for (l, s) in ls.iter().zip(&scales) {
                let want = project(l, p);
                let got = foot + (ground - foot) * *s;
                assert!(
                    (Vec3::new(got.x, 0.0, got.z) - Vec3::new(want.x, 0.0, want.z)).length() < 1e-4,
                    "{got} {want}"
                );
            }
        }
        // The plan draws one map layer and resolves every plane.
        let plan = plan(ShadowMode::Soft, &ls, Mat4::IDENTITY, &[min, max], (8, 8));
        assert_eq!(plan.layers.len(), 1);
        assert_eq!(plan.resolve.map(|r| r.foot_ground_count[3]), Some(SOFT_LAYERS as f32));
        let hard =
            super::plan(ShadowMode::Hard, &layers(ShadowMode::Hard, min, max, Vec3::Y), Mat4::IDENTITY, &[], (8, 8));
        assert!(hard.resolve.is_none() && hard.layers.len() == 1);
    }
}
