//! A minimal glTF 2.0 document model and its binary (.glb) writer: exactly what the samples need (nodes with
//! TRS or matrix transforms, one triangle primitive per mesh with POSITION, NORMAL and indices, metallic-roughness
//! materials), written so the Khronos validator reports no error, warning, info or hint.
//!
//! Layout of the BIN chunk: per mesh, positions, normals, then indices, each in its own buffer view (targets
//! ARRAY_BUFFER / ELEMENT_ARRAY_BUFFER) starting on a 4-byte boundary; accessors start at offset 0 of their view.
//! Indices are u16 when every index fits below 65535 (the restart value a primitive must not use), else u32.
//! The container is framed by `drafter_format::glb::write` (the workspace's one GLB writer): the JSON chunk padded
//! with spaces, the BIN chunk with zeros, both to 4 bytes. The GL enums (component types, buffer view targets) are
//! `drafter_format::accessor`'s.
//!
//! The document is drafter-format's typed glTF ([`gltf::Root`]), written as the format's writer writes its own:
//! members sorted, floats in serde_json's shortest round-trip formatting; nothing depends on time or hashing.
//!
//! Each primitive's `extras.brepFaces` lists its B-rep faces as `[surface, firstTriangle, triangleCount]` (the
//! triangles of a face are contiguous), for tests that want the CAD face of a triangle as ground truth.

use drafter_format::accessor::{ARRAY_BUFFER, ComponentType, ELEMENT_ARRAY_BUFFER};
use drafter_format::gltf::{self, Members};
use serde_json::Value;

use crate::solid::{Surface, TriMesh};

/// Written to `asset.generator`.
pub const GENERATOR: &str = "drafter-samples";

/// Index of a material in its [`Document`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct MaterialId(pub usize);
/// Index of a mesh in its [`Document`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct MeshId(pub usize);
/// Index of a node in its [`Document`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct NodeId(pub usize);

/// A metallic-roughness material.
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    /// Name, e.g. "steel".
    pub name: String,
    /// Linear RGBA base colour factor.
    pub base_color: [f64; 4],
    /// Metallic factor in [0, 1].
    pub metallic: f64,
    /// Roughness factor in [0, 1].
    pub roughness: f64,
}

/// A mesh of one triangle primitive.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Name, e.g. "spur_gear".
    pub name: String,
    /// The triangles, in the mesh's object space.
    pub geometry: TriMesh,
    /// Material of the primitive.
    pub material: MaterialId,
}

/// A node's local transform (parent_from_node).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transform {
    /// No transform written.
    Identity,
    /// Translation, rotation (unit quaternion x, y, z, w) and scale; components at their default are not written.
    Trs {
        /// Translation.
        translation: [f64; 3],
        /// Unit quaternion (x, y, z, w).
        rotation: [f64; 4],
        /// Scale; a negative determinant mirrors the subtree.
        scale: [f64; 3],
    },
    /// Column-major 4×4 matrix; it must decompose into TRS.
    Matrix([f64; 16]),
}

impl Transform {
    /// A pure translation.
    pub fn translation(translation: [f64; 3]) -> Self {
        Self::Trs { translation, rotation: [0.0, 0.0, 0.0, 1.0], scale: [1.0; 3] }
    }
}

/// A scene-graph node.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Name, e.g. "gear_input".
    pub name: String,
    /// Local transform.
    pub transform: Transform,
    /// Mesh drawn at this node, if any.
    pub mesh: Option<MeshId>,
    /// Child nodes.
    pub children: Vec<NodeId>,
}

/// A glTF document with a single scene.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Document {
    /// Name of the scene.
    pub scene_name: String,
    /// Root nodes of the scene.
    pub roots: Vec<NodeId>,
    /// All nodes.
    pub nodes: Vec<Node>,
    /// All meshes.
    pub meshes: Vec<Mesh>,
    /// All materials.
    pub materials: Vec<Material>,
}

impl Document {
    /// An empty document whose scene is called `scene_name`.
    pub fn new(scene_name: &str) -> Self {
        Self { scene_name: scene_name.to_owned(), ..Self::default() }
    }

    /// Adds a material.
    pub fn add_material(&mut self, material: Material) -> MaterialId {
        self.materials.push(material);
        MaterialId(self.materials.len() - 1)
    }

