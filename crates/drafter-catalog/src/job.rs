//! One file's bake, as `drafter bake`, the batch and the Python package all run it: import the
//! bytes within the limits, name the input in the config (file name, format, SHA-256), bake. The
//! three callers go through [`bake_bytes`], so their outputs are the same bytes by construction.

use std::path::Path;

use drafter_bake::{BakeConfig, BakeError, Baked};
use drafter_format::InputInfo;
use sha2::Digest;

/// Why one file could not be baked, by whose fault: the exit code follows from it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The input's content (a typed import error naming the file and the place).
    #[error(transparent)]
    Import(#[from] drafter_io::ImportError),
    /// The input or the options, past the importer: a config the bake refuses, a scene it cannot
    /// bake. The message names the file.
    #[error("{0}")]
    Input(String),
    /// A file could not be read or written for a reason outside its content (permission, disk).
    #[error("{0}")]
    Io(String),
    /// A bake stage failed where it should not: a bug.
    #[error(transparent)]
    Internal(BakeError),
}

/// Exit codes of `drafter` (documented in `drafter --help`).
pub mod exit {
    pub const INTERNAL: u8 = 1;
    pub const BAD_INPUT: u8 = 2;
    pub const IO_FAILURE: u8 = 3;
    /// A batch baked what it could, and at least one input failed.
    pub const SOME_FAILED: u8 = 4;
}

impl Error {
    /// The exit code a single bake ends with: 2 the input's fault (a missing input counts), 3 the
    /// system's, 1 ours.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Import(drafter_io::ImportError::Io { source, .. }) => {
                let users = matches!(source.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::IsADirectory);
                if users { exit::BAD_INPUT } else { exit::IO_FAILURE }
            }
            Error::Import(_) | Error::Input(_) => exit::BAD_INPUT,
            Error::Io(_) => exit::IO_FAILURE,
            Error::Internal(_) => exit::INTERNAL,
        }
    }

    /// Whether the input's content (with the configuration and limits) is at fault, so that the
    /// same input fails the same way again: import and bake refusals, not a file that could not be
    /// read.
    pub fn is_content_fault(&self) -> bool {
        match self {
            Error::Import(drafter_io::ImportError::Io { .. }) => false,
            Error::Import(_) | Error::Input(_) => true,
            Error::Io(_) | Error::Internal(_) => false,
        }
    }

    /// A word for reports: `input`, `io` or `internal`.
    pub fn kind(&self) -> &'static str {
        match self.exit_code() {
            exit::BAD_INPUT => "input",
            exit::IO_FAILURE => "io",
            _ => "internal",
        }
    }
}

/// Reads `path` whole (an unreadable input is an [`Error::Import`] of kind `Io`).
pub fn read_input(path: &Path) -> Result<Vec<u8>, Error> {
    std::fs::read(path).map_err(|source| drafter_io::ImportError::Io { path: path.to_path_buf(), source }.into())
}

/// Bakes `bytes`, read from `path` (which names the file in errors and in the output's provenance,
/// and resolves a glTF's external buffers and images), with `config` (whose `input` is replaced by
/// the file's) within `limits`. `on_stage(stage)` is called as each `drafter_bake::Stage`
/// starts. The caller's `bytes` are dropped after the import: the scene keeps what the writer
/// needs, and the bake's memory peaks later.
pub fn bake_bytes(
    path: &Path,
    bytes: Vec<u8>,
    config: &BakeConfig,
    limits: &drafter_io::Limits,
    on_stage: &mut dyn FnMut(drafter_bake::Stage),
) -> Result<Baked, Error> {
    // The input's digest (for the provenance) beside the import, on the thread pool.
    let (imported, digest) =
        rayon::join(|| drafter_io::import_bytes_within(path, &bytes, limits), || sha2::Sha256::digest(&bytes));
    let imported = imported?;
    drop(bytes);
    let mut config = config.clone();
    config.input = InputInfo {
        name: input_name(path),
        format: format!("{:?}", imported.scene.format).to_lowercase(),
        sha256: digest.iter().map(|b| format!("{b:02x}")).collect(),
    };
    let mut baked = drafter_bake::bake_observed(&imported.scene, &config, on_stage).map_err(|e| match e {
        BakeError::Config(_) | BakeError::Input(_) => Error::Input(format!("{}: {e}", path.display())),
        internal => Error::Internal(internal),
    })?;
    baked.report.diagnostics.extend(imported.diagnostics.iter().cloned());
    Ok(baked)
}

/// The name a bake records for the input at `path` (its file name).
pub fn input_name(path: &Path) -> String {
    path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

/// A config from TOML text on top of the defaults, as `--config` reads it, validated.
pub fn config_from_toml(text: &str) -> Result<BakeConfig, String> {
    validated(BakeConfig::from_toml(text))
}

/// A config from the same tables as JSON (Python's `config=` mapping), validated.
pub fn config_from_json(text: &str) -> Result<BakeConfig, String> {
    validated(BakeConfig::from_json(text))
}

fn validated(config: Result<BakeConfig, BakeError>) -> Result<BakeConfig, String> {
    let config = config.map_err(|e| e.to_string())?;
    config.validate().map_err(|e| e.to_string())?;
    Ok(config)
}
