//! Bake options: [`BakeConfig`], every option of a bake, which is also the `--config FILE.toml` that sets
//! them (stage options and per-part overrides):
//!
//! ```toml
//! [segment]
//! mode = "auto"              # nodes | components | regions | auto
//! region_angle_deg = 30.0
//!
//! [obb]
//! method = "default"         # aabb | pca | hull | default | optimal
//!
//! [gradient]
//! q = 10                     # quantisation, 1..=255
//! f = 0.5                    # fade step, [0, 1]
//! p = 1.0                    # power, [0.01, 10]
//! transfer = "identity"      # identity | smoothstep | ease_in | ease_out | invert
//!
//! [normals]
//! enabled = true
//! strength = 0.5             # k of n_E = normalize(n + k(n - n_L)), [0, 5]
//! iterations = 20            # low-pass iterations, 0..=200
//! crease_angle_deg = 30.0    # vertex normals are not averaged across sharper edges
//! enhanced_in_normal = false # true: NORMAL holds the enhanced normals, for plain viewers
//!
//! [lines]
//! enabled = true
//! crease_angle_deg = 30.0    # sharper edges are creases (hard edges, drawn white)
//! crease_min_edges = 4       # a chain of creases alone with fewer edges (0 keeps all)...
//! crease_min_length = 0.01   # ...and shorter than this fraction of the mesh's diagonal...
//! strong_crease_deg = 60.0   # ...and no crease sharper than this is a speck (scan noise)
//! hierarchies = true         # store silhouette hierarchies where they beat brute force
//!
//! [textures]                 # NPR lookup textures embedded as PNG (see `crate::textures`)
//! enabled = true
//! styles = ["gradient", "cel", "gooch", "goochel", "hatch"]  # scene-wide styles to bake lookups for
//! metallic_threshold = 0.5   # material metallicFactor >= this makes a part metal
//! [textures.cool_to_warm]    # drafter-textures' options; a table replaces that texture's defaults
//! splash_back = true
//! [textures.metal]
//! specular_power = 40.0
//! [textures.hatching]
//! contrast = 4.0
//! [textures.cel]
//! steps = 3
//! specular = true
//!
//! [output]
//! compress = "meshopt"       # "none" (default) or "meshopt": EXT_meshopt_compression, .glb only
//!
//! [[part]]                   # any number; `name` or `id` selects the part(s)
//! name = "gear"
//! method = "optimal"
//! direction = [0.0, 0.0, 1.0]
//! anchor = [0.0, 0.0, 0.0]
//! scale = 2.0
//! q = 17
//! f = 1.0
//! p = 0.19
//! style = "metal"            # gradient | cel | gooch | goochel | phong | metal | hatch
//! transfer = "smoothstep"    # the part's transfer curve γ
//! flat = 0.0                 # a flat grey in [0, 1] instead of shading (0 black, 1 white)
//! ```
//!
//! The file is this module's [`BakeConfig`], read by serde and nothing else: each table is a field
//! (`[[part]]` the [`BakeConfig::overrides`]), a key or table left out keeps its default (each type's
//! `Default`, through `#[serde(default)]`), and an unknown key is an error that names it
//! (`deny_unknown_fields`). Python's `config=` mapping is the same tables as JSON
//! ([`BakeConfig::from_json`]). Reading checks types only; [`BakeConfig::validate`] then checks every
//! range, once, after every source of options is applied (`drafter bake`'s flags go over the file),
//! and its errors name the key. An `anchor` and `scale` that leave a part no gradient (a scale at or
//! below 1e-12 of the anchor's largest coordinate, or either beyond `f32`) are refused when the
//! part's projector is made.

use drafter_bounds::{GradientParams, ObbMethod, ObbOptions, TransferCurve};
use drafter_format::{Container, InputInfo, PartStyle};
use drafter_normals::NormalsOptions;
use drafter_segment::SegmentOptions;
use drafter_textures::{CelOptions, CoolToWarmOptions, HatchingOptions, MetalOptions};
use serde::{Deserialize, Serialize};

