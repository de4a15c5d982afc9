//! Mutators: what a case does to its seed.
//!
//! * bytes, for every target: bit flips, interesting bytes, little-endian u32/f32 overwrites,
//!   truncation, deleted and repeated ranges, splices with another seed of the same target;
//! * text (OBJ, OFF, ASCII PLY and STL, glTF): number tokens replaced by interesting numbers
//!   (`4294967295`, `-1`, `1e309`, `nan`, `9007199254740993`, ...), lines deleted, repeated (up to
//!   2,000 times: duplicate faces), swapped, or inserted from a per-format dictionary;
//! * headers: PLY element counts, property types, list types and `format`; OFF counts; the binary
//!   STL triangle count;
//! * glTF JSON (a .gltf, the JSON chunk of a .glb or of a baked file): a value replaced by an
//!   interesting number (2^53 + 1, 2^32, -1, 1e300, ...), by a raw token JSON parsers disagree on
//!   (`NaN`, `1e309`, `-0`, 30 digits), by a wrong type or an out-of-range index; a key dropped or
//!   duplicated (textually: a `Value` cannot hold two); a value buried under 64 to 5,000 arrays; array
//!   elements removed, duplicated or swapped; a sparse block or a missing `bufferView` on an
//!   accessor; `componentType`, `type`, `byteStride` and `mode` set to their neighbours;
//! * glTF structure (half of the JSON edits): a member glTF requires removed (an image's
//!   `uri` or `bufferView`, an accessor's `count`...), an object emptied (`{}` for an image), a
//!   reference pointed into another array's range, entries of a top-level array dropped,
//!   duplicated or cut off, a member's type changed (a number as a string, an object as an array).
//!
//! Outputs are capped at [`MAX_OUTPUT`] bytes so that a case costs what a small input costs.

use drafter_testkit::Rng;
use serde_json::{Map, Value, json};

use crate::Target;

/// No case grows past this size (4 MiB).
pub const MAX_OUTPUT: usize = 4 << 20;

/// The bytes of one case: `seed` with one to four mutations (a single one in three cases of seven);
/// `other` is a second seed of the same target, for splices.
pub fn mutate(target: Target, seed: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut bytes = seed.to_vec();
    // Mostly one mutation, so that most cases stay close enough to a valid file to reach the bake.
    let rounds = [1, 1, 1, 2, 2, 3, 4][rng.below(7) as usize];
    for _ in 0..rounds {
        bytes = match target {
            Target::Gltf => pick3(rng, 6, 1, 1).map_or_else(
                || bytes.clone(),
                |k| match k {
                    0 => mutate_json_text(&bytes, rng),
                    1 => mutate_text(target, &bytes, other, rng),
                    _ => mutate_bytes(&bytes, other, rng),
                },
            ),
            Target::Glb | Target::Baked => match rng.below(10) {
                0..=6 => mutate_glb_json(&bytes, rng),
                7 => mutate_glb_bin(&bytes, rng),
                _ => mutate_bytes(&bytes, other, rng),
            },
            Target::StlBinary => match rng.below(4) {
                0 => stl_binary_header(&bytes, rng),
                _ => mutate_bytes(&bytes, other, rng),
            },
            Target::Ply if !is_ascii_ply(&bytes) => match rng.below(3) {
                0 => ply_header(&bytes, rng),
                _ => mutate_bytes(&bytes, other, rng),
            },
            _ => match rng.below(5) {
                0..=2 => mutate_text(target, &bytes, other, rng),
                3 if target == Target::Ply => ply_header(&bytes, rng),
                _ => mutate_bytes(&bytes, other, rng),
            },
        };
        bytes.truncate(MAX_OUTPUT);
    }
    bytes
}

/// 0, 1 or 2 with the given weights (always `Some`; an `Option` to read well at the call site).
fn pick3(rng: &mut Rng, a: u64, b: u64, c: u64) -> Option<u64> {
    let r = rng.below(a + b + c);
    Some(if r < a {
        0
    } else if r < a + b {
        1
    } else {
        2
    })
}

fn index(rng: &mut Rng, len: usize) -> usize {
    rng.below(len.max(1) as u64) as usize
}

fn choose<'a, T>(rng: &mut Rng, items: &'a [T]) -> &'a T {
    &items[index(rng, items.len())]
}

// ---------------------------------------------------------------------------------------------
// Bytes

