//! Which glTF buffer URIs drafter follows, decided once for the importer (drafter-io) and the
//! reader of baked files (drafter-format): a `data:` URI with a base64 payload, or a relative
//! reference that stays inside the glTF's folder — no scheme, no absolute path or drive, no `..`,
//! also not when spelled with percent escapes (`%2e%2e/`) or backslashes. Anything else is refused
//! with a message naming the URI.
//!
//! [`resolve`] only looks at the string. [`resolve_buffer_uri`] and [`read_buffer_uri`], which the
//! importer, the readers of baked files and the batch cache's key all use, also canonicalize the
//! joined path and check it is still inside the folder ([`inside`]), which catches symbolic links
//! leading out of it.

use std::path::{Component, Path, PathBuf};

use base64::Engine as _;

/// What a buffer URI refers to, once accepted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum UriTarget {
    /// The decoded payload of a `data:…;base64,` URI.
    Data(Vec<u8>),
    /// A path relative to the glTF's folder, percent escapes decoded, `/` as separator.
    Relative(PathBuf),
}

/// Accepts a `data:` URI (base64 only, decoded here) or a relative reference inside the file's
/// folder (see [`relative_path`]).
pub fn resolve(uri: &str) -> Result<UriTarget, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("data URI is not base64".into());
        };
        return base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map(UriTarget::Data)
            .map_err(|e| format!("bad base64 in data URI: {e}"));
    }
    relative_path(uri).map(UriTarget::Relative)
}

/// Accepts only a relative reference that stays inside the glTF's folder: no scheme, no absolute
/// path or drive, no `..` (checked after percent decoding and with `\` read as a separator).
pub fn relative_path(uri: &str) -> Result<PathBuf, String> {
    let decoded = percent_decode(uri).ok_or_else(|| format!("URI {uri:?} has a bad percent escape"))?;
    if let Some(colon) = decoded.find(':') {
        let before = &decoded[..colon];
        if !before.contains('/') {
            return Err(format!("URI {uri:?} has a scheme; only relative paths and data: URIs are allowed"));
        }
    }
    if decoded.starts_with('/') || decoded.starts_with('\\') {
        return Err(format!("URI {uri:?} is an absolute path; only paths inside the file's folder are allowed"));
    }
    let normalised = decoded.replace('\\', "/");
    let path = PathBuf::from(&normalised);
    for component in path.components() {
        match component {
            Component::Normal(_) | Component::CurDir => {}
            _ => return Err(format!("URI {uri:?} leaves the file's folder; only paths inside it are allowed")),
        }
    }
    Ok(path)
}

/// Whether `canonical_target` lies inside `canonical_folder` (both already canonicalized by the
/// caller, symbolic links followed): the last check before a relative URI's file is read.
pub fn inside(canonical_folder: &Path, canonical_target: &Path) -> bool {
    canonical_target.starts_with(canonical_folder) && canonical_target != canonical_folder
}

fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// What a glTF buffer or image URI refers to: the bytes of a data URI, or a file.
#[derive(Debug)]
pub enum UriSource {
    Data(Vec<u8>),
    /// A file inside the glTF's folder: its canonical path, and the path the URI gives (for
    /// messages).
    File {
        path: std::path::PathBuf,
        relative: std::path::PathBuf,
    },
}

/// What a glTF buffer URI refers to, for a glTF in `folder`, or why it is refused: the rule of
/// what may be followed is drafter-core's (`drafter_format::uri`); the joined path is then
/// canonicalized and must stay inside the canonical folder, so a symbolic link cannot lead out of
/// it either. [`read_buffer_uri`] reads what this resolves; the cache's key hashes the file
/// without reading it into memory.
pub fn resolve_buffer_uri(folder: &Path, uri: &str) -> Result<UriSource, String> {
    let relative = match resolve(uri)? {
        UriTarget::Data(bytes) => return Ok(UriSource::Data(bytes)),
        UriTarget::Relative(relative) => relative,
    };
    let unreadable = |e: std::io::Error| format!("cannot read file {}: {e}", relative.display());
    let folder = if folder.as_os_str().is_empty() { Path::new(".") } else { folder };
    let canonical_folder = folder.canonicalize().map_err(unreadable)?;
    let canonical = folder.join(&relative).canonicalize().map_err(unreadable)?;
    if canonical.is_dir() {
        return Err(format!("URI {uri:?} names a folder, not a file"));
    }
    if !inside(&canonical_folder, &canonical) {
        return Err(format!("URI {uri:?} leads out of the file's folder (through a symbolic link)"));
    }
    Ok(UriSource::File { path: canonical, relative })
}

