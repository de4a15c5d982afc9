//! The textures stage: decides which NPR lookup textures the scene uses, bakes them with
//! drafter-textures and encodes them as PNG for drafter-format to embed.
//!
//! # What is baked when
//! The styles a scene uses are [`TexturesStage::styles`] (the styles a viewer may apply to the
//! whole scene; default `gradient`, `cel`, `gooch`, `goochel`, `hatch`), plus every part's style
//! hint, plus `metal` when some part is metal. A part is **metal** when its style hint is `metal`,
//! or when it has no hint and the material of most of its triangles has a metallic factor of at
//! least [`TexturesStage::metallic_threshold`] (0.5). A triangle without a material is not metal,
//! although glTF's default material would be: CAD exports leave materials out for plain parts.
//!
//! | style | texture(s) | paper |
//! |---|---|---|
//! | `gradient` | `gamma_atlas`: one 128-texel row per distinct γ curve of the parts, part order | Lux et al. 2013 §3 (`../shared/papers/000_*`) |
//! | `cel`, `goochel` | `cel_atlas`: the one table of [`TexturesStage::cel`] | ten Bosch 2005 (`003_*`) |
//! | `gooch`, `goochel` | `cool_to_warm_0`: [`TexturesStage::cool_to_warm`] | Gooch et al. 1999 §3.2, Fig. 10 (`001_*`) |
//! | `hatch` | `hatching`, `hatching_mip1` … : the halftone's stored mip levels, one PNG each | Freudenberg 2002 (`002_*`) |
//! | `metal` | `metal_bands`, `metal_highlights` | Gooch et al. 1999 §5.2.1 |
//! | `phong` | none | |
//!
//! The γ atlas holds the curves of *all* parts when it is baked: with part styles off a viewer
//! shades every part in the scene style. Nothing is baked when [`TexturesStage::enabled`] is off.
//! Every texture is deterministic (seeded generators, fixed PNG settings; see drafter-textures), so
//! the bake's output stays byte-identical at any thread count.

use drafter_core::{PartId, Scene};
use drafter_format::{
    CelTableRecord, CelTexture, CoolToWarmTexture, EmbeddedTextures, GradientTexture, HatchingTexture, MetalTexture,
    PartRecord, PartStyle, SamplerDesc, TextureImage, TextureRef, TexturesRecord,
};
use drafter_segment::Parts;
use drafter_textures::{Texture, TextureKind, TextureRequest, Wrap, bake_textures, encode_png_levels};
use serde::Serialize;

use crate::BakeError;
use crate::config::TexturesStage;

/// What the stage baked: the images to embed, in record order.
#[derive(Clone, Debug)]
pub(crate) struct BakedTextures {
    pub embedded: EmbeddedTextures,
    pub summary: TexturesSummary,
}

/// The textures part of the bake report.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TexturesSummary {
    /// Every embedded PNG, in the order of the images in the file.
    pub images: Vec<TextureReport>,
    /// Sum of the PNGs' bytes.
    pub total_bytes: usize,
    /// Ids of the parts found metal.
    pub metal_parts: Vec<u32>,
}

/// One embedded PNG.
#[derive(Clone, Debug, Serialize)]
pub struct TextureReport {
    /// Image name, also the file name (`NAME.png`) of `--textures-out`.
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Bytes of the PNG.
    pub bytes: usize,
}

/// The metal parts (module docs), in id order.
pub(crate) fn metal_parts(scene: &Scene, parts: &Parts, records: &[PartRecord], threshold: f32) -> Vec<u32> {
    records
        .iter()
        .filter(|r| match r.style {
            Some(style) => style == PartStyle::Metal,
            None => majority_metallic(scene, parts, PartId(r.id)) >= threshold,
        })
        .map(|r| r.id)
        .collect()
}

