//! The interactive window (`drafter view FILE`): the renderer's frame in a winit 0.30 window.
//!
//! # Controls
//! * left drag: turn the *object* (Gooch et al. 1999, §4.1: the viewer and the light stay put, so
//!   the cool-to-warm shading sweeps over the surface as it turns). For one frame that is the
//!   camera orbiting the other way with the light fixed to it, which is how the renderer draws it
//!   ([`drafter_render::camera`]): dragging right turns the object's front to the right.
//! * wheel: zoom about the frame's centre; right or middle drag: pan. While a button drags, frames
//!   are drawn at reduced resolution and filtered up ([`RenderOptions::interactive`], at the
//!   adapter's [`drafter_render::Gpu::interactive_scale`]); the frame after the release is full quality.
//! * `1`–`7`: style (gradient, cel, gooch, goochel, phong, metal, hatch); `S`: next style.
//! * `E` image-space edges, `L` baked lines, `H` next drop shadow (none, hard, penumbra, soft),
//!   `O` orthographic, `R` reset the view.
//! * left click (no drag): pick the part under the cursor (the G-buffer's part-id target read
//!   back); its name and parameters are printed and shown in the title, and it is highlighted.
//! * `P`: save a screenshot PNG (`<file stem>-<n>.png` beside the model, at the window's size with
//!   2× supersampling; the path is printed).
//! * `Esc` / `Q`: quit. With unsaved edits the first `Esc`, `Q` or close only asks (a message in
//!   the window: press `Esc` again to quit without saving, `Ctrl`+`S` to save); the second quits
//!   ([`quit_request`]).
//!
//! # Editing (Lux et al. 2013 §4; the data and functions are [`crate::edit`])
//! * left click: select the part under the cursor alone, or, on a selected part, make it the
//!   *reference* (drawn lighter); `Shift`+click adds or removes a part; a click on the background
//!   clears. `Ctrl`+drag draws a lasso (a part is selected when its box centre falls inside;
//!   `Ctrl`+`Shift` adds). The selection is listed on stdout.
//! * tools, for a left drag over a selection (the same key again: back to turning the object):
//!   `A` anchor (drag the gradient across the part; a click centres it under the cursor), `X`
//!   scale (drag away from or towards the anchor; from the anchor's dot, the projector's end
//!   follows the cursor), `D` direction (drag right or left: turn clockwise or counter-clockwise
//!   about the anchor, 0.5° a pixel; a direction facing the viewer tilts towards the drag), `V`
//!   projector line (draw anchor, direction and scale at once). Several parts follow the
//!   reference: the same anchor offset, the same scale, the same turn about each part's axis.
//! * gradient of the selection: `[`/`]` q, `,`/`.` f, `-`/`=` p, `T` next transfer curve γ,
//!   `Y` next style hint (after the last: the scene's style), `G` flat grey (black, three greys,
//!   white, shaded again).
//! * `Ctrl`+`Z` undo, `Ctrl`+`Y` or `Ctrl`+`Shift`+`Z` redo; `Ctrl`+`S` saves the edited part
//!   records into the file (atomically; every other byte stays), `Ctrl`+`E` writes
//!   `<file stem>.edits.toml` beside it, the overrides that `drafter bake --config` applies to the
//!   source model to re-create the edits (nothing is written when no part was edited). A save
//!   keeps the file's mode and owner and refuses a read-only file (the CLI's writer,
//!   `drafter_catalog::output::replace_in_place`); what a save or export did, or why it failed, is
//!   shown in the window ([`crate::panel::Status`]) as well as printed.
//! * the panel ([`crate::panel`], `F1` shows or hides it) lists the selection and sets its style, q,
//!   f, p, γ and flat grey, the tool, undo/redo, save and export; events it uses do not reach the
//!   view. The selection's projectors are drawn over the frame as handles.
//!
//! Everything an event changes goes through pure functions ([`Orbit`], [`action_for_key`],
//! [`Action::apply`]) that are unit-tested without a display; the event loop only routes events
//! to them and draws.
//!
//! Without a display (no `DISPLAY` on X11) [`run`] returns [`WindowError::NoDisplay`] before any
//! GPU work.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec2;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalPosition;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

use drafter_render::context::{Gpu, RenderError};
use drafter_render::model::Model;
use drafter_render::renderer::Renderer;
use drafter_render::style::RenderOptions;

use crate::edit::{Adjust, Editor, PartBox, ScreenView, Tool, parts_in_lasso};
use crate::panel::{self, Handle, Overlay, PanelAction, PanelPart, PanelView, Status, count};

