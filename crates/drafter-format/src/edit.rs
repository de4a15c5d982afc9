//! Saving an illustrator's edits (Lux et al. 2013 §4) back into a baked file: the edited
//! part records are rewritten in place in the JSON, and every other byte of the file stays as it
//! was — the binary chunk, the other records, the key order and the formatting — apart from the
//! lengths in the GLB header and the JSON chunk's padding.
//!
//! The records are found by their byte spans: serde_json's `RawValue` borrows each part record's
//! text straight from the document, so its offset is its position in the JSON (no second JSON
//! parser by hand). A replaced record is serialised as the writer serialises it (through
//! `serde_json::Value`, so the keys come in the same order).

use std::collections::{BTreeMap, HashMap};

use serde::Deserialize;
use serde_json::value::RawValue;

use drafter_core::gradient::GradientParams;

use crate::ext::{EXTENSION, FORMAT_VERSION, PartRecord};
use crate::{FormatError, split_container};

#[derive(Deserialize)]
struct RawDocument<'a> {
    #[serde(default, borrow)]
    nodes: Vec<RawNode<'a>>,
    #[serde(default, borrow)]
    extensions: HashMap<String, &'a RawValue>,
}

#[derive(Deserialize)]
struct RawNode<'a> {
    #[serde(default, borrow)]
    extensions: HashMap<String, &'a RawValue>,
}

#[derive(Deserialize)]
struct RawNodeExtension<'a> {
    #[serde(borrow)]
    parts: Vec<&'a RawValue>,
}

#[derive(Deserialize)]
struct VersionOnly {
    version: String,
}

/// The file `bytes` (a baked .glb, or a baked .gltf's JSON) with the part records of `records`
/// (matched by id) replaced. Records equal to the file's are left alone, byte for byte. Fails when
/// the file is not a bake of this version, when a record's id is not in the file, or when a record
/// is out of range ([`validate`]).
pub fn replace_part_records(bytes: &[u8], records: &[PartRecord]) -> Result<Vec<u8>, FormatError> {
    for record in records {
        validate(record).map_err(|e| FormatError::Invalid(format!("part {}: {e}", record.id)))?;
    }
    let (json, bin) = split_container(bytes)?;
    let text = std::str::from_utf8(json).map_err(|e| FormatError::Invalid(format!("JSON is not UTF-8: {e}")))?;
    let document: RawDocument<'_> = serde_json::from_str(text)?;
    let root = document
        .extensions
        .get(EXTENSION)
        .ok_or_else(|| FormatError::NotBaked(format!("no root {EXTENSION} extension")))?;
    let version: VersionOnly = serde_json::from_str(root.get())?;
    if version.version != FORMAT_VERSION {
        return Err(FormatError::Version(version.version));
    }

    let wanted: BTreeMap<u32, &PartRecord> = records.iter().map(|r| (r.id, r)).collect();
    // (start, end, replacement text), for the records that change.
    let mut splices: Vec<(usize, usize, String)> = Vec::new();
    let mut found = Vec::new();
    for node in &document.nodes {
        let Some(raw) = node.extensions.get(EXTENSION) else { continue };
        let extension: RawNodeExtension<'_> = serde_json::from_str(raw.get())?;
        for raw_part in extension.parts {
            let current: PartRecord = serde_json::from_str(raw_part.get())?;
            let Some(&new) = wanted.get(&current.id) else { continue };
            found.push(current.id);
            if *new == current {
                continue;
            }
            let start = offset_in(text, raw_part.get())?;
            let replacement = serde_json::to_string(&serde_json::to_value(new)?)?;
            splices.push((start, start + raw_part.get().len(), replacement));
        }
    }
    if let Some(missing) = wanted.keys().find(|id| !found.contains(id)) {
        return Err(FormatError::Invalid(format!("part {missing} is not in the file")));
    }
    splices.sort_by_key(|s| s.0);
    let mut out = String::with_capacity(text.len() + splices.iter().map(|s| s.2.len()).sum::<usize>());
    let mut at = 0;
    for (start, end, replacement) in &splices {
        out.push_str(&text[at..*start]);
        out.push_str(replacement);
        at = *end;
    }
    out.push_str(&text[at..]);
    match bin {
        _ if !crate::glb::is_glb(bytes) => Ok(out.into_bytes()),
        bin => Ok(crate::glb::write(out.as_bytes(), bin.unwrap_or(&[]))?),
    }
}

/// The byte offset of `part` (a slice borrowed from `text`) in `text`.
fn offset_in(text: &str, part: &str) -> Result<usize, FormatError> {
    let offset = (part.as_ptr() as usize).wrapping_sub(text.as_ptr() as usize);
    if offset <= text.len() && offset + part.len() <= text.len() {
        Ok(offset)
    } else {
        Err(FormatError::Inconsistent("a part record is not borrowed from the document".into()))
    }
}

/// Checks an edited record against the ranges the schema and the bake's config accept: a finite
/// anchor, a unit direction (within 1e-6), a finite scale ≥ 0, q in 1..=255 and whole, f in [0, 1],
/// p in [0.01, 10], a flat grey in [0, 1], and a finite projector matrix.
pub fn validate(record: &PartRecord) -> Result<(), String> {
    let projector = &record.projector;
    if !projector.anchor.iter().all(|v| v.is_finite()) {
        return Err(format!("anchor {:?} is not finite", projector.anchor));
    }
    let length = projector.direction.iter().map(|v| v * v).sum::<f64>().sqrt();
    if !length.is_finite() || (length - 1.0).abs() > 1e-6 {
        return Err(format!("direction {:?} is not a unit vector", projector.direction));
    }
    if !projector.scale.is_finite() || projector.scale < 0.0 {
        return Err(format!("scale {} must be finite and >= 0", projector.scale));
    }
    if !projector.matrix.iter().all(|v| v.is_finite()) {
        return Err("the projector matrix is not finite".into());
    }
    // q, f and p as the bake holds them (whole q, f32 f and p), checked by the one range check
    // the bake's config uses.
    let gradient = &record.gradient;
    if !(gradient.q >= 1.0 && gradient.q <= f64::from(u32::MAX)) || gradient.q.fract() != 0.0 {
        return Err(format!("q {} must be a whole number in 1..=255", gradient.q));
    }
    GradientParams { q: gradient.q as u32, f: gradient.f as f32, p: gradient.p as f32 }
        .validate()
        .map_err(|e| e.to_string())?;
    if let Some(flat) = record.flat
        && !(0.0..=1.0).contains(&flat)
    {
        return Err(format!("flat {flat} is out of range [0, 1]"));
    }
    Ok(())
}
