//! `KHR_draco_mesh_compression`: [`decompress`] turns a glTF whose primitives carry Draco streams
//! into the plain document every reader here, and the gltf crate, understands: each compressed
//! primitive's accessors point at the decoded data in one appended buffer, and the extension is
//! gone from the primitives and from `extensionsUsed`/`extensionsRequired`
//! (<https://github.com/KhronosGroup/glTF/tree/main/extensions/2.0/Khronos/KHR_draco_mesh_compression>).
//! The importer (drafter-io) calls it once it has the buffers, so `drafter bake`, the batch, Python,
//! `drafter view` and the page all read Draco through this one place, and a bake writes the
//! decoded geometry without the extension.
//!
//! # The decoder, and why this one
//!
//! The codec is Google's; only the framing (which accessors, which buffer, the JSON) is ours. The
//! streams are decoded by `draco-oxide-decoder` (crates.io, MIT OR Apache-2.0, Re:Earth's pure-Rust
//! port of draco's decoder, bitstream 2.2: sequential and edgebreaker connectivity, every
//! prediction scheme, quantized and octahedral attributes), pinned exactly while it is an alpha and
//! patched in `vendor/` (below).
//! Compared on a 2-core VM:
//!
//! * **Correctness.** On the Khronos sample assets' Draco variants in `../shared/models`
//!   (GearboxAssy: 42 streams, 409,264 triangles; Buggy: 148 streams, 278,672 triangles) it gives
//!   the triangles of Google's own C++ decoder (Debian's `draco_decoder` 1.5.5) face for face, in
//!   the same order, with the same positions, and every triangle of the uncompressed siblings is
//!   found with the same winding and positions within the 11-bit quantization step.
//!   `tests/draco.rs` here and `cli/tests/draco.rs` keep that checked.
//! * **Build.** Pure Rust: nothing beyond cargo. It brings 23 crates (draco-oxide-core, kiddo,
//!   fixed, tracing-subscriber, …): about 33 s of CPU added to a clean release build (`docs/usage.md`).
//!   The C++ binding `draco-rs` (0.1.3, MIT) builds Google's library with CMake and generates its
//!   bindings with autocxx (libclang), build requirements drafter has nowhere else; here (Debian 12,
//!   GCC 12, CMake 3.25, libclang 22) it did not build at all: after 10.4 min (2 jobs, shared VM) the
//!   library was built and autocxx's generated C++ failed ("use of deleted function
//!   `draco::PointCloud::PointCloud(const draco::PointCloud&)`"). `draco_decoder` (0.0.31, "wip")
//!   compiles the C++ natively and loads Google's JavaScript decoder in the browser.
//! * **Browser.** A C++ library has no `wasm32-unknown-unknown` build without a C++ standard
//!   library (meshoptimizer compiles only because it needs no libc++), so `draco-rs` cannot go into
//!   the page; the Rust port compiles for it, adding about 50 KB gzip (`docs/web.md`).
//! * **License and maintenance.** Both MIT (draco-oxide: MIT OR Apache-2.0, as drafter). draco-oxide
//!   is an organisation's repository (reearth/draco-oxide) with 13 releases so far (alpha.0 to
//!   alpha.12), split into core and decoder crates; `draco-rs` is one author's binding
//!   (soraxas/draco-rs, 4 releases). An alpha is the risk taken: pinned exactly, checked by the
//!   tests below and the fuzzer, and patched here where they found a gap.
//!
//! # Hostile streams
//!
//! The decoder sizes its arrays from the counts in the stream, so before it runs, the stream's
//! header and connectivity counts are read here ([`preflight`]) and held against the glTF: the
//! face count must be the indices accessor's count / 3 (which the importer has already checked
//! against `--max-triangles`), and the vertex and symbol counts cannot exceed what that many faces
//! can use. A stream that decodes anything else than the accessors describe (components, types) is
//! refused, naming the primitive. One count deeper in the stream (texture-coordinate orientations,
//! a u32 that drove a loop and an allocation of up to 2^32 entries: 30-40 s for a mutated 2 KB
//! stream) is checked by a one-line patch of the decoder, `vendor/draco-oxide-decoder`
//! (`PATCHED.md`), until upstream has it. The decoder's own checks cover the rest, and a panic inside it
//! (one is known, see [`guarded`]) becomes the primitive's error; the fuzzer (`fuzz/`, a Draco seed
//! among the glTF and GLB ones) and `tests/draco.rs` mutate streams in every test run.
//!
//! # What is decoded, and the fallback rule
//!
//! * Every attribute the extension lists (positions, normals, texture coordinates, colors, joints,
//!   weights, generic `_NAME` attributes): dequantized (positions, texture coordinates, generic
//!   attributes quantized over a box; normals from their octahedral form) to the component type of
//!   the primitive's accessor, which Draco's decoded type must match (or be an integer written to a
//!   `FLOAT` accessor). Elements are padded to 4 bytes with a `byteStride` where glTF asks.
//! * Faces become the indices accessor (its component type kept when every index fits, else
//!   `UNSIGNED_INT`); a primitive without one gets one. Only `TRIANGLES` primitives are read: the
//!   extension also allows `TRIANGLE_STRIP`, which no exporter in reach writes and Babylon.js
//!   refuses too, so it is refused rather than guessed.
//! * Accessor `count`s follow the decoded stream; `min`/`max` are computed again from the decoded
//!   values (required for `POSITION`, and the Khronos validator checks them against the data).
//! * **Fallback:** when an accessor also has a `bufferView` (uncompressed data beside the stream, as
//!   a file that lists the extension in `extensionsUsed` only may have), the extension allows
//!   either; drafter always decodes the Draco stream and ignores that data, so a file reads the
//!   same whether or not its writer kept a fallback, and the one path is the tested one.
//! * Attributes of a compressed primitive that the extension does not list stay as they are; their
//!   count must equal the decoded point count.

