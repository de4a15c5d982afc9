//! `EXT_meshopt_compression` on GLB files: [`compress_glb`] encodes the buffer views of a plain
//! GLB (what `drafter bake --compress` writes), [`decompress_glb`] turns a compressed GLB back into
//! the plain form that every reader here, and the gltf crate, understands.
//!
//! The codec is meshoptimizer's, through the `meshopt` crate (a maintained binding; the format is
//! its author's, so no codec is written here). Only the framing is ours: which views to encode,
//! in which mode, and the JSON of the extension
//! (<https://github.com/KhronosGroup/glTF/tree/main/extensions/2.0/Vendor/EXT_meshopt_compression>).
//!
//! # What is encoded
//!
//! Compression is lossless: no filters, no quantization. A reader decodes exactly the bytes the
//! plain file holds, so everything computed on those bytes (the silhouette hierarchies, which are
//! exact with respect to the stored normals and positions) stays exact without a rebuild.
//!
//! * Index views of triangle primitives: `TRIANGLES` mode when the decoded indices come back
//!   identical (checked on every view), else `INDICES` mode.
//! * Every other view that accessors read, whose length is a multiple of 4: `ATTRIBUTES` mode
//!   with the view's stride, or 4 for tightly packed scalars, vertex codec version 0 (what the
//!   extension requires).
//! * A view is encoded only if that makes it smaller; images and views no accessor reads stay
//!   as they are. The extension is listed as required only when a view was encoded.
//!
//! The encoded streams live in the GLB's binary chunk (buffer 0); the decoded views point into a
//! second buffer without data that the extension marks as `fallback`, as gltfpack writes it.
//!
//! # Decoding untrusted files
//!
//! [`decompress_glb`] checks every range against the binary chunk, and refuses a decoded size
//! beyond [`MAX_EXPANSION`] times its encoded stream (the codecs cannot expand more than that),
//! so a small file cannot make it allocate gigabytes. Streams must lie in the binary chunk;
//! the filters `OCTAHEDRAL`, `QUATERNION`, `EXPONENTIAL` and `COLOR` are decoded (gltfpack's
//! `-cc` output uses them).

use std::fmt;

use rayon::prelude::*;
use serde_json::Value;

use crate::glb;
use crate::gltf::{Accessor, Buffer, Extensible, MeshoptBuffer, MeshoptBufferView, Root};

/// The extension's name.
pub const EXTENSION: &str = "EXT_meshopt_compression";

/// The largest ratio of decoded to encoded bytes accepted when decoding. meshoptimizer's vertex
/// codec stores at least 2 header bits per 16 bytes of a byte channel (at most 64×), its index
/// codecs at least 4 bits per index; a margin on top.
pub const MAX_EXPANSION: usize = 128;

/// Why a GLB could not be compressed or decompressed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MeshoptError {
    Glb(glb::GlbError),
    /// The JSON is not what the extension (or glTF) requires; the message names the place.
    Invalid(String),
}

impl fmt::Display for MeshoptError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Glb(e) => write!(f, "{e}"),
            Self::Invalid(m) => write!(f, "{EXTENSION}: {m}"),
        }
    }
}

impl std::error::Error for MeshoptError {}

impl From<glb::GlbError> for MeshoptError {
    fn from(e: glb::GlbError) -> Self {
        Self::Glb(e)
    }
}

fn invalid(message: impl Into<String>) -> MeshoptError {
    MeshoptError::Invalid(message.into())
}

/// What [`compress_glb`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct CompressionStats {
    /// Buffer views in the file.
    pub views: usize,
    /// Views stored encoded.
    pub encoded_views: usize,
    /// Bytes of the encoded views before and after encoding.
    pub encoded_bytes_before: u64,
    pub encoded_bytes_after: u64,
    /// The whole file before and after.
    pub file_bytes_before: u64,
    pub file_bytes_after: u64,
}

