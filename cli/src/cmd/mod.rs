//! One module per subcommand, each with `Args` (clap derive) and `run(Args) -> anyhow::Result<()>`.

pub mod bake;
pub mod batch;
pub mod bench;
pub mod bench_draw;
pub mod bench_silhouettes;
pub mod bench_sweep;
pub mod cache;
pub mod draw;
pub mod draw_batch;
pub mod inspect;
pub mod render;
pub mod sheet;
pub mod view;
pub mod web;

use std::io::Write;

/// `println!` for a command's output: a reader that stops early (`drafter inspect … | head`) ends
/// the command quietly (exit 0, see [`StdoutClosed`]) instead of panicking as `println!` does.
/// Use it in functions that return `anyhow::Result`.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cmd::write_line(format_args!($($arg)*))?
    };
}
pub(crate) use out;

/// Standard output was closed by its reader: the command stops, and that is not an error.
#[derive(Debug)]
pub struct StdoutClosed;

impl std::fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output closed")
    }
}

impl std::error::Error for StdoutClosed {}

/// Writes one line to standard output (what [`out!`] expands to).
pub fn write_line(args: std::fmt::Arguments) -> anyhow::Result<()> {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_fmt(args).and_then(|()| stdout.write_all(b"\n")) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(StdoutClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("writing to standard output")),
    }
}
