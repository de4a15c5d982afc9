//! Environment maps indexed by a unit normal (Gooch et al. 1999, §5.2, Fig. 10: "all normals in
//! eye-space are mapped to a 2D texture"; ../shared/papers/001_*).
//!
//! Two parameterisations, both with glTF's `v` pointing down the image (row 0 at the top) and both
//! indexed by the **eye-space** normal (x right, y up, z towards the viewer):
//!
//! * [`EnvMapping::Octahedral`] (the default): the whole sphere. With `s = |n.x| + |n.y| + |n.z|` and
//!   `p = n.xy / s`; for `n.z < 0` fold: `p = (1 − |p.y|, 1 − |p.x|) · sign(p)` (sign(0) = +1); then
//!   `uv = (0.5 + 0.5·p.x, 0.5 − 0.5·p.y)`. The front hemisphere is the central diamond. WGSL:
//!   ```text
//!   fn oct_uv(n: vec3f) -> vec2f {
//!       var p = n.xy / (abs(n.x) + abs(n.y) + abs(n.z));
//!       if (n.z < 0.0) { p = (1.0 - abs(p.yx)) * select(vec2f(-1.0), vec2f(1.0), p >= vec2f(0.0)); }
//!       return vec2f(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y);
//!   }
//!   ```
//!   Normals that face slightly away from the eye (perspective, interpolated normals) stay valid.
//! * [`EnvMapping::NormalSphere`]: the picture of a lit sphere seen along −z (a "matcap", exactly
//!   Fig. 10's images): `uv = (0.5 + 0.5·n.x, 0.5 − 0.5·n.y)`. Only the front hemisphere is stored; a
//!   normal with `n.z < 0` reads its mirror image in `z`. Texels outside the disc hold the rim value
//!   (`n = (p/|p|, 0)`) so bilinear filtering at the silhouette does not blend in background.
//!
//! Sample both with linear filtering and clamp-to-edge. A texel's value is the shading function
//! evaluated at the normal of its centre.

//!
//! These mapping and encoding names live here, in the shared core, because three crates read them:
//! drafter-textures bakes the maps, drafter-format names them in the file, drafter-scene and the
//! renderer sample them.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};

/// How a unit normal becomes a texture coordinate (formulas in the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum EnvMapping {
    /// Octahedral map of the whole sphere.
    #[default]
    Octahedral,
    /// Orthographic image of the front hemisphere (a matcap, as Gooch et al.'s Fig. 10).
    NormalSphere,
}

fn sign_not_zero(x: f32) -> f32 {
    if x >= 0.0 { 1.0 } else { -1.0 }
}

impl EnvMapping {
    /// The texture coordinate of a unit normal (`n` need not be normalised; zero → the centre).
    pub fn uv_from_normal(self, n: Vec3) -> Vec2 {
        match self {
            EnvMapping::Octahedral => {
                let s = n.x.abs() + n.y.abs() + n.z.abs();
                if s <= 0.0 || !s.is_finite() {
                    return Vec2::splat(0.5);
                }
                let mut p = Vec2::new(n.x, n.y) / s;
                if n.z < 0.0 {
                    p = Vec2::new((1.0 - p.y.abs()) * sign_not_zero(p.x), (1.0 - p.x.abs()) * sign_not_zero(p.y));
                }
                Vec2::new(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y)
            }
            EnvMapping::NormalSphere => {
                let n = n.normalize_or_zero();
                Vec2::new(0.5 + 0.5 * n.x, 0.5 - 0.5 * n.y)
            }
        }
    }

    /// The unit normal a texture coordinate stands for (the inverse of [`Self::uv_from_normal`] on the
    /// represented set; coordinates outside `[0, 1]²` are clamped).
    pub fn normal_from_uv(self, uv: Vec2) -> Vec3 {
        let uv = uv.clamp(Vec2::ZERO, Vec2::ONE);
        let p = Vec2::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y);
        match self {
            EnvMapping::Octahedral => {
                let mut n = Vec3::new(p.x, p.y, 1.0 - p.x.abs() - p.y.abs());
                if n.z < 0.0 {
                    let (x, y) = (n.x, n.y);
                    n.x = (1.0 - y.abs()) * sign_not_zero(x);
                    n.y = (1.0 - x.abs()) * sign_not_zero(y);
                }
                n.normalize()
            }
            EnvMapping::NormalSphere => {
                let r2 = p.length_squared();
                if r2 <= 1.0 { Vec3::new(p.x, p.y, (1.0 - r2).sqrt()) } else { (p / r2.sqrt()).extend(0.0) }
            }
        }
    }
}

/// What the channels of a cool-to-warm map hold (drafter-textures' `cool_warm` module bakes both).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoolToWarmEncoding {
    /// RGB = the shaded colour for one object colour; A = 1.
    Colour,
    /// RGB = colour-independent base, A = object-colour weight: `I = clamp(rgb + a·k_d)`.
    Factored,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn octahedral_round_trips_the_whole_sphere() {
        let mut rng = Rng::new(12);
        for _ in 0..10_000 {
            let n = rng.direction_f32();
            let uv = EnvMapping::Octahedral.uv_from_normal(n);
            assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y), "{uv}");
            let back = EnvMapping::Octahedral.normal_from_uv(uv);
            assert!(back.dot(n) > 1.0 - 1e-5, "{n} → {uv} → {back}");
        }
        // Orientation: +y is up (small v), +x is right, +z the centre.
        assert_eq!(EnvMapping::Octahedral.uv_from_normal(Vec3::Z), Vec2::splat(0.5));
        assert_eq!(EnvMapping::Octahedral.uv_from_normal(Vec3::Y), Vec2::new(0.5, 0.0));
        assert_eq!(EnvMapping::Octahedral.uv_from_normal(Vec3::X), Vec2::new(1.0, 0.5));
    }

    #[test]
    fn normal_sphere_round_trips_the_front_hemisphere() {
        let mut rng = Rng::new(34);
        for _ in 0..10_000 {
            let mut n = rng.direction_f32();
            n.z = n.z.abs();
            let back = EnvMapping::NormalSphere.normal_from_uv(EnvMapping::NormalSphere.uv_from_normal(n));
            assert!(back.dot(n) > 1.0 - 1e-4, "{n} → {back}");
        }
        // Outside the disc: the rim.
        let rim = EnvMapping::NormalSphere.normal_from_uv(Vec2::new(0.0, 0.0));
        assert!(rim.z == 0.0 && (rim.length() - 1.0).abs() < 1e-6);
    }
}
