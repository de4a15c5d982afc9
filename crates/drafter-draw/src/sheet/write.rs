//! A sheet as SVG, PDF or DXF: its views' strokes with the pens of [`crate::style`] (the same table
//! and class order as a single view's [`crate::to_svg`] and [`crate::to_pdf`], through
//! [`crate::pen_of`] and [`crate::CLASS_ORDER`]), then the frame. Millimetres throughout: the SVG's
//! user unit is a millimetre (`viewBox="0 0 420 297"` on a `420mm` × `297mm` page), coordinates to
//! a thousandth; the PDF's page is the sheet in points (72/25.4 a millimetre), y turned up. No
//! dates, no generator versions: the bytes depend only on the sheet.

use std::fmt::Write as _;

use drafter_scene::edges::LineClass;
use glam::DVec2;

use super::{FrameLine, Sheet};
use crate::dxf::ExtraLayer;
use crate::style::{Length, LineStyle, MM_PER_PX, Pen};
use crate::{CLASS_ORDER, Drawing, Hidden, Stroke, class_name, pen_of};

/// A number of millimetres to a thousandth, without trailing zeros.
fn mm(v: f64) -> String {
    let text = format!("{v:.3}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0".to_string() } else { text.to_string() }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn svg_path(s: &mut String, class: &str, points: &[DVec2]) {
    let _ = write!(s, "<path{class} d=\"");
    for (i, p) in points.iter().enumerate() {
        let _ = write!(s, "{}{} {}", if i == 0 { "M" } else { " L" }, mm(p.x), mm(p.y));
    }
    let _ = writeln!(s, "\"/>");
}

fn svg_dashes(dash: Option<[Length; 2]>) -> String {
    dash.map(|[on, off]| format!(r#" stroke-dasharray="{} {}""#, mm(on.mm()), mm(off.mm()))).unwrap_or_default()
}

/// The strokes of one visibility and class, in the drawing's order.
fn of_class(strokes: &[Stroke], visible: bool, class: LineClass) -> impl Iterator<Item = &Stroke> {
    strokes.iter().filter(move |s| s.visible == visible && s.class == class)
}

/// The visibilities a sheet draws: hidden lines first when it has them.
fn visibilities(hidden: Hidden) -> impl Iterator<Item = bool> {
    [false, true].into_iter().filter(move |&v| v || hidden != Hidden::None)
}

/// The sheet as SVG: a group per view (`id="view-front"`, …) holding a group per visibility
/// (`class="hidden"`, `class="visible"`) and per line class as a single view's SVG does, each
/// path naming its part; then the frame (`id="frame"`: border, title block, lettering, symbol).
pub fn to_svg(sheet: &Sheet, style: LineStyle) -> String {
    let mut s = String::new();
    let (w, h) = sheet.mm;
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}" fill="none" stroke="#000" stroke-linecap="round" stroke-linejoin="round">"##,
        w = mm(w),
        h = mm(h)
    );
    let _ = writeln!(s, "<title>{}</title>", escape(&sheet.title));
    let _ = writeln!(
        s,
        "<desc>drafter draw --sheet {}: scale {}, {}-angle projection, style {}; user unit 1 mm, y down</desc>",
        sheet.size.name(),
        sheet.scale,
        sheet.angle.name(),
        style.name()
    );
    for view in &sheet.views {
        let r = &view.rect;
        let _ = writeln!(
            s,
            r#"<g id="view-{}" class="view" data-rect="{} {} {} {}">"#,
            view.kind.name(),
            mm(r.min.x),
            mm(r.min.y),
            mm(r.max.x),
            mm(r.max.y)
        );
        for visible in visibilities(sheet.hidden) {
            let group = style.pen(LineClass::Crease, visible, sheet.hidden);
            let _ = writeln!(
                s,
                r#"<g class="{}" stroke="{}"{}>"#,
                if visible { "visible" } else { "hidden" },
                group.svg_colour(),
                svg_dashes(group.dash)
            );
            for class in CLASS_ORDER {
                let mut strokes = of_class(&view.drawing.strokes, visible, class).peekable();
                if strokes.peek().is_none() {
                    continue;
                }
                let pen = pen_of(&view.drawing, style, class, visible, sheet.hidden);
                let mut extra = String::new();
                if pen.grey != group.grey {
                    let _ = write!(extra, r#" stroke="{}""#, pen.svg_colour());
                }
                if pen.dash != group.dash {
                    extra +=
                        &pen.dash.map_or_else(|| r#" stroke-dasharray="none""#.to_string(), |d| svg_dashes(Some(d)));
                }
                let _ =
                    writeln!(s, r#"<g class="{}" stroke-width="{}"{extra}>"#, class_name(class), mm(pen.width.mm()));
                for stroke in strokes {
                    let part = stroke.part.map(|p| format!(r#" class="part-{p}""#)).unwrap_or_default();
                    svg_path(&mut s, &part, &stroke.points);
                }
                let _ = writeln!(s, "</g>");
            }
            let _ = writeln!(s, "</g>");
        }
        if !view.cut_outlines.is_empty() {
            // A section's cut faces: their hatching (narrow) under their outlines (wide).
            let (thin, wide) = section_pens(style);
            let _ = writeln!(s, r#"<g class="section">"#);
            let _ = writeln!(s, r#"<g class="hatching" stroke-width="{}">"#, mm(thin.width.mm()));
            for line in &view.hatching {
                svg_path(&mut s, "", line);
            }
            let _ = writeln!(s, "</g>");
            let _ = writeln!(s, r#"<g class="cut" stroke-width="{}">"#, mm(wide.width.mm()));
            for ring in &view.cut_outlines {
                svg_path(&mut s, "", ring);
            }
            let _ = writeln!(s, "</g>");
            let _ = writeln!(s, "</g>");
        }
        let _ = writeln!(s, "</g>");
    }
    let _ = writeln!(s, r#"<g id="frame">"#);
    for line in &sheet.frame {
        let dashes = if line.dashes.is_empty() {
            String::new()
        } else {
            format!(r#" stroke-dasharray="{}""#, line.dashes.iter().map(|d| mm(*d)).collect::<Vec<_>>().join(" "))
        };
        svg_path(&mut s, &format!(r#" stroke-width="{}"{dashes}"#, mm(line.width)), &line.points);
    }
    let _ = writeln!(s, "</g>");
    let _ = writeln!(s, "</svg>");
    s
}

/// PDF points per millimetre.
const PT_PER_MM: f32 = 72.0 / 25.4;

/// The sheet as a one-page PDF (pdf-writer) the size of the sheet: the views' strokes with the
/// same pens and order as [`to_svg`], then the frame; the title in the document's information.
pub fn to_pdf(sheet: &Sheet, style: LineStyle) -> Vec<u8> {
    use pdf_writer::Content;
    use pdf_writer::types::{LineCapStyle, LineJoinStyle};
    let (w, h) = (sheet.mm.0 as f32 * PT_PER_MM, sheet.mm.1 as f32 * PT_PER_MM);
    let mut content = Content::new();
    content.set_line_cap(LineCapStyle::RoundCap);
    content.set_line_join(LineJoinStyle::RoundJoin);
    let at = |q: DVec2| (q.x as f32 * PT_PER_MM, h - q.y as f32 * PT_PER_MM);
    let path = |content: &mut Content, points: &[DVec2]| {
        for (i, q) in points.iter().enumerate() {
            let (x, y) = at(*q);
            if i == 0 {
                content.move_to(x, y);
            } else {
                content.line_to(x, y);
            }
        }
    };
    let set_pen = |content: &mut Content, pen: &Pen| {
        content.set_stroke_gray(pen.grey as f32);
        match pen.dash {
            Some([on, off]) => content.set_dash_pattern([on.mm() as f32 * PT_PER_MM, off.mm() as f32 * PT_PER_MM], 0.0),
            None => content.set_dash_pattern([], 0.0),
        };
        content.set_line_width(pen.width.mm() as f32 * PT_PER_MM);
    };
    for view in &sheet.views {
        for visible in visibilities(sheet.hidden) {
            for class in CLASS_ORDER {
                let mut strokes = of_class(&view.drawing.strokes, visible, class).peekable();
                if strokes.peek().is_none() {
                    continue;
                }
                set_pen(&mut content, &pen_of(&view.drawing, style, class, visible, sheet.hidden));
                for stroke in strokes {
                    path(&mut content, &stroke.points);
                }
                content.stroke();
            }
        }
        if !view.cut_outlines.is_empty() {
            let (thin, wide) = section_pens(style);
            set_pen(&mut content, &thin);
            for line in &view.hatching {
                path(&mut content, line);
            }
            content.stroke();
            set_pen(&mut content, &wide);
            for ring in &view.cut_outlines {
                path(&mut content, ring);
            }
            content.stroke();
        }
    }
    content.set_stroke_gray(0.0);
    for FrameLine { width, dashes, points } in &sheet.frame {
        content.set_dash_pattern(dashes.iter().map(|d| *d as f32 * PT_PER_MM), 0.0);
        content.set_line_width(*width as f32 * PT_PER_MM);
        path(&mut content, points);
        content.stroke();
    }
    crate::one_page_pdf((w, h), Some(&sheet.title), content)
}

/// The sheet as DXF R2000 through [`crate::dxf::to_dxf_with`]: the views' strokes on the layers
/// of a single view's DXF (`VISIBLE`, `HIDDEN`, `TANGENT`, with the pens of `style`), the frame
/// (border, title block, lettering, projection symbol) on a layer `FRAME` (0.7 mm, each line with
/// its own lineweight where it differs; the symbol's centre lines continuous), millimetres with y up
/// and the sheet's lower left corner at the origin. The writer's page is whole pixels
/// ([`MM_PER_PX`]), so the file's limits are the sheet rounded up to the next pixel (A3: 420.16 ×
/// 297.13 mm); the coordinates are exact.
pub fn to_dxf(sheet: &Sheet, style: LineStyle) -> Vec<u8> {
    let (w, h) = sheet.mm;
    let height = (h / MM_PER_PX).ceil();
    // The writer puts a pixel (x, y) at (x, height − y) · MM_PER_PX millimetres.
    let to_px = |p: DVec2| DVec2::new(p.x / MM_PER_PX, height - (h - p.y) / MM_PER_PX);
    let mut drawing = Drawing {
        width: (w / MM_PER_PX).ceil() as u32,
        height: height as u32,
        smooth: sheet.views.first().map(|v| v.drawing.smooth).unwrap_or_default(),
        ..Drawing::default()
    };
    for view in &sheet.views {
        drawing.strokes.extend(
            view.drawing
                .strokes
                .iter()
                .map(|s| Stroke { points: s.points.iter().map(|p| to_px(*p)).collect(), ..s.clone() }),
        );
        // A section's cut outlines are visible outlines.
        drawing.strokes.extend(view.cut_outlines.iter().map(|ring| Stroke {
            class: LineClass::Silhouette,
            visible: true,
            part: None,
            points: ring.iter().map(|p| to_px(*p)).collect(),
        }));
    }
    let (thin, _) = section_pens(style);
    let hatching: Vec<(Length, Vec<DVec2>)> =
        sheet.views.iter().flat_map(|v| &v.hatching).map(|[a, b]| (thin.width, vec![to_px(*a), to_px(*b)])).collect();
    let frame: Vec<(Length, Vec<DVec2>)> =
        sheet.frame.iter().map(|l| (Length::Mm(l.width), l.points.iter().map(|p| to_px(*p)).collect())).collect();
    let layer = ExtraLayer {
        name: "FRAME",
        pen: Pen { width: Length::Mm(super::BORDER_WIDTH_MM), grey: 0.0, dash: None },
        lines: &frame,
    };
    let hatch = ExtraLayer { name: "HATCH", pen: thin, lines: &hatching };
    if hatching.is_empty() {
        crate::dxf::to_dxf_with(&drawing, sheet.hidden, style, &[layer])
    } else {
        crate::dxf::to_dxf_with(&drawing, sheet.hidden, style, &[layer, hatch])
    }
}

/// The pens of a section's hatching (the style's narrow continuous line, ISO 128-50's thin
/// hatching) and its cut outlines (the style's outline).
fn section_pens(style: LineStyle) -> (Pen, Pen) {
    let thin = Pen { dash: None, ..style.pen(LineClass::Crease, false, Hidden::Solid) };
    (thin, style.pen(LineClass::Silhouette, true, Hidden::None))
}
