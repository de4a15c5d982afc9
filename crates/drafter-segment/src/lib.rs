//! Segmentation: a [`Scene`] cut into parts, each of which later gets its own box, projector and
//! gradient.
//!
//! Lux et al. 2013 (*Interactive Projective Texturing for Non-Photorealistic Shading of Technical
//! 3D Models*, ../shared/papers/000_*, "Limitations") name both ways this goes wrong: a scene that
//! is a single object gets a single gradient, "which kind of defeats the purpose", and a scene of
//! many small objects gives "visual clutter"; they leave mesh segmentation to future work. This
//! crate is that step, with a default ([`SegmentMode::Auto`]) that aims for the real parts of an
//! assembly: not one blob, not hundreds of slivers.
//!
//! # How it works
//!
//! Segmentation is computed once per unique mesh and shared by every instance of it
//! ([`MeshLabels::PerTriangle`] holds an `Arc`); part ids are then handed out per instance, in
//! instance order and then label order, so a mesh instanced 20 times that splits into 3 gives 60
//! parts. Labels within a mesh are numbered in order of their first triangle.
//!
//! * [`SegmentMode::Nodes`]: each instance is one part (a glTF mesh node, an OBJ group).
//! * [`SegmentMode::Components`]: faces connected through shared *edges* of the welded topology
//!   ([`Topology::build`] with [`SegmentOptions::weld`]). A vertex alone does not connect (two
//!   cubes touching at a corner are two parts). At a **non-manifold edge** (three or more faces),
//!   faces are paired the way the solids that meet there own them: around the edge `a → b`, a
//!   face that runs `a → b` has its outward normal towards increasing angle and one that runs
//!   `b → a` towards decreasing angle, so for closed, outward-facing solids the faces sorted by
//!   angle alternate, and each solid fills the wedge from a `b → a` face to the next `a → b` face.
//!   Each such pair is connected; the faces of different solids are not. Faces within 1e-3 rad of
//!   each other are reordered to keep the alternation (coincident faces where two solids touch
//!   along a face, zero-thickness sheets). Inside-out vertex-connected components (negative
//!   signed volume) are read reversed. A fan that cannot be made to alternate (odd count, open
//!   surfaces, overlapping solids) is paired **in part**: in the same order (closing
//!   faces first among equal angles), an opening face is linked to the next face around the edge
//!   when that one closes, since the wedge between them holds no other face and so is one
//!   solid's; faces left over are free edges of their parts. This is the case of a part with a
//!   crack (a T-junction seam, as exporters leave where two faces of a B-rep are discretized
//!   differently) along a rim that lies on the edges of a closed part it touches: a gasket under a
//!   cover, a washer under a screw head. The edge has three faces, two of the closed part and one
//!   of the cracked one; linking nothing there (as before) cut the closed part along the whole
//!   rim, and a cover came out as two parts. Partly paired edges and the faces left over are
//!   counted in a diagnostic, since overlapping solids can also make such a fan; a fan with no
//!   such pair links nothing and is reported as unpaired.
//!
//!   Why not simply connect every face of a non-manifold edge, or none? On `obj/occt/motor.stl`
//!   the first gives 12 vertex-connected blobs of several solids each; the second gives 85
//!   pieces, 68 of them single triangles (where two solids touch along a face the exporter wrote
//!   the same triangles twice, and each copy has three non-manifold edges). Pairing gives the 17
//!   solids. On merged glTF assemblies (every instance in world space, one mesh) it keeps every
//!   component within one original part.
//!
//!   Triangles whose three welded vertices are not distinct have no edge; they join the first
//!   triangle with an edge around one of their vertices.
//! * [`SegmentMode::Regions`]: the same links, kept only where the angle between the two face
//!   normals is below [`SegmentOptions::region_angle_deg`]: crease-bounded regions (a cube gives
//!   its 6 faces). Zero-area faces join one neighbour each, so they cannot bridge two regions.
//! * [`SegmentMode::Auto`] (default): [`SegmentMode::Nodes`] when the scene has several
//!   instances — the file's own parts are the best segmentation there is, and Auto never merges
//!   or splits them. With a single instance (an STL, a one-group OBJ), [`SegmentMode::Components`]
//!   then open pieces glued across cracks (see Cracks), then small parts merged (below).
//!
//! # What is merged, and why
//!
//! Components of real files include pieces that are not parts: faces of a part whose
//! tessellation does not weld, one- or two-triangle flaps, debris cut off at a fan that could not
//! be paired. Auto merges them; it must not merge the small real parts of an assembly (screws,
//! clips, sheet-metal brackets) into whatever they touch. The rule:
//!
//! 1. A part is **small** when it has fewer than [`SegmentOptions::merge_triangle_fraction`] of
//!    the mesh's triangles *and* its bounding-box diagonal is below
//!    [`SegmentOptions::merge_diagonal_fraction`] of the mesh's (here and below, the mesh's
//!    *robust* diagonal, `drafter_core::robust_diagonal`: a few far-away vertices do not count).
//!    A **closed solid** (no boundary edge, no unpaired fan, enclosed volume above 1e-6 of its
//!    diagonal cubed) is never small: it is a part in its own right whatever its size (a
//!    12-triangle washer stays a washer).
//! 2. Where a small part touches is probed at the welded vertices of its *free* edges (boundary
//!    edges and unpaired fans: where a fragment was cut off, its edge lies on what it was cut
//!    from), or at all its vertices if it has none. A neighbour *shares* a probe when it uses the
//!    same welded vertex, and is *near* it when one of its triangles is within
//!    [`SegmentOptions::touch_fraction`] of the mesh diagonal (exact point–triangle distance;
//!    candidates from a uniform grid of at most 64³ cells over the probes).
//! 3. Small parts are visited from the fewest triangles up (ties by label). A part joins the
//!    neighbour that shares the most of its probes (then the largest, then the lowest label), with
//!    no limit. If none shares any, it joins the neighbour near the most probes among those with
//!    room: through near-only contacts a part takes in at most
//!    [`SegmentOptions::max_absorbed_fraction`] of its core component's triangles. A part that has
//!    grown past the size thresholds is no longer small; a small part that touches nothing, or
//!    only neighbours without room, stays on its own.
//!
//! Why two kinds of contact: on the merged assemblies of ../shared/models (measured without the
//! cap), every merge through a shared vertex joined pieces of the same original part (Buggy: 97
//! of 97; the scan `dragon_vrip_res4.ply`: 147 of 147), while every merge that crossed original
//! parts was a near-only contact (a small open part lying on a housing, a screw in its hole: 24
//! of 27 near-only merges on ReciprocatingSaw, 48 of 143 on Buggy). The cap bounds what such a
//! mistake costs: a part is at least `1 / (1 + f)` its core component plus what came through
//! shared vertices. Merging happens only inside one mesh's segmentation, never across instances.
//!
//! `tests/real_models.rs` holds the defaults to their purpose on every glTF assembly of
//! ../shared/models merged into one mesh: at least 99% of triangles in parts that are at least
//! 99% one original instance. More parts than instances come from meshes that hold several
//! separate solids, such as a bearing and its balls. The figures per assembly, with the command
//! that prints them: docs/bench.md#segmentation-where-parts-touch.
//!
//! # Cracks
//!
//! A crack is a seam where two faces of one part were tessellated apart: their edges lie on each
//! other (a T-junction seam, or vertices a float's rounding apart) but share no welded vertex, so
//! the part's surface comes apart into open pieces. A crack all the way round a pin leaves two
//! pieces with no edge between them; an exporter that writes a cylinder's caps apart from its
//! side leaves three. Before merging small parts, [`SegmentMode::Auto`] glues open pieces across
//! cracks (`stitch.rs`):
//!
//! 1. A *free* edge is an edge of a face that no other face of its piece shares. A free edge of
//!    piece A is *covered* by piece B when both its ends and its midpoint lie within
//!    [`SegmentOptions::stitch_fraction`] of the mesh diagonal of B's free edges.
//! 2. A is *sealed* when at least [`STITCH_SEALED_FRACTION`] (90%) of its free length is covered;
//!    a sealed piece is glued to every piece that covers at least [`STITCH_SHARE_FRACTION`] (5%)
//!    of it. Closed solids have no free edges, so a solid is never glued to anything: a cover
//!    over a casing, a washer under a screw head stay apart.
//!
//! Gluing is a statement about geometry, not about the file: open surfaces of two *different*
//! parts whose rims seal each other are glued too, and nothing in a merged mesh tells them from
//! the pieces of one cracked part. On the merged ReciprocatingSaw (every instance in world
//! space) open bodies of consecutive nodes meet rim to rim within 1e-6 of the diagonal, so a
//! tolerance of 1e-6 glues them across nodes, while 2CylinderEngine's cracks need 1e-5 to close
//! all. The default, 1e-7 (the rounding of f32
//! coordinates near the origin), glues no two nodes of any merged assembly here. Glued pieces are
//! counted in a diagnostic ([`DiagnosticKind::GluedCrack`]).
//!
//! `tests/contacts.rs` runs this over `drafter_testkit::assemblies` (generated clamped gaskets,
//! washers under screw heads, pins pressed into holes, stacked plates, covers over casings with a
//! gasket, each with matching, non-matching and cracked tessellation) and requires every part
//! recovered on all of them; without gluing, a pin cracked all the way round comes out as two
//! parts. On the glTF assemblies of ../shared/models merged into one unwelded mesh, what stays
//! apart is open pieces that share no vertex with their part and seal against it, if at all, only
//! at 1e-4 of the diagonal, or float off it (docs/bench.md#segmentation-where-parts-touch).
//!
//! # Determinism
//!
//! Part ids depend only on the input: unions go through union-find forests whose roots are the
//! smallest member, labels are numbered by first triangle, contact lists are sorted, and nothing
//! iterates a hash map. The result is the same at any thread count.
//!
//! # Limits
//!
//! * Thresholds are relative to the segmented mesh (in Auto, the only mesh of the scene).
//! * Touching solids that share no edge pairing information (separate shells that merely
//!   interpenetrate or touch) are separate components, as they should be; a single part made of
//!   several disconnected shells is several parts unless its shells are small and open.
//! * Small *open* real parts of an assembly that share a welded vertex with a larger part are
//!   merged into it (no cap); near-only ones only up to the cap. Closed solids never are.
//! * Pieces of one part that are larger than the cap and touch it only spatially (a face patch
//!   that does not weld, holding more than 1% of its part's triangles) stay separate parts:
//!   over-segmentation is the price of purity.
//! * Pairing assumes consistently oriented faces; a fan whose faces disagree is cut, not paired.
//! * Cracks wider than [`SegmentOptions::stitch_fraction`] of the diagonal (or, for a model far
//!   from the origin, than its coordinates' rounding) are not glued; their pieces are parts unless
//!   small. Different open parts whose rims seal each other within it are glued (see Cracks).
//! * Regions follow creases only; a smooth fillet joins the faces on both sides of it.
//!
//! # Cost
//!
//! Linear apart from the weld inside [`Topology::build`], which dominates: with the topology
//! given, [`segment_with_topologies`] (edge links, union-find, labels) costs a fraction of
//! building it, and the link pass runs on the thread pool (`examples/segment_bench.rs` times the
//! two against each other). A pipeline
//! that builds the topologies for other stages anyway should pass them. Merging costs a pass
//! over the triangles against a grid of the small parts' boundary vertices, only when small parts
//! exist; `Nodes` (and `Auto` on a scene with several instances) costs nothing per triangle.

