//! The interactive window (`drafter view FILE`): the renderer's frame in a winit 0.30 window.
//!
//! # Controls
//! * left drag: turn the *object* (Gooch et al. 1999, §4.1: the viewer and the light stay put, so
//!   the cool-to-warm shading sweeps over the surface as it turns). For one frame that is the
//!   camera orbiting the other way with the light fixed to it, which is how the renderer draws it
//!   ([`crate::camera`]): dragging right turns the object's front to the right.
//! * wheel: zoom about the frame's centre; right or middle drag: pan.
//! * `1`–`7`: style (gradient, cel, gooch, goochel, phong, metal, hatch); `S`: next style.
//! * `E` image-space edges, `L` baked lines, `H` next drop shadow (none, hard, penumbra, soft),
//!   `O` orthographic, `R` reset the view.
//! * left click (no drag): pick the part under the cursor (the G-buffer's part-id target read
//!   back); its name and parameters are printed and shown in the title, and it is highlighted.
//! * `P`: save a screenshot PNG (`<file stem>-<n>.png` beside the model, at the window's size with
//!   2× supersampling; the path is printed).
//! * `Esc` / `Q`: quit.
//!
//! Everything an event changes goes through pure functions ([`Orbit`], [`action_for_key`],
//! [`Action::apply`]) that are unit-tested without a display; the event loop only routes events
//! to them and draws.
//!
//! Without a display (no `DISPLAY` on X11) [`run`] returns [`WindowError::NoDisplay`] before any
//! GPU work.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use winit::application::ApplicationHandler;
use winit::dpi::PhysicalPosition;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use crate::context::{Gpu, RenderError};
use crate::model::Model;
use crate::renderer::Renderer;
use crate::style::{Enhancements, RenderOptions, ShadowMode, Style, View, ZOOM_RANGE};

/// Degrees the object turns per pixel of drag.
pub const DEGREES_PER_PIXEL: f32 = 0.4;
/// Zoom factor per wheel line.
pub const ZOOM_PER_LINE: f32 = 1.1;
/// Pixels of wheel movement counted as one line (touchpads report pixels).
pub const PIXELS_PER_LINE: f32 = 40.0;
/// Largest elevation the orbit reaches, degrees (the renderer accepts (−90, 90)).
pub const MAX_ELEVATION_DEG: f32 = 89.0;
/// A press and release closer than this many pixels is a click (a pick), not a drag.
pub const CLICK_SLOP_PX: f64 = 3.0;

/// Why the window could not run.
#[derive(Debug, thiserror::Error)]
pub enum WindowError {
    /// No display to open a window on.
    #[error("cannot open a window: {0} (no display? `drafter render` draws headless to PNG)")]
    NoDisplay(String),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error("window: {0}")]
    Window(String),
}

/// The view the mouse controls: the object's turn, the zoom and the pan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub view: View,
    pub zoom: f32,
    /// Normalised device units (see [`RenderOptions::pan`]).
    pub pan: [f32; 2],
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit { view: View::default(), zoom: 1.0, pan: [0.0, 0.0] }
    }
}

impl Orbit {
    /// Turns the object by a drag of (`dx`, `dy`) pixels (x right, y down): dragging right turns
    /// the object's front to the right (the camera's azimuth decreases), dragging down tips its top
    /// towards the viewer (the elevation increases), clamped short of the poles.
    pub fn rotate(&mut self, dx: f32, dy: f32) {
        let az = self.view.azimuth_deg - dx * DEGREES_PER_PIXEL;
        self.view.azimuth_deg = az.rem_euclid(360.0);
        self.view.elevation_deg =
            (self.view.elevation_deg + dy * DEGREES_PER_PIXEL).clamp(-MAX_ELEVATION_DEG, MAX_ELEVATION_DEG);
    }

    /// Zooms by `lines` wheel lines (positive: closer), keeping the point under the frame's centre.
    pub fn zoom_by(&mut self, lines: f32) {
        let zoom = self.zoom * ZOOM_PER_LINE.powf(lines);
        let zoom = zoom.clamp(ZOOM_RANGE.0, ZOOM_RANGE.1);
        // The pan is applied after the zoom: scale it too so the image centre stays put.
        let k = zoom / self.zoom;
        self.pan = [self.pan[0] * k, self.pan[1] * k];
        self.zoom = zoom;
    }

