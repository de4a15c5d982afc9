//! Per-face geometry: unit normals, areas and centroids, computed in f64 from the welded positions.

use drafter_core::Topology;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Faces per rayon task in the per-face loops: large enough that scheduling costs nothing, small enough
/// that two cores share a 10k-face mesh.
pub(crate) const FACE_CHUNK: usize = 4096;

/// Per-face geometry of a mesh, indexed like `Topology::faces`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceGeometry {
    /// Unit normal of each face (right-handed winding); `Vec3::ZERO` for a degenerate face.
    pub normals: Vec<Vec3>,
    /// Area of each face; `0.0` for a degenerate face.
    pub areas: Vec<f32>,
    /// Centroid of each face.
    pub centroids: Vec<Vec3>,
}

impl FaceGeometry {
    /// Computes normals, areas and centroids of `topology.faces` over `topology.welded_positions`.
    ///
    /// The cross product is taken in f64 on edge vectors, so CAD coordinates far from the origin and
    /// slivers keep their precision. A face flagged degenerate by the topology, or whose f32 normal
    /// would not be finite, gets a zero normal and a zero area: it never votes in any average.
    pub fn compute(topology: &Topology) -> FaceGeometry {
        let positions = &topology.welded_positions;
        let (normals, (areas, centroids)): (Vec<Vec3>, (Vec<f32>, Vec<Vec3>)) = topology
            .faces
            .par_iter()
            .zip(topology.face_degenerate.par_iter())
            .with_min_len(FACE_CHUNK)
            .map(|(&[a, b, c], &degenerate)| {
                let pa = positions[a as usize].as_dvec3();
                let pb = positions[b as usize].as_dvec3();
                let pc = positions[c as usize].as_dvec3();
                let centroid = ((pa + pb + pc) / 3.0).as_vec3();
                if degenerate {
                    return (Vec3::ZERO, (0.0, centroid));
                }
                let cross: DVec3 = (pb - pa).cross(pc - pa);
                let length = cross.length();
                let normal = (cross / length).as_vec3();
                let area = (0.5 * length) as f32;
                if length.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
                    || !normal.is_finite()
                    || area <= 0.0
                    || !area.is_finite()
                {
                    return (Vec3::ZERO, (0.0, centroid));
                }
                (normal, (area, centroid))
            })
            .unzip();
        FaceGeometry { normals, areas, centroids }
    }

    pub fn len(&self) -> usize {
        self.normals.len()
    }

    pub fn is_empty(&self) -> bool {
        self.normals.is_empty()
    }

    /// True when face `f` has no normal (zero area or collapsed after welding).
    #[inline]
    pub fn is_degenerate(&self, f: usize) -> bool {
        self.areas[f] == 0.0
    }

    /// Number of faces without a normal.
    pub fn degenerate_count(&self) -> usize {
        self.areas.iter().filter(|&&a| a == 0.0).count()
    }
}