use std::fmt;

use draco_oxide_core::attribute::{Attribute, ComponentDataType};
use serde_json::Value;

use crate::gltf::{Accessor, Buffer, BufferView, DracoPrimitive, Extensible, Root};

/// The extension's name.
pub const EXTENSION: &str = "KHR_draco_mesh_compression";

/// Why a document's Draco data could not be decoded. The place is a JSON pointer.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DracoError {
    pub place: String,
    pub message: String,
}

impl fmt::Display for DracoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {EXTENSION}: {}", self.place, self.message)
    }
}

impl std::error::Error for DracoError {}

fn error(place: &str, message: impl Into<String>) -> DracoError {
    DracoError { place: place.to_owned(), message: message.into() }
}

/// A document with its Draco streams decoded.
#[derive(Clone, Debug, PartialEq)]
pub struct Decompressed {
    /// The JSON without the extension; its last buffer (no `uri`) is [`Self::buffer`].
    pub json: String,
    /// The decoded data: indices and attributes, each in a buffer view of its own.
    pub buffer: Vec<u8>,
    /// Primitives decoded, and their triangles.
    pub primitives: usize,
    pub triangles: usize,
}

/// Whether the JSON mentions the extension (a cheap test before [`decompress`]).
pub fn mentions_extension(json: &[u8]) -> bool {
    let name = EXTENSION.as_bytes();
    json.windows(name.len()).any(|w| w == name)
}