/// The bytes a glTF buffer URI refers to, for a glTF in `folder`, or why it is refused
/// ([`resolve_buffer_uri`]'s rule). The importer (drafter-io) and the loader of baked files
/// ([`crate::external_buffers`]) both call this, so they follow the same URIs.
pub fn read_buffer_uri(folder: &Path, uri: &str) -> Result<Vec<u8>, String> {
    match resolve_buffer_uri(folder, uri)? {
        UriSource::Data(bytes) => Ok(bytes),
        UriSource::File { path, relative } => {
            std::fs::read(&path).map_err(|e| format!("cannot read file {}: {e}", relative.display()))
        }
    }
}

/// The buffer and image URIs of a glTF's JSON that name files (not data URIs), in document order.
/// Only these members are decoded (the rest of the document is skipped, not built), since a batch
/// reads them for every glTF it is given (the cache's key, the batch's sizes, `bake`'s check that
/// the output is none of the input's files). Empty for anything that is not such a JSON object.
pub fn file_uris(json: &[u8]) -> (Vec<String>, Vec<String>) {
    #[derive(serde::Deserialize)]
    struct Document {
        #[serde(default)]
        buffers: Vec<Item>,
        #[serde(default)]
        images: Vec<Item>,
    }
    #[derive(serde::Deserialize)]
    struct Item {
        #[serde(default)]
        uri: Option<String>,
    }
    let start = json.iter().position(|b| !b.is_ascii_whitespace());
    if start.is_none_or(|i| json[i] != b'{') {
        return (Vec::new(), Vec::new());
    }
    let Ok(doc) = serde_json::from_slice::<Document>(json) else { return (Vec::new(), Vec::new()) };
    let files =
        |items: Vec<Item>| items.into_iter().filter_map(|i| i.uri).filter(|u| !u.starts_with("data:")).collect();
    (files(doc.buffers), files(doc.images))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uris_stay_inside_the_folder() {
        assert_eq!(relative_path("a%20b.bin"), Ok(PathBuf::from("a b.bin")));
        assert_eq!(relative_path("sub/x.bin"), Ok(PathBuf::from("sub/x.bin")));
        for bad in [
            "../x.bin",
            "sub/../../x.bin",
            "/etc/passwd",
            "\\\\server\\x",
            "file:///etc/passwd",
            "http://h/x.bin",
            "C:/x.bin",
            "%2e%2e/x.bin",
            "%2fetc/passwd",
            "sub%5c..%5c..%5cx.bin",
            "%zz.bin",
        ] {
            assert!(relative_path(bad).is_err(), "{bad} accepted");
            assert!(resolve(bad).is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn data_uris_decode_base64_only() {
        assert_eq!(resolve("data:application/octet-stream;base64,AQID"), Ok(UriTarget::Data(vec![1, 2, 3])));
        assert!(resolve("data:application/octet-stream,abc").is_err());
        assert!(resolve("data:application/octet-stream;base64,!!").is_err());
    }

    #[test]
    fn inside_means_strictly_below_the_folder() {
        assert!(inside(Path::new("/m"), Path::new("/m/a.bin")));
        assert!(!inside(Path::new("/m"), Path::new("/m")));
        assert!(!inside(Path::new("/m"), Path::new("/mx/a.bin")));
        assert!(!inside(Path::new("/m"), Path::new("/etc/passwd")));
    }
}
