//! Edge classes on the welded topology.
//!
//! Every undirected edge of a [`Topology`] gets one [`EdgeClass`], decided in this order (the first
//! rule that applies wins):
//!
//! 1. one incident face: [`EdgeClass::Boundary`];
//! 2. three or more: [`EdgeClass::NonManifold`];
//! 3. two faces of different parts (when part ids are given): [`EdgeClass::PartBorder`];
//! 4. a degenerate incident face (zero area or a repeated welded vertex, so no normal):
//!    [`EdgeClass::Degenerate`] — neither a crease nor a silhouette candidate, encoded hidden. Such
//!    faces are slivers that close T-junctions of CAD tessellations; drawing their edges would draw
//!    seams, and their missing normal makes the front/back test meaningless;
//! 5. dihedral angle (the angle between the two face normals) above
//!    [`LineOptions::crease_angle_deg`]: [`EdgeClass::Crease`], unless the crease is a speck (below);
//! 6. two faces of different input faces (when [`FaceLabels::input_faces`] are given: the glTF
//!    primitives of one mesh, which OpenCascade and most CAD exporters write one per B-rep face):
//!    at or below [`LineOptions::coplanar_angle_deg`] [`EdgeClass::Coplanar`] (a planar face split
//!    in two: a seam, not drawn), otherwise [`EdgeClass::Tangent`] (a fillet meeting a plane, a
//!    pipe meeting a casing: the tangent edges CAD viewers draw by default);
//! 7. dihedral angle at or below [`LineOptions::coplanar_angle_deg`]: [`EdgeClass::Coplanar`]
//!    (hidden: a silhouette between coplanar faces is invisible);
//! 8. otherwise: [`EdgeClass::SilhouetteCandidate`].
//!
//! **Creases kept whole (hysteresis).** A CAD chamfer of exactly the crease angle tessellates at
//! angles on both sides of it (a 30° chamfer at 29.5–30.5°), so a threshold alone draws its circle
//! dotted. As Canny's edge detector does along its lines, a crease chain is continued past its end:
//! at a welded vertex where exactly one hard edge ends, and that edge is a crease, the edge that
//! continues the chain most straightly (smallest turn, among all the vertex's other edges) is
//! followed when it is a silhouette candidate whose dihedral angle is above
//! [`LineOptions::crease_continue`] × the crease angle and its turn is below
//! [`LineOptions::crease_turn_deg`], and the walk goes on from its far end. It stops when the
//! straightest edge fails either test or leads back onto the walk, and then changes nothing; when
//! it reaches a vertex with another hard edge (the next dot of a dotted chamfer, or the chain's own
//! other end around a circle), the gap is bridged and the edges it walked become creases. So it
//! bridges gaps and never extends a chain into the open: on range scans, open-ended hysteresis
//! grows noise lines trailing every feature's end, far more added creases than bridging alone
//! (docs/drawing.md, "Creases kept whole"). It follows one line, never floods: the facet lines of a
//! cylinder meet its crease circles at 90° and a closed circle has no end, and a surface without
//! creases gains none. Ends are visited in vertex order and the walk is serial, so the result
//! depends on the topology alone. The continued edges count in [`EdgeClassCounts::continued`] (and
//! in [`EdgeClassCounts::crease`]).
//!
//! **Specks.** Range scans are covered in creases of a few edges each that are noise, not features
//! (the dragon: 686 isolated crease edges and 1,061 chains of 2 or 3 at 30°). Hard edges are joined
//! into chains through their welded vertices; a chain made of creases alone, with fewer than
//! [`LineOptions::crease_min_edges`] edges, shorter than [`LineOptions::crease_min_length`] of the
//! mesh's bounding diagonal, none of whose dihedral angles exceeds
//! [`LineOptions::strong_crease_deg`], is a speck: its edges are silhouette candidates instead (their
//! faces are not coplanar), so silhouettes stay exact. Edges, length and strength count the chain's
//! creases above the angle only: continued edges join creases into one chain (a dotted chamfer's
//! dots become one loop) but never make a speck a feature by themselves, so a speck of scan noise
//! that hysteresis lengthened is still a speck, continued edges and all. A crease that touches a
//! boundary, a part border, a tangent edge, a non-manifold edge or a longer chain is kept (weak
//! creases continue a feature: hysteresis by length), and so is a short one sharper than the strong
//! angle or long against the model (a coarse CAD fillet's facet line is one long edge). CAD
//! tessellations keep their feature lines; what they lose are the same kind of specks, single edges
//! of 30–39° on curved faces (GearboxAssy: 2,846 of 30,534; every shared model is counted in
//! `docs/bench.md`, "Crease specks").
//!
//! Face normals are computed in `f64` from the welded `f32` positions ((b − a) × (c − a), normalised),
//! so the dihedral angles do not depend on the weld representative's rounding. Candidates keep their
//! two normals rounded to `f32` (face with the smaller index first): these `f32` vectors are what
//! every silhouette query of this crate evaluates, bit for bit.
//!
//! The orientation of the two faces is not repaired: if they traverse their shared edge in the same
//! direction (inconsistent winding) the dihedral angle is measured between the normals as they are,
//! which usually makes the edge a crease. Such edges are counted in
//! [`EdgeClassCounts::inconsistent_orientation`].

