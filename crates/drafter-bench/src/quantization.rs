//! What each byte buys: the silhouette normals of one mesh (two per candidate edge, as
//! `EXT_mesh_primitive_edge_visibility` stores them) quantized to 4–16 bits per component and kept
//! as f32, each stored as the file stores them and through meshoptimizer's vertex codec as
//! `--compress` stores them, against what is lost: the angle to the f32 face normal, and the
//! silhouette decisions that change (candidates whose two faces disagree on facing a view, over
//! random orthographic views, compared with the f32 normals' decisions). 8 bits is what drafter
//! ships (`drafter_core::snorm8_encode_direction`: nearest direction on the byte lattice); the
//! other widths round per component. The hierarchies are exact for whatever is stored; this
//! measures how far what is stored is from the geometry.

use std::time::Instant;

use drafter_core::{Topology, snorm8_decode, snorm8_encode_direction};
use drafter_lines::{LineOptions, classify_edges};
use glam::Vec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use drafter_testkit::Rng;

/// Bits per component measured; 32 stands for f32.
pub const QUANTIZATION_BITS: [u32; 7] = [4, 6, 8, 10, 12, 16, 32];
/// The width drafter writes.
pub const SHIPPED_BITS: u32 = 8;
/// Views per measurement (orthographic), at most.
const MAX_VIEWS: usize = 64;

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct QuantizationSweep {
    /// The measured mesh (the one with the most candidates), its candidates, and the views.
    pub mesh: usize,
    pub candidates: usize,
    pub views: usize,
    pub points: Vec<QuantizationPoint>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct QuantizationPoint {
    pub bits: u32,
    /// Bytes as the file stores them (tightly packed VEC3 of the component type), and through
    /// meshoptimizer's vertex codec (stride 12, as `--compress` encodes them).
    pub raw_bytes: usize,
    pub encoded_bytes: usize,
    /// Quantizing and encoding, milliseconds.
    pub encode_ms: f64,
    /// Angle between the f32 face normal and the decoded one, degrees.
    pub mean_error_deg: f64,
    pub max_error_deg: f64,
    /// Candidate-view pairs whose silhouette decision differs from the f32 normals', per million.
    pub disagreement_ppm: f64,
}

/// Measures the mesh with the most silhouette candidates; `None` when no mesh has one.
pub fn sweep_quantization(topologies: &[Topology], views: usize, seed: u64) -> Option<QuantizationSweep> {
    let (mesh, lines) = topologies
        .iter()
        .enumerate()
        .filter(|(_, t)| !t.faces.is_empty())
        .filter_map(|(m, t)| classify_edges(t, None, &LineOptions::default()).ok().map(|l| (m, l)))
        .max_by_key(|(m, l)| (l.candidates.len(), usize::MAX - m))?;
    let normals: Vec<Vec3> = lines.candidate_normals.iter().flatten().copied().collect();
    if normals.is_empty() {
        return None;
    }
    let mut rng = Rng::new(seed);
    let views: Vec<Vec3> = (0..views.clamp(1, MAX_VIEWS)).map(|_| rng.direction().as_vec3()).collect();
    let points = QUANTIZATION_BITS.iter().map(|&bits| measure(&normals, bits, &views)).collect();
    Some(QuantizationSweep { mesh, candidates: normals.len() / 2, views: views.len(), points })
}

/// `n` at `bits` per component, decoded as a glTF reader decodes normalized integers, and the
/// stored bytes.
fn quantize(n: Vec3, bits: u32) -> (Vec3, Vec<u8>) {
    match bits {
        32 => (n, n.to_array().iter().flat_map(|c| c.to_le_bytes()).collect()),
        SHIPPED_BITS => {
            let c = snorm8_encode_direction(n);
            (snorm8_decode(c), c.iter().map(|&x| x as u8).collect())
        }
        _ => {
            let m = ((1u32 << (bits - 1)) - 1) as f32;
            let q = n.to_array().map(|x| if x.is_finite() { (x.clamp(-1.0, 1.0) * m).round() } else { 0.0 });
            let decoded = Vec3::from(q.map(|c| (c / m).max(-1.0)));
            let bytes = if bits <= 8 {
                q.iter().map(|&c| c as i8 as u8).collect()
            } else {
                q.iter().flat_map(|&c| (c as i16).to_le_bytes()).collect()
            };
            (decoded, bytes)
        }
    }
}

fn measure(normals: &[Vec3], bits: u32, views: &[Vec3]) -> QuantizationPoint {
    let start = Instant::now();
    let (decoded, bytes): (Vec<Vec3>, Vec<Vec<u8>>) = normals.par_iter().map(|&n| quantize(n, bits)).unzip();
    let mut raw: Vec<u8> = bytes.concat();
    let raw_bytes = raw.len();
    raw.resize(raw.len().next_multiple_of(12), 0);
    let elements: Vec<[u8; 12]> = raw.chunks_exact(12).map(|c| c.try_into().unwrap_or([0; 12])).collect();
    let encoded_bytes = meshopt::encode_vertex_buffer_level(&elements, 2, Some(0)).map_or(raw_bytes, |e| e.len());
    let encode_ms = start.elapsed().as_secs_f64() * 1e3;

    let angles: Vec<f64> = normals
        .par_iter()
        .zip(&decoded)
        .map(|(&a, &b)| {
            // atan2 of sine and cosine in f64: an f32 acos cannot resolve angles below 0.02°.
            let (a, b) = (a.as_dvec3(), b.as_dvec3());
            if a == glam::DVec3::ZERO || b == glam::DVec3::ZERO {
                0.0
            } else {
                a.cross(b).length().atan2(a.dot(b)).to_degrees()
            }
        })
        .collect();
    let mean_error_deg = angles.iter().sum::<f64>() / angles.len().max(1) as f64;
    let max_error_deg = angles.iter().copied().fold(0.0, f64::max);
    // A candidate is a silhouette from direction d when its faces disagree on facing d.
    let silhouette = |n: &[Vec3], k: usize, d: Vec3| (n[2 * k].dot(d) > 0.0) != (n[2 * k + 1].dot(d) > 0.0);
    let candidates = normals.len() / 2;
    let differ: usize = (0..candidates)
        .into_par_iter()
        .map(|k| views.iter().filter(|&&d| silhouette(normals, k, d) != silhouette(&decoded, k, d)).count())
        .sum();
    let pairs = (candidates * views.len()).max(1) as f64;
    QuantizationPoint {
        bits,
        raw_bytes,
        encoded_bytes,
        encode_ms,
        mean_error_deg,
        max_error_deg,
        disagreement_ppm: differ as f64 / pairs * 1e6,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drafter_core::Weld;

    #[test]
    fn more_bits_cost_more_bytes_and_lose_less() {
        // A 64-segment cylinder, subdivided twice: curved sides give candidates in every direction.
        let mesh = drafter_testkit::generate::cylinder(64, 2.0).subdivided().subdivided().to_mesh("cylinder");
        let topology = Topology::build(&mesh, Weld::default());
        let sweep = sweep_quantization(&[topology], 32, 7).expect("the cylinder has candidates");
        assert_eq!(sweep.points.len(), QUANTIZATION_BITS.len());
        let normals = 2 * sweep.candidates;
        for p in &sweep.points {
            let per_component = match p.bits {
                0..=8 => 1,
                9..=16 => 2,
                _ => 4,
            };
            assert_eq!(p.raw_bytes, 3 * per_component * normals, "{p:?}");
            assert!(p.encoded_bytes > 0);
        }
        let f32_point = sweep.points.last().expect("f32");
        assert_eq!((f32_point.max_error_deg, f32_point.disagreement_ppm), (0.0, 0.0));
        for w in sweep.points.windows(2) {
            assert!(w[1].mean_error_deg < w[0].mean_error_deg, "{:?} then {:?}", w[0], w[1]);
            assert!(w[1].disagreement_ppm <= w[0].disagreement_ppm, "{:?} then {:?}", w[0], w[1]);
        }
        // Bytes: the shipped 8 bits is 3 bytes a normal as stored.
        let shipped = sweep.points.iter().find(|p| p.bits == SHIPPED_BITS).expect("8 bits");
        assert!(shipped.max_error_deg < 0.5, "{shipped:?}");
    }
}