pub use drafter_render::controls::{
    Action, DEGREES_PER_PIXEL, MAX_ELEVATION_DEG, Orbit, PIXELS_PER_LINE, ZOOM_PER_LINE, action_for_char,
};

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

/// The action of a pressed key, if any (case-insensitive letters; see the module docs).
pub fn action_for_key(key: &Key) -> Option<Action> {
    match key {
        Key::Named(NamedKey::Escape) => Some(Action::Quit),
        Key::Character(c) => action_for_char(c.chars().next()?),
        _ => None,
    }
}

/// What a request to quit (`Esc`, `Q`, closing the window) does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quit {
    Now,
    /// Unsaved edits and not asked yet: show the question, stay open.
    Ask,
}

/// A request to quit with `unsaved` parts not saved, `asked` when the window already asked (and
/// nothing happened since): it quits when nothing is unsaved or on the second request.
pub fn quit_request(unsaved: usize, asked: bool) -> Quit {
    if unsaved == 0 || asked { Quit::Now } else { Quit::Ask }
}

/// What a key does to the edits (see the module docs); checked before [`action_for_key`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EditCommand {
    /// Select this tool, or go back to turning the object when it is the current one.
    Tool(Tool),
    Adjust(Adjust),
    Undo,
    Redo,
    Save,
    Export,
}

/// The edit command of a pressed key with the modifiers held, if any.
pub fn edit_command_for_key(key: &Key, ctrl: bool, shift: bool) -> Option<EditCommand> {
    let Key::Character(c) = key else { return None };
    let c = c.chars().next()?.to_ascii_lowercase();
    if ctrl {
        return match c {
            'z' if shift => Some(EditCommand::Redo),
            'z' => Some(EditCommand::Undo),
            'y' => Some(EditCommand::Redo),
            's' => Some(EditCommand::Save),
            'e' => Some(EditCommand::Export),
            _ => None,
        };
    }
    Some(match c {
        'a' => EditCommand::Tool(Tool::Anchor),
        'x' => EditCommand::Tool(Tool::Scale),
        'd' => EditCommand::Tool(Tool::Direction),
        'v' => EditCommand::Tool(Tool::Line),
        '[' => EditCommand::Adjust(Adjust::Q(-1)),
        ']' => EditCommand::Adjust(Adjust::Q(1)),
        ',' => EditCommand::Adjust(Adjust::F(-1)),
        '.' => EditCommand::Adjust(Adjust::F(1)),
        '-' => EditCommand::Adjust(Adjust::P(-1)),
        '=' | '+' => EditCommand::Adjust(Adjust::P(1)),
        't' => EditCommand::Adjust(Adjust::NextTransfer),
        'y' => EditCommand::Adjust(Adjust::NextStyle),
        'g' => EditCommand::Adjust(Adjust::NextFlat),
        _ => return None,
    })
}

/// The edits file written beside `file` by `Ctrl`+`E`: `<stem>.edits.toml`.
pub fn edits_path(file: &Path) -> PathBuf {
    let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "drafter".into());
    file.with_file_name(format!("{stem}.edits.toml"))
}

/// Writes a file for the window (a save, an export): the CLI passes its atomic writer, so an
/// interrupted save never leaves a partial file. Its error names the file.
pub type Writer = dyn Fn(&Path, &[u8]) -> Result<(), String>;

/// One line about a part: its name and baked parameters (what a pick shows).
pub fn describe_part(model: &Model, id: u32) -> String {
    let Some(part) = model.part(id) else { return format!("part {id}: unknown") };
    describe_record(id, &part.name, part.record.as_ref())
}

