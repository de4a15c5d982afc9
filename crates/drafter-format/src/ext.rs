//! The `DRAFTER_illustration` extension's objects as serde types. The spec is `spec/README.md`
//! beside this crate, the schema `spec/schema/`; keep the three in sync.
//!
//! The schema's enumerations are enums here ([`PartStyle`], [`ObbMethod`], [`TransferCurve`]), so a
//! value outside them is refused when the file is read and no user parses a name again later.

pub use drafter_core::ObbMethod;
pub use drafter_core::env_map::{CoolToWarmEncoding, EnvMapping};
pub use drafter_core::gradient::TransferCurve;
use serde::{Deserialize, Serialize};

/// The extension's name, as listed in `extensionsUsed` (never in `extensionsRequired`).
pub const EXTENSION: &str = "DRAFTER_illustration";

/// Version of the extension's layout written by this crate.
pub const FORMAT_VERSION: &str = "0.2";

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
    /// How the normals were computed, when the bake wrote them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normals: Option<NormalsInfo>,
    /// The baked NPR lookup textures, by glTF texture index (absent when the bake embedded none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub textures: Option<TexturesRecord>,
}

/// A reference to a glTF texture (`textures[index]`), as glTF's own `textureInfo`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct TextureRef {
    pub index: u32,
}

/// The NPR lookup textures a bake embedded (only those the scene uses; see the spec's "Textures").
/// Every texture is a PNG image in the binary buffer with a standard glTF `texture` and `sampler`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct TexturesRecord {
    /// γ transfer tables (Lux et al. 2013): R8, 128 × rows, row `r` is the curve `curves[r]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gradient: Option<GradientTexture>,
    /// Cel step tables (ten Bosch 2005): R8, 128 × rows, row `r` is `tables[r]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cel: Option<CelTexture>,
    /// Cool-to-warm maps (Gooch et al. 1999, Fig. 10), one per variant.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cool_to_warm: Vec<CoolToWarmTexture>,
    /// Hatching halftone (Freudenberg 2002), one texture per stored mip level.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hatching: Option<HatchingTexture>,
    /// Gooch metal bands and highlights; present only when some part is metal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub metal: Option<MetalTexture>,
}

impl TexturesRecord {
    /// Every texture index the record refers to: gradient, cel, cool-to-warm maps, hatching levels,
    /// metal bands and highlights.
    pub fn indices(&self) -> Vec<u32> {
        let mut out = Vec::new();
        out.extend(self.gradient.as_ref().map(|g| g.index));
        out.extend(self.cel.as_ref().map(|c| c.index));
        out.extend(self.cool_to_warm.iter().map(|c| c.index));
        if let Some(h) = &self.hatching {
            out.extend(h.levels.iter().map(|l| l.index));
        }
        if let Some(m) = &self.metal {
            out.extend([m.bands.index, m.highlights.index]);
        }
        out
    }

    /// Mutable access to every texture index, same order as [`Self::indices`].
    pub fn indices_mut(&mut self) -> Vec<&mut u32> {
        let mut out = Vec::new();
        out.extend(self.gradient.as_mut().map(|g| &mut g.index));
        out.extend(self.cel.as_mut().map(|c| &mut c.index));
        out.extend(self.cool_to_warm.iter_mut().map(|c| &mut c.index));
        if let Some(h) = &mut self.hatching {
            out.extend(h.levels.iter_mut().map(|l| &mut l.index));
        }
        if let Some(m) = &mut self.metal {
            out.push(&mut m.bands.index);
            out.push(&mut m.highlights.index);
        }
        out
    }
}

/// The γ atlas: sample at `u = (0.5 + 127·p)/128`, `v = (row + 0.5)/rows`, linear, clamped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct GradientTexture {
    /// The glTF texture.
    pub index: u32,
    /// The transfer curve of each row (the parts' `gradient.transfer`).
    pub curves: Vec<TransferCurve>,
}

