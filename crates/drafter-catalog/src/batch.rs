//! Many files in one run: files bake side by side on the stages' own thread pool, admitted in
//! order under a memory budget; one bad file never stops the others.
//!
//! **Admission.** Each file's peak is estimated before its bake ([`crate::estimate`]); a file is
//! admitted when the estimates of the files running plus its own fit the budget, or when nothing
//! else runs (a file larger than the whole budget runs alone). Admission is first come, first
//! served (tickets), so a large file waiting for room is not overtaken by small ones forever. Files
//! are taken largest first (their size with a glTF's external buffers), which keeps both cores busy
//! to the end instead of finishing on one large file.
//!
//! **Cache.** With a cache, a file whose key has an intact entry is written from it without
//! running a stage or waiting for admission; a baked file is stored after its output is written.
//!
//! **Stopping.** `stop()` is polled before each file and while a file waits for room: the files
//! running finish and are written, the rest are reported as skipped.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

use drafter_bake::BakeConfig;
use serde::Serialize;

use crate::cache::{Cache, Miss};
use crate::discover::Item;
use crate::job::{self, Error};

/// What happened to one file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    Baked,
    /// Drawn (a catalog of drawings, [`crate::draw`]).
    Drawn,
    /// Written from the cache.
    Cached,
    Failed,
    /// Not started: the batch was stopped.
    Skipped,
}

/// How the cache served a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CacheUse {
    /// No cache.
    Off,
    Hit,
    Miss,
    /// An entry failed its check (truncated, corrupted), was removed, and the file was baked.
    Rebuilt,
    /// No key: an external file the input names could not be read.
    Uncacheable,
}

/// One file's line in the batch report (`--report`).
#[derive(Clone, Debug, Serialize)]
pub struct Record {
    pub input: String,
    pub output: String,
    pub status: Status,
    pub cache: CacheUse,
    /// Wall time of this file: reading, hashing, waiting for admission excluded, baking, writing.
    pub ms: f64,
    pub bytes_in: u64,
    pub bytes_out: u64,
    /// The peak memory the admission reserved (0 for a file that was not baked).
    pub estimated_peak_bytes: u64,
    /// The one-line reason of a failure.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The exit code the failure alone would have had (2 input, 3 I/O, 1 internal).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exit_code: Option<u8>,
    /// With a cache: the output already held this key's bytes (its receipt matched), so it was
    /// left as it was.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub up_to_date: bool,
    /// A problem that did not fail the file (the cache could not be written).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
    /// The bake's notes, one line per kind (`non-finite positions: 1 (first: ...)`), as a single
    /// bake prints them; a file written from the cache repeats the notes of the bake stored.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// The file's estimated peak was over the whole memory budget: it ran alone.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub over_budget: bool,
    /// Every file written for this input when there are several (a drawing in more than one
    /// format); `output` is the first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
}

impl Record {
    pub(crate) fn new(input: &Path, output: &Path) -> Self {
        Record {
            input: input.display().to_string(),
            output: output.display().to_string(),
            status: Status::Skipped,
            cache: CacheUse::Off,
            ms: 0.0,
            bytes_in: 0,
            bytes_out: 0,
            estimated_peak_bytes: 0,
            error: None,
            exit_code: None,
            up_to_date: false,
            warning: None,
            notes: Vec::new(),
            over_budget: false,
            outputs: Vec::new(),
        }
    }

    pub(crate) fn fail(&mut self, e: &Error) {
        self.status = Status::Failed;
        self.error = Some(e.to_string().replace('\n', " "));
        self.exit_code = Some(e.exit_code());
    }
}

/// A reservation of the memory budget, released when dropped.
pub struct Permit<'a> {
    budget: Option<&'a Budget>,
    /// What this permit reserves of the budget (at most all of it).
    bytes: u64,
    /// The estimate asked for, which may be over the budget (such a file runs alone).
    estimate: u64,
}

impl std::fmt::Debug for Permit<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Permit({} bytes)", self.bytes)
    }
}

impl Permit<'_> {
    /// A permit outside any budget (a single bake).
    pub fn unbounded(bytes: u64) -> Permit<'static> {
        Permit { budget: None, bytes, estimate: bytes }
    }

    /// Whether the estimate asked for was over the whole budget (the file runs alone).
    pub fn over_budget(&self) -> bool {
        self.estimate > self.bytes
    }
}

