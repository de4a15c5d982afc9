//! The editing panel of `drafter view` and the on-screen projector handles (Lux et al. 2013 §4),
//! drawn with egui over the frame by the renderer's own wgpu device.
//!
//! [`show`] is the panel as a function of plain data ([`PanelView`]) returning what the user asked
//! for ([`PanelAction`]); the window applies the actions through the same editor calls as the keys,
//! so undo, save and export treat them alike. A slider that is held changes the selection live and
//! makes one undo step when released ([`crate::edit::Editor::adjust_live`]). [`paint_overlay`] draws
//! each selected part's projector (anchor, direction and scale as a line from the anchor) and the
//! lasso being drawn, under the panel. The window's last message ([`Status`]: a save, a refused
//! save, an export, the question before quitting with unsaved edits) is shown in the panel, or at
//! the window's bottom-left corner while the panel is hidden ([`show_status`]). [`Overlay`] owns
//! egui's context, its winit input state and its wgpu renderer.

use drafter_core::gradient::{MAX_POWER, MAX_QUANTIZATION, MIN_POWER};
use drafter_format::{PartStyle, TransferCurve};
use glam::DVec2;

use crate::edit::{Adjust, PartParams, Tool};

/// The panel's width in logical points (it is anchored to the window's top-right corner).
pub const PANEL_WIDTH: f32 = 250.0;

/// Selected parts listed by name before the list scrolls.
const LISTED_ROWS: f32 = 8.0;

/// `n` and `noun`, in the plural unless `n` is 1: "1 part", "2 parts".
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 { format!("1 {noun}") } else { format!("{n} {noun}s") }
}

/// The window's last message: what a save, an export or a quit did or asks.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Status {
    pub text: String,
    /// A failure (drawn in red).
    pub error: bool,
}

impl Status {
    pub fn info(text: impl Into<String>) -> Self {
        Status { text: text.into(), error: false }
    }

    pub fn error(text: impl Into<String>) -> Self {
        Status { text: text.into(), error: true }
    }

    fn colour(&self) -> egui::Color32 {
        if self.error { egui::Color32::from_rgb(200, 30, 30) } else { egui::Color32::from_rgb(20, 110, 40) }
    }
}

/// One selected part as the panel lists it.
#[derive(Clone, Debug, PartialEq)]
pub struct PanelPart {
    pub id: u32,
    pub name: String,
    pub reference: bool,
    /// `None`: the part has no baked record (not editable).
    pub params: Option<PartParams>,
}

/// Everything the panel shows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PanelView {
    pub file: String,
    pub parts: usize,
    /// The selection, the reference part first.
    pub selected: Vec<PanelPart>,
    pub tool: Option<Tool>,
    pub unsaved: usize,
    pub can_undo: bool,
    pub can_redo: bool,
    /// The style parts without a hint are drawn in.
    pub scene_style: String,
    /// The last message (a save, an export, a quit that asks first).
    pub status: Option<Status>,
    /// Why the current tool may change nothing visible on the reference part (its direction runs
    /// along the line of sight).
    pub hint: Option<String>,
}

/// What the user did in the panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PanelAction {
    /// The drag tool (`None`: dragging turns the object).
    Tool(Option<Tool>),
    /// A value changed by a held or clicked widget: applied to the selection as it was when the
    /// widget was grabbed.
    Live(Adjust),
    /// The widget was released: one undo step.
    EndLive,
    Undo,
    Redo,
    Save,
    Export,
}

/// A selected part's projector on screen, in window pixels (y down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Handle {
    pub anchor: DVec2,
    /// `anchor + scale · direction`, projected: where ω's parameter reaches 1.
    pub end: Option<DVec2>,
    pub reference: bool,
}

