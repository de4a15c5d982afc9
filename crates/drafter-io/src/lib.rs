//! Importers into the drafter [`Scene`]: glTF 2.0 (.gltf, .glb), OBJ, STL (binary and ASCII), OFF and
//! PLY (ASCII and binary little-endian).
//!
//! The format is chosen by content first (glb magic, `ply`, `OFF`, a binary STL whose size matches
//! its triangle count, JSON) and by extension second. Every importer returns either a scene plus
//! diagnostics for what it recovered from, or an [`ImportError`] naming the file and the place.
//!
//! Invariants: no panic on any input; no allocation is sized by a count read from the file unless
//! the file's length can back it; a glTF's external URIs resolve only inside the file's folder.

mod error;
mod gltf_import;
mod obj;
mod off;
mod ply;
mod raw;
mod stl;

use std::path::Path;

use drafter_core::{Diagnostic, Diagnostics, Scene, SourceFormat};

pub use error::{ImportError, ParseError, Place};
pub use obj::{material_libraries as obj_material_libraries, open_material_library as open_obj_material_library};
pub use raw::RawMesh;

/// A successfully imported file.
#[derive(Debug)]
pub struct Imported {
    pub scene: Scene,
    /// Problems recovered from, aggregated by kind.
    pub diagnostics: Vec<Diagnostic>,
}

/// The file extensions of the formats drafter reads, each with the format it names, compared
/// without case (CAD tools write `.STL`). The content decides first ([`detect_format`]); the
/// extension decides for a file without a known signature, and a folder's files are chosen by it.
pub const EXTENSIONS: [(&str, SourceFormat); 6] = [
    ("gltf", SourceFormat::Gltf),
    ("glb", SourceFormat::Glb),
    ("obj", SourceFormat::Obj),
    ("stl", SourceFormat::Stl),
    ("off", SourceFormat::Off),
    ("ply", SourceFormat::Ply),
];

/// Whether `path`'s extension is one of [`EXTENSIONS`].
pub fn has_input_extension(path: &Path) -> bool {
    path.extension().is_some_and(|e| EXTENSIONS.iter().any(|(x, _)| e.eq_ignore_ascii_case(x)))
}

/// The most triangles an import takes by default ([`Limits::max_triangles`]): about 9 GB at the
/// peak of a bake (the dragon's bake peaks at 0.44 KB a triangle).
pub const DEFAULT_MAX_TRIANGLES: u64 = 20_000_000;

/// Bounds on what an import builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The most triangles over all meshes, counted as the file lists them (an instanced mesh
    /// once). A glTF can list the same accessors in any number of primitives, so a file of a few
    /// kilobytes can describe billions of triangles: those are counted from the accessors before
    /// any is read. The other formats hold every triangle they list.
    pub max_triangles: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits { max_triangles: DEFAULT_MAX_TRIANGLES }
    }
}

/// Reads `path`, choosing the format by content and extension.
pub fn import(path: &Path) -> Result<Imported, ImportError> {
    let bytes = std::fs::read(path).map_err(|source| ImportError::Io { path: path.to_path_buf(), source })?;
    import_bytes(path, &bytes)
}

/// Imports `bytes` that were read from `path`. The path names the file in errors, resolves a glTF's
/// external buffers and OBJ material libraries, and breaks ties in format detection.
pub fn import_bytes(path: &Path, bytes: &[u8]) -> Result<Imported, ImportError> {
    import_bytes_within(path, bytes, &Limits::default())
}

/// [`import_bytes`] within `limits`: a file that lists more is refused, naming the place where
/// the count passes the limit.
pub fn import_bytes_within(path: &Path, bytes: &[u8], limits: &Limits) -> Result<Imported, ImportError> {
    let format = detect_format(path, bytes)?;
    let mut diagnostics = Diagnostics::new();
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let scene = match format {
        SourceFormat::Glb => match drafter_format::meshopt::decompress_glb(bytes) {
            // EXT_meshopt_compression (drafter bake --compress, gltfpack -cc): the plain GLB.
            Ok(Some(plain)) => gltf_import::import(path, &plain, limits, &mut diagnostics)?,
            Ok(None) => gltf_import::import(path, bytes, limits, &mut diagnostics)?,
            Err(e) => return Err(ParseError::in_file(e.to_string()).in_path(path)),
        },
        SourceFormat::Gltf => gltf_import::import(path, bytes, limits, &mut diagnostics)?,
        SourceFormat::Obj => obj::import(path, bytes, &mut diagnostics)?,
        SourceFormat::Stl => raw_scene(path, stl::read(bytes), format, &name, &mut diagnostics)?,
        SourceFormat::Off => raw_scene(path, off::read(bytes), format, &name, &mut diagnostics)?,
        SourceFormat::Ply => raw_scene(path, ply::read(bytes), format, &name, &mut diagnostics)?,
    };
    // The text and STL formats hold every triangle they list, so this follows their parse.
    let triangles: u64 = scene.meshes.iter().map(|m| m.triangles.len() as u64).sum();
    if triangles > limits.max_triangles {
        return Err(over_limit(triangles, limits).in_path(path));
    }
    Ok(Imported { scene, diagnostics: diagnostics.into_vec() })
}

/// The error of a file that lists `triangles`, over `limits`.
fn over_limit(triangles: u64, limits: &Limits) -> ParseError {
    ParseError::in_file(format!(
        "{} triangles, more than the limit of {} (--max-triangles)",
        drafter_core::thousands(triangles.min(usize::MAX as u64) as usize),
        drafter_core::thousands(limits.max_triangles.min(usize::MAX as u64) as usize)
    ))
}

fn raw_scene(
    path: &Path,
    raw: Result<RawMesh, ParseError>,
    format: SourceFormat,
    name: &str,
    diagnostics: &mut Diagnostics,
) -> Result<Scene, ImportError> {
    raw.and_then(|raw| raw::single_mesh_scene(raw, format, name, diagnostics)).map_err(|e| e.in_path(path))
}

/// Decides the format of `bytes`, content first.
pub fn detect_format(path: &Path, bytes: &[u8]) -> Result<SourceFormat, ImportError> {
    let unsupported =
        |reason: &str| ImportError::UnsupportedFormat { path: path.to_path_buf(), reason: reason.to_owned() };
    if bytes.is_empty() {
        return Err(ParseError::in_file("empty file").in_path(path));
    }
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    if drafter_format::glb::is_glb(bytes) {
        return Ok(SourceFormat::Glb);
    }
    if bytes.starts_with(b"ply") {
        return Ok(SourceFormat::Ply);
    }
    if stl::is_binary(bytes) {
        return Ok(SourceFormat::Stl);
    }
    let text_start = trim_ascii_start(bytes);
    if text_start.starts_with(b"OFF") || text_start.starts_with(b"COFF") || text_start.starts_with(b"NOFF") {
        return Ok(SourceFormat::Off);
    }
    if text_start.starts_with(b"{") {
        return Ok(SourceFormat::Gltf);
    }
    if text_start.starts_with(b"solid") {
        return Ok(SourceFormat::Stl);
    }
    match EXTENSIONS.iter().find(|(x, _)| *x == extension) {
        Some(&(_, format)) => Ok(format),
        None if extension.is_empty() => Err(unsupported("no extension and no known signature")),
        None => Err(unsupported(&format!("extension .{extension} and no known signature"))),
    }
}

fn trim_ascii_start(bytes: &[u8]) -> &[u8] {
    let skip = bytes.iter().take_while(|b| b.is_ascii_whitespace()).count();
    &bytes[skip..]
}