impl Drop for Permit<'_> {
    fn drop(&mut self) {
        if let Some(budget) = self.budget {
            let mut state = budget.state.lock().unwrap_or_else(|e| e.into_inner());
            state.in_use -= self.bytes;
            state.estimated -= self.estimate;
            state.running -= 1;
            budget.changed.notify_all();
        }
    }
}

/// The memory budget shared by a batch's files.
#[derive(Debug)]
pub struct Budget {
    total: u64,
    state: Mutex<BudgetState>,
    changed: Condvar,
}

#[derive(Debug, Default)]
struct BudgetState {
    in_use: u64,
    /// The estimates of the files running, over the budget where one file is.
    estimated: u64,
    running: usize,
    /// Tickets handed out and the one to be admitted next.
    issued: u64,
    serving: u64,
    /// The most estimated at once (over the budget when a file over it ran alone).
    peak: u64,
}

impl Budget {
    pub fn new(total: u64) -> Self {
        Budget { total, state: Mutex::new(BudgetState::default()), changed: Condvar::new() }
    }

    /// Waits until `bytes` fit (or nothing else runs) and this caller is next in line; `None` if
    /// `stop()` turns true first. A request over the whole budget reserves the whole budget.
    pub fn admit(&self, estimate: u64, stop: &dyn Fn() -> bool) -> Option<Permit<'_>> {
        let bytes = estimate.min(self.total);
        let mut state = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let ticket = state.issued;
        state.issued += 1;
        loop {
            if stop() {
                // Later tickets must not wait for this one.
                if state.serving == ticket {
                    state.serving += 1;
                }
                self.changed.notify_all();
                return None;
            }
            if state.serving >= ticket && (state.in_use + bytes <= self.total || state.running == 0) {
                state.serving = state.serving.max(ticket + 1);
                state.in_use += bytes;
                state.estimated += estimate;
                state.running += 1;
                state.peak = state.peak.max(state.estimated);
                self.changed.notify_all();
                return Some(Permit { budget: Some(self), bytes, estimate });
            }
            if rayon::current_thread_index().is_some() {
                // A thread of the stages' pool (a batch worker) helps the files running while it
                // waits, instead of leaving a large file that runs alone one thread short.
                drop(state);
                if rayon::yield_now() != Some(rayon::Yield::Executed) {
                    std::thread::sleep(Duration::from_micros(500));
                }
                state = self.state.lock().unwrap_or_else(|e| e.into_inner());
            } else {
                // A timeout, so that a stop request is seen while waiting.
                state =
                    self.changed.wait_timeout(state, Duration::from_millis(50)).unwrap_or_else(|e| e.into_inner()).0;
            }
        }
    }

    /// The most estimated peak memory admitted at once: within the budget, unless a file over the
    /// whole budget ran (alone).
    pub fn peak(&self) -> u64 {
        self.state.lock().unwrap_or_else(|e| e.into_inner()).peak
    }
}

/// Bakes `input` into `output` (a .glb or .gltf), through `cache` when given: a hit writes the
/// stored bytes without running a stage; otherwise `admit` is asked for the bake's estimated
/// peak, and `None` from it skips the file. The record says what happened; nothing is partial.
pub fn bake_file<'b>(
    input: &Path,
    output: &Path,
    config: &BakeConfig,
    limits: &drafter_io::Limits,
    cache: Option<&Cache>,
    admit: &dyn Fn(u64) -> Option<Permit<'b>>,
) -> Record {
    let started = Instant::now();
    let mut record = Record::new(input, output);
    let result = bake_file_inner(input, output, config, limits, cache, admit, &mut record);
    if let Err(e) = result {
        record.fail(&e);
    }
    record.ms = started.elapsed().as_secs_f64() * 1e3;
    record
}

