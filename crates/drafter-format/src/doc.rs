//! A glTF document under construction: the typed document ([`crate::gltf::Root`]) plus one binary
//! buffer that new buffer views append to. Only this module touches buffer/bufferView/accessor
//! bookkeeping.

use std::collections::HashMap;

use serde_json::Value;

use crate::FormatError;
use crate::accessor::{ARRAY_BUFFER, ComponentType, ELEMENT_ARRAY_BUFFER};
use crate::gltf::{Accessor, Buffer, BufferView, Extensible, Node, Root};
use crate::reader::{ByteSections, sections_of};

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
    pub root: Root,
    pub bin: Vec<u8>,
    /// The buffer views this writer pushed, by a hash of their bytes, and the accessors it pushed,
    /// by their buffer view (then compared by their JSON text): an identical push reuses the
    /// first. Meshes that share their data in the input (two glTF meshes on the same accessors, as
    /// CAD exports write a part used with two materials) are baked separately but come out
    /// byte-identical, and are stored once again.
    pushed_views: HashMap<u64, Vec<usize>>,
    pushed_accessors: HashMap<u64, Vec<usize>>,
}

impl Doc {
    pub fn new(root: Root) -> Self {
        Self { root, bin: Vec::new(), pushed_views: HashMap::new(), pushed_accessors: HashMap::new() }
    }

