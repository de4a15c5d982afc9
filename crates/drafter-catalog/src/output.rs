//! Atomic writes: every file is written in full to a temporary file beside its target, synced,
//! then renamed over it, so a reader never sees a partial file and a failure (a full disk, a
//! signal: [`crate::interrupt`]) leaves every target as it was.

use std::io::Write;
use std::path::{Path, PathBuf};

use drafter_format::Container;

use crate::job::Error;

/// A file written in full beside its target, not yet renamed over it. Dropped before [`commit`],
/// it removes its temporary file (and a signal removes it too, see [`crate::interrupt`]).
#[derive(Debug)]
pub struct Staged {
    temp: PathBuf,
    target: PathBuf,
    _guard: crate::interrupt::TempFileGuard,
}

impl Staged {
    pub fn new(path: &Path, bytes: &[u8]) -> Result<Self, Error> {
        let folder = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let temp = folder.join(format!(".{name}.{}.tmp", std::process::id()));
        // A signal from here on removes the temporary file before the process exits.
        let staged = Self { _guard: crate::interrupt::TempFileGuard::new(&temp), temp, target: path.to_path_buf() };
        let written = (|| -> std::io::Result<()> {
            let mut file = std::fs::File::create(&staged.temp)?;
            file.write_all(bytes)?;
            file.sync_all()
        })();
        written.map_err(|e| Error::Io(format!("{}: cannot write: {e}", path.display())))?;
        Ok(staged)
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        // After a successful rename there is nothing left to remove.
        let _ = std::fs::remove_file(&self.temp);
    }
}

/// Renames every staged file over its target, in order; the ones not reached are removed.
pub fn commit(staged: Vec<Staged>) -> Result<(), Error> {
    for file in staged {
        std::fs::rename(&file.temp, &file.target)
            .map_err(|e| Error::Io(format!("{}: cannot write: {e}", file.target.display())))?;
    }
    Ok(())
}

/// Writes `bytes` to `path` atomically.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    commit(vec![Staged::new(path, bytes)?])
}

/// A bake's files: `extra` first (a report, textures), then a .gltf's .bin, then the main file,
/// all staged before any is renamed, so a failure in any of them leaves every target as it was.
pub fn write_outputs(
    output: &Path,
    main: &[u8],
    bin: Option<&[u8]>,
    container: &Container,
    extra: &[(PathBuf, &[u8])],
) -> Result<(), Error> {
    let mut staged = Vec::new();
    for (path, bytes) in extra {
        staged.push(Staged::new(path, bytes)?);
    }
    if let (Container::Gltf { bin_uri }, Some(bin)) = (container, bin) {
        staged.push(Staged::new(&output.with_file_name(bin_uri), bin)?);
    }
    staged.push(Staged::new(output, main)?);
    commit(staged)
}

/// The container an output path asks for: `.glb`, or `.gltf` with its `.bin` beside it.
pub fn container_for(output: &Path) -> Result<Container, Error> {
    let extension = output.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    match extension.as_str() {
        "glb" => Ok(Container::Glb),
        "gltf" => {
            let stem = output.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
            Ok(Container::Gltf { bin_uri: format!("{stem}.bin") })
        }
        _ => Err(Error::Input(format!("{}: output must end in .glb or .gltf", output.display()))),
    }
}
