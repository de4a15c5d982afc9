//! Lines pass: the baked hard edges and this frame's silhouettes, drawn as
//! screen-space quads over the display output.
//!
//! # How it works
//! 1. **Which lines.** Hard edges come from the file's `EXT_mesh_primitive_edge_visibility` with the
//!    classes of our `hardEdgeClasses` (see [`crate::edges`]); they are uploaded once per model, one
//!    segment per edge and instance. Silhouettes are found per frame on the CPU by the baked
//!    hierarchies (Gooch et al. 1999, §5.1: Gauss-map arcs for orthographic views; a normal-cone
//!    BVH for eye points), queried per instance in object space, exactly the set of drafter-lines'
//!    brute force ([`crate::edges::ModelLines::silhouettes`]), and uploaded every frame.
//! 2. **Wide lines.** wgpu has no wide lines: each segment is one instance of 6 vertices. The
//!    vertex shader transforms both ends through the instance's `render_from_object` (so instancing
//!    and mirrored nodes need nothing special), clips them to the near plane in view space, projects
//!    them to pixels and spans a quad around the segment, extended by the half-width at both ends.
//!    The fragment shader keeps the capsule (distance to the segment ≤ half-width, anti-aliased over
//!    one pixel): segments that share an end overlap in a round cap, so polylines join without
//!    gaps.
//! 3. **In front of their surfaces, behind others.** There is no depth attachment: the fragment
//!    shader compares the line's view depth at the segment's nearest point (perspective-correct,
//!    interpolating 1/depth) with the G-buffer's linear depth there and one and a half pixels to
//!    either side, taking the farthest of the three — a silhouette's own faces turn away steeply
//!    beside it, an occluder in front covers all three. The line is kept within a tolerance of
//!    [`DEPTH_TOLERANCE_RELATIVE`] of its depth plus [`DEPTH_TOLERANCE_PIXELS`] pixel footprints,
//!    so it never fights the surface it lies on.
//! 4. **Gooch's conventions** (§3.1 and §4, ../shared/papers/001_*): silhouettes, boundaries, part
//!    borders and non-manifold edges black, [`OUTLINE_WIDTH_PX`] wide; creases thinner
//!    ([`CREASE_WIDTH_PX`]) and white on the Gooch styles (grey on the others, where white would
//!    vanish on light shading, as the display pass does for image-space creases) — except a crease
//!    that lies on the contour in this view (the part id, or the depth by more than
//!    [`CONTOUR_DEPTH_JUMP`], differs across it: a box's outer edge), which is a silhouette and
//!    drawn as one; the outer outline heavier by [`OUTER_EXTRA_PX`] — added only where the line
//!    covers background, so it grows outwards.
//!
//! Widths are in output pixels and scale with supersampling (and `RenderOptions::line_scale`). Silhouettes are queried on the CPU:
//! the hierarchy answers in microseconds to a few milliseconds (see `drafter bench render`'s
//! `silhouette_query_ms`), well under a lavapipe frame, so no compute pass is used.

use crate::edges::{ModelLines, SilhouetteFrame};
use crate::gpu_types::{LineSegmentGpu, LinesUniforms};
use crate::passes::{FLOAT, UINT, color_attachment, texture_entry, uniform_entry};
use crate::style::{RenderOptions, Style};
use crate::table::{self, Table};
use crate::targets::Targets;

pub const LABEL: &str = "lines";
/// Vertices per segment: its quad's two triangles (`vs_main` in lines.wgsl).
const VERTICES_PER_SEGMENT: u32 = 6;
/// Table texels per segment (`segment_at` in lines.wgsl).
const SEGMENT_TEXELS: u64 = (size_of::<LineSegmentGpu>() / crate::table::TEXEL_BYTES) as u64;

