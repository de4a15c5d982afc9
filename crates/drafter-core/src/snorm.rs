//! Unit vectors as glTF's normalized signed integers (`normalized: true`): SHORT for
//! `EXT_mesh_primitive_edge_visibility`'s `silhouetteNormals`, BYTE for our compact
//! `_ENHANCED_NORMAL`. One definition for the writer (drafter-lines, drafter-format) and every
//! reader, so the decoded values are bit-identical wherever they are computed.
//!
//! Why SHORT for silhouettes: with BYTE normals 3–15 % of the silhouette edges of a view change
//! (the dragon 8 %, fandisk 15 %, its worst view all of them), with SHORT 0.01–0.16 %, measured by
//! drafter-lines' `examples/normal_precision.rs` (docs/bench.md). Shading normals have no such
//! threshold: 8 bits per axis (within 0.4°) is what gltfpack gives `NORMAL` too.

use glam::Vec3;

/// `round(m·x)` per component, `x` clamped to [−1, 1]; a non-finite component encodes 0.
fn encode(n: Vec3, m: f32) -> [f32; 3] {
    let q = |x: f32| if x.is_finite() { (x.clamp(-1.0, 1.0) * m).round() } else { 0.0 };
    [q(n.x), q(n.y), q(n.z)]
}

/// A unit vector as normalized signed bytes.
pub fn snorm8_encode(n: Vec3) -> [i8; 3] {
    encode(n, 127.0).map(|c| c as i8)
}

/// What a glTF reader decodes from normalized signed bytes: `max(c / 127, −1)` per component
/// (glTF 2.0 §3.11). Not renormalised.
pub fn snorm8_decode(c: [i8; 3]) -> Vec3 {
    let f = |c: i8| (f32::from(c) / 127.0).max(-1.0);
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

/// A unit vector as normalized signed shorts.
pub fn snorm16_encode(n: Vec3) -> [i16; 3] {
    encode(n, 32767.0).map(|c| c as i16)
}

/// What a glTF reader decodes from normalized signed shorts: `max(c / 32767, −1)` per component.
/// Not renormalised: the silhouette predicates only compare signs.
pub fn snorm16_decode(c: [i16; 3]) -> Vec3 {
    let f = |c: i16| (f32::from(c) / 32767.0).max(-1.0);
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worst_error_deg(round_trip: impl Fn(Vec3) -> Vec3) -> f32 {
        let mut s = 3u64;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        };
        let mut worst = 0.0f32;
        for k in 0..20000 {
            let n = match k {
                0 => Vec3::X,
                1 => Vec3::NEG_Z,
                2 => Vec3::new(-1.0, 0.0, -1.0).normalize(),
                _ => Vec3::new(r(), r(), r()).normalize(),
            };
            // In f64: an f32 dot product near 1 cannot resolve angles below ~0.02°.
            let back = round_trip(n).as_dvec3().normalize();
            worst = worst.max(n.as_dvec3().normalize().dot(back).clamp(-1.0, 1.0).acos().to_degrees() as f32);
        }
        worst
    }

    #[test]
    fn round_trips_and_conventions() {
        assert!(worst_error_deg(|n| snorm8_decode(snorm8_encode(n))) < 0.5);
        assert!(worst_error_deg(|n| snorm16_decode(snorm16_encode(n))) < 0.002);
        // Decoding then encoding again gives the same integers (a reader that rewrites keeps them).
        for n in [Vec3::new(0.3, -0.9, 0.1).normalize(), Vec3::new(-1.0, 0.0, 1e-7)] {
            assert_eq!(snorm8_encode(snorm8_decode(snorm8_encode(n))), snorm8_encode(n));
            assert_eq!(snorm16_encode(snorm16_decode(snorm16_encode(n))), snorm16_encode(n));
        }
        assert_eq!(snorm8_encode(Vec3::Z), [0, 0, 127]);
        assert_eq!(snorm8_encode(Vec3::NEG_X), [-127, 0, 0]);
        assert_eq!(snorm8_encode(Vec3::new(f32::NAN, 1.0, 0.0)), [0, 127, 0]);
        assert_eq!(snorm8_decode([-128, 0, 127]), Vec3::new(-1.0, 0.0, 1.0));
        assert_eq!(snorm16_encode(Vec3::new(1.0, -1.0, 0.0)), [32767, -32767, 0]);
        assert_eq!(snorm16_decode([i16::MIN, 0, 32767]), Vec3::new(-1.0, 0.0, 1.0));
    }
}
