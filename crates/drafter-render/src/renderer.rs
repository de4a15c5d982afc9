//! The frame: camera fit, uniforms, and the passes in order (Lux et al. 2013, Algorithm 1, with
//! Gooch et al.'s drop shadow). [`Renderer::render`] draws offscreen and reads the image back;
//! [`Renderer::encode_frame`] records the same frame into any encoder and target (the window and
//! the benchmark use it).

use std::time::Duration;

use web_time::Instant;

use glam::Vec3;

use crate::camera::{Camera, LIGHT_IN_VIEW, view_rotation};
use crate::context::{Gpu, RenderError};
use crate::gpu_types::{FLAG_CEL_SPECULAR, FLAG_SPLASH_BACK, FrameUniforms};
use crate::image::Image;
use crate::model::Model;
use crate::passes::display::{self, DisplayPass};
use crate::passes::enhance::{EnhanceBindings, EnhancePass, EnhanceSetup};
use crate::passes::gbuffer::GBufferPass;
use crate::passes::lines::{self, LinesPass, LinesScene};
use crate::passes::shadow::{self, ShadowPass};
use crate::passes::upscale::UpscalePass;
use crate::scene::SceneGpu;
use crate::style::{HATCH_SHARPNESS, RenderOptions, SPLASH_BACK_ALPHA, SPLASH_BACK_BETA, ShadowMode};
use crate::targets::{SHADOW_REDUCTION, Target, Targets};
/// Where a camera looks from, in world space (drafter-scene's, re-exported for the renderer's users).
pub use drafter_scene::camera::world_view;

/// A model on the GPU with what the camera fit needs.
#[derive(Debug)]
struct LoadedScene {
    gpu: SceneGpu,
    /// Render-space bounds.
    min: Vec3,
    max: Vec3,
    /// See [`Model::fit_points`].
    fit_points: Vec<Vec3>,
    /// See [`Model::frame_points`].
    frame_points: Vec<Vec3>,
    /// World position of the render-space origin.
    origin: glam::DVec3,
    lines: LinesScene,
    /// The parts' style hints, bit [`crate::Style::index`] each, and whether some part has none:
    /// which G-buffer pipeline a frame needs ([`crate::passes::gbuffer::frame_styles`]).
    part_hints: u32,
    unhinted_parts: bool,
}

/// The style-hint bits of a part table, and whether some part has no hint.
fn style_hints(parts: &[crate::gpu_types::PartGpu]) -> (u32, bool) {
    let mut hints = 0;
    let mut unhinted = parts.is_empty();
    for part in parts {
        match part.style_hint {
            crate::gpu_types::NO_STYLE => unhinted = true,
            k if k < 32 => hints |= 1 << k,
            _ => unhinted = true,
        }
    }
    (hints, unhinted)
}

/// Targets of one size with their bind groups.
#[derive(Debug)]
struct FrameTargets {
    targets: Targets,
    enhance: EnhanceBindings,
    display: wgpu::BindGroup,
    lines: wgpu::BindGroup,
    /// Reads `targets.output` (an interactive frame's reduced image).
    upscale: wgpu::BindGroup,
}

/// What a recorded frame used.
#[derive(Clone, Copy, Debug)]
pub struct FrameInfo {
    pub camera: Camera,
    /// Render-target size (output size × supersampling): the frame's pixels, whatever it was
    /// drawn at.
    pub target_size: (u32, u32),
    /// The size the passes drew at (and of the part-id target): `target_size`, or less for an
    /// interactive frame ([`RenderOptions::drawn_size`]).
    pub drawn_size: (u32, u32),
}

/// The passes in the order [`Renderer::encode_frame`] records them, by their module under
/// `passes/` (a frame skips the passes it does not use and keeps the order of the rest).
/// ARCHITECTURE.md states this order; `cli/tests/architecture.rs` checks the document and the
/// encoding code against this list.
pub const PASS_ORDER: &[&str] = &["gbuffer", "shadow", "enhance", "display", "lines", "upscale"];

