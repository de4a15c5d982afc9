//! Feature lines for technical illustration: creases, boundaries, part borders, silhouette
//! candidates, their encoding in `EXT_mesh_primitive_edge_visibility`, and exact hierarchies that
//! answer "which edges are silhouettes from this view" much faster than testing every edge.
//!
//! Technical illustrations live on their lines (Gooch et al. 1999, "Interactive Technical
//! Illustration", I3D; ../shared/papers/001_*): black silhouettes, white creases, heavier outer
//! lines. This crate bakes what a renderer needs to draw them.
//!
//! # Stages
//!
//! 1. [`classify_edges`] gives every welded edge of a [`drafter_core::Topology`] an [`EdgeClass`]:
//!    boundary, non-manifold, part border, crease (dihedral angle above
//!    [`DEFAULT_CREASE_ANGLE_DEG`] = 30° by default), silhouette candidate, coplanar or next to a
//!    degenerate face. Normals are computed in `f64` from the welded positions; classification uses
//!    the welded topology, so unwelded CAD corners do not make every triangle edge a boundary.
//! 2. [`encode_edge_visibility`] writes a primitive's triangles as the draft extension's 2-bit
//!    `visibility` values plus `silhouetteNormals` as VEC3 normalized bytes (the merged draft);
//!    [`decode_edge_visibility`] reads them back and recounts every edge against the encode-once
//!    rules; [`encode_edge_visibility_continuing`] encodes the chunks of a primitive split for
//!    16-bit indices (hard edges per chunk, each silhouette candidate once over the chunks), and
//!    [`encode_faces_continuing`] does the same for a range of the topology's own faces, reading
//!    each corner's edge id instead of searching for it (the bake's path; same bytes, tested).
//! 3. [`BruteForce`] tests every candidate: the reference and the fallback. Structure of arrays,
//!    64 candidates per step into one bitset word, SSE2 by auto-vectorisation, rayon above
//!    [`PARALLEL_MIN_CANDIDATES`]; about a nanosecond a candidate on one core.
//! 4. [`GaussMapHierarchy`] (orthographic): each candidate is the great-circle arc between its two
//!    normals, stored in a hierarchy of spherical triangles (icosahedron, 4:1 splits) at the
//!    deepest cell whose overlapping bin holds it (Gooch et al. §5.1.2, Fig. 8, Table 2); each
//!    node has a data-dependent bounding cap; a query enters only the nodes whose cap the view's
//!    great circle meets. The [`CostModel`] collapses subtrees that are cheaper as one node, and
//!    the build does not descend where a lower bound on any split's cost proves the collapse
//!    (same map, at a fraction of the nodes). [`LevelHistogram`] is the paper's Table 2 as far as
//!    the build descended.
//! 5. [`ConeBvh`] (perspective): candidates split by normal (the Gauss-map cell their arc is
//!    stored in), then within each cell a binned-SAH tree in the dual space of face planes
//!    (a plane is the 4D point `(k·n̂, n̂·(v − c))`, an eye a hyperplane through them; Hertzmann &
//!    Zorin 2000), with a box, a normal cone and the range of face-plane offsets per node, culled
//!    by an exact plane-offset test (anchored cones as in Sander et al. 2000, "Silhouette
//!    Clipping"; Johnson & Cohen 2001, "Spatialized Normal Cone Hierarchies").
//! 6. [`SilhouetteIndex`] builds the hierarchies, keeps each only if the [`CostModel`] predicts a
//!    speedup of at least [`DEFAULT_MIN_SPEEDUP`] (none below [`DEFAULT_MIN_HIERARCHY_CANDIDATES`]),
//!    says what it chose and why ([`HierarchyChoice`]), and converts to and from flat `u32`/`f32`
//!    arrays for glTF buffer views ([`SilhouetteArrays`]; loading validates that every bound holds
//!    its candidates). When a Gauss map is stored, the index numbers its candidates in the map's
//!    storage order ([`SilhouetteIndex::candidate_edges`] gives the edge id of each). A writer that
//!    never queries takes [`SilhouetteIndex::stored_hierarchies`]: the same arrays and choices,
//!    built without the query layouts.
//!
//! Both hierarchies are laid out breadth-first with up to 4 children tested per SIMD pass and
//! candidates in blocks of 4 lanes: a dependent cache miss costs as much as streaming brute force
//! over tens to hundreds of candidates, so what a query touches, and in which order, matters more
//! than how many bounds it tests.
//!
//! # Guarantee and tie rule
//!
//! Every query method returns exactly the set of [`BruteForce`], bit for bit, for every view: the
//! hierarchies only skip groups of candidates that a conservative bound (with a 1e-5 margin) proves
//! to be rejected by the `f32` predicate, and test all others with the same `f32` arithmetic
//! (same operations in the same order, no fused multiply-add). The predicate (see
//! [`is_silhouette_orthographic`] and [`is_silhouette_perspective`]): with `a = n1·w`, `b = n2·w`
//! (`w` the unit view direction from [`unit_direction`], or `e − v` from the candidate's first
//! welded vertex `v` to the eye `e`), the edge is a silhouette iff `a` and `b` have **strictly**
//! opposite signs. **Tie rule:** a zero on either side is *not* a silhouette, whatever the method.
//!
//! # Defaults
//!
//! Crease above [`DEFAULT_CREASE_ANGLE_DEG`] (30°), coplanar at or below
//! [`DEFAULT_COPLANAR_ANGLE_DEG`] (0.001°), icosahedron with overlapping bins of
//! [`DEFAULT_OVERLAP`] (1.5) circumradii and depth by [`depth_for_count`], cone-BVH leaves of
//! [`DEFAULT_LEAF_SIZE`] (64) before pruning, [`DEFAULT_SAMPLE_EYES`] (96) sampled eyes, cost
//! constants in [`CostModel`].
//!
//! # Limits
//!
//! Coordinates are assumed finite and not subnormal; a zero or non-finite view direction selects
//! no edge, NaN eyes select none either (every method agrees). The encoder's rules hold per call
//! (per glTF primitive). Faces are not re-oriented: inconsistent winding shows as creases.
//!
//! # References
//!
//! * Gooch, Sloan, Gooch, Shirley, Riesenfeld 1999, "Interactive Technical Illustration", I3D
//!   (../shared/papers/001_*): §5.1 silhouettes, Gauss-map arcs, Tables 1–2.
//! * Sander, Gu, Gortler, Hoppe, Snyder 2000, "Silhouette Clipping", SIGGRAPH: anchored cones.
//! * Johnson, Cohen 2001, "Spatialized Normal Cone Hierarchies", I3D.
//! * Hertzmann, Zorin 2000, "Illustrating Smooth Surfaces", SIGGRAPH: silhouettes as the
//!   intersection of the dual surface of face planes with the eye's plane.
//! * Khronos draft `EXT_mesh_primitive_edge_visibility` (../shared/specs).