    /// Starts from a source document, moving every buffer's bytes into the one binary buffer and
    /// rebasing the buffer views onto it.
    pub fn from_source(json_text: &str, buffers: &[Vec<u8>]) -> Result<Self, FormatError> {
        let root = Root::from_slice(json_text.as_bytes()).map_err(|e| FormatError::Source(e.to_string()))?;
        let mut doc = Doc::new(root);
        let declared: Vec<usize> = doc.root.buffers().iter().map(|b| b.byte_length.unwrap_or(0) as usize).collect();
        let mut bases = Vec::with_capacity(buffers.len());
        for (i, data) in buffers.iter().enumerate() {
            doc.align(4);
            bases.push(doc.bin.len() as u64);
            let length = declared.get(i).copied().unwrap_or(data.len()).min(data.len());
            doc.bin.extend_from_slice(&data[..length]);
        }
        for view in doc.root.buffer_views.iter_mut().flatten() {
            let buffer = view.buffer.unwrap_or(0) as usize;
            let offset = view.byte_offset.unwrap_or(0);
            let base = *bases
                .get(buffer)
                .ok_or_else(|| FormatError::Source(format!("bufferView names missing buffer {buffer}")))?;
            view.buffer = Some(0);
            view.byte_offset = Some(base + offset);
        }
        doc.root.buffers = None;
        Ok(doc)
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
            let view = &doc.root.buffer_views()[v];
            let start = view.byte_offset.unwrap_or(0) as usize;
            view.target == target.map(u64::from)
                && view.byte_stride == stride.map(|s| s as u64)
                && doc.bin.get(start..start + bytes.len()) == Some(bytes)
                && view.byte_length == Some(bytes.len() as u64)
        };
        if let Some(&v) = self.pushed_views.get(&key).and_then(|vs| vs.iter().find(|&&v| same(self, v))) {
            return v;
        }
        self.align(4);
        let view = BufferView {
            buffer: Some(0),
            byte_offset: Some(self.bin.len() as u64),
            byte_length: Some(bytes.len() as u64),
            target: target.map(u64::from),
            byte_stride: stride.map(|s| s as u64),
            ..BufferView::default()
        };
        self.bin.extend_from_slice(bytes);
        let views = self.root.buffer_views.get_or_insert_default();
        views.push(view);
        let index = views.len() - 1;
        self.pushed_views.entry(key).or_default().push(index);
        index
    }

    fn push_accessor(&mut self, accessor: Accessor) -> usize {
        // Only an accessor on a buffer view that an earlier push used can repeat one, and views are
        // mostly new: the JSON text is formatted only then (formatting every accessor to key a map
        // was about a sixth of the write stage for 20,000 small meshes: 13 % of a one-thread
        // profile against the stage's 73 %).
        let view = accessor.buffer_view;
        if let Some(earlier) = view.and_then(|v| self.pushed_accessors.get(&v)) {
            // Compared as text, as written: `Value`'s `==` takes -0.0 for 0.0 (in `min`, `max`).
            let text = |a: &Accessor| Value::from(a.clone()).to_string();
            let new = text(&accessor);
            let accessors = self.root.accessors();
            let same = |a: usize| accessors.get(a).is_some_and(|e| text(e) == new);
            if let Some(&a) = earlier.iter().find(|&&a| same(a)) {
                return a;
            }
        }
        let accessors = self.root.accessors.get_or_insert_default();
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
        let mut accessor = Accessor::new(view, ComponentType::F32, values.len(), "VEC3");
        if with_bounds && !values.is_empty() {
            let (lo, hi) = values.iter().fold(([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]), |(lo, hi), v| {
                (std::array::from_fn(|i| lo[i].min(v[i])), std::array::from_fn(|i| hi[i].max(v[i])))
            });
            accessor.min = Some(Value::from(lo.to_vec()));
            accessor.max = Some(Value::from(hi.to_vec()));
        }
        self.push_accessor(accessor)
    }

    /// VEC3 BYTE normalized vertex attribute (`drafter_core::snorm`): a 4-byte stride with one
    /// padding byte, as the spec requires of vertex data.
    pub fn push_snorm8_attribute(&mut self, values: &[[i8; 3]]) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| [v[0] as u8, v[1] as u8, v[2] as u8, 0]).collect();
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), Some(4));
        let accessor = Accessor::new(view, ComponentType::I8, values.len(), "VEC3");
        self.push_accessor(Accessor { normalized: Some(true), ..accessor })
    }

    /// VEC3 unit vectors in their stored component type (BYTE or SHORT normalized, or FLOAT),
    /// tightly packed, read only by an extension.
    pub fn push_unit_vec3(&mut self, values: &crate::StoredNormals) -> usize {
        use crate::StoredNormals;
        let (component, normalized, bytes): (ComponentType, bool, Vec<u8>) = match values {
            StoredNormals::Byte(v) => (ComponentType::I8, true, v.iter().flatten().map(|&c| c as u8).collect()),
            StoredNormals::Short(v) => (ComponentType::I16, true, le_bytes(v.as_flattened(), |c| c.to_le_bytes())),
            StoredNormals::Float(v) => (ComponentType::F32, false, le_bytes(v.as_flattened(), |c| c.to_le_bytes())),
        };
        let view = self.push_view(&bytes, None, None);
        let accessor = Accessor::new(view, component, values.len(), "VEC3");
        self.push_accessor(Accessor { normalized: normalized.then_some(true), ..accessor })
    }

    /// Appends a material and returns its index.
    pub fn push_material(&mut self, material: crate::gltf::Material) -> usize {
        let materials = self.root.materials.get_or_insert_default();
        materials.push(material);
        materials.len() - 1
    }

    pub fn push_vec2(&mut self, values: &[[f32; 2]]) -> usize {
        let bytes = le_bytes(values.as_flattened(), |c| c.to_le_bytes());
        let view = self.push_view(&bytes, Some(ARRAY_BUFFER), None);
        self.push_accessor(Accessor::new(view, ComponentType::F32, values.len(), "VEC2"))
    }

    /// SCALAR FLOAT data read only by an extension.
    pub fn push_f32_scalars(&mut self, values: &[f32]) -> usize {
        let bytes = le_bytes(values, |c| c.to_le_bytes());
        let view = self.push_view(&bytes, None, None);
        self.push_accessor(Accessor::new(view, ComponentType::F32, values.len(), "SCALAR"))
    }

    /// SCALAR data of exactly this component type, read only by an extension.
    pub fn push_typed_scalars(&mut self, component: ComponentType, bytes: &[u8], count: usize) -> usize {
        let view = self.push_view(bytes, None, None);
        self.push_accessor(Accessor::new(view, component, count, "SCALAR"))
    }

    /// Unsigned SCALAR data in the smallest component type that holds `max(values)`.
    /// `target` is ELEMENT_ARRAY_BUFFER for indices, None for data read only by our extension.
    pub fn push_scalars(&mut self, values: &[u32], target: Option<u32>) -> usize {
        let max = values.iter().copied().max().unwrap_or(0);
        // Index buffers may not use the primitive-restart value (2^n - 1) of their type.
        let restart_safe = target == Some(ELEMENT_ARRAY_BUFFER);
        let (component, bytes): (ComponentType, Vec<u8>) = if max < 255 || (!restart_safe && max <= 255) {
            (ComponentType::U8, values.iter().map(|&v| v as u8).collect())
        } else if max < 65535 || (!restart_safe && max <= 65535) {
            (ComponentType::U16, le_bytes(values, |&v| (v as u16).to_le_bytes()))
        } else {
            (ComponentType::U32, le_bytes(values, |v| v.to_le_bytes()))
        };
        // Index data of one byte is allowed; vertex attributes would need a 4-byte stride.
        let view = self.push_view(&bytes, target, None);
        self.push_accessor(Accessor::new(view, component, values.len(), "SCALAR"))
    }

    /// Copies the elements `picks` of a vertex-attribute accessor into a new tightly packed accessor
    /// (4-byte aligned elements, as the spec requires for vertex data). Works on the raw bytes, so
    /// any component type passes through unchanged; min/max are dropped (optional for everything
    /// but POSITION, which callers write themselves). Sparse accessors are not supported.
    pub fn gather_attribute(&mut self, accessor: usize, picks: &[u32]) -> Result<usize, FormatError> {
        let bad = |what: &str| FormatError::Source(format!("/accessors/{accessor}: {what}"));
        let a = self.root.accessors().get(accessor).cloned().ok_or_else(|| bad("missing"))?;
        if a.sparse.is_some() {
            return Err(bad("sparse vertex attributes cannot be re-laid out"));
        }
        let component = a.component().ok_or_else(|| bad("unknown componentType"))?.size();
        let components = a.kind.as_deref().and_then(crate::accessor::components).ok_or_else(|| bad("unknown type"))?;
        let element = component * components;
        let view_index = a.buffer_view.ok_or_else(|| bad("no bufferView"))? as usize;
        let view = self.root.buffer_views().get(view_index).ok_or_else(|| bad("bufferView missing"))?;
        let stride = view.byte_stride.map_or(element, |s| s as usize);
        let base = view.byte_offset.unwrap_or(0) as usize + a.byte_offset.unwrap_or(0) as usize;
        let count = a.count.unwrap_or(0) as usize;
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
        let out = Accessor {
            buffer_view: Some(view as u64),
            component_type: a.component_type,
            count: Some(picks.len() as u64),
            kind: a.kind,
            normalized: (a.normalized == Some(true)).then_some(true),
            ..Accessor::default()
        };
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
        let used = self.root.extensions_used.as_deref().unwrap_or_default();
        if used.iter().any(|e| e != own_extension && !COMPACTION_SAFE_EXTENSIONS.contains(&e.as_str())) {
            return Err("the input uses extensions drafter does not know");
        }
        const DANGLING: &str = "the input refers to accessors or buffer views it does not have";
        let accessor_count = self.root.accessors().len();
        let view_count = self.root.buffer_views().len();
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
        for (a, accessor) in self.root.accessors().iter().enumerate() {
            if keep_accessor[a] {
                accessor_views(accessor).for_each(|v| keep(*v));
            }
        }
        for image in self.root.images() {
            image.buffer_view.into_iter().for_each(&mut keep);
        }
        if dangling {
            return Err(DANGLING);
        }
        let view_map = renumbering(&keep_view);
        // 3. New buffer from the kept views, 4-byte aligned.
        let old_bin = std::mem::take(&mut self.bin);
        let mut views = Vec::new();
        for (v, mut view) in self.root.buffer_views.take().into_iter().flatten().enumerate() {
            if !keep_view[v] {
                continue;
            }
            let start = view.byte_offset.unwrap_or(0) as usize;
            let length = view.byte_length.unwrap_or(0) as usize;
            self.align(4);
            view.byte_offset = Some(self.bin.len() as u64);
            let bytes = start.checked_add(length).and_then(|end| old_bin.get(start..end));
            self.bin.extend_from_slice(bytes.unwrap_or_default());
            views.push(view);
        }
        self.root.buffer_views = Some(views);
        // 4. Renumber.
        let renumber = |v: &mut u64| *v = u64::from(view_map[*v as usize]);
        let accessors = self.root.accessors.take().into_iter().flatten().enumerate();
        let accessors: Vec<Accessor> = accessors
            .filter(|(a, _)| keep_accessor[*a])
            .map(|(_, mut accessor)| {
                accessor_views_mut(&mut accessor).for_each(renumber);
                accessor
            })
            .collect();
        self.root.accessors = Some(accessors);
        for image in self.root.images.iter_mut().flatten() {
            image.buffer_view.iter_mut().for_each(renumber);
        }
        self.visit_accessor_refs(own_extension, &mut |i| *i = u64::from(accessor_map[*i as usize]));
        Ok(())
    }

    /// Calls `f` on every accessor reference of the document (glTF 2.0 core, EXT_mesh_gpu_instancing
    /// and the keys of our own extension and EXT_mesh_primitive_edge_visibility that hold one).
    fn visit_accessor_refs(&mut self, own_extension: &str, f: &mut dyn FnMut(&mut u64)) {
        let primitive_extensions: [(&str, &[&str]); 2] =
            [(own_extension, OWN_ACCESSOR_KEYS), (EDGE_VISIBILITY, EDGE_VISIBILITY_ACCESSOR_KEYS)];
        self.root.visit_accessor_refs(&primitive_extensions, &[(own_extension, OWN_ACCESSOR_KEYS)], f);
    }

    /// Adds `name` to `extensionsUsed` and `extensionsRequired`, once each.
    pub fn require_extension(&mut self, name: &str) {
        self.use_extension(name);
        let required = self.root.extensions_required.get_or_insert_default();
        if !required.iter().any(|v| v == name) {
            required.push(name.to_owned());
        }
    }

    /// Adds `name` to `extensionsUsed` once.
    pub fn use_extension(&mut self, name: &str) {
        let used = self.root.extensions_used.get_or_insert_default();
        if !used.iter().any(|v| v == name) {
            used.push(name.to_owned());
        }
    }

    /// The single buffer's entry, with a URI for the .gltf container.
    fn set_buffer(&mut self, uri: Option<&str>) {
        self.root.buffers = (!self.bin.is_empty()).then(|| {
            vec![Buffer { byte_length: Some(self.bin.len() as u64), uri: uri.map(str::to_owned), ..Buffer::default() }]
        });
    }

    /// A .glb: header, JSON chunk (space padded), BIN chunk (zero padded); and its byte sections.
    /// Node `n` gets `node_extension(n)` (if any) as its extension `name`, see [`NodeExtensions`].
    pub fn into_glb(
        mut self,
        name: &str,
        node_extension: NodeExtensionFn,
    ) -> Result<(Vec<u8>, ByteSections), FormatError> {
        self.set_buffer(None);
        let counted = sections_of(&self.root);
        let json = serde_json::to_vec(&NodeExtensions::over(self.root, name, node_extension))?;
        let glb = crate::glb::write(&json, &self.bin).map_err(FormatError::from)?;
        let sections = counted.sized(json.len().next_multiple_of(4) as u64, glb.len() as u64);
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
        let counted = sections_of(&self.root);
        let mut json = serde_json::to_vec_pretty(&NodeExtensions::over(self.root, name, node_extension))?;
        json.push(b'\n');
        let bin = std::mem::take(&mut self.bin);
        let sections = counted.sized(json.len() as u64, (json.len() + bin.len()) as u64);
        Ok((json, bin, sections))
    }
}