/// Decodes every Draco primitive of the glTF `json`, whose buffers (in order, loaded and
/// length-checked) are `buffers`. `None` when no primitive uses the extension.
pub fn decompress(json: &[u8], buffers: &[Vec<u8>]) -> Result<Option<Decompressed>, DracoError> {
    if !mentions_extension(json) {
        return Ok(None);
    }
    let mut root = Root::from_slice(json).map_err(|e| error("", format!("JSON: {e}")))?;
    let declared_buffers = root.buffers().len();
    if declared_buffers != buffers.len() {
        return Err(error("/buffers", format!("{declared_buffers} buffers listed, {} loaded", buffers.len())));
    }
    let mut out = Output { bin: Vec::new(), buffer: declared_buffers, primitives: 0, triangles: 0 };
    // Accessors already written, with the stream and attribute that filled them: a second
    // primitive naming the same accessor for the same data shares it, for other data gets a copy.
    let mut filled: std::collections::HashMap<usize, (usize, Option<u64>)> = std::collections::HashMap::new();
    for m in 0..root.meshes().len() {
        for p in 0..root.meshes()[m].primitives().len() {
            let place = format!("/meshes/{m}/primitives/{p}");
            let Some(ext) = root.meshes()[m].primitives()[p].extension::<DracoPrimitive>(EXTENSION) else { continue };
            let ext = ext.map_err(|e| error(&format!("{place}/extensions/{EXTENSION}"), e.to_string()))?;
            decode_primitive(&mut root, (m, p), &ext, buffers, &mut out, &mut filled, &place)?;
        }
    }
    if out.primitives == 0 {
        return Ok(None);
    }
    for list in [&mut root.extensions_used, &mut root.extensions_required] {
        if let Some(names) = list {
            names.retain(|name| name != EXTENSION);
            if names.is_empty() {
                *list = None;
            }
        }
    }
    pad4(&mut out.bin);
    let buffer = Buffer { byte_length: Some(out.bin.len() as u64), ..Buffer::default() };
    root.buffers.get_or_insert_default().push(buffer);
    let json = Value::from(root).to_string();
    Ok(Some(Decompressed { json, buffer: out.bin, primitives: out.primitives, triangles: out.triangles }))
}

/// The decoded data being gathered, and the index its buffer will have.
struct Output {
    bin: Vec<u8>,
    buffer: usize,
    primitives: usize,
    triangles: usize,
}

impl Output {
    /// Appends `bytes` as a buffer view (with `stride` when given); its index.
    fn view(&mut self, root: &mut Root, bytes: &[u8], stride: Option<usize>) -> usize {
        pad4(&mut self.bin);
        let view = BufferView {
            buffer: Some(self.buffer as u64),
            byte_offset: Some(self.bin.len() as u64),
            byte_length: Some(bytes.len() as u64),
            byte_stride: stride.map(|s| s as u64),
            ..BufferView::default()
        };
        self.bin.extend_from_slice(bytes);
        let views = root.buffer_views.get_or_insert_default();
        views.push(view);
        views.len() - 1
    }
}

fn pad4(bin: &mut Vec<u8>) {
    bin.resize(bin.len().next_multiple_of(4), 0);
}

/// Accessor `index` of `root`, to edit (it exists: claimed or pushed before).
fn accessor_mut(root: &mut Root, index: usize) -> &mut Accessor {
    &mut root.accessors.get_or_insert_default()[index]
}

/// The bytes of the Draco stream in buffer view `view`, checked against its buffer.
fn stream_bytes<'a>(root: &Root, view: u64, buffers: &'a [Vec<u8>], place: &str) -> Result<&'a [u8], DracoError> {
    let place = format!("{place}/extensions/{EXTENSION}/bufferView");
    let v = usize::try_from(view)
        .ok()
        .and_then(|v| root.buffer_views().get(v))
        .ok_or_else(|| error(&place, format!("buffer view {view} does not exist")))?;
    let buffer = v.buffer.and_then(|b| usize::try_from(b).ok()).and_then(|b| buffers.get(b));
    let Some(buffer) = buffer else { return Err(error(&place, format!("buffer view {view} names no loaded buffer"))) };
    let offset = v.byte_offset.unwrap_or(0);
    let length = v.byte_length.unwrap_or(0);
    offset
        .checked_add(length)
        .filter(|&end| end <= buffer.len() as u64)
        .map(|end| &buffer[offset as usize..end as usize])
        .ok_or_else(|| {
            error(
                &place,
                format!("buffer view {view} ({length} bytes at {offset}) lies outside its buffer of {}", buffer.len()),
            )
        })
}