/// The metallic factor of the material that covers most of the part's triangles (ties: the lower
/// material index; no material: 0).
fn majority_metallic(scene: &Scene, parts: &Parts, part: PartId) -> f32 {
    let info = parts.part(part);
    let mesh = scene.mesh(scene.instances[info.instance.index()].mesh);
    let materials: Vec<Option<usize>> = mesh.groups.iter().map(|g| g.material.map(|m| m.index())).collect();
    let metallic = |m: Option<usize>| m.and_then(|m| scene.materials.get(m)).map_or(0.0, |m| m.metallic);
    if materials.windows(2).all(|w| w[0] == w[1]) {
        return metallic(materials.first().copied().flatten());
    }
    let mut counts = vec![0u64; scene.materials.len() + 1];
    for t in parts.triangles_of(part) {
        let g = mesh.groups.partition_point(|g| g.start + g.count <= t);
        let slot = materials.get(g).copied().flatten().map_or(scene.materials.len(), |m| m.min(scene.materials.len()));
        counts[slot] += 1;
    }
    let (best, _) = counts
        .iter()
        .enumerate()
        .fold((scene.materials.len(), 0u64), |(bi, bc), (i, &c)| if c > bc { (i, c) } else { (bi, bc) });
    metallic((best < scene.materials.len()).then_some(best))
}

/// What the scene needs baked (module docs).
pub(crate) fn request(records: &[PartRecord], metal: &[u32], stage: &TexturesStage) -> TextureRequest {
    if !stage.enabled {
        return TextureRequest::default();
    }
    let uses = |style: PartStyle| stage.styles.contains(&style) || records.iter().any(|r| r.style == Some(style));
    let gamma_curves =
        if uses(PartStyle::Gradient) { records.iter().map(|r| r.gradient.transfer).collect() } else { Vec::new() };
    TextureRequest {
        metal: (uses(PartStyle::Metal) || !metal.is_empty()).then(|| stage.metal.clone()),
        cool_to_warm: if uses(PartStyle::Gooch) || uses(PartStyle::Goochel) {
            vec![stage.cool_to_warm.clone()]
        } else {
            Vec::new()
        },
        hatching: uses(PartStyle::Hatch).then(|| stage.hatching.clone()),
        gamma_curves,
        cel_tables: if uses(PartStyle::Cel) || uses(PartStyle::Goochel) { vec![stage.cel] } else { Vec::new() },
    }
}

/// Requests remembered by [`bake_memoized`]: a batch's files mostly ask for the same few.
const MEMO_ENTRIES: usize = 8;

/// The lookup key of [`bake_memoized`], serialized: every option of the request by its serde form
/// (floats in their shortest round-trip form, as the cache key has the configuration), the metal
/// parts, and the threshold by its bits (so that no two thresholds share a key, as two non-finite
/// floats would in JSON, where both are `null`).
#[derive(Serialize)]
struct MemoKey<'a> {
    /// [`MEMO_FORM`].
    form: &'static str,
    request: &'a TextureRequest,
    metal_parts: &'a [u32],
    threshold_bits: u32,
}

/// The version of [`MemoKey`]'s form. The memo lives in one process, so a change of form can never
/// meet an old key; the tag keeps the key self-describing like the cache's (`drafter-catalog`).
const MEMO_FORM: &str = "drafter-textures-memo-json-1";

/// [`MemoKey`] as JSON; `None` if it does not serialize.
fn memo_key(request: &TextureRequest, metal_parts: &[u32], threshold: f32) -> Option<String> {
    let key = MemoKey { form: MEMO_FORM, request, metal_parts, threshold_bits: threshold.to_bits() };
    serde_json::to_string(&key).ok()
}