fn bake_file_inner<'b>(
    input: &Path,
    output: &Path,
    config: &BakeConfig,
    limits: &drafter_io::Limits,
    cache: Option<&Cache>,
    admit: &dyn Fn(u64) -> Option<Permit<'b>>,
    record: &mut Record,
) -> Result<(), Error> {
    let mut config = config.clone();
    config.container = crate::output::container_for(output)?;
    // With a cache, the key first, without reading the file into memory: an output still up to
    // date then costs the input's hash alone.
    let key = match cache {
        Some(c) => {
            let key = crate::cache::key_of_file(input, &config)
                .map_err(|source| drafter_io::ImportError::Io { path: input.to_path_buf(), source })?;
            Some((c, key))
        }
        None => None,
    };
    // The input's bytes with a glTF's external buffers and images, as the batch's total counts them.
    record.bytes_in = input_size(input);
    let bin_path = match &config.container {
        drafter_format::Container::Gltf { bin_uri } => Some(output.with_file_name(bin_uri)),
        drafter_format::Container::Glb => None,
    };
    let outputs: Vec<&Path> = std::iter::once(output).chain(bin_path.as_deref()).collect();
    if let Some((cache, key)) = key {
        record.cache = CacheUse::Uncacheable;
        if let Some(key) = key {
            if cache.receipt_matches(&outputs, &key) {
                // The entry stays the one in use for eviction, although it was not read.
                cache.touch(&key);
                record.bytes_out = outputs.iter().map(|p| std::fs::metadata(p).map_or(0, |m| m.len())).sum();
                record.status = Status::Cached;
                record.cache = CacheUse::Hit;
                record.up_to_date = true;
                return Ok(());
            }
            match cache.get(&key) {
                Ok(payloads) => {
                    let bin = payloads.get(1).filter(|b| !b.is_empty()).map(Vec::as_slice);
                    crate::output::write_outputs(output, &payloads[0], bin, &config.container, &[])?;
                    cache.write_receipt(&outputs, &key);
                    record.bytes_out = (payloads[0].len() + bin.map_or(0, <[u8]>::len)) as u64;
                    record.status = Status::Cached;
                    record.cache = CacheUse::Hit;
                    record.notes = payloads.get(2).map_or_else(Vec::new, |report| stored_notes(report));
                    return Ok(());
                }
                Err(Miss::Absent) => record.cache = CacheUse::Miss,
                Err(Miss::Corrupt(_)) => record.cache = CacheUse::Rebuilt,
            }
            if record.cache == CacheUse::Miss
                && let Ok(reason) = cache.get(&crate::cache::failure_key(&key, limits))
            {
                record.cache = CacheUse::Hit;
                let reason = reason.first().map(|r| String::from_utf8_lossy(r).into_owned()).unwrap_or_default();
                return Err(Error::Input(reason.replace(INPUT_PLACEHOLDER, &input.display().to_string())));
            }
        }
    }
    let bytes = job::read_input(input)?;
    let estimate = crate::estimate::peak_bytes(input, &bytes);
    let Some(permit) = admit(estimate) else {
        record.status = Status::Skipped;
        return Ok(());
    };
    record.estimated_peak_bytes = estimate;
    record.over_budget = permit.over_budget();
    let baked = match job::bake_bytes(input, bytes, &config, limits, &mut |_| {}) {
        Ok(baked) => baked,
        Err(e) => {
            // The input's fault is decided by what the key covers: stored, so that a rerun replays
            // it without parsing the file again.
            // The key covers the file's name and bytes, not its folder: the path is stored as a
            // placeholder, so that a cache shared between machines names each one's own path.
            if let Some((cache, Some(key))) = key
                && e.is_content_fault()
            {
                let reason = e.to_string().replace(&input.display().to_string(), INPUT_PLACEHOLDER);
                let _ = cache.put(&crate::cache::failure_key(&key, limits), &[reason.as_bytes()], &guard);
            }
            return Err(e);
        }
    };
    record.notes = notes(&baked.report.diagnostics);
    let bin = baked.written.bin.as_deref();
    crate::output::write_outputs(output, &baked.written.main, bin, &config.container, &[])?;
    record.bytes_out = (baked.written.main.len() + bin.map_or(0, <[u8]>::len)) as u64;
    record.status = Status::Baked;
    if let Some((cache, Some(key))) = key {
        let report = serde_json::to_vec(&baked.report).unwrap_or_default();
        let payloads: [&[u8]; 3] = [&baked.written.main, bin.unwrap_or_default(), &report];
        if let Err(e) = cache.put(&key, &payloads, &guard) {
            record.warning = Some(format!("{}: cannot store in the cache: {e}", cache.root().display()));
        }
        cache.write_receipt(&outputs, &key);
    }
    Ok(())
}

/// Stands for the input's path in a refusal stored in the cache (a character no path holds).
const INPUT_PLACEHOLDER: &str = "\u{0}input\u{0}";

