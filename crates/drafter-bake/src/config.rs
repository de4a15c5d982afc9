//! Bake options, and the `--config FILE.toml` that overrides them per part.
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
//! Unknown keys and out-of-range values are errors that name the key. An `anchor` and `scale` that
//! leave a part no gradient (a scale at or below 1e-12 of the anchor's largest coordinate, or either
//! beyond `f32`) are refused when the part's projector is made.

use drafter_bounds::{GradientParams, ObbMethod, ObbOptions, TransferCurve};
use drafter_format::{Container, InputInfo, PartStyle};
use drafter_normals::NormalsOptions;
use drafter_segment::{SegmentMode, SegmentOptions};
use drafter_textures::{CelOptions, CoolToWarmOptions, HatchingOptions, MetalOptions};
use serde::Deserialize;

use crate::BakeError;

/// Every option of a bake, one struct per stage.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BakeConfig {
    pub segment: SegmentOptions,
    pub normals: NormalsStage,
    pub lines: LinesStage,
    pub textures: TexturesStage,
    pub obb: ObbOptions,
    /// The gradient parameters of every part without an override.
    pub gradient: GradientParams,
    pub transfer: TransferCurve,
    /// Per-part overrides, applied in order (a later one wins).
    pub overrides: Vec<PartOverride>,
    /// Provenance written into the file.
    pub input: InputInfo,
    pub container: Container,
    /// How the written file is compressed (`[output] compress`, `drafter bake --compress`).
    pub compress: Compression,
}

/// Compression of the written file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
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

impl Default for BakeConfig {
    fn default() -> Self {
        Self {
            segment: SegmentOptions::default(),
            normals: NormalsStage::default(),
            lines: LinesStage::default(),
            textures: TexturesStage::default(),
            obb: ObbOptions::default(),
            gradient: GradientParams::default(),
            transfer: TransferCurve::default(),
            overrides: Vec::new(),
            input: InputInfo { name: String::new(), format: String::new(), sha256: String::new() },
            container: Container::Glb,
            compress: Compression::None,
        }
    }
}

/// The normal stage (Cignoni et al. 2005 enhancement + crease-aware vertex normals).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct NormalsStage {
    /// Compute and write normals. Default true.
    pub enabled: bool,
    /// Filter and layout options (defaults: drafter-normals').
    pub options: NormalsOptions,
    /// Write the enhanced normals into `NORMAL` (and the crease-aware ones into
    /// `_ENHANCED_NORMAL`), so plain viewers show the enhancement. Default false.
    pub enhanced_in_normal: bool,
}

impl Default for NormalsStage {
    fn default() -> Self {
        Self { enabled: true, options: NormalsOptions::default(), enhanced_in_normal: false }
    }
}

/// The line stage (edge classes, EXT_mesh_primitive_edge_visibility, silhouette hierarchies).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
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

/// The textures stage: which NPR lookup textures (drafter-textures) are baked and embedded as PNG.
/// What is baked when is documented in `crate::textures`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
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
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub enum PartSelector {
    /// Every part with this name.
    Name(String),
    /// The part with this id.
    Id(u32),
}

/// Per-part settings from the config file; `None` keeps the computed value.
#[derive(Clone, Debug, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PartOverride {
    #[serde(skip_deserializing, default = "default_selector")]
    pub selector: PartSelector,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    id: Option<u32>,
    pub method: Option<ObbMethod>,
    pub direction: Option<[f64; 3]>,
    pub anchor: Option<[f64; 3]>,
    pub scale: Option<f64>,
    pub q: Option<u32>,
    pub f: Option<f32>,
    pub p: Option<f32>,
    pub transfer: Option<TransferCurve>,
    /// Checked against the format's styles when the TOML is read (an unknown name is a config error).
    pub style: Option<PartStyle>,
    /// A flat grey in [0, 1] drawn instead of the part's shading (0 black, 1 white).
    pub flat: Option<f32>,
}

