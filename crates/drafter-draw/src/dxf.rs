//! The drawing as DXF (`drafter draw FILE -o view.dxf`): AutoCAD's exchange format, which every CAD
//! program imports.
//!
//! # What is written
//! DXF R2000 (`AC1015`, ASCII), the oldest version with lineweights (group 370): the same strokes
//! as [`crate::to_svg`], in the same order ([`crate::strokes_in_order`]), one `LWPOLYLINE` per
//! stroke (an SVG path), on the page of [`crate::style`] in millimetres with y up (`$INSUNITS` 4,
//! `$MEASUREMENT` 1): a pixel `(x, y)` of the drawing is `(x, height − y) · 25.4/96` mm, so the
//! drawing lies on the sheet `(0, 0)–(width, height) · 25.4/96` (`$LIMMIN`/`$LIMMAX`) at 1:1.
//!
//! Layers by what a draughtsman switches on and off, each with its style's pen:
//! - `VISIBLE`: every visible line (outlines, creases, boundaries, part borders, non-manifold
//!   edges); under `iso128` 0.50 mm, continuous, colour 7 (black on paper);
//! - `HIDDEN`: the hidden lines when the drawing has them; under `iso128` 0.25 mm with the
//!   linetype `HIDDEN`, ISO 128-20 type 02 (dash 12 d = 3 mm, gap 3 d = 0.75 mm), defined in the
//!   file's `LTYPE` table so no `.lin` file is needed;
//! - `TANGENT`: tangent edges, where the drawing has them.
//!
//! Entities take their layer's pen (`BYLAYER`); one whose style gives it another width or grey
//! (`--style gooch`'s three visible weights) carries its own lineweight (370) or colour (62).
//! DXF allows only its standard lineweights (0.05 … 2.11 mm), so a pen width is written as the
//! nearest of them: ISO 128's 0.25 and 0.5 mm are among them, exactly; Gooch's pixel widths are
//! rounded (1.6 px = 0.42 mm is written 0.40 mm).
//!
//! The file is complete as AutoCAD writes one (handles, the nine symbol tables, the model and
//! paper space blocks and layouts, the root dictionary with the plot style placeholder that R2000
//! layers point to), so readers need repair nothing; its bytes depend only on the drawing and the
//! style (handles in writing order, numbers at fixed decimals, no dates). Read back by ezdxf's
//! `recover` with 0 audit errors and fixes, and printed by LibreCAD's `dxf2pdf`
//! (`cli/tests/dxf.rs`).
//!
//! # Why by hand
//! The one maintained Rust crate for DXF, `dxf` (IxMilia, 0.6), reads and writes every entity,
//! table and header variable, its code generated from XML specifications by a build script, and
//! brings `image`, `chrono`, `uuid` and `num` with it. drafter writes three kinds of records
//! (symbol tables, `LWPOLYLINE`, a few objects) in one pass of a few hundred lines, with no
//! dependency or build step to keep in step, and the bytes under its own control (deterministic,
//! no dates).
//!
//! Limits: 2D only (the projected drawing); no part information (layers carry visibility, not
//! parts: a part is a CAD block's job, which a hidden-line drawing does not have); fills
//! (`--fill`) are not written.

use std::fmt::Write as _;

use drafter_scene::edges::LineClass;
use glam::DVec2;

use crate::style::{Length, LineStyle, MM_PER_PX, Pen};
use crate::{Drawing, Hidden, Stroke, pen_of, strokes_in_order};

/// DXF's lineweights (group 370), in hundredths of a millimetre: the only values a reader accepts.
const LINEWEIGHTS: [i64; 24] =
    [0, 5, 9, 13, 15, 18, 20, 25, 30, 35, 40, 50, 53, 60, 70, 80, 90, 100, 106, 120, 140, 158, 200, 211];