impl fmt::Display for CompressionStats {
    /// One line: views encoded, their bytes, and the whole file (plain → compressed).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ratio = |a: u64, b: u64| if b > 0 { a as f64 / b as f64 } else { 0.0 };
        let n = |x: u64| drafter_core::thousands(x as usize);
        write!(
            f,
            "{EXTENSION}: {} of {} buffer views, {} → {} bytes ({:.2}×); file {} → {} bytes ({:.2}×)",
            self.encoded_views,
            self.views,
            n(self.encoded_bytes_before),
            n(self.encoded_bytes_after),
            ratio(self.encoded_bytes_before, self.encoded_bytes_after),
            n(self.file_bytes_before),
            n(self.file_bytes_after),
            ratio(self.file_bytes_before, self.file_bytes_after),
        )
    }
}

/// How a view is encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

impl Mode {
    fn name(self) -> &'static str {
        match self {
            Mode::Attributes => "ATTRIBUTES",
            Mode::Triangles => "TRIANGLES",
            Mode::Indices => "INDICES",
        }
    }
}

/// Whether the JSON chunk of a GLB mentions the extension (a cheap test before [`decompress_glb`]).
pub fn mentions_extension(json: &[u8]) -> bool {
    let name = EXTENSION.as_bytes();
    json.windows(name.len()).any(|w| w == name)
}

fn parse(json: &[u8]) -> Result<Root, MeshoptError> {
    Root::from_slice(json).map_err(|e| invalid(format!("JSON: {e}")))
}

fn frame(doc: Root, bin: &[u8]) -> Result<Vec<u8>, MeshoptError> {
    let json = serde_json::to_vec(&Value::from(doc)).map_err(|e| invalid(format!("JSON: {e}")))?;
    Ok(glb::write(&json, bin)?)
}

/// Bytes of one element of an accessor, from its componentType and type.
fn element_size(accessor: &Accessor) -> Option<u64> {
    let components = crate::accessor::components(accessor.kind.as_deref()?)?;
    Some((accessor.component()?.size() * components) as u64)
}

/// The extension on a buffer view, if it has it.
fn encoding(view: &crate::gltf::BufferView) -> Option<serde_json::Result<MeshoptBufferView>> {
    view.extension(EXTENSION)
}

/// Calls `f` with the vertex codec's element type for `stride` (a multiple of 4, at most 64).
macro_rules! with_stride {
    ($stride:expr, $f:ident, $($arg:expr),*) => {
        match $stride {
            4 => $f::<1>($($arg),*),
            8 => $f::<2>($($arg),*),
            12 => $f::<3>($($arg),*),
            16 => $f::<4>($($arg),*),
            20 => $f::<5>($($arg),*),
            24 => $f::<6>($($arg),*),
            28 => $f::<7>($($arg),*),
            32 => $f::<8>($($arg),*),
            36 => $f::<9>($($arg),*),
            40 => $f::<10>($($arg),*),
            44 => $f::<11>($($arg),*),
            48 => $f::<12>($($arg),*),
            52 => $f::<13>($($arg),*),
            56 => $f::<14>($($arg),*),
            60 => $f::<15>($($arg),*),
            64 => $f::<16>($($arg),*),
            _ => None,
        }
    };
}

fn words<const K: usize>(bytes: &[u8]) -> Vec<[u32; K]> {
    bytes
        .chunks_exact(4 * K)
        .map(|e| std::array::from_fn(|i| u32::from_le_bytes([e[4 * i], e[4 * i + 1], e[4 * i + 2], e[4 * i + 3]])))
        .collect()
}

fn bytes_of<const K: usize>(elements: &[[u32; K]]) -> Vec<u8> {
    elements.iter().flatten().flat_map(|w| w.to_le_bytes()).collect()
}

/// One vertex of `4·K` bytes, as the vertex codec sees it (its size is the stride).
#[derive(Clone, Copy)]
#[repr(transparent)]
struct Element<const K: usize>([u32; K]);

