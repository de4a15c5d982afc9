//! A [`Model`] uploaded to the GPU: one vertex and index buffer per batch, the tables
//! ([`crate::table`]) the passes index (instances, label → part, parts, materials) and the G-buffer's lookup textures.

use std::ops::Range;

use wgpu::util::DeviceExt;

use crate::gpu_types::{MaterialGpu, PartGpu};
use crate::model::Model;
use crate::passes::gbuffer::LookupsGpu;
use crate::table::Table;

/// One draw of the G-buffer and shadow passes.
#[derive(Debug)]
pub struct BatchGpu {
    pub vertices: wgpu::Buffer,
    /// The same vertices with the enhanced normals, when the batch has them.
    pub enhanced_vertices: Option<wgpu::Buffer>,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub instances: Range<u32>,
}

/// The tables of a scene ([`crate::table`]).
#[derive(Debug)]
pub struct SceneBuffers {
    pub instances: Table,
    pub label_to_part: Table,
    pub parts: Table,
    pub materials: Table,
}

/// Everything of a model on the GPU, with the bind groups of the geometry passes.
#[derive(Debug)]
pub struct SceneGpu {
    pub batches: Vec<BatchGpu>,
    pub buffers: SceneBuffers,
    /// The instances again, as the G-buffer and shadow passes' second vertex buffer
    /// ([`crate::passes::gbuffer::instance_layout`]): at least one record, so that it can be bound.
    pub instance_vertices: wgpu::Buffer,
    /// The model's lookup textures (baked, or the procedural fallbacks).
    pub lookups: LookupsGpu,
    pub gbuffer_bind_group: wgpu::BindGroup,
}

impl BatchGpu {
    /// The vertex buffer to draw: with the enhanced normals when asked for and present.
    pub fn vertices_for(&self, enhanced_normals: bool) -> &wgpu::Buffer {
        match (&self.enhanced_vertices, enhanced_normals) {
            (Some(enhanced), true) => enhanced,
            _ => &self.vertices,
        }
    }
}

impl SceneGpu {
    pub fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &Model,
        gbuffer: &crate::passes::gbuffer::GBufferPass,
        frame: &wgpu::Buffer,
    ) -> SceneGpu {
        let storage = |label: &str, contents: &[u8]| Table::with_contents(device, queue, label, contents);
        let parts: Vec<PartGpu> = model.part_table();
        let materials: &[MaterialGpu] = &model.materials;
        let buffers = SceneBuffers {
            instances: storage("scene instances", bytemuck::cast_slice(&model.instances)),
            label_to_part: storage("scene label to part", bytemuck::cast_slice(&model.label_to_part)),
            parts: storage("scene parts", bytemuck::cast_slice(&parts)),
            materials: storage("scene materials", bytemuck::cast_slice(materials)),
        };
        let batches = model
            .batches
            .iter()
            .map(|b| BatchGpu {
                vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("batch {} vertices", b.name)),
                    contents: bytemuck::cast_slice(&b.vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some(&format!("batch {} indices", b.name)),
                    contents: bytemuck::cast_slice(&b.indices),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                enhanced_vertices: b.enhanced_normals.as_ref().map(|normals| {
                    let vertices: Vec<crate::gpu_types::Vertex> = b
                        .vertices
                        .iter()
                        .zip(normals)
                        .map(|(v, &n)| crate::gpu_types::Vertex { normal_in_object: n, ..*v })
                        .collect();
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some(&format!("batch {} vertices, enhanced normals", b.name)),
                        contents: bytemuck::cast_slice(&vertices),
                        usage: wgpu::BufferUsages::VERTEX,
                    })
                }),
                index_count: b.indices.len() as u32,
                instances: b.instances.clone(),
            })
            .collect();
        let instance_records: &[crate::gpu_types::InstanceGpu] =
            if model.instances.is_empty() { &[bytemuck::Zeroable::zeroed()] } else { &model.instances };
        let instance_vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene instance records"),
            contents: bytemuck::cast_slice(instance_records),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let lookups = LookupsGpu::upload(device, queue, model.lookups());
        let gbuffer_bind_group = gbuffer.bind_group(device, frame, &buffers, &lookups);
        SceneGpu { batches, buffers, instance_vertices, lookups, gbuffer_bind_group }
    }
}
