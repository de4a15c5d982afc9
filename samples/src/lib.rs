//! Generator of the small parametric CAD-like parts committed under `samples/`: an L-bracket, a spur gear, a
//! flanged shaft and an assembly of them, written as glTF 2.0 binaries.
//!
//! The parts are tessellated the way CAD exporters (OpenCascade, CadQuery) do it: one patch of vertices per
//! B-rep face, flat normals on planes, smooth normals inside curved faces, no vertex shared across a face
//! boundary, yet closed and consistently oriented once welded by position (see [`solid`]). That makes them
//! ground truth for the project's welding, crease, boundary and silhouette stages.
//!
//! The output is byte-for-byte deterministic, also across platforms: geometry is computed in f64 with the
//! portable trigonometry of [`detmath`] and rounded once to f32; triangulation has no hashing; the JSON is
//! written with sorted keys ([`glb`]).
//!
//! Code map: [`detmath`] (portable sin/cos/atan) → [`triangulate`] (planar faces with holes) → [`solid`] (the
//! face-by-face builder) → [`parts`] (parameter structs with defaults) → [`catalog`] (the documents) → [`glb`]
//! (the writer).

pub mod catalog;
pub mod detmath;
pub mod glb;
pub mod parts;
pub mod solid;
pub mod triangulate;

use std::fmt;
use std::path::{Path, PathBuf};

pub use catalog::{Sample, samples};

/// Why the samples could not be written.
#[derive(Debug)]
pub enum Error {
    /// A part could not be tessellated (a bug or bad parameters).
    Geometry(solid::GeometryError),
    /// A file could not be written.
    Io {
        /// The file.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Geometry(e) => write!(f, "tessellation failed: {e}"),
            Self::Io { path, source } => write!(f, "cannot write {}: {source}", path.display()),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Geometry(e) => Some(e),
            Self::Io { source, .. } => Some(source),
        }
    }
}

impl From<solid::GeometryError> for Error {
    fn from(e: solid::GeometryError) -> Self {
        Self::Geometry(e)
    }
}

/// Every sample's file name and GLB bytes, in a fixed order.
pub fn sample_files() -> Result<Vec<(&'static str, Vec<u8>)>, Error> {
    Ok(samples()?.into_iter().map(|s| (s.file_name, s.document.to_glb())).collect())
}

/// Writes every sample into `dir` (which must exist); returns the paths written and their sizes in bytes.
pub fn write_samples(dir: &Path) -> Result<Vec<(PathBuf, usize)>, Error> {
    let mut written = Vec::new();
    for (name, bytes) in sample_files()? {
        let path = dir.join(name);
        std::fs::write(&path, &bytes).map_err(|source| Error::Io { path: path.clone(), source })?;
        written.push((path, bytes.len()));
    }
    Ok(written)
}