/// The buffer views an accessor reads: its own and its sparse indices' and values'.
fn accessor_views(accessor: &Accessor) -> impl Iterator<Item = &u64> {
    let sparse = accessor.sparse.as_ref();
    let parts = sparse.into_iter().flat_map(|s| s.indices.iter().chain(&s.values));
    accessor.buffer_view.iter().chain(parts.flat_map(|p| &p.buffer_view))
}

/// [`accessor_views`], to renumber.
fn accessor_views_mut(accessor: &mut Accessor) -> impl Iterator<Item = &mut u64> {
    let sparse = accessor.sparse.as_mut();
    let parts = sparse.into_iter().flat_map(|s| s.indices.iter_mut().chain(&mut s.values));
    accessor.buffer_view.iter_mut().chain(parts.flat_map(|p| &mut p.buffer_view))
}

/// The extension object of node `n`, made when the node is serialised (`None`: the node keeps the
/// extensions it has).
pub(crate) type NodeExtensionFn<'a> = &'a dyn Fn(usize) -> Option<Result<Value, serde_json::Error>>;

/// A document serialised with node `n`'s `extensions.<name>` set to `node_extension(n)`: the
/// bytes `serde_json` writes for the document with those objects inserted, without holding all of
/// them at once (one node's at a time).
struct NodeExtensions<'a> {
    /// The document's members but `nodes`, as JSON.
    tree: serde_json::Map<String, Value>,
    nodes: Option<Vec<Node>>,
    name: &'a str,
    node_extension: NodeExtensionFn<'a>,
}