/// A glTF accessor's element description.
struct AccessorType {
    component: u64,
    components: usize,
}

fn accessor_type(accessor: &Accessor) -> Option<AccessorType> {
    let component = accessor.component_type?;
    let components = match accessor.kind.as_deref()? {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" => 4,
        _ => return None,
    };
    Some(AccessorType { component, components })
}

fn component_size(component: u64) -> Option<usize> {
    match component {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

/// The glTF componentType code of a decoded Draco component type, where glTF has one.
fn gltf_code(ty: ComponentDataType) -> Option<u64> {
    Some(match ty {
        ComponentDataType::I8 => 5120,
        ComponentDataType::U8 => 5121,
        ComponentDataType::I16 => 5122,
        ComponentDataType::U16 => 5123,
        ComponentDataType::U32 => 5125,
        ComponentDataType::F32 => 5126,
        _ => return None,
    })
}

/// Reads component `i` of `bytes` (little-endian, of Draco type `ty`) as f64.
fn component_value(ty: ComponentDataType, bytes: &[u8], i: usize) -> f64 {
    let at = |n: usize| &bytes[i * n..i * n + n];
    match ty {
        ComponentDataType::I8 => f64::from(at(1)[0] as i8),
        ComponentDataType::U8 => f64::from(at(1)[0]),
        ComponentDataType::I16 => f64::from(i16::from_le_bytes([at(2)[0], at(2)[1]])),
        ComponentDataType::U16 => f64::from(u16::from_le_bytes([at(2)[0], at(2)[1]])),
        ComponentDataType::I32 => f64::from(i32::from_le_bytes([at(4)[0], at(4)[1], at(4)[2], at(4)[3]])),
        ComponentDataType::U32 => f64::from(u32::from_le_bytes([at(4)[0], at(4)[1], at(4)[2], at(4)[3]])),
        ComponentDataType::F32 => f64::from(f32::from_le_bytes([at(4)[0], at(4)[1], at(4)[2], at(4)[3]])),
        _ => 0.0,
    }
}

/// The stream's counts that size the decoder's arrays, read before it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamCounts {
    /// Faces the connectivity declares.
    pub faces: u64,
    /// Vertices the connectivity declares: sequential `num_points`, edgebreaker's encoded vertices.
    pub vertices: u64,
    /// Edgebreaker's encoded symbols and split symbols (0 for sequential connectivity).
    pub symbols: u64,
    pub splits: u64,
}

/// Reads the header, the metadata (skipped) and the connectivity counts of a Draco mesh stream of
/// bitstream 2.2 (what the decoder reads), without allocating by any of them.
pub fn preflight(stream: &[u8]) -> Result<StreamCounts, String> {
    let mut r = Cursor { bytes: stream, at: 0 };
    if r.take(5)? != b"DRACO" {
        return Err("not a Draco stream (no DRACO magic)".into());
    }
    let (major, minor) = (r.u8()?, r.u8()?);
    if (major, minor) != (2, 2) {
        return Err(format!("Draco bitstream {major}.{minor} is not supported (2.2 is)"));
    }
    let geometry = r.u8()?;
    if geometry != 1 {
        return Err(format!("geometry type {geometry} is not a triangle mesh (point clouds are not read)"));
    }
    let method = r.u8()?;
    let flags = u16::from_le_bytes([r.u8()?, r.u8()?]);
    if flags & 0x8000 != 0 {
        let attributes = r.varint()?;
        for _ in 0..attributes {
            r.varint()?;
            r.skip_metadata(0)?;
        }
        r.skip_metadata(0)?;
    }
    match method {
        0 => {
            let faces = r.varint()?;
            let points = r.varint()?;
            Ok(StreamCounts { faces, vertices: points, symbols: 0, splits: 0 })
        }
        1 => {
            let _traversal = r.u8()?;
            let vertices = r.varint()?;
            let faces = r.varint()?;
            let _attribute_data = r.u8()?;
            let symbols = r.varint()?;
            let splits = r.varint()?;
            Ok(StreamCounts { faces, vertices, symbols, splits })
        }
        other => Err(format!("encoder method {other} is unknown")),
    }
}

struct Cursor<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else { return Err(format!("the stream ends at byte {}", self.bytes.len())) };
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }

    /// An unsigned LEB128 number of at most 64 bits.
    fn varint(&mut self) -> Result<u64, String> {
        let mut value = 0u64;
        for shift in (0..64).step_by(7) {
            let byte = self.u8()?;
            value |= u64::from(byte & 0x7f) << shift;
            if byte & 0x80 == 0 {
                return Ok(value);
            }
        }
        Err("a number in the stream is longer than 64 bits".into())
    }

    fn skip_metadata(&mut self, level: usize) -> Result<(), String> {
        if level > 32 {
            return Err("metadata nested too deeply".into());
        }
        let entries = self.varint()?;
        for _ in 0..entries {
            let name = usize::from(self.u8()?);
            self.take(name)?;
            let size = usize::try_from(self.varint()?).map_err(|_| "metadata entry too large".to_owned())?;
            self.take(size)?;
        }
        let children = self.varint()?;
        for _ in 0..children {
            let name = usize::from(self.u8()?);
            self.take(name)?;
            self.skip_metadata(level + 1)?;
        }
        Ok(())
    }
}