/// Fixed handles of the file's tables and objects (hexadecimal in the file); entities follow from
/// [`FIRST_ENTITY`].
mod handle {
    pub const LAYER_TABLE: u32 = 0x1;
    pub const LTYPE_TABLE: u32 = 0x2;
    pub const APPID_TABLE: u32 = 0x3;
    pub const DIMSTYLE_TABLE: u32 = 0x4;
    pub const STYLE_TABLE: u32 = 0x5;
    pub const UCS_TABLE: u32 = 0x6;
    pub const VIEW_TABLE: u32 = 0x7;
    pub const VPORT_TABLE: u32 = 0x8;
    pub const BLOCK_RECORD_TABLE: u32 = 0x9;
    pub const ROOT_DICTIONARY: u32 = 0xA;
    pub const GROUP_DICTIONARY: u32 = 0xB;
    pub const LAYOUT_DICTIONARY: u32 = 0xC;
    pub const PLOT_STYLE_DICTIONARY: u32 = 0xD;
    pub const PLOT_STYLE_NORMAL: u32 = 0xE;
    pub const MODEL_LAYOUT: u32 = 0xF;
    pub const PAPER_LAYOUT: u32 = 0x10;
    pub const MODEL_SPACE: u32 = 0x11;
    pub const MODEL_BLOCK: u32 = 0x12;
    pub const MODEL_ENDBLK: u32 = 0x13;
    pub const PAPER_SPACE: u32 = 0x14;
    pub const PAPER_BLOCK: u32 = 0x15;
    pub const PAPER_ENDBLK: u32 = 0x16;
    pub const ACTIVE_VPORT: u32 = 0x17;
    pub const STANDARD_STYLE: u32 = 0x18;
    pub const ACAD_APPID: u32 = 0x19;
    pub const STANDARD_DIMSTYLE: u32 = 0x1A;
    /// Linetypes from here, then layers.
    pub const FIRST_RECORD: u32 = 0x20;
    pub const FIRST_ENTITY: u32 = 0x100;
}

/// The layer a stroke goes on.
pub fn layer_of(class: LineClass, visible: bool) -> &'static str {
    if !visible {
        return "HIDDEN";
    }
    match class {
        LineClass::Silhouette
        | LineClass::Crease
        | LineClass::Boundary
        | LineClass::PartBorder
        | LineClass::NonManifold => "VISIBLE",
        // Tangent edges, where the scene has them.
        #[allow(unreachable_patterns)]
        _ => "TANGENT",
    }
}

/// One layer of the file: its name, pen and linetype name.
struct Layer {
    name: &'static str,
    pen: Pen,
    linetype: &'static str,
}

/// Polylines beside a drawing's strokes, on a layer of their own (a sheet's border, title block
/// and lettering, [`crate::sheet`]), in the drawing's pixels; each carries its own lineweight
/// where its width is not the layer's.
#[derive(Clone, Copy, Debug)]
pub struct ExtraLayer<'a> {
    pub name: &'static str,
    /// The layer's pen; continuous lines only.
    pub pen: Pen,
    pub lines: &'a [(Length, Vec<DVec2>)],
}

/// The drawing as a DXF R2000 file (see the module docs), with its hidden lines as `hidden` says
/// and the pens of `style`.
pub fn to_dxf(drawing: &Drawing, hidden: Hidden, style: LineStyle) -> Vec<u8> {
    to_dxf_with(drawing, hidden, style, &[])
}