    /// Adds a mesh.
    pub fn add_mesh(&mut self, name: &str, geometry: TriMesh, material: MaterialId) -> MeshId {
        self.meshes.push(Mesh { name: name.to_owned(), geometry, material });
        MeshId(self.meshes.len() - 1)
    }

    /// Adds a node under `parent` (or as a scene root when `None`).
    pub fn add_node(
        &mut self,
        parent: Option<NodeId>,
        name: &str,
        transform: Transform,
        mesh: Option<MeshId>,
    ) -> NodeId {
        let id = NodeId(self.nodes.len());
        self.nodes.push(Node { name: name.to_owned(), transform, mesh, children: Vec::new() });
        match parent {
            Some(parent) => self.nodes[parent.0].children.push(id),
            None => self.roots.push(id),
        }
        id
    }

    /// The document as GLB bytes.
    pub fn to_glb(&self) -> Vec<u8> {
        let mut bin = BinBuilder::default();
        let meshes: Vec<gltf::Mesh> = self.meshes.iter().map(|mesh| mesh_json(mesh, &mut bin)).collect();
        let root = gltf::Root {
            asset: Some(gltf::Asset {
                generator: Some(GENERATOR.to_owned()),
                version: Some("2.0".to_owned()),
                ..Default::default()
            }),
            scene: Some(0),
            scenes: Some(vec![gltf::Scene {
                name: Some(self.scene_name.clone()),
                nodes: Some(self.roots.iter().map(|n| n.0 as u64).collect()),
                ..Default::default()
            }]),
            // glTF arrays must not be empty: leave out what the document does not have.
            nodes: non_empty(self.nodes.iter().map(node_json).collect()),
            meshes: non_empty(meshes),
            materials: non_empty(self.materials.iter().map(material_json).collect()),
            accessors: non_empty(std::mem::take(&mut bin.accessors)),
            buffer_views: non_empty(std::mem::take(&mut bin.views)),
            buffers: (!bin.data.is_empty())
                .then(|| vec![gltf::Buffer { byte_length: Some(bin.data.len() as u64), ..Default::default() }]),
            ..Default::default()
        };
        let json = Value::from(root).to_string().into_bytes();
        // The samples are a few kilobytes, far below the container's 4 GiB limit.
        drafter_format::glb::write(&json, &bin.data).expect("a sample fits in a GLB")
    }
}

fn non_empty<T>(items: Vec<T>) -> Option<Vec<T>> {
    (!items.is_empty()).then_some(items)
}

fn pad(bytes: &mut Vec<u8>, with: u8) {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(with);
    }
}

/// The BIN chunk being assembled, with its buffer views and accessors.
#[derive(Debug, Default)]
struct BinBuilder {
    data: Vec<u8>,
    views: Vec<gltf::BufferView>,
    accessors: Vec<gltf::Accessor>,
}

impl BinBuilder {
    /// Appends a 4-byte-aligned buffer view and `accessor` over all of it; returns the accessor index.
    fn push(&mut self, bytes: &[u8], target: u32, accessor: gltf::Accessor) -> u64 {
        pad(&mut self.data, 0);
        self.views.push(gltf::BufferView {
            buffer: Some(0),
            byte_offset: Some(self.data.len() as u64),
            byte_length: Some(bytes.len() as u64),
            target: Some(u64::from(target)),
            ..Default::default()
        });
        self.data.extend_from_slice(bytes);
        self.accessors.push(gltf::Accessor { buffer_view: Some(self.views.len() as u64 - 1), ..accessor });
        self.accessors.len() as u64 - 1
    }
}

fn floats(values: &[[f32; 3]]) -> Vec<u8> {
    values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect()
}

/// f32 written as the f64 of the same value, so readers comparing in either precision see equality.
fn float_array(values: [f32; 3]) -> Value {
    values.iter().map(|&v| Value::from(f64::from(v))).collect()
}

