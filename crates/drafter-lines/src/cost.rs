//! The cost model that decides how deep a hierarchy goes and whether it is stored at all.

use serde::{Deserialize, Serialize};

/// Per-operation costs in nanoseconds on one core. The defaults were fitted with
/// `silhouette_bench --calibrate` (release build, SSE2 code, warm caches) by
/// least squares of `time ≈ Σ count · cost` over random views of the generated sphere, the bunny,
/// fandisk and rocker-arm; only their ratios matter. The individual node costs are poorly
/// separated by the fit (nodes entered, bounds tested and ranges move together), their sum is not.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CostModel {
    /// Brute force, per candidate, orthographic. Default 0.6.
    pub brute_ortho_ns: f32,
    /// Brute force, per candidate, perspective. Default 1.15.
    pub brute_perspective_ns: f32,
    /// Gauss map: per node entered. Default 3.
    pub gauss_enter_ns: f32,
    /// Gauss map: per cap tested. Default 1.5.
    pub gauss_test_ns: f32,
    /// Gauss map: per entered node with own arcs. Default 3.
    pub gauss_range_ns: f32,
    /// Gauss map: per block of 4 arcs. Default 2.
    pub gauss_block_ns: f32,
    /// Cone BVH: per node entered. Default 5.
    pub bvh_enter_ns: f32,
    /// Cone BVH: per box and cone tested. Default 5.
    pub bvh_test_ns: f32,
    /// Cone BVH: per leaf whose candidates are tested. Default 20.
    pub bvh_range_ns: f32,
    /// Cone BVH: per block of 4 candidates. Default 3.9.
    pub bvh_block_ns: f32,
}

impl Default for CostModel {
    fn default() -> Self {
        Self {
            brute_ortho_ns: 0.6,
            brute_perspective_ns: 1.15,
            gauss_enter_ns: 3.0,
            gauss_test_ns: 1.5,
            gauss_range_ns: 3.0,
            gauss_block_ns: 2.0,
            bvh_enter_ns: 5.0,
            bvh_test_ns: 5.0,
            bvh_range_ns: 20.0,
            bvh_block_ns: 3.9,
        }
    }
}
