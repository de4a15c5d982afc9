//! Import errors: bad input (the user's file) versus I/O failures, each naming the file and the place.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Place {
    /// 1-based line number of a text format.
    Line(usize),
    /// Byte offset into a binary file.
    Byte(u64),
    /// A JSON pointer into a glTF document, e.g. `/accessors/3`.
    Json(String),
    /// The whole file (e.g. it is empty).
    File,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Line(n) => write!(f, "line {n}"),
            Place::Byte(b) => write!(f, "byte {b}"),
            Place::Json(p) => write!(f, "{p}"),
            Place::File => write!(f, "file"),
        }
    }
}

/// A problem located inside a file's content, before the file's path is attached.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    pub place: Place,
    pub message: String,
}

impl ParseError {
    pub fn new(place: Place, message: impl Into<String>) -> Self {
        Self { place, message: message.into() }
    }

    pub fn at_line(line: usize, message: impl Into<String>) -> Self {
        Self::new(Place::Line(line), message)
    }

    pub fn at_byte(offset: u64, message: impl Into<String>) -> Self {
        Self::new(Place::Byte(offset), message)
    }

    pub fn at_json(pointer: impl Into<String>, message: impl Into<String>) -> Self {
        Self::new(Place::Json(pointer.into()), message)
    }

    pub fn in_file(message: impl Into<String>) -> Self {
        Self::new(Place::File, message)
    }

    /// Attaches the file path.
    pub fn in_path(self, path: &Path) -> ImportError {
        ImportError::Invalid { path: path.to_path_buf(), place: self.place, message: self.message }
    }
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.place, self.message)
    }
}

/// Why a file could not be imported. Every variant is the input's fault or the file system's, never
/// a bug: a caller maps all of them to "bad input" (exit code 2 in the CLI).
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    #[error("{}: cannot read: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{}: {place}: {message}", path.display())]
    Invalid { path: PathBuf, place: Place, message: String },
    #[error("{}: unrecognised format ({reason}); supported: glTF 2.0 (.gltf, .glb), OBJ (.obj), STL (.stl, binary or ASCII), OFF (.off), PLY (.ply, ASCII or binary little-endian)", path.display())]
    UnsupportedFormat { path: PathBuf, reason: String },
}

impl ImportError {
    pub fn path(&self) -> &Path {
        match self {
            ImportError::Io { path, .. }
            | ImportError::Invalid { path, .. }
            | ImportError::UnsupportedFormat { path, .. } => path,
        }
    }
}
