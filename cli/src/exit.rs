//! Mapping errors to exit codes: the input's fault (2) versus ours (1).

use std::process::ExitCode;

pub const INTERNAL: u8 = 1;
pub const BAD_INPUT: u8 = 2;

/// An error caused by the user's input or options (exit code 2), as opposed to a bug.
#[derive(Debug)]
pub struct BadInput(pub String);

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// Prints `err` as one line and picks the exit code.
pub fn report(err: &anyhow::Error) -> ExitCode {
    let bad_input = err.chain().any(|e| e.is::<drafter_io::ImportError>() || e.is::<BadInput>());
    // drafter_bake::BakeError::Internal stays an internal error (exit 1).
    // One line: the chain joined, newlines flattened.
    let message = err.chain().map(|e| e.to_string()).collect::<Vec<_>>().join(": ").replace('\n', " ");
    eprintln!("drafter: error: {message}");
    ExitCode::from(if bad_input { BAD_INPUT } else { INTERNAL })
}
