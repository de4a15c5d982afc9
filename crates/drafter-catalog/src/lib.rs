//! Baking many files, and one file the same way everywhere.
//!
//! - [`job`]: one file's bake as `drafter bake`, a batch and the Python package run it (import
//!   within the limits, provenance, bake), and the errors with their exit codes;
//! - [`cache`]: the content-addressed cache of baked files (keys, entries checked by digest,
//!   atomic inserts, least-recently-used eviction);
//! - [`discover`]: the files of a batch from paths, folders and manifests, and their outputs;
//! - [`estimate`]: a bake's peak memory from the triangles a file lists, before any is read;
//! - [`batch`]: files side by side under a memory budget, one file's bake through the cache
//!   ([`batch::bake_file`]), and the batch report;
//! - [`draw`]: one file's drawing as a catalog, `drafter draw --cache` and Python run it, its
//!   options as one plain value, its cache key, and a catalog of drawings over the batch's scheduler;
//! - [`output`]: atomic writes; [`interrupt`]: what a signal does to them;
//! - [`inspect`]: what `drafter inspect` reports of a file.
//!
//! The CLI (`cli/src/cmd/bake.rs`, `batch.rs`, `cache.rs`, `draw_batch.rs`) and the Python package (`python/`) are
//! thin layers over this crate.

pub mod batch;
pub mod cache;
pub mod discover;
pub mod draw;
pub mod estimate;
pub mod inspect;
pub mod interrupt;
pub mod job;
pub mod output;

pub use job::{Error, bake_bytes, exit};