/// `f` on the decoder, with a panic inside it turned into an error. draco-oxide 0.1.0-alpha.12
/// panics on some hostile streams: `tests/draco.rs`'s mutations found `1u64 << bits` for a
/// quantization of 64 or more bits (`attribute/dequantize.rs:129`, an overflow that panics where
/// overflow checks are on and wraps in release builds). Until the decoder checks its input
/// everywhere, its panics end here as the primitive's error (the panic hook still prints the
/// message); a build with `panic = "abort"` (the browser page) aborts instead.
fn guarded<T>(f: impl FnOnce() -> Result<T, draco_oxide_decoder::Err> + std::panic::UnwindSafe) -> Result<T, String> {
    match std::panic::catch_unwind(f) {
        Ok(Ok(value)) => Ok(value),
        Ok(Err(e)) => Err(format!("decoding: {e}")),
        Err(_) => Err("decoding: the stream is malformed (the decoder gave up)".to_owned()),
    }
}

fn decode_guarded(stream: &[u8]) -> Result<draco_oxide_core::mesh::Mesh, String> {
    guarded(|| draco_oxide_decoder::decode_mesh(stream))
}

/// Decodes the stream of primitive `(m, p)` and points its accessors at the decoded data.
fn decode_primitive(
    root: &mut Root,
    (m, p): (usize, usize),
    ext: &DracoPrimitive,
    buffers: &[Vec<u8>],
    out: &mut Output,
    filled: &mut std::collections::HashMap<usize, (usize, Option<u64>)>,
    place: &str,
) -> Result<(), DracoError> {
    let ext_place = format!("{place}/extensions/{EXTENSION}");
    let view = ext.buffer_view.ok_or_else(|| error(&ext_place, "bufferView is missing"))?;
    let Some(named) = &ext.attributes else { return Err(error(&ext_place, "attributes is missing")) };
    let prim = root.meshes()[m].primitives()[p].clone();
    let mode = prim.mode.unwrap_or(4);
    if mode != 4 {
        // The extension allows TRIANGLE_STRIP too; no exporter in reach writes it (Babylon.js
        // refuses it as well), so it is refused rather than guessed.
        return Err(error(place, format!("mode {mode}: only Draco-compressed TRIANGLES (mode 4) are read")));
    }
    let stream = stream_bytes(root, view, buffers, place)?;
    let counts = preflight(stream).map_err(|m| error(&ext_place, m))?;

    // The indices accessor's count, which the importer has held against --max-triangles, is the
    // face count the stream must declare; every other count is bounded by it.
    // (Without indices, POSITION's count is the corner count, as for any non-indexed primitive.)
    let indices = prim.indices.and_then(|a| usize::try_from(a).ok());
    let (listed_by, counted) = match indices {
        Some(a) => ("the indices accessor", Some(a as u64)),
        None => ("POSITION (no indices)", prim.attribute("POSITION")),
    };
    let listed = counted
        .and_then(|a| root.accessor_count(a))
        .ok_or_else(|| error(place, format!("{listed_by} names no accessor")))?;
    if counts.faces.checked_mul(3) != Some(listed) {
        return Err(error(
            &ext_place,
            format!(
                "the stream declares {} faces; {listed_by} lists {listed} corners (3 per face required)",
                counts.faces
            ),
        ));
    }
    // Edgebreaker: one symbol per face, a vertex at most per corner, a split at most per face.
    let corners = counts.faces.saturating_mul(3);
    if counts.vertices.saturating_add(counts.splits) > corners
        || counts.symbols > counts.faces
        || counts.splits > counts.faces
    {
        return Err(error(
            &ext_place,
            format!(
                "the stream declares {} vertices, {} symbols and {} splits for {} faces",
                counts.vertices, counts.symbols, counts.splits, counts.faces
            ),
        ));
    }

    let mesh = decode_guarded(stream).map_err(|m| error(&ext_place, m))?;
    if mesh.faces.len() as u64 != counts.faces {
        return Err(error(&ext_place, format!("decoded {} faces, declared {}", mesh.faces.len(), counts.faces)));
    }

    // Attributes: the point count is the decoded one, the same for every attribute.
    let mut points: Option<usize> = None;
    let mut attributes = std::collections::BTreeMap::new();
    for (name, id) in named {
        let attr_place = format!("{place}/attributes/{name}");
        let accessor = prim
            .attribute(name)
            .and_then(|a| usize::try_from(a).ok())
            .ok_or_else(|| error(&attr_place, "the extension names an attribute the primitive does not list"))?;
        let attribute = mesh.attributes.iter().find(|a| a.get_id().as_usize() as u64 == *id).ok_or_else(|| {
            error(&format!("{ext_place}/attributes/{name}"), format!("the stream has no attribute {id}"))
        })?;
        let n = attribute.len();
        if *points.get_or_insert(n) != n {
            return Err(error(&attr_place, format!("decodes {n} points, another attribute {}", points.unwrap_or(0))));
        }
        let written = write_attribute(root, out, accessor, attribute, filled, (view as usize, Some(*id)), &attr_place)?;
        attributes.insert(name.clone(), written as u64);
    }
    let points = points.unwrap_or(0);
    if points == 0 {
        return Err(error(&ext_place, "the stream decodes no points"));
    }
    // Faces, checked against the points.
    let mut flat = Vec::with_capacity(mesh.faces.len() * 3);
    for face in &mesh.faces {
        for &corner in face {
            let index = usize::from(corner);
            if index >= points {
                return Err(error(&ext_place, format!("a face uses point {index} of {points}")));
            }
            flat.push(index as u32);
        }
    }
    let written_indices = write_indices(root, out, indices, &flat, filled, (view as usize, None), place)?;

    // Attributes the stream does not carry must already have one element per decoded point.
    for (name, &accessor) in prim.attributes.iter().flatten() {
        if attributes.contains_key(name) {
            continue;
        }
        let count = root.accessor_count(accessor);
        if count != Some(points as u64) {
            return Err(error(
                &format!("{place}/attributes/{name}"),
                format!("uncompressed beside a Draco stream of {points} points, but has {count:?} elements"),
            ));
        }
        attributes.insert(name.clone(), accessor);
    }

    let meshes = root.meshes.get_or_insert_default();
    let target = &mut meshes[m].primitives.get_or_insert_default()[p];
    target.attributes = Some(attributes);
    target.indices = Some(written_indices as u64);
    target.remove_extension(EXTENSION);
    out.primitives += 1;
    out.triangles += mesh.faces.len();
    Ok(())
}

