//! Writes a baked scene as glTF 2.0 plus the `DRAFTER_illustration` extension.
//!
//! glTF input is passed through: the source JSON is kept whole (nodes, names, transforms,
//! materials, textures, cameras, extras, unknown extensions, `_` attributes), its buffers are merged
//! into one, and our data is added next to it. Other input (OBJ, STL, OFF, PLY) gets a fresh
//! document with one node per part instance. Either way the extension is listed in
//! `extensionsUsed` only, so every viewer still opens the file as a plain model.

use drafter_core::{Mesh, Scene, TriangleGroup};
use serde_json::{Map, Value, json};

use crate::FormatError;
use crate::doc::{Doc, ELEMENT_ARRAY_BUFFER};
use crate::ext::{EXTENSION, NodeExtension, PartRecord, PrimitiveExtension, RootExtension};

/// Everything a bake produced, ready to write.
#[derive(Clone, Debug)]
pub struct BakeOutput<'a> {
    pub scene: &'a Scene,
    pub root: RootExtension,
    /// For each scene instance, its parts, indexed by the mesh's triangle labels.
    pub instance_parts: Vec<Vec<PartRecord>>,
    /// For each scene mesh, the part label of each triangle (`None`: the whole mesh is label 0).
    pub mesh_labels: Vec<Option<Vec<u32>>>,
}

/// The file layout to write.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Container {
    /// One self-contained .glb.
    Glb,
    /// A .gltf whose buffer is the file `bin_uri` beside it.
    Gltf { bin_uri: String },
}

/// The bytes of the written file(s).
#[derive(Clone, Debug)]
pub struct Written {
    /// The .glb or .gltf.
    pub main: Vec<u8>,
    /// The .bin of a .gltf container.
    pub bin: Option<Vec<u8>>,
}

/// Serialises `out`. Deterministic: the same input gives the same bytes.
pub fn write(out: &BakeOutput, container: &Container) -> Result<Written, FormatError> {
    let scene = out.scene;
    if out.instance_parts.len() != scene.instances.len() || out.mesh_labels.len() != scene.meshes.len() {
        return Err(FormatError::Inconsistent("instance_parts / mesh_labels do not match the scene".into()));
    }
    let mut doc = match &scene.source {
        Some(source) => Doc::from_source(&source.json, &source.buffers)?,
        None => synthesize(scene),
    };
    // Node index of each instance: the source node, or the synthesized node i.
    let node_of = |i: usize| scene.instances[i].node.map_or(i, |n| n.index());
    for (i, parts) in out.instance_parts.iter().enumerate() {
        let ext = serde_json::to_value(NodeExtension { parts: parts.clone() })?;
        let node = doc
            .array_mut("nodes")
            .get_mut(node_of(i))
            .ok_or_else(|| FormatError::Inconsistent(format!("instance {i} has no node")))?;
        extension_slot(node).insert(EXTENSION.into(), ext);
    }
    for (m, mesh) in scene.meshes.iter().enumerate() {
        let used = scene.source.is_some();
        for (g, group) in mesh.groups.iter().enumerate() {
            let primitive = if used { group.primitive.map_or(g, |p| p as usize) } else { g };
            if used {
                rewrite_if_faces_dropped(&mut doc, mesh, m, primitive, group)?;
            }
            let Some(labels) = &out.mesh_labels[m] else { continue };
            let range = group.start as usize..(group.start + group.count) as usize;
            let slice =
                labels.get(range).ok_or_else(|| FormatError::Inconsistent(format!("mesh {m}: too few labels")))?;
            let accessor = doc.push_scalars(slice, None) as u32;
            let ext = serde_json::to_value(PrimitiveExtension { part_labels: Some(accessor) })?;
            let prim = primitive_mut(&mut doc, m, primitive)?;
            extension_slot(prim).insert(EXTENSION.into(), ext);
        }
    }
    let root_ext = serde_json::to_value(&out.root)?;
    let root = doc.json.entry("extensions").or_insert_with(|| json!({}));
    if let Value::Object(map) = root {
        map.insert(EXTENSION.into(), root_ext);
    }
    doc.use_extension(EXTENSION);
    match container {
        Container::Glb => Ok(Written { main: doc.into_glb()?, bin: None }),
        Container::Gltf { bin_uri } => {
            let (main, bin) = doc.into_gltf(bin_uri)?;
            Ok(Written { main, bin: Some(bin) })
        }
    }
}

fn extension_slot(object: &mut Value) -> &mut Map<String, Value> {
    let extensions = &mut object["extensions"];
    if !extensions.is_object() {
        *extensions = json!({});
    }
    match extensions {
        Value::Object(map) => map,
        _ => unreachable!("made an object above"),
    }
}

fn primitive_mut(doc: &mut Doc, mesh: usize, primitive: usize) -> Result<&mut Value, FormatError> {
    doc.array_mut("meshes")
        .get_mut(mesh)
        .and_then(|m| m.get_mut("primitives"))
        .and_then(|p| p.get_mut(primitive))
        .ok_or_else(|| FormatError::Inconsistent(format!("mesh {mesh} has no primitive {primitive}")))
}

