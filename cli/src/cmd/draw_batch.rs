//! `drafter draw INPUT... -o DIR [--format svg,pdf,dxf] [--sheet A3 ...] [--cache DIR] [--jobs N]
//! [--report FILE.json]`: a catalog of drawings (`drafter_catalog::draw` does the work, over the
//! batch's scheduler, discovery, confinement and cache): several inputs, folders or manifests, each
//! drawn once and written as `DIR/<its relative path>.<format>` for every format. The progress,
//! the failures listed at the end, exit code 4 when some inputs failed and Ctrl-C are the bake's
//! (`batch.rs`). Also `drafter draw FILE -o x.svg --cache DIR`: one drawing through the cache.

use std::path::PathBuf;

use anyhow::Result;
use drafter_catalog::batch::{self, CacheUse, Permit, Record, Status};
use drafter_catalog::cache::Cache;
use drafter_catalog::draw::{self, DrawSpec, Format};

use crate::cmd::batch::{Bar, Interrupted, Shown, some_failed};
use crate::cmd::draw::Args;
use crate::cmd::out;
use crate::exit::{BadInput, IoFailure};

/// The options of a catalog, part of `drafter draw`'s.
#[derive(Debug, clap::Args)]
pub struct CatalogArgs {
    /// The formats of a catalog, comma-separated: svg, pdf, dxf. Each input is drawn once and
    /// written in each as `-o DIR/<its path relative to what named it>.<format>` (a folder's files
    /// mirror their paths below it, a manifest's entries their paths; `..` and roots are dropped,
    /// nothing is written outside DIR). Given with one input, it makes a catalog of that one file.
    /// Without it, a catalog writes svg; one file's format is -o's extension.
    #[arg(long, value_name = "LIST")]
    pub format: Option<String>,
    /// A list of inputs for a catalog: a `.toml` file with `inputs = ["a.gltf", "parts/"]`, or any
    /// other file with one path per line (`#` comments); paths are relative to the manifest's
    /// folder. Repeatable.
    #[arg(long, value_name = "FILE")]
    pub manifest: Vec<PathBuf>,
    /// A content-addressed cache of drawings (created if missing; the bake's cache folder may be
    /// shared): an input drawn before with the same bytes, external files, options, format and
    /// drafter build is written from it without loading the model. Safe to share between
    /// processes and machines.
    #[arg(long, value_name = "DIR", env = "DRAFTER_CACHE")]
    pub cache: Option<PathBuf>,
    /// Keep the cache within this size (e.g. 20G, 500M), evicting the least recently used
    /// entries after the run.
    #[arg(long, value_name = "SIZE", value_parser = crate::cmd::bake::parse_size, env = "DRAFTER_CACHE_MAX")]
    pub cache_max: Option<u64>,
    /// A catalog's memory budget (e.g. 8G): files are admitted while their estimated peaks fit
    /// together; a file larger than the budget runs alone. Default: half the available memory.
    #[arg(long, value_name = "SIZE", value_parser = crate::cmd::bake::parse_size)]
    pub memory: Option<u64>,
    /// A catalog's files drawn at once, at most (default: the cores; each drawing also uses the
    /// thread pool).
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Write a catalog's report (every file's status, cache use, time and bytes) as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub report: Option<PathBuf>,
}

/// Several inputs, a folder, a manifest or `--format`: a catalog.
pub fn is_catalog(args: &Args) -> bool {
    args.inputs.len() > 1
        || !args.catalog.manifest.is_empty()
        || args.catalog.format.is_some()
        || args.inputs.first().is_some_and(|p| p.is_dir())
}

/// The drawing's options from the command line as drafter-catalog's plain value.
pub fn spec(args: &Args) -> DrawSpec {
    DrawSpec {
        hidden: args.hidden,
        smooth: args.smooth,
        style: args.style,
        tolerance_px: args.tolerance,
        size: args.size,
        view: args.view,
        orthographic: args.ortho,
        fill: args.fill,
        sheet: args.sheet.spec(),
    }
}

fn open_cache(args: &Args) -> Result<Option<Cache>> {
    let c = &args.catalog;
    c.cache
        .as_ref()
        .map(|dir| {
            Cache::open(dir, c.cache_max)
                .map_err(|e| IoFailure(format!("{}: cannot open the cache: {e}", dir.display())).into())
        })
        .transpose()
}

/// `drafter draw FILE -o x.svg --cache DIR`: one drawing through the cache, the same bytes as
/// without it. `--json` prints the file's record.
pub fn single(args: &Args) -> Result<()> {
    drafter_catalog::interrupt::install();
    let format = Format::of_path(&args.output)
        .ok_or_else(|| BadInput(format!("{}: output must end in .svg, .pdf or .dxf", args.output.display())))?;
    let resolved = spec(args).resolve(args.file())?;
    let folder = args.output.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(std::path::Path::new("."));
    if !folder.is_dir() {
        return Err(BadInput(format!("{}: no folder {} to write into", args.output.display(), folder.display())).into());
    }
    if args.output.is_dir() {
        return Err(BadInput(format!("{}: is a folder", args.output.display())).into());
    }
    let cache = open_cache(args)?;
    let limits = drafter_io::Limits { max_triangles: args.max_triangles };
    let admit = |bytes| Some(Permit::unbounded(bytes));
    let outputs = [(format, args.output.clone())];
    let record = draw::draw_file(args.file(), &outputs, &resolved, &limits, cache.as_ref(), &admit);
    if let Some(cache) = &cache {
        crate::cmd::bake::evict(cache, args.quiet);
    }
    if args.json {
        out!("{}", serde_json::to_string_pretty(&record)?);
    }
    if record.status == Status::Failed {
        let message = record.error.clone().unwrap_or_default();
        return Err(match record.exit_code {
            Some(drafter_catalog::exit::IO_FAILURE) => IoFailure(message).into(),
            Some(drafter_catalog::exit::BAD_INPUT) => BadInput(message).into(),
            _ => anyhow::anyhow!(message),
        });
    }
    if !args.quiet {
        let how = match record.cache {
            CacheUse::Hit if record.up_to_date => "up to date, from the cache",
            CacheUse::Hit => "from the cache",
            _ => "drawn",
        };
        eprintln!(
            "drew {} → {} ({how}): {} bytes in {:.0} ms",
            args.file().display(),
            args.output.display(),
            record.bytes_out,
            record.ms
        );
        for note in &record.notes {
            eprintln!("  note: {note}");
        }
        if let Some(warning) = &record.warning {
            eprintln!("  warning: {warning}");
        }
    }
    Ok(())
}

