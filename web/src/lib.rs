//! drafter's viewer in the browser: the renderer (`drafter-render`, which names no window crate)
//! compiled to WebAssembly, drawing into a canvas through WebGPU, or WebGL2 where the
//! browser has no WebGPU adapter. The same passes and WGSL as `drafter render` and `drafter view`;
//! only the device request (asynchronous here) and the surface are the browser's.
//!
//! The page (`web/page/`) owns the DOM: it reads the file (a URL or a dropped file), turns mouse,
//! wheel and key events into the calls below, and asks for a frame when something changed. The
//! view controls are the desktop window's own ([`drafter_render::controls`]), so a drag, the wheel and
//! the keys do here what they do in `drafter view`. Editing stays in the desktop window (drafter-app).
//!
//! Everything here is wasm32-only: natively this crate is empty (`cargo build --workspace` builds
//! it without any of the browser's crates). Built by `scripts/web`.
#![cfg(target_arch = "wasm32")]

use std::path::Path;

use drafter_render::controls::{Action, Orbit, PIXELS_PER_LINE, action_for_char};
use drafter_render::edges::Hierarchies;
use drafter_render::{Enhancements, Gpu, Model, RenderOptions, Renderer, ShadowMode, Style};
use wasm_bindgen::prelude::*;

/// Reports panics on the console (the page shows the last console error too).
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        web_sys::console::error_1(&format!("drafter: {info}").into());
    }));
}

/// The event a lost device fires on the window: `detail` is a [`DeviceLoss`] (the page re-creates
/// that viewer on WebGL2).
pub const DEVICE_LOST_EVENT: &str = "drafter-device-lost";

/// The `detail` of a [`DEVICE_LOST_EVENT`].
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug)]
pub struct DeviceLoss {
    /// The lost viewer's [`Viewer::id`].
    #[wasm_bindgen(readonly)]
    pub id: u32,
    /// wgpu's reason, as its name (`Destroyed`, `Unknown`).
    #[wasm_bindgen(readonly)]
    pub reason: String,
    /// The browser's message.
    #[wasm_bindgen(readonly)]
    pub message: String,
}

/// What [`Viewer::load`] read. Field names are the page's (camelCase).
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug)]
pub struct Summary {
    /// The file's name, as given.
    #[wasm_bindgen(readonly)]
    pub name: String,
    #[wasm_bindgen(readonly)]
    pub triangles: u32,
    #[wasm_bindgen(readonly)]
    pub parts: u32,
    /// Baked hard edges (creases and boundaries) the lines pass draws.
    #[wasm_bindgen(readonly, js_name = hardEdges)]
    pub hard_edges: u32,
    /// The file carries `DRAFTER_illustration` data.
    #[wasm_bindgen(readonly)]
    pub baked: bool,
    /// The file carries baked lines for the lines pass.
    #[wasm_bindgen(readonly)]
    pub lines: bool,
    /// What the load noted (textures baked or computed, parts, …), one line each.
    #[wasm_bindgen(readonly)]
    pub notices: Vec<String>,
    /// Milliseconds reading the file into the CPU model.
    #[wasm_bindgen(readonly, js_name = readMs)]
    pub read_ms: f64,
    /// Milliseconds uploading it.
    #[wasm_bindgen(readonly, js_name = uploadMs)]
    pub upload_ms: f64,
}

/// The frame's settings ([`Viewer::state`]).
#[wasm_bindgen(getter_with_clone)]
#[derive(Clone, Debug)]
pub struct ViewState {
    /// The scene's style by name (`gradient`, `phong`, …).
    #[wasm_bindgen(readonly)]
    pub style: String,
    #[wasm_bindgen(readonly)]
    pub edges: bool,
    #[wasm_bindgen(readonly)]
    pub lines: bool,
    /// The drop shadow by name (`none`, `hard`, `penumbra`, `soft`).
    #[wasm_bindgen(readonly)]
    pub shadow: String,
    #[wasm_bindgen(readonly)]
    pub orthographic: bool,
    #[wasm_bindgen(readonly)]
    pub azimuth: f32,
    #[wasm_bindgen(readonly)]
    pub elevation: f32,
    #[wasm_bindgen(readonly)]
    pub zoom: f32,
    /// The pan, in the orbit's units, x and y.
    #[wasm_bindgen(readonly, js_name = panX)]
    pub pan_x: f32,
    #[wasm_bindgen(readonly, js_name = panY)]
    pub pan_y: f32,
    /// The frame's size in canvas pixels.
    #[wasm_bindgen(readonly)]
    pub width: u32,
    #[wasm_bindgen(readonly)]
    pub height: u32,
}