/// The bake's notes as a single bake prints them: one line per kind.
fn notes(diagnostics: &[drafter_core::Diagnostic]) -> Vec<String> {
    drafter_core::summarize(diagnostics).iter().map(ToString::to_string).collect()
}

/// The notes of the bake whose report a cache entry stored.
fn stored_notes(report: &[u8]) -> Vec<String> {
    #[derive(serde::Deserialize)]
    struct Stored {
        #[serde(default)]
        diagnostics: Vec<drafter_core::Diagnostic>,
    }
    serde_json::from_slice::<Stored>(report).map_or_else(|_| Vec::new(), |r| notes(&r.diagnostics))
}

/// Registers a temporary file with the signal handler ([`crate::interrupt`]).
pub fn guard(path: &Path) -> Box<dyn Send> {
    Box::new(crate::interrupt::TempFileGuard::new(path))
}

/// Options of a batch.
#[derive(Debug)]
pub struct Options {
    pub config: BakeConfig,
    pub limits: drafter_io::Limits,
    pub cache: Option<Cache>,
    /// Bytes of estimated peak memory the running files may reserve together.
    pub memory_budget: u64,
    /// Files baked at once, at most.
    pub workers: usize,
}

/// Follows a batch (a progress bar).
pub trait Observer: Sync {
    /// The batch holds `files` files of `bytes` in all.
    fn begin(&self, _files: usize, _bytes: u64) {}
    /// `item` was taken; `bytes` is its size as counted in [`Summary::bytes_total`].
    fn started(&self, _item: &Item, _bytes: u64) {}
    fn finished(&self, _item: &Item, _bytes: u64, _record: &Record) {}
}

/// No progress shown.
#[derive(Debug)]
pub struct Quiet;
impl Observer for Quiet {}

/// The batch report (`--report`).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub files: Vec<Record>,
    pub baked: usize,
    /// A catalog of drawings ([`crate::draw::run`]): the files drawn (none is baked: `baked` is 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drawn: Option<usize>,
    pub cached: usize,
    pub failed: usize,
    pub skipped: usize,
    pub wall_ms: f64,
    pub bytes_total: u64,
    pub memory_budget: u64,
    /// The most estimated peak memory admitted at once.
    pub peak_admitted_bytes: u64,
    pub workers: usize,
    /// Files whose estimated peak was over the whole budget (each ran alone).
    pub over_budget: usize,
    /// drafter's build ([`crate::cache::BUILD_ID`]), so that a report says what made its files.
    pub build: String,
    /// The effective configuration, in the canonical form the cache's key hashes.
    pub config: serde_json::Value,
}

/// As [`run`] over what [`crate::discover::discover_all`] found: each folder that could not be
/// listed is one more failed file of the report.
pub fn run_discovered(
    found: &crate::discover::Discovered,
    out_dir: &Path,
    options: &Options,
    stop: &(dyn Fn() -> bool + Sync),
    observer: &dyn Observer,
) -> Summary {
    let mut summary = run(&found.items, out_dir, options, stop, observer);
    add_unreadable(&mut summary, found, out_dir);
    summary
}

/// Each folder of `found` that could not be listed, as one more failed file of `summary`.
pub(crate) fn add_unreadable(summary: &mut Summary, found: &crate::discover::Discovered, out_dir: &Path) {
    for (folder, why) in &found.unreadable {
        let mut record = Record::new(folder, out_dir);
        record.fail(&Error::Io(format!("{}: cannot list: {why}", folder.display())));
        record.output = String::new();
        summary.files.push(record);
        summary.failed += 1;
    }
}

/// Bakes `items` into `out_dir`, `options.workers` files at a time under the memory budget.
pub fn run(
    items: &[Item],
    out_dir: &Path,
    options: &Options,
    stop: &(dyn Fn() -> bool + Sync),
    observer: &dyn Observer,
) -> Summary {
    let bake: &Job<'_> = &|item, admit| {
        // Every output is named below `out_dir` through `output::confined`, which refuses `..`,
        // absolute parts and symbolic links on the way: no caller of the batch can write outside it.
        match crate::output::confined(out_dir, &item.relative_output) {
            Err(e) => {
                let mut record = Record::new(&item.input, &out_dir.join(&item.relative_output));
                record.fail(&e);
                record
            }
            Ok(output) => {
                bake_file(&item.input, &output, &options.config, &options.limits, options.cache.as_ref(), admit)
            }
        }
    };
    let scheduling = Scheduling { memory_budget: options.memory_budget, workers: options.workers };
    let mut summary = run_jobs(items, out_dir, &scheduling, stop, observer, bake);
    summary.config = crate::cache::canonical_config(&options.config);
    summary
}

