//! G-buffer pass (Lux et al. 2013, §5 "G-Buffer Generation Pass"; Algorithm 1, lines 1–11).
//!
//! # How it works
//! Every mesh is drawn **once**, instanced over all its placements: the vertex shader takes the
//! instance's transform from a second vertex buffer stepped per instance ([`instance_layout`]),
//! maps the vertex's part label through the instance's slice of `label_to_part` (a table,
//! [`crate::table`]) to a scene-wide part id, and the fragment shader fetches that
//! part's projector, gradient parameters and style from the part table. Algorithm 1 sets uniforms
//! per object; doing it through a table instead keeps the frame time independent of the
//! number of parts.
//!
//! The fragment shader writes four targets in one pass (multiple render targets): shaded colour,
//! view-space normal, linear view depth and part id + 1 (0 = background), which the enhancement
//! and display passes read.
//!
//! # Styles (see `gbuffer.wgsl`)
//! `gradient` (projective texturing with ω(i, q, f, p) and the γ table), `phong`, `cel` (2–4 steps,
//! optional specular band), `gooch` (cool-to-warm, optional splash-back), `goochel`, `metal` (Gooch
//! metal bands around the principal axis + icosahedron highlights) and `hatch` (Freudenberg's soft
//! threshold `ink = clamp(c·(1 − (T + I)))`, screen-space as ten Bosch's "simple hatching"). A
//! part's baked style hint wins over the scene style unless [`crate::RenderOptions::use_part_styles`]
//! is off.
//!
//! # Lookup textures
//! The styles read the lookup textures a baked file embeds (drafter-textures' images, decoded by
//! [`crate::lookups`]) and fall back, lookup by lookup, to the viewer's own where the file has none
//! (plain glTF). Six textures and two samplers (clamped linear; repeating trilinear) are bound
//! whatever the source; [`LookupUniforms`] flags which are baked, and the shader computes the others:
//!
//! * **γ atlas** (gradient): always a texture, the file's (8-bit) or the procedural one (32-bit
//!   float: exactly the tables drafter-core interpolates), texel `k` = γ(k/127) interpolated
//!   linearly in the part's row ([`crate::Model::part_table`] maps the part's curve to the row).
//!   Equivalent to the spec's `u = (0.5 + 127·p)/128` with linear filtering, done with two
//!   `textureLoad`s because core WebGPU cannot filter 32-bit floats.
//! * **cel atlas** (cel, goochel; ten Bosch 2005): the row whose steps and specular band match
//!   [`crate::RenderOptions::cel_steps`] and `cel_specular` (the bake's default table matches the
//!   default options); with other options the procedural steps. Cel: `x = max(n·l, 0)`, the diffuse
//!   steps scale the base colour relative to the brightest one, values above it (the row's specular
//!   band) are drawn towards white. Goochel: `x = (1 + n·l)/2`, the steps rescaled to [0, 1] are the
//!   cool-to-warm blend.
//! * **cool-to-warm map** (gooch, goochel; Gooch et al. 1999, Fig. 10): indexed by an eye-space
//!   normal. The map depends on the normal only through `n·l_map` (drafter-textures' `cool_warm`),
//!   so it is read at the normal `c·l_map + √(1 − c²)·a` (`a` ⟂ `l_map`, leaning to the viewer) with
//!   `c` the frame's `n·l`: exactly the map's shading for the viewer's light, which the other
//!   styles and the drop shadow share. Goochel reads it at `c = 2t − 1` for the stepped blend `t`.
//!   Factored maps give `clamp(rgb + a·k_d)`; splash-back, when asked for and not in the map, is
//!   multiplied in (`|0.76·c + 0.24|^0.78`). Limit: a normal-sphere map stores the front
//!   hemisphere only, so for `c` below `−√(1 − l_z²)` the mirrored texel is read.
//! * **halftone** (hatch; Freudenberg 2002): `T` sampled at `pixel / tile` with the stored mip
//!   levels (trilinear, explicit gradients), `ink = clamp(c·(1 − (T + I)))` with the file's `c`.
//!   The tile is scaled so that [`crate::style::HALFTONE_STROKE_SPACING_TEXELS`] (the default
//!   halftone's stroke spacing) spans `hatch_period_px` (times the supersampling); since each level
//!   keeps the strokes' width and spacing in texels, a period below that spacing in target pixels
//!   moves to a coarser level rather than packing strokes closer (as tonal art maps do): with
//!   supersampling 2 the default 5 px period is met, without it the strokes are about 10 px apart.
//! * **metal** (Gooch et al. 1999, §5.2.1): bands at `u = s·(1 + n·w)/2`, `w` the part's
//!   `obb.axes[1]` (⟂ the principal axis, so the bands run along it), `s` =
//!   [`crate::style::METAL_STRIPE_SCALE`], repeat; highlights from the map by the eye-space normal.
//!   Colour `tint·mix(0.4, 1, band)·(0.75 + 0.25·max(n·l, 0)) + highlight`: the spec's
//!   `base·band + highlight` with the band lifted so no streak is black and a little diffuse light
//!   so flat faces read apart. Procedural: the bake's default band table
//!   ([`crate::style::metal_table`], [`crate::style::METAL_TABLE_LEN`] = 16 entries) by the angle
//!   around the axis and six of the icosahedron's lights, Blinn–Phong.
//!
//! # Specialised pipelines
//! One fragment shader holds every style, but a frame usually draws one or two of them: the scene's
//! style, or the parts' style hints. On a GPU a branch that no pixel takes costs nothing; on a CPU
//! rasteriser it does: lavapipe runs SIMD lanes under masks and executes every style's code, texture
//! reads included, for every pixel (a G-buffer with all seven styles compiled in costs several
//! times one with its style alone). So the pipeline is
//! specialised by the pipeline constant `STYLES`, a bit per style that may be drawn
//! ([`frame_styles`]): the others are compiled out, and with one bit set the style is a constant.
//! Each set of styles is compiled once, when a frame first needs it, and kept.
//!
//! # Limits
//! Enhanced normals come from the file when baked ([`crate::RenderOptions::enhanced_normals`]);
//! otherwise every style uses the file's normals, or the face normal (from screen-space
//! derivatives) where a mesh has none. No back-face culling: open surfaces show their inner side,
//! turned towards the viewer. One cool-to-warm map is used (the file's first).