use drafter_core::{Diagnostic, DiagnosticKind, Diagnostics, PartId, Topology};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::LinesError;

/// Default dihedral angle, in degrees, above which a manifold edge is a crease (Gooch et al. 1999
/// leave it to the user; 30° is the common CAD default and what trimesh-based checks use).
pub const DEFAULT_CREASE_ANGLE_DEG: f32 = 30.0;

/// Default dihedral angle, in degrees, at or below which two faces count as coplanar. It absorbs the
/// `f32` rounding of positions on planar CAD faces (normals of a 1/1000-of-the-model triangle move
/// by about 1e-5 rad ≈ 6e-4°) while keeping the finest real tessellation (≥ 0.01°) as candidates.
pub const DEFAULT_COPLANAR_ANGLE_DEG: f32 = 1e-3;

/// Default of [`LineOptions::crease_min_edges`]: isolated crease chains of 1 to 3 edges are specks.
pub const DEFAULT_CREASE_MIN_EDGES: u32 = 4;

/// Default of [`LineOptions::strong_crease_deg`]: twice the default crease angle.
pub const DEFAULT_STRONG_CREASE_DEG: f32 = 60.0;

/// Default of [`LineOptions::crease_min_length`]: 1% of the mesh's bounding diagonal.
pub const DEFAULT_CREASE_MIN_LENGTH: f32 = 0.01;

/// Default of [`LineOptions::crease_continue`]: a gap in a crease chain is bridged along edges above
/// 0.9 × the crease angle (27° at the default 30°). CAD tessellators keep a chamfer's facets within
/// a few tenths of a degree of its angle (29.5–30.5° for a 30° chamfer), well inside; on range
/// scans, where near-creases are noise, 0.9 bridges about half as much as 0.8 (`crease_survey` in
/// drafter-bake's examples, figures in `docs/drawing.md`, "Creases kept whole").
pub const DEFAULT_CREASE_CONTINUE: f32 = 0.9;

/// Default of [`LineOptions::crease_turn_deg`]: a continued crease turns by less than 45° per
/// vertex (a circle's tessellation turns by 360°/n; a facet line meets a crease circle at 90°).
pub const DEFAULT_CREASE_TURN_DEG: f32 = 45.0;

/// Options of [`classify_edges`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LineOptions {
    /// Dihedral angle in degrees above which a manifold edge is a crease.
    /// Default [`DEFAULT_CREASE_ANGLE_DEG`]; range `[0, 180]` (180 turns creases off).
    pub crease_angle_deg: f32,
    /// Dihedral angle in degrees at or below which the two faces count as coplanar (hidden edge).
    /// Default [`DEFAULT_COPLANAR_ANGLE_DEG`]; range `[0, crease_angle_deg]`; a negative value makes
    /// even exactly coplanar faces candidates.
    pub coplanar_angle_deg: f32,
    /// A chain of creases alone (no other hard edge touching it) with fewer edges than this is a
    /// speck unless it holds a crease sharper than [`Self::strong_crease_deg`] (module docs).
    /// Default [`DEFAULT_CREASE_MIN_EDGES`]; 0 or 1 keeps every crease.
    pub crease_min_edges: u32,
    /// A short chain holding a crease sharper than this, in degrees, is kept. Default
    /// [`DEFAULT_STRONG_CREASE_DEG`].
    pub strong_crease_deg: f32,
    /// A short chain at least this long, as a fraction of the mesh's bounding diagonal, is kept (a
    /// coarse CAD fillet's facet line is one long edge). Default [`DEFAULT_CREASE_MIN_LENGTH`].
    pub crease_min_length: f32,
    /// Hysteresis: a crease chain is continued along the straightest edge whose dihedral angle is
    /// above this fraction of [`Self::crease_angle_deg`] (module docs). Default
    /// [`DEFAULT_CREASE_CONTINUE`]; range `[0, 1]`, 1 (or more) turns continuation off.
    pub crease_continue: f32,
    /// Hysteresis: the most a continued chain turns at a vertex, in degrees. Default
    /// [`DEFAULT_CREASE_TURN_DEG`]; range `[0, 180]`.
    pub crease_turn_deg: f32,
}

impl Default for LineOptions {
    fn default() -> Self {
        Self {
            crease_angle_deg: DEFAULT_CREASE_ANGLE_DEG,
            coplanar_angle_deg: DEFAULT_COPLANAR_ANGLE_DEG,
            crease_min_edges: DEFAULT_CREASE_MIN_EDGES,
            strong_crease_deg: DEFAULT_STRONG_CREASE_DEG,
            crease_min_length: DEFAULT_CREASE_MIN_LENGTH,
            crease_continue: DEFAULT_CREASE_CONTINUE,
            crease_turn_deg: DEFAULT_CREASE_TURN_DEG,
        }
    }
}

/// Per-face labels that make borders, one entry per face of the topology when given.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FaceLabels<'a> {
    /// The part of each face: edges between parts are [`EdgeClass::PartBorder`].
    pub parts: Option<&'a [PartId]>,
    /// The input face of each face (for glTF, the primitive it was read from): edges between
    /// input faces are [`EdgeClass::Tangent`] below the crease angle (module docs). `None`: one
    /// input face.
    pub input_faces: Option<&'a [u32]>,
}