/// The importer drops faces that use NaN positions; when it did, the source primitive's indices no
/// longer match our triangles (and the labels written per triangle), so the primitive gets a new
/// triangle-list index accessor with the surviving triangles.
fn rewrite_if_faces_dropped(
    doc: &mut Doc,
    mesh: &Mesh,
    m: usize,
    primitive: usize,
    group: &TriangleGroup,
) -> Result<(), FormatError> {
    let prim = primitive_mut(doc, m, primitive)?.clone();
    let accessors = doc.array("accessors");
    let count_of = |key: Option<&Value>| {
        key.and_then(Value::as_u64)
            .and_then(|a| accessors.get(a as usize))
            .and_then(|a| a["count"].as_u64())
            .unwrap_or(0)
    };
    let elements = match prim.get("indices") {
        Some(i) => count_of(Some(i)),
        None => count_of(prim.get("attributes").and_then(|a| a.get("POSITION"))),
    };
    let mode = prim.get("mode").and_then(Value::as_u64).unwrap_or(4);
    let source_triangles = if mode == 4 { elements / 3 } else { elements.saturating_sub(2) };
    if source_triangles == u64::from(group.count) {
        return Ok(());
    }
    let range = group.start as usize..(group.start + group.count) as usize;
    let local: Vec<u32> = mesh.triangles[range].iter().flatten().map(|&v| v - group.first_vertex).collect();
    let accessor = doc.push_scalars(&local, Some(ELEMENT_ARRAY_BUFFER));
    let prim = primitive_mut(doc, m, primitive)?;
    prim["indices"] = accessor.into();
    if let Value::Object(map) = prim {
        map.remove("mode");
    }
    Ok(())
}

/// A fresh document for input without one: materials, one mesh per scene mesh (one primitive per
/// triangle group), one node per instance, one scene.
fn synthesize(scene: &Scene) -> Doc {
    let mut doc = Doc::new(Map::new());
    doc.json.insert("asset".into(), json!({"version": "2.0", "generator": crate::GENERATOR}));
    let materials: Vec<Value> = scene
        .materials
        .iter()
        .map(|m| {
            json!({
                "name": m.name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": m.base_color,
                    "metallicFactor": m.metallic,
                    "roughnessFactor": m.roughness
                }
            })
        })
        .collect();
    if !materials.is_empty() {
        doc.json.insert("materials".into(), Value::Array(materials));
    }
    let mut meshes = Vec::with_capacity(scene.meshes.len());
    for mesh in &scene.meshes {
        let mut primitives = Vec::new();
        for group in &mesh.groups {
            let vertices = group.first_vertex as usize..(group.first_vertex + group.vertex_count) as usize;
            let positions: Vec<[f32; 3]> = mesh.positions[vertices.clone()].iter().map(|p| p.to_array()).collect();
            let mut attributes = json!({"POSITION": doc.push_vec3(&positions, true)});
            if let Some(normals) = &mesh.normals {
                // The spec requires unit normals; skip the attribute if any cannot be normalised.
                let unit: Option<Vec<[f32; 3]>> =
                    normals[vertices.clone()].iter().map(|n| n.try_normalize().map(|n| n.to_array())).collect();
                if let Some(unit) = unit {
                    attributes["NORMAL"] = doc.push_vec3(&unit, false).into();
                }
            }
            if let Some(uvs) = &mesh.uvs {
                let uv: Vec<[f32; 2]> = uvs[vertices].iter().map(|t| t.to_array()).collect();
                attributes["TEXCOORD_0"] = doc.push_vec2(&uv).into();
            }
            let range = group.start as usize..(group.start + group.count) as usize;
            let local: Vec<u32> = mesh.triangles[range].iter().flatten().map(|&v| v - group.first_vertex).collect();
            let mut primitive =
                json!({"attributes": attributes, "indices": doc.push_scalars(&local, Some(ELEMENT_ARRAY_BUFFER))});
            if let Some(material) = group.material {
                primitive["material"] = material.0.into();
            }
            primitives.push(primitive);
        }
        let mut m = json!({"primitives": primitives});
        if !mesh.name.is_empty() {
            m["name"] = mesh.name.clone().into();
        }
        meshes.push(m);
    }
    doc.json.insert("meshes".into(), Value::Array(meshes));
    let nodes: Vec<Value> = scene
        .instances
        .iter()
        .map(|inst| {
            let mut node = json!({"name": inst.name, "mesh": inst.mesh.0});
            if inst.world_from_object != glam::DMat4::IDENTITY {
                node["matrix"] = json!(inst.world_from_object.to_cols_array());
            }
            node
        })
        .collect();
    let roots: Vec<usize> = (0..nodes.len()).collect();
    doc.json.insert("nodes".into(), Value::Array(nodes));
    doc.json.insert("scenes".into(), json!([{"nodes": roots}]));
    doc.json.insert("scene".into(), 0.into());
    doc
}