impl<'a> NodeExtensions<'a> {
    fn over(mut root: Root, name: &'a str, node_extension: NodeExtensionFn<'a>) -> Self {
        let nodes = root.nodes.take();
        let tree = match Value::from(root) {
            Value::Object(tree) => tree,
            _ => unreachable!("an object is written as a JSON object"),
        };
        NodeExtensions { tree, nodes, name, node_extension }
    }
}

impl serde::Serialize for NodeExtensions<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.nodes {
            Some(nodes) => {
                WithEntry { map: &self.tree, key: "nodes", value: NodesOut { nodes, of: self } }.serialize(s)
            }
            None => self.tree.serialize(s),
        }
    }
}

struct NodesOut<'a> {
    nodes: &'a [Node],
    of: &'a NodeExtensions<'a>,
}

impl serde::Serialize for NodesOut<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::{Error, SerializeSeq};
        let mut seq = s.serialize_seq(Some(self.nodes.len()))?;
        for (n, node) in self.nodes.iter().enumerate() {
            let mut node = node.clone();
            if let Some(ext) = (self.of.node_extension)(n) {
                node.set_extension(self.of.name, ext.map_err(S::Error::custom)?);
            }
            seq.serialize_element(&Value::from(node))?;
        }
        seq.end()
    }
}