mod connect;
mod geometry;
mod merge;
mod parts;
mod stitch;
mod union_find;

use std::sync::Arc;

use drafter_core::{Diagnostic, DiagnosticKind, InstanceId, Mesh, MeshId, PartId, Scene, Topology, Weld};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub use parts::{InstanceParts, LabelTable, MeshLabels, Part, PartTriangles, Parts};

/// Default of [`SegmentOptions::region_angle_deg`]: a crease is a dihedral angle of 30° or more,
/// the usual crease angle of CAD viewers and of drafter's line extraction.
pub const DEFAULT_REGION_ANGLE_DEG: f64 = 30.0;
/// Default of [`SegmentOptions::merge_triangle_fraction`]: 1% of the mesh's triangles.
pub const DEFAULT_MERGE_TRIANGLE_FRACTION: f64 = 0.01;
/// Default of [`SegmentOptions::merge_diagonal_fraction`]: 5% of the mesh's bounding diagonal.
pub const DEFAULT_MERGE_DIAGONAL_FRACTION: f64 = 0.05;
/// Default of [`SegmentOptions::touch_fraction`]: 1e-4 of the mesh's bounding diagonal.
pub const DEFAULT_TOUCH_FRACTION: f64 = 1e-4;
/// Default of [`SegmentOptions::stitch_fraction`]: 1e-7 of the mesh's bounding diagonal, about
/// the rounding of f32 coordinates (6e-8 of their magnitude) for a model near the origin. Larger
/// tolerances glue more cracks but also different parts (crate docs, "Cracks").
pub const DEFAULT_STITCH_FRACTION: f64 = 1e-7;
/// A label whose free edges lie at least this fraction (by length) on other labels' free edges is
/// sealed by them, and glued to them ([`SegmentOptions::stitch_fraction`]).
pub const STITCH_SEALED_FRACTION: f64 = 0.9;
/// ...to each of those that covers at least this fraction of its free length.
pub const STITCH_SHARE_FRACTION: f64 = 0.05;
/// Default of [`SegmentOptions::max_absorbed_fraction`]: 1%, so that near-only merges leave every
/// part more than 99% its core component.
pub const DEFAULT_MAX_ABSORBED_FRACTION: f64 = 0.01;

