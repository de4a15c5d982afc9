//! Atomic writes: every file is written in full to a temporary file beside its target, synced,
//! then renamed over it, so a reader never sees a partial file and a failure (a full disk, a
//! signal: [`crate::interrupt`]) leaves every target as it was. [`replace_in_place`] is the
//! editor's save (`drafter view`): the file keeps its mode and, where it can, its owner, and a file
//! the user cannot write is refused rather than replaced.

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

/// Saves `bytes` over an existing file as an editor does (`drafter view`'s `Ctrl`+`S` and
/// `Ctrl`+`E`), atomically: a symbolic link is followed (the link stays, its target is replaced);
/// a file without any write permission (mode 0444, even for root, as vim's read-only files) or one
/// this user cannot open for writing is refused and left as it was; otherwise the new bytes are
/// staged beside it, given the file's owner and group where the user may (root; a group the user
/// is in) and then its mode, and renamed over it. A path that does not exist yet is written as
/// [`write_atomically`] writes (the umask's mode). Off Unix the file's owner and mode are the
/// platform's business: the read-only flag is checked, the new file takes the folder's defaults.
pub fn replace_in_place(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let io = |what: &str, e: std::io::Error| Error::Io(format!("{}: {what}: {e}", path.display()));
    let target = match std::fs::canonicalize(path) {
        Ok(target) => target,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return write_atomically(path, bytes),
        Err(e) => return Err(io("cannot write", e)),
    };
    let metadata = std::fs::metadata(&target).map_err(|e| io("cannot write", e))?;
    if !metadata.is_file() {
        return Err(Error::Input(format!("{}: not a regular file; not replaced", path.display())));
    }
    if metadata.permissions().readonly() {
        #[cfg(unix)]
        let mode = format!(" (mode {:04o})", std::os::unix::fs::PermissionsExt::mode(&metadata.permissions()) & 0o7777);
        #[cfg(not(unix))]
        let mode = String::new();
        return Err(Error::Io(format!("{}: read-only{mode}; not replaced", path.display())));
    }
    // Opening for writing (no truncation, nothing written) asks the kernel what it would allow:
    // the mode bits, ACLs, a read-only mount.
    std::fs::OpenOptions::new().write(true).open(&target).map_err(|e| io("cannot write", e))?;
    let staged = Staged::new(&target, bytes)?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::{MetadataExt, PermissionsExt};
        // Owner first: a change of owner clears the set-id bits, which the mode then restores.
        if std::os::unix::fs::chown(&staged.temp, Some(metadata.uid()), Some(metadata.gid())).is_err() {
            let _ = std::os::unix::fs::chown(&staged.temp, None, Some(metadata.gid()));
        }
        let mode = metadata.permissions().mode() & 0o7777;
        std::fs::set_permissions(&staged.temp, std::fs::Permissions::from_mode(mode))
            .map_err(|e| io("cannot keep its mode", e))?;
    }
    commit(vec![staged])
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

/// The path of `relative` below the folder `root`, its folders created: the one way a batch (the
/// CLI's, `drafter.bake_many`, `drafter.ray`) names an output file, and the cache names its files.
/// Every component of `relative` must be a plain name (no `..`, `.`, root or drive), and no folder
/// between `root` and the file, nor the file itself, may be a symbolic link: a link inside the
/// output folder (left there by anyone) could lead a write out of it, so it is refused rather than
/// followed. `root` itself is the caller's choice and is taken as it is.
pub fn confined(root: &Path, relative: &Path) -> Result<PathBuf, Error> {
    use std::path::Component;
    let names: Vec<&std::ffi::OsStr> = relative
        .components()
        .map(|c| match c {
            Component::Normal(name) => Ok(name),
            _ => Err(Error::Input(format!(
                "{}: leaves the output folder {} (only plain names below it are written)",
                relative.display(),
                root.display()
            ))),
        })
        .collect::<Result<_, _>>()?;
    let Some((file, folders)) = names.split_last() else {
        return Err(Error::Input(format!("{}: an empty output name", root.display())));
    };
    let refuse = |path: &Path, what: &str| {
        Error::Io(format!("{}: {what} inside the output folder; not written", path.display()))
    };
    let mut path = root.to_path_buf();
    for name in folders {
        path.push(name);
        match std::fs::symlink_metadata(&path) {
            Ok(meta) if meta.file_type().is_symlink() => return Err(refuse(&path, "a symbolic link")),
            Ok(meta) if meta.is_dir() => {}
            Ok(_) => return Err(refuse(&path, "a file where a folder is needed")),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => match std::fs::create_dir(&path) {
                Ok(()) => {}
                // Another worker made it in between: checked again as above.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let meta =
                        std::fs::symlink_metadata(&path).map_err(|e| Error::Io(format!("{}: {e}", path.display())))?;
                    if !meta.is_dir() {
                        return Err(refuse(&path, "not a folder"));
                    }
                }
                Err(e) => return Err(Error::Io(format!("{}: cannot create: {e}", path.display()))),
            },
            Err(e) => return Err(Error::Io(format!("{}: {e}", path.display()))),
        }
    }
    path.push(file);
    match std::fs::symlink_metadata(&path) {
        Ok(meta) if meta.file_type().is_symlink() => Err(refuse(&path, "a symbolic link")),
        Ok(meta) if meta.is_dir() => Err(refuse(&path, "a folder where the output file goes")),
        _ => Ok(path),
    }
}

