//! What a batch bakes: files, folders (every file of a supported format, recursively) and
//! manifests, each with the output path that mirrors its relative path under the output folder.

use std::path::{Path, PathBuf};

/// One input of a batch and where its output goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Item {
    pub input: PathBuf,
    /// The input's path relative to what named it (its folder, the manifest's folder), with the
    /// extension replaced by `.glb`: the output's path under the output folder.
    pub relative_output: PathBuf,
}

/// Why the inputs could not be listed (bad input: exit 2).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct DiscoverError(pub String);

/// What a batch holds: the files to bake, and the folders below a named one that could not be
/// read (each a failure of the batch, not a reason to refuse the others).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Discovered {
    pub items: Vec<Item>,
    /// A folder found below an input folder, and why it could not be listed.
    pub unreadable: Vec<(PathBuf, String)>,
}

/// Lists the files to bake from `inputs` (files or folders) and `manifests`, in a stable order
/// (the order given; a folder's files sorted by path). `skip` is a folder never entered (the
/// output folder, when it lies inside an input folder). Two inputs whose outputs would be the same
/// file are refused, as is a path that does not exist. A folder below a named one that cannot be
/// read is refused too, by its own path; [`discover_all`] lists it instead.
pub fn discover(inputs: &[PathBuf], manifests: &[PathBuf], skip: Option<&Path>) -> Result<Vec<Item>, DiscoverError> {
    let found = discover_all(inputs, manifests, skip)?;
    match found.unreadable.first() {
        Some((folder, why)) => Err(DiscoverError(format!("{}: cannot list: {why}", folder.display()))),
        None => Ok(found.items),
    }
}

/// As [`discover`], with the unreadable folders below named ones listed rather than refused.
/// Every output path is relative, made of plain names only: a manifest's `../models` (a file or a
/// folder) is written as `models` under the output folder, an absolute entry by its file name or
/// below its folder, never above the output folder ([`crate::output::confined`] checks it again
/// where the file is written).
pub fn discover_all(
    inputs: &[PathBuf],
    manifests: &[PathBuf],
    skip: Option<&Path>,
) -> Result<Discovered, DiscoverError> {
    let skip = skip.and_then(|s| s.canonicalize().ok());
    let mut found = Discovered::default();
    let items = &mut found.items;
    let unreadable = &mut found.unreadable;
    for input in inputs {
        add(input, None, skip.as_deref(), items, unreadable)?;
    }
    for manifest in manifests {
        let text = std::fs::read_to_string(manifest)
            .map_err(|e| DiscoverError(format!("{}: cannot read manifest: {e}", manifest.display())))?;
        let base = manifest.parent().unwrap_or(Path::new(""));
        for (line, entry) in manifest_entries(manifest, &text)? {
            let path = base.join(&entry);
            let relative = (Path::new(&entry).is_relative()).then(|| PathBuf::from(&entry));
            add(&path, relative.as_deref(), skip.as_deref(), items, unreadable)
                .map_err(|e| DiscoverError(format!("{}:{line}: {e}", manifest.display())))?;
        }
    }
    let mut seen = std::collections::HashMap::new();
    for item in items.iter() {
        if let Some(first) = seen.insert(item.relative_output.clone(), item.input.clone()) {
            return Err(DiscoverError(format!(
                "{} and {} would both be written to {}; name them in separate runs or rename one",
                first.display(),
                item.input.display(),
                item.relative_output.display()
            )));
        }
    }
    Ok(found)
}

/// The entries of a manifest with their line numbers: a `.toml` file's `inputs = [...]`, or one
/// path per line (blank lines and lines starting with `#` skipped).
fn manifest_entries(path: &Path, text: &str) -> Result<Vec<(usize, String)>, DiscoverError> {
    let is_toml = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    if !is_toml {
        return Ok(text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
            .map(|(i, l)| (i, l.to_owned()))
            .collect());
    }
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Manifest {
        inputs: Vec<String>,
    }
    let manifest: Manifest = toml::from_str(text)
        .map_err(|e| DiscoverError(format!("{}: {}", path.display(), e.to_string().replace('\n', " "))))?;
    // A TOML array has no line of its own per entry: entries are numbered from 1 instead.
    Ok(manifest.inputs.into_iter().enumerate().map(|(i, s)| (i + 1, s)).collect())
}

