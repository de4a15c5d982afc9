//! G-buffer pass (Lux et al. 2013, §5 "G-Buffer Generation Pass"; Algorithm 1, lines 1–11).
//!
//! # How it works
//! Every mesh is drawn **once**, instanced over all its placements: the vertex shader reads the
//! instance's transform from a storage buffer, maps the vertex's part label through the
//! instance's slice of `label_to_part` to a scene-wide part id, and the fragment shader fetches that
//! part's projector, gradient parameters and style from the part table. Algorithm 1 sets uniforms
//! per object; doing it through a storage buffer instead keeps the frame time independent of the
//! number of parts.
//!
//! The fragment shader writes four targets in one pass (multiple render targets): shaded colour,
//! view-space normal, linear view depth and part id + 1 (0 = background), which the enhancement
//! and display passes read.
//!
//! # Styles (see `gbuffer.wgsl`)
//! `gradient` (projective texturing with ω(i, q, f, p) and the γ table), `phong`, `cel` (2–4 steps,
//! optional specular band), `gooch` (cool-to-warm, optional splash-back), `goochel`, `metal` (Gooch
//! metal bands around the principal axis + icosahedron highlights; procedural until baked textures
//! exist) and `hatch` (Freudenberg's soft threshold, screen-space strokes). A part's baked style
//! hint wins over the scene style unless [`crate::RenderOptions::use_part_styles`] is off.
//!
//! # Limits
//! Enhanced normals are not in baked files yet: every style uses the file's normals, or the face
//! normal (from screen-space derivatives) where a mesh has none. No back-face culling: open
//! surfaces show their inner side, turned towards the viewer.

use wgpu::util::DeviceExt;

use crate::gpu_types::Vertex;
use crate::passes::{color_attachment, storage_entry, uniform_entry};
use crate::scene::SceneGpu;
use crate::style::{metal_table, transfer_tables};
use crate::targets::{COLOR_FORMAT, DEPTH_FORMAT, LINEAR_DEPTH_FORMAT, NORMAL_FORMAT, PART_ID_FORMAT, Targets};

pub const LABEL: &str = "gbuffer";

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 4] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Uint32, 3 => Uint32];

/// The vertex buffer layout of [`Vertex`] (also used by the shadow pass).
pub fn vertex_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: size_of::<Vertex>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &VERTEX_ATTRIBUTES,
    }
}

#[derive(Debug)]
pub struct GBufferPass {
    pub bind_group_layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    transfer_tables: wgpu::Buffer,
    metal_table: wgpu::Buffer,
}

impl GBufferPass {
    pub fn new(device: &wgpu::Device) -> GBufferPass {
        let module = device.create_shader_module(wgpu::include_wgsl!("gbuffer.wgsl"));
        use wgpu::ShaderStages as S;
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer bind group layout"),
            entries: &[
                uniform_entry(0, S::VERTEX_FRAGMENT, false),
                storage_entry(1, S::VERTEX),
                storage_entry(2, S::VERTEX),
                storage_entry(3, S::FRAGMENT),
                storage_entry(4, S::FRAGMENT),
                storage_entry(5, S::FRAGMENT),
                storage_entry(6, S::FRAGMENT),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer pipeline layout"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let target = |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout())],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    target(COLOR_FORMAT),
                    target(NORMAL_FORMAT),
                    target(LINEAR_DEPTH_FORMAT),
                    target(PART_ID_FORMAT),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        let transfer_tables = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gbuffer transfer tables"),
            contents: bytemuck::cast_slice(&transfer_tables()),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let metal_table = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("gbuffer metal table"),
            contents: bytemuck::cast_slice(&metal_table()),
            usage: wgpu::BufferUsages::STORAGE,
        });
        GBufferPass { bind_group_layout, pipeline, transfer_tables, metal_table }
    }

    /// The bind group of a scene: frame uniforms, instances, label → part, parts, materials and the
    /// lookup tables.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        frame: &wgpu::Buffer,
        scene: &crate::scene::SceneBuffers,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer bind group"),
            layout: &self.bind_group_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: frame.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: scene.instances.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: scene.label_to_part.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: scene.parts.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: scene.materials.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: self.transfer_tables.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: self.metal_table.as_entire_binding() },
            ],
        })
    }

    /// Clears the G-buffer and draws every batch once, instanced.
    /// Draws every batch of `scene`, with its enhanced normals when `enhanced_normals` is set and
    /// the batch has them.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        targets: &Targets,
        scene: &SceneGpu,
        enhanced_normals: bool,
    ) {
        encoder.push_debug_group(LABEL);
        {
            let clear = Some(wgpu::Color::TRANSPARENT);
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("gbuffer pass"),
                color_attachments: &[
                    color_attachment(&targets.color.view, clear),
                    color_attachment(&targets.normal.view, clear),
                    color_attachment(&targets.linear_depth.view, clear),
                    color_attachment(&targets.part_id.view, clear),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &targets.depth.view,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &scene.gbuffer_bind_group, &[]);
            for batch in &scene.batches {
                pass.set_vertex_buffer(0, batch.vertices_for(enhanced_normals).slice(..));
                pass.set_index_buffer(batch.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..batch.index_count, 0, batch.instances.clone());
            }
        }
        encoder.pop_debug_group();
    }
}