use crate::BakeError;

/// Every option of a bake, one field per table of the config file (see the module docs).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BakeConfig {
    /// `[segment]`: `mode` and `region_angle_deg` (drafter-segment reads no other key).
    pub segment: SegmentOptions,
    /// `[obb]`: `method` (drafter-bounds reads no other key).
    pub obb: ObbOptions,
    /// `[gradient]`: the gradient of every part without an override.
    pub gradient: GradientOptions,
    /// `[normals]`.
    pub normals: NormalsStage,
    /// `[lines]`.
    pub lines: LinesStage,
    /// `[textures]`.
    pub textures: TexturesStage,
    /// `[output]`: how the written file is compressed (also `drafter bake --compress`).
    pub output: OutputOptions,
    /// `[[part]]`: per-part overrides, applied in order (a later one wins).
    #[serde(rename = "part")]
    pub overrides: Vec<PartOverride>,
    /// Provenance written into the file: the input's, never the config file's.
    #[serde(skip_deserializing)]
    pub input: InputInfo,
    /// The file layout written: the output's name decides it, never the config file.
    #[serde(skip_deserializing)]
    pub container: Container,
}

impl Default for BakeConfig {
    fn default() -> Self {
        Self {
            segment: SegmentOptions::default(),
            obb: ObbOptions::default(),
            gradient: GradientOptions::default(),
            normals: NormalsStage::default(),
            lines: LinesStage::default(),
            textures: TexturesStage::default(),
            output: OutputOptions::default(),
            overrides: Vec::new(),
            input: InputInfo { name: String::new(), format: String::new(), sha256: String::new() },
            container: Container::Glb,
        }
    }
}

impl BakeConfig {
    /// The options a config file's TOML text sets (see the module docs), the rest at their
    /// defaults. Types and keys are checked here, ranges by [`BakeConfig::validate`], which the
    /// caller runs once it has applied its own options (as `drafter bake`'s flags) over these.
    pub fn from_toml(text: &str) -> Result<Self, BakeError> {
        toml::from_str(text).map_err(|e| BakeError::Config(one_line(&e.to_string())))
    }

    /// The same tables as JSON (what Python's `config=` mapping becomes); as [`BakeConfig::from_toml`].
    /// The JSON is read as TOML values first, so that an error names its key, as a file's does
    /// (``… expected u32 in `gradient.q` ``), where the JSON reader would give a column of text the
    /// user never wrote.
    pub fn from_json(text: &str) -> Result<Self, BakeError> {
        let config = |e: &dyn std::fmt::Display| BakeError::Config(one_line(&e.to_string()));
        let value: toml::Value = serde_json::from_str(text).map_err(|e| config(&e))?;
        Self::deserialize(value).map_err(|e| config(&e))
    }

    /// Checks every option against its documented range: the one check of a config, whether it
    /// came from a file, flags, Python or code. The error names the key (`normals.strength = 9 is
    /// outside [0, 5]`, `part[2]: scale = -1 must be finite and > 0`).
    pub fn validate(&self) -> Result<(), BakeError> {
        self.check().map_err(BakeError::Config)
    }