/// The accessor to write for `source` (an index into `accessors`) filled from `origin`: itself the
/// first time, shared when the same data filled it before, else a copy appended.
fn claim_accessor(
    root: &mut Root,
    source: usize,
    filled: &mut std::collections::HashMap<usize, (usize, Option<u64>)>,
    origin: (usize, Option<u64>),
) -> (usize, bool) {
    match filled.get(&source) {
        None => {
            filled.insert(source, origin);
            (source, false)
        }
        Some(&before) if before == origin => (source, true),
        Some(_) => {
            let copy = root.accessors().get(source).cloned().unwrap_or_default();
            let accessors = root.accessors.get_or_insert_default();
            accessors.push(copy);
            let index = accessors.len() - 1;
            filled.insert(index, origin);
            (index, false)
        }
    }
}

/// Writes a decoded attribute into the accessor `source` describes; the accessor written.
fn write_attribute(
    root: &mut Root,
    out: &mut Output,
    source: usize,
    attribute: &Attribute,
    filled: &mut std::collections::HashMap<usize, (usize, Option<u64>)>,
    origin: (usize, Option<u64>),
    place: &str,
) -> Result<usize, DracoError> {
    let described =
        root.accessors().get(source).ok_or_else(|| error(place, format!("accessor {source} does not exist")))?;
    let Some(ty) = accessor_type(described) else {
        return Err(error(place, format!("accessor {source}: a Draco attribute is SCALAR or VEC2-4 of a glTF type")));
    };
    let Some(size) = component_size(ty.component) else {
        return Err(error(place, format!("accessor {source}: componentType {} is not glTF's", ty.component)));
    };
    let decoded = attribute.get_component_type();
    let components = attribute.get_num_components();
    if components != ty.components {
        return Err(error(place, format!("decodes {components} components; accessor {source} has {}", ty.components)));
    }
    let same = gltf_code(decoded) == Some(ty.component);
    if !(same || ty.component == 5126 && decoded.is_integer()) {
        return Err(error(
            place,
            format!("decodes {decoded:?} components; accessor {source} has componentType {}", ty.component),
        ));
    }
    let (index, shared) = claim_accessor(root, source, filled, origin);
    if shared {
        return Ok(index);
    }
    let values = attribute.get_data_as_bytes();
    let value_size = decoded.size() * components;
    let unique = attribute.num_unique_values();
    if values.len() != unique * value_size {
        return Err(error(place, "the decoder's values do not fill their attribute"));
    }
    let map = attribute.point_map_as_slice();
    let points = attribute.len();
    let element = size * components;
    let stride = element.next_multiple_of(4);
    let mut bytes = Vec::with_capacity(points * stride);
    let mut min = vec![f64::INFINITY; components];
    let mut max = vec![f64::NEG_INFINITY; components];
    for point in 0..points {
        let value = match map {
            Some(map) => usize::from(map[point]),
            None => point,
        };
        if value >= unique {
            return Err(error(place, format!("point {point} names value {value} of {unique}")));
        }
        let start = bytes.len();
        for c in 0..components {
            let v = component_value(decoded, values, value * components + c);
            min[c] = min[c].min(v);
            max[c] = max[c].max(v);
            if same {
                let at = (value * components + c) * size;
                bytes.extend_from_slice(&values[at..at + size]);
            } else {
                bytes.extend_from_slice(&(v as f32).to_le_bytes());
            }
        }
        bytes.resize(start + stride, 0);
    }
    let view = out.view(root, &bytes, (stride != element).then_some(stride));
    let accessor = accessor_mut(root, index);
    accessor.buffer_view = Some(view as u64);
    accessor.count = Some(points as u64);
    accessor.byte_offset = None;
    accessor.sparse = None;
    let number = |v: f64| if ty.component == 5126 { Value::from(v as f32) } else { Value::from(v as i64) };
    accessor.min = Some(Value::Array(min.into_iter().map(number).collect()));
    accessor.max = Some(Value::Array(max.into_iter().map(number).collect()));
    Ok(index)
}