/// Width of silhouettes, boundaries and part borders, output pixels.
pub const OUTLINE_WIDTH_PX: f32 = 1.5;
/// Width of creases, output pixels.
pub const CREASE_WIDTH_PX: f32 = 1.0;
/// Extra width of the outer outline (over the background only), output pixels.
pub const OUTER_EXTRA_PX: f32 = 1.0;
/// Depth tolerance relative to the line's view depth.
pub const DEPTH_TOLERANCE_RELATIVE: f32 = 1e-3;
/// Depth tolerance in pixel footprints at the line's depth.
pub const DEPTH_TOLERANCE_PIXELS: f32 = 2.0;
/// A crease is drawn as an outline where the G-buffer depth on its two sides differs by more than
/// this fraction (or the part id differs): it lies on the contour in this view. Keep in sync with
/// `CONTOUR_DEPTH_JUMP` in lines.wgsl.
pub const CONTOUR_DEPTH_JUMP: f32 = 0.1;
/// Outline colour: black.
pub const OUTLINE_COLOR: [f32; 4] = [0.0, 0.0, 0.0, 1.0];
/// Baked crease lines (the file's crease and tangent edges, drawn as quads here) on the Gooch
/// styles: white (Gooch et al. 1999, Fig. 9). The shader multiplies the alpha by the capsule's
/// anti-aliased coverage; the display pass's image-space creases have their own colours
/// ([`crate::passes::display::IMAGE_SPACE_CREASE_WHITE`]).
pub const BAKED_CREASE_WHITE: [f32; 4] = [1.0, 1.0, 1.0, 1.0];
/// Baked crease lines on the other styles: dark grey.
pub const BAKED_CREASE_DARK: [f32; 4] = [0.15, 0.15, 0.15, 0.85];

/// The line the renderer reports when `--lines` has nothing to draw.
pub fn notice(lines: &ModelLines) -> Option<&'static str> {
    lines.is_empty().then_some("no baked edges in this file (bake it for lines): only image-space edges are drawn")
}

/// The uniforms for a frame of `options` seen through `camera` on targets `target_height` high.
pub fn uniforms(options: &RenderOptions, camera: &crate::Camera, target_height: u32) -> LinesUniforms {
    let scale = options.line_pixel_scale();
    let gooch = matches!(options.style, Style::Gooch | Style::Goochel | Style::Metal);
    // Pixel footprint: 2 / (P[1][1] · height), times the depth for a perspective camera.
    let footprint = 2.0 / (camera.clip_from_view.y_axis.y * target_height.max(1) as f32);
    LinesUniforms {
        clip_from_view: camera.clip_from_view.to_cols_array_2d(),
        outline_color: OUTLINE_COLOR,
        crease_color: if gooch { BAKED_CREASE_WHITE } else { BAKED_CREASE_DARK },
        half_widths: [
            OUTLINE_WIDTH_PX * 0.5 * scale,
            CREASE_WIDTH_PX * 0.5 * scale,
            OUTER_EXTRA_PX * scale,
            camera.near,
        ],
        depth_tolerance: [
            DEPTH_TOLERANCE_RELATIVE,
            DEPTH_TOLERANCE_PIXELS,
            if camera.orthographic { 0.0 } else { footprint },
            if camera.orthographic { footprint } else { 0.0 },
        ],
    }
}

/// A table of segments ([`crate::table`]) with its bind group, grown on demand.
#[derive(Debug)]
struct SegmentBuffer {
    label: &'static str,
    buffer: Table,
    bind_group: wgpu::BindGroup,
    capacity: u64,
    count: u32,
}

/// A model's lines on the GPU and on the CPU.
#[derive(Debug)]
pub struct LinesScene {
    pub lines: ModelLines,
    frame_bind_group: wgpu::BindGroup,
    hard: SegmentBuffer,
    silhouettes: SegmentBuffer,
    last: Option<SilhouetteFrame>,
}

impl LinesScene {
    /// The silhouettes of the last frame drawn with lines.
    pub fn last_silhouettes(&self) -> Option<&SilhouetteFrame> {
        self.last.as_ref()
    }

    /// Hard-edge segments uploaded (edges × instances).
    pub fn hard_count(&self) -> u32 {
        self.hard.count
    }
}

#[derive(Debug)]
pub struct LinesPass {
    frame_layout: wgpu::BindGroupLayout,
    targets_layout: wgpu::BindGroupLayout,
    segments_layout: wgpu::BindGroupLayout,
    layout: wgpu::PipelineLayout,
    format: wgpu::TextureFormat,
    /// Compiled, with its shader module, by [`Self::ensure_pipeline`] at the first frame with
    /// lines (a view without them never needs it).
    pipeline: Option<wgpu::RenderPipeline>,
    uniforms: wgpu::Buffer,
}