impl<const K: usize> Default for Element<K> {
    fn default() -> Self {
        Self([0; K])
    }
}

fn encode_attributes<const K: usize>(bytes: &[u8]) -> Option<Vec<u8>> {
    let elements: Vec<Element<K>> = words::<K>(bytes).into_iter().map(Element).collect();
    // Version 0: the one EXT_meshopt_compression decoders must read.
    meshopt::encode_vertex_buffer_level(&elements, 2, Some(0)).ok()
}

fn decode_attributes<const K: usize>(encoded: &[u8], count: usize) -> Option<Vec<u8>> {
    let elements = meshopt::decode_vertex_buffer::<Element<K>>(encoded, count).ok()?;
    Some(elements.iter().flat_map(|e| e.0).flat_map(u32::to_le_bytes).collect())
}

fn indices_of(bytes: &[u8], size: usize) -> Vec<u32> {
    match size {
        2 => bytes.chunks_exact(2).map(|c| u32::from(u16::from_le_bytes([c[0], c[1]]))).collect(),
        _ => bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect(),
    }
}

fn index_bytes(indices: &[u32], size: usize) -> Vec<u8> {
    match size {
        2 => indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(),
        _ => indices.iter().flat_map(|i| i.to_le_bytes()).collect(),
    }
}

fn decode_indices(encoded: &[u8], count: usize, mode: Mode) -> Option<Vec<u32>> {
    match mode {
        Mode::Triangles => meshopt::decode_index_buffer::<u32>(encoded, count).ok(),
        _ => meshopt::decode_index_sequence::<u32>(encoded, count).ok(),
    }
}

/// The encoded stream of one view's bytes, if some mode gives one that decodes back exactly and
/// is smaller.
fn encode_view(bytes: &[u8], stride: usize, index: bool) -> Option<(Vec<u8>, Mode)> {
    let decodes_back = |encoded: &[u8], mode: Mode| -> bool {
        let count = bytes.len() / stride;
        let decoded = match mode {
            Mode::Attributes => with_stride!(stride, decode_attributes, encoded, count),
            _ => decode_indices(encoded, count, mode).map(|i| index_bytes(&i, stride)),
        };
        decoded.as_deref() == Some(bytes)
    };
    let candidate = if index {
        let indices = indices_of(bytes, stride);
        let vertex_count = indices.iter().max().map_or(0, |&m| m as usize + 1);
        let triangles = indices
            .len()
            .is_multiple_of(3)
            .then(|| meshopt::encode_index_buffer(&indices, vertex_count).ok())
            .flatten()
            .filter(|e| decodes_back(e, Mode::Triangles))
            .map(|e| (e, Mode::Triangles));
        triangles.or_else(|| {
            meshopt::encode_index_sequence(&indices, vertex_count)
                .ok()
                .filter(|e| decodes_back(e, Mode::Indices))
                .map(|e| (e, Mode::Indices))
        })
    } else {
        with_stride!(stride, encode_attributes, bytes)
            .filter(|e| decodes_back(e, Mode::Attributes))
            .map(|e| (e, Mode::Attributes))
    };
    candidate.filter(|(e, _)| e.len() < bytes.len())
}

fn lcm(a: usize, b: usize) -> usize {
    let gcd = |mut x: usize, mut y: usize| {
        while y != 0 {
            (x, y) = (y, x % y);
        }
        x
    };
    a / gcd(a, b) * b
}

fn pad4(bin: &mut Vec<u8>) {
    bin.resize(bin.len().next_multiple_of(4), 0);
}

