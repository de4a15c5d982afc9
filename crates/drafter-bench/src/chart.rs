//! Charts of the sweeps: a small description ([`Figure`] of [`Panel`]s of [`Series`]) rendered to
//! SVG, or to PNG for a quick look, with plotters.
//!
//! No system fonts: the text is set in DejaVu Sans (Bitstream Vera license, `fonts/`), embedded in
//! the binary and registered with plotters' `ab_glyph` backend, so the charts look the same on any
//! machine and the build needs no fontconfig. SVG text names the family `sans-serif`; a viewer
//! without DejaVu substitutes a similar face.

use std::error::Error;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;

/// DejaVu Sans, embedded (license in `fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is a fixed, valid file: failing here would be a build problem, and text would
        // then simply not render.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// How a series is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Points joined by a line, each point marked.
    Line,
    /// Scattered points (small, translucent).
    Points,
    /// One large point per entry (a summary).
    BigPoints,
    /// Bars from zero at category positions 0, 1, 2, ….
    Bars,
}

/// One named set of points.
#[derive(Clone, Debug)]
pub struct Series {
    pub name: String,
    pub kind: Kind,
    pub points: Vec<(f64, f64)>,
    /// Index into the palette (series sharing a colour share a method).
    pub color: usize,
    /// Shown in the legend.
    pub legend: bool,
}

impl Series {
    pub fn new(name: impl Into<String>, kind: Kind, color: usize, points: Vec<(f64, f64)>) -> Self {
        Self { name: name.into(), kind, points, color, legend: true }
    }

    pub fn without_legend(mut self) -> Self {
        self.legend = false;
        self
    }
}

/// An annotated point, e.g. "chosen" or "default".
#[derive(Clone, Debug)]
pub struct Mark {
    pub label: String,
    pub x: f64,
    pub y: f64,
}

/// One plot.
#[derive(Clone, Debug, Default)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_log: bool,
    pub y_log: bool,
    pub series: Vec<Series>,
    pub marks: Vec<Mark>,
    /// Names of the x positions 0, 1, 2, … (bar charts).
    pub categories: Vec<String>,
    /// Extra room above the data, as a fraction of the range (for the legend). Default 0.
    pub headroom: f64,
    /// Start a linear y axis at zero. Default false.
    pub y_from_zero: bool,
    /// Upper end of the y axis at most this (e.g. 100 for percentages). Default none.
    pub y_max: Option<f64>,
}

/// Panels on a grid under one title.
#[derive(Clone, Debug)]
pub struct Figure {
    pub title: String,
    pub columns: usize,
    pub panels: Vec<Panel>,
    /// Size in pixels.
    pub size: (u32, u32),
}

/// Colour-blind-safe palette (Okabe & Ito 2008).
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// The figure as an SVG document.
pub fn to_svg(figure: &Figure) -> Result<String, Box<dyn Error>> {
    register_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, figure.size).into_drawing_area();
        draw_figure(&root, figure)?;
        root.present()?;
    }
    Ok(svg)
}

/// The figure as a PNG (RGB, 8 bit).
pub fn to_png(figure: &Figure) -> Result<Vec<u8>, Box<dyn Error>> {
    register_font();
    let (w, h) = figure.size;
    let mut pixels = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        draw_figure(&root, figure)?;
        root.present()?;
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.write_header()?.write_image_data(&pixels)?;
    Ok(out)
}

fn draw_figure<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, figure: &Figure) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let root = root.titled(&figure.title, ("sans-serif", 24))?;
    let columns = figure.columns.max(1);
    let rows = figure.panels.len().div_ceil(columns).max(1);
    let areas = root.split_evenly((rows, columns));
    for (area, panel) in areas.iter().zip(&figure.panels) {
        draw_panel(area, panel)?;
    }
    Ok(())
}

/// Data range of a panel, padded; log axes keep positive values only.
fn range(values: impl Iterator<Item = f64>, log: bool, headroom: f64, from_zero: bool) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (!log || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = ((h - l) * 0.08).max(0.15);
        (10f64.powf(l - pad), 10f64.powf(h + pad + (h - l + pad) * headroom))
    } else {
        if from_zero {
            lo = lo.min(0.0);
        }
        let span = (hi - lo).max(hi.abs().max(1e-12) * 0.1);
        let lo = if from_zero && lo == 0.0 { 0.0 } else { lo - span * 0.08 };
        (lo, hi + span * (0.08 + headroom))
    }
}

fn draw_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, panel: &Panel) -> Result<(), Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let bars = panel.series.iter().any(|s| s.kind == Kind::Bars);
    let xs = panel.series.iter().flat_map(|s| s.points.iter().map(|p| p.0)).chain(panel.marks.iter().map(|m| m.x));
    let ys = panel.series.iter().flat_map(|s| s.points.iter().map(|p| p.1)).chain(panel.marks.iter().map(|m| m.y));
    let (x0, x1) =
        if bars { (-0.6, panel.categories.len().max(1) as f64 - 0.4) } else { range(xs, panel.x_log, 0.0, false) };
    let (y0, mut y1) = range(ys, panel.y_log, panel.headroom, bars || panel.y_from_zero);
    if let Some(max) = panel.y_max {
        y1 = y1.min(max);
    }
    match (panel.x_log, panel.y_log) {
        (false, false) => draw_in(area, panel, x0..x1, y0..y1),
        (true, false) => draw_in(area, panel, (x0..x1).log_scale(), y0..y1),
        (false, true) => draw_in(area, panel, x0..x1, (y0..y1).log_scale()),
        (true, true) => draw_in(area, panel, (x0..x1).log_scale(), (y0..y1).log_scale()),
    }
}