/// The cel atlas: sample at `u = (0.5 + 127·x)/128`, `v = (row + 0.5)/rows`, `x = max(n·l, 0)`
/// (cel) or `(1 + n·l)/2` (Goochel).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct CelTexture {
    /// The glTF texture.
    pub index: u32,
    pub tables: Vec<CelTableRecord>,
}

/// One cel step table.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct CelTableRecord {
    /// Diffuse steps, 2–4.
    pub steps: u32,
    /// Whether the table ends in a white specular band.
    pub specular: bool,
    /// Value of the darkest step.
    pub min_level: f64,
    /// Start of the specular band (when `specular`).
    pub specular_threshold: f64,
    /// Value of the brightest diffuse step when `specular`.
    pub diffuse_max: f64,
}

/// A cool-to-warm map indexed by the eye-space normal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct CoolToWarmTexture {
    /// The glTF texture.
    pub index: u32,
    /// `octahedral` or `normal_sphere` (formulas in the spec).
    pub mapping: EnvMapping,
    /// `factored` (RGB = base, A = object-colour weight: `clamp(rgb + a·k_d)`) or `colour`.
    pub encoding: CoolToWarmEncoding,
    /// Unit direction towards the light in eye space the map was baked for.
    pub light_in_eye: [f64; 3],
    /// Whether the splash-back multiplier is included (Fig. 10(b)).
    pub splash_back: bool,
}

/// The hatching halftone T: ink = `clamp(contrast·(1 − (T + I)), 0, 1)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct HatchingTexture {
    /// Mip levels, level 0 (full size) first; level `m` is `size/2^m` square. A renderer uploads them
    /// as the texture's mip chain (and creates no further levels).
    pub levels: Vec<TextureRef>,
    /// The recommended soft-threshold constant `c` (> 1).
    pub contrast: f64,
}

/// Gooch metal: `colour = base · band(u) + highlight(n_eye)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct MetalTexture {
    /// R8, `n × 1`, repeat: sampled at `u = s·(1 + n·w)/2`, `w` the part's `obb.axes[1]`.
    pub bands: TextureRef,
    /// R8 highlights, indexed by the eye-space normal through `highlightMapping`.
    pub highlights: TextureRef,
    /// `octahedral` or `normal_sphere`.
    pub highlight_mapping: EnvMapping,
    /// Ids of the parts the bake found metal (style hint `metal`, or material metallic factor at
    /// or above `metallicThreshold`).
    pub parts: Vec<u32>,
    /// The metallic-factor threshold of the detection.
    pub metallic_threshold: f64,
}

/// The normal stage's parameters (Cignoni et al. 2005), for provenance and for a viewer's toggle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct NormalsInfo {
    /// Enhancement strength k of n_E = normalize(n + k·(n − n_L)).
    pub strength: f64,
    /// Low-pass iterations.
    pub iterations: u32,
    /// Crease angle of the vertex normals, degrees.
    pub crease_angle_deg: f64,
    /// True when `NORMAL` holds the enhanced normals (for plain viewers) and the attribute named by
    /// `enhancedNormal` holds the crease-aware ones.
    pub enhanced_in_normal: bool,
}

/// Name of the vertex attribute with the other set of normals (see [`NormalsInfo`]).
pub const ENHANCED_NORMAL_ATTRIBUTE: &str = "_ENHANCED_NORMAL";

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

/// [`NodeExtension`] over borrowed parts, as the writer serialises it: the same JSON.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
pub(crate) struct NodeExtensionRef<'a> {
    pub parts: &'a [PartRecord],
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
    /// Shading style hint; absent means "the scene's style".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub style: Option<PartStyle>,
    /// A flat grey in [0, 1] (0 black, 1 white) that replaces the part's shading in every style
    /// (Lux et al. 2013 §4: parts set to a constant tone); absent means shaded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flat: Option<f64>,
}

