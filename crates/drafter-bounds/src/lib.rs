//! Bounding volumes, gradient projectors and gradient functions for drafter's bake.
//!
//! Lux et al. 2013 ("Interactive Projective Texturing for Non-Photorealistic Shading of Technical 3D
//! Models", ../shared/papers/000_*) shade each part with a 1D gradient placed by a projector that is
//! derived from the part's bounding box (§3). This crate computes, per part:
//!
//! 1. a convex hull ([`convex_hull`]): quickhull in f64 with an exact orientation predicate (`hull`);
//! 2. an axis-aligned box ([`aabb`]) and an oriented box ([`oriented_box`]) by one of five methods
//!    ([`ObbMethod`]: `aabb`, `pca`, `hull` (Gottschalk 2000), `default` (fast and tight), `optimal`
//!    (exhaustive over face and edge configurations after O'Rourke 1985 and Jylänki 2015, plus
//!    refinement)) — the module docs of `obb` state the algorithm, the guarantee and the limits;
//! 3. the initial projector ([`Projector::from_obb`]) and its matrix `M = R·P·V` (`projector`);
//! 4. the gradient function ω of Eqn. 1 / Listing 1 ([`omega`], [`GradientParams`]) and the intensity
//!    transfer table γ ([`IntensityTransfer`]) (defined in `drafter_core::gradient`, shared with the
//!    textures and the viewer, and re-exported here).
//!
//! Input points are world-space `DVec3` (transform object-space positions with [`world_points`]); every
//! function is a pure function of its arguments, deterministic, and independent of the thread count.
//!
//! ```
//! use drafter_bounds::{oriented_box, GradientParams, ObbOptions, Projector};
//! use glam::DVec3;
//!
//! let points: Vec<DVec3> = (0..8)
//!     .map(|i| DVec3::new((i & 1) as f64 * 4.0, (i >> 1 & 1) as f64 * 2.0, (i >> 2 & 1) as f64))
//!     .collect();
//! let obb = oriented_box(&points, &ObbOptions::default())?;
//! assert!((obb.volume - 8.0).abs() < 1e-12);
//! let projector = Projector::from_obb(&obb, DVec3::ZERO);
//! let p = projector.coordinate(DVec3::new(4.0, 1.0, 0.5)) as f32; // far end: 1.0
//! let shade = GradientParams::default().eval(p);
//! assert_eq!(shade, 1.0);
//! # Ok::<(), drafter_bounds::BoundsError>(())
//! ```

mod error;
mod hull;
mod linalg;
mod obb;
mod predicates;
mod projector;
mod rect;
mod search;

pub use drafter_core::Aabb;
pub use drafter_core::gradient::{
    DEFAULT_FADE_STEP, DEFAULT_POWER, DEFAULT_QUANTIZATION, GradientParams, INTENSITY_TABLE_LEN, IntensityTransfer,
    MAX_POWER, MAX_QUANTIZATION, MIN_POWER, TransferCurve, omega,
};
pub use error::{BoundsError, ParamError};
pub use hull::{ConvexHull, DEFAULT_HULL_TOLERANCE, HullDimension, HullOptions, convex_hull};
pub use obb::{
    Coverage, DEFAULT_FACE_NORMALS, DEFAULT_OBB_METHOD, DEFAULT_OPTIMAL_BUDGET, Obb, ObbMethod, ObbOptions, ObbStats,
    aabb, box_with_axes, oriented_box, oriented_box_f32, oriented_box_with_stats, world_points,
};
pub use projector::{BIAS_MATRIX, Projector, facing_away};
