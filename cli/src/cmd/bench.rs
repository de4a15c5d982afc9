//! `drafter bench render FILE [--size WxH] [--frames N] [--interactive] [--json]`: frame time of
//! every style as a ratio to `phong` in the same run; with `--interactive`, every case again as the
//! window draws it while the user drags (`NAME~drag`).
//!
//! Frames are interleaved (one frame of each style in turn, after a warm-up of every style) so that
//! drift of a shared, noisy machine hits every style alike; each style's time is the median of its
//! frames. A frame is measured from recording to completion on the device (submit and wait), the
//! image not read back. Besides the styles: `edges` (gradient with outlines, creases and the depth
//! unsharp mask), `lines` (gradient with the baked lines: hard edges and this view's silhouettes from
//! the baked hierarchies), `shadow_hard` and `shadow_soft` (gradient with a drop shadow), and
//! `illustration`, the full frame: gradient shading, edges, lines and a soft shadow. The CPU
//! silhouette query of the line frames is timed on its own too (median per frame).

use crate::cmd::out;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Result;
use drafter_render::{Enhancements, Model, RenderOptions, Renderer, ShadowMode, Style};
use serde::Serialize;

use crate::exit::BadInput;

/// `drafter bench FILE` (the whole-stage sweep, `bench_sweep.rs`) or `drafter bench WHAT ...`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
#[group(skip)]
pub struct Args {
    #[command(subcommand)]
    pub what: Option<What>,
    #[command(flatten)]
    pub sweep: crate::cmd::bench_sweep::Args,
}

#[derive(Debug, clap::Subcommand)]
pub enum What {
    /// Frame time per style, as a ratio to phong (median over N frames after warm-up).
    Render(RenderArgs),
    /// Frame time of the same triangles (1000 synthetic spheres) in 10 and in 1000 parts, as parts of
    /// one mesh (per-triangle labels) and as separate meshes.
    Parts(PartsArgs),
    /// Silhouettes per view: brute force against the hierarchies (a baked file's stored ones, as loaded; else built), speedup, counts and
    /// mismatches (`--views N|icosa`, `--perspective`).
    Silhouettes(super::bench_silhouettes::Args),
    /// Line drawings: time per view against accuracy at several tolerances (agreement with the
    /// finest drawing), SVG size, and brute-force ray casting side by side (extrapolated).
    Draw(super::bench_draw::Args),
}

#[derive(Debug, clap::Args)]
pub struct PartsArgs {
    /// Triangles in the scene.
    #[arg(long, default_value_t = 200_000)]
    pub triangles: usize,
    /// Frame size, WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1600x1200", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Measured frames per case (at least 30).
    #[arg(long, default_value_t = 30)]
    pub frames: usize,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
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
    /// Also time every case as an interactive frame (`RenderOptions::interactive`, what the window
    /// draws while the user drags: reduced resolution filtered up), as `NAME~drag`, in the same
    /// interleaved run.
    #[arg(long)]
    pub interactive: bool,
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
    /// By name (`phong`, the styles, `edges`, `lines`, `shadow_hard`, `shadow_soft`, `illustration`).
    pub styles: serde_json::Map<String, serde_json::Value>,
    /// Hard-edge segments drawn (edges × instances).
    pub hard_edges: u32,
    /// Silhouette candidates of the model.
    pub silhouette_candidates: usize,
    /// Silhouettes drawn in the illustration frame.
    pub silhouettes: usize,
    /// Median CPU time of the per-frame silhouette query (all instances), milliseconds.
    pub silhouette_query_ms: f64,
    /// Load to first frame, milliseconds: reading and decoding the file into the model (`load`),
    /// the GPU device (`device`), uploading the model (`upload`), the first illustration frame
    /// (`first_frame`, with its silhouette query) and their sum (`total`). One run: noisy.
    pub startup_ms: Startup,
}

#[derive(Debug, Serialize)]
pub struct Startup {
    pub load: f64,
    pub device: f64,
    pub upload: f64,
    pub first_frame: f64,
    pub total: f64,
}

#[derive(Debug, Serialize)]
struct StyleTime {
    ms: f64,
    ratio: f64,
}

pub fn run(args: Args) -> Result<()> {
    let Some(what) = args.what else { return crate::cmd::bench_sweep::run(args.sweep) };
    match what {
        What::Render(args) => render(args),
        What::Parts(args) => parts(args),
        What::Silhouettes(args) => super::bench_silhouettes::run(args),
        What::Draw(args) => super::bench_draw::run(args),
    }
}