impl LinesPass {
    /// A lines pass blending over a `format` target (the display pass's output).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> LinesPass {
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let frame_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lines frame bind group layout"),
            entries: &[uniform_entry(0, vf, false), uniform_entry(1, vf, false), table::layout_entry(2, vf)],
        });
        let targets_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lines targets bind group layout"),
            entries: &[texture_entry(0, FLOAT), texture_entry(1, UINT)],
        });
        let segments_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lines segments bind group layout"),
            entries: &[table::layout_entry(0, wgpu::ShaderStages::VERTEX)],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lines pipeline layout"),
            bind_group_layouts: &[Some(&frame_layout), Some(&targets_layout), Some(&segments_layout)],
            immediate_size: 0,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("lines uniforms"),
            size: size_of::<LinesUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        LinesPass { frame_layout, targets_layout, segments_layout, layout, format, pipeline: None, uniforms }
    }

    /// Compiles the pipeline the first time a frame draws lines.
    /// How many pipelines this pass has compiled (0 or 1).
    pub fn compiled(&self) -> usize {
        usize::from(self.pipeline.is_some())
    }

    pub fn ensure_pipeline(&mut self, device: &wgpu::Device) {
        if self.pipeline.is_some() {
            return;
        }
        let module = device.create_shader_module(super::shader_source!("lines.wgsl", "shared.wgsl"));
        self.pipeline = Some(device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("lines pipeline"),
            layout: Some(&self.layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: self.format,
                    blend: Some(wgpu::BlendState::ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        }));
    }

    fn segment_buffer(&self, device: &wgpu::Device, label: &'static str, capacity: u64) -> SegmentBuffer {
        let buffer = Table::new(device, label, capacity.max(1) * SEGMENT_TEXELS);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some(label),
            layout: &self.segments_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&buffer.view) }],
        });
        // Segments beyond the largest table are not drawn (millions: far beyond any model here).
        let capacity = buffer.capacity / SEGMENT_TEXELS;
        SegmentBuffer { label, buffer, bind_group, capacity, count: 0 }
    }

    /// Uploads `lines` (the hard edges now, the silhouettes per frame).
    pub fn scene(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        lines: ModelLines,
        frame: &wgpu::Buffer,
        instances: &Table,
    ) -> LinesScene {
        let frame_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lines frame bind group"),
            layout: &self.frame_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: frame.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&instances.view) },
            ],
        });
        let hard_segments = lines.hard_segments();
        let mut hard = self.segment_buffer(device, "lines hard edges", hard_segments.len() as u64);
        hard.buffer.write(queue, bytemuck::cast_slice(&hard_segments));
        hard.count = hard_segments.len().min(hard.capacity as usize) as u32;
        let silhouettes = self.segment_buffer(device, "lines silhouettes", 1024);
        LinesScene { lines, frame_bind_group, hard, silhouettes, last: None }
    }

    /// The bind group of the G-buffer targets the pass reads.
    pub fn targets_bind_group(&self, device: &wgpu::Device, targets: &Targets) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lines targets bind group"),
            layout: &self.targets_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(&targets.linear_depth.view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::TextureView(&targets.part_id.view),
                },
            ],
        })
    }

    /// Writes the uniforms and this frame's silhouettes (`silhouettes`, from
    /// [`ModelLines::silhouettes`]).
    pub fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        scene: &mut LinesScene,
        uniforms: &LinesUniforms,
        silhouettes: SilhouetteFrame,
    ) {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
        let needed = silhouettes.segments.len() as u64;
        if needed > scene.silhouettes.capacity {
            scene.silhouettes = self.segment_buffer(device, scene.silhouettes.label, needed.next_power_of_two());
        }
        scene.silhouettes.buffer.write(queue, bytemuck::cast_slice(&silhouettes.segments));
        scene.silhouettes.count = needed.min(scene.silhouettes.capacity) as u32;
        scene.last = Some(silhouettes);
    }

    /// Draws the lines over `output` (the display pass's result, same size as the targets);
    /// [`Self::ensure_pipeline`] must have run (the renderer's `prepare` does).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        scene: &LinesScene,
        targets_bind_group: &wgpu::BindGroup,
        output: &wgpu::TextureView,
    ) {
        let Some(pipeline) = self.pipeline.as_ref() else {
            debug_assert!(false, "lines are encoded before their pipeline was compiled");
            return;
        };
        encoder.push_debug_group(LABEL);
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("lines pass"),
                color_attachments: &[color_attachment(output, None)],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &scene.frame_bind_group, &[]);
            pass.set_bind_group(1, targets_bind_group, &[]);
            for segments in [&scene.hard, &scene.silhouettes] {
                if segments.count > 0 {
                    pass.set_bind_group(2, &segments.bind_group, &[]);
                    // Six vertices a segment in one plain draw, not one instance a segment: a CPU
                    // rasteriser (SwiftShader, the browsers' WebGL without a GPU) sets up every
                    // instance as a draw of its own, which for an assembly's 10⁵ segments is most
                    // of the frame.
                    pass.draw(0..segments.count.saturating_mul(VERTICES_PER_SEGMENT), 0..1);
                }
            }
        }
        encoder.pop_debug_group();
    }
}