/// How the scene is cut into parts. See the crate docs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum SegmentMode {
    /// Each mesh instance is one part.
    Nodes,
    /// Edge-connected components of each welded mesh.
    Components,
    /// Components split further at creases.
    Regions,
    /// Nodes when the scene has several instances, otherwise components with small parts merged.
    #[default]
    Auto,
}

impl SegmentMode {
    /// Every mode, in declaration order.
    pub const ALL: [SegmentMode; 4] = [Self::Nodes, Self::Components, Self::Regions, Self::Auto];

    /// The lowercase name used on the command line and in configuration files.
    pub fn name(self) -> &'static str {
        match self {
            Self::Nodes => "nodes",
            Self::Components => "components",
            Self::Regions => "regions",
            Self::Auto => "auto",
        }
    }
}

impl std::fmt::Display for SegmentMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SegmentMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|m| m.name() == s).ok_or_else(|| {
            format!("unknown segmentation mode `{s}` (expected one of: nodes, components, regions, auto)")
        })
    }
}

/// How the faces around a non-manifold edge are paired when they do not alternate (see the crate
/// docs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FanPairing {
    /// Pair only fans that alternate completely; any other fan links nothing (the earlier rule,
    /// kept for comparison: `drafter bench` charts both).
    Whole,
    /// Also pair, in part, fans that do not alternate; the faces left over are free edges.
    #[default]
    Partial,
}

