//! `drafter bake` of several inputs, folders or manifests into `-o DIR` (`drafter_catalog::batch`
//! does the work): a progress bar on a terminal, one plain line per file elsewhere (a CI log), the
//! failures listed at the end, `--report` with every file's status, and exit code 4 when some
//! inputs failed. The first Ctrl-C stops admitting
//! files and lets the running ones finish (exit 130); a second one exits at once, leaving no
//! partial file. With `--cache`, a rerun serves the files already baked from the cache.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::Mutex;
use std::time::Duration;

use anyhow::Result;
use drafter_bake::BakeConfig;
use drafter_catalog::batch::{self, Observer, Record, Status};
use drafter_catalog::discover::Item;

use crate::cmd::bake::{Args, evict, open_cache};
use crate::cmd::out;
use crate::exit::{BadInput, IoFailure};

/// Some inputs of a batch failed (exit 4); the others were baked.
#[derive(Debug)]
pub struct SomeFailed(pub String);

impl std::fmt::Display for SomeFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SomeFailed {}

/// A batch stopped by a signal (exit 128 + the signal).
#[derive(Debug)]
pub struct Interrupted(pub i32);

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "stopped by signal {}; the files started were finished, the rest skipped", self.0)
    }
}

impl std::error::Error for Interrupted {}