/// Where [`Viewer::create`]'s time went, in milliseconds.
#[wasm_bindgen]
#[derive(Clone, Copy, Debug)]
pub struct Startup {
    /// The instance, with WebGPU's detection where it may be used.
    #[wasm_bindgen(readonly)]
    pub instance: f64,
    /// The canvas's context.
    #[wasm_bindgen(readonly)]
    pub surface: f64,
    #[wasm_bindgen(readonly)]
    pub adapter: f64,
    #[wasm_bindgen(readonly)]
    pub device: f64,
    /// The passes' shaders and layouts (pipelines compile at the first frame that uses them).
    #[wasm_bindgen(readonly)]
    pub renderer: f64,
}

/// What a typed key did ([`Viewer::key`]).
#[wasm_bindgen]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeyEffect {
    /// The key means nothing here.
    Nothing = 0,
    /// The frame changed: draw again.
    Redraw = 1,
    /// `p`: the page saves the canvas.
    Screenshot = 2,
}

/// The next [`Viewer::id`].
static NEXT_ID: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(1);

/// Tells the page that viewer `id` lost its GPU device: a [`DEVICE_LOST_EVENT`] on the window,
/// and a warning on the console.
fn announce_device_loss(id: u32, reason: wgpu::DeviceLostReason, message: &str) {
    let reason = format!("{reason:?}");
    web_sys::console::warn_1(&format!("drafter: the GPU device was lost ({reason}): {message}").into());
    let detail = DeviceLoss { id, reason, message: message.to_owned() };
    let init = web_sys::CustomEventInit::new();
    init.set_detail(&JsValue::from(detail));
    if let (Some(window), Ok(event)) =
        (web_sys::window(), web_sys::CustomEvent::new_with_event_init_dict(DEVICE_LOST_EVENT, &init))
    {
        let _ = window.dispatch_event(&event);
    }
}

/// A renderer on one canvas, with at most one model.
#[wasm_bindgen]
#[derive(Debug)]
pub struct Viewer {
    id: u32,
    renderer: Renderer,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    options: RenderOptions,
    orbit: Orbit,
    model: Option<Model>,
    backend: String,
    /// Milliseconds of [`Viewer::create`]'s steps.
    startup: Startup,
}

/// Resolves on a later task of the page's event loop (`setTimeout(…, 0)`).
async fn next_task() -> Result<(), JsError> {
    let window = web_sys::window().ok_or_else(|| js_error("no window"))?;
    let mut scheduled = Ok(0);
    let promise = js_sys::Promise::new(&mut |resolve, _| {
        scheduled = window.set_timeout_with_callback(&resolve);
    });
    scheduled.map_err(|_| js_error("setTimeout failed"))?;
    wasm_bindgen_futures::JsFuture::from(promise).await.map_err(|_| js_error("the page's timer failed"))?;
    Ok(())
}

fn js_error(e: impl std::fmt::Display) -> JsError {
    JsError::new(&e.to_string())
}

/// Milliseconds to a tenth.
fn ms(d: std::time::Duration) -> f64 {
    (d.as_secs_f64() * 1e4).round() / 10.0
}

/// A count for the page (JavaScript numbers; a model this large was refused long before).
fn saturating_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