/// Options of [`segment`]. serde reads `mode` and `region_angle_deg`, the choices a user makes (a bake
/// config's `[segment]` table, any other key refused); the other fields are tuning that reading
/// leaves at its default, and all are written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SegmentOptions {
    /// How to cut. Default [`SegmentMode::Auto`].
    pub mode: SegmentMode,
    /// [`SegmentMode::Regions`]: faces whose normals differ by less than this angle, in degrees,
    /// stay in one region. Default [`DEFAULT_REGION_ANGLE_DEG`]; range 0–180 (0 puts every face on
    /// its own, 180 gives the components).
    pub region_angle_deg: f64,
    /// [`SegmentMode::Auto`]: a part with fewer than this fraction of the mesh's triangles (and a
    /// small diagonal, below) may be merged into a neighbour. Default
    /// [`DEFAULT_MERGE_TRIANGLE_FRACTION`]; range 0–1, 0 turns merging off.
    #[serde(skip_deserializing)]
    pub merge_triangle_fraction: f64,
    /// [`SegmentMode::Auto`]: a part whose bounding-box diagonal is below this fraction of the
    /// mesh's (and with few triangles, above) may be merged into a neighbour. Default
    /// [`DEFAULT_MERGE_DIAGONAL_FRACTION`]; range 0–1, 0 turns merging off.
    #[serde(skip_deserializing)]
    pub merge_diagonal_fraction: f64,
    /// [`SegmentMode::Auto`]: a small part is near a neighbour where a vertex of its free boundary
    /// comes this close to one of the neighbour's triangles, as a fraction of the mesh's bounding
    /// diagonal. Default [`DEFAULT_TOUCH_FRACTION`]; range 0–1.
    #[serde(skip_deserializing)]
    pub touch_fraction: f64,
    /// [`SegmentMode::Auto`]: through contacts that share no welded vertex (see the crate docs), a
    /// part takes in at most this fraction of its core component's triangles, in all, so wrong
    /// merges cost little: such a part is at least `1 / (1 + f)` its core. Merges through shared
    /// vertices are not capped. Default [`DEFAULT_MAX_ABSORBED_FRACTION`]; range 0–∞, 0 allows
    /// shared-vertex merges only.
    #[serde(skip_deserializing)]
    pub max_absorbed_fraction: f64,
    /// [`SegmentMode::Auto`]: open pieces whose free edges lie on each other's, within this
    /// fraction of the mesh's bounding diagonal, are glued across the crack (see the crate docs,
    /// "Cracks"). Default [`DEFAULT_STITCH_FRACTION`]; 0 turns gluing off.
    #[serde(skip_deserializing)]
    pub stitch_fraction: f64,
    /// How non-manifold fans that do not alternate are paired (all modes but `Nodes`). Default
    /// [`FanPairing::Partial`].
    #[serde(skip_deserializing)]
    pub fan_pairing: FanPairing,
    /// How positions are welded before connectivity is derived (all modes but `Nodes`). Default
    /// [`Weld::default`]. Ignored by [`segment_with_topologies`] for meshes whose topology is given.
    #[serde(skip_deserializing)]
    pub weld: Weld,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        Self {
            mode: SegmentMode::Auto,
            region_angle_deg: DEFAULT_REGION_ANGLE_DEG,
            merge_triangle_fraction: DEFAULT_MERGE_TRIANGLE_FRACTION,
            merge_diagonal_fraction: DEFAULT_MERGE_DIAGONAL_FRACTION,
            touch_fraction: DEFAULT_TOUCH_FRACTION,
            max_absorbed_fraction: DEFAULT_MAX_ABSORBED_FRACTION,
            stitch_fraction: DEFAULT_STITCH_FRACTION,
            fan_pairing: FanPairing::default(),
            weld: Weld::default(),
        }
    }
}