const INTERESTING_BYTES: [u8; 12] = [0, 1, 0x7f, 0x80, 0xff, b'-', b'9', b'\n', b' ', b'e', b'.', b'"'];
const INTERESTING_U32: [u32; 12] =
    [0, 1, 2, 3, 255, 65_535, 65_536, 0x00ff_ffff, 0x7fff_ffff, 0x8000_0000, 0xffff_fffe, 0xffff_ffff];
const INTERESTING_F32: [f32; 9] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, -0.0, 4.29e9, 1e-45, 1e20, -1e20];

/// A generic mutation of raw bytes.
pub fn mutate_bytes(bytes: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = bytes.to_vec();
    if out.is_empty() {
        return other.to_vec();
    }
    let len = out.len();
    match rng.below(9) {
        0 => {
            for _ in 0..1 + rng.below(8) {
                let i = index(rng, len);
                out[i] ^= 1 << rng.below(8);
            }
        }
        1 => {
            let i = index(rng, len);
            out[i] = *choose(rng, &INTERESTING_BYTES);
        }
        2 => {
            let value = if rng.below(2) == 0 {
                choose(rng, &INTERESTING_U32).to_le_bytes()
            } else {
                choose(rng, &INTERESTING_F32).to_le_bytes()
            };
            let at = index(rng, len.saturating_sub(3));
            for (k, b) in value.iter().enumerate() {
                if let Some(slot) = out.get_mut(at + k) {
                    *slot = *b;
                }
            }
        }
        3 => out.truncate(index(rng, len)),
        4 => {
            let (a, b) = range(rng, len);
            out.drain(a..b);
        }
        5 => {
            // Repeat a range a few times in place.
            let (a, b) = range(rng, len.min(4096));
            let piece = out[a..b].to_vec();
            let times = 1 + rng.below(8) as usize;
            let at = index(rng, len + 1);
            out.splice(at..at, piece.iter().copied().cycle().take(piece.len() * times));
        }
        6 | 7 => {
            // Splice: our head, the other seed's tail.
            let cut = index(rng, len + 1);
            let other_cut = index(rng, other.len() + 1);
            out.truncate(cut);
            out.extend_from_slice(&other[other_cut..]);
        }
        _ => {
            // Overwrite with a chunk of the other seed at the same offset.
            let (a, b) = range(rng, len.min(other.len()));
            out[a..b].copy_from_slice(&other[a..b]);
        }
    }
    out
}

/// A non-empty-when-possible range `a..b` within `0..len`, at most 1/4 of the length plus 16.
fn range(rng: &mut Rng, len: usize) -> (usize, usize) {
    if len == 0 {
        return (0, 0);
    }
    let a = index(rng, len);
    let span = 1 + index(rng, (len / 4 + 16).min(len - a));
    (a, (a + span).min(len))
}

// ---------------------------------------------------------------------------------------------
// Text

/// Numbers that break parsers, counts and allocations, as text.
const INTERESTING_NUMBERS: [&str; 26] = [
    "0",
    "-0",
    "1",
    "-1",
    "2",
    "3",
    "-2147483649",
    "2147483648",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "18446744073709551616",
    "1e309",
    "-1e309",
    "1e-320",
    "3.4028236e38",
    "4.29e9",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "NaN",
    "0x10",
    "1e",
    "1.5",
    "123456789012345678901234567890",
];

/// Lines each text format knows, valid and not.
fn dictionary(target: Target) -> &'static [&'static str] {
    match target {
        Target::Obj => &[
            "v 0 0 0",
            "v 1e309 0 0",
            "v nan nan nan",
            "v 4.29e9 4.29e9 4.29e9",
            "v 1 2",
            "vt 0 0",
            "vn 0 0 1",
            "f 1 2 3",
            "f -1 -2 -3",
            "f 0 0 0",
            "f 1 1 1",
            "f 4294967295 1 2",
            "f -4294967296 1 2",
            "f 1/1/1 2/2/2 3/3/3",
            "f 1//9 2//9 3//9",
            "f 1 2",
            "f 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16",
            "l 1 2",
            "p 1",
            "o object",
            "g group",
            "s 1",
            "usemtl missing",
            "mtllib missing.mtl",
            "mtllib ../../../etc/passwd",
            "mtllib /dev/zero",
            "f 1 2 \\",
            "#",
            "",
        ],
        Target::StlAscii => &[
            "solid fuzz",
            "facet normal 0 0 1",
            "facet normal nan nan nan",
            "outer loop",
            "vertex 0 0 0",
            "vertex 1e309 0 0",
            "vertex 1 2",
            "endloop",
            "endfacet",
            "endsolid fuzz",
            "endsolid",
            "",
        ],
        Target::Off => &[
            "OFF",
            "4294967295 1 0",
            "3 4294967295 0",
            "-1 -1 -1",
            "3 1 0",
            "0 0 0",
            "3 0 1 2",
            "4294967295 0 1 2",
            "3 0 0 0",
            "1e309 0 0",
            "# comment",
            "",
        ],
        Target::Ply => &[
            "element vertex 4294967295",
            "element face 4294967295",
            "element vertex 0",
            "property float x",
            "property list uchar int vertex_indices",
            "property list uint uint vertex_indices",
            "property list float int vertex_indices",
            "comment fuzz",
            "obj_info fuzz",
            "0 0 0",
            "3 0 1 2",
            "255 0 1 2",
            "3 4294967295 0 1",
            "nan nan nan",
            "end_header",
        ],
        Target::Gltf => &["{", "}", "[", "]", "\"accessors\": [{}],", "null"],
        _ => &[""],
    }
}

