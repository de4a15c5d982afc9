//! A campaign: cases spread over targets, run on worker threads, findings kept and saved.
//!
//! Scheduling gives every target the same share of time: a worker always takes the next case of the
//! target that has had the least busy time so far (in `--cases` mode, among those still short of
//! their count), so a slow target (a bake) gets fewer cases but as many CPU-seconds.
//!
//! A case is a finding when it panics, returns an internal error, takes longer than the time budget
//! (measured after it ends; a watchdog thread saves a case the moment it passes the budget, so a
//! hang leaves its input behind) or raises the process's peak RSS by more than the memory budget
//! (Linux: the high-water mark is reset before each case through `/proc/self/clear_refs` and read
//! after it from `/proc/self/status`; exact with one worker, shared between workers otherwise).

use std::any::Any;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use drafter_testkit::Rng;

use crate::seeds::Corpus;
use crate::{Outcome, Target, run_case};

/// How a campaign runs.
#[derive(Clone, Debug)]
pub struct Options {
    /// The campaign's seed: case `n` of a target is a function of it.
    pub seed: u64,
    /// Stop after this many cases per target (`None`: run until `duration`).
    pub cases_per_target: Option<u64>,
    /// Stop after this long (`None`: run until `cases_per_target`).
    pub duration: Option<Duration>,
    /// Worker threads (and rayon's pool size, which the bake uses inside a case).
    pub threads: usize,
    /// The targets to run.
    pub targets: Vec<Target>,
    /// A case running longer is a finding (20 s).
    pub time_budget: Duration,
    /// A case raising peak RSS by more is a finding (1 GB for inputs under 1 MB).
    pub memory_budget: u64,
    /// Where findings are saved (`<out>/<target>/<kind>-<hash>.<ext>` plus a `.txt`); `None` keeps
    /// them in memory only.
    pub out: Option<PathBuf>,
    /// Print one line per finding and a progress line per minute.
    pub verbose: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            seed: 0x5eed,
            cases_per_target: Some(100),
            duration: None,
            threads: 1,
            targets: Target::ALL.to_vec(),
            time_budget: Duration::from_secs(20),
            memory_budget: 1 << 30,
            out: None,
            verbose: false,
        }
    }
}

/// What kind of contract break a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Kind {
    Panic,
    Internal,
    Timeout,
    Memory,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Panic => "panic",
            Kind::Internal => "internal",
            Kind::Timeout => "timeout",
            Kind::Memory => "memory",
        }
    }
}

/// One case that broke the contract.
#[derive(Clone, Debug)]
pub struct Finding {
    pub target: Target,
    pub case: u64,
    pub kind: Kind,
    /// The panic message with its place, the error, or the time or memory measured.
    pub message: String,
    pub bytes: Arc<Vec<u8>>,
    /// Where it was saved, if it was.
    pub saved: Option<PathBuf>,
}

/// Per-target figures.
#[derive(Clone, Debug, Default)]
pub struct TargetStats {
    pub cases: u64,
    pub accepted: u64,
    pub rejected: u64,
    pub findings: u64,
    /// Wall time spent in this target's cases (CPU time with one worker).
    pub busy: Duration,
    pub slowest: Duration,
    /// The largest rise of peak RSS over the RSS before a case, in bytes.
    pub max_peak_growth: u64,
}

impl TargetStats {
    pub fn exec_per_s(&self) -> f64 {
        self.cases as f64 / self.busy.as_secs_f64().max(1e-9)
    }
}

/// A campaign's result.
#[derive(Clone, Debug, Default)]
pub struct Report {
    pub stats: BTreeMap<Target, TargetStats>,
    pub findings: Vec<Finding>,
    pub elapsed: Duration,
    /// The process's RSS after the seeds were loaded and at the end (bytes; 0 off Linux).
    pub rss_start: u64,
    pub rss_end: u64,
    /// The highest peak RSS seen by any case (bytes).
    pub peak_rss: u64,
}

impl Report {
    pub fn cases(&self) -> u64 {
        self.stats.values().map(|s| s.cases).sum()
    }