/// Cuts `scene` into parts. Builds the welded topology of every mesh it needs; see
/// [`segment_with_topologies`] to reuse topologies built elsewhere.
///
/// Diagnostics report non-manifold edges whose faces could not be paired
/// ([`DiagnosticKind::UnpairedNonManifoldEdge`]) or were paired only in part
/// ([`DiagnosticKind::PartlyPairedNonManifoldEdge`]), and how many small parts were merged.
pub fn segment(scene: &Scene, options: &SegmentOptions) -> (Parts, Vec<Diagnostic>) {
    segment_with_topologies(scene, &[], options)
}

/// [`segment`] with the welded topologies of the scene's meshes already built:
/// `topologies[i]` must be `Topology::build(&scene.meshes[i], weld)` for some weld. Meshes past
/// the end of `topologies` (or whose topology does not match their size) get theirs built with
/// [`SegmentOptions::weld`].
pub fn segment_with_topologies(
    scene: &Scene,
    topologies: &[Topology],
    options: &SegmentOptions,
) -> (Parts, Vec<Diagnostic>) {
    let (mode, merge) = match options.mode {
        SegmentMode::Auto if scene.instances.len() > 1 => (SegmentMode::Nodes, false),
        SegmentMode::Auto => (SegmentMode::Components, true),
        m => (m, false),
    };
    let mut used: Vec<MeshId> = scene.instances.iter().map(|i| i.mesh).collect();
    used.sort_unstable();
    used.dedup();
    let mut per_mesh: Vec<Option<MeshResult>> = (0..scene.meshes.len()).map(|_| None).collect();
    if mode != SegmentMode::Nodes {
        let results: Vec<MeshResult> = used
            .par_iter()
            .map(|&m| segment_mesh(scene.mesh(m), topologies.get(m.index()), mode, merge, options))
            .collect();
        for (m, r) in used.iter().zip(results) {
            per_mesh[m.index()] = Some(r);
        }
    }
    let diagnostics = diagnostics(per_mesh.iter().flatten());
    let mut parts = Parts::default();
    for (i, inst) in scene.instances.iter().enumerate() {
        let instance = InstanceId::from(i);
        let first_part = PartId::from(parts.parts.len());
        match per_mesh[inst.mesh.index()].as_ref().and_then(|r| r.table.clone()) {
            None => {
                parts.parts.push(Part {
                    name: inst.name.clone(),
                    instance,
                    mesh: inst.mesh,
                    label: 0,
                    triangles: scene.mesh(inst.mesh).triangle_count() as u32,
                });
                parts.instances.push(InstanceParts { first_part, part_count: 1, labels: MeshLabels::Whole });
            }
            Some(table) => {
                let count = table.label_count();
                for label in 0..count {
                    parts.parts.push(Part {
                        name: format!("{}#{label}", inst.name),
                        instance,
                        mesh: inst.mesh,
                        label,
                        triangles: table.triangles(label).len() as u32,
                    });
                }
                parts.instances.push(InstanceParts {
                    first_part,
                    part_count: count,
                    labels: MeshLabels::PerTriangle(table),
                });
            }
        }
    }
    (parts, diagnostics)
}