/// The panel: tools, the selection with its parameters, the edits of the selection (the reference
/// part's values are shown; a change sets every selected part), undo/redo, save and export.
pub fn show(ctx: &egui::Context, view: &PanelView) -> Vec<PanelAction> {
    let mut actions = Vec::new();
    egui::Window::new("drafter")
        .id(egui::Id::unique("drafter panel"))
        .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
        .default_width(PANEL_WIDTH)
        .resizable(false)
        .collapsible(true)
        .show(ctx, |ui| {
            ui.set_width(PANEL_WIDTH - 16.0);
            let unsaved = if view.unsaved > 0 { format!(", {} unsaved", view.unsaved) } else { String::new() };
            ui.label(format!("{}: {}{unsaved}", view.file, count(view.parts, "part")));
            ui.horizontal_wrapped(|ui| {
                ui.label("drag:");
                let mut tool = view.tool;
                ui.selectable_value(&mut tool, None, "turn");
                for t in Tool::ALL {
                    ui.selectable_value(&mut tool, Some(t), t.name());
                }
                if tool != view.tool {
                    actions.push(PanelAction::Tool(tool));
                }
            });
            if let Some(hint) = &view.hint {
                ui.colored_label(egui::Color32::from_rgb(150, 90, 0), hint);
            }
            ui.separator();
            selection(ui, view, &mut actions);
            ui.separator();
            ui.horizontal(|ui| {
                if ui.add_enabled(view.can_undo, egui::Button::new("undo")).clicked() {
                    actions.push(PanelAction::Undo);
                }
                if ui.add_enabled(view.can_redo, egui::Button::new("redo")).clicked() {
                    actions.push(PanelAction::Redo);
                }
                if ui.button("save").on_hover_text("Ctrl+S: write the edits into the file").clicked() {
                    actions.push(PanelAction::Save);
                }
                if ui.button("export").on_hover_text("Ctrl+E: the edits as drafter bake --config TOML").clicked() {
                    actions.push(PanelAction::Export);
                }
            });
            if let Some(status) = &view.status {
                ui.colored_label(status.colour(), &status.text);
            }
            egui::CollapsingHeader::new("keys and gestures").default_open(false).show(ui, |ui| {
                for line in KEY_HELP {
                    ui.label(*line);
                }
            });
        });
    actions
}

/// The panel's summary of the keys (README "Editing" has the long form).
const KEY_HELP: &[&str] = &[
    "click: select, Shift+click: add/remove",
    "click a selected part: make it the reference",
    "Ctrl+drag: lasso, drag: the tool (or turn)",
    "A anchor, X scale, D direction, V projector line",
    "[ ] q, , . f, - = p, T transfer, Y style, G flat",
    "Ctrl+Z / Ctrl+Y undo / redo, Ctrl+S save, Ctrl+E export",
    "s style, e edges, l lines, h shadow, p screenshot, F1 panel",
];

fn selection(ui: &mut egui::Ui, view: &PanelView, actions: &mut Vec<PanelAction>) {
    if view.selected.is_empty() {
        ui.label("nothing selected: click a part");
        return;
    }
    ui.label(format!("{} selected", count(view.selected.len(), "part")));
    egui::ScrollArea::vertical().max_height(LISTED_ROWS * 18.0).show(ui, |ui| {
        for part in &view.selected {
            let mark = if part.reference { "▶ " } else { "  " };
            let text = match &part.params {
                Some(p) => format!(
                    "{mark}{} {}: {} q{} f{:.2} p{:.2} {}{}",
                    part.id,
                    part.name,
                    p.style.map_or("scene", PartStyle::name),
                    p.q,
                    p.f,
                    p.p,
                    p.transfer.name(),
                    p.flat.map(|g| format!(" flat {g:.2}")).unwrap_or_default()
                ),
                None => format!("{mark}{} {} (not editable)", part.id, part.name),
            };
            ui.monospace(text);
        }
    });
    let Some(p) = view.selected.iter().find_map(|part| part.params) else { return };
    ui.separator();
    let mut style = p.style;
    egui::ComboBox::from_label("style")
        .selected_text(style.map_or(format!("scene ({})", view.scene_style), |s| s.name().to_owned()))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut style, None, format!("scene ({})", view.scene_style));
            for s in PartStyle::ALL {
                ui.selectable_value(&mut style, Some(s), s.name());
            }
        });
    if style != p.style {
        actions.extend([PanelAction::Live(Adjust::SetStyle(style)), PanelAction::EndLive]);
    }
    let mut q = p.q;
    let r = ui.add(egui::Slider::new(&mut q, 1..=MAX_QUANTIZATION).text("q bands"));
    live(&r, q != p.q, Adjust::SetQ(q), actions);
    let mut f = p.f;
    let r = ui.add(egui::Slider::new(&mut f, 0.0..=1.0).text("f smooth"));
    live(&r, f != p.f, Adjust::SetF(f), actions);
    let mut power = p.p;
    let r = ui.add(egui::Slider::new(&mut power, MIN_POWER..=MAX_POWER).logarithmic(true).text("p power"));
    live(&r, power != p.p, Adjust::SetP(power), actions);
    let mut transfer = p.transfer;
    egui::ComboBox::from_label("transfer γ").selected_text(transfer.name()).show_ui(ui, |ui| {
        for c in TransferCurve::ALL {
            ui.selectable_value(&mut transfer, c, c.name());
        }
    });
    if transfer != p.transfer {
        actions.extend([PanelAction::Live(Adjust::SetTransfer(transfer)), PanelAction::EndLive]);
    }
    ui.horizontal(|ui| {
        let mut flat = p.flat.is_some();
        let r = ui.checkbox(&mut flat, "flat grey");
        if r.changed() {
            let grey = flat.then_some(p.flat.unwrap_or(0.5));
            actions.extend([PanelAction::Live(Adjust::SetFlat(grey)), PanelAction::EndLive]);
        }
        if let Some(g) = p.flat {
            let mut grey = g;
            let r = ui.add(egui::Slider::new(&mut grey, 0.0..=1.0));
            live(&r, grey != g, Adjust::SetFlat(Some(grey)), actions);
        }
    });
}