/// How a batch's files are run side by side, whatever each one's job.
#[derive(Clone, Copy, Debug)]
pub struct Scheduling {
    /// Bytes of estimated peak memory the running files may reserve together.
    pub memory_budget: u64,
    /// Files run at once, at most.
    pub workers: usize,
}

/// One file's job in a batch: `admit` asks the memory budget for room (`None`: the batch was
/// stopped while it waited, and the file is skipped).
pub type Job<'j> = dyn for<'b> Fn(&Item, &dyn Fn(u64) -> Option<Permit<'b>>) -> Record + Sync + 'j;

/// Runs `job` over `items` (a bake, a drawing), `scheduling.workers` files at a time under the
/// memory budget, largest first; the summary's `config` is left for the caller to fill.
pub fn run_jobs(
    items: &[Item],
    out_dir: &Path,
    scheduling: &Scheduling,
    stop: &(dyn Fn() -> bool + Sync),
    observer: &dyn Observer,
    job: &Job<'_>,
) -> Summary {
    let started = Instant::now();
    let sizes: Vec<u64> = items.iter().map(|i| input_size(&i.input)).collect();
    // Largest first; ties in the given order.
    let mut order: Vec<usize> = (0..items.len()).collect();
    order.sort_by(|&a, &b| sizes[b].cmp(&sizes[a]).then(a.cmp(&b)));
    observer.begin(items.len(), sizes.iter().sum());
    let budget = Budget::new(scheduling.memory_budget.max(1));
    let next = AtomicUsize::new(0);
    let records: Vec<Mutex<Option<Record>>> = items.iter().map(|_| Mutex::new(None)).collect();
    // A folder no file can be written in fails every file at once, before any work.
    let unwritable = crate::output::check_writable(out_dir).err();
    let workers = scheduling.workers.clamp(1, items.len().max(1));
    let work = || {
        loop {
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(&index) = order.get(k) else { break };
            let item = &items[index];
            let output = out_dir.join(&item.relative_output);
            let record = if stop() {
                Record::new(&item.input, &output)
            } else if let Some(e) = &unwritable {
                let mut record = Record::new(&item.input, &output);
                record.fail(e);
                record
            } else {
                observer.started(item, sizes[index]);
                let record = job(item, &|bytes| budget.admit(bytes, stop));
                observer.finished(item, sizes[index], &record);
                record
            };
            *records[index].lock().unwrap_or_else(|e| e.into_inner()) = Some(record);
        }
    };
    if workers <= rayon::current_num_threads() {
        // Each worker is a thread of the stages' pool: a file's parallel loops then run on the
        // thread that bakes it and are stolen only by a thread with nothing else to do (one
        // whose worker is waiting for room, or has run out of files), instead of every loop
        // being handed from the worker to the pool and back. Measured on the shared models
        // (docs/catalog.md): less CPU for the same bytes.
        rayon::broadcast(|thread| {
            if thread.index() < workers {
                work();
            }
        });
    } else {
        std::thread::scope(|scope| {
            for _ in 0..workers {
                scope.spawn(work);
            }
        });
    }
    let files: Vec<Record> = records
        .into_iter()
        .zip(items)
        .map(|(r, item)| {
            r.into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .unwrap_or_else(|| Record::new(&item.input, &out_dir.join(&item.relative_output)))
        })
        .collect();
    let count = |s: Status| files.iter().filter(|r| r.status == s).count();
    Summary {
        baked: count(Status::Baked),
        drawn: None,
        cached: count(Status::Cached),
        failed: count(Status::Failed),
        skipped: count(Status::Skipped),
        wall_ms: started.elapsed().as_secs_f64() * 1e3,
        bytes_total: sizes.iter().sum(),
        memory_budget: scheduling.memory_budget,
        peak_admitted_bytes: budget.peak(),
        workers,
        over_budget: files.iter().filter(|r| r.over_budget).count(),
        build: crate::cache::BUILD_ID.to_owned(),
        config: serde_json::Value::Null,
        files,
    }
}

/// A file's size for ordering and progress: a .gltf's own bytes plus the external buffers it names.
pub(crate) fn input_size(path: &Path) -> u64 {
    let own = std::fs::metadata(path).map_or(0, |m| m.len());
    let is_gltf = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf"));
    if !is_gltf || own > 64 << 20 {
        return own;
    }
    let Ok(text) = std::fs::read(path) else { return own };
    let folder = path.parent().unwrap_or(Path::new(""));
    own + drafter_format::uri::file_uris(&text)
        .0
        .into_iter()
        .filter_map(|uri| drafter_format::uri::relative_path(&uri).ok())
        .map(|relative: PathBuf| std::fs::metadata(folder.join(relative)).map_or(0, |m| m.len()))
        .sum::<u64>()
}

/// A safe default budget: half the memory available now (`/proc/meminfo`), or 2 GiB where that
/// cannot be read.
pub fn default_memory_budget() -> u64 {
    let available = std::fs::read_to_string("/proc/meminfo").ok().and_then(|text| {
        let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib * 1024)
    });
    available.map_or(2 << 30, |a| a / 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn admission_never_exceeds_the_budget_and_a_large_request_runs_alone() {
        let budget = Budget::new(100);
        let never = || false;
        let running = std::sync::atomic::AtomicU64::new(0);
        let worst = std::sync::atomic::AtomicU64::new(0);
        let requests: Vec<u64> = (0..200).map(|i| [10, 35, 60, 150, 1][i % 5]).collect();
        let next = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..6 {
                s.spawn(|| {
                    while let Some(&bytes) = requests.get(next.fetch_add(1, Ordering::SeqCst)) {
                        let permit = budget.admit(bytes, &never).unwrap();
                        assert_eq!(permit.over_budget(), bytes > 100);
                        let now = running.fetch_add(permit.bytes, Ordering::SeqCst) + permit.bytes;
                        worst.fetch_max(now, Ordering::SeqCst);
                        std::thread::sleep(Duration::from_micros(200));
                        running.fetch_sub(permit.bytes, Ordering::SeqCst);
                    }
                });
            }
        });
        assert!(worst.load(Ordering::SeqCst) <= 100, "reserved at once");
        // The peak is of the estimates: the request over the whole budget ran alone, and the peak
        // says so rather than the budget it was held to.
        assert_eq!(budget.peak(), 150);
        // A stop request releases a waiter.
        let held = budget.admit(100, &never).unwrap();
        assert!(budget.admit(50, &|| true).is_none());
        drop(held);
        assert!(budget.admit(50, &never).is_some());
    }

    #[test]
    fn pool_threads_waiting_for_room_help_the_running_files_and_keep_the_budget() {
        // The batch's workers are the pool's threads: one waiting for room must neither exceed the
        // budget nor deadlock the parallel loops of the file that holds it.
        let pool = rayon::ThreadPoolBuilder::new().num_threads(3).build().unwrap();
        let budget = Budget::new(100);
        let never = || false;
        let running = std::sync::atomic::AtomicU64::new(0);
        let worst = std::sync::atomic::AtomicU64::new(0);
        let requests: Vec<u64> = (0..60).map(|i| [70, 40, 150, 10][i % 4]).collect();
        let next = AtomicUsize::new(0);
        let sums = Mutex::new(Vec::new());
        pool.broadcast(|_| {
            while let Some(&bytes) = requests.get(next.fetch_add(1, Ordering::SeqCst)) {
                let permit = budget.admit(bytes, &never).unwrap();
                let now = running.fetch_add(permit.bytes, Ordering::SeqCst) + permit.bytes;
                worst.fetch_max(now, Ordering::SeqCst);
                use rayon::prelude::*;
                let sum: u64 = (0..20_000u64).into_par_iter().map(|x| x * bytes).sum();
                sums.lock().unwrap().push((bytes, sum));
                running.fetch_sub(permit.bytes, Ordering::SeqCst);
            }
        });
        assert!(worst.load(Ordering::SeqCst) <= 100);
        let sums = sums.into_inner().unwrap();
        assert_eq!(sums.len(), requests.len());
        assert!(sums.iter().all(|&(bytes, sum)| sum == bytes * (20_000 * 19_999 / 2)));
    }
}
