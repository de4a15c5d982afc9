//! `drafter bench draw FILE [--views N] [--tolerances LIST] [--size WxH] [--ortho] [--brute-samples N]
//! [--json]`: time against accuracy of `drafter draw`.
//!
//! For each view (azimuths spread evenly around the model at one elevation) the drawing is made at
//! every tolerance, hidden lines included, and timed (the fastest of three). Each drawing is compared
//! with the one at the smallest tolerance, which is the reference: the share of the reference's
//! visible (and hidden) length that lies within 0.5 px of the drawing's, and of the drawing's within
//! 0.5 px of the reference's, both measured on points every 0.25 px along the strokes. The SVG's
//! size is reported per tolerance.
//!
//! Brute force, side by side: points on the view's edges ray-cast from the eye against every
//! triangle of the scene in world space (Möller–Trumbore in f64, as `crates/drafter-draw/tests/visibility.rs`
//! checks the drawing). Timing every pixel of every edge that way would take minutes to hours on a
//! large model, so `--brute-samples` points spread over the edges are timed and the time per point
//! is multiplied by the drawing's edge length in pixels (one point per pixel): the printed brute
//! force time is that extrapolation, and says so.

use std::time::{Duration, Instant};

use anyhow::Result;
use drafter_draw::brute::{blocked, world_triangles};
use drafter_draw::{self as drawing, DrawOptions, Drawing, Hidden};
use drafter_scene::View;
use drafter_scene::edges::WorldView;
use glam::DVec2;
use serde::Serialize;

use crate::cmd::out;
use crate::cmd::render::parse_size;
use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The model: a baked .glb/.gltf, or any model (then only its outline is drawn).
    pub file: std::path::PathBuf,
    /// Views: azimuths 35° + k·360°/N at the elevation of `--elevation`.
    #[arg(long, default_value_t = 4)]
    pub views: usize,
    /// Elevation of the views, in degrees.
    #[arg(long, default_value_t = 25.0, allow_hyphen_values = true)]
    pub elevation: f32,
    /// Tolerances in pixels, comma-separated; the smallest gives the reference drawing.
    #[arg(long, value_delimiter = ',', default_values_t = [0.0, 0.05, 0.2, 1.0])]
    pub tolerances: Vec<f64>,
    /// Drawing size in pixels, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "800x600", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Orthographic views instead of perspective.
    #[arg(long)]
    pub ortho: bool,
    /// Points ray-cast by brute force per view (0: no brute force).
    #[arg(long, default_value_t = 2000)]
    pub brute_samples: usize,
    /// Print the figures as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Refuse a model that lists more triangles than this.
    #[arg(long, value_name = "N", default_value_t = drafter_io::DEFAULT_MAX_TRIANGLES)]
    pub max_triangles: u64,
}

/// One drawing's figures.
#[derive(Debug, Serialize)]
struct Row {
    view: usize,
    tolerance_px: f64,
    ms: f64,
    strokes: usize,
    svg_bytes: usize,
    visible_px: f64,
    hidden_px: f64,
    /// Share of the reference's visible length within 0.5 px of this drawing's, and the reverse.
    visible_reference_covered: f64,
    visible_covered_by_reference: f64,
    hidden_reference_covered: f64,
    hidden_covered_by_reference: f64,
}

/// One view's brute force.
#[derive(Debug, Serialize)]
struct Brute {
    view: usize,
    samples: usize,
    ns_per_sample: f64,
    edge_px: f64,
    /// `ns_per_sample` × `edge_px`: one ray per pixel of every edge (extrapolated).
    extrapolated_s: f64,
}

#[derive(Debug, Serialize)]
struct Report {
    file: String,
    triangles: usize,
    threads: usize,
    rows: Vec<Row>,
    brute: Vec<Brute>,
}

