//! `drafter bench FILE [--out DIR] [--json]`: every method of each bake stage over its parameter
//! range on the user's model, as SVG charts plus one JSON of the numbers (`drafter_bench::sweep`).
//!
//! Writes `DIR/obb.svg`, `normals.svg`, `silhouettes.svg`, `segmentation.svg`, `bake.svg` and
//! `DIR/bench.json` (`--png` adds PNG copies for a quick look). `--json` also prints the JSON;
//! `--replot` redraws the charts from a saved `bench.json` (given as FILE) without measuring.

use crate::cmd::out;
use std::path::PathBuf;

use anyhow::Result;
use drafter_bench::sweep::{self, Progress, SweepOptions};
use indicatif::{ProgressBar, ProgressStyle};

use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The model to measure (any supported input).
    #[arg(required = true)]
    pub file: Option<PathBuf>,
    /// Folder for the charts and bench.json (created if missing).
    #[arg(long, value_name = "DIR", default_value = "bench")]
    pub out: PathBuf,
    /// Also print the JSON of the numbers on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write each chart as PNG.
    #[arg(long)]
    pub png: bool,
    /// Random views per silhouette measurement (orthographic and perspective each).
    #[arg(long, default_value_t = 200)]
    pub views: usize,
    /// At most this many parts get boxes (evenly spaced by part id).
    #[arg(long, default_value_t = 400)]
    pub max_parts: usize,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Redraw the charts from a saved report instead of measuring: FILE is a `bench.json`.
    #[arg(long)]
    pub replot: bool,
}

/// An indicatif bar per stage.
struct Bar(Option<ProgressBar>);

impl Progress for Bar {
    fn stage(&mut self, name: &str, items: u64) {
        if let Some(bar) = &self.0 {
            bar.set_length(items);
            bar.set_position(0);
            bar.set_message(name.to_owned());
        }
    }
    fn tick(&mut self) {
        if let Some(bar) = &self.0 {
            bar.inc(1);
        }
    }
}

pub fn run(args: Args) -> Result<()> {
    let Some(file) = args.file else {
        return Err(BadInput("bench: a model FILE is required".into()).into());
    };
    if args.views == 0 || args.max_parts == 0 {
        return Err(BadInput("--views and --max-parts must be at least 1".into()).into());
    }
    if args.replot {
        let text = std::fs::read_to_string(&file).map_err(|e| BadInput(format!("{}: {e}", file.display())))?;
        let report: sweep::SweepReport = serde_json::from_str(&text)
            .map_err(|e| BadInput(format!("{}: not a bench report: {e}", file.display())))?;
        std::fs::create_dir_all(&args.out)
            .map_err(|e| BadInput(format!("{}: cannot create: {e}", args.out.display())))?;
        let written = drafter_bench::write_outputs(&report, &args.out, args.png)?;
        out!("wrote {} in {}", written.join(", "), args.out.display());
        return Ok(());
    }
    let imported = drafter_io::import(&file)?;
    if imported.scene.instanced_triangle_count() == 0 {
        return Err(BadInput(format!("{}: no triangles to measure", file.display())).into());
    }
    std::fs::create_dir_all(&args.out).map_err(|e| BadInput(format!("{}: cannot create: {e}", args.out.display())))?;
    let bar = (!args.quiet).then(|| {
        let bar = ProgressBar::new(1);
        if let Ok(style) = ProgressStyle::with_template("{msg:>20} [{bar:40}] {pos}/{len} {elapsed}") {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    });
    let mut progress = Bar(bar);
    let name = file.file_name().map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned());
    let options = SweepOptions { views: args.views, max_obb_parts: args.max_parts, ..SweepOptions::default() };
    let report = sweep::run(&imported.scene, &name, &options, &mut progress);
    if let Some(bar) = &progress.0 {
        bar.finish_and_clear();
    }

    let written = drafter_bench::write_outputs(&report, &args.out, args.png).map_err(|e| match e {
        drafter_bench::OutputError::Write(m) => anyhow::Error::from(BadInput(format!("cannot write {m}"))),
        other => anyhow::Error::from(other),
    })?;
    if args.json {
        out!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_summary(&report)?;
        out!("wrote {} in {}", written.join(", "), args.out.display());
    }
    Ok(())
}

fn print_summary(r: &sweep::SweepReport) -> anyhow::Result<()> {
    out!(
        "{}: {} triangles ({} unique), {} meshes, {} instances, {} threads",
        r.model.name,
        r.model.triangles,
        r.model.unique_triangles,
        r.model.meshes,
        r.model.instances,
        r.threads
    );
    out!("oriented boxes over {} of {} parts (one thread):", r.obb.measured_parts, r.obb.parts);
    for m in &r.obb.methods {
        out!(
            "  {:<8} {:9.3} ms/part (median {:.3})  volume {:.4}× best (worst {:.4}×)",
            m.method,
            m.mean_ms,
            m.median_ms,
            m.mean_relative_volume,
            m.max_relative_volume
        );
    }
    let n = &r.normals;
    out!("normal enhancement over {} faces, {} crease edges:", n.faces, n.crease_edges);
    for p in n.by_iterations.iter().chain(&n.by_strength) {
        out!(
            "  iterations {:3} k {:4.2}: {:9.1} ms, {:7.3}° from converged, {:5.1}% creases sharper ({:+.2}°)",
            p.iterations,
            p.strength,
            p.ms,
            p.mean_deg_from_converged,
            100.0 * p.crease_contrast_increased,
            p.mean_crease_contrast_gain_deg
        );
    }
    if let Some(s) = &r.silhouettes {
        out!(
            "silhouettes on mesh {} ({} candidates), µs per view; stored: {}; {}; {} mismatches",
            s.mesh,
            s.candidates,
            s.chosen_orthographic,
            s.chosen_perspective,
            s.mismatches
        );
        for row in &s.by_size {
            out!(
                "  {:8} edges: brute {:9.1} / {:9.1} persp, gauss {:8.1} (strict {:8.1}), cone BVH {:8.1}",
                row.candidates,
                row.brute_ortho_us,
                row.brute_perspective_us,
                row.gauss_overlapping_us,
                row.gauss_strict_us,
                row.cone_bvh_us
            );
        }
    }
    let g = &r.segmentation;
    out!("segmentation: {} parts with the defaults", g.default_parts);
    for p in &g.by_region_angle {
        out!("  region angle {:5.1}°: {:6} parts in {:8.1} ms", p.value, p.parts, p.ms);
    }
    for p in &g.by_merge_fraction {
        out!("  merge below {:6.3}: {:6} parts in {:8.1} ms", p.value, p.parts, p.ms);
    }
    let b = &r.bake;
    let stages: Vec<String> = b.stages.iter().map(|(n, ms)| format!("{n} {ms:.0}")).collect();
    let bytes: Vec<String> = b.bytes.iter().map(|(n, v)| format!("{n} {v}")).collect();
    out!("bake: {:.0} ms ({}); {} bytes ({})", b.total_ms, stages.join(", "), b.output_bytes, bytes.join(", "));
    Ok(())
}