/// A shading style: a part's style hint in the file (spelled as in the schema's `style` enum), the
/// style the viewer draws a frame in, and the CLI's `--style` (with the `clap` feature) — one type.
/// See the viewer's `passes/gbuffer.wgsl` for the formulas and the papers they come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "snake_case")]
pub enum PartStyle {
    /// Projective gradients (Lux et al. 2013): each part's projector gives `p`, the transfer `γ`
    /// and the gradient function `ω(i, q, f, p)` give a grey value. Independent of light and
    /// normals. The default.
    #[default]
    Gradient,
    /// Cel shading: the clamped diffuse term in 2–4 steps, optional specular band.
    Cel,
    /// Cool-to-warm shading (Gooch et al. 1998/1999), optional splash-back multiplier.
    Gooch,
    /// Cel steps over Gooch's full-range `(1 + n·l)/2` (ten Bosch 2005).
    Goochel,
    /// Blinn–Phong: the photorealistic reference.
    Phong,
    /// Gooch metal: anisotropic bands around the part's principal axis plus highlights.
    Metal,
    /// Pen-and-ink hatching: Freudenberg's soft threshold of a halftone against the intensity.
    Hatch,
}

impl PartStyle {
    /// Every style, in the schema's order.
    pub const ALL: [PartStyle; 7] = [
        PartStyle::Gradient,
        PartStyle::Cel,
        PartStyle::Gooch,
        PartStyle::Goochel,
        PartStyle::Phong,
        PartStyle::Metal,
        PartStyle::Hatch,
    ];

    /// The name written in the file and accepted in configuration files.
    pub fn name(self) -> &'static str {
        match self {
            PartStyle::Gradient => "gradient",
            PartStyle::Cel => "cel",
            PartStyle::Gooch => "gooch",
            PartStyle::Goochel => "goochel",
            PartStyle::Phong => "phong",
            PartStyle::Metal => "metal",
            PartStyle::Hatch => "hatch",
        }
    }
}

impl std::fmt::Display for PartStyle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A style name that is not one of [`PartStyle::ALL`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown style {0:?}: expected one of {names}", names = PartStyle::ALL.map(PartStyle::name).join(", "))]
pub struct UnknownStyle(pub String);

impl std::str::FromStr for PartStyle {
    type Err = UnknownStyle;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PartStyle::ALL.into_iter().find(|style| style.name() == s).ok_or_else(|| UnknownStyle(s.to_owned()))
    }
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
    /// The method that produced it.
    pub method: ObbMethod,
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
    /// The intensity transfer curve γ (`identity` by default).
    pub transfer: TransferCurve,
}

/// Primitive-level object: per-mesh data, bulk arrays as accessors.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct PrimitiveExtension {
    /// Accessor (SCALAR, unsigned byte/short/int): the part label of each triangle of the
    /// primitive, in primitive order; the part is `node.parts[label]`. Absent: label 0 for all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part_labels: Option<u32>,
    /// Name of the `_`-prefixed VEC3 float attribute with the enhanced normals (Cignoni et al.
    /// 2005) — or, when the root's `normals.enhancedInNormal` is true, the crease-aware ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub enhanced_normal: Option<String>,
    /// Accessor (SCALAR, UNSIGNED_BYTE): the class of each hard edge that
    /// `EXT_mesh_primitive_edge_visibility` encodes as 2, in encoding order (see [`HardEdgeClass`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hard_edge_classes: Option<u32>,
}

/// The name of the draft Khronos extension the hard edges and silhouette candidates are written in.
pub const EDGE_VISIBILITY_EXTENSION: &str = "EXT_mesh_primitive_edge_visibility";

/// Codes of `hardEdgeClasses`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum HardEdgeClass {
    /// Dihedral angle above the crease angle: drawn white in Gooch's convention.
    Crease = 1,
    /// One incident face: drawn black.
    Boundary = 2,
    /// Between faces of different parts: drawn black.
    PartBorder = 3,
    /// Three or more incident faces: drawn black.
    NonManifold = 4,
    /// Between two faces of the input (glTF primitives of one mesh: CAD faces) meeting below the
    /// crease angle: a tangent edge (a fillet meeting a plane), drawn thin or left out.
    Tangent = 5,
}

