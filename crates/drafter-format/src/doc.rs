//! A glTF document under construction: the JSON tree plus one binary buffer that new buffer views
//! append to. Only this module touches buffer/bufferView/accessor bookkeeping.

use std::collections::HashMap;

use serde_json::{Map, Value, json};

use crate::FormatError;
use crate::accessor::{ARRAY_BUFFER, ComponentType, ELEMENT_ARRAY_BUFFER};
use crate::reader::{ByteSections, sections_of};

const BYTE: u32 = ComponentType::I8.code();
const SHORT: u32 = ComponentType::I16.code();
const UNSIGNED_BYTE: u32 = ComponentType::U8.code();
const UNSIGNED_SHORT: u32 = ComponentType::U16.code();
const UNSIGNED_INT: u32 = ComponentType::U32.code();
const FLOAT: u32 = ComponentType::F32.code();

/// Extensions whose accessor and buffer-view references [`Doc::compact`] knows (or that have none).
pub(crate) const COMPACTION_SAFE_EXTENSIONS: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_variants",
    "EXT_mesh_gpu_instancing",
    "EXT_mesh_primitive_edge_visibility",
    "KHR_texture_basisu",
    "EXT_texture_webp",
];

/// Keys whose integer values are accessor indices, anywhere inside our extension's objects.
const OWN_ACCESSOR_KEYS: &[&str] =
    &["partLabels", "hardEdgeClasses", "nodeCaps", "nodes", "nodeBoxes", "nodeCones", "splits", "splitStarts"];
const EDGE_VISIBILITY: &str = "EXT_mesh_primitive_edge_visibility";
/// Accessor-valued keys of EXT_mesh_primitive_edge_visibility (`indices` inside `lineStrings`).
const EDGE_VISIBILITY_ACCESSOR_KEYS: &[&str] = &["visibility", "silhouetteNormals", "indices"];