/// One mesh's segmentation and what happened on the way.
struct MeshResult {
    /// `None` when the whole mesh is one part.
    table: Option<Arc<LabelTable>>,
    unpaired_edges: usize,
    /// Non-manifold edges paired in part, and the faces left over there.
    partial_edges: usize,
    left_open: usize,
    /// Open pieces glued to another across a crack.
    glued: usize,
    before_merge: u32,
    merged: usize,
    untouched: usize,
    kept: usize,
}

fn segment_mesh(
    mesh: &Mesh,
    topology: Option<&Topology>,
    mode: SegmentMode,
    merge: bool,
    options: &SegmentOptions,
) -> MeshResult {
    let built;
    let topo = match topology {
        // A topology of another mesh would index out of bounds: build the right one instead.
        Some(t) if t.faces.len() == mesh.triangle_count() && t.welded_of_vertex.len() == mesh.vertex_count() => t,
        _ => {
            built = Topology::build(mesh, options.weld);
            &built
        }
    };
    let mut labelling = match mode {
        SegmentMode::Regions => connect::regions(topo, options.region_angle_deg, options.fan_pairing),
        _ => connect::components(topo, options.fan_pairing),
    };
    // The fractions below are of the robust diagonal: one stray vertex must not make every free
    // edge "near" (stitch), nor every part "small" and every probe "touching" every triangle (merge:
    // the contact pairs would grow with the product of probes and triangles;
    // `tests/regressions/obj/separate-triangles-one-far-vertex.obj`).
    let diagonal = drafter_core::robust_diagonal(&mesh.positions);
    let mut glued = 0;
    if merge && options.stitch_fraction > 0.0 && labelling.count > 1 {
        let limits = stitch::StitchLimits {
            tolerance: options.stitch_fraction * diagonal,
            sealed_fraction: STITCH_SEALED_FRACTION,
            share_fraction: STITCH_SHARE_FRACTION,
        };
        if let Some(outcome) = stitch::stitch_cracks(topo, &labelling, &limits) {
            glued = outcome.glued;
            labelling.labels = outcome.labels;
            labelling.count = outcome.count;
            labelling.open = outcome.open;
        }
    }
    let before_merge = labelling.count;
    let (mut merged, mut untouched, mut kept) = (0, 0, 0);
    if merge && labelling.count > 1 {
        let limits = merge::MergeLimits {
            max_triangles: options.merge_triangle_fraction * mesh.triangle_count() as f64,
            max_diagonal: options.merge_diagonal_fraction * diagonal,
            touch_distance: options.touch_fraction.max(0.0) * diagonal,
            max_absorbed: options.max_absorbed_fraction.max(0.0),
        };
        let outcome = merge::merge_small(topo, &labelling, &limits);
        (merged, untouched, kept) = (outcome.merged, outcome.untouched, outcome.kept);
        labelling.labels = outcome.labels;
        labelling.count = outcome.count;
    }
    let table = (labelling.count > 1).then(|| Arc::new(LabelTable::new(labelling.labels, labelling.count)));
    MeshResult {
        table,
        unpaired_edges: labelling.unpaired_edges.len(),
        partial_edges: labelling.partial_edges.len(),
        left_open: labelling.left_open,
        glued,
        before_merge,
        merged,
        untouched,
        kept,
    }
}

