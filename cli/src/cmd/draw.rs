//! `drafter draw FILE -o view.svg|view.pdf|view.dxf [--view AZ,EL] [--ortho] [--size WxH] [--hidden none|dashed|solid]
//! [--style iso128|gooch] [--fill none|flat|bands] [--smooth none|thin|dashed] [--tolerance PX] [--json]`: a vector line drawing of one view with exact hidden lines
//! (drafter-draw, which reads drafter-scene's model and links no GPU code): the baked hard edges and the view's silhouettes, split where they
//! pass behind a surface, chained into polylines, grouped by visibility and class in SVG.
//!
//! Several inputs, a folder, a manifest or `--format` make a catalog: every input drawn into `-o
//! DIR` (`draw_batch.rs`).

use std::path::{Path, PathBuf};

use anyhow::Result;
use drafter_catalog::draw::{Fill, Hidden, Smooth, Style};
use drafter_draw::{self as drawing, DrawOptions, LineStyle};
use drafter_scene::{Model, View};

use crate::cmd::out;
use crate::cmd::render::{parse_size, parse_view};
use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The models to draw: baked .glb/.gltf files (their edges and silhouette hierarchies), or any
    /// model drafter reads (.glb/.gltf, .obj, .stl, .off, .ply), which is then baked in memory with
    /// the default settings first, so it draws the lines its bake would; or folders of them
    /// (recursively). More than one input, a folder, a manifest or --format make a catalog written
    /// under `-o DIR`.
    #[arg(value_name = "INPUT", required_unless_present = "manifest")]
    pub inputs: Vec<PathBuf>,
    /// The drawing to write: .svg, .pdf (the same strokes on one page, a pixel as 0.75 pt) or .dxf
    /// (DXF R2000: a polyline per stroke on layers VISIBLE, HIDDEN and TANGENT, in millimetres, y up).
    /// For a catalog: the output folder, where each input's drawing mirrors its relative path with
    /// the extension of each --format.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Drawing size in pixels (the SVG's user units), WIDTHxHEIGHT: the same view as `render`. On
    /// paper a pixel is 1/96 inch (0.2646 mm): 800x600 is a 211.7 x 158.75 mm page.
    #[arg(long, value_name = "WxH", default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// View direction: azimuth about +y from +z towards +x, and elevation, in degrees.
    #[arg(long, value_name = "AZ,EL", default_value = "35,25", value_parser = parse_view, allow_hyphen_values = true)]
    pub view: (f32, f32),
    /// Orthographic projection instead of perspective.
    #[arg(long)]
    pub ortho: bool,
    /// Lines hidden by surfaces: left out, dashed or thin solid, in a group of their own.
    #[arg(long, value_enum, default_value_t = Hidden::None)]
    pub hidden: Hidden,
    /// Tangent edges (the borders between the input's CAD faces that meet below the crease angle: a
    /// fillet meeting a plane): thin solid lines of their own class `tangent`, thin dashed, or left
    /// out; where one is this view's outline it is drawn as a silhouette whatever this says.
    #[arg(long, value_enum, default_value_t = Smooth::Thin)]
    pub smooth: Smooth,
    /// Line widths and dashes: ISO 128 (one wide visible width, 0.5 mm; hidden lines narrow,
    /// 0.25 mm, dashed 3 mm on and 0.75 mm off), or Gooch et al.'s illustration weights in pixels
    /// (silhouettes 1.6, boundaries 1.2, creases 0.9, hidden 0.6 grey).
    #[arg(long, value_enum, default_value_t = Style::Iso128)]
    pub style: Style,
    /// Part fills under the lines, painted farthest part first: none, each part's area in a flat
    /// grey, or its gradient bands (Lux et al. 2013) as grey regions.
    #[arg(long, value_enum, default_value_t = Fill::None)]
    pub fill: Fill,
    /// Pieces shorter than this many pixels are dropped and end points closer than it joined.
    #[arg(long, value_name = "PX", default_value_t = 0.05, allow_negative_numbers = true)]
    pub tolerance: f64,
    /// Print the drawing's figures as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Print nothing but errors.
    #[arg(long, short)]
    pub quiet: bool,
    /// Refuse a model that lists more triangles than this.
    #[arg(long, value_name = "N", default_value_t = drafter_io::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
    #[command(flatten)]
    pub sheet: crate::cmd::sheet::SheetArgs,
    #[command(flatten)]
    pub catalog: crate::cmd::draw_batch::CatalogArgs,
}

impl Args {
    /// The one input of a single drawing (a catalog named only by manifests has none: its
    /// options are then checked against an empty name, which only titles and default units read).
    pub fn file(&self) -> &Path {
        self.inputs.first().map_or(Path::new(""), PathBuf::as_path)
    }
}

