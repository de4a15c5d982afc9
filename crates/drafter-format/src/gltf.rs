//! The glTF 2.0 document as drafter reads and writes it, typed: [`Root`] and the objects below
//! it, the primitive modes and the one rule for how many triangles a primitive lists.
//!
//! **Typed, and lossless.** Each object types the members drafter reads or writes (indices,
//! counts, URIs, names, modes, GL codes: integers and strings, which write back to the same
//! text; numbers that may be floats, as `min`/`max`, a node's `matrix` and a material's factors,
//! as JSON, so that a passed-through number keeps its text); every other member (translations,
//! textures of materials, members a later glTF adds) is kept as JSON in the object's `other`, and
//! `extensions` and `extras` as they are, so a document read here and written again loses
//! nothing but the `null`s of named members, which read as absent. Members the spec requires are
//! `Option`s all the same, so a reader names what is missing where it needs it instead of
//! refusing the whole document; a member of the wrong JSON type is refused when the document is
//! read.
//!
//! **Read and written as JSON maps.** serde reads the document's text as one `serde_json::Value`;
//! each object is then taken out of its JSON map member by member ([`FromJson`]), and written by
//! moving its members back into that map ([`IntoJson`]; `Value::from(root)`), whose keys are
//! sorted, before the map is written as text: the member order every document drafter writes has
//! (serde would write a struct's fields in declaration order). The `Deserialize` and `Serialize`
//! impls go the same way. Plain functions rather than serde's visitors and serializers, which
//! would put a copy of their machinery for every member type into the browser's module, whose
//! size has a limit (the page's folder, `docs/web.md`).
//!
//! **The owner of the document's JSON.** The writer (`doc.rs`, `writer.rs`), the codecs
//! (`meshopt.rs`, `draco.rs`) and the importer edit these objects, never a `Value` tree; the one
//! walk of JSON left is over the accessor references this layer keeps as JSON
//! ([`Extensible::visit_extension_indices`]: `DRAFTER_illustration`'s records, the edges'
//! `lineStrings`, `EXT_mesh_gpu_instancing`'s attributes; morph targets), here.
//!
//! **Why not gltf-json's `Root`.** The importer reads its input through the gltf crate, whose
//! validation it wants; this layer is for the writer's pass-through of that input, the readers
//! of baked files and of inputs before an import (a batch's memory estimate). gltf-json drops the
//! members of core objects it does not know (its `Root`, `Node`, `Mesh` have no catch-all: a
//! document written back loses them), serializes fields in declaration order rather than sorted,
//! and requires `asset` and every required member up front; here an unknown member survives and a
//! missing one is the reader's to name.
//!
//! The triangle count is needed before any accessor is read — by the importer's triangle limit
//! (drafter-io), by a batch's memory estimate (drafter-catalog) and by the reader of baked files,
//! which numbers a mesh's triangles across its primitives — so the three count alike here
//! ([`triangle_count`]).

use std::collections::BTreeMap;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::accessor::ComponentType;

/// An object's members that the types here do not name, or its `extensions`, as JSON.
pub type Members = serde_json::Map<String, Value>;