/// A slider's change: applied live while it is held, one undo step when it is let go (or at
/// once for a click or a key on it).
fn live(response: &egui::Response, changed: bool, adjust: Adjust, actions: &mut Vec<PanelAction>) {
    if changed {
        actions.push(PanelAction::Live(adjust));
    }
    if (changed || response.drag_stopped()) && !response.dragged() {
        actions.push(PanelAction::EndLive);
    }
}

/// The window's last message at its bottom-left corner (where the panel is hidden).
pub fn show_status(ctx: &egui::Context, status: &Status) {
    egui::Area::new(egui::Id::unique("drafter status"))
        .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
        .interactable(false)
        .show(ctx, |ui| {
            egui::Frame::popup(ui.style()).show(ui, |ui| {
                ui.colored_label(status.colour(), &status.text);
            });
        });
}

/// The projector handles of the selection and the lasso in progress, over the frame and under the
/// panel (window pixels; egui's points are pixels / `pixels_per_point`).
pub fn paint_overlay(ctx: &egui::Context, handles: &[Handle], lasso: Option<&[DVec2]>) {
    let painter = ctx.layer_painter(egui::LayerId::new(egui::Order::Background, egui::Id::unique("drafter handles")));
    let scale = 1.0 / ctx.pixels_per_point();
    let at = |p: DVec2| egui::pos2(p.x as f32 * scale, p.y as f32 * scale);
    for h in handles {
        let colour =
            if h.reference { egui::Color32::from_rgb(140, 205, 255) } else { egui::Color32::from_rgb(30, 90, 255) };
        let outline = egui::Stroke::new(4.0, egui::Color32::from_black_alpha(150));
        let stroke = egui::Stroke::new(2.0, colour);
        let anchor = at(h.anchor);
        if let Some(end) = h.end.map(at) {
            painter.line_segment([anchor, end], outline);
            painter.line_segment([anchor, end], stroke);
            // A bar across the end: where the gradient's parameter reaches 1.
            let along = (end - anchor).normalized();
            let across = egui::vec2(-along.y, along.x) * 7.0;
            painter.line_segment([end - across, end + across], outline);
            painter.line_segment([end - across, end + across], stroke);
        }
        painter.circle(anchor, 5.0, colour, outline);
    }
    if let Some(path) = lasso.filter(|p| p.len() >= 2) {
        let points: Vec<egui::Pos2> = path.iter().map(|&p| at(p)).collect();
        painter.add(egui::Shape::line(points, egui::Stroke::new(1.5, egui::Color32::from_rgb(30, 90, 255))));
    }
}