/// The class of one welded edge. See the module docs for the order in which rules apply.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum EdgeClass {
    /// Exactly one incident face. Hard edge.
    Boundary = 0,
    /// Three or more incident faces. Hard edge.
    NonManifold = 1,
    /// Two faces of different parts. Hard edge.
    PartBorder = 2,
    /// Dihedral angle above the crease threshold. Hard edge.
    Crease = 3,
    /// A manifold edge whose faces are not coplanar: a silhouette from some views.
    SilhouetteCandidate = 4,
    /// Coplanar faces: never drawn.
    Coplanar = 5,
    /// A degenerate incident face (no normal): never drawn.
    Degenerate = 6,
    /// Two faces of different input faces (CAD faces) meeting below the crease angle: a tangent
    /// edge. Hard edge (drawn as CAD viewers draw tangent edges; a drawing may leave it out).
    Tangent = 7,
}

impl EdgeClass {
    /// All classes, in code order.
    pub const ALL: [EdgeClass; 8] = [
        EdgeClass::Boundary,
        EdgeClass::NonManifold,
        EdgeClass::PartBorder,
        EdgeClass::Crease,
        EdgeClass::SilhouetteCandidate,
        EdgeClass::Coplanar,
        EdgeClass::Degenerate,
        EdgeClass::Tangent,
    ];

    /// Hard edges are always drawn (value 2/3 of `EXT_mesh_primitive_edge_visibility`).
    pub fn is_hard(self) -> bool {
        matches!(self, Self::Boundary | Self::NonManifold | Self::PartBorder | Self::Crease | Self::Tangent)
    }

    /// The stable numeric code (the `repr(u8)` value), as written to files.
    pub fn code(self) -> u8 {
        self as u8
    }

    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }
}

/// How many edges fell in each class, plus data problems met on the way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct EdgeClassCounts {
    pub boundary: usize,
    pub non_manifold: usize,
    pub part_border: usize,
    pub crease: usize,
    pub silhouette_candidate: usize,
    pub coplanar: usize,
    pub degenerate: usize,
    /// Borders of input faces below the crease angle ([`EdgeClass::Tangent`]).
    #[serde(default)]
    pub tangent: usize,
    /// Of the creases, those below the crease angle that continue a chain (hysteresis, module docs).
    #[serde(default)]
    pub continued: usize,
    /// Manifold edges whose two faces traverse them in the same direction (any class).
    pub inconsistent_orientation: usize,
}

impl EdgeClassCounts {
    pub fn of(&self, class: EdgeClass) -> usize {
        match class {
            EdgeClass::Boundary => self.boundary,
            EdgeClass::NonManifold => self.non_manifold,
            EdgeClass::PartBorder => self.part_border,
            EdgeClass::Crease => self.crease,
            EdgeClass::SilhouetteCandidate => self.silhouette_candidate,
            EdgeClass::Coplanar => self.coplanar,
            EdgeClass::Degenerate => self.degenerate,
            EdgeClass::Tangent => self.tangent,
        }
    }

    /// Hard edges: boundary + non-manifold + part border + crease + tangent.
    pub fn hard(&self) -> usize {
        self.boundary + self.non_manifold + self.part_border + self.crease + self.tangent
    }

    fn add(&mut self, class: EdgeClass) {
        match class {
            EdgeClass::Boundary => self.boundary += 1,
            EdgeClass::NonManifold => self.non_manifold += 1,
            EdgeClass::PartBorder => self.part_border += 1,
            EdgeClass::Crease => self.crease += 1,
            EdgeClass::SilhouetteCandidate => self.silhouette_candidate += 1,
            EdgeClass::Coplanar => self.coplanar += 1,
            EdgeClass::Degenerate => self.degenerate += 1,
            EdgeClass::Tangent => self.tangent += 1,
        }
    }
}

/// The classified edges of one mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FeatureEdges {
    /// Class of every edge of the topology, indexed like `Topology::edges`.
    pub classes: Vec<EdgeClass>,
    /// Dihedral angle in degrees of every edge with two non-degenerate faces; NaN for the others.
    /// Empty from [`classify_edges_for_encoding`].
    pub dihedral_deg: Vec<f32>,
    /// Unit normal of every face in `f64`; `None` for degenerate faces.
    pub face_normals: Vec<Option<DVec3>>,
    /// Edge id of each silhouette candidate, increasing. A [`crate::SilhouetteIndex`] may renumber
    /// its candidates; its answers are indices into [`crate::SilhouetteIndex::candidate_edges`].
    pub candidates: Vec<u32>,
    /// The two face normals of each candidate, rounded to `f32` (face with the smaller index first).
    pub candidate_normals: Vec<[Vec3; 2]>,
    /// The point `v` of each candidate used by the perspective test: its first welded vertex
    /// (`Topology::edges[e][0]`).
    pub candidate_points: Vec<Vec3>,
    pub counts: EdgeClassCounts,
}

impl FeatureEdges {
    /// Data problems as diagnostics (degenerate neighbours, inconsistent orientation).
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        let mut d = Diagnostics::new();
        d.push(DiagnosticKind::DegenerateEdge, self.counts.degenerate, || {
            format!("{} edges border a degenerate face and are never drawn", self.counts.degenerate)
        });
        d.push(DiagnosticKind::InconsistentWinding, self.counts.inconsistent_orientation, || {
            format!(
                "{} manifold edges join faces of inconsistent winding; their dihedral angle uses the normals as given",
                self.counts.inconsistent_orientation
            )
        });
        d.into_vec()
    }

    /// Edge ids of every edge of `class`, increasing.
    pub fn edges_of_class(&self, class: EdgeClass) -> Vec<u32> {
        (0..self.classes.len() as u32).filter(|&e| self.classes[e as usize] == class).collect()
    }
}

