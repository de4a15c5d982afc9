//! CPU previews: each lookup applied to a sphere (or a cylinder, for the metal bands) the way a
//! shader would apply it, for the README and for eyeballing a bake. Orthographic view along −z,
//! eye space = object space, 3×3 supersampling, white paper background, `Rgba8` (opaque).
//!
//! Preview lighting: the light [`PREVIEW_LIGHT_IN_EYE`] (up and to the right: the default of the
//! cool-to-warm maps) and, for the factored cool-to-warm maps, object colour [`PREVIEW_OBJECT_COLOUR`].

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use drafter_core::gradient::GradientParams;

use crate::cel::CEL_TABLE_LEN;
use crate::cool_warm::CoolToWarmEncoding;
use crate::hatching::hatching_ink;
use crate::texture::{SamplerHint, Texture, TextureFormat, TextureKind, unorm8};

/// The light of the previews (normalised before use): the cool-to-warm default.
pub const PREVIEW_LIGHT_IN_EYE: [f32; 3] = crate::cool_warm::DEFAULT_LIGHT_IN_EYE;
/// The object colour applied to factored cool-to-warm maps in previews.
pub const PREVIEW_OBJECT_COLOUR: [f32; 3] = [0.45, 0.45, 0.45];
/// The base colour of metal in previews.
pub const PREVIEW_METAL_COLOUR: [f32; 3] = [0.85, 0.87, 0.9];
/// Background (paper) of the previews.
pub const PREVIEW_BACKGROUND: [f32; 3] = [1.0, 1.0, 1.0];

/// A shape drawn in each preview cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PreviewShape {
    /// A sphere filling 92 % of the cell.
    Sphere,
    /// A vertical cylinder (axis `y`), 70 % of the cell wide and 85 % high, no caps.
    Cylinder,
}

/// One visible surface point of a preview.
#[derive(Clone, Copy, Debug)]
pub struct PreviewPoint {
    /// Which cell (left to right).
    pub cell: usize,
    /// Unit normal, eye space (= object space).
    pub normal_in_eye: Vec3,
    /// The point in the cell's object coordinates (the shape spans [−1, 1] in x and y).
    pub position: Vec3,
    /// Pixel coordinates in the whole image (x right, y down, fractional: the sub-sample).
    pub pixel: Vec2,
}

fn hit(shape: PreviewShape, p: Vec2) -> Option<(Vec3, Vec3)> {
    match shape {
        PreviewShape::Sphere => {
            let r = 0.92;
            let q = p / r;
            let d = q.length_squared();
            (d <= 1.0).then(|| {
                let n = Vec3::new(q.x, q.y, (1.0 - d).sqrt());
                (n, n * r)
            })
        }
        PreviewShape::Cylinder => {
            let (r, h) = (0.7, 0.85);
            (p.x.abs() <= r && p.y.abs() <= h).then(|| {
                let x = p.x / r;
                let n = Vec3::new(x, 0.0, (1.0 - x * x).max(0.0).sqrt());
                (n, Vec3::new(p.x, p.y, n.z * r))
            })
        }
    }
}