    /// Pans by a drag of (`dx`, `dy`) pixels in a frame of `size` pixels: the image follows the
    /// cursor.
    pub fn pan_by(&mut self, dx: f32, dy: f32, size: (u32, u32)) {
        let (w, h) = (size.0.max(1) as f32, size.1.max(1) as f32);
        self.pan =
            [(self.pan[0] + 2.0 * dx / w).clamp(-100.0, 100.0), (self.pan[1] - 2.0 * dy / h).clamp(-100.0, 100.0)];
    }

    /// Writes the orbit into `options`.
    pub fn apply(&self, options: &mut RenderOptions) {
        options.view = self.view;
        options.zoom = self.zoom;
        options.pan = self.pan;
    }
}

/// What a key does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    SetStyle(Style),
    NextStyle,
    ToggleEdges,
    ToggleLines,
    NextShadow,
    ToggleOrthographic,
    ResetView,
    Screenshot,
    Quit,
}

/// The action of a pressed key, if any (case-insensitive letters; see the module docs).
pub fn action_for_key(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Character(c) => {
            let c = c.chars().next()?.to_ascii_lowercase();
            match c {
                '1'..='7' => Some(Action::SetStyle(Style::ALL[(c as usize) - ('1' as usize)])),
                's' => Some(Action::NextStyle),
                'e' => Some(Action::ToggleEdges),
                'l' => Some(Action::ToggleLines),
                'h' => Some(Action::NextShadow),
                'o' => Some(Action::ToggleOrthographic),
                'r' => Some(Action::ResetView),
                'p' => Some(Action::Screenshot),
                'q' => Some(Action::Quit),
                _ => None,
            }
        }
        _ => None,
    }
}

impl Action {
    /// Applies a view or style change to `options` and `orbit`; `false` for the actions the
    /// window carries out itself (screenshot, quit).
    pub fn apply(self, options: &mut RenderOptions, orbit: &mut Orbit) -> bool {
        match self {
            Action::SetStyle(s) => options.style = s,
            Action::NextStyle => {
                let k = Style::ALL.iter().position(|&s| s == options.style).unwrap_or(0);
                options.style = Style::ALL[(k + 1) % Style::ALL.len()];
            }
            Action::ToggleEdges => {
                options.enhancements =
                    if options.enhancements.any() { Enhancements::default() } else { Enhancements::ALL };
            }
            Action::ToggleLines => options.lines = !options.lines,
            Action::NextShadow => {
                let at = ShadowMode::ALL.iter().position(|&m| m == options.shadow).unwrap_or(0);
                options.shadow = ShadowMode::ALL[(at + 1) % ShadowMode::ALL.len()];
            }
            Action::ToggleOrthographic => options.orthographic = !options.orthographic,
            Action::ResetView => *orbit = Orbit::default(),
            Action::Screenshot | Action::Quit => return false,
        }
        true
    }
}

/// One line about a part: its name and baked parameters (what a pick shows).
pub fn describe_part(model: &Model, id: u32) -> String {
    let Some(part) = model.part(id) else { return format!("part {id}: unknown") };
    let name = if part.name.is_empty() { "(unnamed)" } else { part.name.as_str() };
    match &part.record {
        Some(r) => {
            let d = r.projector.direction;
            let e = r.obb.half_extents;
            format!(
                "part {id} {name:?}: {} triangles, box {} half-extents {:.4} {:.4} {:.4}, projector ({:.3}, {:.3}, {:.3}) scale {:.4}, gradient q {} f {} p {} {}, style {}",
                r.triangles,
                r.obb.method,
                e[0],
                e[1],
                e[2],
                d[0],
                d[1],
                d[2],
                r.projector.scale,
                r.gradient.q,
                r.gradient.f,
                r.gradient.p,
                r.gradient.transfer,
                r.style.map_or("(scene)", drafter_format::PartStyle::name)
            )
        }
        None => format!("part {id} {name:?}: not baked (bounding-box projector)"),
    }
}

/// The window title for the current state.
pub fn title(file: &str, options: &RenderOptions, picked: Option<&str>) -> String {
    let on = |b: bool| if b { "on" } else { "off" };
    let mut t = format!(
        "drafter — {file} — {} | edges {} lines {} shadow {} {}",
        options.style,
        on(options.enhancements.any()),
        on(options.lines),
        options.shadow.name(),
        if options.orthographic { "ortho" } else { "persp" }
    );
    if let Some(p) = picked {
        t.push_str(" | ");
        t.push_str(p);
    }
    t
}