/// [`to_dxf`] with `extra` layers of polylines after the drawing's strokes.
pub fn to_dxf_with(drawing: &Drawing, hidden: Hidden, style: LineStyle, extra: &[ExtraLayer]) -> Vec<u8> {
    let strokes: Vec<&Stroke> = strokes_in_order(drawing, hidden).collect();
    // Layers: VISIBLE and HIDDEN always (a reader sees what the drawing can hold), TANGENT when
    // strokes go there. A layer's pen: its outlines' for VISIBLE, the hidden lines' for HIDDEN,
    // its first stroke's otherwise.
    let mut layers = vec![
        Layer { name: "VISIBLE", pen: style.pen(LineClass::Silhouette, true, hidden), linetype: "Continuous" },
        Layer { name: "HIDDEN", pen: style.pen(LineClass::Crease, false, hidden), linetype: "Continuous" },
    ];
    for stroke in &strokes {
        let name = layer_of(stroke.class, stroke.visible);
        if !layers.iter().any(|l| l.name == name) {
            layers.push(Layer {
                name,
                pen: pen_of(drawing, style, stroke.class, stroke.visible, hidden),
                linetype: "Continuous",
            });
        }
    }
    for layer in extra {
        layers.push(Layer { name: layer.name, pen: Pen { dash: None, ..layer.pen }, linetype: "Continuous" });
    }
    for layer in &mut layers {
        if layer.pen.dash.is_some() {
            layer.linetype = layer.name;
        }
    }

    let (width_mm, height_mm) = (f64::from(drawing.width) * MM_PER_PX, f64::from(drawing.height) * MM_PER_PX);
    let to_mm = |p: DVec2| DVec2::new(p.x * MM_PER_PX, (f64::from(drawing.height) - p.y) * MM_PER_PX);
    // The extents of what is drawn (the sheet when nothing is).
    let (mut low, mut high) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    let extra_points = extra.iter().flat_map(|l| l.lines.iter().flat_map(|(_, points)| points));
    for p in strokes.iter().flat_map(|s| &s.points).chain(extra_points) {
        let q = to_mm(*p);
        (low, high) = (low.min(q), high.max(q));
    }
    if low.x > high.x {
        (low, high) = (DVec2::ZERO, DVec2::new(width_mm, height_mm));
    }

    let mut w = Writer::default();
    let extra_lines: usize = extra.iter().map(|l| l.lines.len()).sum();
    let entities_end = handle::FIRST_ENTITY + (strokes.len() + extra_lines) as u32;

    // HEADER
    w.section("HEADER");
    w.var("$ACADVER").str(1, "AC1015");
    w.var("$ACADMAINTVER").int(70, 6);
    w.var("$DWGCODEPAGE").str(3, "ANSI_1252");
    w.var("$INSBASE").point(10, DVec2::ZERO, true);
    w.var("$EXTMIN").point(10, low, true);
    w.var("$EXTMAX").point(10, high, true);
    w.var("$LIMMIN").point(10, DVec2::ZERO, false);
    w.var("$LIMMAX").point(10, DVec2::new(width_mm, height_mm), false);
    w.var("$LTSCALE").real(40, 1.0);
    w.var("$PSLTSCALE").int(70, 1);
    w.var("$CLAYER").str(8, "0");
    w.var("$CELTYPE").str(6, "ByLayer");
    w.var("$CELWEIGHT").int(370, -1);
    w.var("$LUNITS").int(70, 2);
    w.var("$INSUNITS").int(70, 4);
    w.var("$MEASUREMENT").int(70, 1);
    w.var("$LWDISPLAY").int(290, 1);
    w.var("$HANDSEED").handle(5, entities_end);
    w.end_section();

    // CLASSES: the object classes the OBJECTS section uses that are not built into DXF.
    w.section("CLASSES");
    for (name, cpp) in [
        ("ACDBDICTIONARYWDFLT", "AcDbDictionaryWithDefault"),
        ("ACDBPLACEHOLDER", "AcDbPlaceHolder"),
        ("LAYOUT", "AcDbLayout"),
    ] {
        w.str(0, "CLASS").str(1, name).str(2, cpp).str(3, "ObjectDBX Classes").int(90, 0).int(280, 0).int(281, 0);
    }
    w.end_section();

    // TABLES
    w.section("TABLES");
    w.table("VPORT", handle::VPORT_TABLE, 1);
    w.record("VPORT", handle::ACTIVE_VPORT, handle::VPORT_TABLE, "AcDbViewportTableRecord");
    let centre = (low + high) * 0.5;
    let view_height = ((high.y - low.y).max((high.x - low.x) * height_mm / width_mm) * 1.05).max(1.0);
    w.str(2, "*Active").int(70, 0);
    w.point(10, DVec2::ZERO, false).point(11, DVec2::ONE, false).point(12, centre, false);
    w.point(13, DVec2::ZERO, false).point(14, DVec2::splat(10.0), false).point(15, DVec2::splat(10.0), false);
    w.real(16, 0.0).real(26, 0.0).real(36, 1.0).real(17, 0.0).real(27, 0.0).real(37, 0.0);
    w.real(40, view_height).real(41, width_mm / height_mm).real(42, 50.0).real(43, 0.0).real(44, 0.0);
    w.real(50, 0.0).real(51, 0.0);
    for (code, value) in [(71, 0), (72, 1000), (73, 1), (74, 3), (75, 0), (76, 0), (77, 0), (78, 0), (281, 0), (65, 0)]
    {
        w.int(code, value);
    }
    w.real(146, 0.0);
    w.end_table();

    let dashed: Vec<&Layer> = layers.iter().filter(|l| l.pen.dash.is_some()).collect();
    w.table("LTYPE", handle::LTYPE_TABLE, 3 + dashed.len());
    let mut next = handle::FIRST_RECORD;
    for name in ["ByBlock", "ByLayer", "Continuous"] {
        w.record("LTYPE", next, handle::LTYPE_TABLE, "AcDbLinetypeTableRecord");
        w.str(2, name).int(70, 0).str(3, if name == "Continuous" { "Solid line" } else { "" });
        w.int(72, 65).int(73, 0).real(40, 0.0);
        next += 1;
    }
    for layer in &dashed {
        let [on, off] = layer.pen.dash.map(|d| d.map(Length::mm)).unwrap_or_default();
        w.record("LTYPE", next, handle::LTYPE_TABLE, "AcDbLinetypeTableRecord");
        let description = match (style, layer.name) {
            (LineStyle::Iso128, "HIDDEN") => format!(
                "ISO 128-20 type 02 dashed: dash {} mm, gap {} mm (12 d, 3 d at d = {} mm)",
                number(on),
                number(off),
                number(layer.pen.width.mm())
            ),
            _ => format!("dashed: dash {} mm, gap {} mm", number(on), number(off)),
        };
        w.str(2, layer.linetype).int(70, 0).str(3, &description).int(72, 65).int(73, 2).real(40, on + off);
        w.real(49, on).int(74, 0).real(49, -off).int(74, 0);
        next += 1;
    }
    w.end_table();

    w.table("LAYER", handle::LAYER_TABLE, 1 + layers.len());
    w.record("LAYER", next, handle::LAYER_TABLE, "AcDbLayerTableRecord");
    w.str(2, "0").int(70, 0).int(62, 7).str(6, "Continuous").int(370, -3).handle(390, handle::PLOT_STYLE_NORMAL);
    next += 1;
    for layer in &layers {
        w.record("LAYER", next, handle::LAYER_TABLE, "AcDbLayerTableRecord");
        w.str(2, layer.name).int(70, 0).int(62, colour(layer.pen.grey)).str(6, layer.linetype);
        w.int(370, lineweight(layer.pen.width)).handle(390, handle::PLOT_STYLE_NORMAL);
        next += 1;
    }
    w.end_table();

    w.table("STYLE", handle::STYLE_TABLE, 1);
    w.record("STYLE", handle::STANDARD_STYLE, handle::STYLE_TABLE, "AcDbTextStyleTableRecord");
    w.str(2, "Standard").int(70, 0).real(40, 0.0).real(41, 1.0).real(50, 0.0).int(71, 0).real(42, 2.5);
    w.str(3, "txt").str(4, "");
    w.end_table();

    w.table("VIEW", handle::VIEW_TABLE, 0);
    w.end_table();
    w.table("UCS", handle::UCS_TABLE, 0);
    w.end_table();

    w.table("APPID", handle::APPID_TABLE, 1);
    w.record("APPID", handle::ACAD_APPID, handle::APPID_TABLE, "AcDbRegAppTableRecord");
    w.str(2, "ACAD").int(70, 0);
    w.end_table();

    w.table("DIMSTYLE", handle::DIMSTYLE_TABLE, 1);
    w.str(100, "AcDbDimStyleTable");
    // A dimension style's handle is group 105, not 5.
    w.str(0, "DIMSTYLE").handle(105, handle::STANDARD_DIMSTYLE).handle(330, handle::DIMSTYLE_TABLE);
    w.str(100, "AcDbSymbolTableRecord").str(100, "AcDbDimStyleTableRecord");
    w.str(2, "Standard").int(70, 0);
    w.end_table();

    w.table("BLOCK_RECORD", handle::BLOCK_RECORD_TABLE, 2);
    for (space, name, layout) in [
        (handle::MODEL_SPACE, "*Model_Space", handle::MODEL_LAYOUT),
        (handle::PAPER_SPACE, "*Paper_Space", handle::PAPER_LAYOUT),
    ] {
        w.record("BLOCK_RECORD", space, handle::BLOCK_RECORD_TABLE, "AcDbBlockTableRecord");
        w.str(2, name).handle(340, layout);
    }
    w.end_table();
    w.end_section();

    // BLOCKS: the model and paper spaces' (empty) block definitions.
    w.section("BLOCKS");
    for (space, block, end, name, paper) in [
        (handle::MODEL_SPACE, handle::MODEL_BLOCK, handle::MODEL_ENDBLK, "*Model_Space", false),
        (handle::PAPER_SPACE, handle::PAPER_BLOCK, handle::PAPER_ENDBLK, "*Paper_Space", true),
    ] {
        w.str(0, "BLOCK").handle(5, block).handle(330, space).str(100, "AcDbEntity");
        if paper {
            w.int(67, 1);
        }
        w.str(8, "0").str(100, "AcDbBlockBegin").str(2, name).int(70, 0).point(10, DVec2::ZERO, true);
        w.str(3, name).str(1, "");
        w.str(0, "ENDBLK").handle(5, end).handle(330, space).str(100, "AcDbEntity");
        if paper {
            w.int(67, 1);
        }
        w.str(8, "0").str(100, "AcDbBlockEnd");
    }
    w.end_section();

    // ENTITIES: one polyline per stroke.
    w.section("ENTITIES");
    for (k, stroke) in strokes.iter().enumerate() {
        let name = layer_of(stroke.class, stroke.visible);
        let layer = layers.iter().find(|l| l.name == name).unwrap_or(&layers[0]);
        let pen = pen_of(drawing, style, stroke.class, stroke.visible, hidden);
        debug_assert_eq!(pen.dash.is_some(), layer.pen.dash.is_some(), "a layer's strokes share its linetype");
        w.str(0, "LWPOLYLINE").handle(5, handle::FIRST_ENTITY + k as u32).handle(330, handle::MODEL_SPACE);
        w.str(100, "AcDbEntity").str(8, name);
        if colour(pen.grey) != colour(layer.pen.grey) {
            w.int(62, colour(pen.grey));
        }
        if lineweight(pen.width) != lineweight(layer.pen.width) {
            w.int(370, lineweight(pen.width));
        }
        w.str(100, "AcDbPolyline").int(90, stroke.points.len() as i64).int(70, 0);
        for p in &stroke.points {
            w.point(10, to_mm(*p), false);
        }
    }
    let mut next_entity = handle::FIRST_ENTITY + strokes.len() as u32;
    for layer in extra {
        for (width, points) in layer.lines {
            w.str(0, "LWPOLYLINE").handle(5, next_entity).handle(330, handle::MODEL_SPACE);
            w.str(100, "AcDbEntity").str(8, layer.name);
            if lineweight(*width) != lineweight(layer.pen.width) {
                w.int(370, lineweight(*width));
            }
            w.str(100, "AcDbPolyline").int(90, points.len() as i64).int(70, 0);
            for p in points {
                w.point(10, to_mm(*p), false);
            }
            next_entity += 1;
        }
    }
    w.end_section();

    // OBJECTS: the root dictionary, groups (none), plot styles (the placeholder R2000 layers point
    // to) and the two layouts the block records name.
    w.section("OBJECTS");
    w.dictionary(
        handle::ROOT_DICTIONARY,
        0,
        &[
            ("ACAD_GROUP", handle::GROUP_DICTIONARY),
            ("ACAD_LAYOUT", handle::LAYOUT_DICTIONARY),
            ("ACAD_PLOTSTYLENAME", handle::PLOT_STYLE_DICTIONARY),
        ],
    );
    w.dictionary(handle::GROUP_DICTIONARY, handle::ROOT_DICTIONARY, &[]);
    w.dictionary(
        handle::LAYOUT_DICTIONARY,
        handle::ROOT_DICTIONARY,
        &[("Model", handle::MODEL_LAYOUT), ("Layout1", handle::PAPER_LAYOUT)],
    );
    w.str(0, "ACDBDICTIONARYWDFLT").handle(5, handle::PLOT_STYLE_DICTIONARY).handle(330, handle::ROOT_DICTIONARY);
    w.str(100, "AcDbDictionary").int(281, 1).str(3, "Normal").handle(350, handle::PLOT_STYLE_NORMAL);
    w.str(100, "AcDbDictionaryWithDefault").handle(340, handle::PLOT_STYLE_NORMAL);
    w.str(0, "ACDBPLACEHOLDER").handle(5, handle::PLOT_STYLE_NORMAL).handle(330, handle::PLOT_STYLE_DICTIONARY);
    for (layout, name, space, tab, model) in [
        (handle::MODEL_LAYOUT, "Model", handle::MODEL_SPACE, 0, true),
        (handle::PAPER_LAYOUT, "Layout1", handle::PAPER_SPACE, 1, false),
    ] {
        w.str(0, "LAYOUT").handle(5, layout).handle(330, handle::LAYOUT_DICTIONARY);
        // Plot settings: no plotter, the sheet's size in millimetres, 1:1.
        w.str(100, "AcDbPlotSettings").str(1, "").str(2, "none_device").str(4, "").str(6, "");
        w.real(40, 0.0).real(41, 0.0).real(42, 0.0).real(43, 0.0).real(44, width_mm).real(45, height_mm);
        w.real(46, 0.0).real(47, 0.0).real(48, 0.0).real(49, 0.0).real(140, 0.0).real(141, 0.0);
        w.real(142, 1.0).real(143, 1.0).int(70, if model { 1024 } else { 0 }).int(72, 1).int(73, 0).int(74, 5);
        w.str(7, "").int(75, 16).real(147, 1.0).real(148, 0.0).real(149, 0.0);
        w.str(100, "AcDbLayout").str(1, name).int(70, 1).int(71, tab);
        w.point(10, DVec2::ZERO, false).point(11, DVec2::new(width_mm, height_mm), false);
        w.point(12, DVec2::ZERO, true).point(14, low, true).point(15, high, true).real(146, 0.0);
        w.point(13, DVec2::ZERO, true).real(16, 1.0).real(26, 0.0).real(36, 0.0);
        w.real(17, 0.0).real(27, 1.0).real(37, 0.0).int(76, 1).handle(330, space);
    }
    w.end_section();
    w.str(0, "EOF");
    w.out.into_bytes()
}

