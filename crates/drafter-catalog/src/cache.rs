//! A content-addressed cache of baked files (`--cache DIR`, `DRAFTER_CACHE`).
//!
//! **Key.** BLAKE3 over: this cache's layout version, drafter's build ([`BUILD_ID`]: the package
//! version and the commit it was built from), the extension's format version, the input's file name
//! (the output records it), the effective configuration in a canonical form, the digest of the
//! input's bytes, and the URI and digest of every external file a glTF input names (buffers and
//! images, resolved by drafter-format's confined URI rule, `drafter_format::uri`); for an OBJ, the
//! name of every material library it names with its digest (or its absence). The configuration's
//! canonical form ([`canonical_config`]) is its serde serialization as JSON with the keys sorted,
//! tagged with [`CONFIG_FORM`]: derived, so it lists every field of every stage's options with
//! floats in their shortest round-trip form, and an option added later can never be left out of
//! the key; unlike `Debug` text, the form is a documented serialization that a compiler or a
//! dependency's update does not change. A bake is byte-identical at any thread count (an invariant
//! of drafter-bake), so the key decides the bytes.
//!
//! **Entries.** One file per key, `entries/KK/KEY` (KK its first two hex digits): a header (magic,
//! layout version, payload count, then per payload its length and BLAKE3 digest) and the payloads
//! (the main file, a .gltf's .bin, the bake report's JSON). A read checks the size against the
//! header and every digest, so a truncated or corrupted entry is removed and rebuilt, never
//! served.
//!
//! **Receipts.** After a batch writes an output, it records the key and the output file's identity
//! (size, modification and change times, inode, device) under `receipts/`, keyed by the host and
//! the output's absolute path. A rerun whose key is unchanged and whose output still has that
//! identity leaves the output as it is: the file holds the bytes of that key, so an unchanged input
//! costs its hash and two `stat`s. An output edited, replaced or removed since no longer matches,
//! and is written again (from the entry, checked).
//!
//! **Concurrency.** An entry is written whole under `tmp/` (a name unique to the host, process and
//! write) and renamed into place: rename is atomic on local file systems and on NFS, so readers see
//! an entry whole or not at all, and two processes or machines that bake the same key at once
//! write the same bytes, the last rename winning. No locks, no daemon. A hit marks the entry used
//! by setting its modification time; [`Cache::evict`] removes the least recently used entries
//! past the size bound, and temporary files older than an hour (left by a killed process).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, SystemTime};

use serde::Serialize;

/// drafter's build as the key sees it: the package version, and the commit the build came from
/// where it was built from a git checkout (`build.rs`), since outputs change between commits of
/// the same version.
pub const BUILD_ID: &str = concat!(env!("CARGO_PKG_VERSION"), "+", env!("DRAFTER_BUILD_COMMIT"));

const MAGIC: &[u8; 8] = b"DRFTCACH";
const LAYOUT: u32 = 1;
/// The version of the configuration's canonical form in the key: changed whenever the form does.
pub const CONFIG_FORM: &str = "drafter-config-json-2";
/// The version of the import limits' encoding in a refusal's key ([`failure_key`]), changed whenever
/// the encoding does. Version 2: the fields' bytes, where version 1 (untagged) hashed their `Debug`
/// text; a refusal stored under version 1 is no longer found, is baked again, and ages out.
pub const LIMITS_FORM: &str = "drafter-limits-le-2";
/// Payloads per entry: main file, .bin, report.
const MAX_PAYLOADS: u32 = 4;
/// Temporary files older than this are a killed writer's and are removed by [`Cache::evict`].
const STALE_TEMP: Duration = Duration::from_secs(3600);

/// A cache key: 32 bytes of BLAKE3, written as 64 hex digits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Key(pub [u8; 32]);

impl std::fmt::Display for Key {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for b in self.0 {
            write!(f, "{b:02x}")?;
        }
        Ok(())
    }
}

/// Hashes `bytes` with BLAKE3, on the thread pool for large inputs (about twice as fast on 2 cores
/// from a few megabytes on).
pub fn digest(bytes: &[u8]) -> [u8; 32] {
    let mut hasher = blake3::Hasher::new();
    if bytes.len() >= 1 << 20 {
        hasher.update_rayon(bytes);
    } else {
        hasher.update(bytes);
    }
    *hasher.finalize().as_bytes()
}