fn diagnostics<'a>(results: impl Iterator<Item = &'a MeshResult> + Clone) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let unpaired: usize = results.clone().map(|r| r.unpaired_edges).sum();
    if unpaired > 0 {
        out.push(Diagnostic {
            kind: DiagnosticKind::UnpairedNonManifoldEdge,
            count: unpaired,
            first_example: format!(
                "{unpaired} non-manifold edges could not be paired into solids (odd count or inconsistent orientation); parts are cut there"
            ),
        });
    }
    let partial: usize = results.clone().map(|r| r.partial_edges).sum();
    if partial > 0 {
        let left: usize = results.clone().map(|r| r.left_open).sum();
        out.push(Diagnostic {
            kind: DiagnosticKind::PartlyPairedNonManifoldEdge,
            count: partial,
            first_example: format!(
                "{partial} non-manifold edges could be paired into solids only in part (odd count: a cracked part touching a solid \
                 along its edge, or overlapping solids); {left} faces there were left unpaired, as free edges of their parts"
            ),
        });
    }
    let glued: usize = results.clone().map(|r| r.glued).sum();
    if glued > 0 {
        out.push(Diagnostic {
            kind: DiagnosticKind::GluedCrack,
            count: glued,
            first_example: format!(
                "{glued} open pieces were glued to the pieces whose free edges their own lie on (cracks: T-junction seams \
                 between faces of one part); check the parts if separate open parts of an assembly meet rim to rim"
            ),
        });
    }
    let merged: usize = results.clone().map(|r| r.merged).sum();
    if merged > 0 {
        let before: u32 = results.clone().filter(|r| r.merged > 0).map(|r| r.before_merge).sum();
        let untouched: usize = results.clone().map(|r| r.untouched).sum();
        let kept: usize = results.map(|r| r.kept).sum();
        out.push(Diagnostic {
            kind: DiagnosticKind::MergedSliver,
            count: merged,
            first_example: format!(
                "{merged} of {before} components were small and merged into a touching neighbour; \
                 {untouched} small ones touch nothing and {kept} touch only parts without room, and stay"
            ),
        });
    }
    out
}