/// [`describe_part`] from the part's name and record. q, f and p are printed as the bake holds
/// them (f32: `f 0.45`, not the f64 widening's `0.45000001788139343`).
pub fn describe_record(id: u32, name: &str, record: Option<&drafter_format::PartRecord>) -> String {
    let name = if name.is_empty() { "(unnamed)" } else { name };
    match record {
        Some(r) => {
            let d = r.projector.direction;
            let e = r.obb.half_extents;
            let a = r.projector.anchor;
            format!(
                "part {id} {name:?}: {} triangles, box {} half-extents {:.4} {:.4} {:.4}, projector anchor ({:.4}, {:.4}, {:.4}) direction ({:.3}, {:.3}, {:.3}) scale {:.4}, gradient q {} f {} p {} {}, style {}",
                r.triangles,
                r.obb.method,
                e[0],
                e[1],
                e[2],
                a[0],
                a[1],
                a[2],
                d[0],
                d[1],
                d[2],
                r.projector.scale,
                r.gradient.q as f32,
                r.gradient.f as f32,
                r.gradient.p as f32,
                r.gradient.transfer,
                r.style.map_or("(scene)", drafter_format::PartStyle::name)
            ) + &r.flat.map(|g| format!(", flat {}", g as f32)).unwrap_or_default()
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
pub fn run(model: Model, file: &Path, options: RenderOptions, writer: &Writer) -> Result<(), WindowError> {
    let event_loop = EventLoop::new().map_err(|e| WindowError::NoDisplay(e.to_string()))?;
    let mut orbit = Orbit { view: options.view, ..Orbit::default() };
    orbit.zoom = options.zoom;
    let editor = Editor::new(model.parts.iter().map(|p| p.record.clone()).collect());
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
        editor,
        tool: None,
        modifiers: ModifiersState::empty(),
        lasso: None,
        writer,
        drag_frames: None,
        parts_version: 0,
        status: None,
        quit_asked: false,
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
    overlay: Overlay,
    /// The surface can be copied into: the frame is drawn into the renderer's own output and
    /// copied, so that a redraw for the panel alone (a hover, a click on it) reuses the last frame
    /// instead of drawing the model again.
    reuse: bool,
    /// What the frame in the renderer's output shows: the options and the part table's version.
    drawn: Option<(RenderOptions, u64)>,
}

/// A button held down: which, where it went down, and whether it has moved past a click.
#[derive(Clone, Copy, Debug)]
struct Press {
    button: MouseButton,
    at: PhysicalPosition<f64>,
    dragged: bool,
}

struct App<'a> {
    model: Model,
    file: PathBuf,
    options: RenderOptions,
    orbit: Orbit,
    state: Option<WindowState>,
    error: Option<WindowError>,
    cursor: PhysicalPosition<f64>,
    pressed: Option<Press>,
    picked: Option<String>,
    editor: Editor,
    /// The manipulator a left drag over the selection applies; `None`: the drag turns the object.
    tool: Option<Tool>,
    modifiers: ModifiersState,
    /// The lasso being drawn (`Ctrl`+drag), in window pixels.
    lasso: Option<Vec<DVec2>>,
    writer: &'a Writer,
    /// Frames drawn since the drag began, and when it began: with `DRAFTER_VIEW_STATS` set, the
    /// frame rate of each drag is printed on release (measured in the event loop).
    drag_frames: Option<(std::time::Instant, u32)>,
    /// Bumped at every upload of the part table (an edit, a selection): a frame drawn before is
    /// stale.
    parts_version: u64,
    /// The last message, shown in the window (panel or corner) and the title.
    status: Option<Status>,
    /// A quit with unsaved edits asked first ([`quit_request`]); any other input clears it.
    quit_asked: bool,
}

impl std::fmt::Debug for App<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("App").field("file", &self.file).field("options", &self.options).finish_non_exhaustive()
    }
}