/// The key of baking `bytes` read from `path` with `config` (its `input` field is ignored: the
/// bake fills it from the file). `None` when an external file the input names cannot be read: the
/// bake then decides (it fails, or the file is not one the importer follows), and nothing is
/// cached for it.
pub fn key_of(path: &Path, bytes: &[u8], config: &drafter_bake::BakeConfig) -> Option<Key> {
    let key = key_from(path, &digest(bytes), &external_uris(json_of(bytes)), config)?;
    Some(if is_obj(path) { with_material_libraries(key, path, bytes) } else { key })
}

/// Whether the importer may read `path` as an OBJ, whose material libraries are then part of the
/// key (by extension: the one way an OBJ is recognised, `drafter_io::detect_format`).
fn is_obj(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"))
}

/// `key` extended with the name and content of every material library the OBJ `bytes` name (a
/// library that is missing or refused, which the import turns into a diagnostic, as such).
fn with_material_libraries(key: Key, path: &Path, bytes: &[u8]) -> Key {
    let libraries = drafter_io::obj_material_libraries(bytes);
    if libraries.is_empty() {
        return key;
    }
    let folder = path.parent().unwrap_or(Path::new("."));
    let mut h = blake3::Hasher::new();
    h.update(b"drafter-cache-mtl\0");
    h.update(&key.0);
    for library in &libraries {
        let name = library.to_string_lossy();
        h.update(&(name.len() as u64).to_le_bytes());
        h.update(name.as_bytes());
        let mut content = Vec::new();
        match drafter_io::open_obj_material_library(folder, library)
            .map(|mut f| std::io::Read::read_to_end(&mut f, &mut content))
        {
            Some(Ok(_)) => {
                h.update(&[1]);
                h.update(&digest(&content));
            }
            _ => {
                h.update(&[0]);
            }
        }
    }
    Key(*h.finalize().as_bytes())
}

/// [`key_of`] without holding the file in memory: the input is hashed through a memory map
/// ([`hash_file`]), and only a glTF's JSON is read. The same key as [`key_of`] of the
/// file's bytes. `Err` when the file cannot be read.
pub fn key_of_file(path: &Path, config: &drafter_bake::BakeConfig) -> std::io::Result<Option<Key>> {
    if is_obj(path) {
        // Its material libraries are found in its text.
        return Ok(key_of(path, &std::fs::read(path)?, config));
    }
    let mut hasher = blake3::Hasher::new();
    hash_file(&mut hasher, path)?;
    let json = json_of_file(path)?;
    Ok(key_from(path, hasher.finalize().as_bytes(), &external_uris(&json), config))
}

/// The key under which the refusal of an input is stored: a file the importer or the bake refuses
/// for its content is refused again by the same build with the same configuration and the same
/// import limits, so a rerun replays the one-line reason instead of parsing the file again. The
/// limits enter as an explicit encoding, tagged with [`LIMITS_FORM`]: each field, in declaration
/// order, little-endian.
pub fn failure_key(key: &Key, limits: &drafter_io::Limits) -> Key {
    // Every field named, so that a field added to the limits cannot be left out of the key.
    let drafter_io::Limits { max_triangles } = *limits;
    let mut h = blake3::Hasher::new();
    h.update(b"drafter-cache-failure\0");
    h.update(&(LIMITS_FORM.len() as u64).to_le_bytes());
    h.update(LIMITS_FORM.as_bytes());
    h.update(&key.0);
    h.update(&max_triangles.to_le_bytes());
    Key(*h.finalize().as_bytes())
}

/// The configuration as the key hashes it and a batch report records it: every option, the
/// input's provenance left out (the key covers the input itself), as JSON whose objects have
/// their keys sorted (serde_json's map), so the same options give the same text everywhere.
pub fn canonical_config(config: &drafter_bake::BakeConfig) -> serde_json::Value {
    let mut config = config.clone();
    config.input = drafter_format::InputInfo { name: String::new(), format: String::new(), sha256: String::new() };
    let mut value = serde_json::to_value(&config).unwrap_or(serde_json::Value::Null);
    if let Some(map) = value.as_object_mut() {
        map.remove("input");
    }
    value
}

