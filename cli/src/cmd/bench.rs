//! `drafter bench render FILE [--size WxH] [--frames N] [--json]`: frame time of every style as a
//! ratio to `phong` in the same run.
//!
//! Frames are interleaved (one frame of each style in turn, after a warm-up of every style) so that
//! drift of a shared, noisy machine hits every style alike; each style's time is the median of its
//! frames. A frame is measured from recording to completion on the device (submit and wait), the
//! image not read back. `illustration` is the full frame: gradient shading, edges, depth unsharp
//! mask and a soft shadow.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use drafter_viewer::{Enhancements, RenderOptions, Renderer, ShadowMode, Style};
use serde::Serialize;

use crate::exit::BadInput;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub what: What,
}

#[derive(Debug, clap::Subcommand)]
pub enum What {
    /// Frame time per style, as a ratio to phong (median over N frames after warm-up).
    Render(RenderArgs),
}

#[derive(Debug, clap::Args)]
pub struct RenderArgs {
    /// The model to draw (baked or not).
    pub file: PathBuf,
    /// Frame size, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1600x1200", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Measured frames per style (at least 30).
    #[arg(long, default_value_t = 30)]
    pub frames: usize,
    /// Warm-up frames per style, not measured.
    #[arg(long, default_value_t = 3)]
    pub warmup: usize,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("{s:?}: {e}"));
    Ok((parse(w)?, parse(h)?))
}

/// The `--json` output.
#[derive(Debug, Serialize)]
pub struct Report {
    pub size: [u32; 2],
    pub frames: usize,
    pub device: String,
    pub triangles: usize,
    pub parts: usize,
    /// By name, in the order measured (`phong` first).
    pub styles: serde_json::Map<String, serde_json::Value>,
}

#[derive(Debug, Serialize)]
struct StyleTime {
    ms: f64,
    ratio: f64,
}

pub fn run(args: Args) -> Result<()> {
    match args.what {
        What::Render(args) => render(args),
    }
}

fn render(args: RenderArgs) -> Result<()> {
    if args.frames < 30 {
        return Err(BadInput(format!("--frames {}: at least 30 frames are measured", args.frames)).into());
    }
    let model = crate::cmd::render::load(&args.file)?;
    let mut renderer = Renderer::new()?;
    renderer.set_model(&model)?;

    let base = RenderOptions { size: args.size, supersample: 1, use_part_styles: false, ..RenderOptions::default() };
    base.validate().map_err(BadInput)?;
    let mut cases: Vec<(String, RenderOptions)> = std::iter::once(Style::Phong)
        .chain(Style::ALL.into_iter().filter(|&s| s != Style::Phong))
        .map(|style| (style.name().to_owned(), RenderOptions { style, ..base.clone() }))
        .collect();
    cases.push((
        "illustration".to_owned(),
        RenderOptions {
            style: Style::Gradient,
            enhancements: Enhancements::ALL,
            shadow: ShadowMode::Soft,
            ..base.clone()
        },
    ));

    for _ in 0..args.warmup.max(1) {
        for (_, options) in &cases {
            renderer.time_frame(options)?;
        }
    }
    let mut times: Vec<Vec<Duration>> = vec![Vec::with_capacity(args.frames); cases.len()];
    for _ in 0..args.frames {
        for (k, (_, options)) in cases.iter().enumerate() {
            times[k].push(renderer.time_frame(options)?);
        }
    }
    let medians: Vec<f64> = times
        .iter_mut()
        .map(|t| {
            t.sort_unstable();
            t[t.len() / 2].as_secs_f64() * 1e3
        })
        .collect();
    let phong = medians[0].max(1e-9);
    let mut styles = serde_json::Map::new();
    for ((name, _), ms) in cases.iter().zip(&medians) {
        styles.insert(name.clone(), serde_json::to_value(StyleTime { ms: round3(*ms), ratio: round3(ms / phong) })?);
    }
    let report = Report {
        size: [args.size.0, args.size.1],
        frames: args.frames,
        device: renderer.gpu().description(),
        triangles: model.triangle_count(),
        parts: model.parts.len(),
        styles,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        println!(
            "{}: {} triangles, {} parts, {}x{}, median of {} frames on {}",
            args.file.display(),
            report.triangles,
            report.parts,
            args.size.0,
            args.size.1,
            args.frames,
            report.device
        );
        for ((name, _), ms) in cases.iter().zip(&medians) {
            println!("  {name:<13} {ms:8.2} ms  {:5.2}× phong", ms / phong);
        }
    }
    Ok(())
}

fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}