impl App<'_> {
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
        let reuse = capabilities.usages.contains(wgpu::TextureUsages::COPY_DST);
        let mut usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        if reuse {
            usage |= wgpu::TextureUsages::COPY_DST;
        }
        let config = wgpu::SurfaceConfiguration {
            usage,
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
        let overlay = Overlay::new(&window, &gpu.device, format);
        let mut renderer = Renderer::with_gpu(gpu, format)?;
        renderer.set_model(&self.model)?;
        Ok(WindowState { window, surface, config, renderer, overlay, reuse, drawn: None })
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
        let queue = state.renderer.gpu().queue.clone();
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("window frame") });
        let key = (self.options.clone(), self.parts_version);
        let fresh = state.reuse && state.drawn.as_ref() == Some(&key);
        // While dragging every frame is new: it is drawn straight into the window, not kept.
        let keep = state.reuse && !self.options.interactive;
        if !fresh {
            let output = if keep { None } else { Some(&view) };
            state.renderer.encode_frame(&self.options, &mut encoder, output)?;
            state.drawn = keep.then_some(key);
            if self.options.interactive {
                let (_, frames) = self.drag_frames.get_or_insert((std::time::Instant::now(), 0));
                *frames += 1;
            }
        }
        if keep || fresh {
            let drawn = state.renderer.output_texture().ok_or(RenderError::NoModel)?;
            encoder.copy_texture_to_texture(
                drawn.as_image_copy(),
                frame.texture.as_image_copy(),
                wgpu::Extent3d { width: state.config.width, height: state.config.height, depth_or_array_layers: 1 },
            );
        }
        let panel_view = self.panel_view();
        let handles = self.handles();
        let lasso = self.lasso.clone();
        let status = self.status.clone();
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        let show_panel = state.overlay.panel;
        let mut actions = Vec::new();
        let size = (state.config.width, state.config.height);
        let again = state.overlay.draw(&state.window, &device, &queue, &mut encoder, &view, size, |ctx| {
            if show_panel {
                actions = panel::show(ctx, &panel_view);
            } else if let Some(status) = &status {
                panel::show_status(ctx, status);
            }
            panel::paint_overlay(ctx, &handles, lasso.as_deref());
        });
        queue.submit([encoder.finish()]);
        queue.present(frame);
        if again {
            state.window.request_redraw();
        }
        for action in actions {
            self.panel_action(action)?;
        }
        Ok(())
    }

    /// What the panel shows now.
    fn panel_view(&self) -> PanelView {
        let selection = &self.editor.selection;
        let mut ids = selection.parts.clone();
        if let Some(r) = selection.reference
            && let Some(at) = ids.iter().position(|&id| id == r)
        {
            ids.remove(at);
            ids.insert(0, r);
        }
        PanelView {
            file: self.file_name(),
            parts: self.model.parts.len(),
            selected: ids
                .iter()
                .map(|&id| PanelPart {
                    id,
                    name: self.model.part(id).map(|p| p.name.clone()).unwrap_or_default(),
                    reference: selection.reference == Some(id),
                    params: self.editor.params(id),
                })
                .collect(),
            tool: self.tool,
            unsaved: self.editor.unsaved().len(),
            can_undo: self.editor.can_undo(),
            can_redo: self.editor.can_redo(),
            scene_style: self.options.style.to_string(),
            status: self.status.clone(),
            hint: self.hint(),
        }
    }

    /// With the anchor tool, on a reference part whose direction runs along the line of sight:
    /// why a drag changes nothing visible, and what does.
    fn hint(&self) -> Option<String> {
        if self.tool != Some(Tool::Anchor) {
            return None;
        }
        let id = self.editor.selection.reference?;
        let record = self.editor.record(id)?;
        let view = self.screen_view()?;
        let params = crate::edit::PartParams::from_record(record);
        let obb = PartBox::from_record(&record.obb);
        obb.faces(params.direction, view.toward_viewer(params.anchor)).then(|| {
            format!(
                "part {id}'s gradient runs towards you: moving its anchor across the part changes nothing from this \
                 view. D tilts the direction, V draws a new one, or turn the view."
            )
        })
    }

    /// Shows `status` in the window (and its title).
    fn set_status(&mut self, status: Status) {
        self.status = Some(status);
        self.refresh_title();
    }

    /// `Esc`, `Q` or closing the window: quits, or with unsaved edits asks first.
    fn request_quit(&mut self, event_loop: &ActiveEventLoop) {
        let unsaved = self.editor.unsaved().len();
        match quit_request(unsaved, self.quit_asked) {
            Quit::Now => event_loop.exit(),
            Quit::Ask => {
                let text = format!(
                    "Unsaved edits ({}): press Esc again to quit without saving, Ctrl+S to save",
                    count(unsaved, "part")
                );
                println!("{text}");
                self.set_status(Status::error(text));
                self.quit_asked = true;
            }
        }
    }

    /// Any input but a quit: a quit asks again next time, and its question goes.
    fn not_quitting(&mut self) {
        if std::mem::take(&mut self.quit_asked) {
            self.status = None;
            self.refresh_title();
        }
    }

    /// The selected parts' projectors on screen (the last frame's camera).
    fn handles(&self) -> Vec<Handle> {
        let Some(view) = self.screen_view() else { return Vec::new() };
        let selection = &self.editor.selection;
        selection
            .parts
            .iter()
            .filter_map(|&id| {
                let p = self.editor.params(id)?;
                Some(Handle {
                    anchor: view.project(p.anchor)?,
                    end: view.project(p.anchor + p.direction * p.scale),
                    reference: selection.reference == Some(id),
                })
            })
            .collect()
    }

    /// Carries out what the panel asked for, as the keys would.
    fn panel_action(&mut self, action: PanelAction) -> Result<(), WindowError> {
        match action {
            PanelAction::Tool(tool) => {
                self.tool = tool;
                println!("tool: {}", self.tool.map_or("turn the object", Tool::name));
                self.refresh_title();
            }
            PanelAction::Live(adjust) => {
                let ids = self.editor.adjust_live(adjust);
                self.parts_changed(&ids)?;
            }
            PanelAction::EndLive => {
                if self.editor.end_live() {
                    let ids = self.editor.selection.parts.clone();
                    self.list_edited(&ids);
                    self.refresh_title();
                }
            }
            PanelAction::Undo => self.edit(EditCommand::Undo)?,
            PanelAction::Redo => self.edit(EditCommand::Redo)?,
            PanelAction::Save => self.save(),
            PanelAction::Export => self.export(),
        }
        Ok(())
    }

    fn screenshot(&mut self) -> Result<(), WindowError> {
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        let options = RenderOptions { supersample: 2, interactive: false, ..self.options.clone() };
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
            let text = format!("screenshot not saved ({})", failures.join("; "));
            eprintln!("drafter: {text}");
            self.status = Some(Status::error(text));
            self.refresh_title();
        }
        let Some(state) = self.state.as_mut() else { return Ok(()) };
        // The screenshot drew at another size: the next frame resizes the targets back and draws
        // the model again.
        state.drawn = None;
        state.window.request_redraw();
        Ok(())
    }

    /// The part under `at` (the G-buffer's part-id target read back), or `None` for the background.
    /// The last frame's targets may be larger (a supersampled screenshot) or smaller (an
    /// interactive frame) than the window: the cursor is scaled to them.
    fn part_at(&mut self, at: DVec2) -> Result<Option<u32>, WindowError> {
        let Some(state) = self.state.as_mut() else { return Ok(None) };
        let window = DVec2::new(f64::from(state.config.width.max(1)), f64::from(state.config.height.max(1)));
        let target = state
            .renderer
            .last_frame()
            .map_or(window, |f| DVec2::new(f64::from(f.target_size.0), f64::from(f.target_size.1)));
        let p = (at.max(DVec2::ZERO) * target / window).floor();
        Ok(state.renderer.pick(p.x as u32, p.y as u32)?)
    }

    /// A click that selects (see the module docs): alone, or with `Shift` added or removed.
    fn click_select(&mut self, at: DVec2) -> Result<(), WindowError> {
        let hit = self.part_at(at)?;
        match hit {
            Some(id) if self.modifiers.shift_key() => self.editor.selection.toggle(id),
            _ => self.editor.selection.click(hit),
        }
        self.picked = hit.map(|id| describe_part(&self.model, id));
        if hit.is_none() {
            println!("background");
        }
        self.selection_changed()
    }

    /// The frame on screen as the edits see it: the last frame's camera at the window's size.
    fn screen_view(&self) -> Option<ScreenView> {
        let state = self.state.as_ref()?;
        let frame = state.renderer.last_frame()?;
        Some(ScreenView::new(
            frame.camera.clip_from_render(),
            self.model.origin,
            (state.config.width, state.config.height),
        ))
    }

    /// Uploads the selection's highlight and lists the selection on stdout.
    fn selection_changed(&mut self) -> Result<(), WindowError> {
        let selection = self.editor.selection.clone();
        self.model.set_selection(&selection.parts, selection.reference);
        self.options.selected_part = None;
        if let Some(state) = self.state.as_mut() {
            state.renderer.update_parts(&self.model)?;
        }
        self.parts_version += 1;
        if !selection.is_empty() {
            println!("selected {}:", count(selection.parts.len(), "part"));
            for &id in &selection.parts {
                let mark = if selection.reference == Some(id) { " (reference)" } else { "" };
                println!("  {}{mark}", describe_part(&self.model, id));
            }
        }
        self.refresh_title();
        Ok(())
    }

    /// Carries the editor's changed records over to the model and the GPU part table: one buffer
    /// write, no re-bake.
    fn parts_changed(&mut self, ids: &[u32]) -> Result<(), WindowError> {
        if ids.is_empty() {
            return Ok(());
        }
        for &id in ids {
            if let Some(record) = self.editor.record(id) {
                self.model.set_part_record(record);
            }
        }
        if let Some(state) = self.state.as_mut() {
            state.renderer.update_parts(&self.model)?;
        }
        self.parts_version += 1;
        self.refresh_title();
        Ok(())
    }

    fn edit(&mut self, command: EditCommand) -> Result<(), WindowError> {
        match command {
            EditCommand::Tool(tool) => {
                self.tool = if self.tool == Some(tool) { None } else { Some(tool) };
                println!("tool: {}", self.tool.map_or("turn the object", Tool::name));
                self.refresh_title();
            }
            EditCommand::Adjust(adjust) => {
                let ids = self.editor.adjust(adjust);
                self.parts_changed(&ids)?;
                self.list_edited(&ids);
            }
            EditCommand::Undo => {
                let ids = self.editor.undo();
                self.parts_changed(&ids)?;
                self.list_edited(&ids);
            }
            EditCommand::Redo => {
                let ids = self.editor.redo();
                self.parts_changed(&ids)?;
                self.list_edited(&ids);
            }
            EditCommand::Save => self.save(),
            EditCommand::Export => self.export(),
        }
        Ok(())
    }

    fn list_edited(&self, ids: &[u32]) {
        for &id in ids {
            println!("  {}", describe_part(&self.model, id));
        }
    }

    /// Writes the edited part records into the file (`Ctrl`+`S`); failures are printed and shown,
    /// the window goes on.
    fn save(&mut self) {
        if !self.model.baked {
            let text = format!("not saved: {} is not a baked file (bake it first)", self.file_name());
            eprintln!("drafter: {text}");
            self.set_status(Status::error(text));
            return;
        }
        let unsaved = self.editor.unsaved();
        let records: Vec<drafter_format::PartRecord> = self.editor.records().cloned().collect();
        let named = |e: &dyn std::fmt::Display| format!("{}: {e}", self.file.display());
        let result = std::fs::read(&self.file)
            .map_err(|e| named(&e))
            .and_then(|bytes| drafter_format::replace_part_records(&bytes, &records).map_err(|e| named(&e)))
            .and_then(|bytes| (self.writer)(&self.file, &bytes));
        match result {
            Ok(()) => {
                self.editor.mark_saved();
                let changed = count(unsaved.len(), "part record");
                println!("saved: {} ({changed} changed)", self.file.display());
                self.set_status(Status::info(format!("saved: {} ({changed} changed)", self.file_name())));
            }
            Err(e) => {
                eprintln!("drafter: not saved: {e}");
                self.set_status(Status::error(format!("not saved: {e}")));
            }
        }
    }

    /// Writes `<stem>.edits.toml` beside the file (`Ctrl`+`E`); with no part edited, writes nothing
    /// and says so.
    fn export(&mut self) {
        let path = edits_path(&self.file);
        let Some(toml) = self.editor.overrides_toml(&self.file_name()) else {
            let text = if self.editor.editable() {
                "nothing to export: no part has been edited".to_owned()
            } else {
                format!(
                    "nothing to export: {} is not baked, its parts cannot be edited (bake it first)",
                    self.file_name()
                )
            };
            println!("{text}");
            self.set_status(Status::info(text));
            return;
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        match (self.writer)(&path, toml.as_bytes()) {
            Ok(()) => {
                println!("edits: {}", path.display());
                let parts = count(self.editor.edited().len(), "part");
                self.set_status(Status::info(format!("edits of {parts} written to {name}")));
            }
            Err(e) => {
                eprintln!("drafter: edits not written: {e}");
                self.set_status(Status::error(format!("edits not written: {e}")));
            }
        }
    }

    fn refresh_title(&self) {
        if let Some(state) = &self.state {
            let short = self.picked.as_deref().map(|p| p.split(':').next().unwrap_or(p));
            let mut title = title(&self.file_name(), &self.options, short);
            let selection = &self.editor.selection;
            if !selection.is_empty() {
                title.push_str(&format!(" | {} selected", selection.parts.len()));
            }
            if let Some(tool) = self.tool {
                title.push_str(&format!(" | tool: {}", tool.name()));
            }
            if !self.editor.unsaved().is_empty() {
                title.push_str(" | unsaved");
            }
            if let Some(status) = &self.status {
                title.push_str(" | ");
                title.push_str(&status.text);
            }
            state.window.set_title(&title);
            state.window.request_redraw();
        }
    }

    fn request_redraw(&self) {
        if let Some(state) = &self.state {
            state.window.request_redraw();
        }
    }

    /// The cursor moved: a drag past the click slop orbits, pans, draws the lasso or drives the
    /// manipulator.
    fn cursor_moved(&mut self, position: PhysicalPosition<f64>) -> Result<(), WindowError> {
        let (dx, dy) = ((position.x - self.cursor.x) as f32, (position.y - self.cursor.y) as f32);
        self.cursor = position;
        let now = DVec2::new(position.x, position.y);
        if let Some(press) = self.pressed.as_mut() {
            let moved = (position.x - press.at.x).hypot(position.y - press.at.y);
            press.dragged |= moved > CLICK_SLOP_PX;
            if press.dragged {
                let button = press.button;
                // Cheaper frames while the mouse drags (half resolution on lavapipe's
                // per-pixel cost); full quality again on release.
                self.options.interactive = true;
                if let Some(path) = self.lasso.as_mut() {
                    if path.last().is_none_or(|last| last.distance(now) >= 2.0) {
                        path.push(now);
                    }
                } else if self.editor.dragging() {
                    if let Some(view) = self.screen_view() {
                        let ids = self.editor.drag_to(&view, now);
                        self.parts_changed(&ids)?;
                    }
                } else {
                    match button {
                        MouseButton::Left => self.orbit.rotate(dx, dy),
                        MouseButton::Right | MouseButton::Middle => {
                            self.orbit.pan_by(dx, dy, self.options.size);
                        }
                        _ => {}
                    }
                }
                self.request_redraw();
            }
        }
        Ok(())
    }

    /// A button came up: ends a lasso, a manipulator drag or a click (selection, or the anchor
    /// tool's centring).
    fn mouse_released(&mut self) -> Result<(), WindowError> {
        let Some(press) = self.pressed.take() else { return Ok(()) };
        if std::mem::take(&mut self.options.interactive) {
            self.request_redraw();
        }
        if let Some((since, frames)) = self.drag_frames.take()
            && std::env::var_os("DRAFTER_VIEW_STATS").is_some()
        {
            // The first frame opens the interval: frames after it over its length.
            let seconds = since.elapsed().as_secs_f64();
            let rate = f64::from(frames.saturating_sub(1)) / seconds.max(1e-9);
            println!("drag: {frames} frames in {seconds:.2} s, {rate:.1} frames/s");
        }
        if press.button != MouseButton::Left {
            return Ok(());
        }
        let at = DVec2::new(press.at.x, press.at.y);
        if let Some(path) = self.lasso.take() {
            if press.dragged {
                if let Some(view) = self.screen_view() {
                    let boxes: Vec<(u32, PartBox)> = self
                        .model
                        .parts
                        .iter()
                        .filter_map(|p| Some((p.id, PartBox::from_record(&p.record.as_ref()?.obb))))
                        .collect();
                    let inside = parts_in_lasso(&path, &view, &boxes);
                    self.editor.selection.lasso(&inside, self.modifiers.shift_key());
                    self.selection_changed()?;
                }
            } else {
                self.click_select(at)?;
            }
        } else if self.editor.dragging() {
            if self.editor.end() {
                let ids = self.editor.selection.parts.clone();
                self.list_edited(&ids);
                self.refresh_title();
            } else if !press.dragged {
                // A click with a tool: the anchor tool centres the anchor under the
                // cursor when the click lands on a selected part; any other click
                // selects.
                let hit = self.part_at(at)?;
                let on_selection = hit.is_some_and(|id| self.editor.selection.contains(id));
                if self.tool == Some(Tool::Anchor) && on_selection {
                    if let Some(view) = self.screen_view() {
                        let ids = self.editor.centre_anchor(&view, at);
                        self.parts_changed(&ids)?;
                        self.list_edited(&ids);
                    }
                } else {
                    self.click_select(at)?;
                }
            }
        } else if !press.dragged {
            self.click_select(at)?;
        }
        Ok(())
    }

    fn handle(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) -> Result<(), WindowError> {
        if !matches!(event, WindowEvent::RedrawRequested)
            && let Some(state) = self.state.as_mut()
        {
            let (consumed, repaint) = state.overlay.on_event(&state.window, &event);
            if repaint {
                state.window.request_redraw();
            }
            // The panel's own clicks, drags and keys; a press that began on the model is ours
            // to the end (its release may land on the panel).
            let ours = match &event {
                WindowEvent::MouseInput { state: ElementState::Released, .. } | WindowEvent::CursorMoved { .. } => {
                    self.pressed.is_some() || !consumed
                }
                WindowEvent::MouseInput { .. } | WindowEvent::MouseWheel { .. } | WindowEvent::KeyboardInput { .. } => {
                    !consumed
                }
                _ => true,
            };
            if !ours {
                if let WindowEvent::CursorMoved { position, .. } = event {
                    self.cursor = position;
                }
                return Ok(());
            }
        }
        match event {
            WindowEvent::CloseRequested => self.request_quit(event_loop),
            WindowEvent::Resized(size) => {
                if let Some(state) = self.state.as_mut() {
                    state.config.width = size.width.max(1);
                    state.config.height = size.height.max(1);
                    state.surface.configure(&state.renderer.gpu().device, &state.config);
                    state.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => self.redraw()?,
            WindowEvent::ModifiersChanged(modifiers) => self.modifiers = modifiers.state(),
            WindowEvent::CursorMoved { position, .. } => self.cursor_moved(position)?,
            WindowEvent::MouseInput { state: button_state, button, .. } => match button_state {
                ElementState::Pressed => {
                    self.not_quitting();
                    self.pressed = Some(Press { button, at: self.cursor, dragged: false });
                    let at = DVec2::new(self.cursor.x, self.cursor.y);
                    if button == MouseButton::Left {
                        if self.modifiers.control_key() {
                            self.lasso = Some(vec![at]);
                        } else if let Some(tool) = self.tool
                            && !self.modifiers.shift_key()
                        {
                            self.editor.begin(tool, at);
                        }
                    }
                }
                ElementState::Released => self.mouse_released()?,
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
                let (ctrl, shift) = (self.modifiers.control_key(), self.modifiers.shift_key());
                let modifier = matches!(
                    event.logical_key,
                    Key::Named(NamedKey::Shift | NamedKey::Control | NamedKey::Alt | NamedKey::Super)
                );
                if modifier || event.repeat {
                    // A modifier alone or a held key's repeat is no answer to the quit question.
                } else if ctrl || action_for_key(&event.logical_key) != Some(Action::Quit) {
                    self.not_quitting();
                }
                if let Some(command) = edit_command_for_key(&event.logical_key, ctrl, shift) {
                    return self.edit(command);
                }
                if ctrl {
                    return Ok(());
                }
                if event.logical_key == Key::Named(NamedKey::F1) {
                    if let Some(state) = self.state.as_mut() {
                        state.overlay.panel = !state.overlay.panel;
                        state.window.request_redraw();
                    }
                    return Ok(());
                }
                match action_for_key(&event.logical_key) {
                    Some(Action::Quit) => self.request_quit(event_loop),
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

impl ApplicationHandler for App<'_> {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(state) => {
                self.options.interactive_scale = state.renderer.gpu().interactive_scale();
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
    use drafter_render::style::{Enhancements, ShadowMode, Style, ZOOM_RANGE};

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
        seen.sort_by_key(|&s| drafter_render::style::shader_index(s));
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
    fn edit_keys_map_to_commands_and_leave_the_view_keys_alone() {
        let key = |s: &str| Key::Character(s.into());
        assert_eq!(edit_command_for_key(&key("a"), false, false), Some(EditCommand::Tool(Tool::Anchor)));
        assert_eq!(edit_command_for_key(&key("X"), false, true), Some(EditCommand::Tool(Tool::Scale)));
        assert_eq!(edit_command_for_key(&key("d"), false, false), Some(EditCommand::Tool(Tool::Direction)));
        assert_eq!(edit_command_for_key(&key("v"), false, false), Some(EditCommand::Tool(Tool::Line)));
        assert_eq!(edit_command_for_key(&key("]"), false, false), Some(EditCommand::Adjust(Adjust::Q(1))));
        assert_eq!(edit_command_for_key(&key(","), false, false), Some(EditCommand::Adjust(Adjust::F(-1))));
        assert_eq!(edit_command_for_key(&key("="), false, false), Some(EditCommand::Adjust(Adjust::P(1))));
        assert_eq!(edit_command_for_key(&key("g"), false, false), Some(EditCommand::Adjust(Adjust::NextFlat)));
        assert_eq!(edit_command_for_key(&key("z"), true, false), Some(EditCommand::Undo));
        assert_eq!(edit_command_for_key(&key("Z"), true, true), Some(EditCommand::Redo));
        assert_eq!(edit_command_for_key(&key("y"), true, false), Some(EditCommand::Redo));
        assert_eq!(edit_command_for_key(&key("s"), true, false), Some(EditCommand::Save));
        assert_eq!(edit_command_for_key(&key("e"), true, false), Some(EditCommand::Export));
        // Without Ctrl, S and E stay the view's keys (next style, edges); no edit key takes a view key.
        for c in ["s", "e", "l", "h", "o", "r", "p", "q", "1", "7"] {
            assert_eq!(edit_command_for_key(&key(c), false, false), None, "{c}");
            assert!(action_for_key(&key(c)).is_some(), "{c}");
        }
        for c in ["a", "x", "d", "v", "[", "]", ",", ".", "-", "=", "t", "y", "g"] {
            assert_eq!(action_for_key(&key(c)), None, "{c} is an edit key only");
        }
        assert_eq!(edits_path(Path::new("out/gear.baked.glb")), Path::new("out/gear.baked.edits.toml"));
    }

    #[test]
    fn a_quit_with_unsaved_edits_asks_once() {
        assert_eq!(quit_request(0, false), Quit::Now, "nothing unsaved: Esc quits");
        assert_eq!(quit_request(2, false), Quit::Ask, "unsaved edits: the first Esc asks");
        assert_eq!(quit_request(2, true), Quit::Now, "the second quits");
    }

    #[test]
    fn a_part_is_described_at_the_precision_the_bake_holds() {
        let mut record = crate::edit::tests::record(3, [0.0; 3]);
        record.gradient.f = f64::from(0.45f32);
        record.gradient.p = f64::from(1.25f32);
        record.flat = Some(f64::from(0.3f32));
        let line = describe_record(3, "bolt", Some(&record));
        assert!(line.contains("gradient q 10 f 0.45 p 1.25 identity"), "{line}");
        assert!(line.ends_with(", flat 0.3"), "{line}");
        assert!(!line.contains("0.4500000"), "{line}");
        assert_eq!(describe_record(4, "", None), "part 4 \"(unnamed)\": not baked (bounding-box projector)");
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
