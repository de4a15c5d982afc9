//! `drafter draw FILE --sheet A4|A3|A2|A1|A0 [--views front,top,right,iso] [--projection first|third]
//! [--scale 1:2] [--up y] [--front z] [--units m] [--date TEXT] -o sheet.svg|sheet.pdf|sheet.dxf`: the standard
//! views of a model on one drawing sheet (drafter-draw's `sheet`), the options `draw` flattens in
//! and the glue that runs them.

use std::path::Path;

use anyhow::Result;
use drafter_catalog::draw::Plan;
use drafter_draw::LineStyle;
use drafter_draw::sheet::{self, SheetOptions, SheetSize};

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
    #[arg(long, value_enum, default_value_t = drafter_catalog::draw::Projection::First)]
    pub projection: drafter_catalog::draw::Projection,
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
    pub units: Option<drafter_catalog::draw::Units>,
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

impl SheetArgs {
    /// The sheet's options as drafter-catalog's plain value (what a catalog and Python draw with).
    pub fn spec(&self) -> Option<drafter_catalog::draw::SheetSpec> {
        let size = self.sheet.clone()?;
        Some(drafter_catalog::draw::SheetSpec {
            size,
            views: vec![self.views.clone()],
            projection: self.projection,
            scale: self.scale.clone(),
            up: self.up.clone(),
            front: self.front.clone(),
            units: self.units,
            date: self.date.clone(),
            title: self.title.clone(),
            section: self.section.clone(),
            uncut: self.uncut.as_deref().map(|list| list.split(',').map(str::to_string).collect()).unwrap_or_default(),
        })
    }
}

/// The sheet's options from the command line, every mistake refused by name before any work
/// (`drafter_catalog::draw::DrawSpec::resolve`, as a catalog of sheets and Python resolve them).
fn options(args: &Args) -> Result<(SheetOptions, SheetSize)> {
    let spec = crate::cmd::draw_batch::spec(args);
    match spec.resolve(args.file()).map_err(|e| BadInput(e.to_string()))?.plan {
        Plan::Sheet(options) => {
            let size = options.size;
            Ok((*options, size))
        }
        Plan::View(_) => Err(BadInput("--sheet: no sheet size given".into()).into()),
    }
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
    let (model, baked_here) = crate::cmd::draw::load(args.file(), args.max_triangles)?;
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
            args.file().display(),
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
