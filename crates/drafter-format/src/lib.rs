//! The extended glTF that `drafter bake` writes: glTF 2.0 plus the `DRAFTER_illustration`
//! extension (see `spec/README.md` in this crate for the specification and `spec/schema/` for its
//! JSON Schema).
//!
//! * [`write`] serialises a bake (a [`BakeOutput`]) as .glb or .gltf + .bin;
//! * [`read`] loads a baked file back into the same types, [`read_textures`] its embedded textures,
//!   [`read_normal_sets`] both sets of vertex normals (crease-aware and enhanced) for the viewer's toggle;
//! * [`replace_part_records`] writes an illustrator's edited part records back into a baked file,
//!   every other byte unchanged (`drafter view`'s save);
//! * [`external_buffers`] is the loader of a baked .gltf's buffer those readers take, confined to the
//!   file's folder; [`split_container`] frames a .glb through [`glb`].
//! * [`glb`] is the workspace's one GLB framer (split and write), [`meshopt`] its one
//!   `EXT_meshopt_compression` codec (`compress_glb` for `bake --compress`, `decompress_glb` in front
//!   of every reader), [`draco`] its one `KHR_draco_mesh_compression` decoder (`decompress`, which the
//!   importer calls once the buffers are loaded), [`uri`] its one rule for which buffer URIs may be followed and how they are
//!   read; the importer (drafter-io), inspect, the viewer and the bake all go through them.
//!
//! Invariant: this is the only crate that knows the file format. The extension is listed in
//! `extensionsUsed` and never in `extensionsRequired`, so any glTF viewer opens the result as a plain
//! model; everything of a glTF input that the scene model does not represent passes through.

pub mod accessor;
mod doc;
pub mod draco;
mod edit;
pub mod ext;
mod external;
pub mod glb;
pub mod gltf;
pub mod meshopt;
mod reader;
pub mod uri;
mod writer;

pub use edit::{replace_part_records, validate as validate_part_record};
pub use ext::{
    BoxRecord, CelTableRecord, CelTexture, ConeBvhRecord, CoolToWarmEncoding, CoolToWarmTexture,
    EDGE_VISIBILITY_EXTENSION, ENHANCED_NORMAL_ATTRIBUTE, EXTENSION, EnvMapping, FORMAT_VERSION, GaussMapRecord,
    GradientRecord, GradientTexture, HardEdgeClass, HatchingTexture, InputInfo, MeshExtension, MetalTexture,
    NodeExtension, NormalsInfo, ObbMethod, OrthographicHierarchy, PartRecord, PartStyle, PerspectiveHierarchy,
    PrimitiveExtension, ProjectorRecord, RootExtension, SilhouettesRecord, TextureRef, TexturesRecord, TransferCurve,
    UnknownStyle,
};
pub use external::external_buffers;
pub use reader::{
    BakedFile, ByteSections, EmbeddedPng, PrimitiveNormals, byte_sections, read, read_floats, read_if_baked,
    read_normal_sets, read_scalars, read_textures, split_container,
};
pub use writer::{
    BakeOutput, Container, DEFAULT_MATERIAL, DEFAULT_MATERIAL_NAME, EmbeddedTextures, MAX_PRIMITIVE_VERTICES,
    MeshSilhouettes, PrimitiveEdges, SamplerDesc, StoredNormals, TextureImage, VertexData, Written, first_use, write,
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
    /// A `DRAFTER_illustration` layout this crate does not read.
    #[error("{EXTENSION} version {0} is not supported (this drafter reads {FORMAT_VERSION}); bake the model again")]
    Version(String),
}

impl From<glb::GlbError> for FormatError {
    fn from(e: crate::glb::GlbError) -> Self {
        match e {
            glb::GlbError::TooLarge(total) => Self::TooLarge(total),
            malformed @ glb::GlbError::Malformed { .. } => Self::Invalid(malformed.to_string()),
        }
    }
}