/// The passes and the device; holds at most one model.
#[derive(Debug)]
pub struct Renderer {
    gpu: Gpu,
    frame_uniforms: wgpu::Buffer,
    gbuffer: GBufferPass,
    shadow: ShadowPass,
    enhance: EnhancePass,
    display: DisplayPass,
    lines: LinesPass,
    upscale: UpscalePass,
    scene: Option<LoadedScene>,
    targets: Option<FrameTargets>,
    /// The targets of the other size (interactive and still frames alternate while dragging:
    /// both sets are kept rather than made again at each switch).
    spare_targets: Option<FrameTargets>,
    /// Where an interactive frame is filtered up to when no output is given (headless).
    upscaled: Option<Target>,
    last_frame: Option<FrameInfo>,
    /// The shadow of the frame being recorded.
    shadow_plan: shadow::ShadowPlan,
    /// What the display and lines pipelines write: [`OUTPUT_FORMAT`] headless, the surface's
    /// format in a window (where screenshots render offscreen in the same format).
    output_format: wgpu::TextureFormat,
}

impl Renderer {
    /// A headless renderer on the default adapter (see [`Gpu::headless`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new() -> Result<Renderer, RenderError> {
        Self::with_gpu(Gpu::headless()?, crate::targets::OUTPUT_FORMAT)
    }

    /// A renderer on `gpu` whose display pass writes `output_format`.
    pub fn with_gpu(gpu: Gpu, output_format: wgpu::TextureFormat) -> Result<Renderer, RenderError> {
        let device = &gpu.device;
        let (frame_uniforms, gbuffer, shadow, enhance, display, lines) = scoped(device, || {
            let frame_uniforms = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("frame uniforms"),
                size: size_of::<FrameUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            (
                frame_uniforms,
                GBufferPass::new(device),
                ShadowPass::new(device),
                EnhancePass::new(device),
                DisplayPass::new(device, output_format),
                LinesPass::new(device, output_format),
            )
        })?;
        let upscale = scoped(device, || UpscalePass::new(device, output_format))?;
        Ok(Renderer {
            gpu,
            frame_uniforms,
            gbuffer,
            shadow,
            enhance,
            display,
            lines,
            upscale,
            scene: None,
            targets: None,
            spare_targets: None,
            upscaled: None,
            last_frame: None,
            shadow_plan: shadow::ShadowPlan { layers: Vec::new(), resolve: None },
            output_format,
        })
    }

    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// Uploads `model`, replacing the previous one.
    pub fn set_model(&mut self, model: &Model) -> Result<(), RenderError> {
        let device = &self.gpu.device;
        let queue = &self.gpu.queue;
        let (gpu, lines) = scoped(device, || {
            let gpu = SceneGpu::upload(device, queue, model, &self.gbuffer, &self.frame_uniforms);
            let lines =
                self.lines.scene(device, queue, model.lines.clone(), &self.frame_uniforms, &gpu.buffers.instances);
            (gpu, lines)
        })?;
        let min = (model.bounds.min - model.origin).as_vec3();
        let max = (model.bounds.max - model.origin).as_vec3();
        let (part_hints, unhinted_parts) = style_hints(&model.part_table());
        self.scene = Some(LoadedScene {
            gpu,
            min,
            max,
            fit_points: model.fit_points.clone(),
            frame_points: model.frame_points.clone(),
            origin: model.origin,
            lines,
            part_hints,
            unhinted_parts,
        });
        Ok(())
    }

    /// Uploads `model`'s part table again after an edit or a selection change: one write into the
    /// part table, nothing else (Lux et al. 2013 §4: no re-processing at edit time). The
    /// model must be the one [`Self::set_model`] uploaded.
    pub fn update_parts(&mut self, model: &Model) -> Result<(), RenderError> {
        let scene = self.scene.as_mut().ok_or(RenderError::NoModel)?;
        let parts = model.part_table();
        (scene.part_hints, scene.unhinted_parts) = style_hints(&parts);
        let bytes: &[u8] = bytemuck::cast_slice(&parts);
        if !scene.gpu.buffers.parts.fits(crate::table::texels_of(bytes.len())) {
            return Err(RenderError::Options(format!(
                "{} parts do not fit the uploaded part table; upload the model again",
                parts.len()
            )));
        }
        if !bytes.is_empty() {
            scene.gpu.buffers.parts.write(&self.gpu.queue, bytes);
        }
        Ok(())
    }

    /// Submits what is queued (buffer writes included) and waits until the GPU has done it all: the
    /// end of an edit's measured cost (`drafter bench parts`).
    pub fn wait_idle(&self) -> Result<(), RenderError> {
        self.gpu.queue.submit([]);
        self.gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RenderError::Gpu(e.to_string()))?;
        Ok(())
    }

    /// The texture the last frame recorded without an output ([`Self::encode_frame`] with `None`)
    /// was drawn into: the renderer's output, or for an interactive frame the one it was filtered
    /// up into. Of the target size, in the renderer's output format.
    pub fn output_texture(&self) -> Option<&wgpu::Texture> {
        match self.last_frame {
            Some(info) if info.drawn_size != info.target_size => self.upscaled.as_ref().map(|t| &t.texture),
            _ => self.targets.as_ref().map(|frame| &frame.targets.output.texture),
        }
    }

    /// The camera and size of the last frame recorded.
    pub fn last_frame(&self) -> Option<FrameInfo> {
        self.last_frame
    }

    /// The silhouettes the lines pass drew in the last frame with lines on: which edges (by
    /// instance and corner), how many queries, and how long the CPU query took.
    pub fn last_silhouettes(&self) -> Option<&crate::edges::SilhouetteFrame> {
        self.scene.as_ref().and_then(|s| s.lines.last_silhouettes())
    }

    /// Hard-edge segments of the loaded model (edges × instances).
    /// Whether the model's silhouette hierarchies wait to be built (a
    /// [`drafter_scene::Hierarchies::Deferred`] load): brute force answers until then.
    pub fn hierarchies_pending(&self) -> bool {
        self.scene.as_ref().is_some_and(|s| s.lines.lines.hierarchies_pending())
    }

    /// Builds the silhouette hierarchies a deferred load left (the lines pass's copy of the
    /// model's lines is the one every frame queries); returns the notices of any that did not
    /// validate.
    pub fn complete_hierarchies(&mut self) -> Vec<String> {
        self.complete_hierarchies_of(usize::MAX).0
    }

    /// [`Self::complete_hierarchies`] for at most `meshes` meshes; also returns how many still wait.
    pub fn complete_hierarchies_of(&mut self, meshes: usize) -> (Vec<String>, usize) {
        self.scene.as_mut().map(|s| s.lines.lines.complete_hierarchies_of(meshes)).unwrap_or_default()
    }

    pub fn hard_edge_count(&self) -> u32 {
        self.scene.as_ref().map_or(0, |s| s.lines.hard_count())
    }

    /// The G-buffer's part-id target of the last frame (the window reads it to pick parts).
    pub fn part_id_texture(&self) -> Option<&wgpu::Texture> {
        self.targets.as_ref().map(|t| &t.targets.part_id.texture)
    }

    /// Compiles, with no model loaded yet, the pipelines a first frame drawn with `options` will
    /// use (a model whose parts carry style hints may still ask for another G-buffer pipeline).
    /// A browser's GL finishes a program in the background after linking it, so the page calls
    /// this before reading its file and that work is done during the read, not at the first draw.
    pub fn warm_pipelines(&mut self, options: &RenderOptions) {
        let device = &self.gpu.device;
        self.gbuffer.compile(device, crate::passes::gbuffer::frame_styles(options, 0, true));
        self.display.compile(device, display::uniforms(options, 1.0, options.orthographic).flags);
        self.ensure_pass_pipelines(options);
    }

    /// Makes the pipelines of the passes a frame drawn with `options` uses beside the G-buffer
    /// and the display (which are specialised per frame): one place for the conditions, shared by
    /// [`Self::prepare`] and [`Self::warm_pipelines`].
    fn ensure_pass_pipelines(&mut self, options: &RenderOptions) {
        let device = &self.gpu.device;
        // A penumbra or soft shadow drawn as the hard one while dragging uses the same pipelines.
        if options.shadow != ShadowMode::None {
            self.shadow.ensure_pipelines(device);
        }
        if options.drawn_enhancements().unsharp_mask {
            self.enhance.ensure_pipeline(device);
        }
        if options.lines {
            self.lines.ensure_pipeline(device);
        }
        if options.interactive {
            self.upscale.ensure_pipeline(device);
        }
    }

    /// How many pipelines the passes have compiled so far (the shadow pass's set counting as one).
    pub fn compiled_pipelines(&self) -> usize {
        self.gbuffer.compiled()
            + self.display.compiled()
            + self.shadow.compiled()
            + self.enhance.compiled()
            + self.lines.compiled()
            + self.upscale.compiled()
    }

    /// Fits the camera for `options` and writes every pass's uniforms.
    fn prepare(&mut self, options: &RenderOptions) -> Result<FrameInfo, RenderError> {
        options.validate().map_err(RenderError::Options)?;
        self.ensure_pass_pipelines(options);
        let size = options.drawn_size();
        if self.targets.as_ref().is_some_and(|t| t.targets.size != size)
            && self.spare_targets.as_ref().is_some_and(|t| t.targets.size == size)
        {
            std::mem::swap(&mut self.targets, &mut self.spare_targets);
        }
        if self.targets.as_ref().is_none_or(|t| t.targets.size != size) {
            if self.targets.is_some() {
                self.spare_targets = self.targets.take();
            }
            let device = &self.gpu.device;
            self.targets = Some(scoped(device, || {
                let targets = Targets::new(device, size, self.output_format);
                let enhance = self.enhance.bindings(device, &targets);
                let display = self.display.bind_group(device, &targets);
                let lines = self.lines.targets_bind_group(device, &targets);
                let upscale = self.upscale.bind_group(device, &targets.output.view);
                FrameTargets { targets, enhance, display, lines, upscale }
            })?);
        }
        let scene = self.scene.as_mut().ok_or(RenderError::NoModel)?;
        let styles = crate::passes::gbuffer::frame_styles(options, scene.part_hints, scene.unhinted_parts);
        self.gbuffer.specialise(&self.gpu.device, styles);

        let (min, max) = (scene.min, scene.max);
        let light_in_render = view_rotation(options.view).inverse().transform_vector3(LIGHT_IN_VIEW.normalize());
        let layers = shadow::layers(options.shadow, min, max, light_in_render);
        // The model's hull and its shadows on the ground (every layer: a soft shadow's outer
        // layers are faint, but a shadow cut by the frame's edge shows).
        let mut frame_points = scene.frame_points.clone();
        for layer in &layers {
            frame_points.extend(scene.frame_points.iter().map(|&c| shadow::project(layer, c)));
        }
        let aspect = size.0 as f32 / size.1 as f32;
        let camera = Camera::fit(&frame_points, options.view, aspect, options.orthographic, options.fov_y_deg)
            .zoomed(options.zoom, options.pan);

        let mut flags = 0;
        if options.cel_specular {
            flags |= FLAG_CEL_SPECULAR;
        }
        if options.splash_back {
            flags |= FLAG_SPLASH_BACK;
        }
        let scale = options.pixel_scale();
        let frame = FrameUniforms {
            clip_from_render: camera.clip_from_render().to_cols_array_2d(),
            view_from_render: camera.view_from_render.to_cols_array_2d(),
            camera_position: camera.position_in_render.extend(if options.orthographic { 1.0 } else { 0.0 }).to_array(),
            light_in_view: LIGHT_IN_VIEW.normalize().extend(0.0).to_array(),
            viewport: [size.0 as f32, size.1 as f32, 1.0 / size.0 as f32, 1.0 / size.1 as f32],
            scene_style: crate::style::shader_index(options.style),
            use_part_styles: u32::from(options.use_part_styles),
            cel_steps: options.cel_steps,
            flags,
            style_params: [SPLASH_BACK_ALPHA, SPLASH_BACK_BETA, options.hatch_period_px * scale, HATCH_SHARPNESS],
        };
        let queue = &self.gpu.queue;
        queue.write_buffer(&self.frame_uniforms, 0, bytemuck::bytes_of(&frame));
        self.gbuffer.prepare(queue, &scene.gpu.lookups, options);
        let mask_size = (size.0.div_ceil(SHADOW_REDUCTION), size.1.div_ceil(SHADOW_REDUCTION));
        // While the window drags, a penumbra or soft shadow is drawn as the hard one (one layer
        // instead of many: measured on lavapipe, a soft shadow held orbiting at 4 frames/s); the
        // framing above keeps the real mode's layers, so nothing jumps on release.
        let drawn_shadow = match options.shadow {
            ShadowMode::Penumbra | ShadowMode::Soft if options.interactive => ShadowMode::Hard,
            mode => mode,
        };
        let drawn_layers;
        let layers = if drawn_shadow == options.shadow {
            &layers
        } else {
            drawn_layers = shadow::layers(drawn_shadow, min, max, light_in_render);
            &drawn_layers
        };
        let plan = shadow::plan(drawn_shadow, layers, camera.clip_from_render(), &scene.fit_points, mask_size);
        self.shadow.prepare(queue, &plan);
        let radius = (max - min).length() * 0.5;
        self.enhance
            .prepare(queue, &EnhanceSetup { height: size.1, far_depth: camera.view_depth(Vec3::ZERO) + radius * 1.5 });
        self.display.prepare(&self.gpu.device, queue, &display::uniforms(options, radius, options.orthographic));
        let info = FrameInfo { camera, target_size: options.target_size(), drawn_size: size };
        self.last_frame = Some(info);
        self.shadow_plan = plan;
        Ok(info)
    }

    /// The lines pass's share of [`Self::prepare`], apart so that [`Self::submit_frame`] can hand
    /// the other passes to the GPU first: this frame's silhouettes (found on the CPU) and the
    /// pass's uniforms.
    fn prepare_lines(&mut self, options: &RenderOptions, info: &FrameInfo) -> Result<(), RenderError> {
        if !options.lines {
            return Ok(());
        }
        let scene = self.scene.as_mut().ok_or(RenderError::NoModel)?;
        let view = world_view(&info.camera, scene.origin);
        let silhouettes = scene.lines.lines.silhouettes(view);
        let uniforms = lines::uniforms(options, &info.camera, info.drawn_size.1);
        self.lines.prepare(&self.gpu.device, &self.gpu.queue, &mut scene.lines, &uniforms, silhouettes);
        Ok(())
    }

    /// Records a whole frame for `options` into `encoder`, the display pass writing `output`
    /// (`None`: the renderer's own output texture, of the target size). An interactive frame is
    /// drawn into the renderer's reduced targets and filtered up into `output` (`None`: a
    /// texture of the renderer's, which [`Self::render`] reads back).
    pub fn encode_frame(
        &mut self,
        options: &RenderOptions,
        encoder: &mut wgpu::CommandEncoder,
        output: Option<&wgpu::TextureView>,
    ) -> Result<FrameInfo, RenderError> {
        let info = self.prepare(options)?;
        self.encode_surface_passes(options, encoder, output)?;
        self.prepare_lines(options, &info)?;
        self.encode_line_passes(options, encoder, output)?;
        Ok(info)
    }

    /// [`Self::encode_frame`] recorded and submitted in two command buffers: the passes before the
    /// lines first, then this frame's silhouettes are found and the lines (and an interactive
    /// frame's filter) follow. The GPU draws the surfaces while this thread finds the silhouettes,
    /// where one command buffer would wait for them: the browser's page, whose silhouettes of a
    /// first frame are found by brute force on the thread that draws (a GL queue flushes its
    /// commands at each submit). The same frame as [`Self::encode_frame`]'s.
    pub fn submit_frame(
        &mut self,
        options: &RenderOptions,
        output: Option<&wgpu::TextureView>,
    ) -> Result<FrameInfo, RenderError> {
        let device = self.gpu.device.clone();
        let encoder = |label| device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        let info = self.prepare(options)?;
        let mut frame = encoder("frame");
        self.encode_surface_passes(options, &mut frame, output)?;
        // Without lines there are no silhouettes to wait for: one submit (each flushes the GL queue).
        if options.lines {
            self.gpu.queue.submit([frame.finish()]);
            frame = encoder("frame lines");
        }
        self.prepare_lines(options, &info)?;
        self.encode_line_passes(options, &mut frame, output)?;
        self.gpu.queue.submit([frame.finish()]);
        Ok(info)
    }

    /// The view the display and lines passes draw into: an interactive frame's reduced output
    /// (filtered up into `output` afterwards), else `output` or the renderer's own.
    fn drawn_view<'a>(
        targets: &'a Targets,
        options: &RenderOptions,
        output: Option<&'a wgpu::TextureView>,
    ) -> &'a wgpu::TextureView {
        if options.interactive { &targets.output.view } else { output.unwrap_or(&targets.output.view) }
    }

    /// The G-buffer, shadow, enhance and display passes of a prepared frame.
    fn encode_surface_passes(
        &mut self,
        options: &RenderOptions,
        encoder: &mut wgpu::CommandEncoder,
        output: Option<&wgpu::TextureView>,
    ) -> Result<(), RenderError> {
        let info = self.last_frame.ok_or(RenderError::NoModel)?;
        if options.interactive && output.is_none() {
            self.ensure_upscaled(info.target_size)?;
        }
        let (Some(scene), Some(frame)) = (self.scene.as_ref(), self.targets.as_ref()) else {
            return Err(RenderError::NoModel);
        };
        let targets = &frame.targets;
        self.gbuffer.encode(encoder, targets, &scene.gpu, options.enhanced_normals);
        if options.shadow != ShadowMode::None {
            self.shadow.encode(encoder, targets, &scene.gpu, &self.shadow_plan);
        }
        if options.drawn_enhancements().unsharp_mask {
            self.enhance.encode(encoder, targets, &frame.enhance);
        }
        self.display.encode(encoder, &frame.display, Self::drawn_view(targets, options, output));
        Ok(())
    }

    /// The lines pass (its silhouettes prepared) and an interactive frame's filter, after
    /// [`Self::encode_surface_passes`].
    fn encode_line_passes(
        &self,
        options: &RenderOptions,
        encoder: &mut wgpu::CommandEncoder,
        output: Option<&wgpu::TextureView>,
    ) -> Result<(), RenderError> {
        let (Some(scene), Some(frame)) = (self.scene.as_ref(), self.targets.as_ref()) else {
            return Err(RenderError::NoModel);
        };
        if options.lines {
            let drawn = Self::drawn_view(&frame.targets, options, output);
            self.lines.encode(encoder, &scene.lines, &frame.lines, drawn);
        }
        if options.interactive {
            let output = output.or(self.upscaled.as_ref().map(|t| &t.view)).ok_or(RenderError::NoModel)?;
            self.upscale.encode(encoder, &frame.upscale, output);
        }
        Ok(())
    }

    /// Makes the headless output of interactive frames `size` large.
    fn ensure_upscaled(&mut self, size: (u32, u32)) -> Result<(), RenderError> {
        if self.upscaled.as_ref().is_none_or(|t| (t.texture.width(), t.texture.height()) != size) {
            let device = &self.gpu.device;
            let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
            self.upscaled =
                Some(scoped(device, || Target::new(device, "upscaled output", size, self.output_format, usage))?);
        }
        Ok(())
    }

    /// Renders one frame offscreen and reads it back, down-sampled to `options.size`.
    pub fn render(&mut self, options: &RenderOptions) -> Result<Image, RenderError> {
        let readback = self.submit_render(options)?;
        map_blocking(&self.gpu.device, &readback.buffer)?;
        readback.image()
    }

    /// Records and submits one offscreen frame and its copy into a buffer, which the caller maps
    /// for reading ([`Readback::buffer`]; [`Self::render`] waits for it, the browser awaits it)
    /// and then reads with [`Readback::image`].
    pub fn submit_render(&mut self, options: &RenderOptions) -> Result<Readback, RenderError> {
        use wgpu::TextureFormat as F;
        let swap_red_blue = match self.output_format {
            F::Rgba8Unorm | F::Rgba8UnormSrgb => false,
            F::Bgra8Unorm | F::Bgra8UnormSrgb => true,
            other => return Err(RenderError::Gpu(format!("cannot read back {other:?} pixels as RGBA8"))),
        };
        let device = self.gpu.device.clone();
        let guard = ErrorScopes::push(&device);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("render frame") });
        let info = self.encode_frame(options, &mut encoder, None)?;
        let (w, h) = info.target_size;
        let bytes_per_row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("render readback"),
            size: u64::from(bytes_per_row) * u64::from(h),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let source = if options.interactive {
            self.upscaled.as_ref()
        } else {
            self.targets.as_ref().map(|frame| &frame.targets.output)
        };
        let Some(source) = source else { return Err(RenderError::NoModel) };
        encoder.copy_texture_to_buffer(
            source.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(bytes_per_row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        self.gpu.queue.submit([encoder.finish()]);
        guard.pop()?;
        Ok(Readback { buffer, bytes_per_row, size: (w, h), swap_red_blue, supersample: options.supersample })
    }

    /// The part drawn at target pixel (`x`, `y`) of the last frame (the G-buffer's part-id target,
    /// read back), `None` for the background or outside the frame. After an interactive frame the
    /// pixel is looked up in its reduced part ids.
    pub fn pick(&self, x: u32, y: u32) -> Result<Option<u32>, RenderError> {
        let Some(frame) = self.targets.as_ref() else { return Ok(None) };
        let (w, h) = frame.targets.size;
        let (x, y) = match self.last_frame {
            Some(info) if info.drawn_size != info.target_size => (
                (u64::from(x) * u64::from(info.drawn_size.0) / u64::from(info.target_size.0.max(1))) as u32,
                (u64::from(y) * u64::from(info.drawn_size.1) / u64::from(info.target_size.1.max(1))) as u32,
            ),
            _ => (x, y),
        };
        if x >= w || y >= h {
            return Ok(None);
        }
        let ids = self.read_part_ids(x, y, 1, 1)?;
        Ok(ids[0].checked_sub(1))
    }

    /// The part id of every pixel of the last frame: what tests compare two renders by.
    pub fn part_map(&self) -> Result<Option<PartMap>, RenderError> {
        let Some(frame) = self.targets.as_ref() else { return Ok(None) };
        let (w, h) = frame.targets.size;
        let ids = self.read_part_ids(0, 0, w, h)?;
        Ok(Some(PartMap { size: (w, h), ids: ids.into_iter().map(|id| id.checked_sub(1)).collect() }))
    }

    /// The part-id target's texels (id + 1; 0 is the background) in a `w`×`h` region at (x, y).
    fn read_part_ids(&self, x: u32, y: u32, w: u32, h: u32) -> Result<Vec<u32>, RenderError> {
        let Some(frame) = self.targets.as_ref() else { return Ok(Vec::new()) };
        let device = &self.gpu.device;
        let guard = ErrorScopes::push(device);
        let bytes_per_row = (w * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("part id readback"),
            size: u64::from(bytes_per_row) * u64::from(h),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pick") });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &frame.targets.part_id.texture,
                mip_level: 0,
                origin: wgpu::Origin3d { x, y, z: 0 },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(bytes_per_row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        self.gpu.queue.submit([encoder.finish()]);
        map_blocking(device, &readback)?;
        let bytes = rows(&readback, bytes_per_row, w, h)?;
        guard.pop()?;
        Ok(bytes.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect())
    }

    /// Records, submits and waits for one frame without reading it back; the wall time from
    /// recording to completion (the benchmark's measure).
    pub fn time_frame(&mut self, options: &RenderOptions) -> Result<Duration, RenderError> {
        let device = self.gpu.device.clone();
        let start = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("timed frame") });
        self.encode_frame(options, &mut encoder, None)?;
        self.gpu.queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RenderError::Gpu(e.to_string()))?;
        Ok(start.elapsed())
    }
}