/// A screenshot's name: `<stem>-<n>.png` with the first `n` whose file does not exist in `folder`.
pub fn screenshot_path(folder: &Path, stem: &str) -> PathBuf {
    (1..).map(|n| folder.join(format!("{stem}-{n}.png"))).find(|p| !p.exists()).unwrap_or_default()
}

/// Opens a window on `model` (named `file` in the title) with `options` as the start state and
/// runs until it is closed.
pub fn run(model: Model, file: &Path, options: RenderOptions) -> Result<(), WindowError> {
    let event_loop = EventLoop::new().map_err(|e| WindowError::NoDisplay(e.to_string()))?;
    let mut orbit = Orbit { view: options.view, ..Orbit::default() };
    orbit.zoom = options.zoom;
    let mut app = App {
        model,
        file: file.to_path_buf(),
        options: RenderOptions { supersample: 1, ..options },
        orbit,
        state: None,
        error: None,
        cursor: PhysicalPosition::new(0.0, 0.0),
        pressed: None,
        picked: None,
    };
    event_loop.run_app(&mut app).map_err(|e| WindowError::Window(e.to_string()))?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

struct WindowState {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    renderer: Renderer,
}

/// A button held down: which, where it went down, and whether it has moved past a click.
#[derive(Clone, Copy, Debug)]
struct Press {
    button: MouseButton,
    at: PhysicalPosition<f64>,
    dragged: bool,
}

struct App {
    model: Model,
    file: PathBuf,
    options: RenderOptions,
    orbit: Orbit,
    state: Option<WindowState>,
    error: Option<WindowError>,
    cursor: PhysicalPosition<f64>,
    pressed: Option<Press>,
    picked: Option<String>,
}

impl std::fmt::Debug for App {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("App").field("file", &self.file).field("options", &self.options).finish_non_exhaustive()
    }
}

impl App {
    fn file_name(&self) -> String {
        self.file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
    }