/// Visits every integer value under `keys` in the tree `value`.
fn visit_keys(value: &mut Value, keys: &[&str], visit: &mut dyn FnMut(&mut Value)) {
    match value {
        Value::Object(map) => {
            for (k, v) in map.iter_mut() {
                if keys.contains(&k.as_str()) && v.is_u64() {
                    visit(v);
                } else {
                    visit_keys(v, keys, visit);
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|v| visit_keys(v, keys, visit)),
        _ => {}
    }
}

/// For each kept item its new index (`u32::MAX` for dropped items).
fn renumbering(keep: &[bool]) -> Vec<u32> {
    let mut next = 0u32;
    keep.iter()
        .map(|&k| {
            if k {
                next += 1;
                next - 1
            } else {
                u32::MAX
            }
        })
        .collect()
}

#[derive(Debug)]
pub(crate) struct Doc {
    pub json: Map<String, Value>,
    pub bin: Vec<u8>,
    /// The buffer views this writer pushed, by a hash of their bytes, and the accessors it pushed,
    /// by their buffer view (then compared by their JSON text): an identical push reuses the first. Meshes that share their data in the input
    /// (two glTF meshes on the same accessors, as CAD exports write a part used with two
    /// materials) are baked separately but come out byte-identical, and are stored once again.
    pushed_views: HashMap<u64, Vec<usize>>,
    pushed_accessors: HashMap<u64, Vec<usize>>,
}

impl Doc {
    pub fn new(json: Map<String, Value>) -> Self {
        Self { json, bin: Vec::new(), pushed_views: HashMap::new(), pushed_accessors: HashMap::new() }
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

    /// The array at `key` for in-place edits; empty (and nothing created) if absent, so no empty
    /// top-level array appears (the spec forbids them).
    pub fn existing_mut(&mut self, key: &str) -> &mut [Value] {
        match self.json.get_mut(key) {
            Some(Value::Array(a)) => a,
            _ => &mut [],
        }
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
        let key = content_hash(bytes, target, stride);
        let same = |doc: &Doc, v: usize| {
            let view = &doc.array("bufferViews")[v];
            let number = |k: &str| view.get(k).and_then(Value::as_u64);
            let start = number("byteOffset").unwrap_or(0) as usize;
            number("target") == target.map(u64::from)
                && number("byteStride") == stride.map(|s| s as u64)
                && doc.bin.get(start..start + bytes.len()) == Some(bytes)
                && number("byteLength") == Some(bytes.len() as u64)
        };
        if let Some(&v) = self.pushed_views.get(&key).and_then(|vs| vs.iter().find(|&&v| same(self, v))) {
            return v;
        }
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
        let index = views.len() - 1;
        self.pushed_views.entry(key).or_default().push(index);
        index
    }

    fn push_accessor(&mut self, accessor: Value) -> usize {
        // Only an accessor on a buffer view that an earlier push used can repeat one, and views are
        // mostly new: the JSON text is formatted only then (formatting every accessor to key a map
        // was about a sixth of the write stage for 20,000 small meshes: 13 % of a one-thread
        // profile against the stage's 73 %).
        let view = accessor.get("bufferView").and_then(Value::as_u64);
        if let Some(earlier) = view.and_then(|v| self.pushed_accessors.get(&v)) {
            // Compared as text, as written: `Value`'s `==` takes -0.0 for 0.0.
            let text = serde_json::to_string(&accessor).ok();
            let accessors = self.array("accessors");
            let same = |a: usize| accessors.get(a).is_some_and(|e| serde_json::to_string(e).ok() == text);
            if let Some(&a) = earlier.iter().find(|&&a| same(a)) {
                return a;
            }
        }
        let accessors = self.array_mut("accessors");
        accessors.push(accessor);
        let index = accessors.len() - 1;
        if let Some(v) = view {
            self.pushed_accessors.entry(v).or_default().push(index);
        }
        index
    }

    /// VEC3 float vertex attribute; `with_bounds` adds min/max (required for POSITION).
    pub fn push_vec3(&mut self, values: &[[f32; 3]], with_bounds: bool) -> usize {
        let bytes = le_bytes(values.as_flattened(), |c| c.to_le_bytes());
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

    /// VEC3 BYTE normalized vertex attribute (`drafter_core::snorm`): a 4-byte stride with one
    /// padding byte, as the spec requires of vertex data.
    pub fn push_snorm8_attribute(&mut self, values: &[[i8; 3]]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| [v[0] as u8, v[1] as u8, v[2] as u8, 0]).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), Some(4));
        self.push_accessor(json!({
            "bufferView": view, "componentType": BYTE, "normalized": true, "count": values.len(), "type": "VEC3"
        }))
    }

    /// VEC3 unit vectors in their stored component type (BYTE or SHORT normalized, or FLOAT),
    /// tightly packed, read only by an extension.
    pub fn push_unit_vec3(&mut self, values: &crate::StoredNormals) -> usize {
        use crate::StoredNormals;
        let (component, normalized, bytes): (u32, bool, Vec<u8>) = match values {
            StoredNormals::Byte(v) => (BYTE, true, v.iter().flatten().map(|&c| c as u8).collect()),
            StoredNormals::Short(v) => (SHORT, true, le_bytes(v.as_flattened(), |c| c.to_le_bytes())),
            StoredNormals::Float(v) => (FLOAT, false, le_bytes(v.as_flattened(), |c| c.to_le_bytes())),
        };
        let view = self.push_view(&bytes, None, None);
        let mut accessor =
            json!({"bufferView": view, "componentType": component, "count": values.len(), "type": "VEC3"});
        if normalized {
            accessor["normalized"] = true.into();
        }
        self.push_accessor(accessor)
    }

    /// Appends a material and returns its index.
    pub fn push_material(&mut self, material: Value) -> usize {
        let materials = self.array_mut("materials");
        materials.push(material);
        materials.len() - 1
    }

    pub fn push_vec2(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes = le_bytes(values.as_flattened(), |c| c.to_le_bytes());
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), None);
        self.push_accessor(json!({"bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "VEC2"}))
    }

    /// SCALAR FLOAT data read only by an extension.
    pub fn push_f32_scalars(&mut self, values: &[f32]) -> usize {
        let bytes = le_bytes(values, |c| c.to_le_bytes());
        let view = self.push_view(&bytes, None, None);
        self.push_accessor(json!({"bufferView": view, "componentType": FLOAT, "count": values.len(), "type": "SCALAR"}))
    }

    /// SCALAR data of exactly this component type (UNSIGNED_BYTE / UNSIGNED_SHORT / UNSIGNED_INT),
    /// read only by an extension.
    pub fn push_typed_scalars(&mut self, component: u32, bytes: &[u8], count: usize) -> usize {
        let view = self.push_view(bytes, None, None);
        self.push_accessor(json!({"bufferView": view, "componentType": component, "count": count, "type": "SCALAR"}))
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
            (UNSIGNED_SHORT, le_bytes(values, |&v| (v as u16).to_le_bytes()))
        } else {
            (UNSIGNED_INT, le_bytes(values, |v| v.to_le_bytes()))
        };
        // Index data of one byte is allowed; vertex attributes would need a 4-byte stride.
        let view = self.push_view(&bytes, target, None);
        self.push_accessor(
            json!({"bufferView": view, "componentType": component, "count": values.len(), "type": "SCALAR"}),
        )
    }

    /// Copies the elements `picks` of a vertex-attribute accessor into a new tightly packed accessor
    /// (4-byte aligned elements, as the spec requires for vertex data). Works on the raw bytes, so
    /// any component type passes through unchanged; min/max are dropped (optional for everything
    /// but POSITION, which callers write themselves). Sparse accessors are not supported.
    pub fn gather_attribute(&mut self, accessor: usize, picks: &[u32]) -> Result<usize, FormatError> {
        let bad = |what: &str| FormatError::Source(format!("/accessors/{accessor}: {what}"));
        let a = self.array("accessors").get(accessor).cloned().ok_or_else(|| bad("missing"))?;
        if a.get("sparse").is_some() {
            return Err(bad("sparse vertex attributes cannot be re-laid out"));
        }
        let component = a
            .get("componentType")
            .and_then(Value::as_u64)
            .and_then(ComponentType::from_code)
            .ok_or_else(|| bad("unknown componentType"))?
            .size();
        let components = a
            .get("type")
            .and_then(Value::as_str)
            .and_then(crate::accessor::components)
            .ok_or_else(|| bad("unknown type"))?;
        let element = component * components;
        let view_index = a.get("bufferView").and_then(Value::as_u64).ok_or_else(|| bad("no bufferView"))? as usize;
        let view = self.array("bufferViews").get(view_index).cloned().ok_or_else(|| bad("bufferView missing"))?;
        let stride = view.get("byteStride").and_then(Value::as_u64).map_or(element, |s| s as usize);
        let base = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize
            + a.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let count = a.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
        let padded = element.next_multiple_of(4);
        let mut bytes = Vec::with_capacity(picks.len() * padded);
        for &i in picks {
            let i = i as usize;
            if i >= count {
                return Err(bad("vertex index out of range"));
            }
            let start = base + i * stride;
            let data = self.bin.get(start..start + element).ok_or_else(|| bad("data outside the buffer"))?;
            bytes.extend_from_slice(data);
            bytes.resize(bytes.len() + padded - element, 0);
        }
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), (padded != element).then_some(padded));
        let mut out =
            json!({"bufferView": view, "componentType": a["componentType"], "count": picks.len(), "type": a["type"]});
        if a.get("normalized").and_then(Value::as_bool) == Some(true) {
            out["normalized"] = true.into();
        }
        Ok(self.push_accessor(out))
    }

    /// Drops accessors and buffer views nothing refers to (the source vertex data that a new layout
    /// replaced) and rebuilds the binary buffer from the views that remain, renumbering every
    /// reference. References are looked for in every place the glTF 2.0 spec and the extensions in
    /// [`COMPACTION_SAFE_EXTENSIONS`] put them; a document that uses any other extension might refer
    /// to accessors from places unknown here, so it is left as it is, and so is a document that refers
    /// to an accessor or buffer view it does not have (nothing to renumber it to). `Err` says why.
    pub fn compact(&mut self, own_extension: &str) -> Result<(), &'static str> {
        // Views and accessors are renumbered below: nothing may be reused by index afterwards.
        self.pushed_views.clear();
        self.pushed_accessors.clear();
        let used = self.array("extensionsUsed").iter().filter_map(Value::as_str).map(str::to_owned).collect::<Vec<_>>();
        if used.iter().any(|e| e != own_extension && !COMPACTION_SAFE_EXTENSIONS.contains(&e.as_str())) {
            return Err("the input uses extensions drafter does not know");
        }
        const DANGLING: &str = "the input refers to accessors or buffer views it does not have";
        let accessor_count = self.array("accessors").len();
        let view_count = self.array("bufferViews").len();
        // 1. Which accessors are referenced.
        let mut keep_accessor = vec![false; accessor_count];
        let mut dangling = false;
        self.visit_accessor_refs(own_extension, &mut |i| match keep_accessor.get_mut(*i as usize) {
            Some(k) => *k = true,
            None => dangling = true,
        });
        let accessor_map = renumbering(&keep_accessor);
        // 2. Which buffer views: those of kept accessors (and their sparse parts) and of images.
        let mut keep_view = vec![false; view_count];
        let mut keep = |v: u64| match keep_view.get_mut(v as usize) {
            Some(k) => *k = true,
            None => dangling = true,
        };
        for (a, accessor) in self.array("accessors").iter().enumerate() {
            if !keep_accessor[a] {
                continue;
            }
            for pointer in ["/bufferView", "/sparse/indices/bufferView", "/sparse/values/bufferView"] {
                if let Some(v) = accessor.pointer(pointer).and_then(Value::as_u64) {
                    keep(v);
                }
            }
        }
        for image in self.array("images") {
            if let Some(v) = image.get("bufferView").and_then(Value::as_u64) {
                keep(v);
            }
        }
        if dangling {
            return Err(DANGLING);
        }
        let view_map = renumbering(&keep_view);
        // 3. New buffer from the kept views, 4-byte aligned.
        let old_bin = std::mem::take(&mut self.bin);
        let mut views = Vec::new();
        for (v, view) in std::mem::take(self.array_mut("bufferViews")).into_iter().enumerate() {
            if !keep_view[v] {
                continue;
            }
            let start = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            let length = view.get("byteLength").and_then(Value::as_u64).unwrap_or(0) as usize;
            self.align(4);
            let mut view = view;
            view["byteOffset"] = self.bin.len().into();
            let bytes = start.checked_add(length).and_then(|end| old_bin.get(start..end));
            self.bin.extend_from_slice(bytes.unwrap_or_default());
            views.push(view);
        }
        *self.array_mut("bufferViews") = views;
        // 4. Renumber.
        let accessors: Vec<Value> = std::mem::take(self.array_mut("accessors"))
            .into_iter()
            .enumerate()
            .filter(|(a, _)| keep_accessor[*a])
            .map(|(_, mut accessor)| {
                for pointer in ["/bufferView", "/sparse/indices/bufferView", "/sparse/values/bufferView"] {
                    if let Some(slot) = accessor.pointer_mut(pointer)
                        && let Some(v) = slot.as_u64()
                    {
                        *slot = view_map[v as usize].into();
                    }
                }
                accessor
            })
            .collect();
        *self.array_mut("accessors") = accessors;
        for image in self.existing_mut("images") {
            if let Some(slot) = image.get_mut("bufferView")
                && let Some(v) = slot.as_u64()
            {
                *slot = view_map[v as usize].into();
            }
        }
        self.visit_accessor_refs(own_extension, &mut |i| *i = u64::from(accessor_map[*i as usize]));
        Ok(())
    }

    /// Calls `f` on every accessor reference of the document (glTF 2.0 core, EXT_mesh_gpu_instancing
    /// and our own extension's `partLabels`).
    fn visit_accessor_refs(&mut self, own_extension: &str, f: &mut dyn FnMut(&mut u64)) {
        let mut visit = |v: &mut Value| {
            if let Some(mut i) = v.as_u64() {
                f(&mut i);
                *v = i.into();
            }
        };
        for mesh in self.existing_mut("meshes") {
            for prim in mesh.get_mut("primitives").and_then(Value::as_array_mut).into_iter().flatten() {
                for (_, a) in prim.get_mut("attributes").and_then(Value::as_object_mut).into_iter().flatten() {
                    visit(a);
                }
                if let Some(i) = prim.get_mut("indices") {
                    visit(i);
                }
                for target in prim.get_mut("targets").and_then(Value::as_array_mut).into_iter().flatten() {
                    for (_, a) in target.as_object_mut().into_iter().flatten() {
                        visit(a);
                    }
                }
                if let Some(ext) = prim.pointer_mut(&format!("/extensions/{own_extension}")) {
                    visit_keys(ext, OWN_ACCESSOR_KEYS, &mut visit);
                }
                if let Some(ext) = prim.pointer_mut(&format!("/extensions/{EDGE_VISIBILITY}")) {
                    visit_keys(ext, EDGE_VISIBILITY_ACCESSOR_KEYS, &mut visit);
                }
            }
            if let Some(ext) = mesh.pointer_mut(&format!("/extensions/{own_extension}")) {
                visit_keys(ext, OWN_ACCESSOR_KEYS, &mut visit);
            }
        }
        for skin in self.existing_mut("skins") {
            if let Some(i) = skin.get_mut("inverseBindMatrices") {
                visit(i);
            }
        }
        for animation in self.existing_mut("animations") {
            for sampler in animation.get_mut("samplers").and_then(Value::as_array_mut).into_iter().flatten() {
                for key in ["input", "output"] {
                    if let Some(i) = sampler.get_mut(key) {
                        visit(i);
                    }
                }
            }
        }
        for node in self.existing_mut("nodes") {
            let instancing =
                node.pointer_mut("/extensions/EXT_mesh_gpu_instancing/attributes").and_then(Value::as_object_mut);
            for (_, a) in instancing.into_iter().flatten() {
                visit(a);
            }
        }
    }

    /// Adds `name` to `extensionsUsed` and `extensionsRequired`, once each.
    pub fn require_extension(&mut self, name: &str) {
        self.use_extension(name);
        let required = self.array_mut("extensionsRequired");
        if !required.iter().any(|v| v.as_str() == Some(name)) {
            required.push(Value::String(name.to_owned()));
        }
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

    /// A .glb: header, JSON chunk (space padded), BIN chunk (zero padded); and its byte sections.
    /// Node `n` gets `node_extension(n)` (if any) as its extension `name`, see [`NodeExtensions`].
    pub fn into_glb(
        mut self,
        name: &str,
        node_extension: NodeExtensionFn,
    ) -> Result<(Vec<u8>, ByteSections), FormatError> {
        self.set_buffer(None);
        let tree = std::mem::take(&mut self.json);
        let json = serde_json::to_vec(&NodeExtensions::over(&tree, name, node_extension))?;
        let glb = crate::glb::write(&json, &self.bin).map_err(FormatError::from)?;
        let sections = sections_of(&tree, json.len().next_multiple_of(4) as u64, glb.len() as u64);
        Ok((glb, sections))
    }

    /// A .gltf (pretty JSON) and its .bin, the buffer referring to `bin_uri`; and their byte
    /// sections. Node extensions as for [`Doc::into_glb`].
    pub fn into_gltf(
        mut self,
        bin_uri: &str,
        name: &str,
        node_extension: NodeExtensionFn,
    ) -> Result<(Vec<u8>, Vec<u8>, ByteSections), FormatError> {
        self.set_buffer(Some(bin_uri));
        let tree = std::mem::take(&mut self.json);
        let mut json = serde_json::to_vec_pretty(&NodeExtensions::over(&tree, name, node_extension))?;
        json.push(b'\n');
        let bin = std::mem::take(&mut self.bin);
        let sections = sections_of(&tree, json.len() as u64, (json.len() + bin.len()) as u64);
        Ok((json, bin, sections))
    }
}