    /// Figures as a table, one line per target and a total.
    pub fn table(&self) -> String {
        let mut s = format!(
            "{:<11} {:>9} {:>9} {:>9} {:>8} {:>8} {:>9} {:>11} {:>10}\n",
            "target", "cases", "accepted", "rejected", "findings", "cpu_s", "exec/s", "slowest_ms", "peak+MB"
        );
        for (target, t) in &self.stats {
            s += &format!(
                "{:<11} {:>9} {:>9} {:>9} {:>8} {:>8.1} {:>9.1} {:>11.1} {:>10.1}\n",
                target.name(),
                t.cases,
                t.accepted,
                t.rejected,
                t.findings,
                t.busy.as_secs_f64(),
                t.exec_per_s(),
                t.slowest.as_secs_f64() * 1e3,
                t.max_peak_growth as f64 / (1 << 20) as f64
            );
        }
        s += &format!(
            "total: {} cases in {:.1} s ({:.1} exec/s), {} findings; RSS {:.0} MB at start, {:.0} MB at end, peak {:.0} MB\n",
            self.cases(),
            self.elapsed.as_secs_f64(),
            self.cases() as f64 / self.elapsed.as_secs_f64().max(1e-9),
            self.findings.len(),
            self.rss_start as f64 / (1 << 20) as f64,
            self.rss_end as f64 / (1 << 20) as f64,
            self.peak_rss as f64 / (1 << 20) as f64,
        );
        s
    }
}

/// The bytes of case `n` of `target` under `seed`: case `n < seeds` is seed `n` unchanged (every
/// seed must be accepted), later cases mutate a seed picked by the case's own generator.
pub fn case_bytes(corpus: &Corpus, target: Target, seed: u64, n: u64) -> Vec<u8> {
    let seeds = corpus.of(target);
    if seeds.is_empty() {
        return Vec::new();
    }
    if (n as usize) < seeds.len() {
        return seeds[n as usize].bytes.clone();
    }
    let mut rng = case_rng(seed, target, n);
    let base = &seeds[rng.below(seeds.len() as u64) as usize].bytes;
    let other = &seeds[rng.below(seeds.len() as u64) as usize].bytes;
    crate::mutate::mutate(target, base, other, &mut rng)
}