    fn check(&self) -> Result<(), String> {
        degrees("segment.region_angle_deg", self.segment.region_angle_deg)?;
        let l = &self.lines;
        degrees("lines.crease_angle_deg", l.crease_angle_deg)?;
        if !(l.crease_min_length.is_finite() && l.crease_min_length >= 0.0) {
            return Err(format!("lines.crease_min_length = {} must be a fraction >= 0", l.crease_min_length));
        }
        degrees("lines.strong_crease_deg", l.strong_crease_deg)?;
        let n = &self.normals;
        if !(0.0..=MAX_STRENGTH).contains(&n.strength) {
            return Err(format!("normals.strength = {} is outside [0, {MAX_STRENGTH}]", n.strength));
        }
        if n.iterations > MAX_ITERATIONS {
            return Err(format!("normals.iterations = {} is outside 0..={MAX_ITERATIONS}", n.iterations));
        }
        degrees("normals.crease_angle_deg", n.crease_angle_deg)?;
        self.textures.validate()?;
        let gradient = self.gradient.params();
        gradient.validate().map_err(|e| format!("gradient: {e}"))?;
        for (i, part) in self.overrides.iter().enumerate() {
            part.validate(&gradient).map_err(|e| format!("part[{i}]: {e}"))?;
        }
        Ok(())
    }
}

/// An angle in degrees, in [0, 180].
fn degrees(key: &str, value: impl Into<f64> + std::fmt::Display + Copy) -> Result<(), String> {
    if (0.0..=180.0).contains(&value.into()) { Ok(()) } else { Err(format!("{key} = {value} is outside [0, 180]")) }
}

/// `[gradient]`: the gradient function's parameters and transfer curve of every part without an
/// override (drafter-core's `gradient` module defines them).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GradientOptions {
    /// Quantisation, the number of bands. Default [`drafter_core::gradient::DEFAULT_QUANTIZATION`]
    /// (10); range 1..=255.
    pub q: u32,
    /// Fade step inside a band. Default [`drafter_core::gradient::DEFAULT_FADE_STEP`] (0.5); range
    /// [0, 1].
    pub f: f32,
    /// Power applied to the intensity. Default [`drafter_core::gradient::DEFAULT_POWER`] (1.0); range
    /// [0.01, 10].
    pub p: f32,
    /// The transfer curve γ. Default [`TransferCurve::Identity`].
    pub transfer: TransferCurve,
}

impl Default for GradientOptions {
    fn default() -> Self {
        let GradientParams { q, f, p } = GradientParams::default();
        Self { q, f, p, transfer: TransferCurve::default() }
    }
}

impl GradientOptions {
    /// The `(q, f, p)` of the gradient function.
    pub fn params(&self) -> GradientParams {
        GradientParams { q: self.q, f: self.f, p: self.p }
    }
}

/// `[output]`: what is done to the written file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputOptions {
    /// Its compression. Default [`Compression::None`].
    pub compress: Compression,
}

/// Compression of the written file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Compression {
    /// Plain buffers (the default): any glTF reader opens the file.
    #[default]
    None,
    /// `EXT_meshopt_compression` on the buffer views where it pays (lossless codecs, see
    /// `drafter_format::meshopt`), on a scene reordered for them (`reorder.rs` in this crate), with
    /// shading normals as bytes (`KHR_mesh_quantization`); readers need the extension (three.js with its MeshoptDecoder,
    /// CesiumJS, gltfpack, our own). GLB output only.
    Meshopt,
}

/// Upper bound of [`NormalsStage::strength`].
const MAX_STRENGTH: f32 = 5.0;
/// Upper bound of [`NormalsStage::iterations`].
const MAX_ITERATIONS: u32 = 200;

/// `[normals]`, the normal stage (Cignoni et al. 2005 enhancement + crease-aware vertex normals).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NormalsStage {
    /// Compute and write normals. Default true.
    pub enabled: bool,
    /// `k` of `n_E = normalize(n + k(n - n_L))`. Default [`drafter_normals::DEFAULT_STRENGTH`]
    /// (0.5); range [0, 5].
    pub strength: f32,
    /// Low-pass iterations. Default [`drafter_normals::DEFAULT_ITERATIONS`] (20); range
    /// 0..=200.
    pub iterations: u32,
    /// Vertex normals are not averaged across edges sharper than this. Default
    /// [`drafter_normals::DEFAULT_CREASE_ANGLE_DEG`] (30°); range [0, 180].
    pub crease_angle_deg: f32,
    /// Write the enhanced normals into `NORMAL` (and the crease-aware ones into
    /// `_ENHANCED_NORMAL`), so plain viewers show the enhancement. Default false.
    pub enhanced_in_normal: bool,
}

