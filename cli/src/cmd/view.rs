//! `drafter view FILE [--style S] [--size WxH] [--view AZ,EL] [--edges] [--lines] [--shadow S]
//! [--ortho]`: the interactive window (winit). Drag turns the object, the wheel zooms, right or
//! middle drag pans, `1`–`7`/`S` switch the style, `E`/`L`/`H` toggle edges, lines and the shadow,
//! a click selects a part (printed and shown in the title), `P` saves a screenshot; parts are
//! edited in place (Lux et al. 2013 §4: anchor, scale, direction and projector-line tools, gradient
//! keys, undo, `Ctrl`+`S` saves into the file, `Ctrl`+`E` exports the edits as bake overrides); see
//! `drafter_app::window` and `--help` ([`KEYS`]). Without a display it fails with one line (exit
//! code 2).

use std::path::PathBuf;

use anyhow::Result;
use drafter_app::window::WindowError;
use drafter_render::{Enhancements, RenderOptions, View};

use crate::cmd::render::load;
use crate::exit::BadInput;
use drafter_render::ShadowMode;

/// `drafter view --help`'s text after the options: the window's keys, the editing gestures, saving
/// and exporting (the README's "Editing the illustration" has the long form).
const KEYS: &str = "\
Window:
  left drag turns the object, wheel zooms, right or middle drag pans; 1-7 or S style, E edges,
  L lines, H shadow, O orthographic, R reset the view, P screenshot PNG beside the model, F1 panel;
  Esc or Q quits (with unsaved edits it asks first: Esc again quits without saving).

Editing the parts' gradients (Lux et al. 2013 \u{a7}4; baked files only):
  click                select a part (on a selected part: make it the reference); Shift+click adds
                       or removes; Ctrl+drag lassoes (Ctrl+Shift adds)
  A, then drag         anchor: move the gradient across the part (a click centres it)
  X, then drag         scale: away from the anchor stretches the gradient, towards it shortens it
                       (a drag from the anchor's dot pulls the projector's end)
  D, then drag         direction: right turns it clockwise about the anchor, left counter-
                       clockwise, 0.5 degrees a pixel (one running towards you tilts towards the drag)
  V, then drag         draw the projector: anchor at the start, direction and scale along the line
  the same key again   back to turning the object
  [ ]  , .  - =        q down/up, f down/up, p down/up;  T transfer curve, Y style hint, G flat grey
  Ctrl+Z, Ctrl+Y       undo, redo
  Ctrl+S               save: the edited part records are written into FILE (atomically; its mode and
                       owner kept; a read-only file is refused, with a message in the window)
  Ctrl+E               export: write <stem>.edits.toml beside FILE, for
                       `drafter bake SOURCE --config <stem>.edits.toml` (nothing when no part is edited)

Without a display it exits with code 2 and one line.";

#[derive(Debug, clap::Args)]
#[command(after_help = KEYS)]
pub struct Args {
    /// The model to show: a baked .glb/.gltf, or any glTF, OBJ, STL, OFF, PLY.
    pub file: PathBuf,
    /// Shading style to start with.
    #[arg(long, value_enum, default_value_t = drafter_render::Style::Gradient)]
    pub style: drafter_render::Style,
    /// Initial window size in pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1024x768", value_parser = crate::cmd::render::parse_size)]
    pub size: (u32, u32),
    /// Initial view: azimuth and elevation in degrees.
    #[arg(long, value_name = "AZ,EL", default_value = "35,25", value_parser = crate::cmd::render::parse_view, allow_hyphen_values = true)]
    pub view: (f32, f32),
    /// Start with image-space edges on.
    #[arg(long)]
    pub edges: bool,
    /// Start with the baked lines on.
    #[arg(long)]
    pub lines: bool,
    /// Start with this drop shadow.
    #[arg(long, value_enum, default_value_t = ShadowMode::None)]
    pub shadow: ShadowMode,
    /// Start with an orthographic camera.
    #[arg(long)]
    pub ortho: bool,
    /// Refuse a model that lists more triangles than this (over all meshes, an instanced mesh
    /// once; a glTF's are counted before any is read).
    #[arg(long, value_name = "N", default_value_t = drafter_io::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
}

pub fn run(args: Args) -> Result<()> {
    let options = RenderOptions {
        size: args.size,
        style: args.style,
        view: View { azimuth_deg: args.view.0, elevation_deg: args.view.1 },
        orthographic: args.ortho,
        enhancements: if args.edges { Enhancements::ALL } else { Enhancements::default() },
        lines: args.lines,
        shadow: args.shadow,
        ..RenderOptions::default()
    };
    options.validate().map_err(BadInput)?;
    let model = load(&args.file, args.max_triangles)?;
    for notice in &model.notices {
        eprintln!("  note: {notice}");
    }
    // Saves and exports from the window go through the bake's atomic writer: a signal during a
    // save leaves the previous file intact and no temporary file. An existing file keeps its mode
    // and owner, and one the user cannot write is refused, as editors do.
    drafter_catalog::interrupt::install();
    let writer = |path: &std::path::Path, bytes: &[u8]| {
        drafter_catalog::output::replace_in_place(path, bytes).map_err(|e| e.to_string())
    };
    drafter_app::window::run(model, &args.file, options, &writer).map_err(|e| match e {
        WindowError::NoDisplay(_) => anyhow::Error::from(BadInput(e.to_string())),
        other => anyhow::Error::from(other),
    })
}