fn key_from(path: &Path, input_digest: &[u8; 32], uris: &[String], config: &drafter_bake::BakeConfig) -> Option<Key> {
    let config = format!("{CONFIG_FORM}\0{}", canonical_config(config));
    let mut h = blake3::Hasher::new();
    h.update(b"drafter-cache-key\0");
    h.update(&LAYOUT.to_le_bytes());
    for text in [BUILD_ID, drafter_format::FORMAT_VERSION, &crate::job::input_name(path), &config] {
        h.update(&(text.len() as u64).to_le_bytes());
        h.update(text.as_bytes());
    }
    h.update(input_digest);
    for uri in uris {
        let folder = path.parent().unwrap_or(Path::new(""));
        let content_digest = match drafter_format::uri::resolve_buffer_uri(folder, uri).ok()? {
            drafter_format::uri::UriSource::Data(bytes) => digest(&bytes),
            drafter_format::uri::UriSource::File { path, .. } => {
                let mut file = blake3::Hasher::new();
                hash_file(&mut file, &path).ok()?;
                *file.finalize().as_bytes()
            }
        };
        h.update(&(uri.len() as u64).to_le_bytes());
        h.update(uri.as_bytes());
        h.update(&content_digest);
    }
    Some(Key(*h.finalize().as_bytes()))
}

/// Feeds the file at `path` to `hasher`: memory-mapped and hashed on the thread pool from 16 KB on
/// (blake3's `update_mmap_rayon`, which reads smaller files), so that the bytes are neither copied
/// nor given fresh pages: in a cached rerun of a catalog, hashing is most of the work, and reading
/// through a buffer would add a copy and a page fault per block to it.
fn hash_file(hasher: &mut blake3::Hasher, path: &Path) -> std::io::Result<()> {
    hasher.update_mmap_rayon(path).map(|_| ())
}

/// The JSON of a glTF's bytes: a GLB's JSON chunk, or the bytes themselves (empty for a GLB whose
/// header or JSON chunk is malformed: the import refuses it anyway). Only the GLB's head is read
/// ([`drafter_format::glb::read_head`]), as [`json_of_file`] reads it from disk, so the two agree
/// on every file.
fn json_of(bytes: &[u8]) -> &[u8] {
    if drafter_format::glb::is_glb(bytes) {
        drafter_format::glb::read_head(bytes, bytes.len() as u64).map_or(&[], |head| &bytes[head.json])
    } else {
        bytes
    }
}

/// What [`json_of`] gives for the file at `path`, reading no more than it: a GLB's head and JSON
/// chunk, a text file that starts like JSON whole, nothing of any other file.
fn json_of_file(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut file = std::fs::File::open(path)?;
    let size = file.metadata()?.len();
    let mut head = Vec::with_capacity(drafter_format::glb::HEAD);
    (&mut file).take(drafter_format::glb::HEAD as u64).read_to_end(&mut head)?;
    if drafter_format::glb::is_glb(&head) {
        let Ok(glb) = drafter_format::glb::read_head(&head, size) else { return Ok(Vec::new()) };
        // The JSON chunk's data start right after the head just read.
        let mut json = Vec::with_capacity(glb.json.len());
        file.take(glb.json.len() as u64).read_to_end(&mut json)?;
        return Ok(json);
    }
    if head.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{') {
        return std::fs::read(path);
    }
    Ok(Vec::new())
}

/// The URIs of files a glTF's JSON names beside it, buffers then images, in document order; data
/// URIs are part of the bytes already. Empty for anything that is not a JSON object.
fn external_uris(json: &[u8]) -> Vec<String> {
    let (buffers, images) = drafter_format::uri::file_uris(json);
    buffers.into_iter().chain(images).collect()
}

/// What `drafter cache stats` prints.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Stats {
    pub entries: u64,
    pub bytes: u64,
    /// Temporary files of writes in progress or of killed writers.
    pub temporary_files: u64,
    /// Seconds since the least and the most recently used entry was last used.
    pub oldest_use_s: Option<u64>,
    pub newest_use_s: Option<u64>,
}

/// What [`Cache::evict`] removed.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Evicted {
    pub entries: u64,
    pub bytes: u64,
    pub stale_temporary_files: u64,
}

/// A cache folder.
#[derive(Debug, Clone)]
pub struct Cache {
    root: PathBuf,
    /// Size bound in bytes for [`Cache::evict`] (`--cache-max`); `None`: unbounded.
    pub max_bytes: Option<u64>,
}

/// Why an entry was not served.
#[derive(Debug, PartialEq, Eq)]
pub enum Miss {
    /// No entry.
    Absent,
    /// An entry that failed its check (truncated, corrupted); it was removed.
    Corrupt(String),
}