pub fn run(args: Args) -> Result<()> {
    let mut tolerances = args.tolerances.clone();
    if tolerances.is_empty() || tolerances.iter().any(|t| !(t.is_finite() && *t >= 0.0)) {
        return Err(BadInput("--tolerances: give finite pixel values, 0 or more".into()).into());
    }
    tolerances.sort_by(f64::total_cmp);
    tolerances.dedup();
    if args.views == 0 || args.views > 360 {
        return Err(BadInput(format!("--views {}: 1 to 360", args.views)).into());
    }
    if !(args.elevation > -90.0 && args.elevation < 90.0) {
        return Err(BadInput(format!("--elevation {}: must be in (-90, 90)", args.elevation)).into());
    }
    let model = crate::cmd::render::load(&args.file, args.max_triangles)?;
    let mut report = Report {
        file: args.file.display().to_string(),
        triangles: 0,
        threads: rayon::current_num_threads(),
        rows: Vec::new(),
        brute: Vec::new(),
    };
    for v in 0..args.views {
        let view = View { azimuth_deg: 35.0 + 360.0 * v as f32 / args.views as f32, elevation_deg: args.elevation };
        let options = |tolerance_px| DrawOptions {
            size: args.size,
            view,
            orthographic: args.ortho,
            hidden: Hidden::Solid,
            tolerance_px,
            ..DrawOptions::default()
        };
        let drawings: Vec<(Drawing, Duration)> = tolerances.iter().map(|&t| timed_draw(&model, &options(t))).collect();
        let reference = &drawings[0].0;
        report.triangles = reference.stats.triangles;
        let reference_points = [sample(reference, true), sample(reference, false)];
        for (&tolerance_px, (drawing, time)) in tolerances.iter().zip(&drawings) {
            let points = [sample(drawing, true), sample(drawing, false)];
            let covered = |a: &[(DVec2, f64)], b: &[(DVec2, f64)]| share_within(a, b, 0.5);
            report.rows.push(Row {
                view: v,
                tolerance_px,
                ms: time.as_secs_f64() * 1e3,
                strokes: drawing.strokes.len(),
                svg_bytes: drawing::to_svg(drawing, Hidden::Dashed, drafter_draw::LineStyle::default()).len(),
                visible_px: drawing.stats.visible_px,
                hidden_px: drawing.stats.hidden_px,
                visible_reference_covered: covered(&reference_points[0], &points[0]),
                visible_covered_by_reference: covered(&points[0], &reference_points[0]),
                hidden_reference_covered: covered(&reference_points[1], &points[1]),
                hidden_covered_by_reference: covered(&points[1], &reference_points[1]),
            });
        }
        if args.brute_samples > 0 {
            report.brute.push(brute_force(&model, &options(tolerances[0]), v, args.brute_samples));
        }
    }
    if args.json {
        out!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_table(&report)?;
    }
    Ok(())
}

/// The drawing and the fastest of three runs' time.
fn timed_draw(model: &drafter_scene::Model, options: &DrawOptions) -> (Drawing, Duration) {
    let mut best = Duration::MAX;
    let mut drawing = Drawing::default();
    for _ in 0..3 {
        let start = Instant::now();
        drawing = drawing::draw(model, options);
        best = best.min(start.elapsed());
    }
    (drawing, best)
}

/// Points at most 0.25 px apart along the visible (or hidden) strokes, each with the length it
/// stands for (a drawing at tolerance 0 holds many pieces far shorter than a pixel: counted by
/// number, they would outweigh the long lines).
fn sample(drawing: &Drawing, visible: bool) -> Vec<(DVec2, f64)> {
    let mut out = Vec::new();
    for stroke in drawing.strokes.iter().filter(|s| s.visible == visible) {
        for w in stroke.points.windows(2) {
            let length = w[0].distance(w[1]);
            let n = (length / 0.25).ceil().max(1.0) as usize;
            out.extend((0..n).map(|k| (w[0].lerp(w[1], (k as f64 + 0.5) / n as f64), length / n as f64)));
        }
    }
    out
}

