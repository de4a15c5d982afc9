//! `drafter draw FILE --sheet A4|A3|A2|A1|A0 [--views front,top,right,iso] [--projection first|third]
//! [--scale 1:2] [--up y] [--front z] [--units m] [--date TEXT] -o sheet.svg|sheet.pdf|sheet.dxf`: the standard
//! views of a model on one drawing sheet (drafter-draw's `sheet`), the options `draw` flattens in
//! and the glue that runs them.

use std::path::Path;

use anyhow::Result;
use drafter_draw::sheet::{self, Angle, Axis, Scale, SheetOptions, SheetSize, ViewKind};
use drafter_draw::{DrawOptions, LineStyle};

use crate::cmd::draw::Args;
use crate::cmd::out;
use crate::exit::BadInput;

/// The sheet's options, part of `drafter draw`'s.
#[derive(Debug, clap::Args)]
pub struct SheetArgs {
    /// Draw a sheet of the standard views instead of one view: an ISO 216 size, landscape, with an
    /// ISO 5457 border (20 mm filing margin on the left, 10 mm elsewhere) and a title block at the
    /// lower right (title from the file's name, scale, projection symbol, size, date). --size,
    /// --view, --ortho and --fill do not apply to a sheet.
    #[arg(long, value_name = "A4|A3|A2|A1|A0")]
    pub sheet: Option<String>,
    /// The sheet's views, comma-separated: front, top, right, left, bottom, rear (orthographic)
    /// and iso (orthographic, from front, right and top alike: azimuth 45, elevation 35.264).
    #[arg(long, value_name = "LIST", default_value = "front,top,right,iso")]
    pub views: String,
    /// Where the views go around the front view: first angle (ISO method E, the default, as ISO
    /// practice: the top view below, the right view to the left) or third angle (ASME: the top
    /// view above, the right view to the right).
    #[arg(long, value_enum, default_value_t = ProjectionArg::First)]
    pub projection: ProjectionArg,
    /// The scale of every view, PAPER:REAL (1:2 draws 2 mm of the model as 1 mm); by default the
    /// largest of the ISO 5455 series (..., 5:1, 2:1, 1:1, 1:2, 1:5, 1:10, 1:20, ...) at which the
    /// views fit. A scale at which they do not fit is refused.
    #[arg(long, value_name = "P:R")]
    pub scale: Option<String>,
    /// The model's up axis: x, y, z, -x, -y or -z (default y, glTF's up).
    #[arg(long, value_name = "AXIS", default_value = "y", allow_hyphen_values = true)]
    pub up: String,
    /// The way the model's front faces, towards the front view's viewer: x, y, z, -x, -y or -z
    /// (default z: glTF assets face +z, so the front view looks along -z).
    #[arg(long, value_name = "AXIS", default_value = "z", allow_hyphen_values = true)]
    pub front: String,
    /// The length of one model unit, for the scale: m, cm, mm or in. Default: m for glTF and GLB
    /// (the glTF specification's unit), mm for OBJ, STL, OFF and PLY (what CAD programs export).
    #[arg(long, value_enum)]
    pub units: Option<UnitArg>,
    /// The title block's date (any text, as 2026-12-01); left empty by default so that a sheet's
    /// bytes depend only on its input.
    #[arg(long, value_name = "TEXT")]
    pub date: Option<String>,
    /// The title block's title (default: the file's name without its extension).
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// A section view A-A through this plane, in model units: x=10, y=-2.5, z=0, or a point and a
    /// normal px,py,pz,nx,ny,nz. The closed bodies are cut and their cut faces hatched (ISO 128-50,
    /// 45 degree thin lines, direction and spacing varied by part); the view looks down the normal
    /// at what lies below the plane, its lines exact as in the other views. Bodies that are not
    /// closed are left uncut and counted.
    #[arg(long, value_name = "PLANE", allow_hyphen_values = true)]
    pub section: Option<String>,
    /// Parts the section leaves whole, by name, comma-separated: `*` matches any run of characters,
    /// case is ignored (ISO 128-50 does not section shafts, bolts, pins or keys:
    /// --uncut 'shaft*,*bolt*,pin*'). They are drawn in full, in front of the plane too.
    #[arg(long, value_name = "PATTERNS")]
    pub uncut: Option<String>,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ProjectionArg {
    First,
    Third,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum UnitArg {
    M,
    Cm,
    Mm,
    In,
}

impl UnitArg {
    fn mm(self) -> f64 {
        match self {
            UnitArg::M => 1000.0,
            UnitArg::Cm => 10.0,
            UnitArg::Mm => 1.0,
            UnitArg::In => 25.4,
        }
    }
}

/// Millimetres per unit of `file`'s coordinates when `--units` does not say: glTF's are metres.
fn default_mm_per_unit(file: &Path) -> f64 {
    let extension = file.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("gltf" | "glb") => 1000.0,
        _ => 1.0,
    }
}

/// The sheet's options from the command line, every mistake refused by name before any work.
fn options(args: &Args) -> Result<(SheetOptions, SheetSize)> {
    let s = &args.sheet;
    let size: SheetSize = s.sheet.as_deref().unwrap_or("A3").parse().map_err(BadInput)?;
    let views = ViewKind::parse_list(&s.views).map_err(BadInput)?;
    let scale = s.scale.as_deref().map(str::parse::<Scale>).transpose().map_err(BadInput)?;
    let axis = |flag: &str, text: &str| text.parse::<Axis>().map_err(|e| BadInput(format!("--{flag} {e}")));
    let (up, front) = (axis("up", &s.up)?, axis("front", &s.front)?);
    if up.vector().cross(front.vector()) == glam::DVec3::ZERO {
        return Err(BadInput(format!("--up {} --front {}: must be two different axes", s.up, s.front)).into());
    }
    if !(args.tolerance.is_finite() && args.tolerance >= 0.0) {
        return Err(
            BadInput(format!("--tolerance {}: must be a finite number of pixels, 0 or more", args.tolerance)).into()
        );
    }
    let title = s.title.clone().unwrap_or_else(|| {
        let name = args.file.file_stem().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        name.strip_suffix(".baked").map(str::to_string).unwrap_or(name)
    });
    let options = SheetOptions {
        size,
        views,
        angle: match s.projection {
            ProjectionArg::First => Angle::First,
            ProjectionArg::Third => Angle::Third,
        },
        scale,
        front,
        up,
        mm_per_unit: s.units.map_or_else(|| default_mm_per_unit(&args.file), UnitArg::mm),
        title,
        date: s.date.clone(),
        section: s.section.as_deref().map(sheet::section::Plane::parse).transpose().map_err(BadInput)?,
        uncut: s
            .uncut
            .as_deref()
            .map(|list| list.split(',').map(str::trim).filter(|p| !p.is_empty()).map(str::to_string).collect())
            .unwrap_or_default(),
        draw: DrawOptions {
            hidden: args.hidden.into(),
            tolerance_px: args.tolerance,
            smooth: args.smooth.into(),
            ..DrawOptions::default()
        },
    };
    Ok((options, size))
}

/// `drafter draw … --sheet SIZE`.
pub fn run(args: Args) -> Result<()> {
    let extension = args.output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let write: fn(&sheet::Sheet, LineStyle) -> Vec<u8> = match extension.as_deref() {
        Some("svg") => |sheet, style| sheet::to_svg(sheet, style).into_bytes(),
        Some("pdf") => sheet::to_pdf,
        Some("dxf") => sheet::to_dxf,
        _ => {
            return Err(BadInput(format!("{}: a sheet is written as .svg, .pdf or .dxf", args.output.display())).into());
        }
    };
    let (options, size) = options(&args)?;
    let folder = args.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !folder.is_dir() {
        return Err(BadInput(format!("{}: no folder {} to write into", args.output.display(), folder.display())).into());
    }
    if args.output.is_dir() {
        return Err(BadInput(format!("{}: is a folder", args.output.display())).into());
    }
    let start = std::time::Instant::now();
    let (model, baked_here) = crate::cmd::draw::load(&args.file, args.max_triangles)?;
    let loaded = start.elapsed();
    let sheet = sheet::draw_sheet(&model, &options).map_err(|e| BadInput(e.to_string()))?;
    let drawn = start.elapsed() - loaded;
    let style = LineStyle::from(args.style);
    let bytes = write(&sheet, style);
    drafter_catalog::output::write_atomically(&args.output, &bytes)?;
    let strokes: usize = sheet.views.iter().map(|v| v.drawing.strokes.len()).sum();
    if args.json {
        let views: Vec<serde_json::Value> = sheet
            .views
            .iter()
            .map(|v| {
                let s = &v.drawing.stats;
                serde_json::json!({
                    "view": v.kind.name(),
                    "rect_mm": [v.rect.min.x, v.rect.min.y, v.rect.max.x, v.rect.max.y],
                    "strokes": v.drawing.strokes.len(),
                    "edges": s.edges,
                    "silhouettes": s.silhouettes,
                    "visible_px": s.visible_px,
                    "hidden_px": s.hidden_px,
                    "ms": s.elapsed.as_secs_f64() * 1e3,
                })
            })
            .collect();
        let value = serde_json::json!({
            "output": args.output.display().to_string(),
            "bytes": bytes.len(),
            "sheet": size.name(),
            "scale": sheet.scale.to_string(),
            "projection": sheet.angle.name(),
            "strokes": strokes,
            "views": views,
            "load_ms": loaded.as_secs_f64() * 1e3,
            "ms": drawn.as_secs_f64() * 1e3,
        });
        out!("{value}");
    }
    if !args.quiet {
        eprintln!(
            "drew {} → {}: {} sheet at {}, {} views, {} strokes in {:.0} ms (loading {:.0} ms); {} bytes",
            args.file.display(),
            args.output.display(),
            size.name(),
            sheet.scale,
            sheet.views.len(),
            strokes,
            drawn.as_secs_f64() * 1e3,
            loaded.as_secs_f64() * 1e3,
            bytes.len()
        );
        if sheet.open_components > 0 {
            eprintln!(
                "  note: {} bodies the section plane crosses are not closed surfaces: left uncut",
                sheet.open_components
            );
        }
        if baked_here {
            eprintln!("  note: {} has no baked lines: baked in memory with the default settings", args.file.display());
        }
        for notice in &model.notices {
            eprintln!("  note: {notice}");
        }
    }
    Ok(())
}