static WRITES: AtomicU64 = AtomicU64::new(0);

impl Cache {
    /// Opens (creating) the cache folder `root`.
    pub fn open(root: &Path, max_bytes: Option<u64>) -> std::io::Result<Self> {
        std::fs::create_dir_all(root)?;
        let cache = Self { root: root.to_path_buf(), max_bytes };
        for folder in ["entries", "tmp"] {
            cache.confined(&Path::new(folder).join("x"))?;
        }
        Ok(cache)
    }

    /// Opens the cache folder `root` only if it exists (`drafter cache stats` on a folder that is
    /// not there creates nothing).
    pub fn open_existing(root: &Path, max_bytes: Option<u64>) -> std::io::Result<Self> {
        let meta = std::fs::metadata(root)?;
        if !meta.is_dir() {
            return Err(std::io::Error::new(std::io::ErrorKind::NotADirectory, "not a folder"));
        }
        Ok(Self { root: root.to_path_buf(), max_bytes })
    }

    /// The path of `relative` in the cache, its folders created, through the batch's confinement
    /// ([`crate::output::confined`]): no symbolic link inside the cache folder is followed, so no
    /// write of the cache lands outside it.
    fn confined(&self, relative: &Path) -> std::io::Result<PathBuf> {
        crate::output::confined(&self.root, relative).map_err(|e| std::io::Error::other(e.to_string()))
    }

    /// Marks the entry of `key` used now, for eviction (an output found up to date by its receipt
    /// uses the entry without reading it).
    pub fn touch(&self, key: &Key) {
        let path = self.entry_path(key);
        if std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file())
            && let Ok(file) = std::fs::File::options().write(true).open(&path)
        {
            let _ = file.set_modified(SystemTime::now());
        }
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    fn entry_path(&self, key: &Key) -> PathBuf {
        let hex = key.to_string();
        self.root.join("entries").join(&hex[..2]).join(hex)
    }

    /// The payloads stored under `key`, checked against their digests; a hit marks the entry used.
    pub fn get(&self, key: &Key) -> Result<Vec<Vec<u8>>, Miss> {
        let path = self.entry_path(key);
        let bytes = match std::fs::read(&path) {
            Ok(bytes) => bytes,
            Err(_) => return Err(Miss::Absent),
        };
        match decode(&bytes) {
            Ok(payloads) => {
                // Last use, for eviction; a failure (a read-only cache) only costs LRU order.
                if let Ok(file) = std::fs::File::options().write(true).open(&path) {
                    let _ = file.set_modified(SystemTime::now());
                }
                Ok(payloads)
            }
            Err(why) => {
                // Removed so that the rebuilt entry replaces it; a concurrent writer's fresh entry
                // renamed in between would be removed too, and is then written again.
                let _ = std::fs::remove_file(&path);
                Err(Miss::Corrupt(why))
            }
        }
    }

    /// Stores `payloads` under `key`: written whole under `tmp/`, synced, renamed into place.
    /// `guard` registers the temporary file for removal should the process be interrupted.
    pub fn put(&self, key: &Key, payloads: &[&[u8]], guard: &dyn Fn(&Path) -> Box<dyn Send>) -> std::io::Result<()> {
        let hex = key.to_string();
        let target = self.confined(&Path::new("entries").join(&hex[..2]).join(&hex))?;
        let temp = self.confined(&Path::new("tmp").join(format!(
            "{}.{}.{}.{}.tmp",
            key,
            hostname(),
            std::process::id(),
            WRITES.fetch_add(1, Ordering::Relaxed)
        )))?;
        let _guard = guard(&temp);
        let written = (|| {
            let mut file = std::fs::File::create(&temp)?;
            file.write_all(&encode_header(payloads))?;
            for p in payloads {
                file.write_all(p)?;
            }
            file.sync_all()?;
            std::fs::rename(&temp, &target)
        })();
        if written.is_err() {
            let _ = std::fs::remove_file(&temp);
        }
        written
    }

    /// The receipt of `output`, relative to the cache folder.
    fn receipt_path(&self, output: &Path) -> PathBuf {
        let absolute = std::path::absolute(output).unwrap_or_else(|_| output.to_path_buf());
        let mut h = blake3::Hasher::new();
        h.update(hostname().as_bytes());
        h.update(b"\0");
        h.update(absolute.as_os_str().as_encoded_bytes());
        let hex = Key(*h.finalize().as_bytes()).to_string();
        Path::new("receipts").join(&hex[..2]).join(hex)
    }