/// Renders `cells` square cells of `cell_size` pixels side by side, each with `shape`, colour from
/// `shade` (RGB in [0, 1]) averaged over 3×3 sub-samples. Named `name`.
pub fn render_cells(
    name: &str,
    cell_size: u32,
    cells: usize,
    shape: PreviewShape,
    shade: impl Fn(&PreviewPoint) -> Vec3 + Sync,
) -> Texture {
    let (cs, cells) = (cell_size.max(1) as usize, cells.max(1));
    let width = cs * cells;
    let mut data = vec![0u8; width * cs * 4];
    data.par_chunks_mut(width * 4).enumerate().for_each(|(y, row)| {
        for (x, px) in row.chunks_mut(4).enumerate() {
            let cell = x / cs;
            let mut sum = Vec3::ZERO;
            for sy in 0..3 {
                for sx in 0..3 {
                    let pixel = Vec2::new(x as f32 + (sx as f32 + 0.5) / 3.0, y as f32 + (sy as f32 + 0.5) / 3.0);
                    let local = Vec2::new(
                        2.0 * (pixel.x - (cell * cs) as f32) / cs as f32 - 1.0,
                        1.0 - 2.0 * pixel.y / cs as f32,
                    );
                    sum += match hit(shape, local) {
                        Some((normal_in_eye, position)) => {
                            shade(&PreviewPoint { cell, normal_in_eye, position, pixel })
                        }
                        None => Vec3::from_array(PREVIEW_BACKGROUND),
                    };
                }
            }
            let c = sum / 9.0;
            px.copy_from_slice(&[unorm8(c.x), unorm8(c.y), unorm8(c.z), 255]);
        }
    });
    Texture {
        name: name.into(),
        kind: TextureKind::Picture,
        width: width as u32,
        height: cs as u32,
        layers: 1,
        format: TextureFormat::Rgba8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

fn light() -> Vec3 {
    Vec3::from_array(PREVIEW_LIGHT_IN_EYE).normalize()
}

/// The preview of one baked texture (named `<name>_preview`): a sphere (a row of spheres for the
/// atlases, a cylinder for the metal bands, a strip of tiles for the tone layers), `cell_size`
/// pixels high. A [`TextureKind::Picture`] is returned as it is (renamed).
pub fn preview(texture: &Texture, cell_size: u32) -> Texture {
    let name = format!("{}_preview", texture.name);
    let grey = |v: f32| Vec3::splat(v);
    match &texture.kind {
        TextureKind::Picture => Texture { name, ..texture.clone() },
        TextureKind::MetalBands => render_cells(&name, cell_size, 1, PreviewShape::Cylinder, |p| {
            let u = (1.0 + p.normal_in_eye.x) / 2.0;
            Vec3::from_array(PREVIEW_METAL_COLOUR) * texture.sample(0, 0, Vec2::new(u, 0.5)).x
        }),
        TextureKind::MetalHighlights { mapping } => render_cells(&name, cell_size, 1, PreviewShape::Sphere, |p| {
            grey(0.2 + texture.sample(0, 0, mapping.uv_from_normal(p.normal_in_eye)).x)
        }),
        TextureKind::CoolToWarm { mapping, encoding, .. } => {
            render_cells(&name, cell_size, 1, PreviewShape::Sphere, |p| {
                let t = texture.sample(0, 0, mapping.uv_from_normal(p.normal_in_eye));
                match encoding {
                    CoolToWarmEncoding::Colour => t.truncate(),
                    CoolToWarmEncoding::Factored => {
                        (t.truncate() + t.w * Vec3::from_array(PREVIEW_OBJECT_COLOUR)).clamp(Vec3::ZERO, Vec3::ONE)
                    }
                }
            })
        }
        TextureKind::Hatching { contrast } => render_cells(&name, cell_size, 1, PreviewShape::Sphere, |p| {
            // Screen-space hatching at 1:1 (level 0), diffuse intensity with a little ambient.
            let i = 0.15 + 0.85 * p.normal_in_eye.dot(light()).max(0.0);
            let uv = p.pixel / texture.width as f32;
            grey(1.0 - hatching_ink(texture.sample(0, 0, uv).x, i, *contrast))
        }),
        TextureKind::HatchingToneLayers { tones } => {
            // A strip of the layers, a `cell_size` square crop of each (no shape): copy the texels.
            let mut out = render_cells(&name, cell_size, tones.len(), PreviewShape::Sphere, |_| Vec3::ZERO);
            let (cs, w) = (cell_size.max(1), cell_size.max(1) as usize * tones.len());
            for (k, px) in out.mip_levels[0].chunks_mut(4).enumerate() {
                let (x, y) = ((k % w) as u32, (k / w) as u32);
                let v = unorm8(texture.texel(0, x / cs, (x % cs) % texture.width, y % texture.height, 0));
                px.copy_from_slice(&[v, v, v, 255]);
            }
            out
        }
        TextureKind::GammaAtlas { curves } => {
            let rows = curves.len().max(1) as f32;
            render_cells(&name, cell_size, curves.len(), PreviewShape::Sphere, |p| {
                // A projector along +y through the sphere: p = (y + 1)/2, then ω(γ(p)) with the
                // default gradient parameters (Lux et al. Fig. 5).
                let pc = (p.position.y / 0.92 + 1.0) / 2.0;
                let uv = Vec2::new((0.5 + 127.0 * pc) / 128.0, (p.cell as f32 + 0.5) / rows);
                let gamma = texture.sample(0, 0, uv).x;
                grey(GradientParams::default().eval(gamma))
            })
        }
        TextureKind::CelAtlas { tables } => {
            let rows = tables.len().max(1) as f32;
            let n = (CEL_TABLE_LEN - 1) as f32;
            render_cells(&name, cell_size, tables.len(), PreviewShape::Sphere, |p| {
                let x = p.normal_in_eye.dot(light()).max(0.0);
                let uv = Vec2::new((0.5 + n * x) / (n + 1.0), (p.cell as f32 + 0.5) / rows);
                let v = texture.sample(0, 0, uv).x;
                let specular = tables.get(p.cell).is_some_and(|t| t.specular);
                if specular && v > 0.9 { Vec3::ONE } else { Vec3::new(0.45, 0.65, 0.95) * v }
            })
        }
    }
}

/// Gooch metal on a sphere and a cylinder side by side: `base · band(u) + highlight(n)` with
/// `u = (1 + n·x̂)/2` (bands stick to the object, axis `y`).
pub fn preview_metal(bands: &Texture, highlights: &Texture, cell_size: u32) -> Texture {
    let mapping = match highlights.kind {
        TextureKind::MetalHighlights { mapping } => mapping,
        _ => crate::envmap::EnvMapping::Octahedral,
    };
    let sphere = render_cells("metal_sphere", cell_size, 1, PreviewShape::Sphere, |p| {
        metal_shade(bands, highlights, mapping, p)
    });
    let cylinder = render_cells("metal_cylinder", cell_size, 1, PreviewShape::Cylinder, |p| {
        metal_shade(bands, highlights, mapping, p)
    });
    side_by_side("metal_preview", &[sphere, cylinder])
}

fn metal_shade(bands: &Texture, highlights: &Texture, mapping: crate::envmap::EnvMapping, p: &PreviewPoint) -> Vec3 {
    let u = (1.0 + p.normal_in_eye.x) / 2.0;
    let band = bands.sample(0, 0, Vec2::new(u, 0.5)).x;
    let spec = highlights.sample(0, 0, mapping.uv_from_normal(p.normal_in_eye)).x;
    (Vec3::from_array(PREVIEW_METAL_COLOUR) * band + Vec3::splat(spec)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// Every stored level of a hatching halftone at its native size, side by side (bottom-aligned),
/// thresholded at intensity `intensity`: the strokes keep their width and spacing in pixels.
pub fn preview_hatching_levels(halftone: &Texture, intensity: f32) -> Texture {
    let contrast = match halftone.kind {
        TextureKind::Hatching { contrast } => contrast,
        _ => crate::hatching::DEFAULT_HATCHING_CONTRAST,
    };
    let gap = 8u32;
    let widths: Vec<u32> = (0..halftone.mip_levels.len()).map(|m| halftone.level_size(m).0).collect();
    let width = widths.iter().sum::<u32>() + gap * widths.len().saturating_sub(1) as u32;
    let height = halftone.height;
    let mut data = vec![255u8; (width * height * 4) as usize];
    let mut x0 = 0;
    for (m, &w) in widths.iter().enumerate() {
        let h = halftone.level_size(m).1;
        for y in 0..h {
            for x in 0..w {
                let v = unorm8(1.0 - hatching_ink(halftone.texel(m, 0, x, y, 0), intensity, contrast));
                let row = height - h + y;
                let i = ((row * width + x0 + x) * 4) as usize;
                data[i..i + 3].copy_from_slice(&[v, v, v]);
            }
        }
        x0 += w + gap;
    }
    Texture {
        name: "hatching_levels_preview".into(),
        kind: halftone.kind.clone(),
        width,
        height,
        layers: 1,
        format: TextureFormat::Rgba8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}

/// Places `Rgba8` images of equal height side by side.
pub fn side_by_side(name: &str, images: &[Texture]) -> Texture {
    let height = images.iter().map(|t| t.height).max().unwrap_or(1);
    let width: u32 = images.iter().map(|t| t.width).sum::<u32>().max(1);
    let mut data = vec![255u8; (width * height * 4) as usize];
    let mut x0 = 0;
    for t in images {
        for y in 0..t.height.min(height) {
            for x in 0..t.width {
                let i = ((y * width + x0 + x) * 4) as usize;
                for c in 0..4 {
                    data[i + c] = unorm8(t.texel(0, 0, x, y, c));
                }
            }
        }
        x0 += t.width;
    }
    Texture {
        name: name.into(),
        kind: TextureKind::Picture,
        width,
        height,
        layers: 1,
        format: TextureFormat::Rgba8,
        sampler: SamplerHint::CLAMPED,
        mip_levels: vec![data],
    }
}
