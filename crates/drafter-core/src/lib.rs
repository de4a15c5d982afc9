//! The in-memory model every drafter stage works on.
//!
//! * [`Scene`]: meshes stored once, instances (mesh + world transform + name), materials and the node
//!   hierarchy they came from.
//! * [`Topology`]: a mesh's welded connectivity (edges with their incident faces, face and vertex
//!   adjacency, components), built in O(n log n) with sorts rather than hash maps so that it is fast and
//!   deterministic.
//! * [`gradient`]: the gradient function ω(i, q, f, p) and intensity transfer γ of Lux et al. 2013,
//!   shared by the stages that bake them (bounds, textures) and the viewer that evaluates them.
//! * [`glb`]: the binary glTF container, split and written in one place; [`uri`]: which glTF buffer
//!   URIs may be followed. Pure byte- and string-level code shared by the importer and the format.
//! * [`Diagnostic`]: recoverable problems of the input, aggregated by kind with a count and a first
//!   example. Flawed input is data, not a failure.
//!
//! Invariant: nothing in this crate reads or writes files.

mod diagnostic;
pub mod glb;
pub mod gradient;
mod ids;
pub mod meshopt;
mod obb_method;
mod param;
mod scene;
pub mod snorm;
mod topology;
pub mod uri;

pub use diagnostic::{Diagnostic, DiagnosticKind, DiagnosticSummary, Diagnostics, summarize, thousands};
pub use ids::{EdgeId, InstanceId, MaterialId, MeshId, NodeId, PartId};
pub use obb_method::ObbMethod;
pub use param::ParamError;
pub use scene::{Aabb, Instance, Material, Mesh, Node, Scene, SourceDocument, SourceFormat, TriangleGroup};
pub use snorm::{
    VALIDATOR_UNIT_TOLERANCE, snorm8_decode, snorm8_encode, snorm8_encode_direction, snorm8_encode_unit,
    snorm16_decode, snorm16_encode,
};
pub use topology::{DEFAULT_SNAP_FRACTION, EDGE_NONE, Topology, Weld, robust_diagonal};

/// `len` copies of `value`, written on the thread pool. For arrays of tens of megabytes whose
/// elements are all overwritten later, but whose first writes must come first: the first touch of
/// each page costs more than the write itself, and `vec![value; len]` does all of it on one core
/// (a 73 MB scratch array took 50 ms that way on the dragon).
pub fn filled_in_parallel<T: Copy + Send + Sync>(len: usize, value: T) -> Vec<T> {
    use rayon::prelude::*;
    let mut items = Vec::new();
    (0..len).into_par_iter().map(|_| value).collect_into_vec(&mut items);
    items
}