/// The nearest DXF lineweight to a width, in hundredths of a millimetre.
pub fn lineweight(width: Length) -> i64 {
    let hundredths = width.mm() * 100.0;
    LINEWEIGHTS
        .into_iter()
        .min_by(|a, b| (*a as f64 - hundredths).abs().total_cmp(&(*b as f64 - hundredths).abs()))
        .unwrap_or(25)
}

/// The AutoCAD colour index of a grey: 7 (black on paper, white on a dark screen) for black, else
/// the nearest of the grey shades 250–255.
fn colour(grey: f64) -> i64 {
    if grey <= 0.0 {
        return 7;
    }
    let level = grey.clamp(0.0, 1.0) * 255.0;
    [(250, 51.0), (251, 80.0), (252, 105.0), (253, 130.0), (254, 190.0), (255, 255.0)]
        .into_iter()
        .min_by(|a, b| (a.1 - level).abs().total_cmp(&(b.1 - level).abs()))
        .map_or(8, |(index, _)| index)
}

/// A real number at a tenth of a micrometre (4 decimals of a millimetre), without trailing zeros.
fn number(v: f64) -> String {
    let text = format!("{v:.4}");
    let text = if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.') } else { &text };
    if text == "-0" { "0".to_string() } else { text.to_string() }
}

