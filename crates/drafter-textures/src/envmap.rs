//! Baking environment maps indexed by a unit normal; the two parameterisations and their formulas
//! are [`drafter_core::env_map`]'s (Gooch et al. 1999, §5.2, Fig. 10; ../shared/papers/001_*).
//!
//! Sample both with linear filtering and clamp-to-edge. A texel's value is the shading function
//! evaluated at the normal of its centre.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

pub use drafter_core::env_map::EnvMapping;

/// Bakes a `size × size` map: `channels` bytes per texel, from `shade(normal) → values in [0, 1]`
/// (only the first `channels` values are used). Rows are computed in parallel; each texel depends
/// only on its own normal, so the result does not depend on the thread count.
pub(crate) fn bake_env_map(
    size: u32,
    mapping: EnvMapping,
    channels: usize,
    shade: impl Fn(Vec3) -> [f32; 4] + Sync,
) -> Vec<u8> {
    let size = size as usize;
    let mut data = vec![0u8; size * size * channels];
    data.par_chunks_mut(size * channels).enumerate().for_each(|(y, row)| {
        for (x, texel) in row.chunks_mut(channels).enumerate() {
            let uv = Vec2::new((x as f32 + 0.5) / size as f32, (y as f32 + 0.5) / size as f32);
            let values = shade(mapping.normal_from_uv(uv));
            for (b, v) in texel.iter_mut().zip(values) {
                *b = crate::texture::unorm8(v);
            }
        }
    });
    data
}
