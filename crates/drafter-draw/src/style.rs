//! Line styles: the pen each stroke of a drawing is drawn with, one table read by the SVG, PDF and
//! DXF writers alike ([`crate::to_svg`], [`crate::to_pdf`], [`crate::dxf::to_dxf`]).
//!
//! # The page
//! A drawing is computed in pixels (`--size`, y down). On paper a pixel is a CSS pixel, 1/96 inch
//! ([`MM_PER_PX`] = 25.4/96 mm, so 800 × 600 px is 211.67 × 158.75 mm): the SVG states that size in
//! millimetres on its root, the PDF's page is the same size in points (0.75 pt a pixel), and the
//! DXF's coordinates are those millimetres with y turned up. Widths and dashes given in millimetres
//! are therefore exact on paper at 1:1.
//!
//! # The styles
//! - [`LineStyle::Iso128`], the default: ISO 128-20 practice for technical drawings. Every visible
//!   line of the object (outlines, creases, boundaries, part borders) is line type 01.2, *continuous
//!   wide*, [`ISO128_WIDE_MM`] = 0.5 mm; hidden lines are type 02.1, *dashed narrow*, half of it,
//!   [`ISO128_NARROW_MM`] = 0.25 mm (ISO 128-20 §4: wide and narrow in the ratio 2 : 1, both from
//!   the series 0.13, 0.18, 0.25, 0.35, 0.5, 0.7, 1, 1.4, 2 mm, [`ISO128_WIDTHS_MM`]), with the
//!   standard's dash proportions: dashes of 12 d and gaps of 3 d, d the line's width
//!   ([`ISO128_DASH`], [`ISO128_GAP`]: 3 mm and 0.75 mm). All lines black. Tangent edges, where a
//!   drawing has them, are continuous narrow (type 01.1, as ISO 128 draws imaginary lines of
//!   intersection). 0.5/0.25 mm is the line group 0.5 of ISO 128-24, one of the two groups it
//!   prefers (0.5 and 0.7); an 800 × 600 px page is about A5.
//! - [`LineStyle::Gooch`]: the illustration weights of Gooch et al. 1999 (§3), in pixels, as
//!   drafter drew before ISO 128 became the default: silhouettes 1.6, boundaries, part borders and
//!   non-manifold edges 1.2, creases 0.9, hidden lines 0.6 in grey (`#666`), dashed 4 px on, 3 off.
//!
//! Limits: one scale, 1:1 at 96 pixels per inch; a drawing meant for another sheet size is drawn
//! at the `--size` whose millimetres fit it (an A4 landscape sheet, 297 × 210 mm, is 1123 × 794 px).

use drafter_scene::edges::LineClass;

use crate::Hidden;

/// Millimetres on the page per pixel of the drawing: a CSS pixel, 1/96 inch.
pub const MM_PER_PX: f64 = 25.4 / 96.0;

/// The ISO 128-20 series of line widths, in millimetres.
pub const ISO128_WIDTHS_MM: [f64; 9] = [0.13, 0.18, 0.25, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0];

/// ISO 128 wide lines (visible outlines and edges, type 01.2), millimetres.
pub const ISO128_WIDE_MM: f64 = 0.5;

/// ISO 128 narrow lines (hidden lines, type 02.1; tangent edges, 01.1): half the wide width.
pub const ISO128_NARROW_MM: f64 = 0.25;

/// ISO 128-20 dashed lines (type 02): a dash is this many line widths long…
pub const ISO128_DASH: f64 = 12.0;

/// …and the gap between dashes this many.
pub const ISO128_GAP: f64 = 3.0;

/// Which pens a drawing's lines are drawn with (`drafter draw --style`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LineStyle {
    /// ISO 128: one wide visible width, narrow dashed hidden lines, millimetres on the page.
    #[default]
    Iso128,
    /// Gooch et al. 1999: three visible weights and thin grey hidden lines, in pixels.
    Gooch,
}

/// A length on the page, in the unit its style's table is written in, so that each writer puts
/// down the table's own number (an SVG's `0.5mm`, or `1.6` pixels) and converts only where its
/// format needs another unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// Millimetres on the page.
    Mm(f64),
    /// Pixels of the drawing ([`MM_PER_PX`] millimetres each).
    Px(f64),
}

impl Length {
    pub fn mm(self) -> f64 {
        match self {
            Length::Mm(mm) => mm,
            Length::Px(px) => px * MM_PER_PX,
        }
    }

    pub fn px(self) -> f64 {
        match self {
            Length::Mm(mm) => mm / MM_PER_PX,
            Length::Px(px) => px,
        }
    }

    /// As an SVG length: millimetres with their unit, pixels as user units (the SVG's viewBox maps
    /// a user unit to exactly one CSS pixel, so both are exact on the page).
    pub fn svg(self) -> String {
        match self {
            Length::Mm(mm) => format!("{}mm", short(mm)),
            Length::Px(px) => short(px),
        }
    }
}