fn render(args: RenderArgs) -> Result<()> {
    if args.frames < 30 {
        return Err(BadInput(format!("--frames {}: at least 30 frames are measured", args.frames)).into());
    }
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let start = Instant::now();
    let model = crate::cmd::render::load(&args.file, drafter_io::DEFAULT_MAX_TRIANGLES)?;
    let load = ms(start);
    let t = Instant::now();
    let mut renderer = Renderer::new()?;
    let device = ms(t);
    let t = Instant::now();
    renderer.set_model(&model)?;
    let upload = ms(t);

    let base = RenderOptions { size: args.size, supersample: 1, use_part_styles: false, ..RenderOptions::default() };
    base.validate().map_err(BadInput)?;
    let mut cases: Vec<(String, RenderOptions)> = std::iter::once(Style::Phong)
        .chain(Style::ALL.into_iter().filter(|&s| s != Style::Phong))
        .map(|style| (style.name().to_owned(), RenderOptions { style, ..base.clone() }))
        .collect();
    let gradient = RenderOptions { style: Style::Gradient, ..base.clone() };
    cases.push(("edges".to_owned(), RenderOptions { enhancements: Enhancements::ALL, ..gradient.clone() }));
    cases.push(("lines".to_owned(), RenderOptions { lines: true, ..gradient.clone() }));
    cases.push(("shadow_hard".to_owned(), RenderOptions { shadow: ShadowMode::Hard, ..gradient.clone() }));
    cases.push(("shadow_soft".to_owned(), RenderOptions { shadow: ShadowMode::Soft, ..gradient.clone() }));
    cases.push((
        "illustration".to_owned(),
        RenderOptions {
            style: Style::Gradient,
            enhancements: Enhancements::ALL,
            lines: true,
            shadow: ShadowMode::Soft,
            ..base.clone()
        },
    ));
    if args.interactive {
        // At the window's scale for this adapter.
        let interactive_scale = renderer.gpu().interactive_scale();
        let dragged: Vec<(String, RenderOptions)> = cases
            .iter()
            .map(|(name, options)| {
                (format!("{name}~drag"), RenderOptions { interactive: true, interactive_scale, ..options.clone() })
            })
            .collect();
        cases.extend(dragged);
    }

    let t = Instant::now();
    if let Some((_, illustration)) = cases.iter().find(|(name, _)| name == "illustration") {
        renderer.time_frame(illustration)?;
    }
    let first_frame = ms(t);
    let startup_ms = Startup {
        load: round3(load),
        device: round3(device),
        upload: round3(upload),
        first_frame: round3(first_frame),
        total: round3(load + device + upload + first_frame),
    };
    for _ in 0..args.warmup.max(1) {
        for (_, options) in &cases {
            renderer.time_frame(options)?;
        }
    }
    let mut times: Vec<Vec<Duration>> = vec![Vec::with_capacity(args.frames); cases.len()];
    let mut queries: Vec<Duration> = Vec::new();
    let mut silhouettes = 0;
    for _ in 0..args.frames {
        for (k, (_, options)) in cases.iter().enumerate() {
            times[k].push(renderer.time_frame(options)?);
            if let (true, Some(frame)) = (options.lines, renderer.last_silhouettes()) {
                queries.push(frame.elapsed);
                silhouettes = frame.drawn.len();
            }
        }
    }
    queries.sort_unstable();
    let silhouette_query_ms = queries.get(queries.len() / 2).map_or(0.0, |d| d.as_secs_f64() * 1e3);
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
        hard_edges: renderer.hard_edge_count(),
        silhouette_candidates: model.lines.candidate_count(),
        silhouettes,
        silhouette_query_ms: round3(silhouette_query_ms),
        startup_ms,
    };
    if args.json {
        out!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        out!(
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
            out!("  {name:<18} {ms:8.2} ms  {:5.2}× phong", ms / phong);
        }
        out!(
            "  lines: {} hard-edge segments, {} silhouettes of {} candidates; silhouette query {:.3} ms per frame (CPU, median)",
            report.hard_edges,
            report.silhouettes,
            report.silhouette_candidates,
            report.silhouette_query_ms
        );
        let s = &report.startup_ms;
        out!(
            "  load to first frame {:.0} ms: load {:.0}, device {:.0}, upload {:.0}, first illustration frame {:.0} (one run)",
            s.total,
            s.load,
            s.device,
            s.upload,
            s.first_frame
        );
    }
    Ok(())
}