/// `glb` with its buffer views encoded where that pays (see the module docs), and what was done.
/// A GLB that already uses the extension, or whose views are not all in its binary chunk, is
/// returned unchanged.
pub fn compress_glb(glb_bytes: &[u8]) -> Result<(Vec<u8>, CompressionStats), MeshoptError> {
    let chunks = glb::split(glb_bytes)?;
    let mut doc = parse(chunks.json)?;
    let bin = chunks.bin.unwrap_or(&[]);
    let mut stats = CompressionStats {
        views: doc.buffer_views().len(),
        file_bytes_before: glb_bytes.len() as u64,
        file_bytes_after: glb_bytes.len() as u64,
        ..CompressionStats::default()
    };
    let unchanged = |stats: &CompressionStats| (glb_bytes.to_vec(), stats.clone());
    let single_buffer = doc.buffers().len() == 1 && doc.buffers()[0].uri.is_none();
    if mentions_extension(chunks.json) || !single_buffer {
        return Ok(unchanged(&stats));
    }

    // What reads each view: index accessors of triangle primitives, and element sizes.
    let views = doc.buffer_views.take().unwrap_or_default();
    let accessors = doc.accessors();
    let mut index_view = vec![false; views.len()];
    let mut other_use = vec![false; views.len()];
    let mut element = vec![None::<u64>; views.len()];
    let mut triangle_index_accessors = std::collections::HashSet::new();
    for mesh in doc.meshes() {
        for prim in mesh.primitives() {
            if prim.mode.unwrap_or(4) == 4
                && let Some(a) = prim.indices
            {
                triangle_index_accessors.insert(a);
            }
        }
    }
    for (a, accessor) in accessors.iter().enumerate() {
        let Some(v) = accessor.buffer_view.map(|v| v as usize).filter(|&v| v < views.len()) else { continue };
        if triangle_index_accessors.contains(&(a as u64)) {
            index_view[v] = true;
        } else {
            other_use[v] = true;
        }
        let size = element_size(accessor);
        element[v] = match (element[v], size) {
            (None, s) => s,
            (Some(x), Some(s)) if x == s => Some(x),
            _ => Some(0),
        };
    }

    // Each view's bytes, codec stride and whether it is encoded, then every view encoded at once
    // on the thread pool (the views are encoded independently), then the new buffer assembled in
    // view order.
    struct Plan<'a> {
        bytes: &'a [u8],
        stride: usize,
        index: bool,
        encodable: bool,
    }
    let mut plans = Vec::with_capacity(views.len());
    for (v, view) in views.iter().enumerate() {
        let (offset, length) = (view.byte_offset.unwrap_or(0) as usize, view.byte_length.unwrap_or(0) as usize);
        let Some(bytes) = offset.checked_add(length).and_then(|end| bin.get(offset..end)) else {
            return Ok(unchanged(&stats));
        };
        // The codec's stride: the view's, or for tightly packed elements the smallest multiple of
        // both the element and 4 (two 6-byte SHORT VEC3 silhouette normals make one 12-byte
        // vertex; four bytes of edge visibility one 4-byte vertex).
        let stride = match (view.byte_stride, element[v]) {
            (Some(s), _) => s as usize,
            (None, Some(e)) if e > 0 => lcm(e as usize, 4),
            (None, _) => 0,
        };
        let index = index_view[v] && !other_use[v];
        let stride = if index { element[v].unwrap_or(0) as usize } else { stride };
        let encodable = stride > 0
            && length > 0
            && if index { (stride == 2 || stride == 4) && length.is_multiple_of(stride) } else { stride <= 64 };
        plans.push(Plan { bytes, stride, index, encodable });
    }
    // A view whose length is not a whole number of strides is encoded zero-padded (its accessors
    // read no further than before; the decoded view is longer by the padding).
    fn padded<'a>(p: &Plan<'a>) -> std::borrow::Cow<'a, [u8]> {
        if p.encodable && !p.bytes.len().is_multiple_of(p.stride) {
            let mut padded = p.bytes.to_vec();
            padded.resize(p.bytes.len().next_multiple_of(p.stride), 0);
            std::borrow::Cow::Owned(padded)
        } else {
            std::borrow::Cow::Borrowed(p.bytes)
        }
    }
    let encodings: Vec<Option<(Vec<u8>, Mode)>> =
        plans.par_iter().map(|p| if p.encodable { encode_view(&padded(p), p.stride, p.index) } else { None }).collect();

    let mut new_bin = Vec::with_capacity(bin.len() / 2);
    let mut fallback_len = 0usize;
    let mut new_views = Vec::with_capacity(views.len());
    for ((view, plan), encoded) in views.iter().zip(&plans).zip(encodings) {
        let (bytes, stride) = (plan.bytes, plan.stride);
        let length = if plan.encodable { bytes.len().next_multiple_of(stride) } else { bytes.len() };
        pad4(&mut new_bin);
        let mut out = view.clone();
        match encoded {
            Some((stream, mode)) => {
                stats.encoded_views += 1;
                stats.encoded_bytes_before += length as u64;
                stats.encoded_bytes_after += stream.len() as u64;
                let ext = MeshoptBufferView {
                    buffer: Some(0),
                    byte_offset: Some(new_bin.len() as u64),
                    byte_length: Some(stream.len() as u64),
                    byte_stride: Some(stride as u64),
                    count: Some((length / stride) as u64),
                    mode: Some(mode.name().to_owned()),
                    ..MeshoptBufferView::default()
                };
                new_bin.extend_from_slice(&stream);
                fallback_len = fallback_len.next_multiple_of(4);
                out.buffer = Some(1);
                out.byte_offset = Some(fallback_len as u64);
                out.byte_length = Some(length as u64);
                fallback_len += length;
                out.set_extension(EXTENSION, Value::from(ext));
            }
            None => {
                out.byte_offset = Some(new_bin.len() as u64);
                new_bin.extend_from_slice(bytes);
            }
        }
        new_views.push(out);
    }
    if stats.encoded_views == 0 {
        return Ok(unchanged(&stats));
    }
    pad4(&mut new_bin);
    doc.buffer_views = Some(new_views);
    let buffers = doc.buffers.get_or_insert_default();
    buffers[0].byte_length = Some(new_bin.len() as u64);
    let mut fallback = Buffer { byte_length: Some(fallback_len as u64), ..Buffer::default() };
    fallback.set_extension(EXTENSION, Value::from(MeshoptBuffer { fallback: Some(true), ..MeshoptBuffer::default() }));
    buffers.push(fallback);
    for list in [&mut doc.extensions_used, &mut doc.extensions_required] {
        list.get_or_insert_default().push(EXTENSION.to_owned());
    }
    let out = frame(doc, &new_bin)?;
    stats.file_bytes_after = out.len() as u64;
    Ok((out, stats))
}

