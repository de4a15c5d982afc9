//! Deterministic PNG encoding.
//!
//! One PNG per mip level: `width_m × (height_m · layers)`, 8-bit greyscale (`R8`) or RGBA (`Rgba8`),
//! layers stacked vertically (layer `k` is rows `k·height_m .. (k+1)·height_m`). Only IHDR, IDAT and
//! IEND chunks are written (no time, text, gamma or sRGB chunks), with fixed settings (zlib level 9,
//! adaptive row filters), so the bytes are a function of the texels alone: identical across runs
//! and thread counts. They are pinned to the `png`/`flate2` versions in `Cargo.lock`; a dependency
//! update may change the compressed bytes (never the decoded texels).

use std::path::Path;

use crate::error::PngError;
use crate::texture::{Texture, TextureFormat};

/// The zlib level every PNG is written with.
pub const PNG_ZLIB_LEVEL: u8 = 9;

/// Encodes mip level `level` of `texture` as PNG bytes (layout in the module docs).
pub fn encode_png(texture: &Texture, level: usize) -> Result<Vec<u8>, PngError> {
    let data = texture.mip_levels.get(level).ok_or_else(|| PngError::NoSuchLevel {
        texture: texture.name.clone(),
        level,
        levels: texture.mip_levels.len(),
    })?;
    texture.check().map_err(|reason| PngError::Malformed { texture: texture.name.clone(), reason })?;
    let (w, h) = texture.level_size(level);
    let mut out = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut out, w, h * texture.layers);
        encoder.set_color(match texture.format {
            TextureFormat::R8 => png::ColorType::Grayscale,
            TextureFormat::Rgba8 => png::ColorType::Rgba,
        });
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_deflate_compression(png::DeflateCompression::Level(PNG_ZLIB_LEVEL));
        encoder.set_filter(png::Filter::Adaptive);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(data)?;
        writer.finish()?;
    }
    Ok(out)
}

/// Encodes every mip level, level 0 first.
pub fn encode_png_levels(texture: &Texture) -> Result<Vec<Vec<u8>>, PngError> {
    (0..texture.mip_levels.len()).map(|m| encode_png(texture, m)).collect()
}

/// Writes mip level `level` of `texture` to `path` as PNG. The only function of this crate that
/// touches the file system (used by the gallery example and by `drafter bake --textures-out`).
pub fn write_png(texture: &Texture, level: usize, path: &Path) -> Result<(), PngError> {
    let bytes = encode_png(texture, level)?;
    std::fs::write(path, bytes).map_err(|source| PngError::Io { path: path.to_path_buf(), source })
}