/// A glTF object type: each named member an `Option` (absent stays absent when written back; a
/// JSON `null` reads as absent), written in camelCase unless given its key (`kind as "type"`), and
/// every other member in `other`. Indices are `u64`, as the importer's gltf-json takes any unsigned
/// number for one: a document that passed it (and so a baked file that passes its members through)
/// reads here too, and a reference out of range is the reader's to refuse where it follows it.
///
/// Written out rather than derived with `#[serde(flatten)]`: flatten buffers every member and
/// deserializes each type through its own copy of that machinery, which made the browser's module
/// tens of kilobytes larger. Here serde only reads the document's JSON, as one `Value`; each
/// object is then taken out of its JSON map member by member ([`FromJson`]) and moved back into
/// it to be written ([`IntoJson`], sorted, as the writer's documents are), by plain functions
/// rather than serde's visitors and serializers, which the browser's module would hold a copy of
/// for every member type.
macro_rules! object {
    ($(#[$meta:meta])* $name:ident { $($(#[$member:meta])* $field:ident $(as $key:literal)?: $ty:ty,)* }) => {
        $(#[$meta])*
        #[derive(Clone, Debug, Default, PartialEq)]
        pub struct $name {
            $($(#[$member])* pub $field: Option<$ty>,)*
            /// The members not named above, as JSON.
            pub other: Members,
        }

        impl From<$name> for Value {
            /// The object as a JSON map: its other members, and each named member that is set.
            fn from(object: $name) -> Value {
                let mut map = object.other;
                $(put(&mut map, member_name!($field $(, $key)?), object.$field.map(IntoJson::into_json));)*
                Value::Object(map)
            }
        }

        impl IntoJson for $name {
            fn into_json(self) -> Value {
                Value::from(self)
            }
        }

        impl FromJson for $name {
            fn from_json(value: Value) -> Result<Self, String> {
                let mut other = Members::from_json(value)?;
                // Every member read before the first error is returned: one drop of the whole
                // object then, rather than one of the members read so far after each.
                let mut error = None;
                let object = $name {
                    $($field: take(&mut other, member_name!($field $(, $key)?), &mut error),)*
                    other,
                };
                match error {
                    None => Ok(object),
                    Some(error) => Err(error),
                }
            }
        }

        impl Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                Value::from(self.clone()).serialize(serializer)
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                Self::from_json(Value::deserialize(deserializer)?).map_err(serde::de::Error::custom)
            }
        }
    };
}

/// A member's name: its own key, or the field's name, which [`camel_case`] makes the key (a key
/// given is one word, which it leaves as it is).
macro_rules! member_name {
    ($field:ident) => {
        stringify!($field)
    };
    ($field:ident, $key:literal) => {
        $key
    };
}

/// `buffer_views` → `bufferViews`.
fn camel_case(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    let mut upper = false;
    for c in name.chars() {
        if c == '_' {
            upper = true;
        } else if upper {
            out.extend(c.to_uppercase());
            upper = false;
        } else {
            out.push(c);
        }
    }
    out
}

/// Member `name` (see [`member_name`]) taken out of `members` and read as a `T`; absent or `null`
/// is `None`, and so is a member that does not read, whose error goes to `error` (the first
/// one). The work that does not depend on `T` is in functions of their own, not copied into
/// every object's reading of every member.
#[inline(never)]
fn take<T: FromJson>(members: &mut Members, name: &str, error: &mut Option<String>) -> Option<T> {
    match T::from_json(member(members, name)?) {
        Ok(value) => Some(value),
        Err(e) => {
            error.get_or_insert_with(|| in_member(name, e));
            None
        }
    }
}

/// Member `name` taken out of `members`; `None` when absent or `null`.
#[inline(never)]
fn member(members: &mut Members, name: &str) -> Option<Value> {
    members.remove(&camel_case(name)).filter(|value| !value.is_null())
}

/// `error` of member `name`, named.
#[inline(never)]
fn in_member(name: &str, error: String) -> String {
    format!("`{}`: {error}", camel_case(name))
}

/// Sets member `name` (see [`member_name`]) of `map` to `value`, if any.
#[inline(never)]
fn put(map: &mut Members, name: &str, value: Option<Value>) {
    if let Some(value) = value {
        map.insert(camel_case(name), value);
    }
}

/// A typed member read from its JSON, the inverse of [`IntoJson`]; `Err` names what was expected.
pub trait FromJson: Sized {
    fn from_json(value: Value) -> Result<Self, String>;
}

/// "invalid type: …, expected `what`", as serde words it.
fn unexpected(value: &Value, what: &str) -> String {
    let found = match value {
        Value::Null => "null".to_owned(),
        Value::Bool(b) => format!("boolean `{b}`"),
        Value::Number(n) => format!("number `{n}`"),
        Value::String(s) => format!("string {s:?}"),
        Value::Array(_) => "sequence".to_owned(),
        Value::Object(_) => "map".to_owned(),
    };
    format!("invalid type: {found}, expected {what}")
}

impl FromJson for u64 {
    fn from_json(value: Value) -> Result<Self, String> {
        value.as_u64().ok_or_else(|| unexpected(&value, "an unsigned integer"))
    }
}

impl FromJson for bool {
    fn from_json(value: Value) -> Result<Self, String> {
        value.as_bool().ok_or_else(|| unexpected(&value, "a boolean"))
    }
}

impl FromJson for String {
    fn from_json(value: Value) -> Result<Self, String> {
        match value {
            Value::String(s) => Ok(s),
            other => Err(unexpected(&other, "a string")),
        }
    }
}

impl FromJson for Value {
    fn from_json(value: Value) -> Result<Self, String> {
        Ok(value)
    }
}

impl FromJson for Members {
    fn from_json(value: Value) -> Result<Self, String> {
        match value {
            Value::Object(map) => Ok(map),
            other => Err(unexpected(&other, "a map")),
        }
    }
}

impl<T: FromJson> FromJson for Vec<T> {
    fn from_json(value: Value) -> Result<Self, String> {
        let Value::Array(items) = value else { return Err(unexpected(&value, "a sequence")) };
        let mut out = Vec::with_capacity(items.len());
        for item in items {
            out.push(T::from_json(item)?);
        }
        Ok(out)
    }
}

impl<T: FromJson> FromJson for BTreeMap<String, T> {
    fn from_json(value: Value) -> Result<Self, String> {
        // Inserted one by one: the members come sorted, and `collect` would bring a sort along.
        let mut out = BTreeMap::new();
        for (key, value) in Members::from_json(value)? {
            out.insert(key, T::from_json(value)?);
        }
        Ok(out)
    }
}

/// A typed member's JSON, moved into a `serde_json::Value` without serde's serializer (whose
/// copy for every member type made the browser's module tens of kilobytes larger): the values
/// `serde_json::to_value` gives, so a document written through it has the same text.
pub trait IntoJson {
    fn into_json(self) -> Value;
}

impl IntoJson for u64 {
    fn into_json(self) -> Value {
        Value::from(self)
    }
}

impl IntoJson for bool {
    fn into_json(self) -> Value {
        Value::Bool(self)
    }
}

impl IntoJson for String {
    fn into_json(self) -> Value {
        Value::String(self)
    }
}

impl IntoJson for Value {
    fn into_json(self) -> Value {
        self
    }
}

impl IntoJson for Members {
    fn into_json(self) -> Value {
        Value::Object(self)
    }
}

impl<T: IntoJson> IntoJson for Vec<T> {
    fn into_json(self) -> Value {
        let mut items = Vec::with_capacity(self.len());
        for item in self {
            items.push(item.into_json());
        }
        Value::Array(items)
    }
}

impl<T: IntoJson> IntoJson for BTreeMap<String, T> {
    fn into_json(self) -> Value {
        let mut map = Members::new();
        for (key, value) in self {
            map.insert(key, value.into_json());
        }
        Value::Object(map)
    }
}

object! {
    /// The top-level glTF object (cameras and members a later glTF adds are in `other`).
    Root {
        accessors: Vec<Accessor>,
        animations: Vec<Animation>,
        asset: Asset,
        buffer_views: Vec<BufferView>,
        buffers: Vec<Buffer>,
        extensions: Members,
        extensions_required: Vec<String>,
        extensions_used: Vec<String>,
        extras: Value,
        images: Vec<Image>,
        materials: Vec<Material>,
        meshes: Vec<Mesh>,
        nodes: Vec<Node>,
        samplers: Vec<Sampler>,
        scene: u64,
        scenes: Vec<Scene>,
        skins: Vec<Skin>,
        textures: Vec<Texture>,
    }
}

object! {
    /// `asset`.
    Asset {
        generator: String,
        version: String,
    }
}

object! {
    /// An entry of `scenes`.
    Scene {
        name: String,
        nodes: Vec<u64>,
    }
}

object! {
    /// An entry of `nodes` (`translation`, `rotation` and `scale` are in `other`).
    Node {
        children: Vec<u64>,
        extensions: Members,
        extras: Value,
        /// 16 numbers, column-major; JSON, so that a passed-through matrix keeps its text.
        matrix: Value,
        mesh: u64,
        name: String,
    }
}

object! {
    /// An entry of `meshes`.
    Mesh {
        extensions: Members,
        extras: Value,
        name: String,
        primitives: Vec<Primitive>,
    }
}

object! {
    /// An entry of a mesh's `primitives`.
    Primitive {
        /// Attribute name → accessor index.
        attributes: BTreeMap<String, u64>,
        extensions: Members,
        extras: Value,
        indices: u64,
        material: u64,
        /// The mode's code ([`Mode::from_code`]); absent means triangles.
        mode: u64,
        /// Morph targets: attribute name → accessor index, each; JSON, as the importer's gltf-json
        /// takes a target's names other than `POSITION`, `NORMAL` and `TANGENT` with any value.
        targets: Vec<Members>,
    }
}

object! {
    /// An entry of `accessors`.
    Accessor {
        buffer_view: u64,
        byte_offset: u64,
        /// The `componentType` code ([`crate::accessor::ComponentType::from_code`]).
        component_type: u64,
        count: u64,
        extensions: Members,
        extras: Value,
        /// One number per component; JSON, so that passed-through bounds keep their text.
        max: Value,
        min: Value,
        name: String,
        normalized: bool,
        sparse: Sparse,
        /// `"SCALAR"`, `"VEC3"`, … ([`crate::accessor::components`]).
        kind as "type": String,
    }
}

object! {
    /// An accessor's `sparse` (its `count` and the component type of its indices are in `other`).
    Sparse {
        indices: SparseArray,
        values: SparseArray,
    }
}

object! {
    /// The `indices` or the `values` of a sparse accessor (their `byteOffset` is in `other`).
    SparseArray {
        buffer_view: u64,
    }
}

object! {
    /// An entry of `bufferViews`.
    BufferView {
        buffer: u64,
        byte_length: u64,
        byte_offset: u64,
        byte_stride: u64,
        extensions: Members,
        extras: Value,
        name: String,
        /// [`crate::accessor::ARRAY_BUFFER`] or [`crate::accessor::ELEMENT_ARRAY_BUFFER`].
        target: u64,
    }
}

object! {
    /// An entry of `buffers`.
    Buffer {
        byte_length: u64,
        extensions: Members,
        extras: Value,
        name: String,
        uri: String,
    }
}

object! {
    /// An entry of `images`.
    Image {
        buffer_view: u64,
        extensions: Members,
        extras: Value,
        mime_type: String,
        name: String,
        uri: String,
    }
}

object! {
    /// An entry of `textures`.
    Texture {
        extensions: Members,
        extras: Value,
        name: String,
        sampler: u64,
        source: u64,
    }
}

object! {
    /// An entry of `samplers`, its GL filter and wrap codes.
    Sampler {
        extensions: Members,
        extras: Value,
        mag_filter: u64,
        min_filter: u64,
        name: String,
        wrap_s: u64,
        wrap_t: u64,
    }
}

object! {
    /// An entry of `materials` (its textures and other factors are in `other`).
    Material {
        extensions: Members,
        extras: Value,
        name: String,
        pbr_metallic_roughness: PbrMetallicRoughness,
    }
}

object! {
    /// A material's `pbrMetallicRoughness` (its textures are in `other`). The factors are JSON, so
    /// that passed-through numbers keep their text.
    PbrMetallicRoughness {
        base_color_factor: Value,
        metallic_factor: Value,
        roughness_factor: Value,
    }
}

object! {
    /// An entry of `skins` (its joints are in `other`).
    Skin {
        inverse_bind_matrices: u64,
    }
}

object! {
    /// An entry of `animations` (its channels are in `other`).
    Animation {
        samplers: Vec<AnimationSampler>,
    }
}

object! {
    /// An entry of an animation's `samplers`: the accessors of its keyframe times and values.
    AnimationSampler {
        input: u64,
        output: u64,
    }
}

object! {
    /// The members of `EXT_mesh_primitive_edge_visibility` on a primitive that drafter reads and
    /// writes (accessor indices, the edges' material); `lineStrings` and the rest are in `other`.
    EdgeVisibility {
        material: u64,
        silhouette_normals: u64,
        visibility: u64,
    }
}

object! {
    /// `EXT_meshopt_compression` on a buffer view: where its encoded stream lies and how it
    /// decodes (`filter` absent: `NONE`).
    MeshoptBufferView {
        buffer: u64,
        byte_length: u64,
        byte_offset: u64,
        byte_stride: u64,
        count: u64,
        filter: String,
        mode: String,
    }
}

object! {
    /// `EXT_meshopt_compression` on a buffer: `fallback` marks the buffer without data that the
    /// decoded views point into.
    MeshoptBuffer {
        fallback: bool,
    }
}

object! {
    /// `KHR_draco_mesh_compression` on a primitive: the buffer view of its stream, and the stream's
    /// attribute id of each attribute it holds.
    DracoPrimitive {
        attributes: BTreeMap<String, u64>,
        buffer_view: u64,
    }
}

/// The slice in an optional array member (empty when the member is absent).
fn items<T>(list: &Option<Vec<T>>) -> &[T] {
    list.as_deref().unwrap_or_default()
}

/// The extension `name` of an object's `extensions`, decoded as `T`: `None` when absent.
fn extension<T: DeserializeOwned>(extensions: &Option<Members>, name: &str) -> Option<serde_json::Result<T>> {
    extensions.as_ref()?.get(name).map(T::deserialize)
}

impl Root {
    /// Reads a document from its JSON text.
    pub fn from_slice(json: &[u8]) -> serde_json::Result<Self> {
        let value: Value = serde_json::from_slice(json)?;
        Self::from_json(value).map_err(serde::de::Error::custom)
    }

    pub fn accessors(&self) -> &[Accessor] {
        items(&self.accessors)
    }

    pub fn buffer_views(&self) -> &[BufferView] {
        items(&self.buffer_views)
    }

    pub fn buffers(&self) -> &[Buffer] {
        items(&self.buffers)
    }

    pub fn images(&self) -> &[Image] {
        items(&self.images)
    }

    pub fn meshes(&self) -> &[Mesh] {
        items(&self.meshes)
    }

    pub fn nodes(&self) -> &[Node] {
        items(&self.nodes)
    }

    pub fn textures(&self) -> &[Texture] {
        items(&self.textures)
    }

    /// The root's extension `name` decoded as `T`; `None` when the root has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }

    /// The `count` of accessor `index`; `None` when there is no such accessor or it has no count.
    pub fn accessor_count(&self, index: u64) -> Option<u64> {
        self.accessors().get(usize::try_from(index).ok()?)?.count
    }

    /// Calls `f` on every accessor reference of the document: glTF 2.0's (primitives' attributes,
    /// indices and morph targets, skins, animation samplers), `EXT_mesh_gpu_instancing`'s, and
    /// those under the keys that `primitive_extensions` and `mesh_extensions` list for each named
    /// extension of a primitive or a mesh.
    pub fn visit_accessor_refs(
        &mut self,
        primitive_extensions: &[(&str, &[&str])],
        mesh_extensions: &[(&str, &[&str])],
        f: &mut dyn FnMut(&mut u64),
    ) {
        for mesh in self.meshes.iter_mut().flatten() {
            for primitive in mesh.primitives.iter_mut().flatten() {
                primitive.attributes.iter_mut().flat_map(BTreeMap::values_mut).for_each(&mut *f);
                primitive.indices.iter_mut().for_each(&mut *f);
                for target in primitive.targets.iter_mut().flatten() {
                    target.values_mut().for_each(|a| visit_index(a, f));
                }
                for (name, keys) in primitive_extensions {
                    primitive.visit_extension_indices(name, keys, f);
                }
            }
            for (name, keys) in mesh_extensions {
                mesh.visit_extension_indices(name, keys, f);
            }
        }
        for skin in self.skins.iter_mut().flatten() {
            skin.inverse_bind_matrices.iter_mut().for_each(&mut *f);
        }
        for animation in self.animations.iter_mut().flatten() {
            for sampler in animation.samplers.iter_mut().flatten() {
                sampler.input.iter_mut().chain(&mut sampler.output).for_each(&mut *f);
            }
        }
        for node in self.nodes.iter_mut().flatten() {
            let instancing = node.extensions.as_mut().and_then(|e| e.get_mut("EXT_mesh_gpu_instancing"));
            let attributes = instancing.and_then(|e| e.get_mut("attributes")).and_then(Value::as_object_mut);
            attributes.into_iter().flat_map(|a| a.values_mut()).for_each(|a| visit_index(a, f));
        }
    }

    /// Triangles the document's primitives list, every mesh once ([`Primitive::triangle_count`]).
    pub fn listed_triangles(&self) -> u64 {
        let primitives = self.meshes().iter().flat_map(Mesh::primitives);
        primitives.fold(0u64, |sum, p| sum.saturating_add(p.triangle_count(self)))
    }
}

impl BufferView {
    /// The view's extension `name` decoded as `T`; `None` when it has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }
}

impl Buffer {
    /// The buffer's extension `name` decoded as `T`; `None` when it has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }
}

impl Accessor {
    /// An accessor of `count` elements of `kind` (`"SCALAR"`, `"VEC3"`, …), each of `component`s,
    /// in buffer view `view`.
    pub fn new(view: usize, component: ComponentType, count: usize, kind: &str) -> Self {
        Accessor {
            buffer_view: Some(view as u64),
            component_type: Some(u64::from(component.code())),
            count: Some(count as u64),
            kind: Some(kind.to_owned()),
            ..Accessor::default()
        }
    }

    /// The component type; `None` when absent or not one of glTF's.
    pub fn component(&self) -> Option<ComponentType> {
        ComponentType::from_code(self.component_type?)
    }
}

impl Node {
    /// The node's extension `name` decoded as `T`; `None` when it has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }
}

/// The objects whose `extensions` the writer edits.
pub trait Extensible {
    /// The object's `extensions`.
    fn extensions_slot(&mut self) -> &mut Option<Members>;

    /// The object's `extensions`, to read.
    fn extensions_ref(&self) -> Option<&Members>;

    /// Calls `f` on every unsigned integer under one of `keys` anywhere inside extension `name`
    /// (read only; see [`Extensible::visit_extension_indices`]).
    fn extension_indices(&self, name: &str, keys: &[&str], f: &mut dyn FnMut(u64)) {
        if let Some(extension) = self.extensions_ref().and_then(|e| e.get(name)) {
            read_keys(extension, keys, f);
        }
    }

    /// Sets extension `name` to `value` (replacing one of that name), creating `extensions`.
    fn set_extension(&mut self, name: &str, value: Value) {
        self.extensions_slot().get_or_insert_default().insert(name.to_owned(), value);
    }

    /// Removes extension `name`, and `extensions` when none is left; the removed extension.
    fn remove_extension(&mut self, name: &str) -> Option<Value> {
        let slot = self.extensions_slot();
        let removed = slot.as_mut()?.remove(name);
        if slot.as_ref().is_some_and(Members::is_empty) {
            *slot = None;
        }
        removed
    }

    /// Calls `f` on every unsigned integer under one of `keys` anywhere inside extension `name`
    /// (an extension whose accessor references this layer does not type, as `DRAFTER_illustration`'s
    /// records or `EXT_mesh_primitive_edge_visibility`'s `lineStrings`).
    fn visit_extension_indices(&mut self, name: &str, keys: &[&str], f: &mut dyn FnMut(&mut u64)) {
        if let Some(extension) = self.extensions_slot().as_mut().and_then(|e| e.get_mut(name)) {
            visit_keys(extension, keys, f);
        }
    }
}

macro_rules! extensible {
    ($($name:ident),*) => {
        $(impl Extensible for $name {
            fn extensions_slot(&mut self) -> &mut Option<Members> {
                &mut self.extensions
            }

            fn extensions_ref(&self) -> Option<&Members> {
                self.extensions.as_ref()
            }
        })*
    };
}

extensible!(Root, Node, Mesh, Primitive, BufferView, Buffer);

/// Calls `f` on every unsigned integer under one of `keys` in the tree `value`.
fn visit_keys(value: &mut Value, keys: &[&str], f: &mut dyn FnMut(&mut u64)) {
    match value {
        Value::Object(map) => {
            for (k, v) in map.iter_mut() {
                if keys.contains(&k.as_str()) && v.is_u64() {
                    visit_index(v, f);
                } else {
                    visit_keys(v, keys, f);
                }
            }
        }
        Value::Array(items) => items.iter_mut().for_each(|v| visit_keys(v, keys, f)),
        _ => {}
    }
}

/// Calls `f` on every unsigned integer under one of `keys` in the tree `value`.
fn read_keys(value: &Value, keys: &[&str], f: &mut dyn FnMut(u64)) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                match v.as_u64() {
                    Some(index) if keys.contains(&k.as_str()) => f(index),
                    _ => read_keys(v, keys, f),
                }
            }
        }
        Value::Array(items) => items.iter().for_each(|v| read_keys(v, keys, f)),
        _ => {}
    }
}