/// Whether files can be created in `folder`: a batch asks before baking anything, so that a
/// read-only output folder is one error at the start, not one per file after every bake.
pub fn check_writable(folder: &Path) -> Result<(), Error> {
    let probe = folder.join(format!(".drafter-write-check.{}.tmp", std::process::id()));
    let _guard = crate::interrupt::TempFileGuard::new(&probe);
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => Err(Error::Io(format!("{}: cannot write in the output folder: {e}", folder.display()))),
    }
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

#[cfg(test)]
mod tests {
    use std::os::unix::fs::PermissionsExt;

    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("drafter-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch");
        dir
    }

    fn mode(path: &Path) -> u32 {
        std::fs::metadata(path).expect("exists").permissions().mode() & 0o7777
    }

    fn set_mode(path: &Path, mode: u32) {
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode)).expect("chmod");
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        let names = std::fs::read_dir(dir).expect("dir").map(|e| e.expect("entry").file_name());
        names.map(|n| n.to_string_lossy().into_owned()).filter(|n| n.ends_with(".tmp")).collect()
    }

    #[test]
    fn a_save_keeps_the_files_mode_and_owner() {
        use std::os::unix::fs::MetadataExt;
        let dir = scratch("mode");
        for m in [0o600, 0o640, 0o664, 0o700] {
            let file = dir.join(format!("m{m:o}.glb"));
            std::fs::write(&file, b"before").expect("write");
            set_mode(&file, m);
            let owner = std::fs::metadata(&file).map(|m| (m.uid(), m.gid())).expect("stat");
            replace_in_place(&file, b"after").expect("saved");
            assert_eq!(std::fs::read(&file).expect("read"), b"after");
            assert_eq!(mode(&file), m, "mode {m:o} kept");
            assert_eq!(std::fs::metadata(&file).map(|m| (m.uid(), m.gid())).expect("stat"), owner);
        }
        // Through a symbolic link: the target is replaced, the link stays a link.
        let link = dir.join("link.glb");
        std::os::unix::fs::symlink("m600.glb", &link).expect("symlink");
        replace_in_place(&link, b"via the link").expect("saved");
        assert!(std::fs::symlink_metadata(&link).expect("lstat").file_type().is_symlink());
        assert_eq!(std::fs::read(dir.join("m600.glb")).expect("read"), b"via the link");
        assert_eq!(mode(&dir.join("m600.glb")), 0o600);
        // A new file (an export's first write) is simply written.
        replace_in_place(&dir.join("new.toml"), b"x").expect("written");
        assert_eq!(std::fs::read(dir.join("new.toml")).expect("read"), b"x");
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
        std::fs::remove_dir_all(&dir).expect("clean");
    }

    #[test]
    fn a_save_refuses_a_read_only_file_and_leaves_it_as_it_was() {
        let dir = scratch("read-only");
        let file = dir.join("locked.glb");
        std::fs::write(&file, b"before").expect("write");
        set_mode(&file, 0o444);
        // Refused even when the process could write it (root): the file says it is read-only.
        let err = replace_in_place(&file, b"after").expect_err("a read-only file is not replaced");
        assert!(err.to_string().contains("read-only (mode 0444)"), "{err}");
        assert_eq!(std::fs::read(&file).expect("read"), b"before");
        assert_eq!(mode(&file), 0o444);
        // Not a regular file: refused.
        let err = replace_in_place(&dir, b"x").expect_err("a folder is not replaced");
        assert!(err.to_string().contains("not a regular file"), "{err}");
        assert!(leftovers(&dir).is_empty(), "{:?}", leftovers(&dir));
        set_mode(&file, 0o644);
        std::fs::remove_dir_all(&dir).expect("clean");
    }
}