#[wasm_bindgen]
impl Viewer {
    /// A viewer drawing into `canvas`. `backend`: `"webgpu"`, `"webgl2"`, or anything else for
    /// WebGPU where the browser gives an adapter and WebGL2 otherwise.
    pub async fn create(canvas: web_sys::HtmlCanvasElement, backend: &str) -> Result<Viewer, JsError> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let start = web_time::Instant::now();
        let backends = match backend {
            "webgpu" => wgpu::Backends::BROWSER_WEBGPU,
            "webgl2" => wgpu::Backends::GL,
            _ => wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL,
        };
        let descriptor =
            wgpu::InstanceDescriptor { backends, ..wgpu::InstanceDescriptor::new_without_display_handle() };
        // WebGPU only where an adapter answers: `navigator.gpu` alone does not promise one.
        let instance = wgpu::util::new_instance_with_webgpu_detection(descriptor).await;
        let instanced = start.elapsed();
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| js_error(format!("cannot draw into the canvas: {e}")))?;
        let surfaced = start.elapsed();
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await
            .map_err(|e| js_error(format!("this browser gives no WebGPU or WebGL2 adapter: {e}")))?;
        let adapted = start.elapsed();
        let capabilities = surface.get_capabilities(&adapter);
        // As the window does: display values end to end, so a non-sRGB 8-bit surface.
        let format = [wgpu::TextureFormat::Rgba8Unorm, wgpu::TextureFormat::Bgra8Unorm]
            .into_iter()
            .find(|f| capabilities.formats.contains(f))
            .or_else(|| capabilities.formats.iter().copied().find(|f| !f.is_srgb()))
            .or_else(|| capabilities.formats.first().copied())
            .ok_or_else(|| js_error("the canvas supports no texture format"))?;
        let gpu = Gpu::request(instance, adapter).await.map_err(js_error)?;
        let requested = start.elapsed();
        // A lost device draws nothing and fails every read: the page hears of it (and re-creates
        // the viewer on WebGL2) through an event on the window.
        let id = NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        gpu.device.set_device_lost_callback(move |reason, message| announce_device_loss(id, reason, &message));
        let backend = gpu.description();
        let interactive_scale = gpu.interactive_scale();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width,
            height,
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: capabilities.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let renderer = Renderer::with_gpu(gpu, format).map_err(js_error)?;
        let startup = Startup {
            instance: ms(instanced),
            surface: ms(surfaced - instanced),
            adapter: ms(adapted - surfaced),
            device: ms(requested - adapted),
            renderer: ms(start.elapsed() - requested),
        };
        let options = RenderOptions { size: (width, height), interactive_scale, ..RenderOptions::default() };
        Ok(Viewer { id, renderer, surface, config, options, orbit: Orbit::default(), model: None, backend, startup })
    }

    /// Where [`Viewer::create`]'s time went.
    pub fn startup(&self) -> Startup {
        self.startup
    }

    /// This viewer's number on the page: the `id` of its [`DEVICE_LOST_EVENT`].
    pub fn id(&self) -> u32 {
        self.id
    }

    /// Destroys the GPU device, as a browser that loses it does (for tests of the page's
    /// fallback): the device-lost event follows.
    pub fn lose_device(&self) {
        self.renderer.gpu().device.destroy();
    }

    /// Line widths in CSS pixels: `ratio` is the canvas's pixels per CSS pixel (the browser's
    /// `devicePixelRatio` when the canvas fills its box), clamped to 0.25–8.
    pub fn set_line_scale(&mut self, ratio: f32) {
        self.options.line_scale = if ratio.is_finite() { ratio.clamp(0.25, 8.0) } else { 1.0 };
    }

    /// The adapter: "name (backend, device type)".
    pub fn backend(&self) -> String {
        self.backend.clone()
    }

    /// Loads a model from its bytes (`name` for messages and to tell the format); refuses one that
    /// lists more than `max_triangles` triangles. The view is reset; the style and the other
    /// settings are kept.
    pub fn load(&mut self, bytes: &[u8], name: &str, max_triangles: f64) -> Result<Summary, JsError> {
        let limits = drafter_io::Limits { max_triangles: max_triangles.max(0.0) as u64 };
        let start = web_time::Instant::now();
        // The silhouette hierarchies wait until the first frame is on screen (`complete_load`).
        let model = Model::load_bytes_with(Path::new(name), bytes, &limits, Hierarchies::Deferred).map_err(js_error)?;
        let read = start.elapsed();
        self.renderer.set_model(&model).map_err(js_error)?;
        let uploaded = start.elapsed();
        self.orbit = Orbit::default();
        let summary = Summary {
            name: name.to_owned(),
            triangles: saturating_u32(model.triangle_count()),
            parts: saturating_u32(model.parts.len()),
            hard_edges: self.renderer.hard_edge_count(),
            baked: model.baked,
            lines: !model.lines.is_empty(),
            notices: model.notices.clone(),
            read_ms: ms(read),
            upload_ms: ms(uploaded - read),
        };
        self.model = Some(model);
        Ok(summary)
    }

    /// Builds part of what [`Viewer::load`] left for after the first frame: the silhouette
    /// hierarchies of the next mesh that waits (they answer later frames' silhouettes faster than
    /// brute force does; frames drawn before are the same, only slower to find). Returns how
    /// many meshes still wait, so the page calls it again on a later task, between input events.
    pub fn complete_load(&mut self) -> u32 {
        let (notices, left) = self.renderer.complete_hierarchies_of(1);
        for notice in notices {
            web_sys::console::warn_1(&notice.into());
        }
        left as u32
    }

    /// Follows the canvas's new size in pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        let (width, height) = (width.max(1), height.max(1));
        if (width, height) != (self.config.width, self.config.height) {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.renderer.gpu().device, &self.config);
        }
        self.options.size = (width, height);
    }

    /// Draws a frame into the canvas; `interactive`: the reduced frame of a drag (see
    /// `RenderOptions::interactive`). Returns the milliseconds spent recording and submitting (the
    /// browser draws after this returns).
    pub fn render(&mut self, interactive: bool) -> Result<f64, JsError> {
        if self.model.is_none() {
            return Err(js_error("no model loaded"));
        }
        let start = web_time::Instant::now();
        self.orbit.apply(&mut self.options);
        self.options.interactive = interactive;
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            _ => {
                self.surface.configure(&self.renderer.gpu().device, &self.config);
                return Ok(0.0);
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        // In two submits: SwiftShader draws the surfaces while the silhouettes are found.
        self.renderer.submit_frame(&self.options, Some(&view)).map_err(js_error)?;
        self.renderer.gpu().queue.present(frame);
        Ok(start.elapsed().as_secs_f64() * 1e3)
    }

    /// Turns the object by a drag of (`dx`, `dy`) CSS pixels, as the window's left drag does.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        self.orbit.rotate(dx, dy);
    }

    /// Pans by a drag of (`dx`, `dy`) canvas pixels (right or middle drag).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        self.orbit.pan_by(dx, dy, self.options.size);
    }

    /// Zooms by a wheel movement of `pixels` (positive: closer).
    pub fn zoom(&mut self, pixels: f32) {
        self.orbit.zoom_by(pixels / PIXELS_PER_LINE);
    }

    /// Sets the view: azimuth and elevation in degrees, and the zoom (as `drafter render --view`).
    pub fn set_view(&mut self, azimuth_deg: f32, elevation_deg: f32, zoom: f32) {
        self.orbit.view.azimuth_deg = azimuth_deg;
        self.orbit.view.elevation_deg = elevation_deg;
        self.orbit.zoom = zoom;
        self.orbit.pan = [0.0, 0.0];
    }

    /// What a typed key does, as in the window (`1`–`7` styles, `s` next style, `e` edges, `l`
    /// lines, `h` next shadow, `o` orthographic, `r` reset, `p` screenshot).
    pub fn key(&mut self, key: &str) -> KeyEffect {
        let mut chars = key.chars();
        let (Some(c), None) = (chars.next(), chars.next()) else { return KeyEffect::Nothing };
        match action_for_char(c) {
            Some(Action::Screenshot) => KeyEffect::Screenshot,
            Some(Action::Quit) | None => KeyEffect::Nothing,
            Some(action) => {
                action.apply(&mut self.options, &mut self.orbit);
                KeyEffect::Redraw
            }
        }
    }

    /// Compiles the pipelines of a first frame in `style` with edges, lines and `shadow` as given,
    /// before a model is loaded (`Renderer::warm_pipelines`): the page calls it before reading its
    /// file, so the browser's GPU process compiles them during the read. The settings stay as they
    /// were.
    pub fn warm_pipelines(&mut self, style: &str, edges: bool, lines: bool, shadow: &str) -> Result<(), JsError> {
        let saved = self.options.clone();
        let set = self.set_style(style).and_then(|()| self.set_shadow(shadow));
        self.set_edges(edges);
        self.set_lines(lines);
        let options = std::mem::replace(&mut self.options, saved);
        set?;
        self.renderer.warm_pipelines(&options);
        Ok(())
    }

    /// Sets the scene's style by name (`gradient`, `phong`, `cel`, `gooch`, `goochel`, `metal`,
    /// `hatch`).
    pub fn set_style(&mut self, name: &str) -> Result<(), JsError> {
        self.options.style = name.parse::<Style>().map_err(js_error)?;
        Ok(())
    }

    /// Image-space edges (outlines, creases, the depth unsharp mask) on or off.
    pub fn set_edges(&mut self, on: bool) {
        self.options.enhancements = if on { Enhancements::ALL } else { Enhancements::default() };
    }

    /// The baked lines with this view's silhouettes on or off.
    pub fn set_lines(&mut self, on: bool) {
        self.options.lines = on;
    }

    /// The drop shadow: `none`, `hard`, `penumbra` or `soft`.
    pub fn set_shadow(&mut self, name: &str) -> Result<(), JsError> {
        self.options.shadow = ShadowMode::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| js_error(format!("unknown shadow '{name}'")))?;
        Ok(())
    }

    /// Orthographic projection on or off.
    pub fn set_orthographic(&mut self, on: bool) {
        self.options.orthographic = on;
    }

    /// Renders the view offscreen, into the renderer's own target as `drafter render` does, and
    /// returns its RGBA bytes row by row (width × height × 4, the canvas's size). For a canvas
    /// that cannot be read back (a WebGPU canvas's texture is gone once presented) or must not be
    /// presented (headless Chromium on SwiftShader loses its WebGPU device when one is: the
    /// page's `offscreen` attribute, docs/web.md).
    pub async fn capture(&mut self) -> Result<Vec<u8>, JsError> {
        if self.model.is_none() {
            return Err(js_error("no model loaded"));
        }
        self.orbit.apply(&mut self.options);
        self.options.interactive = false;
        let readback = self.renderer.submit_render(&self.options).map_err(js_error)?;
        let mapped = std::rc::Rc::new(std::cell::RefCell::new(None));
        let answer = mapped.clone();
        readback.buffer().map_async(wgpu::MapMode::Read, .., move |result| {
            *answer.borrow_mut() = Some(result);
        });
        let device = self.renderer.gpu().device.clone();
        // WebGL2 maps when polled; WebGPU when the browser's promise resolves, on a later task.
        loop {
            let _ = device.poll(wgpu::PollType::Poll);
            if let Some(result) = mapped.borrow_mut().take() {
                result.map_err(js_error)?;
                break;
            }
            next_task().await?;
        }
        Ok(readback.image().map_err(js_error)?.rgba)
    }

    /// The frame's settings.
    pub fn state(&self) -> ViewState {
        ViewState {
            style: self.options.style.name().to_owned(),
            edges: self.options.enhancements.any(),
            lines: self.options.lines,
            shadow: self.options.shadow.name().to_owned(),
            orthographic: self.options.orthographic,
            azimuth: self.orbit.view.azimuth_deg,
            elevation: self.orbit.view.elevation_deg,
            zoom: self.orbit.zoom,
            pan_x: self.orbit.pan[0],
            pan_y: self.orbit.pan[1],
            width: self.options.size.0,
            height: self.options.size.1,
        }
    }
}