impl NormalsStage {
    /// drafter-normals' options this stage asks for (its defaults for the rest).
    pub fn options(&self) -> NormalsOptions {
        let mut options = NormalsOptions::default();
        options.enhance.strength = self.strength;
        options.enhance.iterations = self.iterations;
        options.crease.crease_angle_deg = self.crease_angle_deg;
        options
    }
}

impl Default for NormalsStage {
    fn default() -> Self {
        let options = NormalsOptions::default();
        Self {
            enabled: true,
            strength: options.enhance.strength,
            iterations: options.enhance.iterations,
            crease_angle_deg: options.crease.crease_angle_deg,
            enhanced_in_normal: false,
        }
    }
}

/// `[lines]`, the line stage (edge classes, EXT_mesh_primitive_edge_visibility, silhouette
/// hierarchies).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LinesStage {
    /// Classify and write edges. Default true.
    pub enabled: bool,
    /// Dihedral angle above which an edge is a crease. Default
    /// [`drafter_lines::DEFAULT_CREASE_ANGLE_DEG`] (30°); range [0, 180].
    pub crease_angle_deg: f32,
    /// A chain of creases alone shorter than this many edges, with no crease sharper than
    /// `strong_crease_deg`, is scan noise and drawn as silhouettes only (drafter-lines' `classify`
    /// docs). Default [`drafter_lines::DEFAULT_CREASE_MIN_EDGES`] (4); 0 keeps every crease.
    pub crease_min_edges: u32,
    /// Fraction of the mesh's bounding diagonal; a short chain at least this long is kept. Default
    /// [`drafter_lines::DEFAULT_CREASE_MIN_LENGTH`] (0.01).
    pub crease_min_length: f32,
    /// Degrees; a short chain with a crease sharper than this is kept. Default
    /// [`drafter_lines::DEFAULT_STRONG_CREASE_DEG`] (60°); range [0, 180].
    pub strong_crease_deg: f32,
    /// Build and store silhouette hierarchies where they beat brute force (drafter-lines decides by
    /// candidate count and a cost model). Default true.
    pub hierarchies: bool,
}

impl LinesStage {
    /// The classification options of drafter-lines this stage asks for.
    pub fn line_options(&self) -> drafter_lines::LineOptions {
        drafter_lines::LineOptions {
            crease_angle_deg: self.crease_angle_deg,
            crease_min_edges: self.crease_min_edges,
            crease_min_length: self.crease_min_length,
            strong_crease_deg: self.strong_crease_deg,
            ..drafter_lines::LineOptions::default()
        }
    }
}

impl Default for LinesStage {
    fn default() -> Self {
        Self {
            enabled: true,
            crease_angle_deg: drafter_lines::DEFAULT_CREASE_ANGLE_DEG,
            crease_min_edges: drafter_lines::DEFAULT_CREASE_MIN_EDGES,
            crease_min_length: drafter_lines::DEFAULT_CREASE_MIN_LENGTH,
            strong_crease_deg: drafter_lines::DEFAULT_STRONG_CREASE_DEG,
            hierarchies: true,
        }
    }
}

/// Default of [`TexturesStage::styles`]: every scene-wide style of the viewer that reads a lookup,
/// except `metal` (baked only for metal parts, or when listed).
pub const DEFAULT_TEXTURE_STYLES: [PartStyle; 5] =
    [PartStyle::Gradient, PartStyle::Cel, PartStyle::Gooch, PartStyle::Goochel, PartStyle::Hatch];

/// Default of [`TexturesStage::metallic_threshold`]: a material at least half metallic is metal.
pub const DEFAULT_METALLIC_THRESHOLD: f32 = 0.5;

