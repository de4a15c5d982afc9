//! The scene: meshes stored once, instanced by nodes with world transforms.

use glam::{DMat4, DVec3, Vec2, Vec3};
use serde::Serialize;

use crate::{MaterialId, MeshId, NodeId};

/// The file format a scene was read from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SourceFormat {
    Gltf,
    Glb,
    Obj,
    Stl,
    Off,
    Ply,
}

impl SourceFormat {
    pub fn name(self) -> &'static str {
        match self {
            Self::Gltf => "glTF",
            Self::Glb => "glTF binary",
            Self::Obj => "OBJ",
            Self::Stl => "STL",
            Self::Off => "OFF",
            Self::Ply => "PLY",
        }
    }
}

/// A PBR metallic-roughness material, reduced to what shading styles need.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Material {
    pub name: String,
    /// Linear RGBA base colour factor, default opaque white.
    pub base_color: [f32; 4],
    /// Metallic factor in [0, 1], default 1 as in glTF (0 for formats without materials).
    pub metallic: f32,
    /// Roughness factor in [0, 1], default 1.
    pub roughness: f32,
}

impl Default for Material {
    fn default() -> Self {
        Self { name: String::new(), base_color: [1.0; 4], metallic: 0.0, roughness: 1.0 }
    }
}

/// A contiguous range of a mesh's triangles that share a material (one glTF primitive, one OBJ
/// material run).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TriangleGroup {
    /// First triangle of the group.
    pub start: u32,
    /// Number of triangles.
    pub count: u32,
    pub material: Option<MaterialId>,
    /// The glTF primitive (index within its mesh) the group was read from, if any.
    pub primitive: Option<u32>,
    /// First vertex of the group's own vertex range (glTF primitives do not share vertices).
    pub first_vertex: u32,
    /// Number of vertices in the group's range.
    pub vertex_count: u32,
}

/// Geometry stored once and drawn by any number of instances.
///
/// Invariant: every index in `triangles` is `< positions.len()`, every position is finite, and
/// `normals`/`uvs`, when present, have one entry per position. Importers enforce this.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    /// Material runs covering `triangles` in order (may be empty: one default-material group).
    pub groups: Vec<TriangleGroup>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Bounding box of the positions in object space (empty for a mesh with no vertices).
    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in &self.positions {
            b.extend(p.as_dvec3());
        }
        b
    }
}

/// A node of the source hierarchy. Nodes keep the input's structure so a writer can reproduce it.
#[derive(Clone, Debug, PartialEq)]
pub struct Node {
    pub name: String,
    pub parent: Option<NodeId>,
    pub children: Vec<NodeId>,
    /// Transform from this node's space to its parent's (f64 so that CAD coordinates far from the
    /// origin keep their precision).
    pub parent_from_local: DMat4,
    pub mesh: Option<MeshId>,
}

/// One placement of a mesh in the world.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    pub name: String,
    pub mesh: MeshId,
    /// The node this instance came from, if the format has nodes.
    pub node: Option<NodeId>,
    pub world_from_object: DMat4,
}

impl Instance {
    /// True when the transform mirrors (negative determinant): the triangle winding must be flipped
    /// in the world for faces to keep facing outwards (glTF 2.0 spec, 3.7.4 "Transformations").
    pub fn flips_winding(&self) -> bool {
        self.world_from_object.determinant() < 0.0
    }
}

/// An axis-aligned box in f64. The empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: DVec3::splat(f64::INFINITY), max: DVec3::splat(f64::NEG_INFINITY) };

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn extend(&mut self, p: DVec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.min(other.min), max: self.max.max(other.max) }
    }

    /// Length of the diagonal (0 for an empty box).
    pub fn diagonal(&self) -> f64 {
        if self.is_empty() { 0.0 } else { (self.max - self.min).length() }
    }

    /// The eight corners, x varying fastest, then y, then z.
    pub fn corners(&self) -> impl Iterator<Item = DVec3> + use<> {
        let (min, max) = (self.min, self.max);
        (0..8).map(move |i| {
            DVec3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        })
    }

    /// The box around the eight corners of `self` under `m`.
    pub fn transformed(&self, m: &DMat4) -> Aabb {
        let mut out = Aabb::EMPTY;
        if self.is_empty() {
            return out;
        }
        for c in self.corners() {
            out.extend(m.transform_point3(c));
        }
        out
    }
}

/// The glTF document a scene was read from, kept whole so that a writer can pass through what the
/// scene model does not represent (extras, unknown extensions, textures, cameras, `_` attributes).
#[derive(Clone, Debug, PartialEq)]
pub struct SourceDocument {
    /// The JSON text (the JSON chunk of a .glb).
    pub json: String,
    /// Every buffer's bytes, in buffer order, already loaded and length-checked.
    pub buffers: Vec<Vec<u8>>,
}

/// A whole imported file.
#[derive(Clone, Debug)]
pub struct Scene {
    pub format: SourceFormat,
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    /// The node hierarchy (empty for formats without one).
    pub nodes: Vec<Node>,
    /// Root nodes of the scene that was imported.
    pub roots: Vec<NodeId>,
    /// Every placement of a mesh, in hierarchy order (depth-first, children in file order).
    pub instances: Vec<Instance>,
    /// The source glTF document, for glTF input.
    pub source: Option<std::sync::Arc<SourceDocument>>,
}

impl Scene {
    pub fn new(format: SourceFormat) -> Self {
        Self {
            format,
            meshes: Vec::new(),
            materials: Vec::new(),
            nodes: Vec::new(),
            roots: Vec::new(),
            instances: Vec::new(),
            source: None,
        }
    }

    /// A scene of one mesh placed once, at the identity, in an instance named `name` (what STL,
    /// OFF and PLY import to, and what the merged and generated test scenes are).
    pub fn single_mesh(format: SourceFormat, mesh: Mesh, name: &str) -> Self {
        let mut scene = Self::new(format);
        scene.meshes.push(mesh);
        scene.instances.push(Instance {
            name: name.to_owned(),
            mesh: MeshId(0),
            node: None,
            world_from_object: DMat4::IDENTITY,
        });
        scene
    }

    pub fn mesh(&self, id: MeshId) -> &Mesh {
        &self.meshes[id.index()]
    }

    /// Triangles drawn in the world: every instance counts its mesh once more.
    pub fn instanced_triangle_count(&self) -> usize {
        self.instances.iter().map(|i| self.mesh(i.mesh).triangle_count()).sum()
    }

    pub fn instanced_vertex_count(&self) -> usize {
        self.instances.iter().map(|i| self.mesh(i.mesh).vertex_count()).sum()
    }

    /// The world bounding box: exact (every vertex transformed), in f64.
    pub fn world_bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for inst in &self.instances {
            let m = &inst.world_from_object;
            for p in &self.mesh(inst.mesh).positions {
                b.extend(m.transform_point3(p.as_dvec3()));
            }
        }
        b
    }
}