/// Writes the faces into the indices accessor `source`; the accessor written.
fn write_indices(
    root: &mut Root,
    out: &mut Output,
    source: Option<usize>,
    flat: &[u32],
    filled: &mut std::collections::HashMap<usize, (usize, Option<u64>)>,
    origin: (usize, Option<u64>),
    place: &str,
) -> Result<usize, DracoError> {
    let largest = flat.iter().copied().max().unwrap_or(0);
    let (index, component) = match source {
        Some(source) => {
            let component = root.accessors().get(source).and_then(|a| a.component_type);
            let component = match component {
                Some(5121) if largest <= 0xff => 5121,
                Some(5121 | 5123) if largest <= 0xffff => 5123,
                Some(5121 | 5123 | 5125) => 5125,
                other => {
                    return Err(error(
                        &format!("{place}/indices"),
                        format!("componentType {other:?} is not an index type"),
                    ));
                }
            };
            let (index, shared) = claim_accessor(root, source, filled, origin);
            if shared {
                return Ok(index);
            }
            (index, component)
        }
        None => {
            let accessors = root.accessors.get_or_insert_default();
            accessors.push(Accessor::default());
            (accessors.len() - 1, if largest <= 0xffff { 5123 } else { 5125 })
        }
    };
    let bytes: Vec<u8> = match component {
        5121 => flat.iter().map(|&i| i as u8).collect(),
        5123 => flat.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
        _ => flat.iter().flat_map(|i| i.to_le_bytes()).collect(),
    };
    let view = out.view(root, &bytes, None);
    let smallest = flat.iter().copied().min().unwrap_or(0);
    let accessor = accessor_mut(root, index);
    accessor.buffer_view = Some(view as u64);
    accessor.component_type = Some(component);
    accessor.count = Some(flat.len() as u64);
    accessor.kind = Some("SCALAR".into());
    accessor.byte_offset = None;
    accessor.sparse = None;
    accessor.normalized = None;
    accessor.min = Some(Value::from(vec![smallest]));
    accessor.max = Some(Value::from(vec![largest]));
    Ok(index)
}

/// How one attribute of a stream is quantized: Draco's step (the box's largest side over
/// `2^bits − 1`), for the tests and for reporting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantization {
    /// The attribute's id in the stream (what the extension's `attributes` map names).
    pub id: u64,
    pub bits: u8,
    pub step: f32,
}

/// The quantized attributes of a Draco stream (octahedral normals and raw attributes are left out).
pub fn quantization(stream: &[u8]) -> Result<Vec<Quantization>, String> {
    preflight(stream)?;
    let portable = guarded(|| draco_oxide_decoder::decode_mesh_portable(stream))?;
    Ok(portable
        .mesh
        .attributes
        .iter()
        .zip(&portable.transforms)
        .filter_map(|(attribute, transform)| match transform {
            draco_oxide_decoder::AttributeTransform::Quantized { bits, delta_max, .. } => Some(Quantization {
                id: attribute.get_id().as_usize() as u64,
                bits: *bits,
                step: delta_max / ((1u64 << (*bits).min(31)) - 1).max(1) as f32,
            }),
            _ => None,
        })
        .collect())
}