/// egui in the window: its context, winit input and wgpu renderer.
pub struct Overlay {
    pub ctx: egui::Context,
    input: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    /// The panel is shown (F1 toggles it); the handles always are.
    pub panel: bool,
}

impl std::fmt::Debug for Overlay {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Overlay").field("panel", &self.panel).finish_non_exhaustive()
    }
}

impl Overlay {
    pub fn new(window: &winit::window::Window, device: &wgpu::Device, format: wgpu::TextureFormat) -> Overlay {
        let ctx = egui::Context::default();
        let input = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let renderer = egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        Overlay { ctx, input, renderer, panel: true }
    }

    /// Gives egui the event; true when egui used it (a click on the panel), so that the viewer
    /// does not act on it too.
    pub fn on_event(&mut self, window: &winit::window::Window, event: &winit::event::WindowEvent) -> (bool, bool) {
        let response = self.input.on_window_event(window, event);
        (response.consumed, response.repaint)
    }

    /// Runs `ui` and draws its output over `target` (the frame already drawn there). True when
    /// egui wants another frame soon (an animation).
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        window: &winit::window::Window,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
        ui: impl FnMut(&egui::Context),
    ) -> bool {
        let raw = self.input.take_egui_input(window);
        let mut output = self.ctx.run_pass(raw, ui);
        self.input.handle_platform_output(window, output.platform_output);
        let primitives = self.ctx.tessellate(output.shapes, output.pixels_per_point);
        for (id, deltas) in &output.textures_delta.set {
            for delta in deltas {
                self.renderer.update_texture(device, queue, *id, delta);
            }
        }
        let screen =
            egui_wgpu::ScreenDescriptor { size_in_pixels: [size.0, size.1], pixels_per_point: output.pixels_per_point };
        let extra = self.renderer.update_buffers(device, queue, encoder, &primitives, &screen);
        if !extra.is_empty() {
            queue.submit(extra);
        }
        {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui overlay"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.render(&mut pass.forget_lifetime(), &primitives, &screen);
        }
        for id in &output.textures_delta.free {
            self.renderer.free_texture(id);
        }
        // Applied above (epaint checks in debug builds that no delta is dropped unapplied).
        output.textures_delta.clear();
        output.viewport_output.get(&egui::ViewportId::ROOT).is_some_and(|v| v.repaint_delay.is_zero())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(q: u32) -> PartParams {
        PartParams {
            anchor: glam::DVec3::ZERO,
            direction: glam::DVec3::X,
            scale: 1.0,
            q,
            f: 0.5,
            p: 1.0,
            transfer: TransferCurve::Identity,
            style: None,
            flat: None,
        }
    }

    /// Runs the panel once over `view` with `events` (a headless egui pass, no window).
    fn run(ctx: &egui::Context, view: &PanelView, events: Vec<egui::Event>) -> Vec<PanelAction> {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 600.0))),
            events,
            ..Default::default()
        };
        let mut actions = Vec::new();
        ctx.run_pass(input, |ctx| actions = show(ctx, view)).drop_without_applying_deltas();
        actions
    }

    #[test]
    fn the_panel_lists_the_selection_and_a_click_on_a_tool_selects_it() {
        let ctx = egui::Context::default();
        let view = PanelView {
            file: "a.glb".into(),
            parts: 3,
            selected: vec![
                PanelPart { id: 2, name: "bolt".into(), reference: true, params: Some(params(7)) },
                PanelPart { id: 0, name: "plate".into(), reference: false, params: None },
            ],
            scene_style: "gradient".into(),
            ..Default::default()
        };
        // Nothing done: nothing asked for (two passes: egui lays a window out on its first).
        assert!(run(&ctx, &view, vec![]).is_empty());
        assert!(run(&ctx, &view, vec![]).is_empty());
        // Click the "anchor" tool's button.
        let Some(rect) = find_text(&ctx, &view, "anchor") else { panic!("the anchor tool is not on the panel") };
        let at = rect.center();
        let click = vec![
            egui::Event::PointerMoved(at),
            egui::Event::PointerButton {
                pos: at,
                button: egui::PointerButton::Primary,
                pressed: true,
                modifiers: Default::default(),
            },
        ];
        run(&ctx, &view, click);
        let release = vec![egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed: false,
            modifiers: Default::default(),
        }];
        assert_eq!(run(&ctx, &view, release), vec![PanelAction::Tool(Some(Tool::Anchor))]);
    }

    #[test]
    fn the_panel_counts_in_words_and_shows_the_last_message() {
        assert_eq!(
            (count(1, "part"), count(0, "part"), count(2, "part")),
            ("1 part".into(), "0 parts".into(), "2 parts".into())
        );
        let ctx = egui::Context::default();
        let view = PanelView {
            file: "a.glb".into(),
            parts: 1,
            status: Some(Status::error("not saved: a.glb: read-only (mode 0444); not replaced")),
            hint: Some("part 0's gradient runs towards you".into()),
            ..Default::default()
        };
        run(&ctx, &view, vec![]);
        for text in [
            "a.glb: 1 part",
            "not saved: a.glb: read-only (mode 0444); not replaced",
            "part 0's gradient runs towards you",
        ] {
            assert!(find_text(&ctx, &view, text).is_some(), "{text:?} is not on the panel");
        }
        // With the panel hidden the message is shown at the bottom-left corner.
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 600.0))),
            ..Default::default()
        };
        let status = Status::info("saved: a.glb (1 part record changed)");
        // Twice: egui lays an area out on its first pass without showing it.
        ctx.run_pass(input.clone(), |ctx| show_status(ctx, &status)).drop_without_applying_deltas();
        {
            let output = ctx.run_pass(input.clone(), |ctx| show_status(ctx, &status));
            let shown = output.shapes.iter().find_map(|c| match &c.shape {
                egui::Shape::Text(t) if t.galley.job.text == status.text => Some(t.visual_bounding_rect()),
                _ => None,
            });
            output.drop_without_applying_deltas();
            let rect = shown.expect("the message is shown");
            assert!(rect.min.x < 100.0 && rect.max.y > 500.0, "{rect:?}");
        }
    }

    #[test]
    fn the_projector_handles_are_painted_under_the_panel() {
        let ctx = egui::Context::default();
        let view = PanelView { file: "a.glb".into(), parts: 2, ..Default::default() };
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 600.0))),
            ..Default::default()
        };
        // A handle right across the panel (anchored top right).
        let handle = Handle { anchor: DVec2::new(500.0, 40.0), end: Some(DVec2::new(790.0, 40.0)), reference: true };
        let pass = |ctx: &egui::Context| {
            show(ctx, &view);
            paint_overlay(ctx, &[handle], None);
        };
        // Twice: egui lays a window out on its first pass without showing it.
        ctx.run_pass(input.clone(), pass).drop_without_applying_deltas();
        {
            let output = ctx.run_pass(input.clone(), pass);
            // Shapes come in paint order: the handle's dot before the panel's text.
            let dot = output
                .shapes
                .iter()
                .position(|c| matches!(&c.shape, egui::Shape::Circle(d) if d.center == egui::pos2(500.0, 40.0)));
            let text = output
                .shapes
                .iter()
                .position(|c| matches!(&c.shape, egui::Shape::Text(t) if t.galley.job.text == "a.glb: 2 parts"));
            output.drop_without_applying_deltas();
            let (dot, text) = (dot.expect("the handle is painted"), text.expect("the panel is shown"));
            assert!(dot < text, "the handle (shape {dot}) is painted over the panel (shape {text})");
        }
    }

    /// The rectangle of the panel's widget labelled `text`, from the shapes of a pass.
    fn find_text(ctx: &egui::Context, view: &PanelView, text: &str) -> Option<egui::Rect> {
        let input = egui::RawInput {
            screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(800.0, 600.0))),
            ..Default::default()
        };
        let output = ctx.run_pass(input, |ctx| {
            show(ctx, view);
        });
        let rect = output.shapes.iter().find_map(|clipped| match &clipped.shape {
            egui::Shape::Text(t) if t.galley.job.text == text => Some(t.visual_bounding_rect()),
            _ => None,
        });
        output.drop_without_applying_deltas();
        rect
    }
}