/// A catalog: every input drawn into `-o DIR`.
pub fn run(args: &Args) -> Result<()> {
    drafter_catalog::interrupt::install();
    let c = &args.catalog;
    let formats = match &c.format {
        Some(list) => Format::parse_list(list).map_err(|e| BadInput(format!("--format {e}")))?,
        None => vec![Format::Svg],
    };
    let out_dir = args.output.clone();
    if std::fs::metadata(&out_dir).is_ok_and(|m| !m.is_dir()) {
        return Err(BadInput(format!("{}: a catalog's output must be a folder", out_dir.display())).into());
    }
    let spec = spec(args);
    // The options checked once, before any file: a mistake is one line, not one per file.
    spec.resolve(args.file())?;
    let same = |a: &std::path::Path, b: &std::path::Path| {
        a.canonicalize().ok().zip(b.canonicalize().ok()).is_some_and(|(a, b)| a == b)
    };
    if let Some(input) = args.inputs.iter().find(|i| same(i, &out_dir)) {
        return Err(BadInput(format!("{}: is both an input folder and the output folder", input.display())).into());
    }
    if let Some(report) = &c.report
        && std::fs::metadata(report).is_ok_and(|m| !m.is_file())
    {
        return Err(BadInput(format!("{}: the report must be a file", report.display())).into());
    }
    std::fs::create_dir_all(&out_dir).map_err(|e| IoFailure(format!("{}: cannot create: {e}", out_dir.display())))?;
    drafter_catalog::output::check_writable(&out_dir).map_err(|e| IoFailure(e.to_string()))?;
    let found = drafter_catalog::discover::discover_all(&args.inputs, &c.manifest, Some(&out_dir))
        .map_err(|e| BadInput(e.to_string()))?;
    if found.items.is_empty() && found.unreadable.is_empty() {
        return Err(BadInput("no input of a supported format (.gltf .glb .obj .stl .off .ply) was found".into()).into());
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let options = draw::Options {
        spec,
        formats,
        limits: drafter_io::Limits { max_triangles: args.max_triangles },
        cache: open_cache(args)?,
        scheduling: batch::Scheduling {
            memory_budget: c.memory.unwrap_or_else(batch::default_memory_budget),
            workers: c.jobs.unwrap_or(cores).max(1),
        },
    };

    drafter_catalog::interrupt::set_graceful(true);
    let stop = || drafter_catalog::interrupt::stop_requested().is_some();
    let shown = Shown::choose(args.quiet);
    let bar = Bar::new(shown, &found.items);
    let summary = draw::run(&found, &out_dir, &options, &stop, &bar);
    bar.finish();
    if let Some(cache) = &options.cache {
        crate::cmd::bake::evict(cache, args.quiet);
    }
    if let Some(path) = &c.report {
        drafter_catalog::output::write_atomically(path, &serde_json::to_vec_pretty(&summary)?)?;
    }
    if args.json {
        out!("{}", serde_json::to_string_pretty(&summary)?);
    }
    let failures: Vec<&Record> = summary.files.iter().filter(|r| r.status == Status::Failed).collect();
    let drawn = summary.drawn.unwrap_or(0);
    if !args.quiet {
        for r in summary.files.iter().filter_map(|r| r.warning.as_ref()) {
            eprintln!("  warning: {r}");
        }
        if shown != Shown::Lines {
            for r in summary.files.iter().filter(|r| !r.notes.is_empty()) {
                eprintln!("  {}:", r.input);
                for note in &r.notes {
                    eprintln!("    note: {note}");
                }
            }
        }
        let hits = summary.files.iter().filter(|r| r.cache == CacheUse::Hit).count();
        let formats: Vec<&str> = options.formats.iter().map(|f| f.extension()).collect();
        eprintln!(
            "drew {} of {} files as {} into {} in {:.2} s ({} from the cache, {} failed, {} skipped; {} at once)",
            drawn + summary.cached,
            summary.files.len(),
            formats.join(", "),
            out_dir.display(),
            summary.wall_ms / 1e3,
            hits,
            summary.failed,
            summary.skipped,
            summary.workers,
        );
    }
    // Failures are listed even with --quiet: they are errors.
    for r in &failures {
        eprintln!("  failed: {}", r.error.as_deref().unwrap_or(&r.input));
    }
    if let Some(signal) = drafter_catalog::interrupt::stop_requested() {
        return Err(Interrupted(signal).into());
    }
    if !failures.is_empty() {
        return Err(some_failed(failures.len(), summary.files.len(), drawn + summary.cached, "drawn").into());
    }
    Ok(())
}