/// A line- or number-level mutation of a text format.
fn mutate_text(target: Target, bytes: &[u8], other: &[u8], rng: &mut Rng) -> Vec<u8> {
    match rng.below(7) {
        0..=2 => replace_number(bytes, rng).unwrap_or_else(|| mutate_bytes(bytes, other, rng)),
        3 => line_edit(bytes, rng, |lines, rng| {
            let i = index(rng, lines.len());
            if !lines.is_empty() {
                lines.remove(i);
            }
        }),
        4 => line_edit(bytes, rng, |lines, rng| {
            // Repeat a line: a few times, or 2,000 (duplicate faces must cost what they weigh).
            if lines.is_empty() {
                return;
            }
            let i = index(rng, lines.len());
            let times = if rng.below(4) == 0 { 2000 } else { 1 + index(rng, 8) };
            let line = lines[i].clone();
            // Within the output cap: a 1 MB line (a minified glTF) 2,000 times would take 2 GB
            // before the cap cut it, and the fuzzer's own case would look like the target's blow-up.
            let times = times.min(MAX_OUTPUT / (line.len() + 1));
            for _ in 0..times {
                lines.insert(i, line.clone());
            }
        }),
        5 => line_edit(bytes, rng, |lines, rng| {
            let (a, b) = (index(rng, lines.len()), index(rng, lines.len()));
            if a < lines.len() && b < lines.len() {
                lines.swap(a, b);
            }
        }),
        _ => line_edit(bytes, rng, |lines, rng| {
            let line = choose(rng, dictionary(target)).as_bytes().to_vec();
            let at = index(rng, lines.len() + 1);
            lines.insert(at, line);
        }),
    }
}

fn line_edit(bytes: &[u8], rng: &mut Rng, edit: impl FnOnce(&mut Vec<Vec<u8>>, &mut Rng)) -> Vec<u8> {
    let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    edit(&mut lines, rng);
    let mut out = lines.join(&b'\n');
    out.truncate(MAX_OUTPUT);
    out
}

/// Replaces one number token of `bytes` (digits with sign, point and exponent) by an interesting
/// number; `None` when there is no number.
fn replace_number(bytes: &[u8], rng: &mut Rng) -> Option<Vec<u8>> {
    let tokens = number_tokens(bytes, 4096);
    if tokens.is_empty() {
        return None;
    }
    let (a, b) = *choose(rng, &tokens);
    let replacement: Vec<u8> = match rng.below(4) {
        0 => {
            // Off by a little: the count one past what is there.
            let text = std::str::from_utf8(&bytes[a..b]).ok()?;
            let n: i64 = text.parse().unwrap_or(0);
            n.saturating_add(if rng.below(2) == 0 { 1 } else { -1 }).to_string().into_bytes()
        }
        _ => choose(rng, &INTERESTING_NUMBERS).as_bytes().to_vec(),
    };
    let mut out = Vec::with_capacity(bytes.len() + replacement.len());
    out.extend_from_slice(&bytes[..a]);
    out.extend_from_slice(&replacement);
    out.extend_from_slice(&bytes[b..]);
    Some(out)
}

/// Up to `limit` number tokens, spread over the file (every k-th when there are more).
fn number_tokens(bytes: &[u8], limit: usize) -> Vec<(usize, usize)> {
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts =
            bytes[i].is_ascii_digit() || (bytes[i] == b'-' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
        if starts && !after_word {
            let a = i;
            i += 1;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || matches!(bytes[i], b'.' | b'e' | b'E' | b'+' | b'-'))
            {
                i += 1;
            }
            tokens.push((a, i));
        } else {
            i += 1;
        }
    }
    if tokens.len() > limit {
        let step = tokens.len().div_ceil(limit);
        tokens = tokens.into_iter().step_by(step).collect();
    }
    tokens
}

