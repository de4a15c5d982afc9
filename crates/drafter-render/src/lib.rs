//! drafter-render: renders baked files (and any model drafter-io reads) for non-photorealistic
//! technical illustration with wgpu: headless to PNG, into a window's surface (drafter-app, `drafter
//! view`) or into the browser page's canvas (`web/`).
//!
//! # The frame
//! A multi-pass pipeline after Lux et al. 2013, §5, Algorithm 1 (../shared/papers/000_*), with the
//! line, shading and shadow conventions of Gooch et al. 1999 (../shared/papers/001_*):
//!
//! 1. [`passes::gbuffer`]: every mesh drawn once, instanced; per-part projector, gradient and style
//!    from a table indexed by part id ([`table`]); writes colour, normal, linear depth and part id.
//!    Styles: [`Style`] (`gradient`, `phong`, `cel`, `gooch`, `goochel`, `metal`, `hatch`), reading
//!    the NPR lookup textures the file embeds ([`lookups`]: γ and cel tables, cool-to-warm map,
//!    hatching halftone, metal bands and highlights), each computed procedurally where it has none.
//! 2. [`passes::shadow`]: optional drop shadow on the ground plane (hard, umbra + penumbra, soft).
//! 3. [`passes::enhance`]: the depth unsharp mask's blur; the image-space edges (part-id, depth and
//!    normal discontinuities) it specifies are detected in the display pass, which reads the same
//!    texels (measured on lavapipe: a separate full-screen pass cost half a Phong frame).
//! 4. [`passes::display`]: edges, depth darkening, composite, background, coloured shadow,
//!    selection highlight.
//! 5. [`passes::lines`]: the baked hard edges and this frame's silhouettes (queried per instance
//!    from the baked hierarchies, [`edges`]) as screen-space quads over the display output.
//!
//! drafter-app runs the same frame in a winit window (`drafter view`), with the illustrator's edits
//! (Lux et al. 2013 §4); an edit rewrites the part table only ([`Renderer::update_parts`]). The view
//! controls the window and the browser page share (the orbit, the zoom and pan, what a key does)
//! are pure functions here, in [`controls`], tested without a display.
//!
//! What each style, the edges and the shadows cost against a Phong frame is the benchmark's to say
//! (`drafter bench render FILE` prints the ratios; docs/usage.md, docs/bench.md).
//!
//! # Use
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let model = drafter_render::Model::load(std::path::Path::new("sample.baked.glb"))?;
//! let mut renderer = drafter_render::Renderer::new()?; // lavapipe works: no GPU needed
//! renderer.set_model(&model)?;
//! let options = drafter_render::RenderOptions { style: drafter_render::Style::Gooch, ..Default::default() };
//! std::fs::write("out.png", renderer.render(&options)?.to_png()?)?;
//! # Ok(()) }
//! ```
//!
//! # Platforms
//! No window crate: the crate builds for `wasm32-unknown-unknown` as it is (the browser page in
//! `web/`, WebGPU or WebGL2), the same passes and WGSL, the device requested asynchronously with
//! [`Gpu::request`], frames recorded with [`Renderer::encode_frame`]. Off the web the device
//! requests also block ([`Gpu::headless`], [`Renderer::new`], through pollster).
//!
//! # The CPU side
//! What a frame is made of on the CPU (the [`Model`], the [`Camera`] fit, the baked edges and the
//! silhouette query, the lookup textures, the styles and the view) lives in drafter-scene,
//! re-exported here as [`model`], [`camera`], [`edges`] and [`lookups`] (the styles and the view
//! in [`style`], beside the frame's options). The vector drawings (`drafter draw`) are
//! drafter-draw, which reads the same model without wgpu.
//!
//! Invariant: the renderer draws what drafter-io and drafter-format read; it never runs a bake
//! stage. A file without `DRAFTER_illustration` data renders with one part per instance and a
//! bounding-box projector, and [`Model::notices`] says so.

pub mod context;
pub mod controls;
pub mod gpu_types;
pub mod image;
pub mod passes;
pub mod renderer;
pub mod scene;
pub mod style;
pub mod table;
pub mod targets;

pub use drafter_scene::{camera, edges, lookups, model};

pub use camera::Camera;
pub use context::{Gpu, RenderError};
pub use image::{Image, ImageDiff, PngError};
pub use model::{LoadError, Model, Part};
pub use renderer::{FrameInfo, PartMap, Readback, Renderer};
pub use style::{Enhancements, RenderOptions, ShadowMode, Style, UnknownStyle, View};