/// Group code and value pairs, a line each, as DXF's ASCII form wants them.
#[derive(Default)]
struct Writer {
    out: String,
}

impl Writer {
    fn str(&mut self, code: i32, value: &str) -> &mut Self {
        let _ = write!(self.out, "{code:>3}\n{value}\n");
        self
    }

    fn int(&mut self, code: i32, value: i64) -> &mut Self {
        let _ = write!(self.out, "{code:>3}\n{value}\n");
        self
    }

    fn real(&mut self, code: i32, value: f64) -> &mut Self {
        let value = number(value);
        self.str(code, &value)
    }

    fn handle(&mut self, code: i32, value: u32) -> &mut Self {
        let _ = write!(self.out, "{code:>3}\n{value:X}\n");
        self
    }

    /// A point: x with `code`, y with `code + 10`, and z (0) with `code + 20` when `z`.
    fn point(&mut self, code: i32, p: DVec2, z: bool) -> &mut Self {
        self.real(code, p.x).real(code + 10, p.y);
        if z {
            self.real(code + 20, 0.0);
        }
        self
    }

    fn var(&mut self, name: &str) -> &mut Self {
        self.str(9, name)
    }

    fn section(&mut self, name: &str) {
        self.str(0, "SECTION").str(2, name);
    }

    fn end_section(&mut self) {
        self.str(0, "ENDSEC");
    }