/// Calls `f` on `value` if it is an unsigned integer, and stores what `f` leaves.
fn visit_index(value: &mut Value, f: &mut dyn FnMut(&mut u64)) {
    if let Some(mut index) = value.as_u64() {
        f(&mut index);
        *value = index.into();
    }
}

impl Mesh {
    pub fn primitives(&self) -> &[Primitive] {
        items(&self.primitives)
    }

    /// The mesh's extension `name` decoded as `T`; `None` when it has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }
}

impl Primitive {
    /// The accessor of attribute `name` (`"POSITION"`, `"NORMAL"`, `"_ENHANCED_NORMAL"`, …).
    pub fn attribute(&self, name: &str) -> Option<u64> {
        self.attributes.as_ref()?.get(name).copied()
    }

    /// The primitive's extension `name` decoded as `T`; `None` when it has none.
    pub fn extension<T: DeserializeOwned>(&self, name: &str) -> Option<serde_json::Result<T>> {
        extension(&self.extensions, name)
    }

    /// Triangles the primitive lists by [`triangle_count`], its accessors' counts looked up in
    /// `root` (an accessor that is missing or has no count counts 0).
    pub fn triangle_count(&self, root: &Root) -> u64 {
        let count = |accessor: u64| root.accessor_count(accessor).unwrap_or(0);
        triangle_count(self.mode, self.indices.map(count), self.attribute("POSITION").map(count))
    }
}