/// Reads the model to draw (`drafter_catalog::draw::load`: a file without `DRAFTER_illustration`
/// data is baked in memory with the default settings first, so it draws the lines its bake would).
/// Import errors keep their exit code; a file that loads but cannot be drawn is bad input.
pub(crate) fn load(path: &Path, max_triangles: u64) -> Result<(Model, bool)> {
    let limits = drafter_io::Limits { max_triangles };
    let bytes = drafter_catalog::job::read_input(path)?;
    Ok(drafter_catalog::draw::load(path, bytes, &limits)?)
}

/// What `-o` writes, by its extension.
enum Format {
    Svg,
    Pdf,
    Dxf,
}

pub fn run(args: Args) -> Result<()> {
    if crate::cmd::draw_batch::is_catalog(&args) {
        return crate::cmd::draw_batch::run(&args);
    }
    if args.catalog.cache.is_some() {
        return crate::cmd::draw_batch::single(&args);
    }
    if args.sheet.sheet.is_some() {
        return crate::cmd::sheet::run(args);
    }
    let extension = args.output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format = match extension.as_deref() {
        Some("svg") => Format::Svg,
        Some("pdf") => Format::Pdf,
        Some("dxf") => Format::Dxf,
        _ => return Err(BadInput(format!("{}: output must end in .svg, .pdf or .dxf", args.output.display())).into()),
    };
    let (w, h) = args.size;
    if w == 0 || h == 0 || w > 65_536 || h > 65_536 {
        return Err(BadInput(format!("--size {w}x{h}: each side must be 1 to 65536 pixels")).into());
    }
    if !(args.tolerance.is_finite() && args.tolerance >= 0.0) {
        return Err(
            BadInput(format!("--tolerance {}: must be a finite number of pixels, 0 or more", args.tolerance)).into()
        );
    }
    let view = View { azimuth_deg: args.view.0, elevation_deg: args.view.1 };
    if !view.azimuth_deg.is_finite() {
        return Err(BadInput(format!(
            "--view {},{}: azimuth must be a finite number of degrees",
            args.view.0, args.view.1
        ))
        .into());
    }
    if !(view.elevation_deg > -90.0 && view.elevation_deg < 90.0) {
        return Err(BadInput(format!("--view {},{}: elevation must be in (-90, 90)", args.view.0, args.view.1)).into());
    }
    // The output's folder before any work: a drawing of a large model takes seconds.
    let folder = args.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        return Err(BadInput(format!("{}: no folder {} to write into", args.output.display(), folder.display())).into());
    }
    if args.output.is_dir() {
        return Err(BadInput(format!("{}: is a folder", args.output.display())).into());
    }
    let (model, baked_here) = load(args.file(), args.max_triangles)?;
    let options = DrawOptions {
        size: args.size,
        view,
        orthographic: args.ortho,
        hidden: args.hidden.into(),
        tolerance_px: args.tolerance,
        fill: args.fill.into(),
        smooth: args.smooth.into(),
        ..DrawOptions::default()
    };
    let drawing = drawing::draw(&model, &options);
    let style = LineStyle::from(args.style);
    let bytes = match format {
        Format::Svg => drawing::to_svg(&drawing, options.hidden, style).into_bytes(),
        Format::Pdf => drawing::to_pdf(&drawing, options.hidden, style),
        Format::Dxf => drawing::to_dxf(&drawing, options.hidden, style),
    };
    drafter_catalog::output::write_atomically(&args.output, &bytes)?;
    let s = &drawing.stats;
    if args.json {
        let value = serde_json::json!({
            "output": args.output.display().to_string(),
            "bytes": bytes.len(),
            "strokes": drawing.strokes.len(),
            "edges": s.edges,
            "silhouettes": s.silhouettes,
            "duplicates": s.duplicates,
            "merged": s.merged,
            "triangles": s.triangles,
            "pairs_tested": s.pairs_tested,
            "visible_px": s.visible_px,
            "hidden_px": s.hidden_px,
            "ms": s.elapsed.as_secs_f64() * 1e3,
        });
        out!("{value}");
    }
    if !args.quiet {
        eprintln!(
            "drew {} → {}: {} strokes, {:.0} px visible, {:.0} px hidden, from {} edges ({} silhouettes) over {} triangles in {:.0} ms; {} bytes",
            args.file().display(),
            args.output.display(),
            drawing.strokes.len(),
            s.visible_px,
            s.hidden_px,
            s.edges,
            s.silhouettes,
            s.triangles,
            s.elapsed.as_secs_f64() * 1e3,
            bytes.len()
        );
        if baked_here {
            eprintln!(
                "  note: {} has no baked lines: baked in memory with the default settings",
                args.file().display()
            );
        }
        for notice in &model.notices {
            eprintln!("  note: {notice}");
        }
    }
    Ok(())
}