use drafter_format::CelTableRecord;
use glam::Vec3;
use wgpu::util::DeviceExt;

use crate::gpu_types::{
    InstanceGpu, LOOKUP_CEL, LOOKUP_CEL_SPECULAR, LOOKUP_COOL_TO_WARM, LOOKUP_COOL_TO_WARM_FACTORED,
    LOOKUP_COOL_TO_WARM_SPHERE, LOOKUP_COOL_TO_WARM_SPLASH, LOOKUP_HATCH, LOOKUP_METAL, LOOKUP_METAL_SPHERE,
    LookupUniforms, Vertex,
};
use crate::lookups::{self, BakedLookups, EnvMapping, LookupFormat, LookupImage};
use crate::passes::{FILTERABLE, FLOAT, color_attachment, sampler_entry, texture_entry, uniform_entry};
use crate::scene::SceneGpu;
use crate::style::{HALFTONE_STROKE_SPACING_TEXELS, METAL_STRIPE_SCALE, RenderOptions, Style};
use crate::table;
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

/// [`InstanceGpu`] as vertex attributes (`InstanceIn` in shared.wgsl): its transform's four
/// columns, the normal matrix's three and the ids, in the order of the struct's fields.
const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 8] = wgpu::vertex_attr_array![
    4 => Float32x4, 5 => Float32x4, 6 => Float32x4, 7 => Float32x4,
    8 => Float32x4, 9 => Float32x4, 10 => Float32x4, 11 => Uint32x4,
];

/// The second vertex buffer of the G-buffer and shadow passes: the scene's instances
/// ([`crate::scene::SceneGpu::instance_vertices`]), one record per instance drawn.
pub fn instance_layout() -> wgpu::VertexBufferLayout<'static> {
    wgpu::VertexBufferLayout {
        array_stride: size_of::<InstanceGpu>() as wgpu::BufferAddress,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &INSTANCE_ATTRIBUTES,
    }
}