    fn open(&self, event_loop: &ActiveEventLoop) -> Result<WindowState, WindowError> {
        let attributes = Window::default_attributes()
            .with_title(title(&self.file_name(), &self.options, None))
            .with_inner_size(winit::dpi::PhysicalSize::new(self.options.size.0, self.options.size.1));
        let window = Arc::new(event_loop.create_window(attributes).map_err(|e| WindowError::NoDisplay(e.to_string()))?);
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        if std::env::var_os("WGPU_DEBUG").is_none() {
            // Lavapipe (Mesa 22) crashes on debug labels; see Gpu::headless.
            descriptor.flags.remove(wgpu::InstanceFlags::DEBUG);
        }
        let instance = wgpu::Instance::new(descriptor);
        let surface = instance.create_surface(window.clone()).map_err(|e| WindowError::Window(e.to_string()))?;
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(&instance, Some(&surface)))
            .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        let capabilities = surface.get_capabilities(&adapter);
        // Colours are display values end to end: prefer a non-sRGB surface, and an 8-bit RGBA or
        // BGRA one, which screenshots can read back.
        let eight_bit = [wgpu::TextureFormat::Bgra8Unorm, wgpu::TextureFormat::Rgba8Unorm];
        let format = eight_bit
            .into_iter()
            .find(|f| capabilities.formats.contains(f))
            .or_else(|| capabilities.formats.iter().copied().find(|f| !f.is_srgb()))
            .or_else(|| capabilities.formats.first().copied())
            .ok_or_else(|| WindowError::Window("the surface supports no format".into()))?;
        let gpu = Gpu::with_adapter(instance, adapter)?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: capabilities.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let mut renderer = Renderer::with_gpu(gpu, format)?;
        renderer.set_model(&self.model)?;
        Ok(WindowState { window, surface, config, renderer })
    }

    fn redraw(&mut self) -> Result<(), WindowError> {
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        self.orbit.apply(&mut self.options);
        self.options.size = (state.config.width, state.config.height);
        let frame = match state.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                state.surface.configure(&state.renderer.gpu().device, &state.config);
                state.window.request_redraw();
                return Ok(());
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => return Ok(()),
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(WindowError::Window("the surface texture failed validation".into()));
            }
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let device = state.renderer.gpu().device.clone();
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("window frame") });
        state.renderer.encode_frame(&self.options, &mut encoder, Some(&view))?;
        let queue = &state.renderer.gpu().queue;
        queue.submit([encoder.finish()]);
        queue.present(frame);
        Ok(())
    }

    fn screenshot(&mut self) -> Result<(), WindowError> {
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        let options = RenderOptions { supersample: 2, ..self.options.clone() };
        let image = state.renderer.render(&options)?;
        let stem = self.file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "drafter".into());
        let png = image.to_png().map_err(|e| WindowError::Window(e.to_string()))?;
        // Beside the model; where that folder is read-only, in the working directory. A failed
        // write is reported and the window goes on.
        let beside = self.file.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let mut failures = Vec::new();
        for folder in [beside, Path::new(".")] {
            let path = screenshot_path(folder, &stem);
            match std::fs::write(&path, &png) {
                Ok(()) => {
                    println!("screenshot: {}", path.display());
                    failures.clear();
                    break;
                }
                Err(e) => failures.push(format!("{}: {e}", path.display())),
            }
        }
        if !failures.is_empty() {
            eprintln!("drafter: screenshot not saved ({})", failures.join("; "));
        }
        // The screenshot drew at another size: the next frame resizes the targets back.
        state.window.request_redraw();
        Ok(())
    }

    fn pick(&mut self, at: PhysicalPosition<f64>) -> Result<(), WindowError> {
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        let (x, y) = (at.x.max(0.0) as u32, at.y.max(0.0) as u32);
        let picked = state.renderer.pick(x, y)?;
        self.options.selected_part = picked;
        self.picked = picked.map(|id| describe_part(&self.model, id));
        match &self.picked {
            Some(line) => println!("{line}"),
            None => println!("background"),
        }
        self.refresh_title();
        Ok(())
    }

    fn refresh_title(&self) {
        if let Some(state) = &self.state {
            let short = self.picked.as_deref().map(|p| p.split(':').next().unwrap_or(p));
            state.window.set_title(&title(&self.file_name(), &self.options, short));
            state.window.request_redraw();
        }
    }

    fn handle(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) -> Result<(), WindowError> {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(state) = self.state.as_mut() {
                    state.config.width = size.width.max(1);
                    state.config.height = size.height.max(1);
                    state.surface.configure(&state.renderer.gpu().device, &state.config);
                    state.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => self.redraw()?,
            WindowEvent::CursorMoved { position, .. } => {
                let (dx, dy) = ((position.x - self.cursor.x) as f32, (position.y - self.cursor.y) as f32);
                self.cursor = position;
                if let Some(press) = self.pressed.as_mut() {
                    let moved = (position.x - press.at.x).hypot(position.y - press.at.y);
                    press.dragged |= moved > CLICK_SLOP_PX;
                    if press.dragged {
                        match press.button {
                            MouseButton::Left => self.orbit.rotate(dx, dy),
                            MouseButton::Right | MouseButton::Middle => {
                                self.orbit.pan_by(dx, dy, self.options.size);
                            }
                            _ => {}
                        }
                        if let Some(state) = &self.state {
                            state.window.request_redraw();
                        }
                    }
                }
            }
            WindowEvent::MouseInput { state: button_state, button, .. } => match button_state {
                ElementState::Pressed => self.pressed = Some(Press { button, at: self.cursor, dragged: false }),
                ElementState::Released => {
                    if let Some(press) = self.pressed.take()
                        && press.button == MouseButton::Left
                        && !press.dragged
                    {
                        self.pick(press.at)?;
                    }
                }
            },
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / PIXELS_PER_LINE,
                };
                self.orbit.zoom_by(lines);
                if let Some(state) = &self.state {
                    state.window.request_redraw();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                match action_for_key(&event.logical_key) {
                    Some(Action::Quit) => event_loop.exit(),
                    Some(Action::Screenshot) => self.screenshot()?,
                    Some(action) => {
                        action.apply(&mut self.options, &mut self.orbit);
                        self.refresh_title();
                    }
                    None => {}
                }
            }
            _ => {}
        }
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => {
                state.window.request_redraw();
                self.state = Some(state);
            }
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        if let Err(e) = self.handle(event_loop, event) {
            self.error = Some(e);
            event_loop.exit();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drag_turns_the_object_and_clamps_at_the_poles() {
        let mut o = Orbit::default();
        let start = o.view;
        o.rotate(10.0, 0.0);
        // Right drag: the camera's azimuth decreases by 4° (the object turns right).
        assert!((o.view.azimuth_deg - (start.azimuth_deg - 4.0)).abs() < 1e-4, "{:?}", o.view);
        assert_eq!(o.view.elevation_deg, start.elevation_deg);
        o.rotate(-1000.0, 0.0);
        assert!((0.0..360.0).contains(&o.view.azimuth_deg));
        o.rotate(0.0, 10_000.0);
        assert_eq!(o.view.elevation_deg, MAX_ELEVATION_DEG);
        o.rotate(0.0, -100_000.0);
        assert_eq!(o.view.elevation_deg, -MAX_ELEVATION_DEG);
        let mut options = RenderOptions::default();
        o.apply(&mut options);
        assert!(options.validate().is_ok(), "an orbit always gives valid options");
    }

    #[test]
    fn wheel_zooms_about_the_centre_and_pan_follows_the_cursor() {
        let mut o = Orbit::default();
        o.zoom_by(2.0);
        assert!((o.zoom - 1.21).abs() < 1e-5);
        o.zoom_by(-2.0);
        assert!((o.zoom - 1.0).abs() < 1e-5);
        o.zoom_by(1e6);
        assert_eq!(o.zoom, ZOOM_RANGE.1);
        let mut o = Orbit::default();
        // Dragging by half the frame's width moves the image by half the frame (1 NDC unit).
        o.pan_by(400.0, -300.0, (800, 600));
        assert_eq!(o.pan, [1.0, 1.0]);
        // Zooming keeps the panned point under the same screen position: the pan scales along.
        o.zoom_by(1.0);
        assert!((o.pan[0] - 1.1).abs() < 1e-5 && (o.pan[1] - 1.1).abs() < 1e-5, "{:?}", o.pan);
    }

    #[test]
    fn keys_map_to_actions() {
        let key = |s: &str| Key::Character(s.into());
        for (k, style) in Style::ALL.iter().enumerate() {
            assert_eq!(action_for_key(&key(&(k + 1).to_string())), Some(Action::SetStyle(*style)));
        }
        assert_eq!(action_for_key(&key("8")), None);
        assert_eq!(action_for_key(&key("S")), Some(Action::NextStyle));
        assert_eq!(action_for_key(&key("e")), Some(Action::ToggleEdges));
        assert_eq!(action_for_key(&key("L")), Some(Action::ToggleLines));
        assert_eq!(action_for_key(&key("h")), Some(Action::NextShadow));
        assert_eq!(action_for_key(&key("p")), Some(Action::Screenshot));
        assert_eq!(action_for_key(&Key::Named(NamedKey::Escape)), Some(Action::Quit));
        assert_eq!(action_for_key(&Key::Named(NamedKey::Enter)), None);
    }

    #[test]
    fn actions_change_the_options() {
        let mut options = RenderOptions::default();
        let mut orbit = Orbit::default();
        // S cycles through every style and back.
        let mut seen = Vec::new();
        for _ in 0..Style::ALL.len() {
            assert!(Action::NextStyle.apply(&mut options, &mut orbit));
            seen.push(options.style);
        }
        assert_eq!(options.style, Style::default());
        seen.sort_by_key(|s| s.index());
        assert_eq!(seen.len(), 7);
        seen.dedup();
        assert_eq!(seen.len(), 7, "every style once");
        Action::ToggleLines.apply(&mut options, &mut orbit);
        assert!(options.lines);
        Action::ToggleEdges.apply(&mut options, &mut orbit);
        assert_eq!(options.enhancements, Enhancements::ALL);
        Action::ToggleEdges.apply(&mut options, &mut orbit);
        assert!(!options.enhancements.any());
        // `H` reaches every shadow mode, then none again.
        let mut shadows = Vec::new();
        for _ in 0..ShadowMode::ALL.len() {
            Action::NextShadow.apply(&mut options, &mut orbit);
            shadows.push(options.shadow);
        }
        assert_eq!(shadows, [ShadowMode::Hard, ShadowMode::Penumbra, ShadowMode::Soft, ShadowMode::None]);
        orbit.rotate(50.0, 20.0);
        Action::ResetView.apply(&mut options, &mut orbit);
        assert_eq!(orbit, Orbit::default());
        assert!(!Action::Screenshot.apply(&mut options, &mut orbit));
    }

    #[test]
    fn screenshots_do_not_overwrite() {
        let dir = std::env::temp_dir().join(format!("drafter-shot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let first = screenshot_path(&dir, "m");
        assert_eq!(first.file_name().unwrap(), "m-1.png");
        std::fs::write(&first, b"x").unwrap();
        assert_eq!(screenshot_path(&dir, "m").file_name().unwrap(), "m-2.png");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
