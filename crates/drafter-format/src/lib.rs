//! The extended glTF that `drafter bake` writes: glTF 2.0 plus the `DRAFTER_illustration`
//! extension (see `spec/README.md` in this crate for the specification and `spec/schema/` for its
//! JSON Schema).
//!
//! * [`write`] serialises a bake (a [`BakeOutput`]) as .glb or .gltf + .bin;
//! * [`read`] loads a baked file back into the same types.
//!
//! Invariant: this is the only crate that knows the file format. The extension is listed in
//! `extensionsUsed` and never in `extensionsRequired`, so any glTF viewer opens the result as a plain
//! model; everything of a glTF input that the scene model does not represent passes through.

mod doc;
pub mod ext;
mod reader;
mod writer;

pub use ext::{
    BoxRecord, ConeBvhRecord, EDGE_VISIBILITY_EXTENSION, ENHANCED_NORMAL_ATTRIBUTE, EXTENSION, FORMAT_VERSION,
    GaussMapRecord, GradientRecord, HardEdgeClass, InputInfo, MeshExtension, NodeExtension, NormalsInfo, PartRecord,
    PrimitiveExtension, ProjectorRecord, RootExtension, SilhouettesRecord,
};
pub use reader::{BakedFile, read, read_scalars, split_container};
pub use writer::{
    BakeOutput, ConeBvhData, Container, GaussMapData, MeshSilhouettes, PrimitiveEdges, VertexData, Written, write,
};

/// `drafter <version>`, written as the generator.
pub const GENERATOR: &str = concat!("drafter ", env!("CARGO_PKG_VERSION"));

/// Why a file could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    #[error("JSON: {0}")]
    Json(#[from] serde_json::Error),
    #[error("the source glTF document cannot be passed through: {0}")]
    Source(String),
    #[error("internal inconsistency: {0}")]
    Inconsistent(String),
    #[error("output of {0} bytes exceeds the 4 GiB limit of a .glb")]
    TooLarge(usize),
    #[error("not a drafter bake: {0}")]
    NotBaked(String),
    #[error("invalid baked file: {0}")]
    Invalid(String),
}