/// The extension object of node `n`, made when the node is serialised (`None`: the node keeps the
/// extensions it has).
pub(crate) type NodeExtensionFn<'a> = &'a dyn Fn(usize) -> Option<Result<Value, serde_json::Error>>;

/// A document tree serialised with node `n`'s `extensions.<name>` set to `node_extension(n)`: the
/// bytes `serde_json` writes for the tree with those objects inserted, without holding all of
/// them at once (one node's at a time).
struct NodeExtensions<'a> {
    tree: &'a Map<String, Value>,
    name: &'a str,
    node_extension: NodeExtensionFn<'a>,
}

impl<'a> NodeExtensions<'a> {
    fn over(tree: &'a Map<String, Value>, name: &'a str, node_extension: NodeExtensionFn<'a>) -> Self {
        NodeExtensions { tree, name, node_extension }
    }
}

impl serde::Serialize for NodeExtensions<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.tree.get("nodes").and_then(Value::as_array) {
            Some(nodes) => {
                WithEntry { map: Some(self.tree), key: "nodes", value: NodesOut { nodes, of: self } }.serialize(s)
            }
            None => self.tree.serialize(s),
        }
    }
}

struct NodesOut<'a> {
    nodes: &'a [Value],
    of: &'a NodeExtensions<'a>,
}