/// Unit face normals in `f64`; `None` where the face is degenerate.
pub fn face_normals(topology: &Topology) -> Vec<Option<DVec3>> {
    topology
        .faces
        .par_iter()
        .enumerate()
        .map(|(f, &[a, b, c])| {
            if topology.face_degenerate.get(f).copied().unwrap_or(false) {
                return None;
            }
            let p = |v: u32| topology.welded_positions[v as usize].as_dvec3();
            let n = (p(b) - p(a)).cross(p(c) - p(a));
            let len = n.length();
            (len > 0.0 && len.is_finite()).then(|| n / len)
        })
        .collect()
}

/// "Is the dihedral angle `atan2(sine, cosine)` in degrees (`sine = |n₁ × n₂|`, `cosine = n₁·n₂`,
/// accurate near 0° and 180°) above `threshold`?", answered as the arctangent answers it but mostly
/// without it (an `atan2` per edge was a large share of the classification). For `sine ≥ 0` the
/// angle lies in `[0°, 180°]` and, for a threshold `α` strictly inside that range, `sine·cos α −
/// cosine·sin α` has the sign of the angle minus `α`.
/// Both the product and the arctangent are accurate to a few units in the last place, so where
/// that sign clears [`AngleTest::MARGIN`] of `|sine| + |cosine|` they agree; nearer, and for a
/// threshold outside the open range, the arctangent decides.
#[derive(Clone, Copy, Debug)]
struct AngleTest {
    threshold: f64,
    /// `(sin α, cos α)` for `α` strictly between 0° and 180°.
    sin_cos: Option<(f64, f64)>,
}

impl AngleTest {
    /// A relative margin some thousand times the rounding of either side.
    const MARGIN: f64 = 1e-12;

    fn new(threshold: f64) -> Self {
        let inside = threshold > 0.0 && threshold < 180.0;
        AngleTest { threshold, sin_cos: inside.then(|| threshold.to_radians().sin_cos()) }
    }

    #[inline]
    fn above(&self, sine: f64, cosine: f64) -> bool {
        if let Some((sin, cos)) = self.sin_cos {
            let t = sine * cos - cosine * sin;
            let margin = Self::MARGIN * (sine.abs() + cosine.abs());
            if t > margin {
                return true;
            }
            if t < -margin {
                return false;
            }
        }
        sine.atan2(cosine).to_degrees() > self.threshold
    }
}

/// Classifies every edge of `topology`. `face_parts`, when given, holds one part id per face.
pub fn classify_edges(
    topology: &Topology,
    face_parts: Option<&[PartId]>,
    options: &LineOptions,
) -> Result<FeatureEdges, LinesError> {
    classify(topology, FaceLabels { parts: face_parts, input_faces: None }, options, true)
}

/// [`classify_edges`] with every per-face label: parts and input faces ([`FaceLabels`]).
pub fn classify_edges_labelled(
    topology: &Topology,
    labels: FaceLabels<'_>,
    options: &LineOptions,
) -> Result<FeatureEdges, LinesError> {
    classify(topology, labels, options, true)
}

/// [`classify_edges_labelled`] for the edge encoder alone: [`FeatureEdges::candidate_normals`] and
/// [`FeatureEdges::candidate_points`] are left empty (tens of megabytes on a large scan),
/// which the encoder does not read, and so is [`FeatureEdges::dihedral_deg`] (the classes come
/// out the same, mostly without an arctangent per edge). Do not build a
/// [`crate::SilhouetteIndex`] from the result.
pub fn classify_edges_for_encoding(
    topology: &Topology,
    labels: FaceLabels<'_>,
    options: &LineOptions,
) -> Result<FeatureEdges, LinesError> {
    classify(topology, labels, options, false)
}