fn mesh_json(mesh: &Mesh, bin: &mut BinBuilder) -> gltf::Mesh {
    let geometry = &mesh.geometry;
    let count = geometry.positions.len();
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &geometry.positions {
        for axis in 0..3 {
            min[axis] = min[axis].min(p[axis]);
            max[axis] = max[axis].max(p[axis]);
        }
    }
    let vec3 = gltf::Accessor {
        component_type: Some(u64::from(ComponentType::F32.code())),
        count: Some(count as u64),
        kind: Some("VEC3".to_owned()),
        ..Default::default()
    };
    let position = bin.push(
        &floats(&geometry.positions),
        ARRAY_BUFFER,
        gltf::Accessor { min: Some(float_array(min)), max: Some(float_array(max)), ..vec3.clone() },
    );
    let normal = bin.push(&floats(&geometry.normals), ARRAY_BUFFER, vec3);
    let flat = geometry.triangles.iter().flatten();
    let (index_bytes, component): (Vec<u8>, ComponentType) = if count <= usize::from(u16::MAX) {
        (flat.flat_map(|&i| (i as u16).to_le_bytes()).collect(), ComponentType::U16)
    } else {
        (flat.flat_map(|&i| i.to_le_bytes()).collect(), ComponentType::U32)
    };
    let indices = bin.push(
        &index_bytes,
        ELEMENT_ARRAY_BUFFER,
        gltf::Accessor {
            component_type: Some(u64::from(component.code())),
            count: Some(3 * geometry.triangles.len() as u64),
            kind: Some("SCALAR".to_owned()),
            ..Default::default()
        },
    );
    let faces: Value = geometry
        .faces
        .iter()
        .map(|f| {
            Value::from(vec![Value::from(surface_name(f.surface)), f.first_triangle.into(), f.triangle_count.into()])
        })
        .collect();
    let primitive = gltf::Primitive {
        attributes: Some([("NORMAL".to_owned(), normal), ("POSITION".to_owned(), position)].into()),
        extras: Some(serde_json::json!({ "brepFaces": faces })),
        indices: Some(indices),
        material: Some(mesh.material.0 as u64),
        ..Default::default()
    };
    gltf::Mesh { name: Some(mesh.name.clone()), primitives: Some(vec![primitive]), ..Default::default() }
}

/// Name of a surface kind in `extras.brepFaces`.
pub fn surface_name(surface: Surface) -> &'static str {
    match surface {
        Surface::Plane => "plane",
        Surface::Cylinder => "cylinder",
        Surface::Cone => "cone",
        Surface::Extrusion => "extrusion",
    }
}

fn numbers(values: &[f64]) -> Value {
    values.iter().map(|&v| Value::from(v)).collect()
}

fn node_json(node: &Node) -> gltf::Node {
    // Translation, rotation and scale are members the typed node keeps among its others.
    let mut other = Members::new();
    let mut matrix = None;
    match node.transform {
        Transform::Identity => {}
        Transform::Trs { translation, rotation, scale } => {
            if translation != [0.0; 3] {
                other.insert("translation".to_owned(), numbers(&translation));
            }
            if rotation != [0.0, 0.0, 0.0, 1.0] {
                other.insert("rotation".to_owned(), numbers(&rotation));
            }
            if scale != [1.0; 3] {
                other.insert("scale".to_owned(), numbers(&scale));
            }
        }
        Transform::Matrix(m) => matrix = Some(numbers(&m)),
    }
    gltf::Node {
        name: Some(node.name.clone()),
        mesh: node.mesh.map(|m| m.0 as u64),
        children: (!node.children.is_empty()).then(|| node.children.iter().map(|c| c.0 as u64).collect()),
        matrix,
        other,
        ..Default::default()
    }
}

fn material_json(material: &Material) -> gltf::Material {
    gltf::Material {
        name: Some(material.name.clone()),
        pbr_metallic_roughness: Some(gltf::PbrMetallicRoughness {
            base_color_factor: Some(numbers(&material.base_color)),
            metallic_factor: Some(material.metallic.into()),
            roughness_factor: Some(material.roughness.into()),
            ..Default::default()
        }),
        ..Default::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_document_is_a_valid_glb_header_and_padded_json() {
        let glb = Document::new("empty").to_glb();
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(u32::from_le_bytes([glb[8], glb[9], glb[10], glb[11]]) as usize, glb.len());
        assert_eq!(glb.len() % 4, 0);
        let json_len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
        assert_eq!(20 + json_len, glb.len(), "no BIN chunk without meshes");
    }
}
