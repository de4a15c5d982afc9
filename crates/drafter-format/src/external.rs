//! The one place a baked .gltf's external buffer is resolved: the reader's functions take a loader
//! `Fn(uri) -> Option<bytes>`, and [`external_buffers`] is the loader every reader of baked files
//! (`drafter inspect`, the viewer) passes, so none of them joins URIs onto folders itself.
//!
//! The rule is the importer's, and so is the code: [`crate::uri::read_buffer_uri`] decodes `data:`
//! base64 URIs and follows relative references only inside the file's folder (the string checked,
//! the joined path canonicalized, symbolic links followed, and still inside the canonical folder).

use std::path::{Path, PathBuf};

/// The loader for the buffers of the glTF at `path` (a .glb needs none; passing this one is
/// harmless): a URI that is refused or cannot be read gives `None`, which the reader reports as a
/// buffer it cannot load.
pub fn external_buffers(path: &Path) -> impl Fn(&str) -> Option<Vec<u8>> + use<> {
    let folder = folder_of(path);
    move |uri: &str| crate::uri::read_buffer_uri(&folder, uri).ok()
}

/// The folder a file's relative URIs resolve against (`.` for a bare file name).
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("drafter-format-external-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch dir");
        dir
    }

    #[test]
    fn reads_inside_the_folder_and_refuses_the_rest() {
        let dir = scratch("confine");
        let inner = dir.join("model");
        std::fs::create_dir_all(inner.join("sub")).expect("dirs");
        std::fs::write(inner.join("a b.bin"), [1, 2]).expect("bin");
        std::fs::write(inner.join("sub/c.bin"), [3]).expect("bin");
        std::fs::write(dir.join("secret.bin"), [9]).expect("secret");
        let load = external_buffers(&inner.join("model.gltf"));
        assert_eq!(load("a%20b.bin"), Some(vec![1, 2]));
        assert_eq!(load("sub/c.bin"), Some(vec![3]));
        assert_eq!(load("data:application/octet-stream;base64,BAU="), Some(vec![4, 5]));
        for refused in ["../secret.bin", "%2e%2e/secret.bin", "file:///etc/passwd", "/etc/passwd", "missing.bin"] {
            assert_eq!(load(refused), None, "{refused}");
        }
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.join("secret.bin"), inner.join("link.bin")).expect("symlink");
            let refused = crate::uri::read_buffer_uri(&inner, "link.bin").expect_err("a link out of the folder");
            assert!(refused.contains("symbolic link"), "{refused}");
            std::os::unix::fs::symlink(inner.join("sub/c.bin"), inner.join("inner-link.bin")).expect("symlink");
            assert_eq!(load("inner-link.bin"), Some(vec![3]));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