fn classify(
    topology: &Topology,
    labels: FaceLabels<'_>,
    options: &LineOptions,
    candidate_arrays: bool,
) -> Result<FeatureEdges, LinesError> {
    let face_parts = labels.parts;
    if let Some(parts) = face_parts
        && parts.len() != topology.faces.len()
    {
        return Err(LinesError::PartCount { parts: parts.len(), faces: topology.faces.len() });
    }
    // One input face in all is no border anywhere.
    let input_faces = labels.input_faces.filter(|f| f.first().is_some_and(|&first| f.iter().any(|&x| x != first)));
    if let Some(faces) = input_faces
        && faces.len() != topology.faces.len()
    {
        return Err(LinesError::InputFaceCount { labels: faces.len(), faces: topology.faces.len() });
    }
    let face_normals = face_normals(topology);
    let crease = f64::from(options.crease_angle_deg);
    let coplanar = f64::from(options.coplanar_angle_deg);
    // Each threshold is compared without an arctangent where that decides it (see `AngleTest`).
    let (crease_test, coplanar_test) = (AngleTest::new(crease), AngleTest::new(coplanar));
    let per_edge: Vec<(EdgeClass, f32, bool)> = (0..topology.edges.len())
        .into_par_iter()
        .map(|e| {
            let faces = topology.faces_of_edge(e);
            match faces.len() {
                0 | 1 => return (EdgeClass::Boundary, f32::NAN, false),
                2 => {}
                _ => return (EdgeClass::NonManifold, f32::NAN, false),
            }
            let (f1, f2) = (faces[0] as usize, faces[1] as usize);
            let consistent = runs_forward(topology, f1, e) != runs_forward(topology, f2, e);
            // The sine and cosine of the dihedral angle (both faces have a normal); the classes come
            // from them without an arctangent, the angle itself only where it is kept.
            let angle = face_normals[f1].zip(face_normals[f2]).map(|(n1, n2)| (n1.cross(n2).length(), n1.dot(n2)));
            let border = input_faces.is_some_and(|f| f[f1] != f[f2]);
            let class = match angle {
                _ if face_parts.is_some_and(|p| p[f1] != p[f2]) => EdgeClass::PartBorder,
                None => EdgeClass::Degenerate,
                Some((sine, cosine)) if crease_test.above(sine, cosine) => EdgeClass::Crease,
                Some((sine, cosine)) if !coplanar_test.above(sine, cosine) => EdgeClass::Coplanar,
                Some(_) if border => EdgeClass::Tangent,
                Some(_) => EdgeClass::SilhouetteCandidate,
            };
            let dihedral = match angle {
                Some((sine, cosine)) if candidate_arrays => sine.atan2(cosine).to_degrees(),
                _ => f64::NAN,
            };
            (class, dihedral as f32, !consistent)
        })
        .collect();

    let mut per_edge = per_edge;
    let continued = continue_creases(topology, &face_normals, options, &mut per_edge);
    drop_specks(topology, &face_normals, options, &continued, &mut per_edge);
    let mut counts = EdgeClassCounts::default();
    for (e, &(class, _, inconsistent)) in per_edge.iter().enumerate() {
        counts.add(class);
        counts.inconsistent_orientation += usize::from(inconsistent);
        counts.continued += usize::from(class == EdgeClass::Crease && continued.get(e).copied().unwrap_or(false));
    }
    // The arrays on the thread pool (in edge order, as a serial loop gives them).
    let classes: Vec<EdgeClass> = per_edge.par_iter().map(|p| p.0).collect();
    let dihedral_deg: Vec<f32> = if candidate_arrays { per_edge.par_iter().map(|p| p.1).collect() } else { Vec::new() };
    drop(per_edge);
    let candidates: Vec<u32> = (0..classes.len())
        .into_par_iter()
        .filter(|&e| classes[e] == EdgeClass::SilhouetteCandidate)
        .map(|e| e as u32)
        .collect();
    let (candidate_normals, candidate_points) = if candidate_arrays {
        let normal = |f: u32| face_normals[f as usize].map_or(Vec3::ZERO, |n| n.as_vec3());
        candidates
            .par_iter()
            .map(|&e| {
                let faces = topology.faces_of_edge(e as usize);
                let point = topology.welded_positions[topology.edges[e as usize][0] as usize];
                ([normal(faces[0]), normal(faces[1])], point)
            })
            .unzip()
    } else {
        (Vec::new(), Vec::new())
    };
    Ok(FeatureEdges { classes, dihedral_deg, face_normals, candidates, candidate_normals, candidate_points, counts })
}

/// The most edges one continuation walk takes (a bound on the work, far above any gap of a CAD
/// tessellation).
const MAX_WALK: usize = 1 << 16;