/// A primitive's `mode` (glTF 2.0, "meshes": the topology of its vertices).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Points,
    Lines,
    LineLoop,
    LineStrip,
    Triangles,
    TriangleStrip,
    TriangleFan,
}

impl Mode {
    /// The mode of a `mode` code (0 POINTS … 6 TRIANGLE_FAN); `None` for any other number.
    pub fn from_code(code: u64) -> Option<Self> {
        Some(match code {
            0 => Self::Points,
            1 => Self::Lines,
            2 => Self::LineLoop,
            3 => Self::LineStrip,
            4 => Self::Triangles,
            5 => Self::TriangleStrip,
            6 => Self::TriangleFan,
            _ => return None,
        })
    }

    /// Triangles that `vertices` listed vertices make in this mode: `n / 3` for a list, `n − 2` for
    /// a strip or a fan (none below three vertices), none for points and lines.
    pub fn triangles(self, vertices: u64) -> u64 {
        match self {
            Self::Triangles => vertices / 3,
            Self::TriangleStrip | Self::TriangleFan => vertices.saturating_sub(2),
            Self::Points | Self::Lines | Self::LineLoop | Self::LineStrip => 0,
        }
    }
}

/// Triangles a primitive lists, from its `mode` code (absent: triangles, as the spec defaults it;
/// a code outside the spec: none), the count of its `indices` accessor where it has one (`Some`
/// even when that accessor cannot be found: then `Some(0)`, its count unknown) and otherwise the
/// count of its `POSITION` accessor.
pub fn triangle_count(mode: Option<u64>, indices: Option<u64>, positions: Option<u64>) -> u64 {
    let vertices = indices.or(positions).unwrap_or(0);
    match mode {
        None => Mode::Triangles.triangles(vertices),
        Some(code) => Mode::from_code(code).map_or(0, |mode| mode.triangles(vertices)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A document with members of every kind: typed ones, unknown ones at every level, integers
    /// written as floats where the spec has numbers, extensions and extras.
    const DOCUMENT: &str = r#"{
        "asset": {"version": "2.0", "generator": "g", "copyright": "c"},
        "scene": 0, "scenes": [{"nodes": [0], "extras": {"a": 1}}],
        "nodes": [{"mesh": 0, "translation": [1, 2.0, -0.0], "children": [1],
                   "extensions": {"DRAFTER_illustration": {"parts": []}, "X_other": {"k": [1, 2]}}},
                  {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1], "futureMember": true}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "_ENHANCED_NORMAL": 1}, "indices": 2,
                    "mode": 4, "targets": [{"POSITION": 3}],
                    "extensions": {"EXT_mesh_primitive_edge_visibility": {"visibility": 4, "lineStrings": []}}},
                   {"attributes": {"POSITION": 0}, "mode": 5}, {"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 9, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1.5, 1e300, 1]},
                      {"componentType": 5126, "count": 9, "type": "VEC3", "sparse": {"count": 1}},
                      {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR", "normalized": false}],
        "bufferViews": [{"buffer": 0, "byteLength": 108, "byteStride": 12, "target": 34962},
                        {"buffer": 0, "byteOffset": 108, "byteLength": 24}],
        "buffers": [{"byteLength": 132, "uri": "a.bin"}],
        "images": [{"bufferView": 1, "mimeType": "image/png", "name": "i"}],
        "textures": [{"source": 0, "sampler": 0}], "samplers": [{"magFilter": 9729}],
        "materials": [{"name": "m", "pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0, 1]}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1, "znear": 0.1}}],
        "extensionsUsed": ["X_other"], "extras": {"top": null}, "unknownTopLevel": [1, "two"]
    }"#;

    #[test]
    fn a_document_reads_typed_and_writes_back_whole() {
        let root = Root::from_slice(DOCUMENT.as_bytes()).expect("read");
        let original: Value = serde_json::from_str(DOCUMENT).expect("JSON");
        assert_eq!(serde_json::to_value(&root).expect("write"), original, "nothing lost or changed");
        // Written through a Value, the text has the writer's sorted member order.
        let text = serde_json::to_value(&root).expect("write").to_string();
        assert_eq!(text, original.to_string());
        assert!(text.contains(r#""translation":[1,2.0,-0.0]"#), "numbers as written: {text}");
        let primitive = &root.meshes()[0].primitives()[0];
        assert_eq!((primitive.attribute("_ENHANCED_NORMAL"), primitive.indices), (Some(1), Some(2)));
        let edges: EdgeVisibility =
            primitive.extension("EXT_mesh_primitive_edge_visibility").expect("some").expect("ok");
        assert_eq!((edges.visibility, edges.silhouette_normals), (Some(4), None));
        assert!(root.nodes()[0].extension::<Value>("DRAFTER_illustration").is_some());
        assert!(root.nodes()[1].extension::<Value>("DRAFTER_illustration").is_none());
        assert_eq!(root.accessors()[2].kind.as_deref(), Some("SCALAR"));
        assert_eq!(root.buffers()[0].uri.as_deref(), Some("a.bin"));
        assert_eq!(root.images()[0].mime_type.as_deref(), Some("image/png"));
        // 12 indices: 4 triangles; a strip and a list of 9 positions: 7 and 3.
        assert_eq!(root.listed_triangles(), 4 + 7 + 3);
    }

    #[test]
    fn a_member_of_the_wrong_type_is_refused_and_a_missing_one_left_to_the_reader() {
        assert!(Root::from_slice(br#"{"accessors": [{"count": "nine"}]}"#).is_err());
        assert!(Root::from_slice(br#"{"meshes": [{"primitives": [{"mode": 4.5}]}]}"#).is_err());
        let root = Root::from_slice(br#"{"accessors": [{"type": "SCALAR"}], "meshes": [{}]}"#).expect("read");
        assert_eq!((root.accessor_count(0), root.accessor_count(1)), (None, None));
        assert_eq!((root.asset.as_ref(), root.meshes()[0].primitives().len()), (None, 0));
        assert_eq!(Root::from_slice(b"{}").expect("empty").listed_triangles(), 0);
        // An index past 32 bits (the importer takes it; the writer passes it through) reads, and
        // counts as a missing accessor.
        let root = Root::from_slice(
            br#"{"accessors": [{"bufferView": 4294967296, "count": 3}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 4294967296}}]}]}"#,
        )
        .expect("read");
        assert_eq!((root.accessors()[0].buffer_view, root.listed_triangles()), (Some(1 << 32), 0));
    }

    #[test]
    fn every_mode_counts_its_triangles() {
        // Points, lines, line loop and line strip list no triangles, whatever their counts.
        for code in 0..=3 {
            assert_eq!(triangle_count(Some(code), Some(12), Some(99)), 0, "mode {code}");
        }
        assert_eq!(triangle_count(Some(4), Some(12), Some(99)), 4, "triangles: indices first");
        assert_eq!(triangle_count(Some(4), Some(13), None), 4, "a partial triangle is not one");
        assert_eq!(triangle_count(Some(5), Some(12), None), 10, "strip");
        assert_eq!(triangle_count(Some(6), None, Some(12)), 10, "fan of positions");
        assert_eq!(triangle_count(None, None, Some(9)), 3, "no mode: triangles");
        assert_eq!(triangle_count(None, Some(0), Some(9)), 0, "indices of unknown count: not the positions");
        assert_eq!(triangle_count(Some(7), Some(12), None), 0, "a mode outside the spec");
        assert_eq!(triangle_count(Some(u64::MAX), Some(12), None), 0);
        // Counts too small for one triangle.
        for code in [4, 5, 6] {
            for n in 0..3 {
                assert_eq!(triangle_count(Some(code), Some(n), None), 0, "mode {code}, {n} vertices");
            }
        }
        assert_eq!(triangle_count(Some(4), None, None), 0, "no indices, no positions");
        assert_eq!(triangle_count(Some(5), Some(u64::MAX), None), u64::MAX - 2);
        assert_eq!(Mode::from_code(6), Some(Mode::TriangleFan));
    }
}