/// The share of the length of `points` within `radius` of a point of `of` (1 when there is none):
/// `of` is sampled densely enough (0.25 px) that point distance stands for distance to its strokes
/// within 0.125 px.
fn share_within(points: &[(DVec2, f64)], of: &[(DVec2, f64)], radius: f64) -> f64 {
    let total: f64 = points.iter().map(|p| p.1).sum();
    if total <= 0.0 {
        return 1.0;
    }
    // A grid of cells `radius` wide: a near point lies in the 3 × 3 cells around.
    let cell = |p: DVec2| ((p.x / radius).floor() as i64, (p.y / radius).floor() as i64);
    let mut grid: Vec<((i64, i64), DVec2)> = of.iter().map(|&(p, _)| (cell(p), p)).collect();
    grid.sort_by_key(|e| e.0);
    let near = |p: DVec2| {
        let (cx, cy) = cell(p);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                let key = (cx + dx, cy + dy);
                let start = grid.partition_point(|e| e.0 < key);
                grid[start..].iter().take_while(|e| e.0 == key).any(|e| e.1.distance_squared(p) <= radius * radius)
            })
        })
    };
    points.iter().filter(|&&(p, _)| near(p)).map(|p| p.1).sum::<f64>() / total
}

/// Times `samples` points on the view's edges ray-cast against every triangle, and extrapolates to
/// one point per pixel of every edge.
fn brute_force(model: &drafter_scene::Model, options: &DrawOptions, view: usize, samples: usize) -> Brute {
    let vis = drawing::visibility(model, options);
    let triangles = world_triangles(model);
    let edge_px: f64 = vis.edges.iter().map(|e| e.screen[0].distance(e.screen[1])).sum();
    let diagonal = model.bounds.max.distance(model.bounds.min).max(1e-9);
    let viewer = vis.projection.view();
    // Points spread over the edges in proportion to their length.
    let mut points = Vec::with_capacity(samples);
    let step = edge_px / samples as f64;
    let mut along = 0.5 * step;
    let mut walked = 0.0;
    for e in &vis.edges {
        let length = e.screen[0].distance(e.screen[1]);
        while along < walked + length && points.len() < samples {
            let s = ((along - walked) / length.max(1e-12)).clamp(0.0, 1.0);
            points.push(e.a + (e.b - e.a) * s);
            along += step;
        }
        walked += length;
    }
    let start = Instant::now();
    let mut hidden = 0usize;
    for &p in &points {
        let towards = match viewer {
            WorldView::Perspective { eye } => eye,
            WorldView::Orthographic { direction } => p - direction.normalize() * (10.0 * diagonal),
        };
        hidden += usize::from(blocked(p, towards, &triangles));
    }
    let elapsed = start.elapsed().as_secs_f64();
    std::hint::black_box(hidden);
    let ns_per_sample = elapsed * 1e9 / points.len().max(1) as f64;
    Brute { view, samples: points.len(), ns_per_sample, edge_px, extrapolated_s: ns_per_sample * edge_px * 1e-9 }
}

fn print_table(r: &Report) -> Result<()> {
    out!(
        "{}: {} triangles, {} threads; reference = the smallest tolerance; agreement within 0.5 px",
        r.file,
        r.triangles,
        r.threads
    );
    out!(
        "{:>4} {:>9} {:>9} {:>8} {:>10} {:>10} {:>10}  {:>15}  {:>15}",
        "view",
        "tol px",
        "ms",
        "strokes",
        "SVG bytes",
        "visible px",
        "hidden px",
        "visible ref/ours",
        "hidden ref/ours"
    );
    for row in &r.rows {
        out!(
            "{:>4} {:>9} {:>9.1} {:>8} {:>10} {:>10.0} {:>10.0}  {:>7.2}% {:>6.2}%  {:>7.2}% {:>6.2}%",
            row.view,
            row.tolerance_px,
            row.ms,
            row.strokes,
            row.svg_bytes,
            row.visible_px,
            row.hidden_px,
            100.0 * row.visible_reference_covered,
            100.0 * row.visible_covered_by_reference,
            100.0 * row.hidden_reference_covered,
            100.0 * row.hidden_covered_by_reference
        );
    }
    for b in &r.brute {
        let reference = r.rows.iter().find(|row| row.view == b.view).map_or(0.0, |row| row.ms);
        out!(
            "view {}: brute force {:.0} ns per point over {} points; one point per pixel of {:.0} px of edges ≈ {:.1} s (extrapolated), {:.0}× the drawing's {:.1} ms",
            b.view,
            b.ns_per_sample,
            b.samples,
            b.edge_px,
            b.extrapolated_s,
            b.extrapolated_s * 1e3 / reference.max(1e-9),
            reference
        );
    }
    Ok(())
}