/// Every style's bit (`STYLES` in `gbuffer.wgsl`): the pipeline that draws any mix of part styles.
pub const ALL_STYLES: u32 = (1 << Style::ALL.len()) - 1;

/// The styles a frame draws, bit [`Style::index`] each: the scene's style when part styles are off
/// (or some part has no hint), and every part's hint (`part_hints`, the same bits) when they are on.
pub fn frame_styles(options: &RenderOptions, part_hints: u32, unhinted_parts: bool) -> u32 {
    let scene = 1 << crate::style::shader_index(options.style);
    if !options.use_part_styles {
        return scene;
    }
    part_hints | if unhinted_parts { scene } else { 0 }
}

/// Bindings of the lookup textures (keep in sync with `gbuffer.wgsl`).
const LOOKUP_BINDINGS: std::ops::Range<u32> = 5..11;

#[derive(Debug)]
pub struct GBufferPass {
    pub bind_group_layout: wgpu::BindGroupLayout,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    /// The pipelines compiled so far, by the styles they draw (see "Specialised pipelines").
    pipelines: std::collections::BTreeMap<u32, wgpu::RenderPipeline>,
    /// The styles of the pipeline that [`Self::encode`] draws with.
    styles: u32,
    /// Linear, clamp to edge, one level: the tables and environment maps.
    clamp_sampler: wgpu::Sampler,
    /// Trilinear, repeat: the halftone (its stored mip chain) and the metal bands.
    repeat_sampler: wgpu::Sampler,
}

/// What the per-frame [`LookupUniforms`] are made of: the baked lookups' parameters, without
/// their texels.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LookupPlan {
    /// The cel atlas's tables (row order); empty: procedural steps.
    pub cel_tables: Vec<CelTableRecord>,
    /// The cool-to-warm map: mapping, factored, light in eye space, splash-back included.
    pub cool_to_warm: Option<(EnvMapping, bool, Vec3, bool)>,
    /// The halftone: level-0 side in texels, the file's `c`.
    pub hatching: Option<(u32, f32)>,
    /// The metal highlight map's mapping.
    pub metal: Option<EnvMapping>,
}

impl LookupPlan {
    pub fn of(lookups: &BakedLookups) -> LookupPlan {
        LookupPlan {
            cel_tables: lookups.cel.as_ref().map(|c| c.tables.clone()).unwrap_or_default(),
            cool_to_warm: lookups.cool_to_warm.as_ref().map(|c| (c.mapping, c.factored, c.light_in_eye, c.splash_back)),
            hatching: lookups.hatching.as_ref().map(|h| (h.image.width, h.contrast)),
            metal: lookups.metal.as_ref().map(|m| m.mapping),
        }
    }
}