/// What a GLB's JSON says about its compression: views encoded, and their bytes decoded
/// (`encoded_bytes_before`) and encoded (`encoded_bytes_after`); `None` when no view is encoded.
/// The file sizes are left at 0 (the caller knows them).
pub fn describe(json: &[u8]) -> Option<CompressionStats> {
    if !mentions_extension(json) {
        return None;
    }
    let doc = parse(json).ok()?;
    let views = doc.buffer_views();
    let mut stats = CompressionStats { views: views.len(), ..CompressionStats::default() };
    for view in views {
        if let Some(ext) = encoding(view) {
            stats.encoded_views += 1;
            stats.encoded_bytes_before += view.byte_length.unwrap_or(0);
            stats.encoded_bytes_after += ext.map_or(0, |e| e.byte_length.unwrap_or(0));
        }
    }
    (stats.encoded_views > 0).then_some(stats)
}

/// The plain GLB of a GLB that uses the extension (every view decoded into one binary chunk, the
/// extension and its fallback buffer removed); `None` when `glb` does not use it.
pub fn decompress_glb(glb_bytes: &[u8]) -> Result<Option<Vec<u8>>, MeshoptError> {
    let chunks = glb::split(glb_bytes)?;
    if !mentions_extension(chunks.json) {
        return Ok(None);
    }
    let mut doc = parse(chunks.json)?;
    let bin = chunks.bin.unwrap_or(&[]);
    let views = doc.buffer_views.take().unwrap_or_default();
    if !views.iter().any(|v| v.extensions.as_ref().is_some_and(|e| e.contains_key(EXTENSION))) {
        return Ok(None);
    }
    let buffers = doc.buffers.take().unwrap_or_default();
    let is_fallback = |b: usize| {
        let ext = buffers.get(b).and_then(|b| b.extension::<MeshoptBuffer>(EXTENSION));
        ext.and_then(Result::ok).and_then(|e| e.fallback) == Some(true)
    };
    // The bytes of buffer `b` in `offset..offset + length`: only the binary chunk holds data here.
    let range = |b: u64, offset: u64, length: u64, place: &str| -> Result<&[u8], MeshoptError> {
        if b != 0 || buffers.first().is_none_or(|b| b.uri.is_some()) {
            return Err(invalid(format!("{place}: data outside the GLB's binary chunk is not supported")));
        }
        offset
            .checked_add(length)
            .and_then(|end| bin.get(usize::try_from(offset).ok()?..usize::try_from(end).ok()?))
            .ok_or_else(|| invalid(format!("{place}: bytes {offset}..+{length} lie outside the binary chunk")))
    };
    let mut new_bin = Vec::new();
    let mut new_views = Vec::with_capacity(views.len());
    for (v, view) in views.iter().enumerate() {
        let place = format!("/bufferViews/{v}");
        let length = view.byte_length.ok_or_else(|| invalid(format!("{place}: no byteLength")))?;
        let decoded: Vec<u8> = match encoding(view) {
            Some(ext) => {
                let ext = ext.map_err(|e| invalid(format!("{place}: {e}")))?;
                let field = |value: Option<u64>, key: &str| value.ok_or_else(|| invalid(format!("{place}: no {key}")));
                let stride = field(ext.byte_stride, "byteStride")? as usize;
                let count = field(ext.count, "count")? as usize;
                let (buffer, length_encoded) = (field(ext.buffer, "buffer")?, field(ext.byte_length, "byteLength")?);
                let stream = range(buffer, ext.byte_offset.unwrap_or(0), length_encoded, &place)?;
                let size = stride.checked_mul(count).filter(|&s| s as u64 == length).ok_or_else(|| {
                    invalid(format!("{place}: count {count} × byteStride {stride} is not the byteLength {length}"))
                })?;
                if size > MAX_EXPANSION.saturating_mul(stream.len()).saturating_add(4096) {
                    return Err(invalid(format!(
                        "{place}: {size} bytes cannot come from a {}-byte stream",
                        stream.len()
                    )));
                }
                let mode = match ext.mode.as_deref() {
                    Some("ATTRIBUTES") => Mode::Attributes,
                    Some("TRIANGLES") => Mode::Triangles,
                    Some("INDICES") => Mode::Indices,
                    other => return Err(invalid(format!("{place}: unknown mode {other:?}"))),
                };
                let bad = || invalid(format!("{place}: the {} stream does not decode", mode.name()));
                let mut bytes = match mode {
                    Mode::Attributes if stride.is_multiple_of(4) && stride <= 64 => {
                        with_stride!(stride, decode_attributes, stream, count).ok_or_else(bad)?
                    }
                    Mode::Attributes => return Err(invalid(format!("{place}: byteStride {stride} not supported"))),
                    _ if stride == 2 || stride == 4 => {
                        index_bytes(&decode_indices(stream, count, mode).ok_or_else(bad)?, stride)
                    }
                    _ => return Err(invalid(format!("{place}: index byteStride {stride}"))),
                };
                apply_filter(&mut bytes, stride, ext.filter.as_deref().unwrap_or("NONE"), &place)?;
                bytes
            }
            None => {
                let b = view.buffer.unwrap_or(0);
                if is_fallback(b as usize) {
                    return Err(invalid(format!("{place}: reads the fallback buffer but is not encoded")));
                }
                range(b, view.byte_offset.unwrap_or(0), length, &place)?.to_vec()
            }
        };
        new_bin.resize(new_bin.len().next_multiple_of(16), 0);
        let mut out = view.clone();
        out.buffer = Some(0);
        out.byte_offset = Some(new_bin.len() as u64);
        out.remove_extension(EXTENSION);
        new_bin.extend_from_slice(&decoded);
        new_views.push(out);
    }
    new_bin.resize(new_bin.len().next_multiple_of(4), 0);
    doc.buffer_views = Some(new_views);
    let first = buffers.into_iter().next().unwrap_or_default();
    doc.buffers = Some(vec![Buffer { byte_length: Some(new_bin.len() as u64), ..first }]);
    for list in [&mut doc.extensions_used, &mut doc.extensions_required] {
        list.iter_mut().for_each(|names| names.retain(|name| name != EXTENSION));
    }
    Ok(Some(frame(doc, &new_bin)?))
}