/// How one stroke is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pen {
    pub width: Length,
    /// 0 black to 1 white.
    pub grey: f64,
    /// Dash and gap lengths, for a dashed line.
    pub dash: Option<[Length; 2]>,
}

impl Pen {
    /// The colour as an SVG hex colour (`#000`, `#666`).
    pub fn svg_colour(&self) -> String {
        let g = (self.grey.clamp(0.0, 1.0) * 15.0).round() as u8;
        format!("#{g:x}{g:x}{g:x}")
    }
}

impl LineStyle {
    /// The style's name, as `--style` takes it.
    pub fn name(self) -> &'static str {
        match self {
            LineStyle::Iso128 => "iso128",
            LineStyle::Gooch => "gooch",
        }
    }

    /// The pen of a line of `class`, visible or hidden, where hidden lines are drawn as `hidden`
    /// says (their pen is the same for every class).
    pub fn pen(self, class: LineClass, visible: bool, hidden: Hidden) -> Pen {
        let dashed = hidden == Hidden::Dashed;
        match self {
            LineStyle::Iso128 => {
                let (wide, narrow) = (Length::Mm(ISO128_WIDE_MM), Length::Mm(ISO128_NARROW_MM));
                if !visible {
                    let dash = [Length::Mm(ISO128_DASH * ISO128_NARROW_MM), Length::Mm(ISO128_GAP * ISO128_NARROW_MM)];
                    return Pen { width: narrow, grey: 0.0, dash: dashed.then_some(dash) };
                }
                let width = match class {
                    LineClass::Silhouette
                    | LineClass::Crease
                    | LineClass::Boundary
                    | LineClass::PartBorder
                    | LineClass::NonManifold => wide,
                    // Tangent edges (smooth CAD face borders), where the scene has them: narrow.
                    #[allow(unreachable_patterns)]
                    _ => narrow,
                };
                Pen { width, grey: 0.0, dash: None }
            }
            LineStyle::Gooch => {
                if !visible {
                    let dash = [Length::Px(4.0), Length::Px(3.0)];
                    return Pen { width: Length::Px(0.6), grey: 0.4, dash: dashed.then_some(dash) };
                }
                let width = match class {
                    LineClass::Silhouette => 1.6,
                    LineClass::Boundary | LineClass::PartBorder | LineClass::NonManifold => 1.2,
                    LineClass::Crease => 0.9,
                    // Tangent edges, where the scene has them: the creases' weight.
                    #[allow(unreachable_patterns)]
                    _ => 0.9,
                };
                Pen { width: Length::Px(width), grey: 0.0, dash: None }
            }
        }
    }
}

/// A number with at most 6 decimals and no trailing zeros (`0.5`, `1.6`, `211.666667`).
pub(crate) fn short(v: f64) -> String {
    let text = format!("{v:.6}");
    let text = text.trim_end_matches('0').trim_end_matches('.');
    if text == "-0" { "0".to_string() } else { text.to_string() }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLASSES: [LineClass; 5] =
        [LineClass::Silhouette, LineClass::Crease, LineClass::Boundary, LineClass::PartBorder, LineClass::NonManifold];

    #[test]
    fn iso128_draws_one_visible_width_and_narrow_dashes_in_its_proportions() {
        let style = LineStyle::Iso128;
        for class in CLASSES {
            let pen = style.pen(class, true, Hidden::Dashed);
            assert_eq!((pen.width, pen.dash, pen.grey), (Length::Mm(0.5), None, 0.0), "{class:?}");
            let hidden = style.pen(class, false, Hidden::Dashed);
            let d = hidden.width.mm();
            assert_eq!(d * 2.0, pen.width.mm(), "narrow is half of wide");
            let [dash, gap] = hidden.dash.expect("dashed");
            assert_eq!((dash.mm() / d, gap.mm() / d), (12.0, 3.0));
            assert_eq!(style.pen(class, false, Hidden::Solid).dash, None);
        }
        for width in [ISO128_WIDE_MM, ISO128_NARROW_MM] {
            assert!(ISO128_WIDTHS_MM.contains(&width), "{width} is in the ISO 128 series");
        }
        assert_eq!(Length::Mm(0.5).svg(), "0.5mm");
        assert_eq!(Length::Mm(0.25 * 3.0).svg(), "0.75mm");
    }

    #[test]
    fn gooch_keeps_its_three_weights_in_pixels() {
        let style = LineStyle::Gooch;
        let widths: Vec<String> = CLASSES.iter().map(|&c| style.pen(c, true, Hidden::None).width.svg()).collect();
        assert_eq!(widths, ["1.6", "0.9", "1.2", "1.2", "1.2"]);
        let hidden = style.pen(LineClass::Crease, false, Hidden::Dashed);
        assert_eq!((hidden.width.svg(), hidden.svg_colour()), ("0.6".to_string(), "#666".to_string()));
        assert_eq!(hidden.dash.map(|d| d.map(Length::svg)), Some(["4".to_string(), "3".to_string()]));
        assert!((Length::Px(96.0).mm() - 25.4).abs() < 1e-12);
    }
}