/// The uniforms of one frame (module docs, "Lookup textures").
pub fn lookup_uniforms(plan: &LookupPlan, options: &RenderOptions) -> LookupUniforms {
    let mut u = LookupUniforms { cel_diffuse_max: 1.0, ..Default::default() };
    let row = plan.cel_tables.iter().position(|t| t.steps == options.cel_steps && t.specular == options.cel_specular);
    if let Some(r) = row {
        let t = &plan.cel_tables[r];
        u.flags |= LOOKUP_CEL;
        u.cel_row_v = (r as f32 + 0.5) / plan.cel_tables.len() as f32;
        u.cel_min_level = t.min_level as f32;
        if t.specular {
            u.flags |= LOOKUP_CEL_SPECULAR;
            u.cel_diffuse_max = t.diffuse_max as f32;
        }
    }
    if let Some((mapping, factored, light, splash)) = plan.cool_to_warm {
        u.flags |= LOOKUP_COOL_TO_WARM;
        if factored {
            u.flags |= LOOKUP_COOL_TO_WARM_FACTORED;
        }
        if splash {
            u.flags |= LOOKUP_COOL_TO_WARM_SPLASH;
        }
        if mapping == EnvMapping::NormalSphere {
            u.flags |= LOOKUP_COOL_TO_WARM_SPHERE;
        }
        let across =
            (Vec3::Z - Vec3::Z.dot(light) * light).try_normalize().unwrap_or_else(|| light.any_orthonormal_vector());
        u.map_light = light.extend(0.0).to_array();
        u.map_across = across.extend(0.0).to_array();
    }
    if let Some((side, contrast)) = plan.hatching {
        u.flags |= LOOKUP_HATCH;
        let period = options.hatch_period_px * options.supersample.max(1) as f32;
        let tile = side as f32 * period / HALFTONE_STROKE_SPACING_TEXELS;
        u.hatch = [tile, contrast, 0.0, 0.0];
    }
    if let Some(mapping) = plan.metal {
        u.flags |= LOOKUP_METAL;
        if mapping == EnvMapping::NormalSphere {
            u.flags |= LOOKUP_METAL_SPHERE;
        }
    }
    u.metal = [METAL_STRIPE_SCALE, 0.0, 0.0, 0.0];
    u
}

/// A scene's lookup textures on the GPU, with their uniforms.
#[derive(Debug)]
pub struct LookupsGpu {
    /// γ atlas, cel atlas, cool-to-warm, halftone, metal bands, metal highlights (binding order).
    textures: Vec<wgpu::Texture>,
    views: Vec<wgpu::TextureView>,
    uniforms: wgpu::Buffer,
    plan: LookupPlan,
}

impl LookupsGpu {
    /// Uploads `lookups`, with the procedural γ atlas and metal table and 1 × 1 placeholders where
    /// a lookup is not baked.
    pub fn upload(device: &wgpu::Device, queue: &wgpu::Queue, lookups: &BakedLookups) -> LookupsGpu {
        let gamma = lookups.gamma.as_ref().map_or_else(|| lookups::procedural_gamma().image, |g| g.image.clone());
        let or_placeholder = |image: Option<&LookupImage>, name: &str, format| {
            image.cloned().unwrap_or_else(|| lookups::placeholder(name, format))
        };
        let images = [
            gamma,
            or_placeholder(lookups.cel.as_ref().map(|c| &c.image), "cel atlas", LookupFormat::R8),
            or_placeholder(lookups.cool_to_warm.as_ref().map(|c| &c.image), "cool-to-warm", LookupFormat::Rgba8),
            or_placeholder(lookups.hatching.as_ref().map(|h| &h.image), "hatching", LookupFormat::R8),
            lookups.metal.as_ref().map_or_else(lookups::procedural_metal_bands, |m| m.bands.clone()),
            or_placeholder(lookups.metal.as_ref().map(|m| &m.highlights), "metal highlights", LookupFormat::R8),
        ];
        let textures: Vec<wgpu::Texture> = images.iter().map(|image| upload_image(device, queue, image)).collect();
        let views = textures.iter().map(|t| t.create_view(&wgpu::TextureViewDescriptor::default())).collect();
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("gbuffer lookup uniforms"),
            size: size_of::<LookupUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        LookupsGpu { textures, views, uniforms, plan: LookupPlan::of(lookups) }
    }

    /// The textures, in binding order (their labels name the images).
    pub fn textures(&self) -> &[wgpu::Texture] {
        &self.textures
    }
}

/// One lookup image as a 2D texture with its stored mip levels (`*Unorm`: the texels are data).
fn upload_image(device: &wgpu::Device, queue: &wgpu::Queue, image: &LookupImage) -> wgpu::Texture {
    let format = match image.format {
        LookupFormat::R8 => wgpu::TextureFormat::R8Unorm,
        LookupFormat::Rgba8 => wgpu::TextureFormat::Rgba8Unorm,
        LookupFormat::R32Float => wgpu::TextureFormat::R32Float,
    };
    let data: Vec<u8> = image.levels.concat();
    device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some(&format!("gbuffer lookup {}", image.name)),
            size: wgpu::Extent3d { width: image.width, height: image.height, depth_or_array_layers: 1 },
            mip_level_count: image.levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    )
}