/// `[textures]`, the textures stage: which NPR lookup textures (drafter-textures) are baked and
/// embedded as PNG. What is baked when is documented in `crate::textures`. A sub-table
/// (`[textures.cel]`) replaces that texture's options, its keys left out at drafter-textures'
/// defaults.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TexturesStage {
    /// Bake and embed textures. Default true.
    pub enabled: bool,
    /// Styles a viewer may apply to the whole scene; the lookups they read are baked (`gradient`:
    /// γ atlas, `cel`: cel atlas, `gooch`: cool-to-warm map, `goochel`: both, `hatch`: hatching,
    /// `metal`: metal bands and highlights, `phong`: none). Part style hints and metal parts add to
    /// them. Default [`DEFAULT_TEXTURE_STYLES`].
    pub styles: Vec<PartStyle>,
    /// A part without a style hint whose material's metallic factor is at least this is metal and
    /// gets the metal textures baked. Default [`DEFAULT_METALLIC_THRESHOLD`] (0.5); range [0, ∞),
    /// above 1 turns detection from materials off.
    pub metallic_threshold: f32,
    /// Metal bands and highlights. Default: the paper's (drafter-textures' `MetalOptions::default`).
    pub metal: MetalOptions,
    /// The cool-to-warm map. Default: factored (serves every part colour), octahedral, no
    /// splash-back.
    pub cool_to_warm: CoolToWarmOptions,
    /// The hatching halftone. Default: drafter-textures' (128², 4 mip levels).
    pub hatching: HatchingOptions,
    /// The cel step table (read by `cel` and `goochel`). Default: 3 steps with a specular band, as
    /// the viewer's default cel shading.
    pub cel: CelOptions,
}

impl Default for TexturesStage {
    fn default() -> Self {
        Self {
            enabled: true,
            styles: DEFAULT_TEXTURE_STYLES.to_vec(),
            metallic_threshold: DEFAULT_METALLIC_THRESHOLD,
            metal: MetalOptions::default(),
            cool_to_warm: CoolToWarmOptions::default(),
            hatching: HatchingOptions::default(),
            cel: CelOptions { specular: true, ..CelOptions::default() },
        }
    }
}

impl TexturesStage {
    /// Checks every option against its documented range; errors name the key.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.metallic_threshold.is_finite() && self.metallic_threshold >= 0.0) {
            return Err(format!("textures.metallic_threshold = {} must be finite and >= 0", self.metallic_threshold));
        }
        self.metal.validate("textures.metal.").map_err(|e| e.to_string())?;
        self.cool_to_warm.validate("textures.cool_to_warm.").map_err(|e| e.to_string())?;
        self.hatching.validate("textures.hatching.").map_err(|e| e.to_string())?;
        self.cel.validate("textures.cel.").map_err(|e| e.to_string())?;
        Ok(())
    }
}

/// Which parts an override applies to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub enum PartSelector {
    /// Every part with this name.
    Name(String),
    /// The part with this id.
    Id(u32),
}

/// `[[part]]`: settings of the parts it selects (by `name` or by `id`, exactly one); `None` keeps
/// the computed value.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartOverride {
    /// Selects every part with this name.
    pub name: Option<String>,
    /// Selects the part with this id.
    pub id: Option<u32>,
    pub method: Option<ObbMethod>,
    /// The projector's direction: finite, not zero; made unit.
    pub direction: Option<[f64; 3]>,
    /// The projector's anchor: finite.
    pub anchor: Option<[f64; 3]>,
    /// The projector's scale: finite, > 0.
    pub scale: Option<f64>,
    /// The gradient's parameters, in the ranges of [`GradientOptions`].
    pub q: Option<u32>,
    pub f: Option<f32>,
    pub p: Option<f32>,
    pub transfer: Option<TransferCurve>,
    /// The style hint (one of the format's styles; serde refuses another name).
    pub style: Option<PartStyle>,
    /// A flat grey in [0, 1] drawn instead of the part's shading (0 black, 1 white).
    pub flat: Option<f32>,
}

