//! What tests, the fuzzer and the benchmarks build their inputs from, kept in one place instead of a
//! copy per test file:
//!
//! * [`Rng`]: the workspace's one seeded generator (drafter-core's SplitMix64, re-exported), so a
//!   failing case reproduces from its seed;
//! * [`generate`]: shapes with a known answer and the inputs where methods are known to struggle
//!   (symmetric, paper-thin, sliver, non-manifold, open, unwelded), rigid motions, re-indexings and
//!   subdivision of any mesh;
//! * [`assemblies`]: generated assemblies of touching parts merged into one mesh with the true part
//!   of every triangle, glTF scenes flattened the same way, and a segmentation's accuracy against
//!   either;
//! * [`models`]: the shared model corpus (`../shared/models`) and the input files below a folder.
//!
//! A dev-dependency: no crate a bake, a render or the browser page links names it. The benchmarks
//! (drafter-bench, behind `drafter bench`) and the fuzzer (drafter-fuzz) build on it as well;
//! `cli/tests/architecture.rs` holds every other crate to `[dev-dependencies]`.

pub mod assemblies;
pub mod generate;
pub mod models;

/// The seeded generator of tests, fuzzing and benchmarks: the workspace's one (drafter-core's
/// SplitMix64).
pub use drafter_core::rng::Rng;
