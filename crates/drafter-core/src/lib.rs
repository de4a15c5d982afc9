//! The in-memory model every drafter stage works on.
//!
//! * [`Scene`]: meshes stored once, instances (mesh + world transform + name), materials and the node
//!   hierarchy they came from.
//! * [`Topology`]: a mesh's welded connectivity (edges with their incident faces, face and vertex
//!   adjacency, components), built in O(n log n) with sorts rather than hash maps so that it is fast and
//!   deterministic.
//! * [`Diagnostic`]: recoverable problems of the input, aggregated by kind with a count and a first
//!   example. Flawed input is data, not a failure.
//!
//! Invariant: nothing in this crate reads or writes files.

mod diagnostic;
mod ids;
mod scene;
mod topology;

pub use diagnostic::{Diagnostic, DiagnosticKind, Diagnostics};
pub use ids::{EdgeId, InstanceId, MaterialId, MeshId, NodeId, PartId};
pub use scene::{Aabb, Instance, Material, Mesh, Node, Scene, SourceDocument, SourceFormat, TriangleGroup};
pub use topology::{DEFAULT_SNAP_FRACTION, EDGE_NONE, Topology, Weld};