/// Maps `buffer` and copies `height` rows of `width × 4` bytes out of its padded rows.
/// Maps `buffer` for reading and waits for it (natively; the browser cannot wait).
fn map_blocking(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<(), RenderError> {
    let (sender, receiver) = std::sync::mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, .., move |result| {
        let _ = sender.send(result);
    });
    device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| RenderError::Gpu(e.to_string()))?;
    receiver.recv().map_err(|e| RenderError::Gpu(e.to_string()))?.map_err(|e| RenderError::Gpu(e.to_string()))
}

/// The first `width * 4` bytes of each of `height` rows of a mapped `buffer`; unmaps it.
fn rows(buffer: &wgpu::Buffer, bytes_per_row: u32, width: u32, height: u32) -> Result<Vec<u8>, RenderError> {
    let mut out = Vec::with_capacity((width * height * 4) as usize);
    {
        let view = buffer.get_mapped_range(..).map_err(|e| RenderError::Gpu(e.to_string()))?;
        for row in view.chunks(bytes_per_row as usize).take(height as usize) {
            out.extend_from_slice(&row[..(width * 4) as usize]);
        }
    }
    buffer.unmap();
    Ok(out)
}

/// A submitted offscreen frame on its way back ([`Renderer::submit_render`]).
#[derive(Debug)]
pub struct Readback {
    buffer: wgpu::Buffer,
    bytes_per_row: u32,
    size: (u32, u32),
    swap_red_blue: bool,
    supersample: u32,
}

