//! drafter-scene: what a view of a model is made of, on the CPU, with no GPU code: the model read
//! from a baked file (or any file drafter-io imports) as draw batches, instances and parts
//! ([`model`]), the camera that frames it ([`camera`]), the styles and the view ([`style`]), the
//! baked edges and the per-view silhouette query ([`edges`]), and the file's NPR lookup textures
//! ([`lookups`]).
//!
//! Two crates read it: drafter-render (the wgpu renderer of the window and the page) uploads it, and
//! drafter-draw (`drafter draw`, vector drawings with exact hidden lines) projects it. So the
//! drawing does not link wgpu.
//!
//! The model's records are still stored in the layout the renderer uploads ([`layout`]: `#[repr(C)]`
//! plain data, bytemuck `Pod`); a layout of its own, converted at upload, is the next step of the
//! crate map.
//!
//! Invariant: like the viewer, this crate reads what drafter-io and drafter-format read and never
//! runs a bake stage.

pub mod camera;
pub mod edges;
pub mod layout;
pub mod lookups;
pub mod model;
pub mod style;

pub use camera::Camera;
pub use edges::Hierarchies;
pub use model::{LoadError, Model, Part};
pub use style::{Style, UnknownStyle, View};