/// Continues crease chains past their ends along near-creases where that bridges a gap to another
/// hard edge (hysteresis, module docs). Returns, per edge, whether it became a crease here (empty
/// when nothing did).
fn continue_creases(
    topology: &Topology,
    face_normals: &[Option<DVec3>],
    options: &LineOptions,
    per_edge: &mut [(EdgeClass, f32, bool)],
) -> Vec<bool> {
    if options.crease_continue.is_nan()
        || options.crease_continue >= 1.0
        || !per_edge.iter().any(|p| p.0 == EdgeClass::Crease)
    {
        return Vec::new();
    }
    let low = AngleTest::new(f64::from(options.crease_angle_deg) * f64::from(options.crease_continue.max(0.0)));
    let min_cos = f64::from(options.crease_turn_deg).clamp(0.0, 180.0).to_radians().cos();
    // Hard edges at each welded vertex (saturating), and the last one seen.
    let vertex_count = topology.welded_positions.len();
    let mut degree = vec![0u8; vertex_count];
    let mut last = vec![u32::MAX; vertex_count];
    for (e, p) in per_edge.iter().enumerate() {
        if p.0.is_hard() {
            for v in topology.edges[e] {
                degree[v as usize] = degree[v as usize].saturating_add(1);
                last[v as usize] = e as u32;
            }
        }
    }
    let position = |v: u32| topology.welded_positions[v as usize].as_dvec3();
    let near_crease = |e: usize| {
        let faces = topology.faces_of_edge(e);
        faces.len() == 2
            && face_normals[faces[0] as usize]
                .zip(face_normals[faces[1] as usize])
                .is_some_and(|(n1, n2)| low.above(n1.cross(n2).length(), n1.dot(n2)))
    };
    let mut continued = vec![false; per_edge.len()];
    // The walk's own vertices, stamped with its start; its edges, committed only when it meets
    // another hard edge.
    let mut on_walk = vec![u32::MAX; vertex_count];
    let mut path: Vec<u32> = Vec::new();
    for start in 0..vertex_count as u32 {
        if degree[start as usize] != 1 || per_edge[last[start as usize] as usize].0 != EdgeClass::Crease {
            continue;
        }
        path.clear();
        on_walk[start as usize] = start;
        let (mut v, mut arrived) = (start, last[start as usize]);
        let met = loop {
            if path.len() >= MAX_WALK {
                break false;
            }
            let [a, b] = topology.edges[arrived as usize];
            let from = if a == v { b } else { a };
            let Some(heading) = (position(v) - position(from)).try_normalize() else { break false };
            // The straightest other edge at v (smallest turn; the smaller edge id on a tie).
            let mut best: Option<(f64, u32)> = None;
            for &f in topology.faces_of_vertex(v as usize) {
                for &e in &topology.face_edges[f as usize] {
                    if e == drafter_core::EDGE_NONE || e == arrived || !topology.edges[e as usize].contains(&v) {
                        continue;
                    }
                    let [a, b] = topology.edges[e as usize];
                    let to = if a == v { b } else { a };
                    let Some(direction) = (position(to) - position(v)).try_normalize() else { continue };
                    let straight = heading.dot(direction);
                    if best.is_none_or(|(s, id)| straight > s || (straight == s && e < id)) {
                        best = Some((straight, e));
                    }
                }
            }
            let Some((straight, e)) = best else { break false };
            if straight < min_cos
                || per_edge[e as usize].0 != EdgeClass::SilhouetteCandidate
                || !near_crease(e as usize)
            {
                break false;
            }
            let [a, b] = topology.edges[e as usize];
            let to = if a == v { b } else { a };
            if to == start || on_walk[to as usize] == start {
                break false; // back on its own path
            }
            path.push(e);
            if degree[to as usize] > 0 {
                break true; // another hard edge: the gap is bridged
            }
            on_walk[to as usize] = start;
            (v, arrived) = (to, e);
        };
        if met {
            for &e in &path {
                per_edge[e as usize].0 = EdgeClass::Crease;
                continued[e as usize] = true;
                for v in topology.edges[e as usize] {
                    degree[v as usize] = degree[v as usize].saturating_add(1);
                    last[v as usize] = e;
                }
            }
        }
    }
    continued
}

/// Turns the creases of speck chains into silhouette candidates (module docs). Chains are the
/// connected components of the hard edges through their welded vertices (union-find over the
/// vertices, in edge order: the result depends on the topology alone). `continued` marks the
/// creases of [`continue_creases`] (empty: none), which join chains without counting in them.
fn drop_specks(
    topology: &Topology,
    face_normals: &[Option<DVec3>],
    options: &LineOptions,
    continued: &[bool],
    per_edge: &mut [(EdgeClass, f32, bool)],
) {
    if options.crease_min_edges <= 1 || !per_edge.iter().any(|p| p.0 == EdgeClass::Crease) {
        return;
    }
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let up = parent[parent[v as usize] as usize];
            parent[v as usize] = up;
            v = up;
        }
        v
    }
    let mut parent: Vec<u32> = (0..topology.welded_positions.len() as u32).collect();
    for (e, p) in per_edge.iter().enumerate() {
        if p.0.is_hard() {
            let [a, b] = topology.edges[e];
            let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb) as usize] = ra.min(rb);
            }
        }
    }
    // Per chain (its root vertex): hard edges, whether all are creases, whether one is strong.
    #[derive(Clone, Copy, Default)]
    struct Chain {
        edges: u32,
        length: f64,
        other_hard: bool,
        strong: bool,
    }
    let (lo, hi) = topology
        .welded_positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let min_length = f64::from(options.crease_min_length) * f64::from((hi - lo).length());
    let mut chains: std::collections::HashMap<u32, Chain> = std::collections::HashMap::new();
    let strong = AngleTest::new(f64::from(options.strong_crease_deg));
    for (e, p) in per_edge.iter().enumerate() {
        if !p.0.is_hard() {
            continue;
        }
        let [a, b] = topology.edges[e];
        let chain = chains.entry(root(&mut parent, a)).or_default();
        if continued.get(e).copied().unwrap_or(false) {
            continue;
        }
        chain.edges = chain.edges.saturating_add(1);
        chain.length +=
            f64::from(topology.welded_positions[a as usize].distance(topology.welded_positions[b as usize]));
        if p.0 == EdgeClass::Crease {
            let faces = topology.faces_of_edge(e);
            let angle = face_normals[faces[0] as usize]
                .zip(face_normals[faces[1] as usize])
                .map(|(n1, n2)| (n1.cross(n2).length(), n1.dot(n2)));
            chain.strong |= angle.is_some_and(|(sine, cosine)| strong.above(sine, cosine));
        } else {
            chain.other_hard = true;
        }
    }
    for (e, p) in per_edge.iter_mut().enumerate() {
        if p.0 != EdgeClass::Crease {
            continue;
        }
        let chain = chains[&root(&mut parent, topology.edges[e][0])];
        if !chain.other_hard && !chain.strong && chain.edges < options.crease_min_edges && chain.length < min_length {
            p.0 = EdgeClass::SilhouetteCandidate;
        }
    }
}