    /// Whether the files `outputs` (a main file and a .gltf's .bin) are still the ones written
    /// for `key` and recorded by [`Cache::write_receipt`].
    pub fn receipt_matches(&self, outputs: &[&Path], key: &Key) -> bool {
        let Ok(recorded) = std::fs::read_to_string(self.root.join(self.receipt_path(outputs[0]))) else { return false };
        let mut now = key.to_string();
        for output in outputs {
            match identity(output) {
                Some(id) => now.push_str(&id),
                None => return false,
            }
        }
        recorded == now
    }

    /// Records that `outputs` now hold the bytes of `key` (a hint: a failure only costs a rewrite
    /// next time).
    pub fn write_receipt(&self, outputs: &[&Path], key: &Key) {
        let Ok(path) = self.confined(&self.receipt_path(outputs[0])) else { return };
        let mut text = key.to_string();
        for output in outputs {
            match identity(output) {
                Some(id) => text.push_str(&id),
                None => return,
            }
        }
        let temp =
            path.with_extension(format!("{}.{}.tmp", std::process::id(), WRITES.fetch_add(1, Ordering::Relaxed)));
        let written = std::fs::write(&temp, text);
        if written.and_then(|()| std::fs::rename(&temp, &path)).is_err() {
            let _ = std::fs::remove_file(&temp);
        }
    }

    /// Every entry with its size and last use.
    fn entries(&self) -> Vec<(PathBuf, u64, SystemTime)> {
        let mut out = Vec::new();
        // Only real folders and files: eviction removes what this lists, and a symbolic link
        // planted in the cache must not lead it to files outside.
        let entries = self.root.join("entries");
        if !std::fs::symlink_metadata(&entries).is_ok_and(|m| m.is_dir()) {
            return out;
        }
        let Ok(folders) = std::fs::read_dir(entries) else { return out };
        for folder in folders.flatten() {
            if !folder.file_type().is_ok_and(|t| t.is_dir()) {
                continue;
            }
            let Ok(files) = std::fs::read_dir(folder.path()) else { continue };
            for file in files.flatten() {
                // DirEntry::metadata does not follow a symbolic link.
                if let Ok(meta) = file.metadata()
                    && meta.is_file()
                {
                    out.push((file.path(), meta.len(), meta.modified().unwrap_or(SystemTime::UNIX_EPOCH)));
                }
            }
        }
        out
    }

    pub fn stats(&self) -> Stats {
        let entries = self.entries();
        let now = SystemTime::now();
        let age = |t: SystemTime| now.duration_since(t).unwrap_or_default().as_secs();
        Stats {
            entries: entries.len() as u64,
            bytes: entries.iter().map(|e| e.1).sum(),
            temporary_files: std::fs::read_dir(self.root.join("tmp")).map_or(0, |d| d.count() as u64),
            oldest_use_s: entries.iter().map(|e| e.2).min().map(age),
            newest_use_s: entries.iter().map(|e| e.2).max().map(age),
        }
    }

    /// Removes the least recently used entries until the cache holds at most `max_bytes`, and
    /// temporary files older than an hour.
    pub fn evict(&self) -> Evicted {
        let mut evicted = Evicted::default();
        let now = SystemTime::now();
        let tmp = self.root.join("tmp");
        let real = std::fs::symlink_metadata(&tmp).is_ok_and(|m| m.is_dir());
        if let Some(Ok(temps)) = real.then(|| std::fs::read_dir(&tmp)) {
            for temp in temps.flatten() {
                let stale = temp
                    .metadata()
                    .and_then(|m| m.modified())
                    .is_ok_and(|t| now.duration_since(t).unwrap_or_default() > STALE_TEMP);
                if stale && std::fs::remove_file(temp.path()).is_ok() {
                    evicted.stale_temporary_files += 1;
                }
            }
        }
        let Some(max) = self.max_bytes else { return evicted };
        let mut entries = self.entries();
        let mut total: u64 = entries.iter().map(|e| e.1).sum();
        // Oldest use first; ties by path, so two evictions of one state agree.
        entries.sort_by(|a, b| a.2.cmp(&b.2).then_with(|| a.0.cmp(&b.0)));
        for (path, bytes, _) in entries {
            if total <= max {
                break;
            }
            if std::fs::remove_file(&path).is_ok() {
                total -= bytes;
                evicted.entries += 1;
                evicted.bytes += bytes;
            }
        }
        evicted
    }

