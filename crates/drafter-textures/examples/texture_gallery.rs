//! Bakes every texture drafter-textures makes and writes them, with sphere previews, as PNG files.
//!
//! ```text
//! cargo run -p drafter-textures --example texture_gallery -- docs/textures
//! ```
//! Files: `<name>.png` (level 0 of each texture; `hatching_mip<m>.png` for its other levels),
//! `<name>_preview.png` (the lookup applied to a sphere), `metal_preview.png` (bands + highlights on a
//! sphere and a cylinder), `hatching_levels_preview.png` (every mip level at native size).

use std::path::PathBuf;

use drafter_core::gradient::TransferCurve;
use drafter_textures::preview::{preview, preview_hatching_levels, preview_metal};
use drafter_textures::{
    CelOptions, CoolToWarmOptions, EnvMapping, HatchingOptions, MetalOptions, Texture, TextureRequest, bake_textures,
    hatching_tone_layers, write_png,
};

/// Edge of the preview images.
const PREVIEW_SIZE: u32 = 128;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "docs/textures".into()));
    std::fs::create_dir_all(&dir)?;
    let request = TextureRequest {
        metal: Some(MetalOptions::default()),
        cool_to_warm: vec![
            // Fig. 10(a): Gooch cool-to-warm, factored (one map for every object colour).
            CoolToWarmOptions { size: 64, ..Default::default() },
            // Fig. 10(b): with splash-back.
            CoolToWarmOptions { size: 64, splash_back: true, ..Default::default() },
            // One object colour baked in, as the matcap parameterisation (looks like Fig. 10 itself).
            CoolToWarmOptions {
                size: 64,
                splash_back: true,
                object_colour: Some([0.8, 0.25, 0.15]),
                mapping: EnvMapping::NormalSphere,
                ..Default::default()
            },
        ],
        hatching: Some(HatchingOptions::default()),
        gamma_curves: TransferCurve::ALL.to_vec(),
        cel_tables: vec![
            CelOptions { steps: 2, ..Default::default() },
            CelOptions { steps: 3, ..Default::default() },
            CelOptions { steps: 4, ..Default::default() },
            CelOptions { steps: 3, specular: true, ..Default::default() },
        ],
    };
    request.validate()?;
    let textures = bake_textures(&request);

    let mut written: Vec<(PathBuf, u64)> = Vec::new();
    let mut write = |t: &Texture, level: usize, file: String| -> Result<(), Box<dyn std::error::Error>> {
        let path = dir.join(file);
        write_png(t, level, &path)?;
        written.push((path.clone(), std::fs::metadata(&path)?.len()));
        Ok(())
    };

    for t in &textures {
        write(t, 0, format!("{}.png", t.name))?;
        for m in 1..t.mip_levels.len() {
            write(t, m, format!("{}_mip{m}.png", t.name))?;
        }
        let p = preview(t, PREVIEW_SIZE);
        write(&p, 0, format!("{}.png", p.name))?;
    }
    let find = |name: &str| textures.iter().find(|t| t.name == name);
    if let (Some(bands), Some(highlights)) = (find("metal_bands"), find("metal_highlights")) {
        let p = preview_metal(bands, highlights, PREVIEW_SIZE);
        write(&p, 0, format!("{}.png", p.name))?;
    }
    if let Some(halftone) = find("hatching") {
        let p = preview_hatching_levels(halftone, 0.55);
        write(&p, 0, format!("{}.png", p.name))?;
        let c = HatchingOptions::default().contrast;
        if let Some(layers) = hatching_tone_layers(halftone, &[0.9, 0.75, 0.6, 0.45, 0.3, 0.15], c) {
            let p = preview(&layers, PREVIEW_SIZE / 2);
            write(&p, 0, format!("{}.png", p.name))?;
        }
    }

    let total: u64 = written.iter().map(|(_, n)| n).sum();
    for (path, n) in &written {
        println!("{n:>8}  {}", path.display());
    }
    println!("{total:>8}  bytes in {} files", written.len());
    Ok(())
}
