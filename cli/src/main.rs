//! `drafter`: bake technical 3D models into illustration-ready glTF, inspect them, render them.
//!
//! Exit codes: 0 success, 2 bad input (one line on stderr naming the file and the place), 3 a file
//! could not be read or written (disk full, permission denied, ...), 4 a batch in which some inputs
//! failed (the others were baked; the failures are listed), 1 internal error (a bug: please report
//! it); 130 / 143 after Ctrl-C / SIGTERM during a bake, which leaves no partial file.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

mod cmd;
mod exit;
mod gpu_env;

#[derive(Debug, Parser)]
#[command(
    name = "drafter",
    version,
    about = "Bake CAD assemblies and meshes into assets for technical illustration",
    after_help = "Exit codes: 0 success; 2 bad input (one line naming the file and the place); 3 a file could not be \
                  read or written (disk full, permission); 4 some inputs of a batch or a catalog of drawings failed \
                  (the others were baked or drawn, the failures are listed); 1 internal error (a bug). Ctrl-C or \
                  SIGTERM during a bake exits with 130 or 143 and leaves no partial file (a batch finishes the files \
                  it started first; a second signal exits at once)."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Bake a model into an extended glTF: parts, oriented boxes, projectors and gradients.
    Bake(cmd::bake::Args),
    /// The content-addressed cache of `bake --cache`: stats, clear, evict.
    Cache(cmd::cache::Args),
    /// Print what a file contains: parts, meshes, triangle counts, bounds and welded topology.
    Inspect(cmd::inspect::Args),
    /// Render a model headless to PNG in an illustration style (gradient, cel, gooch, metal, ...).
    Render(cmd::render::Args),
    /// Draw one view, or a sheet of views (--sheet A3), as vector lines (SVG, PDF, DXF): baked edges
    /// and silhouettes, hidden lines exact. Several inputs or a folder draw a catalog into -o DIR.
    Draw(cmd::draw::Args),
    /// Measure: `bench FILE` charts every stage's speed against accuracy; `bench render FILE` prints
    /// frame time per style as a ratio to phong.
    Bench(cmd::bench::Args),
    /// Show a model in a window: turn, zoom, pan, switch styles, take screenshots; select parts and
    /// edit their gradients (anchor, scale, direction, q/f/p), save them into the file (Ctrl+S) or
    /// export them as bake overrides (Ctrl+E).
    View(cmd::view::Args),
    /// Write a folder for any static host: the browser page (the viewer compiled to WebAssembly,
    /// built by scripts/web) and the model; orbit, styles, edges, lines, shadows in a browser.
    Web(cmd::web::Args),
}

fn main() -> ExitCode {
    // Parsing starts no thread; the heap policy is set before any other (see the modules' docs):
    // a batch bakes files side by side, so its threads get heaps of their own.
    let cli = Cli::parse();
    match &cli.command {
        Command::Bake(args) if cmd::bake::is_batch(args) => {
            let cores = std::thread::available_parallelism().map_or(1, usize::from);
            drafter_bake::heap::keep_freed_memory_in(2 * cores + args.jobs.unwrap_or(cores));
        }
        _ => drafter_bake::heap::keep_freed_memory(),
    }
    gpu_env::quiet_device_select();
    let result = std::panic::catch_unwind(|| match cli.command {
        Command::Bake(args) => cmd::bake::run(args),
        Command::Cache(args) => cmd::cache::run(args),
        Command::Inspect(args) => cmd::inspect::run(args),
        Command::Render(args) => cmd::render::run(args),
        Command::Draw(args) => cmd::draw::run(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::View(args) => cmd::view::run(args),
        Command::Web(args) => cmd::web::run(args),
    });
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        // The reader of our output stopped early (`| head`): not a failure.
        Ok(Err(err)) if err.is::<cmd::StdoutClosed>() => ExitCode::SUCCESS,
        Ok(Err(err)) => exit::report(&err),
        Err(_) => {
            eprintln!("drafter: internal error (a panic, reported above); this is a bug");
            ExitCode::from(exit::INTERNAL)
        }
    }
}