impl Readback {
    /// The buffer to map for reading.
    pub fn buffer(&self) -> &wgpu::Buffer {
        &self.buffer
    }

    /// The frame, down-sampled to the options' size, once the buffer is mapped.
    pub fn image(self) -> Result<Image, RenderError> {
        let (width, height) = self.size;
        let mut rgba = rows(&self.buffer, self.bytes_per_row, width, height)?;
        if self.swap_red_blue {
            rgba.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        Ok(Image { width, height, rgba }.downsample(self.supersample))
    }
}

/// The part drawn at each pixel of a frame ([`Renderer::part_map`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartMap {
    /// Width and height of the target.
    pub size: (u32, u32),
    /// Row by row; `None` for the background.
    pub ids: Vec<Option<u32>>,
}

/// Validation and out-of-memory error scopes, so GPU errors come back as [`RenderError::Gpu`]
/// instead of the default handler's panic.
struct ErrorScopes {
    out_of_memory: wgpu::ErrorScopeGuard,
    validation: wgpu::ErrorScopeGuard,
}

impl ErrorScopes {
    fn push(device: &wgpu::Device) -> ErrorScopes {
        let out_of_memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        ErrorScopes { out_of_memory, validation }
    }

    fn pop(self) -> Result<(), RenderError> {
        let validation = settle(self.validation.pop());
        let out_of_memory = settle(self.out_of_memory.pop());
        match validation.or(out_of_memory) {
            Some(e) => Err(RenderError::Gpu(e.to_string())),
            None => Ok(()),
        }
    }
}