/// `map` with `key` set to `value`: inserted where the map's sorted order puts it, as `serde_json`
/// writes a `Map` that holds it (`map` does not hold `key`).
struct WithEntry<'a, V> {
    map: &'a serde_json::Map<String, Value>,
    key: &'a str,
    value: V,
}

impl<V: serde::Serialize> serde::Serialize for WithEntry<'_, V> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut out = s.serialize_map(Some(self.map.len() + 1))?;
        let mut written = false;
        for (k, v) in self.map {
            if !written && k.as_str() > self.key {
                out.serialize_entry(self.key, &self.value)?;
                written = true;
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
/// time (FxHash's step; the standard SipHash is several times slower and shows in the serial
/// write of a large mesh). Only a key: a view is reused after comparing its bytes, so a collision
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
    use serde::Deserialize;
    use serde_json::json;

    use super::*;

    /// The document as JSON with node `n`'s `extensions.<name>` set to `ext(n)` (or the node left as
    /// it is), built whole: the reference.
    fn inserted(root: &Root, name: &str, ext: &dyn Fn(usize) -> Option<Value>) -> Value {
        let mut root = root.clone();
        for (n, node) in root.nodes.iter_mut().flatten().enumerate() {
            if let Some(e) = ext(n) {
                node.set_extension(name, e);
            }
        }
        Value::from(root)
    }

    #[test]
    fn identical_arrays_are_written_once() {
        let mut doc = Doc::new(Root::default());
        let (a, b) = ([[0.0f32, 1.0, 2.0], [3.0, 4.0, -0.0]], [[0.0f32, 1.0, 2.0], [3.0, 4.0, 0.0]]);
        let first = doc.push_vec3(&a, true);
        assert_eq!(doc.push_vec3(&a, true), first, "same bytes and JSON: the same accessor");
        let unbounded = doc.push_vec3(&a, false);
        assert_ne!(unbounded, first, "same view, other JSON (no min/max): another accessor");
        assert_eq!(doc.root.accessors()[unbounded].buffer_view, doc.root.accessors()[first].buffer_view);
        assert_eq!(doc.push_vec3(&a, false), unbounded);
        // -0.0 and 0.0 differ in bytes: another view and accessor.
        let other = doc.push_vec3(&b, true);
        assert_ne!(other, first);
        assert_eq!((doc.root.accessors().len(), doc.root.buffer_views().len()), (3, 2));
        // The same bytes read by an extension only (no vertex-buffer target): another view.
        let scalars = doc.push_f32_scalars(a.as_flattened());
        assert_eq!(doc.push_f32_scalars(a.as_flattened()), scalars);
        assert_eq!((doc.root.accessors().len(), doc.root.buffer_views().len()), (4, 3));
    }

    #[test]
    fn compaction_drops_what_nothing_reads_and_renumbers_every_reference() {
        // Views 0-5 of 4 bytes each; accessor 0 (on view 1) is read by nothing, so both go. Every
        // other accessor is read from one of the places the compaction knows.
        let document = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["EXT_mesh_gpu_instancing", "DRAFTER_illustration"],
            "bufferViews": (0..6).map(|v| json!({"buffer": 0, "byteOffset": 4 * v, "byteLength": 4})).collect::<Vec<_>>(),
            "accessors": [
                {"bufferView": 1, "componentType": 5126, "count": 1, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 1, "type": "SCALAR", "min": [0, -0.0]},
                {"bufferView": 3, "componentType": 5126, "count": 1, "type": "SCALAR"},
                {"componentType": 5126, "count": 1, "type": "SCALAR",
                 "sparse": {"count": 1, "indices": {"bufferView": 4, "componentType": 5121}, "values": {"bufferView": 5}}},
                {"bufferView": 2, "componentType": 5126, "count": 1, "type": "SCALAR"}
            ],
            "images": [{"bufferView": 0, "mimeType": "image/png"}],
            "meshes": [{"primitives": [{
                "attributes": {"POSITION": 1},
                "targets": [{"POSITION": 2, "_X": "not an index"}],
                "extensions": {"DRAFTER_illustration": {"partLabels": 4}}
            }]}],
            "skins": [{"inverseBindMatrices": 3, "joints": [0]}],
            "animations": [{"samplers": [{"input": 4, "output": 4}], "channels": []}],
            "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 4}}}}]
        });
        let mut doc = Doc::new(Root::deserialize(&document).expect("a document"));
        doc.bin = (0..24).collect();
        doc.compact("DRAFTER_illustration").expect("compacts");
        let views: Vec<_> = doc.root.buffer_views().iter().map(|v| (v.byte_offset, v.byte_length)).collect();
        assert_eq!(views, (0..5).map(|v| (Some(4 * v), Some(4))).collect::<Vec<_>>());
        assert_eq!(doc.bin, [0, 1, 2, 3].into_iter().chain(8..24).collect::<Vec<u8>>(), "view 1's bytes gone");
        let out = Value::from(doc.root);
        let accessors = &out["accessors"];
        assert_eq!(accessors.as_array().map(Vec::len), Some(4));
        assert_eq!((&accessors[0]["bufferView"], &accessors[0]["min"]), (&json!(1), &json!([0, -0.0])));
        assert_eq!(accessors[1]["bufferView"], 2);
        assert_eq!(
            accessors[2]["sparse"],
            json!({"count": 1, "indices": {"bufferView": 3, "componentType": 5121}, "values": {"bufferView": 4}})
        );
        assert_eq!(accessors[3]["bufferView"], 1);
        assert_eq!(out["images"][0]["bufferView"], 0);
        let primitive = &out["meshes"][0]["primitives"][0];
        assert_eq!(primitive["attributes"]["POSITION"], 0);
        assert_eq!(primitive["targets"], json!([{"POSITION": 1, "_X": "not an index"}]));
        assert_eq!(primitive["extensions"]["DRAFTER_illustration"]["partLabels"], 3);
        assert_eq!(out["skins"][0], json!({"inverseBindMatrices": 2, "joints": [0]}));
        assert_eq!(out["animations"][0]["samplers"][0], json!({"input": 3, "output": 3}));
        assert_eq!(out["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"], 3);
        // A reference to an accessor the document lacks leaves it as it is.
        let mut dangling = Doc::new(Root::deserialize(&json!({"meshes": [{"primitives": [{"indices": 9}]}]})).unwrap());
        assert!(dangling.compact("DRAFTER_illustration").is_err());
    }

    #[test]
    fn node_extensions_serialise_as_the_document_that_holds_them() {
        // Every node but the last gets an extension; the cases put `extensions` and our key first,
        // between and after the existing keys, and in place of an old one.
        let node_cases = json!([
            {"mesh": 0, "name": "plain"},
            {"children": [2, 3], "extensions": {"AAA_first": {"x": 1}, "ZZZ_last": true}, "mesh": 1},
            {"extensions": {"DRAFTER_illustration": {"stale": 1}, "KHR_other": {}}, "matrix": [1, 0]},
            {"camera": 0, "extensions": {}},
            {"a": 1, "z": 2},
            {},
            {"extensions": {}},
            {"camera": 0, "children": [1]},
            {"extensions": {"AAA": 1, "DRAFTER_": 2, "DRAFTER_illustrationX": 3, "drafter_illustration": 4}},
            {"extensions": {"DRAFTER_illustrationX": 3}, "mesh": 2},
            {"mesh": 3}
        ]);
        let document = json!({"asset": {"version": "2.0"}, "nodes": node_cases, "scenes": [{"nodes": [0]}]});
        let root = Root::deserialize(&document).expect("a document");
        let last = root.nodes().len() - 1;
        let ours =
            |n: usize| (n != last).then(|| json!({"parts": [{"id": n, "name": format!("p{n}"), "v": [1.5, -0.0]}]}));
        let name = "DRAFTER_illustration";
        let made = |n: usize| ours(n).map(Ok);
        let expected = inserted(&root, name, &ours);
        let written = |f: NodeExtensionFn| serde_json::to_string(&NodeExtensions::over(root.clone(), name, f));
        let written_pretty =
            |f: NodeExtensionFn| serde_json::to_string_pretty(&NodeExtensions::over(root.clone(), name, f));
        assert_eq!(written(&made).unwrap(), serde_json::to_string(&expected).unwrap());
        assert_eq!(written_pretty(&made).unwrap(), serde_json::to_string_pretty(&expected).unwrap());
        // No node extensions: the document as it is, and as it was read.
        let none = |_: usize| None;
        assert_eq!(written(&none).unwrap(), document.to_string());
        // A record that cannot be made fails the serialisation.
        let failing = |n: usize| (n == 2).then(|| Err(serde::ser::Error::custom("no record")));
        assert!(written(&failing).is_err());
        // A document without nodes.
        let bare = Root { nodes: None, ..root.clone() };
        let text = serde_json::to_string(&NodeExtensions::over(bare.clone(), name, &made)).unwrap();
        assert_eq!(text, Value::from(bare).to_string());
    }
}