/// Tick label: short, no float noise.
fn tick(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".into()
    } else if !(1e-3..1e7).contains(&a) {
        format!("{v:.0e}")
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 100.0 {
        let s = format!("{v:.1}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else if a >= 1.0 {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

fn draw_in<DB, X, Y>(area: &DrawingArea<DB, Shift>, panel: &Panel, x: X, y: Y) -> Result<(), Box<dyn Error>>
where
    DB: DrawingBackend,
    DB::ErrorType: 'static,
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 17))
        .margin(12)
        .x_label_area_size(46)
        .y_label_area_size(64)
        .build_cartesian_2d(x, y)?;
    let categories = panel.categories.clone();
    let x_fmt = move |v: &f64| {
        if categories.is_empty() {
            tick(*v)
        } else {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 {
                categories.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        }
    };
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&|v| tick(*v))
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .light_line_style(RGBColor(0, 0, 0).mix(0.04));
    if !panel.categories.is_empty() {
        mesh.x_labels(panel.categories.len() * 2 + 1).disable_x_mesh();
    }
    mesh.draw()?;

    for s in &panel.series {
        let c = color(s.color);
        let style = ShapeStyle::from(&c).stroke_width(2);
        let anno = match s.kind {
            Kind::Line => {
                chart.draw_series(LineSeries::new(s.points.iter().copied(), style))?;
                chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 3, c.filled())))?
            }
            Kind::Points => chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 2, c.mix(0.35).filled())))?,
            Kind::BigPoints => {
                chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 7, c.filled())))?;
                chart.draw_series(s.points.iter().map(|&p| Circle::new(p, 7, BLACK.stroke_width(1))))?
            }
            Kind::Bars => chart.draw_series(
                s.points.iter().map(|&(x, y)| Rectangle::new([(x - 0.35, 0.0), (x + 0.35, y)], c.mix(0.85).filled())),
            )?,
        };
        if s.legend {
            anno.label(s.name.clone()).legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], c.filled()));
        }
    }
    for m in &panel.marks {
        let red = RGBColor(200, 0, 0);
        chart.draw_series(std::iter::once(Circle::new((m.x, m.y), 11, red.stroke_width(2))))?;
        // The label sits up and to the right of the ring, in pixels.
        let label = EmptyElement::at((m.x, m.y))
            + Text::new(m.label.clone(), (12, -22), ("sans-serif", 13).into_font().color(&red));
        chart.draw_series(std::iter::once(label))?;
    }
    if panel.series.iter().any(|s| s.legend) {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(0, 0, 0).mix(0.3))
            .label_font(("sans-serif", 13))
            .draw()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> Figure {
        Figure {
            title: "test".into(),
            columns: 2,
            size: (800, 400),
            panels: vec![
                Panel {
                    title: "log-log".into(),
                    x_label: "candidate edges".into(),
                    y_label: "time per view (µs)".into(),
                    x_log: true,
                    y_log: true,
                    series: vec![Series::new("brute force", Kind::Line, 0, vec![(100.0, 1.0), (1e4, 90.0)])],
                    marks: vec![Mark { label: "chosen".into(), x: 1e4, y: 90.0 }],
                    ..Panel::default()
                },
                Panel {
                    title: "bars".into(),
                    x_label: "stage".into(),
                    y_label: "ms".into(),
                    categories: vec!["a".into(), "b".into()],
                    series: vec![Series::new("time", Kind::Bars, 1, vec![(0.0, 3.0), (1.0, 5.0)])],
                    ..Panel::default()
                },
            ],
        }
    }

    #[test]
    fn svg_has_titles_axes_and_legend_text() {
        let svg = to_svg(&figure()).expect("renders");
        for text in ["test", "log-log", "candidate edges", "time per view (µs)", "brute force", "chosen", "stage"] {
            assert!(svg.contains(text), "missing {text:?}");
        }
        assert!(svg.starts_with("<svg"));
    }

    #[test]
    fn png_is_a_png_with_ink() {
        let png = to_png(&figure()).expect("renders");
        assert_eq!(&png[1..4], b"PNG");
        // Text and lines put dark pixels on the white page.
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().expect("header");
        let mut buf = vec![0; reader.output_buffer_size().expect("size")];
        reader.next_frame(&mut buf).expect("frame");
        let dark = buf.chunks(3).filter(|p| p.iter().all(|&c| c < 100)).count();
        assert!(dark > 500, "only {dark} dark pixels");
    }
}
