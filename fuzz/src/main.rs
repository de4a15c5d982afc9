//! `drafter-fuzz`: runs a fuzzing campaign and prints its figures, or replays one file.
//!
//! ```text
//! cargo run --release -p drafter-fuzz -- --minutes 30 --threads 1 --out /tmp/findings
//! cargo run --release -p drafter-fuzz -- --cases 500 --target obj --target ply
//! cargo run --release -p drafter-fuzz -- --replay tests/regressions/gltf/x.gltf --target gltf
//! cargo run --release -p drafter-fuzz -- --case 14707 --target gltf --out /tmp/case
//! ```
//! Exit code: 0 without findings, 1 with findings, 2 for bad arguments.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::Context as _;
use clap::Parser;
use drafter_fuzz::campaign::{self, Options};
use drafter_fuzz::{Target, seeds};

#[derive(Debug, Parser)]
#[command(about = "Stable in-process mutation fuzzer of drafter's importers, bake, baked-file reader and viewer model")]
struct Args {
    /// Run for this many minutes (time split evenly across targets).
    #[arg(long, conflicts_with = "cases")]
    minutes: Option<f64>,
    /// Run this many cases per target (default 200 when --minutes is not given).
    #[arg(long)]
    cases: Option<u64>,
    /// Worker threads (also the size of rayon's pool for the bake inside a case).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// The campaign seed: the same seed gives the same cases.
    #[arg(long, default_value_t = 0x5eed)]
    seed: u64,
    /// Only these targets (repeatable; default: all).
    #[arg(long = "target", value_enum)]
    targets: Vec<Target>,
    /// Save findings here (`<out>/<target>/<kind>-<hash>.<ext>` and a `.txt` beside each).
    #[arg(long)]
    out: Option<PathBuf>,
    /// A case running longer than this is a finding.
    #[arg(long, default_value_t = 20.0)]
    time_budget_s: f64,
    /// A case raising peak RSS by more than this is a finding.
    #[arg(long, default_value_t = 1024)]
    memory_budget_mb: u64,
    /// Leave out seed files larger than this.
    #[arg(long, default_value_t = 1024)]
    max_seed_kb: usize,
    /// The repository root (samples/, and ../shared/models beside it).
    #[arg(long)]
    repo: Option<PathBuf>,
    /// Run this one file through the target given with --target and print the outcome.
    #[arg(long, requires = "targets")]
    replay: Option<PathBuf>,
    /// Make case N of the target given with --target (under --seed), run it and print the outcome;
    /// with --out, save its bytes there.
    #[arg(long, requires = "targets", conflicts_with = "replay")]
    case: Option<u64>,
}

fn main() -> ExitCode {
    let args = Args::parse();
    match run(args) {
        Ok(clean) => ExitCode::from(if clean { 0 } else { 1 }),
        Err(e) => {
            eprintln!("drafter-fuzz: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Whether the run found nothing.
fn run(args: Args) -> anyhow::Result<bool> {
    let targets = if args.targets.is_empty() { Target::ALL.to_vec() } else { args.targets.clone() };
    if let Some(file) = &args.replay {
        let bytes = std::fs::read(file).with_context(|| file.display().to_string())?;
        campaign::quiet_panics();
        let dir = std::env::temp_dir().join(format!("drafter-fuzz-replay-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let start = std::time::Instant::now();
        let outcome = drafter_fuzz::run_case(targets[0], &bytes, &dir);
        let _ = std::fs::remove_dir_all(&dir);
        println!("{}: {outcome:?} in {:.3} s", targets[0].name(), start.elapsed().as_secs_f64());
        return Ok(!outcome.is_finding());
    }
    let repo = args.repo.clone().unwrap_or_else(|| PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/..")));
    let corpus = seeds::corpus(&repo, args.max_seed_kb * 1024)?;
    if let Some(n) = args.case {
        let target = targets[0];
        let bytes = campaign::case_bytes(&corpus, target, args.seed, n);
        if let Some(out) = &args.out {
            std::fs::create_dir_all(out)?;
            let path = out.join(format!("case-{n}-{}", target.file_name()));
            std::fs::write(&path, &bytes).with_context(|| path.display().to_string())?;
            println!("saved {}", path.display());
        }
        campaign::quiet_panics();
        let dir = std::env::temp_dir().join(format!("drafter-fuzz-case-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let outcome = drafter_fuzz::run_case(target, &bytes, &dir);
        let _ = std::fs::remove_dir_all(&dir);
        println!("{} case {n}: {} bytes, {outcome:?}", target.name(), bytes.len());
        return Ok(!outcome.is_finding());
    }
    for target in &targets {
        eprintln!("seeds: {} {}", target.name(), corpus.of(*target).len());
    }
    let options = Options {
        seed: args.seed,
        cases_per_target: match args.minutes {
            Some(_) => None,
            None => Some(args.cases.unwrap_or(200)),
        },
        duration: args.minutes.map(|m| Duration::from_secs_f64(m * 60.0)),
        threads: args.threads.max(1),
        targets,
        time_budget: Duration::from_secs_f64(args.time_budget_s),
        memory_budget: args.memory_budget_mb << 20,
        out: args.out.clone(),
        verbose: true,
    };
    let report = campaign::run(&corpus, &options);
    print!("{}", report.table());
    for f in &report.findings {
        println!(
            "finding: {} {} case {}: {}{}",
            f.target.name(),
            f.kind.name(),
            f.case,
            f.message,
            f.saved.as_ref().map(|p| format!(" ({})", p.display())).unwrap_or_default()
        );
    }
    Ok(report.findings.is_empty())
}