    fn table(&mut self, name: &str, handle: u32, entries: usize) {
        self.str(0, "TABLE").str(2, name).handle(5, handle).handle(330, 0).str(100, "AcDbSymbolTable");
        self.int(70, entries as i64);
    }

    fn end_table(&mut self) {
        self.str(0, "ENDTAB");
    }

    /// A symbol table record's common part.
    fn record(&mut self, kind: &str, handle: u32, table: u32, subclass: &str) {
        self.str(0, kind).handle(5, handle).handle(330, table);
        self.str(100, "AcDbSymbolTableRecord").str(100, subclass);
    }

    fn dictionary(&mut self, handle: u32, owner: u32, entries: &[(&str, u32)]) {
        self.str(0, "DICTIONARY").handle(5, handle).handle(330, owner).str(100, "AcDbDictionary").int(281, 1);
        for (name, value) in entries {
            self.str(3, name).handle(350, *value);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widths_become_the_nearest_dxf_lineweight() {
        assert_eq!(lineweight(Length::Mm(0.5)), 50);
        assert_eq!(lineweight(Length::Mm(0.25)), 25);
        assert_eq!(lineweight(Length::Px(1.6)), 40);
        assert_eq!(lineweight(Length::Px(0.6)), 15);
        assert_eq!((colour(0.0), colour(0.4)), (7, 252));
        assert_eq!((number(-0.00001), number(2.5), number(211.666667)), ("0".into(), "2.5".into(), "211.6667".into()));
    }

    #[test]
    fn a_stroke_is_one_polyline_in_millimetres_with_y_up() {
        let stroke = |visible, points: &[(f64, f64)]| Stroke {
            class: LineClass::Crease,
            visible,
            part: None,
            points: points.iter().map(|&(x, y)| DVec2::new(x, y)).collect(),
        };
        let drawing = Drawing {
            width: 96,
            height: 96,
            strokes: vec![
                stroke(true, &[(0.0, 0.0), (96.0, 0.0), (96.0, 48.0)]),
                stroke(false, &[(0.0, 96.0), (48.0, 48.0)]),
            ],
            ..Drawing::default()
        };
        let text = String::from_utf8(to_dxf(&drawing, Hidden::Dashed, LineStyle::Iso128)).unwrap();
        assert_eq!(text.matches("\nLWPOLYLINE\n").count(), 2);
        assert_eq!(text, String::from_utf8(to_dxf(&drawing, Hidden::Dashed, LineStyle::Iso128)).unwrap());
        // Hidden first, as in the SVG; 96 px = 25.4 mm, y turned up.
        let hidden = text.find("\n  8\nHIDDEN\n100\nAcDbPolyline\n 90\n2\n").expect("hidden polyline");
        let visible = text.find("\n  8\nVISIBLE\n100\nAcDbPolyline\n 90\n3\n").expect("visible polyline");
        assert!(hidden < visible);
        assert!(
            text.contains(" 90\n3\n 70\n0\n 10\n0\n 20\n25.4\n 10\n25.4\n 20\n25.4\n 10\n25.4\n 20\n12.7\n"),
            "{text}"
        );
        assert!(text.contains("  2\nHIDDEN\n 70\n0\n  3\nISO 128-20 type 02 dashed: dash 3 mm, gap 0.75 mm"));
        assert!(text.contains(" 49\n3\n 74\n0\n 49\n-0.75\n"));
        let without = String::from_utf8(to_dxf(&drawing, Hidden::None, LineStyle::Iso128)).unwrap();
        assert_eq!(without.matches("\nLWPOLYLINE\n").count(), 1);
    }

    #[test]
    fn tangent_edges_get_a_layer_of_their_own_with_their_dashes() {
        let tangent = Stroke {
            class: LineClass::Tangent,
            visible: true,
            part: None,
            points: vec![DVec2::new(0.0, 0.0), DVec2::new(10.0, 0.0)],
        };
        let drawing = Drawing {
            width: 96,
            height: 96,
            strokes: vec![tangent],
            smooth: crate::Smooth::Dashed,
            ..Drawing::default()
        };
        let text = String::from_utf8(to_dxf(&drawing, Hidden::Dashed, LineStyle::Iso128)).unwrap();
        assert!(text.contains("\n  8\nTANGENT\n100\nAcDbPolyline\n"), "{text}");
        // Narrow (0.25 mm), dashed 6 d on and 3 d off: a linetype named after the layer.
        assert!(text.contains("  2\nTANGENT\n 70\n0\n 62\n7\n  6\nTANGENT\n370\n25\n"), "{text}");
        assert!(text.contains(" 49\n1.5\n 74\n0\n 49\n-0.75\n"), "{text}");
    }
}