fn round3(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

/// The `bench parts` report: median frame times (ms) per case and the 1000-to-10 ratios.
#[derive(Debug, Serialize)]
pub struct PartsReport {
    pub size: [u32; 2],
    pub frames: usize,
    pub device: String,
    pub triangles: usize,
    /// `labels_10`, `labels_1000`, `meshes_10`, `meshes_1000`, each `{ "phong": ms, "gradient": ms }`.
    pub cases: serde_json::Map<String, serde_json::Value>,
    /// Frame time with 1000 parts over the time with 10, per layout and style.
    pub ratios: serde_json::Map<String, serde_json::Value>,
    /// What an illustrator's edit of all 1000 parts at once costs (the editing budget: 1 ms).
    pub edit: EditCost,
}

/// Median milliseconds, CPU and upload until the GPU is idle, of one edit of every part of the
/// 1000-part model: a keyboard edit (q) and a step of an anchor drag (the manipulator over 1000
/// targets), each followed by the part-table upload ([`Renderer::update_parts`]).
#[derive(Debug, Serialize)]
pub struct EditCost {
    pub parts: usize,
    pub edits: usize,
    pub key_ms: f64,
    pub drag_ms: f64,
}

/// Times [`EditCost`] on the 1000-part labelled model, its parts given baked records (a box and a
/// projector each) so that the editor can change them.
fn edit_cost(renderer: &mut Renderer, base: &RenderOptions, triangles: usize) -> Result<EditCost> {
    use drafter_app::edit::{Adjust, Editor, ScreenView, Tool};
    const EDITS: usize = 101;
    let mut model = spheres_model(1000, triangles, true)?;
    let origin = model.origin;
    let records: Vec<Option<drafter_format::PartRecord>> = model
        .parts
        .iter()
        .map(|p| {
            // The fallback projector row is p = d·x + w in render space: the anchor is where p = 1/2.
            let row = glam::DVec4::from(p.gpu.projector_row.map(f64::from));
            let gradient = glam::DVec3::new(row.x, row.y, row.z);
            let scale = 1.0 / gradient.length().max(1e-12);
            let direction = gradient * scale;
            let anchor = origin + direction * (0.5 - row.w) * scale;
            let projector = drafter_bounds::Projector { anchor, direction, scale };
            Some(drafter_format::PartRecord {
                id: p.id,
                name: p.name.clone(),
                triangles: 0,
                obb: drafter_format::BoxRecord {
                    center: anchor.to_array(),
                    axes: p.gpu.axes.map(|a| [f64::from(a[0]), f64::from(a[1]), f64::from(a[2])]),
                    half_extents: [scale * 0.5; 3],
                    volume: scale.powi(3),
                    method: drafter_format::ObbMethod::Aabb,
                },
                projector: drafter_format::ProjectorRecord {
                    anchor: anchor.to_array(),
                    direction: direction.to_array(),
                    scale,
                    matrix: projector.matrix().to_cols_array(),
                },
                gradient: drafter_format::GradientRecord { q: 10.0, f: 0.5, p: 1.0, transfer: Default::default() },
                style: None,
                flat: None,
            })
        })
        .collect();
    for (part, record) in model.parts.iter_mut().zip(&records) {
        part.record = record.clone();
    }
    renderer.set_model(&model)?;
    renderer.time_frame(base)?;
    let frame = renderer.last_frame().ok_or_else(|| anyhow::anyhow!("no frame drawn"))?;
    let view = ScreenView::new(frame.camera.clip_from_render(), origin, frame.target_size);
    let mut editor = Editor::new(records);
    let all: Vec<u32> = model.parts.iter().map(|p| p.id).collect();
    editor.selection.lasso(&all, false);
    let mut apply = |editor: &Editor, ids: &[u32], model: &mut Model| -> Result<()> {
        for &id in ids {
            if let Some(record) = editor.record(id) {
                model.set_part_record(record);
            }
        }
        renderer.update_parts(model)?;
        renderer.wait_idle()?;
        Ok(())
    };
    let median = |mut t: Vec<f64>| {
        t.sort_by(f64::total_cmp);
        round3(t[t.len() / 2])
    };
    let mut key = Vec::new();
    for k in 0..EDITS {
        let start = Instant::now();
        let ids = editor.adjust(Adjust::Q(if k % 2 == 0 { 1 } else { -1 }));
        apply(&editor, &ids, &mut model)?;
        key.push(start.elapsed().as_secs_f64() * 1e3);
        anyhow::ensure!(ids.len() == all.len(), "the edit changed {} of {} parts", ids.len(), all.len());
    }
    let mut drag = Vec::new();
    let (w, h) = (f64::from(frame.target_size.0), f64::from(frame.target_size.1));
    editor.begin(Tool::Anchor, glam::DVec2::new(w * 0.5, h * 0.5));
    for k in 0..EDITS {
        let now = glam::DVec2::new(w * 0.5 + (k % 20) as f64, h * 0.5 + 1.0);
        let start = Instant::now();
        let ids = editor.drag_to(&view, now);
        apply(&editor, &ids, &mut model)?;
        drag.push(start.elapsed().as_secs_f64() * 1e3);
    }
    editor.end();
    Ok(EditCost { parts: all.len(), edits: EDITS, key_ms: median(key), drag_ms: median(drag) })
}

fn parts(args: PartsArgs) -> Result<()> {
    if args.frames < 30 {
        return Err(BadInput(format!("--frames {}: at least 30 frames are measured", args.frames)).into());
    }
    if !(2_000..=20_000_000).contains(&args.triangles) {
        return Err(BadInput(format!("--triangles {} is out of range 2000..=20000000", args.triangles)).into());
    }
    let mut renderer = Renderer::new()?;
    let layouts = [("labels", true), ("meshes", false)];
    let styles = [Style::Phong, Style::Gradient];
    let mut models = Vec::new();
    for (layout, labelled) in layouts {
        for n in [10usize, 1000] {
            models.push((format!("{layout}_{n}"), spheres_model(n, args.triangles, labelled)?));
        }
    }
    let base = RenderOptions { size: args.size, supersample: 1, use_part_styles: false, ..RenderOptions::default() };
    base.validate().map_err(BadInput)?;
    let mut cases = serde_json::Map::new();
    let mut medians = std::collections::BTreeMap::new();
    for (name, model) in &models {
        renderer.set_model(model)?;
        let mut times: Vec<Vec<Duration>> = vec![Vec::new(); styles.len()];
        for _ in 0..3 {
            for style in styles {
                renderer.time_frame(&RenderOptions { style, ..base.clone() })?;
            }
        }
        for _ in 0..args.frames {
            for (k, style) in styles.iter().enumerate() {
                times[k].push(renderer.time_frame(&RenderOptions { style: *style, ..base.clone() })?);
            }
        }
        let mut row = serde_json::Map::new();
        for (k, style) in styles.iter().enumerate() {
            times[k].sort_unstable();
            let ms = times[k][times[k].len() / 2].as_secs_f64() * 1e3;
            medians.insert((name.clone(), style.name()), ms);
            row.insert(style.name().to_owned(), serde_json::json!(round3(ms)));
        }
        cases.insert(name.clone(), serde_json::Value::Object(row));
    }
    let edit = edit_cost(&mut renderer, &base, args.triangles)?;
    let mut ratios = serde_json::Map::new();
    for (layout, _) in layouts {
        for style in styles {
            let few = medians.get(&(format!("{layout}_10"), style.name())).copied().unwrap_or(f64::NAN);
            let many = medians.get(&(format!("{layout}_1000"), style.name())).copied().unwrap_or(f64::NAN);
            ratios.insert(format!("{layout}_{}", style.name()), serde_json::json!(round3(many / few)));
        }
    }
    let report = PartsReport {
        size: [args.size.0, args.size.1],
        frames: args.frames,
        device: renderer.gpu().description(),
        triangles: models.first().map_or(0, |(_, m)| m.triangle_count()),
        cases,
        ratios,
        edit,
    };
    if args.json {
        out!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        out!(
            "{} triangles ({} spheres) as 10 or 1000 parts, {}x{}, median of {} frames on {}",
            report.triangles,
            drafter_bench::spheres::SPHERES,
            args.size.0,
            args.size.1,
            args.frames,
            report.device
        );
        for (name, row) in &report.cases {
            out!("  {name:<12} {row}");
        }
        for (name, ratio) in &report.ratios {
            out!("  1000 / 10 parts, {name:<16} {ratio}×");
        }
        let e = &report.edit;
        out!(
            "  edit of all {} parts, CPU + part-table upload until the GPU is idle (median of {}): key {:.3} ms, anchor-drag step {:.3} ms",
            e.parts,
            e.edits,
            e.key_ms,
            e.drag_ms
        );
    }
    Ok(())
}

/// A synthetic scene of [`drafter_bench::spheres`] as the renderer's model.
fn spheres_model(parts: usize, triangles: usize, labelled: bool) -> Result<Model> {
    let (scene, baked) = drafter_bench::spheres::scene(parts, triangles, labelled)?;
    Model::from_scene(&scene, baked.as_ref()).ok_or_else(|| anyhow::anyhow!("empty synthetic scene"))
}
