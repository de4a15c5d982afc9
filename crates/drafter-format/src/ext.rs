//! The `DRAFTER_illustration` extension's objects as serde types. The spec is `spec/README.md`
//! beside this crate, the schema `spec/schema/`; keep the three in sync.

use serde::{Deserialize, Serialize};

/// The extension's name, as listed in `extensionsUsed` (never in `extensionsRequired`).
pub const EXTENSION: &str = "DRAFTER_illustration";

/// Version of the extension's layout written by this crate.
pub const FORMAT_VERSION: &str = "0.1";

/// Root-level object: scene-wide data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct RootExtension {
    pub version: String,
    /// Tool name and version, e.g. `drafter 0.1.0`.
    pub generator: String,
    pub input: InputInfo,
    /// The bake options as given (the bake report repeats them); free-form, for provenance.
    #[serde(default)]
    pub settings: serde_json::Value,
    /// Centre of the scene's world bounding box, which projector directions face away from.
    pub scene_center: [f64; 3],
    /// Number of parts; part ids are `0..partCount`.
    pub part_count: u32,
}

/// Where the bake came from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct InputInfo {
    /// File name of the input (no folders).
    pub name: String,
    /// Input format (`gltf`, `glb`, `obj`, `stl`, `off`, `ply`).
    pub format: String,
    /// SHA-256 of the input file's bytes, 64 lowercase hex digits.
    pub sha256: String,
}

/// Node-level object: the parts drawn by this node's mesh instance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct NodeExtension {
    /// The parts of this instance, indexed by the mesh's per-triangle part label (one entry when
    /// the mesh has no labels).
    pub parts: Vec<PartRecord>,
}

/// Everything baked for one part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct PartRecord {
    /// Scene-wide part id.
    pub id: u32,
    pub name: String,
    pub triangles: u32,
    /// Oriented bounding box in world space.
    pub obb: BoxRecord,
    pub projector: ProjectorRecord,
    pub gradient: GradientRecord,
    /// Shading style hint (`metal`, `gooch`, ...); absent means "the scene's style".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub style: Option<String>,
}

/// An oriented box: `center + Σ axes[i] · t_i · halfExtents[i]` for t in [-1, 1]³.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct BoxRecord {
    pub center: [f64; 3],
    /// Three orthonormal, right-handed unit vectors.
    pub axes: [[f64; 3]; 3],
    pub half_extents: [f64; 3],
    pub volume: f64,
    /// The method that produced it (`aabb`, `pca`, `hull`, `default`, `optimal`).
    pub method: String,
}

/// A part's projector (Lux et al. 2013, §3): the gradient runs along `direction` from `anchor`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct ProjectorRecord {
    pub anchor: [f64; 3],
    /// Unit vector.
    pub direction: [f64; 3],
    /// Extent along `direction` mapped to [0, 1].
    pub scale: f64,
    /// Column-major 4×4 matrix taking a world position to (p, ·, ·, 1) with p ∈ [0, 1] along the
    /// projector.
    pub matrix: [f64; 16],
}

/// Parameters of the gradient function ω(i, q, f, p) (Lux et al. 2013, Eqn. 1) and the transfer γ.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct GradientRecord {
    /// Quantisation steps q.
    pub q: f64,
    /// Fade step f.
    pub f: f64,
    /// Power p.
    pub p: f64,
    /// Name of the intensity transfer curve γ (`identity` by default).
    pub transfer: String,
}

/// Primitive-level object: per-mesh data, bulk arrays as accessors.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct PrimitiveExtension {
    /// Accessor (SCALAR, unsigned byte/short/int): the part label of each triangle of the
    /// primitive, in primitive order; the part is `node.parts[label]`. Absent: label 0 for all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part_labels: Option<u32>,
}