/// Whether face `f` traverses edge `e` from its smaller to its larger welded vertex.
fn runs_forward(topology: &Topology, f: usize, e: usize) -> bool {
    let tri = topology.faces[f];
    let k = topology.face_edges[f].iter().position(|&x| x as usize == e).unwrap_or(0);
    tri[k] < tri[(k + 1) % 3]
}

#[cfg(test)]
mod tests {
    use drafter_core::Weld;

    /// The threshold test without an arctangent answers as the arctangent does: on random
    /// angles, on angles a few units in the last place from each threshold, and on the angle
    /// between unit normals turned by exactly the threshold (a 12-gon's 30° edges), for
    /// thresholds inside and outside (0°, 180°).
    #[test]
    fn angle_test_answers_as_the_arctangent() {
        let mut rng = drafter_core::rng::Rng::new(17);
        for threshold in [30.0, 0.001, 1e-9, 45.0, 90.0, 120.0, 179.999, 0.0, 180.0, -1.0, 200.0] {
            let test = super::AngleTest::new(threshold);
            let rule = |s: f64, c: f64| s.atan2(c).to_degrees() > threshold;
            let alpha = threshold.clamp(0.0, 180.0).to_radians();
            let mut pairs: Vec<(f64, f64)> = Vec::new();
            for _ in 0..20_000 {
                let r = 10f64.powf(f64::from(rng.unit_f32()) * 8.0 - 4.0);
                let theta = f64::from(rng.unit_f32()) * std::f64::consts::PI;
                pairs.push((r * theta.sin(), r * theta.cos()));
                let near = alpha + (f64::from(rng.unit_f32()) - 0.5) * 1e-13;
                pairs.push((near.sin().abs(), near.cos()));
                let n1 = rng.direction_f32().as_dvec3().normalize();
                let axis = n1.any_orthonormal_vector();
                let n2 = glam::DQuat::from_axis_angle(axis, alpha) * n1;
                pairs.push((n1.cross(n2).length(), n1.dot(n2)));
            }
            pairs.extend([(0.0, 1.0), (0.0, -1.0), (1.0, 0.0), (0.0, 0.0), (1e-300, 1.0)]);
            for (s, c) in pairs {
                assert_eq!(test.above(s, c), rule(s, c), "threshold {threshold}: sine {s:e}, cosine {c:e}");
            }
        }
    }

    use super::*;

    /// A unit cube with a ridge: the top face split into two triangles that fold up by `tilt`.
    fn tent(height: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, height),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        // Two triangles sharing the diagonal 0-2.
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    /// A closed cube whose faces are `n` × `n` grids: its interior edges are coplanar, its cube
    /// edges 90° creases.
    fn grid_cube(n: u32) -> Topology {
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        let axes = [Vec3::X, Vec3::Y, Vec3::Z];
        for (k, &normal) in axes.iter().enumerate() {
            for sign in [-1.0f32, 1.0] {
                let (u, v) = (axes[(k + 1) % 3], axes[(k + 2) % 3]);
                let (u, v) = if sign > 0.0 { (u, v) } else { (v, u) };
                let base = positions.len() as u32;
                for j in 0..=n {
                    for i in 0..=n {
                        let (a, b) = (i as f32 / n as f32 * 2.0 - 1.0, j as f32 / n as f32 * 2.0 - 1.0);
                        positions.push(normal * sign + u * a + v * b);
                    }
                }
                for j in 0..n {
                    for i in 0..n {
                        let q = base + j * (n + 1) + i;
                        triangles.push([q, q + 1, q + n + 2]);
                        triangles.push([q, q + n + 2, q + n + 1]);
                    }
                }
            }
        }
        Topology::from_triangles(&positions, &triangles, Weld::Exact)
    }