/// The error a popped scope reports. Natively it blocks until the device answers. In the browser
/// nothing may block: WebGL2 (wgpu-core) answers at once; a WebGPU answer still pending after one
/// poll is awaited on the page's event loop and, if it is an error, written to the console (which
/// the page and its tests watch), since the frame that caused it has already returned.
#[cfg(not(target_arch = "wasm32"))]
fn settle(pop: impl std::future::Future<Output = Option<wgpu::Error>>) -> Option<wgpu::Error> {
    pollster::block_on(pop)
}

#[cfg(target_arch = "wasm32")]
fn settle(pop: impl std::future::Future<Output = Option<wgpu::Error>> + 'static) -> Option<wgpu::Error> {
    let mut pop = Box::pin(pop);
    match pop.as_mut().poll(&mut std::task::Context::from_waker(std::task::Waker::noop())) {
        std::task::Poll::Ready(error) => error,
        std::task::Poll::Pending => {
            report_later(pop);
            None
        }
    }
}

#[cfg(target_arch = "wasm32")]
fn report_later(pop: std::pin::Pin<Box<dyn std::future::Future<Output = Option<wgpu::Error>>>>) {
    wasm_bindgen_futures::spawn_local(async move {
        if let Some(error) = pop.await {
            web_sys::console::error_1(&format!("drafter: GPU error: {error}").into());
        }
    });
}

/// Runs `f` inside error scopes.
fn scoped<T>(device: &wgpu::Device, f: impl FnOnce() -> T) -> Result<T, RenderError> {
    let scopes = ErrorScopes::push(device);
    let value = f();
    scopes.pop()?;
    Ok(value)
}