mod brute;
mod classify;
mod cone_bvh;
mod cost;
mod error;
mod gauss;
mod index;
pub mod measure;
mod set;
mod sphere;
mod tree;
mod visibility;

pub use brute::{
    BruteForce, PARALLEL_MIN_CANDIDATES, View, is_silhouette_orthographic, is_silhouette_perspective, opposite_signs,
    unit_direction,
};
pub use classify::{
    DEFAULT_COPLANAR_ANGLE_DEG, DEFAULT_CREASE_ANGLE_DEG, DEFAULT_CREASE_CONTINUE, DEFAULT_CREASE_MIN_EDGES,
    DEFAULT_CREASE_MIN_LENGTH, DEFAULT_CREASE_TURN_DEG, DEFAULT_STRONG_CREASE_DEG, EdgeClass, EdgeClassCounts,
    FaceLabels, FeatureEdges, LineOptions, classify_edges, classify_edges_for_encoding, classify_edges_labelled,
    face_normals,
};
pub use cone_bvh::{
    CONE_MARGIN, ConeBvh, ConeBvhArrays, ConeBvhOptions, DEFAULT_LEAF_SIZE, DEFAULT_SAMPLE_EYES, DUAL_NORMAL_WEIGHT,
    NormalSplit, normal_level_for_count,
};
pub use cost::CostModel;
pub use error::{ArraysError, LinesError};
pub use gauss::{
    BaseSolid, Bins, CULL_MARGIN, DEFAULT_OVERLAP, GaussMapArrays, GaussMapHierarchy, GaussMapOptions, LevelCount,
    LevelHistogram, depth_for_count,
};
pub use index::{
    BruteForceReason, DEFAULT_MIN_HIERARCHY_CANDIDATES, DEFAULT_MIN_SPEEDUP, HierarchyChoice, SilhouetteArrays,
    SilhouetteIndex, SilhouetteOptions, StoredHierarchies,
};
pub use set::EdgeSet;
pub use tree::QueryCounts;
pub use visibility::{
    DecodedEdgeVisibility, EdgeVisibility, HARD, HARD_REPEATED, HIDDEN, SILHOUETTE, SilhouettesEncoded,
    VisibilityError, decode_edge_visibility, encode_edge_visibility, encode_edge_visibility_continuing,
    encode_faces_continuing,
};