/// Mesh-level object: data that spans all primitives of a mesh.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct MeshExtension {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub silhouettes: Option<SilhouettesRecord>,
}

/// What answers orthographic silhouette queries of a mesh (`silhouettes.orthographic`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum OrthographicHierarchy {
    /// The Gauss map of `silhouettes.gaussMap` (Gooch et al. 1999).
    GaussMap,
    /// Every candidate tested.
    #[default]
    BruteForce,
}

/// What answers perspective silhouette queries of a mesh (`silhouettes.perspective`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase")]
pub enum PerspectiveHierarchy {
    /// The normal-cone BVH of `silhouettes.coneBvh`.
    ConeBvh,
    /// Every candidate tested.
    #[default]
    BruteForce,
}

/// The silhouette candidates of a mesh and the hierarchies that answer "which are silhouettes from
/// here" (Gooch et al. 1999 Gauss map for orthographic views, a normal-cone BVH for eye points).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct SilhouettesRecord {
    /// Number of candidates: the edges the mesh's primitives encode as 1 in
    /// `EXT_mesh_primitive_edge_visibility`, primitive by primitive in encoding order. Candidate i
    /// has that extension's normals `2i` and `2i + 1` (as decoded) and, for an eye e, the point v
    /// of the edge's first vertex: a silhouette for view direction u iff (n1·u) and (n2·u) have
    /// strictly opposite signs, for an eye iff n1·(e − v) and n2·(e − v) do.
    pub candidates: u32,
    /// What answers orthographic views.
    pub orthographic: OrthographicHierarchy,
    /// What answers perspective views.
    pub perspective: PerspectiveHierarchy,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gauss_map: Option<GaussMapRecord>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cone_bvh: Option<ConeBvhRecord>,
}

/// Gauss-map arc hierarchy arrays (accessors). See drafter-lines' `GaussMapArrays`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct GaussMapRecord {
    /// 0 octahedron, 1 icosahedron.
    pub base: u32,
    pub max_depth: u32,
    /// Overlapping-bin factor in circumradii (0: strict bins).
    pub overlap: f32,
    /// FLOAT, 4 per node: cap centre and cull threshold.
    pub node_caps: u32,
    /// Unsigned integers, 4 per node: first child, child count, first own arc, end of own arcs
    /// (positions in the storage order the bin rule gives).
    pub nodes: u32,
}