fn case_rng(seed: u64, target: Target, n: u64) -> Rng {
    let mut mix = Rng::new(seed ^ (target as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let salt = mix.next_u64();
    Rng::new(salt ^ n.wrapping_mul(0xd1b5_4a32_d192_ed03))
}

/// The case a worker is running, for the watchdog.
#[derive(Debug)]
struct InFlight {
    target: Target,
    case: u64,
    bytes: Arc<Vec<u8>>,
    started: Instant,
    reported: bool,
}

#[derive(Debug)]
struct Shared {
    stats: BTreeMap<Target, TargetStats>,
    /// Cases started per target.
    next_case: BTreeMap<Target, u64>,
    findings: Vec<Finding>,
    /// Findings saved per (target, kind, message): at most [`SAVED_PER_SIGNATURE`] inputs each.
    signatures: BTreeMap<(Target, Kind, String), u64>,
    peak_rss: u64,
}

const SAVED_PER_SIGNATURE: u64 = 3;

/// Runs a campaign over `corpus`. Panics are silenced for its duration ([`quiet_panics`]).
pub fn run(corpus: &Corpus, options: &Options) -> Report {
    quiet_panics();
    let scratch = std::env::temp_dir().join(format!("drafter-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&scratch);
    let start = Instant::now();
    let rss_start = rss_bytes("VmRSS");
    let shared = Arc::new(Mutex::new(Shared {
        stats: options.targets.iter().map(|&t| (t, TargetStats::default())).collect(),
        next_case: options.targets.iter().map(|&t| (t, 0)).collect(),
        findings: Vec::new(),
        signatures: BTreeMap::new(),
        peak_rss: 0,
    }));
    let in_flight: Arc<Mutex<Vec<Option<InFlight>>>> =
        Arc::new(Mutex::new((0..options.threads.max(1)).map(|_| None).collect()));
    let done = Arc::new(AtomicBool::new(false));

    // The bake inside a case runs on rayon's global pool: as many threads as workers (the first
    // campaign of a process sets it; rayon allows that once).
    let _ = rayon::ThreadPoolBuilder::new().num_threads(options.threads.max(1)).build_global();
    let watchdog = {
        let (in_flight, shared, done, options) = (in_flight.clone(), shared.clone(), done.clone(), options.clone());
        std::thread::spawn(move || watch(&in_flight, &shared, &done, &options, start))
    };
    let work = |worker: usize| {
        while let Some((target, n)) = next_case(&shared, options, start) {
            let bytes = Arc::new(case_bytes(corpus, target, options.seed, n));
            if let Ok(mut slots) = in_flight.lock() {
                slots[worker] =
                    Some(InFlight { target, case: n, bytes: bytes.clone(), started: Instant::now(), reported: false });
            }
            reset_peak();
            let rss_before = rss_bytes("VmRSS");
            let case_start = Instant::now();
            let outcome = run_case(target, &bytes, &scratch);
            let elapsed = case_start.elapsed();
            let peak = rss_bytes("VmHWM");
            let timed_out_reported =
                in_flight.lock().ok().and_then(|mut slots| slots[worker].take()).is_some_and(|f| f.reported);
            let growth = peak.saturating_sub(rss_before);
            let mut found = Vec::new();
            match &outcome {
                Outcome::Panic(m) => found.push((Kind::Panic, m.clone())),
                Outcome::Internal(m) => found.push((Kind::Internal, m.clone())),
                Outcome::Accepted | Outcome::Rejected(_) => {}
            }
            if elapsed > options.time_budget && !timed_out_reported {
                found.push((Kind::Timeout, format!("{:.1} s", elapsed.as_secs_f64())));
            }
            if growth > options.memory_budget {
                found.push((Kind::Memory, format!("peak RSS +{} MB", growth >> 20)));
            }
            let Ok(mut s) = shared.lock() else { break };
            s.peak_rss = s.peak_rss.max(peak);
            let stats = s.stats.entry(target).or_default();
            stats.cases += 1;
            stats.busy += elapsed;
            stats.slowest = stats.slowest.max(elapsed);
            stats.max_peak_growth = stats.max_peak_growth.max(growth);
            match outcome {
                Outcome::Accepted => stats.accepted += 1,
                Outcome::Rejected(_) => stats.rejected += 1,
                _ => {}
            }
            for (kind, message) in found {
                record(&mut s, options, Finding { target, case: n, kind, message, bytes: bytes.clone(), saved: None });
            }
        }
    };
    std::thread::scope(|scope| {
        for worker in 0..options.threads.max(1) {
            let work = &work;
            scope.spawn(move || work(worker));
        }
    });
    done.store(true, Ordering::Relaxed);
    let _ = watchdog.join();
    let _ = std::fs::remove_dir_all(&scratch);
    let shared = Arc::try_unwrap(shared).ok().and_then(|m| m.into_inner().ok());
    let (stats, findings, peak_rss) = shared.map(|s| (s.stats, s.findings, s.peak_rss)).unwrap_or_default();
    Report { stats, findings, elapsed: start.elapsed(), rss_start, rss_end: rss_bytes("VmRSS"), peak_rss }
}

/// The next (target, case) to run, or `None` when the campaign is over.
fn next_case(shared: &Mutex<Shared>, options: &Options, start: Instant) -> Option<(Target, u64)> {
    if options.duration.is_some_and(|d| start.elapsed() >= d) {
        return None;
    }
    let mut s = shared.lock().ok()?;
    let limit = options.cases_per_target.unwrap_or(u64::MAX);
    let target = options
        .targets
        .iter()
        .copied()
        .filter(|t| s.next_case.get(t).copied().unwrap_or(0) < limit)
        .min_by_key(|t| (s.stats.get(t).map(|st| st.busy).unwrap_or_default(), *t))?;
    let n = s.next_case.entry(target).or_default();
    let case = *n;
    *n += 1;
    Some((target, case))
}

fn record(s: &mut Shared, options: &Options, mut finding: Finding) {
    if let Some(stats) = s.stats.get_mut(&finding.target) {
        stats.findings += 1;
    }
    let signature = (finding.target, finding.kind, signature_of(&finding.message));
    let seen = s.signatures.entry(signature).or_default();
    *seen += 1;
    if *seen <= SAVED_PER_SIGNATURE {
        if let Some(out) = &options.out {
            finding.saved = save(out, &finding, options.seed).ok();
        }
        if options.verbose {
            eprintln!(
                "finding: {} {} case {}: {}{}",
                finding.target.name(),
                finding.kind.name(),
                finding.case,
                finding.message,
                finding.saved.as_ref().map(|p| format!(" -> {}", p.display())).unwrap_or_default()
            );
        }
    }
    s.findings.push(finding);
}

/// The message without numbers, so that one bug seen with many lengths counts once.
fn signature_of(message: &str) -> String {
    let mut s: String = message.chars().map(|c| if c.is_ascii_digit() { '#' } else { c }).collect();
    s.truncate(200);
    s
}

/// Saves the input and a `.txt` with the message and how to replay it.
fn save(out: &Path, finding: &Finding, seed: u64) -> std::io::Result<PathBuf> {
    let dir = out.join(finding.target.name());
    std::fs::create_dir_all(&dir)?;
    let ext = Path::new(finding.target.file_name()).extension().unwrap_or_default().to_string_lossy().into_owned();
    let path = dir.join(format!("{}-{:016x}.{ext}", finding.kind.name(), fnv1a(&finding.bytes)));
    std::fs::write(&path, finding.bytes.as_slice())?;
    let note = format!(
        "target: {}\nkind: {}\ncase: {} (seed {seed:#x})\nmessage: {}\nreplay: cargo run --release -p drafter-fuzz -- --replay {} --target {}\n",
        finding.target.name(),
        finding.kind.name(),
        finding.case,
        finding.message,
        path.display(),
        finding.target.name(),
    );
    std::fs::write(path.with_extension(format!("{ext}.txt")), note)?;
    Ok(path)
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3))
}

/// Every 100 ms: saves a case that passes the time budget (once), and the running cases when the
/// process's RSS passes the memory budget over its start; prints progress once a minute.
fn watch(
    in_flight: &Mutex<Vec<Option<InFlight>>>,
    shared: &Mutex<Shared>,
    done: &AtomicBool,
    options: &Options,
    start: Instant,
) {
    let rss_start = rss_bytes("VmRSS");
    let mut last_progress = Instant::now();
    let mut memory_reported = false;
    while !done.load(Ordering::Relaxed) {
        std::thread::sleep(Duration::from_millis(100));
        let rss = rss_bytes("VmRSS");
        let mut late = Vec::new();
        if let Ok(mut slots) = in_flight.lock() {
            for f in slots.iter_mut().flatten() {
                if !f.reported && f.started.elapsed() > options.time_budget {
                    f.reported = true;
                    late.push((
                        f.target,
                        f.case,
                        f.bytes.clone(),
                        Kind::Timeout,
                        format!("still running after {:.0} s", f.started.elapsed().as_secs_f64()),
                    ));
                }
                if !memory_reported && rss.saturating_sub(rss_start) > options.memory_budget {
                    late.push((
                        f.target,
                        f.case,
                        f.bytes.clone(),
                        Kind::Memory,
                        format!("RSS {} MB while running", rss >> 20),
                    ));
                }
            }
        }
        if !late.is_empty() {
            memory_reported |= late.iter().any(|l| l.3 == Kind::Memory);
            if let Ok(mut s) = shared.lock() {
                for (target, case, bytes, kind, message) in late {
                    record(&mut s, options, Finding { target, case, kind, message, bytes, saved: None });
                }
            }
        }
        if options.verbose && last_progress.elapsed() >= Duration::from_secs(60) {
            last_progress = Instant::now();
            if let Ok(s) = shared.lock() {
                let cases: u64 = s.stats.values().map(|t| t.cases).sum();
                let per_target: Vec<String> = s
                    .stats
                    .iter()
                    .map(|(t, st)| format!("{} {}/{:.0}s", t.name(), st.cases, st.busy.as_secs_f64()))
                    .collect();
                eprintln!(
                    "progress: {:.0} s, {cases} cases, {} findings, RSS {} MB ({})",
                    start.elapsed().as_secs_f64(),
                    s.findings.len(),
                    rss >> 20,
                    per_target.join(", ")
                );
            }
        }
    }
}

/// A `/proc/self/status` figure in bytes (`VmRSS`, `VmHWM`); 0 where there is none.
pub fn rss_bytes(field: &str) -> u64 {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else { return 0 };
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

/// Resets the process's peak RSS (`VmHWM`) to its current RSS (Linux 4.0+; a no-op elsewhere).
pub fn reset_peak() {
    let _ = std::fs::write("/proc/self/clear_refs", "5");
}

thread_local! {
    static LAST_PANIC: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Installs a panic hook that prints nothing and keeps the message and place for
/// [`take_panic_message`] (once per process; later calls do nothing).
pub fn quiet_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        std::panic::set_hook(Box::new(|info| {
            let message = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(no message)".into());
            let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
            LAST_PANIC.with(|p| *p.borrow_mut() = Some(format!("{message}{place}")));
        }));
    });
}

/// The message of the panic just caught on this thread: the hook's, with its place, else the
/// payload's.
pub fn take_panic_message(payload: &(dyn Any + Send)) -> String {
    LAST_PANIC.with(|p| p.borrow_mut().take()).unwrap_or_else(|| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".into())
    })
}