impl PartOverride {
    /// An override selecting `selector` and changing nothing yet.
    pub fn new(selector: PartSelector) -> Self {
        match selector {
            PartSelector::Name(name) => Self { name: Some(name), ..Self::default() },
            PartSelector::Id(id) => Self { id: Some(id), ..Self::default() },
        }
    }

    /// The parts it selects: by `name`, else by `id` ([`BakeConfig::validate`] refuses an override
    /// with both or neither; with neither it selects no part).
    pub fn selector(&self) -> PartSelector {
        match (&self.name, self.id) {
            (Some(name), _) => PartSelector::Name(name.clone()),
            (None, id) => PartSelector::Id(id.unwrap_or(u32::MAX)),
        }
    }

    /// The gradient parameters of a part that starts from `base`.
    pub fn gradient(&self, base: &GradientParams) -> GradientParams {
        GradientParams { q: self.q.unwrap_or(base.q), f: self.f.unwrap_or(base.f), p: self.p.unwrap_or(base.p) }
    }

    fn validate(&self, base: &GradientParams) -> Result<(), String> {
        if self.name.is_some() == self.id.is_some() {
            return Err("give exactly one of `name` or `id`".into());
        }
        self.gradient(base).validate().map_err(|e| e.to_string())?;
        if let Some(d) = self.direction {
            let length = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if !(length.is_finite() && length > 1e-12) {
                return Err(format!("direction {d:?} is not a non-zero finite vector"));
            }
        }
        if let Some(a) = self.anchor
            && !a.iter().all(|c| c.is_finite())
        {
            return Err(format!("anchor {a:?} is not finite"));
        }
        if let Some(s) = self.scale
            && !(s.is_finite() && s > 0.0)
        {
            return Err(format!("scale = {s} must be finite and > 0"));
        }
        if let Some(g) = self.flat
            && !(0.0..=1.0).contains(&g)
        {
            return Err(format!("flat = {g} is out of range [0, 1]"));
        }
        Ok(())
    }
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_segment::SegmentMode;

    /// The config a TOML text gives, validated.
    fn read(text: &str) -> Result<BakeConfig, BakeError> {
        let config = BakeConfig::from_toml(text)?;
        config.validate()?;
        Ok(config)
    }

    #[test]
    fn full_config_parses() {
        let c = read(
            "[segment]\nmode = \"components\"\n[obb]\nmethod = \"optimal\"\n[gradient]\nq = 7\nf = 0.715\np = 1.4\n\
             [[part]]\nname = \"gear\"\nstyle = \"metal\"\ndirection = [0.0, 0.0, 2.0]\n[[part]]\nid = 3\nq = 17\n",
        )
        .unwrap();
        assert_eq!(c.segment.mode, SegmentMode::Components);
        assert_eq!(c.obb.method, ObbMethod::Optimal);
        assert_eq!((c.gradient.q, c.gradient.f, c.gradient.p), (7, 0.715, 1.4));
        assert_eq!(c.overrides.len(), 2);
        assert_eq!(c.overrides[0].selector(), PartSelector::Name("gear".into()));
        assert_eq!(c.overrides[1].selector(), PartSelector::Id(3));
    }