// ---------------------------------------------------------------------------------------------
// Headers

fn is_ascii_ply(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(64)];
    head.windows(12).any(|w| w == b"format ascii")
}

/// Edits one line of a PLY header: a count, a property type, a list type or the format.
fn ply_header(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    const TYPES: [&str; 17] = [
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8", "int16", "uint16",
        "int32", "uint32", "float32", "float64", "bogus",
    ];
    const FORMATS: [&str; 4] =
        ["format ascii 1.0", "format binary_little_endian 1.0", "format binary_big_endian 1.0", "format ascii 2.0"];
    let end = find(bytes, b"end_header").map_or(bytes.len(), |e| e + b"end_header".len());
    let (header, body) = bytes.split_at(end);
    let text = String::from_utf8_lossy(header);
    let mut lines: Vec<String> = text.split('\n').map(str::to_owned).collect();
    let candidates: Vec<usize> = (0..lines.len())
        .filter(|&i| {
            lines[i].starts_with("element") || lines[i].starts_with("property") || lines[i].starts_with("format")
        })
        .collect();
    if candidates.is_empty() {
        return bytes.to_vec();
    }
    let i = *choose(rng, &candidates);
    let words: Vec<String> = lines[i].split_whitespace().map(str::to_owned).collect();
    lines[i] = match words.first().map(String::as_str) {
        Some("element") if words.len() >= 3 => {
            format!("element {} {}", words[1], choose(rng, &INTERESTING_NUMBERS))
        }
        Some("format") => (*choose(rng, &FORMATS)).to_owned(),
        Some("property") if words.len() >= 3 => {
            let mut w = words.clone();
            let slot = if w[1] == "list" { 2 + index(rng, 2) } else { 1 };
            if slot < w.len() - 1 {
                w[slot] = (*choose(rng, &TYPES)).to_owned();
            }
            if rng.below(4) == 0 {
                // A property repeated: a wider vertex than the data holds.
                let line = w.join(" ");
                lines.insert(i, line.clone());
                line
            } else {
                w.join(" ")
            }
        }
        _ => lines[i].clone(),
    };
    let mut out = lines.join("\n").into_bytes();
    out.extend_from_slice(body);
    out
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// The triangle count of a binary STL (bytes 80..84) set to an interesting value, or a float of a
/// triangle overwritten.
fn stl_binary_header(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut out = bytes.to_vec();
    if out.len() < 84 {
        return out;
    }
    let triangles = (out.len() - 84) / 50;
    if rng.below(2) == 0 || triangles == 0 {
        let count = match rng.below(3) {
            0 => *choose(rng, &INTERESTING_U32),
            1 => (triangles as u32).wrapping_add(1),
            _ => (triangles as u32).wrapping_sub(1),
        };
        out[80..84].copy_from_slice(&count.to_le_bytes());
    } else {
        let at = 84 + 50 * index(rng, triangles) + 4 * index(rng, 12);
        out[at..at + 4].copy_from_slice(&choose(rng, &INTERESTING_F32).to_le_bytes());
    }
    out
}

// ---------------------------------------------------------------------------------------------
// glTF JSON

/// Mutates the JSON chunk of a .glb (or its BIN chunk's bytes) and frames it again; a file that
/// does not split gets a byte mutation.
fn mutate_glb_json(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let Ok(chunks) = drafter_format::glb::split(bytes) else { return mutate_bytes(bytes, &[], rng) };
    let json = mutate_json_text(chunks.json, rng);
    drafter_format::glb::write(&json, chunks.bin.unwrap_or_default()).unwrap_or_else(|_| bytes.to_vec())
}

fn mutate_glb_bin(bytes: &[u8], rng: &mut Rng) -> Vec<u8> {
    let Ok(chunks) = drafter_format::glb::split(bytes) else { return mutate_bytes(bytes, &[], rng) };
    let bin = mutate_bytes(chunks.bin.unwrap_or_default(), &[], rng);
    drafter_format::glb::write(chunks.json, &bin).unwrap_or_else(|_| bytes.to_vec())
}

/// Keys whose integer values index another array of the document.
const REFERENCE_KEYS: [&str; 24] = [
    "bufferView",
    "buffer",
    "accessor",
    "indices",
    "material",
    "mesh",
    "node",
    "scene",
    "skin",
    "camera",
    "source",
    "sampler",
    "index",
    "POSITION",
    "NORMAL",
    "TEXCOORD_0",
    "partLabels",
    "visibility",
    "silhouetteNormals",
    "hardEdgeClasses",
    "nodes",
    "order",
    "nodeCaps",
    "part",
];

/// A raw token spliced in where a value was: what `serde_json::Value` cannot hold.
const RAW_TOKENS: [&str; 10] = [
    "NaN",
    "Infinity",
    "-Infinity",
    "1e309",
    "-1e309",
    "-0",
    "1e-400",
    "123456789012345678901234567890",
    "9007199254740993",
    "18446744073709551616",
];

/// Stands for a raw token or a duplicated member while the document is serialised.
const MARK: &str = "\u{1}drafter-fuzz-mark\u{1}";

/// A path from the document's root to one value.
type JsonPath = Vec<Step>;

#[derive(Clone, Debug)]
enum Step {
    Key(String),
    Index(usize),
}

/// A structure-aware mutation of glTF JSON text; text that does not parse gets a text mutation.
pub fn mutate_json_text(text: &[u8], rng: &mut Rng) -> Vec<u8> {
    let Ok(mut doc) = serde_json::from_slice::<Value>(text) else {
        return mutate_text(Target::Gltf, text, &[], rng);
    };
    let mut paths = Vec::new();
    collect_paths(&doc, &mut Vec::new(), &mut paths, 20_000);
    if paths.is_empty() {
        return text.to_vec();
    }
    let path = choose(rng, &paths).clone();
    let key = match path.last() {
        Some(Step::Key(k)) => Some(k.clone()),
        _ => None,
    };
    // Half of the edits change the document's shape: a member glTF requires removed,
    // an object emptied, a reference pointed into another array, entries dropped or duplicated, a
    // member's type changed. The rest change one value.
    if rng.below(2) == 0 {
        mutate_structure(&mut doc, rng);
        return serde_json::to_vec(&doc).unwrap_or_else(|_| text.to_vec());
    }
    let Some(target) = get_mut(&mut doc, &path) else { return text.to_vec() };
    let mut raw: Option<String> = None;
    match rng.below(12) {
        0 | 1 => *target = interesting_json_number(rng),
        2 => {
            raw = Some((*choose(rng, &RAW_TOKENS)).to_owned());
            *target = Value::String(MARK.to_owned());
        }
        3 => {
            // An index past the end, or far past it.
            let big = [1u64, 2, 100, 65_536, 1 << 31, 1 << 32, (1 << 53) + 1];
            *target = json!(target.as_u64().unwrap_or(0).saturating_add(*choose(rng, &big)));
        }
        4 => {
            *target = match rng.below(6) {
                0 => Value::Null,
                1 => json!("text"),
                2 => json!([]),
                3 => json!({}),
                4 => json!(true),
                _ => json!([[1, 2], {"a": null}]),
            }
        }
        5 => {
            // Drop this member or element.
            let (parent_path, last) = path.split_at(path.len() - 1);
            if let Some(parent) = get_mut(&mut doc, parent_path) {
                match (&last[0], parent) {
                    (Step::Key(k), Value::Object(map)) => {
                        map.remove(k);
                    }
                    (Step::Index(i), Value::Array(items)) if *i < items.len() => {
                        items.remove(*i);
                    }
                    _ => {}
                }
            }
        }
        6 => {
            // Bury the value under many arrays.
            let depth = *choose(rng, &[64usize, 128, 200, 1000, 5000]);
            let mut v = std::mem::take(target);
            for _ in 0..depth {
                v = Value::Array(vec![v]);
            }
            *target = v;
        }
        7 => match target {
            Value::Array(items) if !items.is_empty() => {
                let i = index(rng, items.len());
                if rng.below(2) == 0 {
                    let copy = items[i].clone();
                    items.push(copy);
                } else {
                    let j = index(rng, items.len());
                    items.swap(i, j);
                }
            }
            Value::Object(map) if !map.is_empty() => {
                // A duplicated key, spliced in as text.
                let k = index(rng, map.len());
                let Some((dup_key, dup_value)) = map.iter().nth(k).map(|(k, v)| (k.clone(), v.clone())) else {
                    return text.to_vec();
                };
                let mut members = vec![format!("{}:{}", json!(dup_key), dup_value)];
                members.extend(map.iter().map(|(k, v)| format!("{}:{}", json!(k), v)));
                raw = Some(format!("{{{}}}", members.join(",")));
                *target = Value::String(MARK.to_owned());
            }
            _ => *target = interesting_json_number(rng),
        },
        8 => {
            if let Some(k) = key.as_deref() {
                *target = field_neighbour(k, rng).unwrap_or_else(|| interesting_json_number(rng));
            }
        }
        9 => {
            if key.as_deref().is_some_and(|k| REFERENCE_KEYS.contains(&k)) || target.is_u64() {
                *target = json!(*choose(rng, &[u32::MAX as u64, 1 << 32, (1 << 53) + 1, 7, 1000]));
            } else {
                *target = interesting_json_number(rng);
            }
        }
        _ => accessor_edit(&mut doc, rng),
    }
    let mut out = serde_json::to_string(&doc).unwrap_or_default();
    if let Some(raw) = raw {
        let mark = serde_json::to_string(MARK).unwrap_or_default();
        out = out.replacen(&mark, &raw, 1);
    }
    out.into_bytes()
}

/// Every value's path, up to `limit` of them (the first found, breadth by document order).
fn collect_paths(value: &Value, here: &mut JsonPath, out: &mut Vec<JsonPath>, limit: usize) {
    if out.len() >= limit {
        return;
    }
    if !here.is_empty() {
        out.push(here.clone());
    }
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                here.push(Step::Key(k.clone()));
                collect_paths(v, here, out, limit);
                here.pop();
            }
        }
        Value::Array(items) => {
            // Long arrays (matrices, big node lists) are sampled: their first 16 elements.
            for (i, v) in items.iter().enumerate().take(16) {
                here.push(Step::Index(i));
                collect_paths(v, here, out, limit);
                here.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(mut value: &'a mut Value, path: &[Step]) -> Option<&'a mut Value> {
    for step in path {
        value = match (step, value) {
            (Step::Key(k), Value::Object(map)) => map.get_mut(k)?,
            (Step::Index(i), Value::Array(items)) => items.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(value)
}

fn interesting_json_number(rng: &mut Rng) -> Value {
    match rng.below(14) {
        0 => json!(0),
        1 => json!(-1),
        2 => json!(1u64 << 31),
        3 => json!(u32::MAX),
        4 => json!(1u64 << 32),
        5 => json!(1u64 << 53),
        6 => json!((1u64 << 53) + 1),
        7 => json!(u64::MAX),
        8 => json!(i64::MIN),
        9 => json!(1e300),
        10 => json!(-1e300),
        11 => json!(0.5),
        12 => json!(f64::MIN_POSITIVE / 1e10),
        _ => json!(f32::MAX as f64 * 2.0),
    }
}

/// A plausible-but-wrong value for a glTF field this mutator knows, or `None`.
fn field_neighbour(key: &str, rng: &mut Rng) -> Option<Value> {
    Some(match key {
        "componentType" => json!(*choose(rng, &[5120, 5121, 5122, 5123, 5124, 5125, 5126, 5130, 0])),
        "type" => json!(*choose(rng, &["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "BOGUS", ""])),
        "byteStride" => json!(*choose(rng, &[0, 1, 2, 3, 4, 6, 252, 256, 4096])),
        "mode" => json!(rng.below(9)),
        "count" | "byteLength" | "byteOffset" => {
            json!(*choose(rng, &[0u64, 1, 3, 4, 255, 65_536, u32::MAX as u64, 1 << 40, (1 << 53) + 1]))
        }
        "normalized" => json!(rng.below(2) == 0),
        "uri" => json!(*choose(
            rng,
            &[
                "data:application/octet-stream;base64,",
                "data:application/octet-stream;base64,AAAA",
                "missing.bin",
                "../outside.bin",
                "/dev/zero",
                "%2e%2e/x.bin",
                "file:///etc/passwd",
            ]
        )),
        "matrix" => json!([1e308, 0, 0, 0, 0, 1e308, 0, 0, 0, 0, 1e308, 0, 1e308, 0, 0, 1]),
        "translation" => json!([4.29e9, -1e300, 0]),
        "rotation" => json!([0, 0, 0, 0]),
        "scale" => json!([0, 0, 0]),
        "min" | "max" => json!([-1e300, f32::MAX, 0]),
        "partCount" | "candidates" | "maxDepth" | "base" => interesting_json_number(rng),
        _ => return None,
    })
}

/// Gives a random accessor a sparse block with a large count, or takes its `bufferView` away.
fn accessor_edit(doc: &mut Value, rng: &mut Rng) {
    let Some(accessors) = doc.get_mut("accessors").and_then(Value::as_array_mut) else { return };
    if accessors.is_empty() {
        return;
    }
    let i = index(rng, accessors.len());
    let Some(accessor) = accessors[i].as_object_mut() else { return };
    match rng.below(3) {
        0 => {
            accessor.remove("bufferView");
        }
        _ => {
            let count = *choose(rng, &[1u64, 3, 1 << 20, 1 << 26, u32::MAX as u64]);
            let mut sparse = Map::new();
            sparse.insert("count".into(), json!(count));
            sparse.insert("indices".into(), json!({"bufferView": 0, "componentType": 5125}));
            sparse.insert("values".into(), json!({"bufferView": 0}));
            accessor.insert("sparse".into(), Value::Object(sparse));
            if rng.below(2) == 0 {
                accessor.remove("bufferView");
                accessor.insert("count".into(), json!(*choose(rng, &[1u64 << 26, u32::MAX as u64])));
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// glTF structure

/// The members glTF 2.0 requires of an object, by its kind ([`kind_of`]). For an image, one of
/// `uri` and `bufferView`, and `mimeType` with a view; for a camera, `type` and the member it names.
fn required_members(kind: &str) -> &'static [&'static str] {
    match kind {
        "accessors" => &["componentType", "count", "type"],
        "bufferViews" => &["buffer", "byteLength"],
        "buffers" => &["byteLength"],
        "images" => &["uri", "bufferView", "mimeType"],
        "textures" => &["source"],
        "cameras" => &["type", "perspective", "orthographic"],
        "perspective" => &["yfov", "znear"],
        "orthographic" => &["xmag", "ymag", "zfar", "znear"],
        "skins" => &["joints"],
        "animations" => &["channels", "samplers"],
        "channels" => &["sampler", "target"],
        "target" => &["node", "path"],
        "animation samplers" => &["input", "output"],
        "meshes" => &["primitives"],
        "primitives" => &["attributes"],
        "attributes" => &["POSITION"],
        "sparse" => &["count", "indices", "values"],
        "indices" => &["bufferView", "componentType"],
        "values" => &["bufferView"],
        "asset" => &["version"],
        "baseColorTexture" | "metallicRoughnessTexture" | "normalTexture" | "occlusionTexture" | "emissiveTexture" => {
            &["index"]
        }
        _ => &[],
    }
}

/// The kind of the object at `path`: the key it sits under, or the key of the array it is an
/// element of (`/images/3` is an `images`); an animation's `samplers` are `animation samplers`.
fn kind_of(path: &[Step]) -> String {
    let mut keys = path.iter().filter_map(|s| match s {
        Step::Key(k) => Some(k.as_str()),
        Step::Index(_) => None,
    });
    let last = keys.next_back().unwrap_or("");
    if last == "samplers" && keys.any(|k| k == "animations") {
        "animation samplers".to_owned()
    } else {
        last.to_owned()
    }
}

/// The top-level array a reference member's integer indexes, by its key (`None`: not a reference
/// drafter-fuzz knows).
fn referenced_array(key: &str) -> Option<&'static str> {
    Some(match key {
        "bufferView" => "bufferViews",
        "buffer" => "buffers",
        "indices" | "POSITION" | "NORMAL" | "TEXCOORD_0" | "TANGENT" | "inverseBindMatrices" | "input" | "output" => {
            "accessors"
        }
        "material" => "materials",
        "mesh" => "meshes",
        "node" | "skeleton" => "nodes",
        "scene" => "scenes",
        "skin" => "skins",
        "camera" => "cameras",
        "source" => "images",
        "sampler" => "samplers",
        "index" => "textures",
        _ => return None,
    })
}

/// One structural edit of a glTF document, in place; a document without the needed parts is left
/// as it was. Objects are picked kind first, then one of that kind, so that an `images` entry
/// beside hundreds of accessors is as likely a target as an accessor.
pub fn mutate_structure(doc: &mut Value, rng: &mut Rng) {
    let mut paths = Vec::new();
    collect_paths(doc, &mut Vec::new(), &mut paths, 20_000);
    // Objects by kind (the root excluded: it is never a path).
    let mut objects: std::collections::BTreeMap<String, Vec<JsonPath>> = std::collections::BTreeMap::new();
    for path in &paths {
        if get_mut(doc, path).is_some_and(|v| v.is_object()) {
            objects.entry(kind_of(path)).or_default().push(path.clone());
        }
    }
    let pick_kind = |rng: &mut Rng, keep: &dyn Fn(&str) -> bool| -> Option<JsonPath> {
        let kinds: Vec<&String> = objects.keys().filter(|k| keep(k)).collect();
        if kinds.is_empty() {
            return None;
        }
        let of_kind = &objects[*choose(rng, &kinds)];
        Some(choose(rng, of_kind).clone())
    };
    match rng.below(5) {
        0 => {
            // A required member removed (for an image, its source or its MIME type).
            let Some(path) = pick_kind(rng, &|k| !required_members(k).is_empty()) else { return };
            let kind = kind_of(&path);
            let Some(Value::Object(map)) = get_mut(doc, &path) else { return };
            let present: Vec<&str> = required_members(&kind).iter().copied().filter(|m| map.contains_key(*m)).collect();
            if !present.is_empty() {
                let member = *choose(rng, &present);
                map.remove(member);
            }
        }
        1 => {
            // An object emptied: `{}` where an image, an accessor, a primitive... was.
            let Some(path) = pick_kind(rng, &|_| true) else { return };
            if let Some(target) = get_mut(doc, &path) {
                *target = json!({});
            }
        }
        2 => {
            // A reference pointed into another array's range: an index that exists, of the wrong
            // kind of object (or past the end of its own array).
            let references: Vec<(JsonPath, &'static str)> = paths
                .iter()
                .filter_map(|p| match p.last() {
                    Some(Step::Key(k)) => referenced_array(k).map(|a| (p.clone(), a)),
                    Some(Step::Index(_)) => match p.get(p.len().wrapping_sub(2)) {
                        Some(Step::Key(k)) if matches!(k.as_str(), "nodes" | "children" | "joints") => {
                            Some((p.clone(), "nodes"))
                        }
                        _ => None,
                    },
                    None => None,
                })
                .filter(|(p, _)| get_mut(doc, p).is_some_and(|v| v.is_u64()))
                .collect();
            if references.is_empty() {
                return;
            }
            let (path, own) = choose(rng, &references).clone();
            let own_len = doc.get(own).and_then(Value::as_array).map_or(0, Vec::len);
            let others: Vec<usize> = doc
                .as_object()
                .into_iter()
                .flat_map(|root| root.iter())
                .filter(|(k, _)| k.as_str() != own)
                .filter_map(|(_, v)| v.as_array().map(Vec::len))
                .filter(|&len| len > 0 && len != own_len)
                .collect();
            let Some(&len) = (!others.is_empty()).then(|| choose(rng, &others)) else { return };
            // The other array's last index, or any of its indices.
            let value = if rng.below(2) == 0 { len - 1 } else { index(rng, len) };
            if let Some(target) = get_mut(doc, &path) {
                *target = json!(value);
            }
        }
        3 => {
            // Entries of a top-level array dropped (the later ones' indices shift under their
            // references) or duplicated.
            let Some(root) = doc.as_object_mut() else { return };
            let arrays: Vec<String> = root
                .iter()
                .filter(|(_, v)| v.as_array().is_some_and(|a| !a.is_empty()))
                .map(|(k, _)| k.clone())
                .collect();
            if arrays.is_empty() {
                return;
            }
            let key = choose(rng, &arrays).clone();
            let Some(Value::Array(items)) = root.get_mut(&key) else { return };
            let i = index(rng, items.len());
            match rng.below(4) {
                0 => {
                    items.remove(i);
                }
                1 => {
                    let copy = items[i].clone();
                    items.insert(i, copy);
                }
                2 => {
                    let copy = items[i].clone();
                    items.push(copy);
                }
                _ => items.truncate(i),
            }
        }
        _ => {
            // A member's type changed: a number as a string, a string as a number, an object as
            // an array holding it, an array as an object, a boolean as a number, null as {}.
            let members: Vec<&JsonPath> = paths.iter().filter(|p| matches!(p.last(), Some(Step::Key(_)))).collect();
            if members.is_empty() {
                return;
            }
            let path = (*choose(rng, &members)).clone();
            let Some(target) = get_mut(doc, &path) else { return };
            *target = match std::mem::take(target) {
                Value::Number(n) => {
                    if rng.below(2) == 0 {
                        json!(n.to_string())
                    } else {
                        json!([n])
                    }
                }
                Value::String(s) => {
                    if rng.below(2) == 0 {
                        json!(s.len())
                    } else {
                        json!([s])
                    }
                }
                Value::Object(map) => {
                    if rng.below(2) == 0 {
                        json!([map])
                    } else {
                        Value::Array(map.into_iter().map(|(_, v)| v).collect())
                    }
                }
                Value::Array(items) => {
                    Value::Object(items.into_iter().enumerate().map(|(i, v)| (i.to_string(), v)).collect())
                }
                Value::Bool(b) => json!(u8::from(b)),
                Value::Null => json!({}),
            };
        }
    }
}