/// [`bake`], remembered for the process: the images are a function of the request, the metal parts
/// and the threshold alone (the stage's own determinism), so a process that bakes many files (a
/// batch, the Python package) computes and encodes each distinct set once. The lookup key is the
/// arguments' canonical serialization ([`MemoKey`] as JSON), which holds every option. On a small part
/// the stage is most of the bake; the bytes written do not change.
pub(crate) fn bake_memoized(
    request: &TextureRequest,
    metal_parts: Vec<u32>,
    threshold: f32,
) -> Result<BakedTextures, BakeError> {
    use std::sync::{Arc, Mutex};
    static MEMO: Mutex<Vec<(String, Arc<BakedTextures>)>> = Mutex::new(Vec::new());
    // The request's types serialize to JSON without fail (no map with other than string keys); were
    // one to fail, the textures are baked without the memo.
    let Some(key) = memo_key(request, &metal_parts, threshold) else { return bake(request, metal_parts, threshold) };
    let found = {
        let memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
        memo.iter().find(|(k, _)| *k == key).map(|(_, v)| Arc::clone(v))
    };
    if let Some(baked) = found {
        return Ok((*baked).clone());
    }
    let baked = bake(request, metal_parts, threshold)?;
    let mut memo = MEMO.lock().unwrap_or_else(|e| e.into_inner());
    if !memo.iter().any(|(k, _)| *k == key) {
        if memo.len() == MEMO_ENTRIES {
            memo.remove(0);
        }
        memo.push((key, Arc::new(baked.clone())));
    }
    Ok(baked)
}

/// Bakes `request` and encodes every texture level as PNG, with the extension's record.
pub(crate) fn bake(
    request: &TextureRequest,
    metal_parts: Vec<u32>,
    threshold: f32,
) -> Result<BakedTextures, BakeError> {
    let internal = |message: String| BakeError::Internal { stage: "textures", message };
    let mut record = TexturesRecord::default();
    let mut images: Vec<TextureImage> = Vec::new();
    let mut reports = Vec::new();
    for texture in bake_textures(request) {
        let pngs = encode_png_levels(&texture).map_err(|e| internal(e.to_string()))?;
        let first = images.len() as u32;
        let sampler = sampler_of(&texture);
        for (level, png) in pngs.into_iter().enumerate() {
            let name = if level == 0 { texture.name.clone() } else { format!("{}_mip{level}", texture.name) };
            let (width, height) = texture.level_size(level);
            reports.push(TextureReport {
                name: name.clone(),
                width,
                height: height * texture.layers,
                bytes: png.len(),
            });
            images.push(TextureImage { name, png, sampler });
        }
        let levels = images.len() as u32 - first;
        match &texture.kind {
            TextureKind::MetalBands | TextureKind::MetalHighlights { .. } => {
                let metal = record.metal.get_or_insert_with(|| MetalTexture {
                    bands: TextureRef { index: u32::MAX },
                    highlights: TextureRef { index: u32::MAX },
                    highlight_mapping: Default::default(),
                    parts: metal_parts.clone(),
                    metallic_threshold: shortest(threshold),
                });
                if let TextureKind::MetalHighlights { mapping } = &texture.kind {
                    metal.highlights.index = first;
                    metal.highlight_mapping = *mapping;
                } else {
                    metal.bands.index = first;
                }
            }
            TextureKind::CoolToWarm { mapping, encoding, light_in_eye, splash_back } => {
                record.cool_to_warm.push(CoolToWarmTexture {
                    index: first,
                    mapping: *mapping,
                    encoding: *encoding,
                    light_in_eye: light_in_eye.map(shortest),
                    splash_back: *splash_back,
                });
            }
            TextureKind::Hatching { contrast } => {
                record.hatching = Some(HatchingTexture {
                    levels: (first..first + levels).map(|index| TextureRef { index }).collect(),
                    contrast: shortest(*contrast),
                });
            }
            TextureKind::GammaAtlas { curves } => {
                record.gradient = Some(GradientTexture { index: first, curves: curves.clone() });
            }
            TextureKind::CelAtlas { tables } => {
                record.cel = Some(CelTexture {
                    index: first,
                    tables: tables
                        .iter()
                        .map(|t| CelTableRecord {
                            steps: t.steps,
                            specular: t.specular,
                            min_level: shortest(t.min_level),
                            specular_threshold: shortest(t.specular_threshold),
                            diffuse_max: shortest(t.diffuse_max),
                        })
                        .collect(),
                });
            }
            TextureKind::HatchingToneLayers { .. } | TextureKind::Picture => {
                return Err(internal(format!("unexpected texture {} from bake_textures", texture.name)));
            }
        }
    }
    if record.metal.as_ref().is_some_and(|m| m.bands.index == u32::MAX || m.highlights.index == u32::MAX) {
        return Err(internal("metal bands without highlights".into()));
    }
    let total_bytes = reports.iter().map(|r| r.bytes).sum();
    let metal_parts = record.metal.as_ref().map(|m| m.parts.clone()).unwrap_or_default();
    Ok(BakedTextures {
        embedded: EmbeddedTextures { record, images },
        summary: TexturesSummary { images: reports, total_bytes, metal_parts },
    })
}

