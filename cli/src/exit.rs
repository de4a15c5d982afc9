//! Mapping errors to exit codes: the input's fault (2), the system's (3: reading or writing failed
//! for a reason other than the input's content, such as a full disk or a permission), or ours (1);
//! a batch in which some inputs failed ends with 4 (`drafter_catalog::exit`, where the codes live).

use std::process::ExitCode;

pub use drafter_catalog::exit::{BAD_INPUT, INTERNAL, IO_FAILURE, SOME_FAILED};

/// `drafter web` without the built browser page (`scripts/web` builds it).
pub const MISSING_PAGE: u8 = 5;

/// The browser page `drafter web` copies is not built (exit code 5).
#[derive(Debug)]
pub struct MissingPage(pub String);

impl std::fmt::Display for MissingPage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for MissingPage {}

/// An error caused by the user's input or options (exit code 2), as opposed to a bug.
#[derive(Debug)]
pub struct BadInput(pub String);

impl std::fmt::Display for BadInput {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BadInput {}

/// A file could not be read or written for a reason outside the input's content (exit code 3).
#[derive(Debug)]
pub struct IoFailure(pub String);

impl std::fmt::Display for IoFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for IoFailure {}

/// The exit code of `err`: 3 for I/O failures (an unreadable input counts, except one that does
/// not exist or is a folder, which is the user's to fix: 2), 2 for bad input, 1 otherwise.
pub fn code_of(err: &anyhow::Error) -> u8 {
    for e in err.chain() {
        if e.is::<crate::cmd::batch::SomeFailed>() {
            return SOME_FAILED;
        }
        if let Some(crate::cmd::batch::Interrupted(signal)) = e.downcast_ref() {
            return u8::try_from(128 + signal).unwrap_or(INTERNAL);
        }
        if let Some(e) = e.downcast_ref::<drafter_catalog::Error>() {
            return e.exit_code();
        }
        if e.is::<IoFailure>() {
            return IO_FAILURE;
        }
        if e.is::<MissingPage>() {
            return MISSING_PAGE;
        }
        if let Some(drafter_io::ImportError::Io { source, .. }) = e.downcast_ref::<drafter_io::ImportError>() {
            let users = matches!(source.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::IsADirectory);
            return if users { BAD_INPUT } else { IO_FAILURE };
        }
        if e.is::<drafter_io::ImportError>() || e.is::<BadInput>() {
            return BAD_INPUT;
        }
    }
    // drafter_bake::BakeError::Internal stays an internal error (exit 1).
    INTERNAL
}

/// The chain of `err` joined into one line, newlines flattened. A cause whose text its wrapper already
/// ends with (`ImportError::Io` prints its `std::io::Error`) is not repeated.
pub fn one_line(err: &anyhow::Error) -> String {
    let mut message = String::new();
    for text in err.chain().map(|e| e.to_string()) {
        if message.ends_with(&text) {
            continue;
        }
        if !message.is_empty() {
            message.push_str(": ");
        }
        message.push_str(&text);
    }
    message.replace('\n', " ")
}

/// Prints `err` as one line and picks the exit code.
pub fn report(err: &anyhow::Error) -> ExitCode {
    eprintln!("drafter: error: {}", one_line(err));
    ExitCode::from(code_of(err))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cause_the_message_already_names_is_not_repeated() {
        let path = std::path::PathBuf::from("missing.obj");
        let source = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file or directory (os error 2)");
        let err = anyhow::Error::new(drafter_io::ImportError::Io { path, source });
        assert_eq!(one_line(&err), "missing.obj: cannot read: No such file or directory (os error 2)");
        assert_eq!(code_of(&err), BAD_INPUT);
        let err = anyhow::anyhow!("first line\nsecond").context("writing out.glb");
        assert_eq!(one_line(&err), "writing out.glb: first line second");
    }
}
