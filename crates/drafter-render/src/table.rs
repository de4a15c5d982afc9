//! The arrays the scene's shaders index by instance, label, part, material or segment, held in 2D
//! textures of 16-byte texels (`Rgba32Uint`, a float stored by its bits) and read with
//! `textureLoad`; the accessors (`instance_transform_at`, `part_at`, ...) are WGSL functions beside the
//! structs they return (`passes/shared.wgsl` and the passes' own files).
//!
//! # Why textures and not storage buffers
//! WebGL2, the browser page's backend where WebGPU is missing (`web/`), has no storage buffers in
//! any shader stage, while every backend reads integer textures in the vertex and the fragment
//! stage. One layout for every platform keeps one shader and one upload path: the native window,
//! `drafter render` and the page run the same WGSL, and the native goldens test what the browser
//! draws. The reads are exact (`bitcast` of the stored bits), so the images did not change.
//!
//! # Layout
//! Texel `k` of a table lies at (`k % TABLE_WIDTH`, `k / TABLE_WIDTH`); an element of `n` texels
//! starts at texel `i * n`. A table is at least one row; its capacity is whole rows, at most the
//! device's largest texture side of them. Writes beyond the capacity are dropped (the callers size
//! their tables first; [`Table::fits`] says whether a count fits).

/// Texels per row (WGSL: `TABLE_WIDTH` in `shared.wgsl`). WebGL2 guarantees sides of 2048.
pub const TABLE_WIDTH: u32 = 1024;
/// The texel format of every table.
pub const TABLE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// Bytes per texel.
pub const TEXEL_BYTES: usize = 16;

/// One table on the GPU.
#[derive(Debug)]
pub struct Table {
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    /// Texels it holds (whole rows).
    pub capacity: u64,
}

impl Table {
    /// A table of at least `texels` texels (as many as the device's largest texture allows).
    pub fn new(device: &wgpu::Device, label: &str, texels: u64) -> Table {
        let max_rows = u64::from(device.limits().max_texture_dimension_2d.max(1));
        let rows = texels.div_ceil(u64::from(TABLE_WIDTH)).clamp(1, max_rows);
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width: TABLE_WIDTH, height: rows as u32, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: TABLE_FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        Table { texture, view, capacity: rows * u64::from(TABLE_WIDTH) }
    }

    /// A table holding `bytes` (padded with zeros to whole texels).
    pub fn with_contents(device: &wgpu::Device, queue: &wgpu::Queue, label: &str, bytes: &[u8]) -> Table {
        let table = Table::new(device, label, texels_of(bytes.len()));
        table.write(queue, bytes);
        table
    }

    /// Whether `texels` texels fit.
    pub fn fits(&self, texels: u64) -> bool {
        texels <= self.capacity
    }

    /// Writes `bytes` from texel 0 on (padded with zeros to whole texels; what does not fit is
    /// dropped).
    pub fn write(&self, queue: &wgpu::Queue, bytes: &[u8]) {
        let texels = texels_of(bytes.len()).min(self.capacity);
        if texels == 0 {
            return;
        }
        let mut padded;
        let bytes = if bytes.len() as u64 == texels * TEXEL_BYTES as u64 {
            bytes
        } else {
            padded = bytes[..bytes.len().min(texels as usize * TEXEL_BYTES)].to_vec();
            padded.resize(texels as usize * TEXEL_BYTES, 0);
            &padded
        };
        let width = u64::from(TABLE_WIDTH);
        let (full_rows, rest) = (texels / width, texels % width);
        let row_bytes = TABLE_WIDTH * TEXEL_BYTES as u32;
        let write = |row: u64, columns: u32, rows: u32, data: &[u8]| {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &self.texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y: row as u32, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                data,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row_bytes), rows_per_image: Some(rows) },
                wgpu::Extent3d { width: columns, height: rows, depth_or_array_layers: 1 },
            );
        };
        let split = (full_rows * width) as usize * TEXEL_BYTES;
        if full_rows > 0 {
            write(0, TABLE_WIDTH, full_rows as u32, &bytes[..split]);
        }
        if rest > 0 {
            write(full_rows, rest as u32, 1, &bytes[split..]);
        }
    }
}

/// Texels that hold `bytes` bytes.
pub fn texels_of(bytes: usize) -> u64 {
    (bytes as u64).div_ceil(TEXEL_BYTES as u64)
}

/// A bind group layout entry for a table read in `visibility`.
pub fn layout_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Uint,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        },
        count: None,
    }
}

#[cfg(test)]
mod tests {
    use super::TEXEL_BYTES;
    use crate::gpu_types::{InstanceGpu, LineSegmentGpu, MaterialGpu, PartGpu};

    /// The WGSL accessors step whole records: `instance_transform_at` 8 texels (of which it
    /// reads the transform's 4), `segment_at` 2 (lines.wgsl), `part_at` 6 and `material_at` 2
    /// (gbuffer.wgsl).
    #[test]
    fn the_accessors_read_the_rust_structs_whole() {
        for (name, size, texels, source) in [
            ("instance_transform_at", size_of::<InstanceGpu>(), 8, include_str!("passes/lines.wgsl")),
            ("part_at", size_of::<PartGpu>(), 6, include_str!("passes/gbuffer.wgsl")),
            ("material_at", size_of::<MaterialGpu>(), 2, include_str!("passes/gbuffer.wgsl")),
            ("segment_at", size_of::<LineSegmentGpu>(), 2, include_str!("passes/lines.wgsl")),
        ] {
            assert_eq!(size, texels * TEXEL_BYTES, "{name}");
            let body = &source[source.find(&format!("fn {name}(")).unwrap_or_else(|| panic!("{name} in WGSL"))..];
            assert!(body.contains(&format!("i * {texels}u")), "{name} does not step {texels} texels");
        }
    }
}