    /// Chains of creases alone: short and weak ones become candidates; four edges, a touching
    /// boundary, a length over the fraction or a crease past the strong angle keep them.
    #[test]
    fn specks_are_short_weak_chains_of_creases_alone() {
        let topo = grid_cube(12);
        let normals = face_normals(&topo);
        // The cube's own edges are strong creases; every other edge is coplanar.
        let base: Vec<(EdgeClass, f32, bool)> = (0..topo.edges.len())
            .map(|e| {
                let f = topo.faces_of_edge(e);
                let angle = normals[f[0] as usize].unwrap().angle_between(normals[f[1] as usize].unwrap());
                (if angle > 0.5 { EdgeClass::Crease } else { EdgeClass::Coplanar }, f32::NAN, false)
            })
            .collect();
        let cube_edges = base.iter().filter(|p| p.0 == EdgeClass::Crease).count();
        // Interior edges of the +Z face, chosen by their vertices' grid positions.
        let on_top = |e: usize| topo.edges[e].iter().all(|&v| topo.welded_positions[v as usize].z == 1.0);
        let interior = |e: usize| {
            topo.edges[e].iter().all(|&v| {
                topo.welded_positions[v as usize].abs().max_element() < 1.0 - 1e-6
                    || topo.welded_positions[v as usize].z == 1.0
                        && topo.welded_positions[v as usize].truncate().abs().max_element() < 1.0 - 1e-6
            })
        };
        let top: Vec<usize> = (0..topo.edges.len()).filter(|&e| on_top(e) && interior(e)).collect();
        // A chain of `k` connected top edges starting at edge `start`.
        let chain = |start: usize, k: usize| {
            let mut chosen = vec![start];
            while chosen.len() < k {
                let last = topo.edges[*chosen.last().unwrap()];
                let next = top.iter().copied().find(|&e| {
                    !chosen.contains(&e)
                        && topo.edges[e][0] == last[1]
                        && !chosen.iter().any(|&c| topo.edges[c].contains(&topo.edges[e][1]))
                });
                chosen.push(next.expect("a continuing edge"));
            }
            chosen
        };
        let options = LineOptions { crease_min_length: 1.0, ..LineOptions::default() };
        let run = |marked: &[usize], options: &LineOptions| {
            let mut per_edge = base.clone();
            for &e in marked {
                per_edge[e].0 = EdgeClass::Crease;
            }
            drop_specks(&topo, &normals, options, &[], &mut per_edge);
            per_edge.iter().filter(|p| p.0 == EdgeClass::Crease).count() - cube_edges
        };
        let far_apart = |a: usize, b: usize| topo.edges[a].iter().all(|v| !topo.edges[b].contains(v));
        let singles: Vec<usize> = top.iter().copied().fold(Vec::new(), |mut acc, e| {
            if acc.len() < 5 && acc.iter().all(|&a| far_apart(a, e)) {
                acc.push(e);
            }
            acc
        });
        assert_eq!(singles.len(), 5);
        assert_eq!(run(&singles, &options), 0, "isolated weak creases are specks");
        assert_eq!(run(&chain(top[40], 3), &options), 0, "three edges: a speck");
        assert_eq!(run(&chain(top[40], 4), &options), 4, "four edges: a feature");
        assert_eq!(run(&singles, &LineOptions { crease_min_edges: 0, ..options }), 5, "the rule off");
        assert_eq!(
            run(&singles, &LineOptions { crease_min_length: 0.01, ..options }),
            5,
            "long against the cube's diagonal"
        );
        assert_eq!(
            run(&singles, &LineOptions { strong_crease_deg: -1.0, ..options }),
            5,
            "sharper than the strong angle"
        );
        // A crease touching a cube edge (another hard edge) continues it.
        let touching: Vec<usize> = (0..topo.edges.len())
            .filter(|&e| on_top(e) && !interior(e) && base[e].0 != EdgeClass::Crease)
            .take(1)
            .collect();
        assert_eq!(touching.len(), 1);
        assert_eq!(run(&touching, &options), 1);
    }

    #[test]
    fn classes_follow_dihedral_angle() {
        let flat = Topology::from_triangles(&tent(0.0).0, &tent(0.0).1, Weld::Exact);
        let lines = classify_edges(&flat, None, &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.boundary, 4);
        assert_eq!(lines.counts.coplanar, 1);
        let bent = tent(0.2);
        let topo = Topology::from_triangles(&bent.0, &bent.1, Weld::Exact);
        let lines = classify_edges(&topo, None, &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.silhouette_candidate, 1);
        assert_eq!(lines.candidates.len(), 1);
        let e = lines.candidates[0] as usize;
        assert_eq!(topo.edges[e], [0, 2]);
        assert_eq!(lines.candidate_points[0], Vec3::ZERO);
        let steep = tent(2.0);
        let topo = Topology::from_triangles(&steep.0, &steep.1, Weld::Exact);
        let lines = classify_edges(&topo, None, &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.crease, 1);
        // The dihedral angle of the steep tent, computed by hand from the normals.
        let n1 = Vec3::new(1.0, 0.0, 0.0).cross(Vec3::new(1.0, 1.0, 2.0)).normalize();
        let n2 = Vec3::new(1.0, 1.0, 2.0).cross(Vec3::new(0.0, 1.0, 0.0)).normalize();
        let expected = n1.dot(n2).acos().to_degrees();
        assert!((lines.dihedral_deg[e] - expected).abs() < 1e-3);
    }

    #[test]
    fn part_borders_and_degenerate_neighbours() {
        let (p, t) = tent(0.2);
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        let parts = [PartId(0), PartId(1)];
        let lines = classify_edges(&topo, Some(&parts), &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.part_border, 1);
        assert!(classify_edges(&topo, Some(&parts[..1]), &LineOptions::default()).is_err());
        // A zero-area triangle glued to a good one along 0-1.
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(0.5, 0.0, 0.0)];
        let t = vec![[0, 1, 2], [1, 0, 3]];
        let topo = Topology::from_triangles(&p, &t, Weld::Exact);
        let lines = classify_edges(&topo, None, &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.degenerate, 1);
        assert_eq!(lines.diagnostics().len(), 1);
    }

    #[test]
    fn inconsistent_winding_is_counted() {
        let (p, _) = tent(0.2);
        let topo = Topology::from_triangles(&p, &[[0, 1, 2], [0, 3, 2]], Weld::Exact);
        let lines = classify_edges(&topo, None, &LineOptions::default()).unwrap();
        assert_eq!(lines.counts.inconsistent_orientation, 1);
        assert_eq!(lines.counts.crease, 1);
    }

    #[test]
    fn class_codes_round_trip() {
        for c in EdgeClass::ALL {
            assert_eq!(EdgeClass::from_code(c.code()), Some(c));
        }
        assert_eq!(EdgeClass::from_code(8), None);
    }
}
