//! A bake's peak memory, estimated before any triangle is read, so that a batch admits files under
//! its memory budget: the triangles a file lists (a glTF's from its accessors' counts, as the
//! importer's limit counts them; the other formats from their headers or a scan of their face
//! lines), times the measured peak per triangle, plus the file's own bytes.

use std::path::Path;

/// Peak bytes per listed triangle. Measured peaks of single bakes on this repository's 2-core
/// machine (`/usr/bin/time -v drafter bake`, maximum resident set minus the process's 9 MB before
/// the input is read) were at most 470 bytes a triangle on the shared models (the dragon: 0.44 KB);
/// the estimate keeps a margin over that.
pub const PEAK_BYTES_PER_TRIANGLE: u64 = 600;
/// The bake's floor: the process's own data, the thread pool's stacks, the output's buffers of a
/// small file.
pub const BASE_BYTES: u64 = 24 << 20;

/// The estimated peak memory of baking `bytes` (read from `path`): the file is held until the
/// import ends, and the scene, topology and outputs scale with the triangles.
pub fn peak_bytes(path: &Path, bytes: &[u8]) -> u64 {
    BASE_BYTES + 2 * bytes.len() as u64 + PEAK_BYTES_PER_TRIANGLE.saturating_mul(listed_triangles(path, bytes))
}

/// The triangles `bytes` lists, without building any: exact for glTF/GLB (from the accessors,
/// every mesh once), binary STL, PLY and OFF (their headers' face counts, capped by what the bytes
/// can hold), and for OBJ (face lines, a polygon of n corners counting n - 2); about one per 250
/// bytes of an ASCII STL.
pub fn listed_triangles(path: &Path, bytes: &[u8]) -> u64 {
    let format = match drafter_io::detect_format(path, bytes) {
        Ok(format) => format,
        Err(_) => return 0,
    };
    use drafter_core::SourceFormat as F;
    match format {
        F::Glb => drafter_format::glb::split(bytes).map_or(0, |c| gltf_triangles(c.json)),
        F::Gltf => gltf_triangles(bytes),
        F::Stl => binary_stl_triangles(bytes).unwrap_or(bytes.len() as u64 / 250),
        F::Ply => header_count(bytes, b"element face").min(bytes.len() as u64 / 3),
        F::Off => off_faces(bytes).min(bytes.len() as u64 / 3),
        F::Obj => obj_triangles(bytes),
    }
}

/// The count of a binary STL whose size matches it (the importer's test of a binary STL).
fn binary_stl_triangles(bytes: &[u8]) -> Option<u64> {
    let count = u64::from(u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?));
    (84 + 50 * count == bytes.len() as u64).then_some(count)
}

/// Triangles a glTF's JSON lists (drafter-format's typed document and triangle rule); 0 for JSON
/// that is not a glTF document, which the import refuses.
fn gltf_triangles(json: &[u8]) -> u64 {
    drafter_format::gltf::Root::from_slice(json).map_or(0, |root| root.listed_triangles())
}

/// The number after `key` on a header line (PLY: `element face N`).
fn header_count(bytes: &[u8], key: &[u8]) -> u64 {
    let head = &bytes[..bytes.len().min(64 << 10)];
    head.split(|&b| b == b'\n')
        .find_map(|line| {
            let line = line.strip_prefix(key)?;
            std::str::from_utf8(line).ok()?.trim().parse().ok()
        })
        .unwrap_or(0)
}

/// The face count of an OFF header (`OFF`, then `V F E`, comments and blank lines skipped).
fn off_faces(bytes: &[u8]) -> u64 {
    let head = &bytes[..bytes.len().min(64 << 10)];
    let text = String::from_utf8_lossy(head);
    let mut tokens = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(str::split_whitespace)
        .skip_while(|t| t.ends_with("OFF"));
    let _vertices = tokens.next();
    tokens.next().and_then(|t| t.parse().ok()).unwrap_or(0)
}

fn obj_triangles(bytes: &[u8]) -> u64 {
    bytes
        .split(|&b| b == b'\n')
        .filter(|line| line.first() == Some(&b'f') && line.get(1).is_some_and(u8::is_ascii_whitespace))
        .map(|line| (line.split(u8::is_ascii_whitespace).filter(|t| !t.is_empty()).count() as u64).saturating_sub(3))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_match_what_the_importer_builds() {
        let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 2 3 4\n";
        assert_eq!(listed_triangles(Path::new("a.obj"), obj), 3);
        let off = b"OFF\n# c\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
        assert_eq!(listed_triangles(Path::new("a.off"), off), 2);
        let mut stl = vec![0u8; 80];
        stl.extend_from_slice(&2u32.to_le_bytes());
        stl.extend_from_slice(&[0u8; 100]);
        assert_eq!(listed_triangles(Path::new("a.stl"), &stl), 2);
        let sample = include_bytes!("../../../samples/assembly.glb");
        let imported = drafter_io::import_bytes(Path::new("assembly.glb"), sample).unwrap();
        let built: usize = imported.scene.meshes.iter().map(|m| m.triangles.len()).sum();
        assert_eq!(listed_triangles(Path::new("assembly.glb"), sample), built as u64);
        assert!(peak_bytes(Path::new("assembly.glb"), sample) > BASE_BYTES);
    }
}