impl GBufferPass {
    pub fn new(device: &wgpu::Device) -> GBufferPass {
        let module = device.create_shader_module(super::shader_source!("gbuffer.wgsl", "shared.wgsl"));
        use wgpu::ShaderStages as S;
        let mut entries = vec![
            uniform_entry(0, S::VERTEX_FRAGMENT, false),
            table::layout_entry(1, S::VERTEX),
            table::layout_entry(2, S::FRAGMENT),
            table::layout_entry(3, S::FRAGMENT),
            uniform_entry(4, S::FRAGMENT, false),
        ];
        // The γ atlas is read with `textureLoad` (its procedural form is 32-bit float, which
        // core WebGPU cannot filter); the others with the samplers.
        entries.push(texture_entry(LOOKUP_BINDINGS.start, FLOAT));
        entries.extend((LOOKUP_BINDINGS.start + 1..LOOKUP_BINDINGS.end).map(|b| texture_entry(b, FILTERABLE)));
        entries.extend([sampler_entry(LOOKUP_BINDINGS.end), sampler_entry(LOOKUP_BINDINGS.end + 1)]);
        let bind_group_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gbuffer bind group layout"),
            entries: &entries,
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer pipeline layout"),
            bind_group_layouts: &[Some(&bind_group_layout)],
            immediate_size: 0,
        });
        let clamp_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("gbuffer lookup sampler, clamped"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Nearest,
            ..Default::default()
        });
        let repeat_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("gbuffer lookup sampler, repeating"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        // No pipeline yet: each frame's [`Self::specialise`] compiles the one it draws with. Compiling
        // the every-style pipeline up front cost a browser's first frame a compile it never used
        // (a WebGL2 link on a CPU rasteriser is hundreds of milliseconds).
        GBufferPass {
            bind_group_layout,
            module,
            layout,
            pipelines: std::collections::BTreeMap::new(),
            styles: ALL_STYLES,
            clamp_sampler,
            repeat_sampler,
        }
    }

    /// Makes the frames that follow use the pipeline specialised for `styles` (bit
    /// [`Style::index`] per style that may be drawn), compiling it the first time it is asked for.
    pub fn specialise(&mut self, device: &wgpu::Device, styles: u32) {
        self.styles = self.compile(device, styles);
    }

    /// How many pipelines this pass has compiled.
    pub fn compiled(&self) -> usize {
        self.pipelines.len()
    }

    /// Compiles the pipeline for `styles` if it is not yet, without selecting it; returns the
    /// styles it draws.
    pub fn compile(&mut self, device: &wgpu::Device, styles: u32) -> u32 {
        let styles = if styles & ALL_STYLES == 0 { ALL_STYLES } else { styles & ALL_STYLES };
        if self.pipelines.contains_key(&styles) {
            return styles;
        }
        let target = |format| Some(wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL });
        let constants = [("STYLES", f64::from(styles))];
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer pipeline"),
            layout: Some(&self.layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(vertex_layout()), Some(instance_layout())],
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
                module: &self.module,
                entry_point: Some("fs_main"),
                compilation_options: wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() },
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
        self.pipelines.insert(styles, pipeline);
        styles
    }

    /// The bind group of a scene: frame uniforms, instances, label → part, parts, materials and the
    /// lookup textures.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        frame: &wgpu::Buffer,
        scene: &crate::scene::SceneBuffers,
        lookups: &LookupsGpu,
    ) -> wgpu::BindGroup {
        let mut entries = vec![
            wgpu::BindGroupEntry { binding: 0, resource: frame.as_entire_binding() },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&scene.label_to_part.view),
            },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&scene.parts.view) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::TextureView(&scene.materials.view) },
            wgpu::BindGroupEntry { binding: 4, resource: lookups.uniforms.as_entire_binding() },
        ];
        entries.extend(LOOKUP_BINDINGS.zip(&lookups.views).map(|(binding, view)| wgpu::BindGroupEntry {
            binding,
            resource: wgpu::BindingResource::TextureView(view),
        }));
        entries.extend([
            wgpu::BindGroupEntry {
                binding: LOOKUP_BINDINGS.end,
                resource: wgpu::BindingResource::Sampler(&self.clamp_sampler),
            },
            wgpu::BindGroupEntry {
                binding: LOOKUP_BINDINGS.end + 1,
                resource: wgpu::BindingResource::Sampler(&self.repeat_sampler),
            },
        ]);
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gbuffer bind group"),
            layout: &self.bind_group_layout,
            entries: &entries,
        })
    }

    /// Writes the scene's lookup uniforms for a frame of `options`.
    pub fn prepare(&self, queue: &wgpu::Queue, lookups: &LookupsGpu, options: &RenderOptions) {
        let uniforms = lookup_uniforms(&lookups.plan, options);
        queue.write_buffer(&lookups.uniforms, 0, bytemuck::bytes_of(&uniforms));
    }

    /// Clears the G-buffer and draws every batch of `scene` once, instanced, with its enhanced
    /// normals when `enhanced_normals` is set and the batch has them.
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
            let pipeline = self.pipelines.get(&self.styles).or_else(|| self.pipelines.get(&ALL_STYLES));
            let Some(pipeline) = pipeline else { return };
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &scene.gbuffer_bind_group, &[]);
            pass.set_vertex_buffer(1, scene.instance_vertices.slice(..));
            for batch in &scene.batches {
                pass.set_vertex_buffer(0, batch.vertices_for(enhanced_normals).slice(..));
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

    /// The instance attributes lie where [`InstanceGpu`]'s fields do, fill the record, and match
    /// `InstanceIn`'s locations and types in shared.wgsl.
    #[test]
    fn the_instance_attributes_are_the_instance_record() {
        let fields = [
            std::mem::offset_of!(InstanceGpu, render_from_object),
            std::mem::offset_of!(InstanceGpu, render_from_object) + 16,
            std::mem::offset_of!(InstanceGpu, render_from_object) + 32,
            std::mem::offset_of!(InstanceGpu, render_from_object) + 48,
            std::mem::offset_of!(InstanceGpu, normal_from_object),
            std::mem::offset_of!(InstanceGpu, normal_from_object) + 16,
            std::mem::offset_of!(InstanceGpu, normal_from_object) + 32,
            std::mem::offset_of!(InstanceGpu, label_base),
        ];
        let offsets: Vec<usize> = INSTANCE_ATTRIBUTES.iter().map(|a| a.offset as usize).collect();
        assert_eq!(offsets, fields);
        let last = INSTANCE_ATTRIBUTES[7];
        assert_eq!(last.offset + last.format.size(), size_of::<InstanceGpu>() as u64);
        let shared = include_str!("shared.wgsl");
        let body = &shared[shared.find("struct InstanceIn {").expect("InstanceIn in shared.wgsl")..];
        let body = &body[..body.find('}').unwrap_or(body.len())];
        for attribute in INSTANCE_ATTRIBUTES {
            let ty = match attribute.format {
                wgpu::VertexFormat::Float32x4 => "vec4<f32>",
                wgpu::VertexFormat::Uint32x4 => "vec4<u32>",
                other => panic!("{other:?} not expected"),
            };
            let line = body
                .lines()
                .find(|l| l.contains(&format!("@location({})", attribute.shader_location)))
                .unwrap_or_else(|| panic!("no @location({}) in InstanceIn", attribute.shader_location));
            assert!(line.contains(ty), "{line}: expected {ty}");
        }
        // The vertex attributes stop below the first instance location.
        assert!(VERTEX_ATTRIBUTES.iter().all(|a| a.shader_location < INSTANCE_ATTRIBUTES[0].shader_location));
    }

    fn table(steps: u32, specular: bool) -> CelTableRecord {
        CelTableRecord { steps, specular, min_level: 0.3, specular_threshold: 0.95, diffuse_max: 0.8 }
    }

    #[test]
    fn cel_rows_follow_the_options() {
        let plan = LookupPlan { cel_tables: vec![table(2, false), table(3, true)], ..Default::default() };
        let o = RenderOptions::default(); // 3 steps with a specular band
        let u = lookup_uniforms(&plan, &o);
        assert_eq!(u.flags & (LOOKUP_CEL | LOOKUP_CEL_SPECULAR), LOOKUP_CEL | LOOKUP_CEL_SPECULAR);
        assert_eq!((u.cel_row_v, u.cel_min_level, u.cel_diffuse_max), (0.75, 0.3, 0.8));
        let u = lookup_uniforms(&plan, &RenderOptions { cel_steps: 2, cel_specular: false, ..o.clone() });
        assert_eq!((u.flags & LOOKUP_CEL, u.cel_row_v, u.cel_diffuse_max), (LOOKUP_CEL, 0.25, 1.0));
        // No row with four steps: the procedural steps.
        let u = lookup_uniforms(&plan, &RenderOptions { cel_steps: 4, ..o });
        assert_eq!(u.flags & LOOKUP_CEL, 0);
    }

    #[test]
    fn the_cool_to_warm_frame_is_orthonormal_and_faces_the_viewer() {
        for light in [Vec3::new(1.0, 1.0, 0.5).normalize(), Vec3::Z, Vec3::NEG_Z, Vec3::X] {
            let plan =
                LookupPlan { cool_to_warm: Some((EnvMapping::Octahedral, true, light, false)), ..Default::default() };
            let u = lookup_uniforms(&plan, &RenderOptions::default());
            let (l, a) = (Vec3::from_slice(&u.map_light), Vec3::from_slice(&u.map_across));
            assert!((l.length() - 1.0).abs() < 1e-6 && (a.length() - 1.0).abs() < 1e-6 && l.dot(a).abs() < 1e-6);
            assert!(a.z >= 0.0, "{light}: {a}");
        }
    }

    #[test]
    fn the_hatching_tile_scales_with_period_and_supersampling() {
        let plan = LookupPlan { hatching: Some((128, 4.0)), ..Default::default() };
        // The stroke spacing spans one period: 128 texels over 5 / 11.31 pixels per texel.
        let o = RenderOptions { hatch_period_px: HALFTONE_STROKE_SPACING_TEXELS, ..Default::default() };
        let u = lookup_uniforms(&plan, &o);
        assert_eq!(u.hatch[1], 4.0);
        assert!((u.hatch[0] - 128.0).abs() < 1e-3, "{}", u.hatch[0]);
        let o = RenderOptions { supersample: 2, hatch_period_px: 2.0 * HALFTONE_STROKE_SPACING_TEXELS, ..o };
        assert!((lookup_uniforms(&plan, &o).hatch[0] - 512.0).abs() < 1e-3);
        assert_eq!(lookup_uniforms(&LookupPlan::default(), &o).flags, 0);
    }

    #[test]
    fn a_frame_compiles_in_the_styles_it_can_draw_and_no_other() {
        let hatch = 1 << crate::style::shader_index(Style::Hatch);
        let metal = 1 << crate::style::shader_index(Style::Metal);
        let gradient = RenderOptions { style: Style::Gradient, ..Default::default() };
        let scene = 1 << crate::style::shader_index(Style::Gradient);
        // Part styles off: the scene's style whatever the hints.
        let off = RenderOptions { use_part_styles: false, ..gradient.clone() };
        assert_eq!(frame_styles(&off, hatch | metal, true), scene);
        // On: the hints, and the scene's style only when some part has none.
        let on = RenderOptions { use_part_styles: true, ..gradient };
        assert_eq!(frame_styles(&on, hatch | metal, false), hatch | metal);
        assert_eq!(frame_styles(&on, hatch, true), hatch | scene);
        assert_eq!(frame_styles(&on, 0, true), scene);
        assert!(ALL_STYLES.count_ones() as usize == Style::ALL.len());
        assert!(Style::ALL.iter().all(|s| ALL_STYLES & (1 << crate::style::shader_index(*s)) != 0));
    }
}