    /// Removes every entry and temporary file; returns the number of entries removed.
    pub fn clear(&self) -> std::io::Result<u64> {
        let count = self.entries().len() as u64;
        for folder in ["entries", "tmp", "receipts"] {
            let path = self.root.join(folder);
            match std::fs::remove_dir_all(&path) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(e),
            }
            std::fs::create_dir_all(&path)?;
        }
        Ok(count)
    }
}

/// A file's identity for receipts: size, modification and change times in nanoseconds, inode and
/// device. Writing or replacing the file changes at least one of them.
#[cfg(unix)]
fn identity(path: &Path) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    let m = std::fs::metadata(path).ok()?;
    Some(format!(
        "\n{} {}.{} {}.{} {} {}",
        m.len(),
        m.mtime(),
        m.mtime_nsec(),
        m.ctime(),
        m.ctime_nsec(),
        m.ino(),
        m.dev()
    ))
}

/// A file's identity for receipts where there is no inode or change time: size, and modification
/// and creation times in nanoseconds since the epoch (a platform without a creation time gives 0).
/// Writing the file changes its size or modification time; a file replaced by another keeps them
/// only if the writer set them, which is what a receipt trusts on such platforms.
#[cfg(not(unix))]
fn identity(path: &Path) -> Option<String> {
    let m = std::fs::metadata(path).ok()?;
    let nanos = |t: std::io::Result<SystemTime>| {
        t.ok().and_then(|t| t.duration_since(SystemTime::UNIX_EPOCH).ok()).map_or(0, |d| d.as_nanos())
    };
    Some(format!("\n{} {} {}", m.len(), nanos(m.modified()), nanos(m.created())))
}

/// The host's name for receipts, so that machines sharing a cache folder keep receipts apart: the
/// kernel's on Linux, `COMPUTERNAME` or `HOSTNAME` elsewhere, empty where neither is known.
fn hostname() -> String {
    #[cfg(target_os = "linux")]
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname").ok();
    #[cfg(not(target_os = "linux"))]
    let name = std::env::var("COMPUTERNAME").or_else(|_| std::env::var("HOSTNAME")).ok();
    name.map(|h| h.trim().chars().filter(char::is_ascii_alphanumeric).collect()).unwrap_or_default()
}

fn encode_header(payloads: &[&[u8]]) -> Vec<u8> {
    let mut header = Vec::with_capacity(16 + payloads.len() * 40);
    header.extend_from_slice(MAGIC);
    header.extend_from_slice(&LAYOUT.to_le_bytes());
    header.extend_from_slice(&(payloads.len() as u32).to_le_bytes());
    for p in payloads {
        header.extend_from_slice(&(p.len() as u64).to_le_bytes());
        header.extend_from_slice(&digest(p));
    }
    header
}

