//! `drafter cache stats|clear|evict --cache DIR`: what the content-addressed cache of `drafter bake
//! --cache` holds, and its upkeep (`drafter_catalog::cache`).

use std::path::PathBuf;

use anyhow::Result;
use drafter_catalog::cache::Cache;

use crate::cmd::out;
use crate::exit::{BadInput, IoFailure};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub action: Action,
    /// The cache folder.
    #[arg(long, value_name = "DIR", env = "DRAFTER_CACHE", global = true)]
    pub cache: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long, global = true)]
    pub json: bool,
}

#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Entries, bytes, temporary files, and how long ago entries were used.
    Stats,
    /// Remove every entry.
    Clear,
    /// Remove the least recently used entries until the cache holds at most SIZE (e.g. 10G), and
    /// temporary files older than an hour.
    Evict {
        #[arg(value_parser = crate::cmd::bake::parse_size)]
        size: u64,
    },
}

pub fn run(args: Args) -> Result<()> {
    let dir = args.cache.ok_or_else(|| BadInput("name the cache with --cache DIR or DRAFTER_CACHE".into()))?;
    if !dir.join("entries").is_dir() {
        return Err(BadInput(format!("{}: is not a drafter cache (no entries/ folder)", dir.display())).into());
    }
    let io = |e: std::io::Error| IoFailure(format!("{}: {e}", dir.display()));
    match args.action {
        Action::Stats => {
            let stats = Cache::open(&dir, None).map_err(io)?.stats();
            if args.json {
                out!("{}", serde_json::to_string_pretty(&stats)?);
            } else {
                let age = |s: Option<u64>| s.map_or("-".to_owned(), |s| format!("{s} s ago"));
                out!(
                    "{}: {} entries, {} bytes ({:.1} MB), {} temporary files; least recently used {}, most recently {}",
                    dir.display(),
                    stats.entries,
                    stats.bytes,
                    stats.bytes as f64 / 1e6,
                    stats.temporary_files,
                    age(stats.oldest_use_s),
                    age(stats.newest_use_s)
                );
            }
        }
        Action::Clear => {
            let removed = Cache::open(&dir, None).map_err(io)?.clear().map_err(io)?;
            out!("{}: removed {removed} entries", dir.display());
        }
        Action::Evict { size } => {
            let evicted = Cache::open(&dir, Some(size)).map_err(io)?.evict();
            if args.json {
                out!("{}", serde_json::to_string_pretty(&evicted)?);
            } else {
                out!(
                    "{}: evicted {} entries ({} bytes) and {} stale temporary files",
                    dir.display(),
                    evicted.entries,
                    evicted.bytes,
                    evicted.stale_temporary_files
                );
            }
        }
    }
    Ok(())
}