fn add(
    path: &Path,
    relative: Option<&Path>,
    skip: Option<&Path>,
    items: &mut Vec<Item>,
    unreadable: &mut Vec<(PathBuf, String)>,
) -> Result<(), DiscoverError> {
    let meta = std::fs::metadata(path).map_err(|e| DiscoverError(format!("{}: {e}", path.display())))?;
    if meta.is_dir() {
        // The folder named is read here (its own failure refuses the batch); its subfolders by
        // `walk`, which lists the ones it cannot read.
        std::fs::read_dir(path).map_err(|e| DiscoverError(format!("{}: cannot list: {e}", path.display())))?;
        let mut files = Vec::new();
        walk(path, skip, &mut files, unreadable);
        files.sort();
        let prefix = relative.map(without_parent_steps).unwrap_or_default();
        for file in files {
            let below = file.strip_prefix(path).unwrap_or(&file);
            let relative_output = prefix.join(below).with_extension("glb");
            items.push(Item { input: file, relative_output });
        }
    } else {
        // A file named directly is baked whatever its extension (the importer decides).
        let relative =
            relative.map(Path::to_path_buf).unwrap_or_else(|| path.file_name().map(PathBuf::from).unwrap_or_default());
        items.push(Item {
            input: path.to_path_buf(),
            relative_output: without_parent_steps(&relative).with_extension("glb"),
        });
    }
    Ok(())
}

/// A manifest's `../x.obj` is written as `x.obj` under the output folder, never above it, and its
/// `../models` folder as `models`.
fn without_parent_steps(path: &Path) -> PathBuf {
    path.components().filter(|c| matches!(c, std::path::Component::Normal(_))).collect()
}

/// Every file of a supported format below `folder`: hidden files and folders (names starting with
/// `.`, such as a bake's temporary files) and `skip` are left out; symbolic links to folders are
/// not followed (no cycles). A folder that cannot be listed goes to `unreadable` with the reason.
fn walk(folder: &Path, skip: Option<&Path>, out: &mut Vec<PathBuf>, unreadable: &mut Vec<(PathBuf, String)>) {
    if skip.is_some_and(|s| folder.canonicalize().is_ok_and(|c| c == s)) {
        return;
    }
    let listed = (|| -> std::io::Result<Vec<(PathBuf, std::fs::FileType)>> {
        let mut entries = Vec::new();
        for entry in std::fs::read_dir(folder)? {
            let entry = entry?;
            if entry.file_name().to_string_lossy().starts_with('.') {
                continue;
            }
            entries.push((entry.path(), entry.file_type()?));
        }
        // Sorted, so that the unreadable folders are listed in the same order on every run.
        entries.sort_by(|a, b| a.0.cmp(&b.0));
        Ok(entries)
    })();
    let entries = match listed {
        Ok(entries) => entries,
        Err(e) => {
            unreadable.push((folder.to_path_buf(), e.to_string()));
            return;
        }
    };
    for (path, kind) in entries {
        if kind.is_dir() {
            walk(&path, skip, out, unreadable);
        } else if (kind.is_file() || kind.is_symlink() && path.is_file()) && is_supported(&path) {
            out.push(path);
        }
    }
}

/// Whether a folder's file is baked: its extension is one of the importers' (`drafter_io::EXTENSIONS`).
pub fn is_supported(path: &Path) -> bool {
    drafter_io::has_input_extension(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_mirror_manifests_resolve_and_collisions_are_refused() {
        let dir = std::env::temp_dir().join(format!("drafter-discover-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for file in ["in/a.obj", "in/sub/b.STL", "in/sub/c.txt", "in/.hidden.obj", "in/out/old.glb", "x.ply"] {
            let path = dir.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, b"x").unwrap();
        }
        let items = discover(&[dir.join("in")], &[], Some(&dir.join("in/out"))).unwrap();
        let outputs: Vec<_> = items.iter().map(|i| i.relative_output.clone()).collect();
        assert_eq!(outputs, [PathBuf::from("a.glb"), PathBuf::from("sub/b.glb")]);

        std::fs::write(dir.join("list.txt"), "# catalog\nin/sub\n\nx.ply\n").unwrap();
        let items = discover(&[], &[dir.join("list.txt")], None).unwrap();
        let outputs: Vec<_> = items.iter().map(|i| i.relative_output.clone()).collect();
        assert_eq!(outputs, [PathBuf::from("in/sub/b.glb"), PathBuf::from("x.glb")]);
        std::fs::write(dir.join("list.toml"), "inputs = [\"in/a.obj\", \"missing.obj\"]\n").unwrap();
        let err = discover(&[], &[dir.join("list.toml")], None).unwrap_err();
        assert!(err.0.contains("list.toml:2") && err.0.contains("missing.obj"), "{err}");

        std::fs::write(dir.join("in/a.stl"), b"x").unwrap();
        let err = discover(&[dir.join("in")], &[], Some(&dir.join("in/out"))).unwrap_err();
        assert!(err.0.contains("a.glb"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
