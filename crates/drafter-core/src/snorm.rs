//! Unit vectors as glTF's normalized signed bytes (`BYTE`, `normalized: true`): the encoding of
//! `EXT_mesh_primitive_edge_visibility`'s `silhouetteNormals` and of our compact `_ENHANCED_NORMAL`.
//! One definition for the writer (drafter-lines, drafter-format) and every reader, so the decoded
//! values are bit-identical wherever they are computed.

use glam::Vec3;

/// `round(127·x)` per component, `x` clamped to [−1, 1]; a non-finite component encodes 0.
pub fn snorm8_encode(n: Vec3) -> [i8; 3] {
    let q = |x: f32| if x.is_finite() { (x.clamp(-1.0, 1.0) * 127.0).round() as i8 } else { 0 };
    [q(n.x), q(n.y), q(n.z)]
}

/// What a glTF reader decodes from normalized signed bytes: `max(c / 127, −1)` per component
/// (glTF 2.0 §3.11). Not renormalised: the silhouette predicates only compare signs.
pub fn snorm8_decode(c: [i8; 3]) -> Vec3 {
    let f = |c: i8| (f32::from(c) / 127.0).max(-1.0);
    Vec3::new(f(c[0]), f(c[1]), f(c[2]))
}

/// Normalized signed shorts decoded as glTF defines them, `max(c / 32767, −1)`, then re-encoded as
/// bytes: how a `silhouetteNormals` accessor of another writer in SHORT is brought to ours.
pub fn snorm16_to_snorm8(c: [i16; 3]) -> [i8; 3] {
    let f = |c: i16| (f32::from(c) / 32767.0).max(-1.0);
    snorm8_encode(Vec3::new(f(c[0]), f(c[1]), f(c[2])))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_within_half_a_degree_and_conventions() {
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
            let c = snorm8_encode(n);
            let back = snorm8_decode(c);
            // Decoding then encoding again gives the same bytes (a reader that rewrites keeps them).
            assert_eq!(snorm8_encode(back), c);
            worst = worst.max(n.dot(back.normalize()).clamp(-1.0, 1.0).acos().to_degrees());
        }
        assert!(worst < 0.5, "worst snorm8 error {worst}°");
        assert_eq!(snorm8_encode(Vec3::Z), [0, 0, 127]);
        assert_eq!(snorm8_encode(Vec3::NEG_X), [-127, 0, 0]);
        assert_eq!(snorm8_encode(Vec3::new(f32::NAN, 1.0, 0.0)), [0, 127, 0]);
        assert_eq!(snorm8_decode([-128, 0, 127]), Vec3::new(-1.0, 0.0, 1.0));
        assert_eq!(snorm16_to_snorm8([32767, -32767, 0]), [127, -127, 0]);
    }
}