fn default_selector() -> PartSelector {
    PartSelector::Id(u32::MAX)
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileConfig {
    #[serde(default)]
    segment: SegmentSection,
    #[serde(default)]
    obb: ObbSection,
    #[serde(default)]
    gradient: GradientSection,
    #[serde(default)]
    normals: NormalsSection,
    #[serde(default)]
    lines: LinesSection,
    #[serde(default)]
    textures: TexturesSection,
    #[serde(default)]
    output: OutputSection,
    #[serde(default, rename = "part")]
    parts: Vec<PartOverride>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct OutputSection {
    compress: Option<Compression>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct SegmentSection {
    mode: Option<SegmentMode>,
    region_angle_deg: Option<f64>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct LinesSection {
    enabled: Option<bool>,
    crease_angle_deg: Option<f32>,
    crease_min_edges: Option<u32>,
    crease_min_length: Option<f32>,
    strong_crease_deg: Option<f32>,
    hierarchies: Option<bool>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct TexturesSection {
    enabled: Option<bool>,
    styles: Option<Vec<PartStyle>>,
    metallic_threshold: Option<f32>,
    metal: Option<MetalOptions>,
    cool_to_warm: Option<CoolToWarmOptions>,
    hatching: Option<HatchingOptions>,
    cel: Option<CelOptions>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct NormalsSection {
    enabled: Option<bool>,
    strength: Option<f32>,
    iterations: Option<u32>,
    crease_angle_deg: Option<f32>,
    enhanced_in_normal: Option<bool>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObbSection {
    method: Option<ObbMethod>,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct GradientSection {
    q: Option<u32>,
    f: Option<f32>,
    p: Option<f32>,
    transfer: Option<TransferCurve>,
}

impl BakeConfig {
    /// Applies a TOML config (see the module docs) on top of `self`. Errors name the key.
    pub fn apply_toml(&mut self, text: &str) -> Result<(), BakeError> {
        let file: FileConfig = toml::from_str(text).map_err(|e| BakeError::Config(one_line(&e.to_string())))?;
        if let Some(mode) = file.segment.mode {
            self.segment.mode = mode;
        }
        if let Some(c) = file.output.compress {
            self.compress = c;
        }
        if let Some(angle) = file.segment.region_angle_deg {
            if !(0.0..=180.0).contains(&angle) {
                return Err(BakeError::Config(format!("segment.region_angle_deg = {angle} is outside [0, 180]")));
            }
            self.segment.region_angle_deg = angle;
        }
        let l = &file.lines;
        if let Some(enabled) = l.enabled {
            self.lines.enabled = enabled;
        }
        if let Some(a) = l.crease_angle_deg {
            if !(0.0..=180.0).contains(&a) {
                return Err(BakeError::Config(format!("lines.crease_angle_deg = {a} is outside [0, 180]")));
            }
            self.lines.crease_angle_deg = a;
        }
        if let Some(n) = l.crease_min_edges {
            self.lines.crease_min_edges = n;
        }
        if let Some(f) = l.crease_min_length {
            if !(f.is_finite() && f >= 0.0) {
                return Err(BakeError::Config(format!("lines.crease_min_length = {f} must be a fraction >= 0")));
            }
            self.lines.crease_min_length = f;
        }
        if let Some(a) = l.strong_crease_deg {
            if !(0.0..=180.0).contains(&a) {
                return Err(BakeError::Config(format!("lines.strong_crease_deg = {a} is outside [0, 180]")));
            }
            self.lines.strong_crease_deg = a;
        }
        if let Some(h) = l.hierarchies {
            self.lines.hierarchies = h;
        }
        let n = &file.normals;
        if let Some(enabled) = n.enabled {
            self.normals.enabled = enabled;
        }
        if let Some(k) = n.strength {
            if !(0.0..=5.0).contains(&k) {
                return Err(BakeError::Config(format!("normals.strength = {k} is outside [0, 5]")));
            }
            self.normals.options.enhance.strength = k;
        }
        if let Some(i) = n.iterations {
            if i > 200 {
                return Err(BakeError::Config(format!("normals.iterations = {i} is outside 0..=200")));
            }
            self.normals.options.enhance.iterations = i;
        }
        if let Some(a) = n.crease_angle_deg {
            if !(0.0..=180.0).contains(&a) {
                return Err(BakeError::Config(format!("normals.crease_angle_deg = {a} is outside [0, 180]")));
            }
            self.normals.options.crease.crease_angle_deg = a;
        }
        if let Some(e) = n.enhanced_in_normal {
            self.normals.enhanced_in_normal = e;
        }
        let t = file.textures;
        if let Some(enabled) = t.enabled {
            self.textures.enabled = enabled;
        }
        if let Some(styles) = t.styles {
            self.textures.styles = styles;
        }
        if let Some(threshold) = t.metallic_threshold {
            self.textures.metallic_threshold = threshold;
        }
        if let Some(metal) = t.metal {
            self.textures.metal = metal;
        }
        if let Some(c) = t.cool_to_warm {
            self.textures.cool_to_warm = c;
        }
        if let Some(h) = t.hatching {
            self.textures.hatching = h;
        }
        if let Some(c) = t.cel {
            self.textures.cel = c;
        }
        self.textures.validate().map_err(BakeError::Config)?;
        if let Some(method) = file.obb.method {
            self.obb.method = method;
        }
        let g = &file.gradient;
        self.gradient = GradientParams {
            q: g.q.unwrap_or(self.gradient.q),
            f: g.f.unwrap_or(self.gradient.f),
            p: g.p.unwrap_or(self.gradient.p),
        };
        self.gradient.validate().map_err(|e| BakeError::Config(format!("gradient: {e}")))?;
        if let Some(t) = g.transfer {
            self.transfer = t;
        }
        for (i, mut part) in file.parts.into_iter().enumerate() {
            let at = format!("part[{i}]");
            part.selector = match (part.name.take(), part.id.take()) {
                (Some(name), None) => PartSelector::Name(name),
                (None, Some(id)) => PartSelector::Id(id),
                _ => return Err(BakeError::Config(format!("{at}: give exactly one of `name` or `id`"))),
            };
            part.validate(&self.gradient).map_err(|e| BakeError::Config(format!("{at}: {e}")))?;
            self.overrides.push(part);
        }
        Ok(())
    }
}

impl PartOverride {
    /// An override selecting `selector` and changing nothing yet.
    pub fn new(selector: PartSelector) -> Self {
        Self {
            selector,
            name: None,
            id: None,
            method: None,
            direction: None,
            anchor: None,
            scale: None,
            q: None,
            f: None,
            p: None,
            transfer: None,
            style: None,
            flat: None,
        }
    }

    /// The gradient parameters of a part that starts from `base`.
    pub fn gradient(&self, base: &GradientParams) -> GradientParams {
        GradientParams { q: self.q.unwrap_or(base.q), f: self.f.unwrap_or(base.f), p: self.p.unwrap_or(base.p) }
    }

    fn validate(&self, base: &GradientParams) -> Result<(), String> {
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

    #[test]
    fn full_config_parses() {
        let mut c = BakeConfig::default();
        c.apply_toml(
            "[segment]\nmode = \"components\"\n[obb]\nmethod = \"optimal\"\n[gradient]\nq = 7\nf = 0.715\np = 1.4\n\
             [[part]]\nname = \"gear\"\nstyle = \"metal\"\ndirection = [0.0, 0.0, 2.0]\n[[part]]\nid = 3\nq = 17\n",
        )
        .unwrap();
        assert_eq!(c.segment.mode, SegmentMode::Components);
        assert_eq!(c.obb.method, ObbMethod::Optimal);
        assert_eq!((c.gradient.q, c.gradient.f, c.gradient.p), (7, 0.715, 1.4));
        assert_eq!(c.overrides.len(), 2);
        assert_eq!(c.overrides[0].selector, PartSelector::Name("gear".into()));
        assert_eq!(c.overrides[1].selector, PartSelector::Id(3));
    }

    #[test]
    fn textures_section_parses() {
        let mut c = BakeConfig::default();
        assert_eq!(c.textures.styles, DEFAULT_TEXTURE_STYLES);
        c.apply_toml(
            "[textures]\nstyles = [\"gooch\"]\nmetallic_threshold = 0.9\n[textures.cool_to_warm]\nsplash_back = true\n\
             [textures.cel]\nsteps = 2\n",
        )
        .unwrap();
        assert_eq!(c.textures.styles, [PartStyle::Gooch]);
        assert_eq!(c.textures.metallic_threshold, 0.9);
        assert!(c.textures.cool_to_warm.splash_back);
        assert_eq!(c.textures.cool_to_warm.alpha, drafter_textures::cool_warm::DEFAULT_COOL_MIX);
        assert_eq!((c.textures.cel.steps, c.textures.cel.specular), (2, false));
        assert!(c.textures.enabled);
        c.apply_toml("[textures]\nenabled = false\n").unwrap();
        assert!(!c.textures.enabled);
    }

    #[test]
    fn errors_name_the_key() {
        let cases = [
            ("[obb]\nmethdo = \"pca\"\n", "methdo"),
            ("[gradient]\nq = 0\n", "q"),
            ("[gradient]\np = 99.0\n", "p"),
            ("[[part]]\nname = \"a\"\nstyle = \"neon\"\n", "style"),
            ("[[part]]\nname = \"a\"\nid = 2\n", "exactly one"),
            ("[[part]]\nid = 1\nscale = -1.0\n", "scale"),
            ("[[part]]\nid = 1\ndirection = [0.0, 0.0, 0.0]\n", "direction"),
            ("[segment]\nmode = \"blobs\"\n", "blobs"),
            ("[normals]\nstrength = 9.0\n", "strength"),
            ("[normals]\nsmooth = true\n", "smooth"),
            ("[textures]\nstyles = [\"neon\"]\n", "neon"),
            ("[textures]\nmetallic_threshold = -1.0\n", "metallic_threshold"),
            ("[textures.cel]\nsteps = 9\n", "textures.cel.steps"),
            ("[textures.metal]\nexponent = 0.0\n", "textures.metal.exponent"),
            ("[textures.hatching]\nsize = 100\n", "textures.hatching.size"),
            ("[textures]\nhatch = true\n", "hatch"),
        ];
        for (text, needle) in cases {
            let err = BakeConfig::default().apply_toml(text).unwrap_err().to_string();
            assert!(err.contains(needle), "{text:?}: {err}");
            assert!(!err.contains('\n'), "multi-line: {err}");
        }
    }
}
