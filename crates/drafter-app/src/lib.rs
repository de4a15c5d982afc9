//! drafter-app: the desktop side of `drafter view`, drafter-render's frame in a window with the
//! illustrator's editing tools (Lux et al. 2013 §4).
//!
//! * [`window`]: the winit 0.30 event loop. Its input handling is pure functions
//!   ([`window::Orbit`], [`window::action_for_key`], [`window::edit_command_for_key`]) tested
//!   without a display; the view controls themselves are drafter-render's
//!   [`drafter_render::controls`], which the browser page (`web/`) shares.
//! * [`panel`]: the editing panel and the projector handles in egui 0.37, drawn on the renderer's
//!   own wgpu device (egui-winit input, egui-wgpu painting).
//! * [`edit`]: the edits as plain data and functions: selection with a reference part, the
//!   projector manipulators, gradient keys, undo/redo, the save and the TOML export. No window or
//!   GPU type: its tests, `drafter bench parts` and the window call the same functions. An edit
//!   rewrites the part table only ([`drafter_render::Renderer::update_parts`]).
//!
//! The renderer builds for the browser without any of this; winit and egui are named here and in
//! the CLI only (`cli/tests/architecture.rs` checks the arrows).

pub mod edit;
pub mod panel;
pub mod window;