    #[test]
    fn an_empty_file_is_the_defaults_and_every_table_reads() {
        let text = "[segment]\nmode = \"regions\"\nregion_angle_deg = 25.0\n[obb]\nmethod = \"pca\"\n\
                    [gradient]\nq = 7\nf = 0.6\np = 1.3\ntransfer = \"smoothstep\"\n\
                    [normals]\nenabled = false\nstrength = 0.7\niterations = 12\ncrease_angle_deg = 40.0\nenhanced_in_normal = true\n\
                    [lines]\nenabled = false\ncrease_angle_deg = 35.0\ncrease_min_edges = 3\ncrease_min_length = 0.02\n\
                    strong_crease_deg = 70.0\nhierarchies = false\n[output]\ncompress = \"meshopt\"\n";
        let json = |c: &BakeConfig| serde_json::to_value(c).unwrap();
        assert_eq!(json(&read("").unwrap()), json(&BakeConfig::default()));
        let c = read(text).unwrap();
        assert_eq!((c.segment.mode, c.segment.region_angle_deg), (SegmentMode::Regions, 25.0));
        assert_eq!(c.segment.weld, SegmentOptions::default().weld, "not a key of the file");
        assert_eq!(c.obb, ObbOptions::with_method(ObbMethod::Pca));
        assert_eq!(c.gradient, GradientOptions { q: 7, f: 0.6, p: 1.3, transfer: TransferCurve::Smoothstep });
        let n = c.normals;
        assert_eq!(
            (n.enabled, n.strength, n.iterations, n.crease_angle_deg, n.enhanced_in_normal),
            (false, 0.7, 12, 40.0, true)
        );
        assert_eq!((n.options().enhance.strength, n.options().enhance.iterations), (0.7, 12));
        assert_eq!(n.options().crease.crease_angle_deg, 40.0);
        let l = c.lines;
        assert_eq!((l.enabled, l.crease_angle_deg, l.crease_min_edges), (false, 35.0, 3));
        assert_eq!((l.crease_min_length, l.strong_crease_deg, l.hierarchies), (0.02, 70.0, false));
        assert_eq!(c.output.compress, Compression::Meshopt);
        // The defaults are drafter-normals' and drafter-core's own.
        let d = BakeConfig::default();
        assert_eq!(d.normals.options(), NormalsOptions::default());
        assert_eq!(d.gradient.params(), GradientParams::default());
        // The same tables as JSON give the same config.
        let from_json = BakeConfig::from_json(
            r#"{"segment": {"mode": "regions", "region_angle_deg": 25}, "obb": {"method": "pca"},
                "gradient": {"q": 7, "f": 0.6, "p": 1.3, "transfer": "smoothstep"},
                "normals": {"enabled": false, "strength": 0.7, "iterations": 12, "crease_angle_deg": 40, "enhanced_in_normal": true},
                "lines": {"enabled": false, "crease_angle_deg": 35, "crease_min_edges": 3, "crease_min_length": 0.02,
                          "strong_crease_deg": 70, "hierarchies": false},
                "output": {"compress": "meshopt"}}"#,
        )
        .unwrap();
        assert_eq!(json(&from_json), json(&c));
    }

    #[test]
    fn textures_section_parses() {
        assert_eq!(BakeConfig::default().textures.styles, DEFAULT_TEXTURE_STYLES);
        let c = read(
            "[textures]\nstyles = [\"gooch\"]\nmetallic_threshold = 0.9\n[textures.cool_to_warm]\nsplash_back = true\n\
             [textures.cel]\nsteps = 2\n",
        )
        .unwrap();
        assert_eq!(c.textures.styles, [PartStyle::Gooch]);
        assert_eq!(c.textures.metallic_threshold, 0.9);
        assert!(c.textures.cool_to_warm.splash_back);
        assert_eq!(c.textures.cool_to_warm.alpha, drafter_textures::cool_warm::DEFAULT_COOL_MIX);
        // A table replaces that texture's options: the keys it leaves out are drafter-textures'.
        assert_eq!((c.textures.cel.steps, c.textures.cel.specular), (2, false));
        assert!(BakeConfig::default().textures.cel.specular);
        assert!(c.textures.enabled);
        assert!(!read("[textures]\nenabled = false\n").unwrap().textures.enabled);
    }

    #[test]
    fn errors_name_the_key() {
        let cases = [
            ("[obb]\nmethdo = \"pca\"\n", "methdo"),
            ("[obb]\nhull_tolerance = 0.1\n", "hull_tolerance"),
            ("[segment]\nweld = \"exact\"\n", "weld"),
            ("[gradient]\nq = 0\n", "gradient: q"),
            ("[gradient]\np = 99.0\n", "gradient: p"),
            ("[gradient]\ntransfer = \"sigmoid\"\n", "sigmoid"),
            ("[[part]]\nname = \"a\"\nstyle = \"neon\"\n", "style"),
            ("[[part]]\nname = \"a\"\nid = 2\n", "part[0]: give exactly one"),
            ("[[part]]\nq = 2\n", "part[0]: give exactly one"),
            ("[[part]]\nid = 1\nscale = -1.0\n", "part[0]: scale"),
            ("[[part]]\nid = 1\n[[part]]\nid = 1\ndirection = [0.0, 0.0, 0.0]\n", "part[1]: direction"),
            ("[[part]]\nid = 1\nflat = 1.5\n", "flat"),
            ("[[part]]\nid = 1\nq = 300\n", "part[0]: q"),
            ("[segment]\nmode = \"blobs\"\n", "blobs"),
            ("[segment]\nregion_angle_deg = 190.0\n", "segment.region_angle_deg = 190"),
            ("[normals]\nstrength = 9.0\n", "normals.strength = 9"),
            ("[normals]\nstrength = nan\n", "normals.strength = NaN"),
            ("[normals]\niterations = 201\n", "normals.iterations = 201"),
            ("[normals]\ncrease_angle_deg = -1.0\n", "normals.crease_angle_deg"),
            ("[normals]\nsmooth = true\n", "smooth"),
            ("[lines]\ncrease_angle_deg = 181.0\n", "lines.crease_angle_deg"),
            ("[lines]\nstrong_crease_deg = 181.0\n", "lines.strong_crease_deg"),
            ("[lines]\ncrease_min_length = -0.5\n", "lines.crease_min_length"),
            ("[textures]\nstyles = [\"neon\"]\n", "neon"),
            ("[textures]\nmetallic_threshold = -1.0\n", "metallic_threshold"),
            ("[textures.cel]\nsteps = 9\n", "textures.cel.steps"),
            ("[textures.metal]\nexponent = 0.0\n", "textures.metal.exponent"),
            ("[textures.hatching]\nsize = 100\n", "textures.hatching.size"),
            ("[textures]\nhatch = true\n", "hatch"),
            ("[output]\nlevel = 3\n", "level"),
            ("input = \"x\"\n", "input"),
            ("container = \"gltf\"\n", "container"),
        ];
        for (text, needle) in cases {
            let err = read(text).unwrap_err().to_string();
            assert!(err.contains(needle), "{text:?}: {err}");
            assert!(err.starts_with("config: "), "{text:?}: {err}");
            assert!(!err.contains('\n'), "multi-line: {err}");
        }
        // JSON's errors name the key too, not a column of text the user never wrote.
        for (json, needle) in [
            (r#"{"normals": {"smooth": true}}"#, "unknown field `smooth`, expected one of `enabled`"),
            (r#"{"gradient": {"q": "ten"}}"#, "expected u32 in `gradient.q`"),
            (r#"{"part": [{"id": 1, "style": "neon"}]}"#, "in `part.style`"),
        ] {
            let err = BakeConfig::from_json(json).unwrap_err().to_string();
            assert!(err.contains(needle) && !err.contains("column"), "{json}: {err}");
        }
    }

    #[test]
    fn validate_checks_options_set_in_code_too() {
        let mut c = BakeConfig::default();
        assert!(c.validate().is_ok());
        c.lines.strong_crease_deg = 200.0;
        assert!(c.validate().unwrap_err().to_string().contains("lines.strong_crease_deg"));
        let mut c = BakeConfig::default();
        c.overrides.push(PartOverride { scale: Some(0.0), ..PartOverride::new(PartSelector::Id(0)) });
        assert!(c.validate().unwrap_err().to_string().contains("part[0]: scale"));
    }
}