/// The payloads of an entry, or why it is not a whole, intact one.
fn decode(bytes: &[u8]) -> Result<Vec<Vec<u8>>, String> {
    let read_u32 = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    if bytes.get(..8) != Some(MAGIC.as_slice()) || read_u32(8) != Some(LAYOUT) {
        return Err("not an entry of this cache layout".into());
    }
    let count = read_u32(12).ok_or("truncated header")?;
    if count > MAX_PAYLOADS {
        return Err(format!("{count} payloads"));
    }
    let mut at = 16 + count as usize * 40;
    let header = bytes.get(16..at).ok_or("truncated header")?;
    let mut payloads = Vec::with_capacity(count as usize);
    for record in header.chunks_exact(40) {
        let mut len = [0u8; 8];
        len.copy_from_slice(&record[..8]);
        let len = u64::from_le_bytes(len);
        let end = usize::try_from(len).ok().and_then(|l| at.checked_add(l)).filter(|&e| e <= bytes.len());
        let end = end.ok_or("truncated")?;
        let payload = &bytes[at..end];
        if digest(payload) != record[8..40] {
            return Err("a payload does not match its digest".into());
        }
        payloads.push(payload.to_vec());
        at = end;
    }
    if at != bytes.len() {
        return Err("trailing bytes".into());
    }
    Ok(payloads)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("drafter-cache-test-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    fn no_guard(_: &Path) -> Box<dyn Send> {
        Box::new(())
    }

    #[test]
    fn an_entry_round_trips_and_a_damaged_one_is_never_served() {
        let dir = scratch("damage");
        let cache = Cache::open(&dir, None).unwrap();
        let key = Key([7; 32]);
        assert_eq!(cache.get(&key), Err(Miss::Absent));
        cache.put(&key, &[b"main bytes", b"", b"{\"report\":1}"], &no_guard).unwrap();
        assert_eq!(cache.get(&key).unwrap(), vec![b"main bytes".to_vec(), vec![], b"{\"report\":1}".to_vec()]);
        let path = cache.entry_path(&key);
        let whole = std::fs::read(&path).unwrap();
        // Every truncation, and a flip of every byte, is detected.
        for cut in 0..whole.len() {
            std::fs::write(&path, &whole[..cut]).unwrap();
            assert!(matches!(cache.get(&key), Err(Miss::Corrupt(_))), "cut at {cut}");
            assert!(!path.exists(), "a damaged entry is removed");
        }
        for at in 0..whole.len() {
            let mut damaged = whole.clone();
            damaged[at] ^= 0x10;
            std::fs::write(&path, &damaged).unwrap();
            assert!(matches!(cache.get(&key), Err(Miss::Corrupt(_))), "flip at {at}");
        }
        let mut longer = whole.clone();
        longer.push(0);
        std::fs::write(&path, &longer).unwrap();
        assert!(matches!(cache.get(&key), Err(Miss::Corrupt(_))));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn eviction_removes_the_least_recently_used_first() {
        let dir = scratch("lru");
        let cache = Cache::open(&dir, Some(2 * (56 + 100))).unwrap();
        let payload = [1u8; 100];
        for k in 0..4u8 {
            cache.put(&Key([k; 32]), &[&payload], &no_guard).unwrap();
            let t = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000_000 + u64::from(k));
            std::fs::File::options()
                .write(true)
                .open(cache.entry_path(&Key([k; 32])))
                .unwrap()
                .set_modified(t)
                .unwrap();
        }
        // Entry 0 used last: it stays, 1 and 2 (the oldest uses) go.
        assert!(cache.get(&Key([0; 32])).is_ok());
        let evicted = cache.evict();
        assert_eq!(evicted.entries, 2);
        assert!(cache.get(&Key([0; 32])).is_ok());
        assert_eq!(cache.get(&Key([1; 32])), Err(Miss::Absent));
        assert_eq!(cache.get(&Key([2; 32])), Err(Miss::Absent));
        assert!(cache.get(&Key([3; 32])).is_ok());
        assert_eq!(cache.stats().entries, 2);
        assert_eq!(cache.clear().unwrap(), 2);
        assert_eq!(cache.stats().entries, 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_key_follows_the_bytes_the_name_the_config_and_external_files() {
        let dir = scratch("key");
        std::fs::create_dir_all(&dir).unwrap();
        let gltf = br#"{"asset":{"version":"2.0"},"buffers":[{"uri":"a.bin","byteLength":4}]}"#;
        std::fs::write(dir.join("a.bin"), [1, 2, 3, 4]).unwrap();
        let config = drafter_bake::BakeConfig::default();
        let path = dir.join("m.gltf");
        let base = key_of(&path, gltf, &config).unwrap();
        assert_eq!(key_of(&path, gltf, &config), Some(base), "deterministic");
        std::fs::write(dir.join("a.bin"), [1, 2, 3, 5]).unwrap();
        assert_ne!(key_of(&path, gltf, &config), Some(base), "an external buffer is part of the key");
        assert_ne!(key_of(&dir.join("n.gltf"), gltf, &config), Some(base), "the name is written into the output");
        let mut other = config.clone();
        other.gradient.q += 1;
        assert_ne!(key_of(&path, gltf, &other), Some(base), "every option is part of the key");
        std::fs::write(&path, gltf).unwrap();
        assert_eq!(key_of_file(&path, &config).unwrap(), key_of(&path, gltf, &config), "from the file, the same key");
        let sample: &[u8] = include_bytes!("../../../samples/assembly.glb");
        let glb = dir.join("assembly.glb");
        std::fs::write(&glb, sample).unwrap();
        assert_eq!(key_of_file(&glb, &config).unwrap(), key_of(&glb, sample, &config));
        // A GLB's JSON is found from its head, in the file as in the bytes, bytes after the
        // container left out; the buffer file its JSON names is part of the key.
        let mut named = drafter_format::glb::write(gltf, &[]).unwrap();
        named.extend_from_slice(b"trailing");
        let glb = dir.join("named.glb");
        std::fs::write(&glb, &named).unwrap();
        let from_bytes = key_of(&glb, &named, &config);
        assert_eq!(key_of_file(&glb, &config).unwrap(), from_bytes, "from the file, the same key");
        std::fs::write(dir.join("a.bin"), [9, 9, 9, 9]).unwrap();
        assert_ne!(key_of(&glb, &named, &config), from_bytes, "the GLB's buffer file is part of its key");
        std::fs::remove_file(dir.join("a.bin")).unwrap();
        assert_eq!(key_of(&path, gltf, &config), None, "a missing external file is not cached");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_refusals_key_follows_the_bake_key_and_the_limits() {
        let key = Key(digest(b"input"));
        let limits = drafter_io::Limits::default();
        let base = failure_key(&key, &limits);
        assert_eq!(failure_key(&key, &limits), base, "deterministic");
        assert_ne!(base, key, "apart from the bake's key");
        assert_ne!(failure_key(&Key(digest(b"other")), &limits), base, "the bake's key is part of it");
        let lower = drafter_io::Limits { max_triangles: limits.max_triangles - 1 };
        assert_ne!(failure_key(&key, &lower), base, "the limits are part of it");
    }

    #[test]
    fn the_configs_canonical_form_is_sorted_json_of_every_option() {
        let config = drafter_bake::BakeConfig::default();
        let form = canonical_config(&config);
        // Objects' keys sorted at every depth, so the text does not depend on declaration order.
        fn sorted(v: &serde_json::Value) -> bool {
            match v {
                serde_json::Value::Object(m) => {
                    m.keys().zip(m.keys().skip(1)).all(|(a, b)| a < b) && m.values().all(sorted)
                }
                serde_json::Value::Array(a) => a.iter().all(sorted),
                _ => true,
            }
        }
        assert!(sorted(&form), "{form}");
        let text = form.to_string();
        let again: serde_json::Value = serde_json::from_str(&text).expect("JSON");
        assert_eq!(again.to_string(), text, "read back and written again, the same text");
        for stage in ["segment", "normals", "lines", "textures", "obb", "gradient", "output", "part"] {
            assert!(form.get(stage).is_some(), "{stage} missing from {form}");
        }
        assert!(form.get("input").is_none());
        // Each option a TOML file sets changes the form, and so the key.
        let base = key_from(Path::new("m.obj"), &[0; 32], &[], &config);
        for toml in [
            "[lines]\ncrease_angle_deg = 31.0\n",
            "[segment]\nmode = \"components\"\n",
            "[normals]\nenabled = false\n",
            "[[part]]\nid = 0\nscale = 2.0\n",
        ] {
            let other = crate::job::config_from_toml(toml).expect("config");
            assert_ne!(canonical_config(&other), form, "{toml}");
            assert_ne!(key_from(Path::new("m.obj"), &[0; 32], &[], &other), base, "{toml}");
        }
    }

    #[test]
    fn an_obj_key_follows_its_material_libraries() {
        let dir = scratch("mtl");
        std::fs::create_dir_all(&dir).unwrap();
        let obj = b"mtllib parts.mtl\nusemtl steel\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        let path = dir.join("m.obj");
        std::fs::write(&path, obj).unwrap();
        let config = drafter_bake::BakeConfig::default();
        let missing = key_of(&path, obj, &config).unwrap();
        std::fs::write(dir.join("parts.mtl"), "newmtl steel\nKd 0.5 0.5 0.5\n").unwrap();
        let grey = key_of(&path, obj, &config).unwrap();
        assert_ne!(grey, missing, "a library written since is part of the key");
        std::fs::write(dir.join("parts.mtl"), "newmtl steel\nKd 0.9 0.1 0.1\n").unwrap();
        let red = key_of(&path, obj, &config).unwrap();
        assert_ne!(red, grey, "a library's content is part of the key");
        assert_eq!(key_of_file(&path, &config).unwrap(), Some(red), "from the file, the same key");
        let plain = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        assert_eq!(
            key_of(&path, plain, &config),
            key_from(&path, &digest(plain), &[], &config),
            "no library, no change"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