/// Undoes a view's filter in place (filters are gltfpack's lossy pre-transforms).
fn apply_filter(bytes: &mut [u8], stride: usize, filter: &str, place: &str) -> Result<(), MeshoptError> {
    let unsupported = || invalid(format!("{place}: filter {filter} with byteStride {stride}"));
    match (filter, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => with_i8x4(bytes, meshopt::decode_filter_oct::<i8>),
        ("OCTAHEDRAL", 8) => with_i16x4(bytes, meshopt::decode_filter_oct::<i16>),
        ("QUATERNION", 8) => with_i16x4(bytes, meshopt::decode_filter_quat),
        ("COLOR", 4) => with_i8x4(bytes, meshopt::decode_filter_color::<i8>),
        ("COLOR", 8) => with_i16x4(bytes, meshopt::decode_filter_color::<i16>),
        ("EXPONENTIAL", s) if s.is_multiple_of(4) => {
            let mut values: Vec<[u32; 1]> = words::<1>(bytes);
            meshopt::decode_filter_exp(&mut values);
            bytes.copy_from_slice(&bytes_of(&values));
        }
        _ => return Err(unsupported()),
    }
    Ok(())
}

fn with_i8x4(bytes: &mut [u8], f: impl Fn(&mut [[i8; 4]])) {
    let mut v: Vec<[i8; 4]> = bytes.chunks_exact(4).map(|c| std::array::from_fn(|i| c[i] as i8)).collect();
    f(&mut v);
    for (dst, src) in bytes.chunks_exact_mut(4).zip(&v) {
        for i in 0..4 {
            dst[i] = src[i] as u8;
        }
    }
}

