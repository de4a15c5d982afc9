//! Reads a baked file back into the extension's types (the viewer and `drafter inspect` use it).

use serde_json::Value;

use crate::FormatError;
use crate::ext::{EXTENSION, NodeExtension, PartRecord, PrimitiveExtension, RootExtension};

/// What a baked file carries in `DRAFTER_illustration`.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedFile {
    pub root: RootExtension,
    /// (node index, its parts), in node order.
    pub nodes: Vec<(u32, NodeExtension)>,
    /// (mesh index, primitive index, part label per triangle), in mesh then primitive order.
    pub primitive_labels: Vec<(u32, u32, Vec<u32>)>,
}

impl BakedFile {
    /// Every part, ordered by id.
    pub fn parts(&self) -> Vec<&PartRecord> {
        let mut parts: Vec<&PartRecord> = self.nodes.iter().flat_map(|(_, n)| n.parts.iter()).collect();
        parts.sort_by_key(|p| p.id);
        parts
    }
}

/// Splits a .glb into its JSON and BIN chunks, or returns a .gltf's JSON as is.
pub fn split_container(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), FormatError> {
    if !bytes.starts_with(b"glTF") {
        return Ok((bytes, None));
    }
    let u32_at = |at: usize| -> Result<usize, FormatError> {
        let b = bytes.get(at..at + 4).ok_or_else(|| FormatError::Invalid(format!("GLB truncated at byte {at}")))?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    let json_length = u32_at(12)?;
    let json =
        bytes.get(20..20 + json_length).ok_or_else(|| FormatError::Invalid("GLB JSON chunk truncated".into()))?;
    let bin_start = 20 + json_length;
    let bin = if bytes.len() >= bin_start + 8 {
        let length = u32_at(bin_start)?;
        Some(
            bytes
                .get(bin_start + 8..bin_start + 8 + length)
                .ok_or_else(|| FormatError::Invalid("GLB BIN chunk truncated".into()))?,
        )
    } else {
        None
    };
    Ok((json, bin))
}

/// Reads a baked .glb, or a .gltf whose buffer `external` returns (given the buffer's URI).
pub fn read(bytes: &[u8], external: &dyn Fn(&str) -> Option<Vec<u8>>) -> Result<BakedFile, FormatError> {
    let (json, bin) = split_container(bytes)?;
    let doc: Value = serde_json::from_slice(json)?;
    let root_value = doc
        .get("extensions")
        .and_then(|e| e.get(EXTENSION))
        .ok_or_else(|| FormatError::NotBaked(format!("no {EXTENSION} extension on the root")))?;
    let root: RootExtension = serde_json::from_value(root_value.clone())?;
    let buffer: Option<Vec<u8>> = match doc.get("buffers").and_then(|b| b.get(0)) {
        Some(b) => match b.get("uri").and_then(Value::as_str) {
            Some(uri) => {
                Some(external(uri).ok_or_else(|| FormatError::Invalid(format!("cannot load buffer {uri:?}")))?)
            }
            None => bin.map(<[u8]>::to_vec),
        },
        None => None,
    };
    let mut nodes = Vec::new();
    for (i, node) in doc.get("nodes").and_then(Value::as_array).map_or(&[][..], Vec::as_slice).iter().enumerate() {
        if let Some(ext) = node.get("extensions").and_then(|e| e.get(EXTENSION)) {
            nodes.push((i as u32, serde_json::from_value::<NodeExtension>(ext.clone())?));
        }
    }
    let mut primitive_labels = Vec::new();
    for (m, mesh) in doc.get("meshes").and_then(Value::as_array).map_or(&[][..], Vec::as_slice).iter().enumerate() {
        for (p, prim) in
            mesh.get("primitives").and_then(Value::as_array).map_or(&[][..], Vec::as_slice).iter().enumerate()
        {
            let Some(ext) = prim.get("extensions").and_then(|e| e.get(EXTENSION)) else { continue };
            let ext: PrimitiveExtension = serde_json::from_value(ext.clone())?;
            if let Some(accessor) = ext.part_labels {
                let data = buffer.as_deref().ok_or_else(|| FormatError::Invalid("labels but no buffer".into()))?;
                primitive_labels.push((m as u32, p as u32, read_scalars(&doc, accessor as usize, data)?));
            }
        }
    }
    Ok(BakedFile { root, nodes, primitive_labels })
}

/// Reads an unsigned SCALAR accessor (tightly packed) from the single buffer.
pub fn read_scalars(doc: &Value, accessor: usize, buffer: &[u8]) -> Result<Vec<u32>, FormatError> {
    let bad = |what: &str| FormatError::Invalid(format!("/accessors/{accessor}: {what}"));
    let a = doc.get("accessors").and_then(|a| a.get(accessor)).ok_or_else(|| bad("missing"))?;
    let view_index = a.get("bufferView").and_then(Value::as_u64).ok_or_else(|| bad("no bufferView"))? as usize;
    let view = doc.get("bufferViews").and_then(|v| v.get(view_index)).ok_or_else(|| bad("bufferView missing"))?;
    let count = a.get("count").and_then(Value::as_u64).ok_or_else(|| bad("no count"))? as usize;
    let size = match a.get("componentType").and_then(Value::as_u64) {
        Some(5121) => 1,
        Some(5123) => 2,
        Some(5125) => 4,
        _ => return Err(bad("not an unsigned integer type")),
    };
    let start = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize
        + a.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let bytes = count
        .checked_mul(size)
        .and_then(|n| buffer.get(start..start.checked_add(n)?))
        .ok_or_else(|| bad("data outside the buffer"))?;
    Ok(bytes
        .chunks_exact(size)
        .map(|c| match size {
            1 => c[0] as u32,
            2 => u16::from_le_bytes([c[0], c[1]]) as u32,
            _ => u32::from_le_bytes([c[0], c[1], c[2], c[3]]),
        })
        .collect())
}