impl serde::Serialize for NodesOut<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeSeq};
        let mut seq = s.serialize_seq(Some(self.nodes.len()))?;
        for (n, node) in self.nodes.iter().enumerate() {
            match (self.of.node_extension)(n) {
                Some(ext) => {
                    let ext = ext.map_err(S::Error::custom)?;
                    if !(node.is_object() || node.is_null()) {
                        return Err(S::Error::custom(format!(
                            "node {n} is not an object; its part records have no place"
                        )));
                    }
                    let existing = node.get("extensions").and_then(Value::as_object);
                    let extensions = WithEntry { map: existing, key: self.of.name, value: &ext };
                    seq.serialize_element(&WithEntry { map: node.as_object(), key: "extensions", value: extensions })?;
                }
                None => seq.serialize_element(node)?,
            }
        }
        seq.end()
    }
}

/// `map` (none: empty) with `key` set to `value`: replaced, or inserted where the map's sorted
/// order puts it, as `serde_json` writes a `Map` that holds it.
struct WithEntry<'a, V> {
    map: Option<&'a Map<String, Value>>,
    key: &'a str,
    value: V,
}

impl<V: serde::Serialize> serde::Serialize for WithEntry<'_, V> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let empty = Map::new();
        let map = self.map.unwrap_or(&empty);
        let mut out = s.serialize_map(Some(map.len() + usize::from(!map.contains_key(self.key))))?;
        let mut written = false;
        for (k, v) in map {
            if !written && k.as_str() >= self.key {
                out.serialize_entry(self.key, &self.value)?;
                written = true;
                if k == self.key {
                    continue;
                }
            }
            out.serialize_entry(k, v)?;
        }
        if !written {
            out.serialize_entry(self.key, &self.value)?;
        }
        out.end()
    }
}