fn with_i16x4(bytes: &mut [u8], f: impl Fn(&mut [[i16; 4]])) {
    let mut v: Vec<[i16; 4]> =
        bytes.chunks_exact(8).map(|c| std::array::from_fn(|i| i16::from_le_bytes([c[2 * i], c[2 * i + 1]]))).collect();
    f(&mut v);
    for (dst, src) in bytes.chunks_exact_mut(8).zip(&v) {
        for i in 0..4 {
            dst[2 * i..2 * i + 2].copy_from_slice(&src[i].to_le_bytes());
        }
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    /// A GLB's JSON as a tree, for the tests to edit.
    fn tree(json: &[u8]) -> Value {
        serde_json::from_slice(json).expect("json")
    }

    fn sample() -> Vec<u8> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../samples/assembly.glb");
        std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    /// The bytes of every buffer view of a plain GLB.
    fn view_bytes(glb_bytes: &[u8]) -> Vec<Vec<u8>> {
        let chunks = glb::split(glb_bytes).expect("glb");
        let doc = parse(chunks.json).expect("json");
        let bin = chunks.bin.unwrap_or(&[]);
        doc.buffer_views()
            .iter()
            .map(|v| {
                let (o, l) = (v.byte_offset.unwrap_or(0) as usize, v.byte_length.unwrap_or(0) as usize);
                bin[o..o + l].to_vec()
            })
            .collect()
    }

    #[test]
    fn round_trip_gives_back_every_view() {
        let plain = sample();
        let (packed, stats) = compress_glb(&plain).expect("compresses");
        assert!(stats.encoded_views > 0, "{stats:?}");
        assert!(packed.len() < plain.len(), "{} vs {}", packed.len(), plain.len());
        assert_eq!(
            describe(glb::split(&packed).expect("glb").json).map(|d| d.encoded_views),
            Some(stats.encoded_views)
        );
        assert_eq!(decompress_glb(&plain).expect("plain"), None, "a plain file is left alone");
        let decoded = decompress_glb(&packed).expect("decodes").expect("was compressed");
        assert_eq!(view_bytes(&decoded), view_bytes(&plain));
        let doc = parse(glb::split(&decoded).expect("glb").json).expect("json");
        assert!(!mentions_extension(&serde_json::to_vec(&doc).expect("json")));
        assert_eq!(doc.buffers().len(), 1);
        // Compressing twice does nothing more.
        assert_eq!(compress_glb(&packed).expect("again").0, packed);
    }

    /// A compressed file whose JSON lies is refused with a message, never decoded into a buffer
    /// sized by the lie.
    #[test]
    fn lying_streams_are_refused() {
        let (packed, _) = compress_glb(&sample()).expect("compresses");
        let chunks = glb::split(&packed).expect("glb");
        let doc = tree(chunks.json);
        let bin = chunks.bin.expect("bin").to_vec();
        let first = parse(chunks.json)
            .expect("json")
            .buffer_views()
            .iter()
            .position(|v| encoding(v).is_some())
            .expect("an encoded view");
        let edit = |f: &dyn Fn(&mut Value)| {
            let mut d = doc.clone();
            f(&mut d["bufferViews"][first]);
            glb::write(&serde_json::to_vec(&d).expect("json"), &bin).expect("glb")
        };
        let cases: Vec<(&str, Vec<u8>)> = vec![
            (
                "huge count",
                edit(&|v| {
                    v["byteLength"] = json!(4u64 << 32);
                    v["extensions"][EXTENSION]["count"] = json!(1u64 << 32);
                    v["extensions"][EXTENSION]["byteStride"] = json!(4);
                }),
            ),
            ("count × stride ≠ length", edit(&|v| v["extensions"][EXTENSION]["count"] = json!(1))),
            ("stream past the chunk", edit(&|v| v["extensions"][EXTENSION]["byteOffset"] = json!(u64::MAX - 2))),
            ("other buffer", edit(&|v| v["extensions"][EXTENSION]["buffer"] = json!(1))),
            ("unknown mode", edit(&|v| v["extensions"][EXTENSION]["mode"] = json!("ZIP"))),
            (
                "odd stride",
                edit(&|v| {
                    let len = v["byteLength"].as_u64().unwrap_or(0);
                    v["extensions"][EXTENSION]["byteStride"] = json!(len);
                    v["extensions"][EXTENSION]["count"] = json!(1);
                    v["extensions"][EXTENSION]["mode"] = json!("ATTRIBUTES");
                }),
            ),
        ];
        for (name, bytes) in cases {
            match decompress_glb(&bytes) {
                Err(MeshoptError::Invalid(message)) => assert!(message.contains("/bufferViews/"), "{name}: {message}"),
                other => panic!("{name}: expected a refusal, got {:?}", other.map(|o| o.map(|b| b.len()))),
            }
        }
    }
}