/// Normal-cone BVH arrays (accessors). See drafter-lines' `ConeBvhArrays`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct ConeBvhRecord {
    /// Gauss-map level of the normal split.
    pub normal_level: u32,
    /// Leaf size of the binary tree before pruning.
    pub leaf_size: u32,
    /// FLOAT, 6 per node: box min, max.
    pub node_boxes: u32,
    /// FLOAT, 4 per node: cone axis and cull threshold.
    pub node_cones: u32,
    /// Unsigned integers, 4 per node: first child, child count, start and end of the subtree's
    /// candidates in the replayed tree's order.
    pub nodes: u32,
    /// UNSIGNED_BYTE: the split of every inner node of the dual-space trees, in preorder. Absent
    /// when no dual-space tree splits (every normal cell fits one leaf): glTF accessors may not be
    /// empty.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub splits: Option<u32>,
    /// Unsigned integers: where each dual-space tree's splits start.
    pub split_starts: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The writer's borrowed node object is the reader's `NodeExtension`, key for key.
    #[test]
    fn the_borrowed_node_extension_writes_what_is_read() {
        let part = |id: u32, style: Option<PartStyle>, flat: Option<f64>| PartRecord {
            id,
            name: format!("part {id}"),
            triangles: 12,
            obb: BoxRecord {
                center: [1.0, -2.0, 3.5],
                axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                half_extents: [0.5, 0.25, -0.0],
                volume: 0.0,
                method: ObbMethod::ALL[0],
            },
            projector: ProjectorRecord {
                anchor: [1.0, -2.0, 3.5],
                direction: [1.0, 0.0, 0.0],
                scale: 1.0,
                matrix: std::array::from_fn(|i| i as f64 * 0.1),
            },
            gradient: GradientRecord { q: 10.0, f: 0.5, p: 1.0, transfer: TransferCurve::default() },
            style,
            flat,
        };
        let parts = vec![part(0, None, None), part(1, Some(PartStyle::Metal), Some(0.25))];
        let borrowed = serde_json::to_value(NodeExtensionRef { parts: &parts }).expect("serialises");
        assert_eq!(borrowed, serde_json::to_value(NodeExtension { parts: parts.clone() }).expect("serialises"));
        let read: NodeExtension = serde_json::from_value(borrowed).expect("reads");
        assert_eq!(read.parts, parts);
    }

    /// The names the code prints are the JSON spellings, and both are the schema's enumerations.
    #[test]
    fn enum_names_are_their_json_spelling_and_the_schemas() {
        let node_schema = include_str!("../spec/schema/DRAFTER_illustration.node.schema.json");
        let schema: serde_json::Value = serde_json::from_str(node_schema).expect("schema");
        let part = &schema["definitions"]["part"]["properties"];
        let listed = |v: &serde_json::Value| -> Vec<String> {
            v["enum"].as_array().expect("enum").iter().map(|s| s.as_str().expect("name").to_owned()).collect()
        };
        let spelled = |v: serde_json::Value| v.as_str().expect("a string").to_owned();
        let styles: Vec<String> = PartStyle::ALL.iter().map(|s| spelled(serde_json::json!(s))).collect();
        assert_eq!(styles, PartStyle::ALL.map(|s| s.name().to_owned()));
        assert_eq!(styles, listed(&part["style"]));
        let methods: Vec<String> = ObbMethod::ALL.iter().map(|m| spelled(serde_json::json!(m))).collect();
        assert_eq!(methods, ObbMethod::ALL.map(|m| m.name().to_owned()));
        assert_eq!(methods, listed(&part["obb"]["properties"]["method"]));
        let curves: Vec<String> = TransferCurve::ALL.iter().map(|c| spelled(serde_json::json!(c))).collect();
        assert_eq!(curves, TransferCurve::ALL.map(|c| c.name().to_owned()));
        assert_eq!(curves, listed(&part["gradient"]["properties"]["transfer"]));
    }

    /// A name outside an enumeration is refused when the file is read, naming the value.
    #[test]
    fn unknown_names_are_refused_on_read() {
        for (field, value) in [("style", "neon"), ("transfer", "sigmoid")] {
            let error = match field {
                "style" => serde_json::from_value::<PartStyle>(value.into()).expect_err(value).to_string(),
                _ => serde_json::from_value::<TransferCurve>(value.into()).expect_err(value).to_string(),
            };
            assert!(error.contains(value), "{field}: {error}");
        }
        assert!(serde_json::from_value::<ObbMethod>("best".into()).is_err());
    }

    #[test]
    fn enums_are_written_and_read_in_the_specs_spelling() {
        assert_eq!(json(&EnvMapping::Octahedral), "\"octahedral\"");
        assert_eq!(json(&EnvMapping::NormalSphere), "\"normal_sphere\"");
        assert_eq!(json(&CoolToWarmEncoding::Factored), "\"factored\"");
        assert_eq!(json(&CoolToWarmEncoding::Colour), "\"colour\"");
        assert_eq!(json(&OrthographicHierarchy::GaussMap), "\"gaussMap\"");
        assert_eq!(json(&OrthographicHierarchy::BruteForce), "\"bruteForce\"");
        assert_eq!(json(&PerspectiveHierarchy::ConeBvh), "\"coneBvh\"");
        assert!(serde_json::from_str::<EnvMapping>("\"NormalSphere\"").is_err());
        assert!(serde_json::from_str::<PerspectiveHierarchy>("\"gaussMap\"").is_err());
    }

    fn json<T: Serialize>(value: &T) -> String {
        serde_json::to_string(value).unwrap()
    }
}