/// `values` as little-endian bytes, `N` a value, written into a buffer sized once (collecting a
/// `flat_map` pushes byte by byte, with a capacity check each time).
fn le_bytes<T, const N: usize>(values: &[T], encode: impl Fn(&T) -> [u8; N]) -> Vec<u8> {
    let mut bytes = vec![0u8; values.len() * N];
    for (out, value) in bytes.chunks_exact_mut(N).zip(values) {
        out.copy_from_slice(&encode(value));
    }
    bytes
}

/// The key [`Doc::push_view`] files a view under: a multiply-rotate hash of the bytes, eight at a
/// time (FxHash's step; the standard SipHash over the dragon's 28 MB was about 9 ms of the serial
/// write in a profile). Only a key: a view is reused after comparing its bytes, so a collision
/// costs a comparison, never a wrong view.
fn content_hash(bytes: &[u8], target: Option<u32>, stride: Option<usize>) -> u64 {
    const K: u64 = 0x9e37_79b9_7f4a_7c15;
    let step = |h: u64, word: u64| (h.rotate_left(5) ^ word).wrapping_mul(K);
    let (words, tail) = bytes.as_chunks::<8>();
    let mut h = words.iter().fold(bytes.len() as u64, |h, w| step(h, u64::from_le_bytes(*w)));
    let mut last = [0u8; 8];
    last[..tail.len()].copy_from_slice(tail);
    h = step(h, u64::from_le_bytes(last));
    h = step(h, target.map_or(u64::MAX, u64::from));
    step(h, stride.map_or(u64::MAX, |s| s as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tree with node `n`'s `extensions.<name>` set to `ext(n)` (or the node left as it is), as
    /// the writer built it before [`NodeExtensions`]: the reference.
    fn inserted(tree: &Map<String, Value>, name: &str, ext: &dyn Fn(usize) -> Option<Value>) -> Value {
        let mut tree = tree.clone();
        if let Some(Value::Array(nodes)) = tree.get_mut("nodes") {
            for (n, node) in nodes.iter_mut().enumerate() {
                if let Some(e) = ext(n) {
                    if !node["extensions"].is_object() {
                        node["extensions"] = json!({});
                    }
                    node["extensions"][name] = e;
                }
            }
        }
        Value::Object(tree)
    }

    #[test]
    fn identical_arrays_are_written_once() {
        let mut doc = Doc::new(Map::new());
        let (a, b) = ([[0.0f32, 1.0, 2.0], [3.0, 4.0, -0.0]], [[0.0f32, 1.0, 2.0], [3.0, 4.0, 0.0]]);
        let first = doc.push_vec3(&a, true);
        assert_eq!(doc.push_vec3(&a, true), first, "same bytes and JSON: the same accessor");
        let unbounded = doc.push_vec3(&a, false);
        assert_ne!(unbounded, first, "same view, other JSON (no min/max): another accessor");
        assert_eq!(doc.array("accessors")[unbounded]["bufferView"], doc.array("accessors")[first]["bufferView"]);
        assert_eq!(doc.push_vec3(&a, false), unbounded);
        // -0.0 and 0.0 differ in bytes: another view and accessor.
        let other = doc.push_vec3(&b, true);
        assert_ne!(other, first);
        assert_eq!((doc.array("accessors").len(), doc.array("bufferViews").len()), (3, 2));
        // The same bytes read by an extension only (no vertex-buffer target): another view.
        let scalars = doc.push_f32_scalars(a.as_flattened());
        assert_eq!(doc.push_f32_scalars(a.as_flattened()), scalars);
        assert_eq!((doc.array("accessors").len(), doc.array("bufferViews").len()), (4, 3));
    }

    #[test]
    fn node_extensions_serialise_as_the_tree_that_holds_them() {
        // Every node but the last gets an extension; the cases put `extensions` and our key first,
        // between and after the existing keys, in place of an old one and of a non-object.
        let node_cases = [
            json!({"mesh": 0, "name": "plain"}),
            json!({"children": [2, 3], "extensions": {"AAA_first": {"x": 1}, "ZZZ_last": true}, "mesh": 1}),
            json!({"extensions": {"DRAFTER_illustration": {"stale": 1}, "KHR_other": {}}, "matrix": [1, 0]}),
            json!({"camera": 0, "extensions": 7}),
            json!({"a": 1, "z": 2}),
            Value::Null,
            json!({}),
            json!({"extensions": {}}),
            json!({"camera": 0, "children": [1]}),
            json!({"extensions": {"AAA": 1, "DRAFTER_": 2, "DRAFTER_illustrationX": 3, "drafter_illustration": 4}}),
            json!({"extensions": {"DRAFTER_illustrationX": 3}, "mesh": 2}),
            json!({"mesh": 3}),
        ];
        let last = node_cases.len() - 1;
        let ours =
            |n: usize| (n != last).then(|| json!({"parts": [{"id": n, "name": format!("p{n}"), "v": [1.5, -0.0]}]}));
        let mut tree = Map::new();
        tree.insert("asset".into(), json!({"version": "2.0"}));
        tree.insert("nodes".into(), Value::Array(node_cases.to_vec()));
        tree.insert("scenes".into(), json!([{"nodes": [0]}]));
        let name = "DRAFTER_illustration";
        let made = |n: usize| ours(n).map(Ok);
        let expected = inserted(&tree, name, &ours);
        let written = NodeExtensions::over(&tree, name, &made);
        assert_eq!(serde_json::to_string(&written).unwrap(), serde_json::to_string(&expected).unwrap());
        assert_eq!(serde_json::to_string_pretty(&written).unwrap(), serde_json::to_string_pretty(&expected).unwrap());
        // No node extensions, and a tree without nodes: the tree as it is.
        let none = |_: usize| None;
        assert_eq!(
            serde_json::to_string(&NodeExtensions::over(&tree, name, &none)).unwrap(),
            serde_json::to_string(&tree).unwrap()
        );
        // A record that cannot be made, or a node that cannot hold one, fails the serialisation.
        let failing = |n: usize| (n == 2).then(|| Err(serde::ser::Error::custom("no record")));
        assert!(serde_json::to_string(&NodeExtensions::over(&tree, name, &failing)).is_err());
        let mut odd = tree.clone();
        odd.insert("nodes".into(), json!([{"mesh": 0}, 7]));
        assert!(serde_json::to_string(&NodeExtensions::over(&odd, name, &made)).is_err());
        let first_only = |n: usize| if n == 0 { made(n) } else { None };
        assert!(serde_json::to_string(&NodeExtensions::over(&odd, name, &first_only)).is_ok());
        tree.remove("nodes");
        assert_eq!(
            serde_json::to_string(&NodeExtensions::over(&tree, name, &made)).unwrap(),
            serde_json::to_string(&tree).unwrap()
        );
    }
}