fn sampler_of(texture: &Texture) -> SamplerDesc {
    let s = texture.sampler;
    SamplerDesc {
        repeat_u: s.wrap_u == Wrap::Repeat,
        repeat_v: s.wrap_v == Wrap::Repeat,
        linear: s.filter == drafter_textures::Filter::Linear,
        mipmaps: s.mipmaps,
    }
}

/// The f64 with the shortest decimal form that reads back as `x` (0.8f32 → 0.8, not
/// 0.800000011920929), so the record shows the configured values.
fn shortest(x: f32) -> f64 {
    x.to_string().parse().unwrap_or(f64::from(x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::gradient::TransferCurve;
    use drafter_format::{BoxRecord, GradientRecord, ProjectorRecord};
    use drafter_textures::HatchingOptions;

    fn record(id: u32, transfer: TransferCurve, style: Option<PartStyle>) -> PartRecord {
        PartRecord {
            id,
            name: format!("p{id}"),
            triangles: 1,
            obb: BoxRecord {
                center: [0.0; 3],
                axes: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                half_extents: [1.0; 3],
                volume: 8.0,
                method: drafter_core::ObbMethod::Aabb,
            },
            projector: ProjectorRecord { anchor: [0.0; 3], direction: [1.0, 0.0, 0.0], scale: 1.0, matrix: [0.0; 16] },
            gradient: GradientRecord { q: 10.0, f: 0.5, p: 1.0, transfer },
            style,
            flat: None,
        }
    }

    fn stage(styles: &[PartStyle]) -> TexturesStage {
        TexturesStage { styles: styles.to_vec(), ..TexturesStage::default() }
    }

    #[test]
    fn the_memo_key_is_the_same_for_the_same_arguments_and_follows_every_option() {
        let request = request(&[record(0, TransferCurve::Smoothstep, None)], &[0], &stage(&[PartStyle::Gradient]));
        let key = memo_key(&request, &[0], 0.5).expect("serializes");
        assert!(key.contains(MEMO_FORM), "{key}");
        assert_eq!(memo_key(&request.clone(), &[0], 0.5).as_ref(), Some(&key), "deterministic");
        let mut other = request.clone();
        other.metal.as_mut().expect("a metal part asks for the metal textures").seed += 1;
        assert_ne!(memo_key(&other, &[0], 0.5).as_ref(), Some(&key), "an option");
        assert_ne!(memo_key(&request, &[1], 0.5).as_ref(), Some(&key), "the metal parts");
        assert_ne!(memo_key(&request, &[0], 0.25).as_ref(), Some(&key), "the threshold");
        assert_ne!(
            memo_key(&request, &[0], f32::NAN),
            memo_key(&request, &[0], f32::INFINITY),
            "non-finite thresholds"
        );
    }

    #[test]
    fn the_request_follows_styles_hints_and_metal_parts() {
        let records = [
            record(0, TransferCurve::Smoothstep, None),
            record(1, TransferCurve::Identity, Some(PartStyle::Hatch)),
            record(2, TransferCurve::Smoothstep, None),
        ];
        // Scene styles only phong; one part hinted hatch: the halftone only.
        let r = request(&records, &[], &stage(&[PartStyle::Phong]));
        assert_eq!(r.hatching, Some(HatchingOptions::default()));
        assert!(r.metal.is_none() && r.cool_to_warm.is_empty() && r.gamma_curves.is_empty() && r.cel_tables.is_empty());
        // Gradient: the curves of all parts (one atlas row per distinct curve), part order.
        let r = request(&records, &[], &stage(&[PartStyle::Gradient]));
        assert_eq!(r.distinct_gamma_curves(), [TransferCurve::Smoothstep, TransferCurve::Identity]);
        // Goochel reads the cel table and the cool-to-warm map; a metal part brings the metal textures.
        let r = request(&records, &[2], &stage(&[PartStyle::Goochel]));
        assert_eq!(r.cel_tables.len(), 1);
        assert_eq!(r.cool_to_warm.len(), 1);
        assert!(r.metal.is_some());
        // Off: nothing, whatever the parts say.
        let off = TexturesStage { enabled: false, ..stage(&[PartStyle::Gradient, PartStyle::Metal]) };
        assert!(request(&records, &[2], &off).is_empty());
    }

    #[test]
    fn baked_record_points_at_each_image_once_in_order() {
        let records = [record(0, TransferCurve::EaseIn, Some(PartStyle::Metal))];
        let r = request(&records, &[0], &TexturesStage::default());
        let baked = bake(&r, vec![0], 0.5).expect("bakes");
        let record = &baked.embedded.record;
        let mut indices = record.indices();
        indices.sort_unstable();
        assert_eq!(indices, (0..baked.embedded.images.len() as u32).collect::<Vec<_>>());
        let name = |i: u32| baked.embedded.images[i as usize].name.as_str();
        assert_eq!(name(record.gradient.as_ref().expect("gradient").index), "gamma_atlas");
        assert_eq!(record.gradient.as_ref().expect("gradient").curves, [TransferCurve::EaseIn]);
        let hatching = record.hatching.as_ref().expect("hatching");
        let levels: Vec<&str> = hatching.levels.iter().map(|l| name(l.index)).collect();
        assert_eq!(levels, ["hatching", "hatching_mip1", "hatching_mip2", "hatching_mip3"]);
        assert_eq!(hatching.contrast, 4.0);
        let metal = record.metal.as_ref().expect("metal");
        assert_eq!((name(metal.bands.index), name(metal.highlights.index)), ("metal_bands", "metal_highlights"));
        assert_eq!((metal.parts.as_slice(), metal.metallic_threshold), (&[0][..], 0.5));
        assert_eq!(record.cel.as_ref().expect("cel").tables[0].diffuse_max, 0.8);
        // Level sizes halve; the report's total is the sum of the PNGs.
        let sizes: Vec<u32> =
            baked.summary.images.iter().filter(|i| i.name.starts_with("hatching")).map(|i| i.width).collect();
        assert_eq!(sizes, [128, 64, 32, 16]);
        let total: usize = baked.embedded.images.iter().map(|i| i.png.len()).sum();
        assert_eq!(baked.summary.total_bytes, total);
        assert!(baked.embedded.images.iter().all(|i| i.png.starts_with(b"\x89PNG")));
        // Hatching is sampled with mipmaps and repeat, the tables clamped.
        let hatch = &baked.embedded.images[hatching.levels[0].index as usize].sampler;
        assert!(hatch.mipmaps && hatch.repeat_u && hatch.repeat_v);
        let gamma = &baked.embedded.images[record.gradient.as_ref().expect("gradient").index as usize].sampler;
        assert!(!gamma.mipmaps && !gamma.repeat_u && gamma.linear);
    }
}