pub fn run(args: &Args, config: BakeConfig) -> Result<()> {
    if args.textures_out.is_some() {
        return Err(
            BadInput("--textures-out takes one input; bake the files one by one to get their textures".into()).into()
        );
    }
    let out_dir = args.output.clone().ok_or_else(|| {
        BadInput("several inputs, a folder or a manifest make a batch, which needs -o DIR (the output folder)".into())
    })?;
    if std::fs::metadata(&out_dir).is_ok_and(|m| !m.is_dir()) {
        return Err(BadInput(format!("{}: a batch's output must be a folder", out_dir.display())).into());
    }
    let same = |a: &Path, b: &Path| a.canonicalize().ok().zip(b.canonicalize().ok()).is_some_and(|(a, b)| a == b);
    if let Some(input) = args.inputs.iter().find(|i| same(i, &out_dir)) {
        return Err(BadInput(format!("{}: is both an input folder and the output folder", input.display())).into());
    }
    std::fs::create_dir_all(&out_dir).map_err(|e| IoFailure(format!("{}: cannot create: {e}", out_dir.display())))?;
    // A folder nothing can be written in is found now, not after every file was baked.
    drafter_catalog::output::check_writable(&out_dir).map_err(|e| IoFailure(e.to_string()))?;
    let found = drafter_catalog::discover::discover_all(&args.inputs, &args.manifest, Some(&out_dir))
        .map_err(|e| BadInput(e.to_string()))?;
    let items = &found.items;
    if items.is_empty() && found.unreadable.is_empty() {
        return Err(BadInput("no input of a supported format (.gltf .glb .obj .stl .off .ply) was found".into()).into());
    }
    if let Some(report) = &args.report
        && std::fs::metadata(report).is_ok_and(|m| !m.is_file())
    {
        return Err(BadInput(format!("{}: the report must be a file", report.display())).into());
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let options = batch::Options {
        config,
        limits: drafter_io::Limits { max_triangles: args.max_triangles },
        cache: open_cache(args)?,
        memory_budget: args.memory.unwrap_or_else(batch::default_memory_budget),
        workers: args.jobs.unwrap_or(cores).max(1),
    };

    drafter_catalog::interrupt::set_graceful(true);
    let stop = || drafter_catalog::interrupt::stop_requested().is_some();
    let shown = Shown::choose(args.quiet);
    let bar = Bar::new(shown, items);
    let summary = batch::run_discovered(&found, &out_dir, &options, &stop, &bar);
    bar.finish();
    if let Some(cache) = &options.cache {
        evict(cache, args.quiet);
    }

    if let Some(path) = &args.report {
        drafter_catalog::output::write_atomically(path, &serde_json::to_vec_pretty(&summary)?)?;
    }
    if args.json {
        out!("{}", serde_json::to_string_pretty(&summary)?);
    }
    let failures: Vec<&Record> = summary.files.iter().filter(|r| r.status == Status::Failed).collect();
    if !args.quiet {
        for r in summary.files.iter().filter_map(|r| r.warning.as_ref()) {
            eprintln!("  warning: {r}");
        }
        if shown != Shown::Lines {
            // On a terminal the bar is gone: the notes of each file, as a single bake prints them
            // (on a pipe they followed each file's line).
            for r in summary.files.iter().filter(|r| !r.notes.is_empty()) {
                eprintln!("  {}:", r.input);
                for note in &r.notes {
                    eprintln!("    note: {note}");
                }
            }
        }
        let hits = summary.files.iter().filter(|r| r.cache == batch::CacheUse::Hit).count();
        let over = match summary.over_budget {
            0 => String::new(),
            n => {
                let largest = summary.files.iter().map(|r| r.estimated_peak_bytes).max().unwrap_or(0);
                format!(
                    "; {n} file{} over the budget ran alone, the largest estimated at {} MB",
                    if n == 1 { "" } else { "s" },
                    largest >> 20
                )
            }
        };
        eprintln!(
            "baked {} of {} files into {} in {:.2} s ({} from the cache, {} failed, {} skipped; {} at once, \
             memory budget {} MB, at most {} MB estimated at once{over})",
            summary.baked + summary.cached,
            summary.files.len(),
            out_dir.display(),
            summary.wall_ms / 1e3,
            hits,
            summary.failed,
            summary.skipped,
            summary.workers,
            summary.memory_budget >> 20,
            summary.peak_admitted_bytes >> 20,
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
        return Err(some_failed(failures.len(), summary.files.len(), summary.baked + summary.cached, "baked").into());
    }
    Ok(())
}

/// A batch's error when `failed` of its `files` failed and `done` were made (`made`: "baked",
/// "drawn"): exit code 4, the failures listed above it.
pub fn some_failed(failed: usize, files: usize, done: usize, made: &str) -> SomeFailed {
    let rest = match done {
        0 => format!("none was {made}"),
        n if n + failed == files => format!("the others were {made}"),
        n => format!("{n} were {made}"),
    };
    SomeFailed(format!("{failed} of {files} inputs failed (listed above); {rest}"))
}

/// How a batch shows its progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Shown {
    /// `--quiet`.
    Nothing,
    /// A progress bar, on a terminal.
    Bar,
    /// One plain line per finished file (`[12/47] name: baked 1.20 s`), no carriage returns: a
    /// pipe, a CI log.
    Lines,
}

impl Shown {
    /// Nothing with `--quiet`, a bar on a terminal, lines elsewhere.
    pub(crate) fn choose(quiet: bool) -> Shown {
        if quiet {
            Shown::Nothing
        } else if std::io::stderr().is_terminal() {
            Shown::Bar
        } else {
            Shown::Lines
        }
    }
}

/// The batch's progress: on a terminal a bar (files done of all, input bytes done of all, the
/// ETA, the files being baked); on a pipe a line per file with its notes.
pub(crate) struct Bar {
    bar: Option<indicatif::ProgressBar>,
    lines: bool,
    files: usize,
    state: Mutex<(usize, Vec<String>)>,
}

impl Bar {
    pub(crate) fn new(shown: Shown, items: &[Item]) -> Self {
        let bar = (shown == Shown::Bar).then(|| {
            let bar = indicatif::ProgressBar::new(0);
            let style = indicatif::ProgressStyle::with_template(
                "{spinner} [{bar:24}] {prefix} {binary_bytes}/{binary_total_bytes} ETA {eta} {wide_msg}",
            )
            .map(|s| s.progress_chars("=> "))
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style);
            bar.enable_steady_tick(Duration::from_millis(100));
            bar
        });
        Bar { bar, lines: shown == Shown::Lines, files: items.len(), state: Mutex::new((0, Vec::new())) }
    }

    fn redraw(&self, state: &(usize, Vec<String>)) {
        if let Some(bar) = &self.bar {
            bar.set_prefix(format!("{}/{} files", state.0, self.files));
            bar.set_message(state.1.join(", "));
        }
    }

    pub(crate) fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

fn name(item: &Item) -> String {
    item.relative_output.with_extension("").display().to_string()
}

/// A finished file's line on a pipe: `[3/47] gear: baked 1.20 s` (`drawn` in a catalog of drawings),
/// `cached (up to date)`, or
/// `FAILED: why`.
fn line(done: usize, files: usize, item: &Item, record: &Record) -> String {
    let what = match record.status {
        Status::Baked => format!("baked {:.2} s", record.ms / 1e3),
        Status::Drawn => format!("drawn {:.2} s", record.ms / 1e3),
        Status::Cached if record.up_to_date => "cached (up to date)".to_owned(),
        Status::Cached => format!("cached {:.2} s", record.ms / 1e3),
        Status::Failed => format!("FAILED: {}", record.error.as_deref().unwrap_or("")),
        Status::Skipped => "skipped".to_owned(),
    };
    let alone = if record.over_budget {
        format!(" (estimated {} MB, over the memory budget: ran alone)", record.estimated_peak_bytes >> 20)
    } else {
        String::new()
    };
    format!("[{done}/{files}] {}: {what}{alone}", name(item))
}

impl Observer for Bar {
    fn begin(&self, _files: usize, bytes: u64) {
        if let Some(bar) = &self.bar {
            bar.set_length(bytes);
        }
    }

    fn started(&self, item: &Item, _bytes: u64) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.1.push(name(item));
        self.redraw(&state);
    }

    fn finished(&self, item: &Item, bytes: u64, record: &Record) {
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        state.0 += 1;
        let n = name(item);
        state.1.retain(|x| *x != n);
        self.redraw(&state);
        if let Some(bar) = &self.bar {
            bar.inc(bytes);
        }
        if self.lines {
            // Under the lock: one file's lines are not interleaved with another's.
            let mut text = line(state.0, self.files, item, record);
            for note in &record.notes {
                text.push_str(&format!("\n    note: {note}"));
            }
            eprintln!("{text}");
        }
    }
}
