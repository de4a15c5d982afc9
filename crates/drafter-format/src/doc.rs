//! A glTF document under construction: the JSON tree plus one binary buffer that new buffer views
//! append to. Only this module touches buffer/bufferView/accessor bookkeeping.

use serde_json::{Map, Value, json};

use crate::FormatError;

pub(crate) const ARRAY_BUFFER: u32 = 34962;
pub(crate) const ELEMENT_ARRAY_BUFFER: u32 = 34963;

pub(crate) const UNSIGNED_BYTE: u32 = 5121;
pub(crate) const UNSIGNED_SHORT: u32 = 5123;
pub(crate) const UNSIGNED_INT: u32 = 5125;
pub(crate) const FLOAT: u32 = 5126;

#[derive(Debug)]
pub(crate) struct Doc {
    pub json: Map<String, Value>,
    pub bin: Vec<u8>,
}

impl Doc {
    pub fn new(json: Map<String, Value>) -> Self {
        Self { json, bin: Vec::new() }
    }

    /// Starts from a source document, moving every buffer's bytes into the one binary buffer and
    /// rebasing the buffer views onto it.
    pub fn from_source(json_text: &str, buffers: &[Vec<u8>]) -> Result<Self, FormatError> {
        let root: Value = serde_json::from_str(json_text).map_err(|e| FormatError::Source(e.to_string()))?;
        let Value::Object(json) = root else { return Err(FormatError::Source("top level is not an object".into())) };
        let mut doc = Doc::new(json);
        let declared: Vec<usize> = doc
            .array("buffers")
            .iter()
            .map(|b| b.get("byteLength").and_then(Value::as_u64).unwrap_or(0) as usize)
            .collect();
        let mut bases = Vec::with_capacity(buffers.len());
        for (i, data) in buffers.iter().enumerate() {
            doc.align(4);
            bases.push(doc.bin.len() as u64);
            let length = declared.get(i).copied().unwrap_or(data.len()).min(data.len());
            doc.bin.extend_from_slice(&data[..length]);
        }
        for view in doc.array_mut("bufferViews") {
            let buffer = view.get("buffer").and_then(Value::as_u64).unwrap_or(0) as usize;
            let offset = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0);
            let base = *bases
                .get(buffer)
                .ok_or_else(|| FormatError::Source(format!("bufferView names missing buffer {buffer}")))?;
            view["buffer"] = 0.into();
            view["byteOffset"] = (base + offset).into();
        }
        doc.json.remove("buffers");
        Ok(doc)
    }

    /// The array at `key` (empty if absent).
    pub fn array(&self, key: &str) -> &[Value] {
        self.json.get(key).and_then(Value::as_array).map_or(&[], Vec::as_slice)
    }

    /// The array at `key`, created if absent.
    pub fn array_mut(&mut self, key: &str) -> &mut Vec<Value> {
        let entry = self.json.entry(key.to_owned()).or_insert_with(|| Value::Array(Vec::new()));
        if !entry.is_array() {
            *entry = Value::Array(Vec::new());
        }
        match entry {
            Value::Array(a) => a,
            _ => unreachable!("replaced by an array above"),
        }
    }

    fn align(&mut self, to: usize) {
        while !self.bin.len().is_multiple_of(to) {
            self.bin.push(0);
        }
    }

    /// Appends `bytes` as a new buffer view (4-byte aligned) and returns its index.
    pub fn push_view(&mut self, bytes: &[u8], target: Option<u32>, stride: Option<usize>) -> usize {
        self.align(4);
        let mut view = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(t) = target {
            view["target"] = t.into();
        }
        if let Some(s) = stride {
            view["byteStride"] = s.into();
        }
        self.bin.extend_from_slice(bytes);
        let views = self.array_mut("bufferViews");
        views.push(view);
        views.len() - 1
    }

    fn push_accessor(&mut self, accessor: Value) -> usize {
        let accessors = self.array_mut("accessors");
        accessors.push(accessor);
        accessors.len() - 1
    }

    /// VEC3 float vertex attribute; `with_bounds` adds min/max (required for POSITION).
    pub fn push_vec3(&mut self, values: &[[f32; 3]], with_bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), None);
        let mut accessor = json!({"bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "VEC3"});
        if with_bounds && !values.is_empty() {
            let (lo, hi) = values.iter().fold(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]), |(lo, hi), v| {
                (std::array::from_fn(|i| lo[i].min(v[i])), std::array::from_fn(|i| hi[i].max(v[i])))
            });
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.push_accessor(accessor)
    }

    pub fn push_vec2(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes: Vec<u8> = values.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), None);
        self.push_accessor(json!({"bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "VEC2"}))
    }

    /// Unsigned SCALAR data in the smallest component type that holds `max(values)`.
    /// `target` is ELEMENT_ARRAY_BUFFER for indices, None for data read only by our extension.
    pub fn push_scalars(&mut self, values: &[u32], target: Option<u32>) -> usize {
        let max = values.iter().copied().max().unwrap_or(0);
        // Index buffers may not use the primitive-restart value (2^n - 1) of their type.
        let restart_safe = target == Some(ELEMENT_ARRAY_BUFFER);
        let (component, bytes): (u32, Vec<u8>) = if max < 255 || (!restart_safe && max <= 255) {
            (UNSIGNED_BYTE, values.iter().map(|&v| v as u8).collect())
        } else if max < 65535 || (!restart_safe && max <= 65535) {
            (UNSIGNED_SHORT, values.iter().flat_map(|&v| (v as u16).to_le_bytes()).collect())
        } else {
            (UNSIGNED_INT, values.iter().flat_map(|v| v.to_le_bytes()).collect())
        };
        // Index data of one byte is allowed; vertex attributes would need a 4-byte stride.
        let view = self.push_view(&bytes, target, None);
        self.push_accessor(
            json!({"bufferView": view, "componentType": component, "count": values.len(), "type": "SCALAR"}),
        )
    }

    /// Adds `name` to `extensionsUsed` once.
    pub fn use_extension(&mut self, name: &str) {
        let used = self.array_mut("extensionsUsed");
        if !used.iter().any(|v| v.as_str() == Some(name)) {
            used.push(Value::String(name.to_owned()));
        }
    }

    /// The single buffer's entry, with a URI for the .gltf container.
    fn set_buffer(&mut self, uri: Option<&str>) {
        if self.bin.is_empty() {
            self.json.remove("buffers");
            return;
        }
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = uri.into();
        }
        self.json.insert("buffers".into(), json!([buffer]));
    }

    /// A .glb: header, JSON chunk (space padded), BIN chunk (zero padded).
    pub fn into_glb(mut self) -> Result<Vec<u8>, FormatError> {
        self.set_buffer(None);
        let mut json = serde_json::to_vec(&Value::Object(std::mem::take(&mut self.json)))?;
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = std::mem::take(&mut self.bin);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
        let total = 12 + 8 + json.len() + bin_chunk;
        let total = u32::try_from(total).map_err(|_| FormatError::TooLarge(total))?;
        let mut out = Vec::with_capacity(total as usize);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&total.to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        if !bin.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        Ok(out)
    }

    /// A .gltf (pretty JSON) and its .bin, the buffer referring to `bin_uri`.
    pub fn into_gltf(mut self, bin_uri: &str) -> Result<(Vec<u8>, Vec<u8>), FormatError> {
        self.set_buffer(Some(bin_uri));
        let mut json = serde_json::to_vec_pretty(&Value::Object(std::mem::take(&mut self.json)))?;
        json.push(b'\n');
        Ok((json, std::mem::take(&mut self.bin)))
    }
}
