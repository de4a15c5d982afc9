//! The Gauss-map arc hierarchy for orthographic silhouettes (Gooch et al. 1999, §5.1.2, Fig. 8,
//! Tables 1–2; ../shared/papers/001_*).
//!
//! # How it works
//!
//! On the sphere of orientations a candidate edge is the great-circle arc between its two face
//! normals. Under an orthographic view along `u` the faces with `n·u > 0` and `n·u < 0` are separated
//! by the great circle `n·u = 0`, and the edge is a silhouette iff its arc crosses that circle.
//!
//! Arcs are stored in a hierarchy of spherical triangles: the faces of an icosahedron (or
//! octahedron), each split 4:1 at its normalised edge midpoints, level after level. An arc goes
//! down from the root towards the cell containing its midpoint for as long as it fits that cell's
//! *bin*, and is stored at the deepest cell whose bin holds it:
//!
//! * [`Bins::Strict`]: the bin is the spherical triangle itself (the paper's first variant; arcs
//!   that straddle a cell boundary get stuck high up, Table 2 "No Overlap");
//! * [`Bins::Overlapping`] (default, the variant the paper recommends): the bin is the cap around
//!   the cell's centre with `factor` × the cell's circumradius, so neighbouring bins overlap and
//!   an arc near a boundary still goes down.
//!
//! Arcs that fit no base cell (longer than a base bin, or with antipodal normals) stay at the root.
//!
//! # Query and exactness
//!
//! Every node keeps a *data-dependent* bounding cap of all the arc endpoints in its subtree (centre
//! `c`, radius `r`, the smaller of the cap around the cell centre and the one around the mean
//! endpoint). A query walks the tree one level at a time (breadth-first, see `tree.rs` for why)
//! and enters a node only when the view's great circle meets its cap, `|c·u| ≤ sin r + ε`. Since
//! the predicate only looks at the two endpoints, a missed cap means both normals of every arc below
//! lie strictly on one side with a margin (`ε` = [`CULL_MARGIN`] = 1e-5 ≫ the ~1e-6 rounding of
//! the `f32` dot products), so the `f32` predicate would reject each of them: culling never drops
//! a silhouette. A cap of radius ≥ π/2 is never culled.
//!
//! Storage: the arcs are stored node after node (breadth-first), in blocks of 4 lanes. A query
//! first walks the caps and collects the block ranges of the nodes it enters, then tests the
//! ranges as one prefetched stream. On x86-64 a 16-bit copy of the normals decides almost every
//! lane with exact integer arithmetic and a proven error bound, and the few lanes within ~6·10⁻⁵
//! of the great circle are tested again with the brute-force arithmetic (same `u`, same `f32`
//! operations in the same order; see `brute::Quantized`); elsewhere every lane takes the `f32`
//! test. Either way the answer is bit-identical to [`crate::BruteForce`]. Blocks at the ends of
//! a range also hold a few arcs of neighbouring nodes; testing them too is harmless (the predicate
//! is exact for any arc, and an arc of a culled node is no silhouette). Up to 4 children's caps
//! are tested in one SIMD pass. A hierarchy built on its own answers in its input order, through
//! `order`; [`GaussMapHierarchy::into_storage_order`] renumbers the candidates by storage position
//! (what [`crate::SilhouetteIndex`] does), and then a block's hits are 4 bits ORed straight into
//! the answer.
//!
//! # How deep
//!
//! Cells are built down to [`depth_for_count`] levels. Then a bottom-up pass collapses every
//! subtree whose expected cost is lower as one node: for a uniformly random `u`, `c·u` is uniform on
//! `[-1, 1]`, so a cap is entered with probability `min(1, sin r + ε)` (capped by its parent's).
//! With the per-operation costs of [`CostModel`] this chooses the depth of every branch; the
//! expected time of the final hierarchy is then measured in operations over fixed directions and
//! priced with the same model, and [`crate::SilhouetteIndex`] compares it with brute force to
//! decide whether to keep the hierarchy at all.

use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::brute::{OrthoBlocks, unit_direction};
use crate::tree::{
    breadth_first, check_breadth_first, check_permutation, depths, for_each_in_subtrees, push_children, widest_level,
    with_levels, with_ranges,
};
use crate::{ArraysError, CostModel, EdgeSet};

/// Margin added to the sine of every cap radius (see the module docs).
pub const CULL_MARGIN: f64 = 1e-5;

/// Default bin size of [`Bins::Overlapping`], in cell circumradii.
pub const DEFAULT_OVERLAP: f32 = 1.5;

/// A threshold at or above which a cap is never culled.
const NEVER_CULL: f32 = 2.0;

/// The platonic solid whose faces are the level-0 cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BaseSolid {
    /// 8 faces.
    Octahedron,
    /// 20 faces (default; the paper's choice).
    Icosahedron,
}

impl BaseSolid {
    pub fn face_count(self) -> usize {
        match self {
            Self::Octahedron => 8,
            Self::Icosahedron => 20,
        }
    }

    fn code(self) -> u32 {
        match self {
            Self::Octahedron => 0,
            Self::Icosahedron => 1,
        }
    }
}

/// Which region of a cell an arc must fit to be stored there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Bins {
    /// The spherical triangle itself.
    Strict,
    /// The cap around the cell centre of `factor` circumradii (`factor` ≥ 1).
    Overlapping { factor: f32 },
}

/// Options of [`GaussMapHierarchy::build`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GaussMapOptions {
    /// Level-0 cells. Default [`BaseSolid::Icosahedron`].
    pub base: BaseSolid,
    /// Bin shape. Default `Overlapping { factor: DEFAULT_OVERLAP }`.
    pub bins: Bins,
    /// Deepest level built (0 = base faces only); `None` (default) picks [`depth_for_count`].
    /// Range 0..=12.
    pub max_depth: Option<u8>,
    /// Collapse subtrees that the cost model says are cheaper as one node. Default `true`.
    pub prune: bool,
}

impl Default for GaussMapOptions {
    fn default() -> Self {
        Self {
            base: BaseSolid::Icosahedron,
            bins: Bins::Overlapping { factor: DEFAULT_OVERLAP },
            max_depth: None,
            prune: true,
        }
    }
}

/// The deepest level worth building for `candidates` arcs: one level below about one arc per
/// cell if they were spread evenly (arcs crowd into a band of the sphere on most models; the
/// cost-model pruning then removes what does not pay), at most 10.
pub fn depth_for_count(candidates: usize, base: BaseSolid) -> u8 {
    let per_face = candidates as f64 / base.face_count() as f64;
    if per_face <= 1.0 {
        return 0;
    }
    (per_face.log(4.0).ceil() as u8 + 1).min(10)
}

/// Nodes and arcs at one level.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelCount {
    pub nodes: usize,
    pub arcs: usize,
}

/// How many arcs are stored at each level (Gooch et al. 1999, Table 2).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct LevelHistogram {
    /// The whole sphere: arcs that fit no base cell (or, after pruning, a collapsed hierarchy).
    pub root: LevelCount,
    /// `levels[k]`: cells after `k` 4:1 splits (level 0 = the base solid's faces).
    pub levels: Vec<LevelCount>,
}

impl LevelHistogram {
    /// From `(depth, own arc count)` per node (depth 0 = root, 1 = base face).
    fn from_nodes(nodes: impl Iterator<Item = (u32, usize)>) -> Self {
        let mut h = LevelHistogram::default();
        for (depth, arcs) in nodes {
            let slot = if depth == 0 {
                &mut h.root
            } else {
                let level = depth as usize - 1;
                if h.levels.len() <= level {
                    h.levels.resize(level + 1, LevelCount::default());
                }
                &mut h.levels[level]
            };
            slot.nodes += 1;
            slot.arcs += arcs;
        }
        h
    }
}

/// Work done by one query (for benchmarks and the cost model).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct QueryCounts {
    /// Nodes entered (their children's bounds tested, their own candidates tested).
    pub nodes_entered: usize,
    /// Bounds (caps, or boxes and cones) tested.
    pub bounds_tested: usize,
    /// Entered nodes with own candidates.
    pub ranges: usize,
    /// Blocks of 4 lanes tested.
    pub blocks_tested: usize,
    /// Candidates tested with the exact predicate (blocks minus padding).
    pub arcs_tested: usize,
}

impl std::ops::AddAssign for QueryCounts {
    fn add_assign(&mut self, o: Self) {
        self.nodes_entered += o.nodes_entered;
        self.bounds_tested += o.bounds_tested;
        self.ranges += o.ranges;
        self.blocks_tested += o.blocks_tested;
        self.arcs_tested += o.arcs_tested;
    }
}

impl QueryCounts {
    /// Priced with a cost model's Gauss-map (`gauss = true`) or cone-BVH costs, in ns.
    pub fn cost_ns(&self, cost: &CostModel, gauss: bool) -> f64 {
        let [enter, test, range, block] = if gauss {
            [cost.gauss_enter_ns, cost.gauss_test_ns, cost.gauss_range_ns, cost.gauss_block_ns]
        } else {
            [cost.bvh_enter_ns, cost.bvh_test_ns, cost.bvh_range_ns, cost.bvh_block_ns]
        };
        self.nodes_entered as f64 * f64::from(enter)
            + self.bounds_tested as f64 * f64::from(test)
            + self.ranges as f64 * f64::from(range)
            + self.blocks_tested as f64 * f64::from(block)
    }
}

/// The flat arrays of a [`GaussMapHierarchy`], ready for glTF buffer views.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GaussMapArrays {
    /// 0 octahedron, 1 icosahedron.
    pub base: u32,
    /// Deepest level that was built.
    pub max_depth: u32,
    /// 4 `f32` per node: cap centre x, y, z and the cull threshold `sin r + ε` (≥ 1: never culled).
    pub node_caps: Vec<f32>,
    /// 4 `u32` per node, nodes breadth-first from the root (the whole sphere; depth 1 = level 0):
    /// first child, child count, first own arc and end of own arcs (into `order`).
    pub nodes: Vec<u32>,
    /// Candidate index of each stored arc; own arcs of the nodes follow one another in node order.
    pub order: Vec<u32>,
}

/// See the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct GaussMapHierarchy {
    base: BaseSolid,
    max_depth: u8,
    /// What a query reads about nodes, each with its cap, padded with 4 culled entries so that
    /// the up to 4 children of a node are tested in one SIMD pass.
    nodes: Vec<GaussNode>,
    /// The most nodes at one depth (sizes the walk's level buffers).
    widest: usize,
    /// The arcs in storage order, in blocks of 4.
    blocks: OrthoBlocks,
    /// Whether `order` is the identity, so that storage positions are candidate indices and hits
    /// go straight into the answer (see [`GaussMapHierarchy::into_storage_order`]).
    identity: bool,
    /// The serialised form: `[first_child, child_count, arc_start, arc_end]` per node.
    flat: Vec<[u32; 4]>,
    caps: Vec<[f32; 4]>,
    order: Vec<u32>,
    assigned: Option<LevelHistogram>,
    predicted_ns: f64,
}

/// A node as the query reads it: its cap next to its record, 32 bytes, so that testing a node's
/// children touches 2 cache lines (caps as 4 separate arrays touched 4 to 8, and the records
/// another 1 or 2 at the next level).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
struct GaussNode {
    /// Centre x, y, z and threshold `sin r + ε` (see the module docs).
    cap: Vec4,
    first_child: u32,
    child_count: u32,
    /// The blocks covering the own arcs (the partial blocks at both ends also hold arcs of
    /// neighbouring nodes, which are tested too: harmless, the predicate is exact for any arc).
    block_start: u32,
    block_end: u32,
}

/// What a query reads, built from the serialised form.
struct Assembled {
    nodes: Vec<GaussNode>,
    widest: usize,
    blocks: OrthoBlocks,
}

/// Query records, cap arrays and blocks of a breadth-first tree.
fn assemble(flat: &[[u32; 4]], caps: &[[f32; 4]], order: &[u32], normals: &[[Vec3; 2]]) -> Assembled {
    let mut nodes: Vec<GaussNode> = flat
        .iter()
        .zip(caps)
        .map(|(&[first_child, child_count, start, end], &cap)| GaussNode {
            cap: Vec4::from(cap),
            first_child,
            child_count,
            block_start: start / 4,
            block_end: if end > start { end.div_ceil(4) } else { start / 4 },
        })
        .collect();
    // Padding: threshold -1 is culled by any finite direction (and masked off anyway).
    let pad =
        GaussNode { cap: Vec4::new(0.0, 0.0, 0.0, -1.0), first_child: 0, child_count: 0, block_start: 0, block_end: 0 };
    nodes.extend(std::iter::repeat_n(pad, 4));
    Assembled { nodes, widest: widest_level(flat), blocks: OrthoBlocks::new(order, normals) }
}

/// Fixed view directions for estimating a hierarchy's cost (a Fibonacci sphere).
fn sample_directions(count: u32) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .map(|k| {
            let z = 1.0 - 2.0 * (k as f32 + 0.5) / count as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * k as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

/// A spherical triangle, counter-clockwise seen from outside.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Cell {
    v: [DVec3; 3],
    /// Unit normals of the planes through the origin and each edge, pointing inside.
    planes: [DVec3; 3],
    center: DVec3,
    /// Cosine of the circumradius.
    cos_radius: f64,
}

impl Cell {
    fn new(a: DVec3, b: DVec3, c: DVec3) -> Cell {
        let center = (a + b + c).normalize();
        let cos_radius = center.dot(a).min(center.dot(b)).min(center.dot(c));
        let planes = [a.cross(b).normalize(), b.cross(c).normalize(), c.cross(a).normalize()];
        Cell { v: [a, b, c], planes, center, cos_radius }
    }

    /// Signed inside-ness: ≥ 0 inside, the larger the deeper.
    pub(crate) fn score(&self, p: DVec3) -> f64 {
        self.planes[0].dot(p).min(self.planes[1].dot(p)).min(self.planes[2].dot(p))
    }

    pub(crate) fn children(&self) -> [Cell; 4] {
        let [a, b, c] = self.v;
        let ab = (a + b).normalize();
        let bc = (b + c).normalize();
        let ca = (c + a).normalize();
        [Cell::new(a, ab, ca), Cell::new(ab, b, bc), Cell::new(ca, bc, c), Cell::new(ab, bc, ca)]
    }
}

pub(crate) fn base_cells(base: BaseSolid) -> Vec<Cell> {
    let (vertices, edge_len2): (Vec<DVec3>, f64) = match base {
        BaseSolid::Octahedron => (vec![DVec3::X, DVec3::NEG_X, DVec3::Y, DVec3::NEG_Y, DVec3::Z, DVec3::NEG_Z], 2.0),
        BaseSolid::Icosahedron => {
            let phi = (1.0 + 5f64.sqrt()) / 2.0;
            let mut v = Vec::new();
            for s1 in [-1.0, 1.0] {
                for s2 in [-1.0, 1.0] {
                    v.push(DVec3::new(0.0, s1, s2 * phi));
                    v.push(DVec3::new(s1, s2 * phi, 0.0));
                    v.push(DVec3::new(s2 * phi, 0.0, s1));
                }
            }
            (v, 4.0)
        }
    };
    let n = vertices.len();
    let adjacent = |i: usize, j: usize| (vertices[i].distance_squared(vertices[j]) - edge_len2).abs() < 1e-9;
    let mut cells = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                if adjacent(i, j) && adjacent(j, k) && adjacent(k, i) {
                    let (a, mut b, mut c) = (vertices[i], vertices[j], vertices[k]);
                    if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
                        std::mem::swap(&mut b, &mut c);
                    }
                    cells.push(Cell::new(a.normalize(), b.normalize(), c.normalize()));
                }
            }
        }
    }
    cells
}

/// Where the overlapping-bin rule stores the arc `n1`–`n2` (unit; zero for a degenerate face):
/// the cells containing its midpoint, level after level, for as long as both endpoints lie in the
/// cell's bin (the cap of `factor` circumradii around its centre), at most `level` splits below
/// the base. Returns `(digits, cells)`: `cells` is how many cells the arc went down (0: it fits
/// no base cell), `digits` the path as `base · 4^level + child digits` with unused digits 0.
pub(crate) fn arc_path(n1: DVec3, n2: DVec3, base: &[Cell], level: u8, factor: f64) -> (u32, u8) {
    let sum = n1 + n2;
    if n1 == DVec3::ZERO || n2 == DVec3::ZERO || sum.length() <= 1e-9 {
        return (0, 0);
    }
    let mid = sum.normalize();
    let fits = |c: &Cell| {
        let cos_bin = (c.cos_radius.clamp(-1.0, 1.0).acos() * factor.max(1.0)).min(std::f64::consts::PI).cos();
        c.center.dot(n1) >= cos_bin && c.center.dot(n2) >= cos_bin
    };
    let most_inside = |cells: &[Cell]| {
        cells
            .iter()
            .enumerate()
            .map(|(k, c)| (k, c.score(mid)))
            .fold((0, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc })
            .0
    };
    let b = most_inside(base);
    if !fits(&base[b]) {
        return (0, 0);
    }
    let (mut key, mut cells, mut cell) = (b as u32, 1u8, base[b]);
    for _ in 0..level {
        let children = cell.children();
        let k = most_inside(&children);
        if !fits(&children[k]) {
            break;
        }
        key = key * 4 + k as u32;
        cells += 1;
        cell = children[k];
    }
    (key * 4u32.pow(u32::from(level + 1 - cells)), cells)
}

/// Unit endpoints and midpoint of an arc; `mid` is `None` for a zero or antipodal arc.
#[derive(Clone, Copy, Debug)]
struct ArcGeom {
    n1: DVec3,
    n2: DVec3,
    mid: Option<DVec3>,
}

fn arc_geometry(normals: &[[Vec3; 2]]) -> Vec<ArcGeom> {
    normals
        .par_iter()
        .map(|&[a, b]| {
            let n1 = a.as_dvec3().normalize_or_zero();
            let n2 = b.as_dvec3().normalize_or_zero();
            let sum = n1 + n2;
            let mid = (n1 != DVec3::ZERO && n2 != DVec3::ZERO && sum.length() > 1e-9).then(|| sum.normalize());
            ArcGeom { n1, n2, mid }
        })
        .collect()
}

struct BuildNode {
    depth: u8,
    own: (u32, u32),
    /// End of the subtree's arcs in `order`.
    sub_end: u32,
    children: Vec<u32>,
    cell_center: Option<DVec3>,
}

struct Builder<'a> {
    geo: &'a [ArcGeom],
    bins: Bins,
    max_depth: u8,
    base: Vec<Cell>,
    nodes: Vec<BuildNode>,
    order: Vec<u32>,
}

impl Builder<'_> {
    fn fits(&self, cell: &Cell, arc: &ArcGeom) -> bool {
        match self.bins {
            Bins::Strict => cell.score(arc.n1) >= 0.0 && cell.score(arc.n2) >= 0.0,
            Bins::Overlapping { factor } => {
                let bin =
                    (cell.cos_radius.clamp(-1.0, 1.0).acos() * f64::from(factor.max(1.0))).min(std::f64::consts::PI);
                let cos_bin = bin.cos();
                cell.center.dot(arc.n1) >= cos_bin && cell.center.dot(arc.n2) >= cos_bin
            }
        }
    }

    /// Builds the node for `cell` (`None`: the root) holding `arcs`; returns its index.
    fn node(&mut self, cell: Option<Cell>, depth: u8, arcs: Vec<u32>) -> u32 {
        let index = self.nodes.len() as u32;
        self.nodes.push(BuildNode {
            depth,
            own: (0, 0),
            sub_end: 0,
            children: Vec::new(),
            cell_center: cell.map(|c| c.center),
        });
        let children: Vec<Cell> = match cell {
            None => self.base.clone(),
            // Depth 1 is level 0; a cell at level `depth - 1` splits while that is below max_depth.
            Some(c) if depth <= self.max_depth => c.children().to_vec(),
            Some(_) => Vec::new(),
        };
        let mut stay = Vec::new();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); children.len()];
        for a in arcs {
            let g = &self.geo[a as usize];
            let target = g.mid.and_then(|m| {
                let (best, _) = children
                    .iter()
                    .enumerate()
                    .map(|(k, c)| (k, c.score(m)))
                    .fold((usize::MAX, f64::NEG_INFINITY), |acc, x| if x.1 > acc.1 { x } else { acc });
                (best < children.len() && self.fits(&children[best], g)).then_some(best)
            });
            match target {
                Some(k) => lists[k].push(a),
                None => stay.push(a),
            }
        }
        let start = self.order.len() as u32;
        self.order.extend_from_slice(&stay);
        self.nodes[index as usize].own = (start, self.order.len() as u32);
        for (k, list) in lists.into_iter().enumerate() {
            if !list.is_empty() {
                let child = self.node(Some(children[k]), depth + 1, list);
                self.nodes[index as usize].children.push(child);
            }
        }
        self.nodes[index as usize].sub_end = self.order.len() as u32;
        index
    }
}

/// The cap of a set of unit endpoints: `[cx, cy, cz, threshold]` with the centre in `f32` and the
/// threshold `sin r + ε` rounded up, `r` measured from the `f32` centre.
fn bounding_cap(points: impl Iterator<Item = DVec3> + Clone, cell_center: Option<DVec3>) -> [f32; 4] {
    let mean = points.clone().fold(DVec3::ZERO, |s, p| s + p);
    let mut best: Option<([f32; 3], f64)> = None;
    for center in [cell_center, (mean.length() > 1e-12).then(|| mean.normalize())].into_iter().flatten() {
        let c32 = center.as_vec3();
        let c = c32.as_dvec3().normalize();
        let r = points.clone().map(|p| c.cross(p).length().atan2(c.dot(p))).fold(0.0f64, f64::max);
        if best.is_none_or(|(_, b)| r < b) {
            best = Some((c32.to_array(), r));
        }
    }
    let Some(([x, y, z], r)) = best else { return [0.0, 0.0, 1.0, NEVER_CULL] };
    // 1e-9 rad covers the rounding of atan2 itself.
    let r = r + 1e-9;
    if r >= std::f64::consts::FRAC_PI_2 - 1e-3 {
        return [x, y, z, NEVER_CULL];
    }
    [x, y, z, round_up(r.sin() + CULL_MARGIN)]
}

fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

impl GaussMapHierarchy {
    /// Builds the hierarchy over candidates with `normals` (see [`crate::FeatureEdges`]).
    pub fn build(normals: &[[Vec3; 2]], options: &GaussMapOptions, cost: &CostModel) -> Self {
        let geo = arc_geometry(normals);
        let max_depth = options.max_depth.unwrap_or_else(|| depth_for_count(normals.len(), options.base)).min(12);
        let mut builder = Builder {
            geo: &geo,
            bins: options.bins,
            max_depth,
            base: base_cells(options.base),
            nodes: Vec::new(),
            order: Vec::with_capacity(normals.len()),
        };
        builder.node(None, 0, (0..normals.len() as u32).collect());
        let Builder { nodes, order, .. } = builder;

        // Caps over each subtree's endpoints (contiguous in the preorder `order`).
        let caps: Vec<[f32; 4]> = nodes
            .par_iter()
            .map(|n| {
                let range = &order[n.own.0 as usize..n.sub_end as usize];
                let points = range.iter().flat_map(|&a| [geo[a as usize].n1, geo[a as usize].n2]);
                bounding_cap(points, n.cell_center)
            })
            .collect();
        let assigned =
            LevelHistogram::from_nodes(nodes.iter().map(|n| (u32::from(n.depth), (n.own.1 - n.own.0) as usize)));

        // Expected cost, bottom-up: collapse a subtree when one node is cheaper.
        let prob = visit_probabilities(&nodes, &caps);
        let enter = f64::from(cost.gauss_enter_ns);
        let test = f64::from(cost.gauss_test_ns);
        let range = f64::from(cost.gauss_range_ns);
        let block = f64::from(cost.gauss_block_ns);
        let mut best = vec![0.0f64; nodes.len()];
        let mut collapse = vec![false; nodes.len()];
        for i in (0..nodes.len()).rev() {
            let n = &nodes[i];
            let own = f64::from((n.own.1 - n.own.0).div_ceil(4));
            let sub = f64::from((n.sub_end - n.own.0).div_ceil(4));
            let children: f64 = n.children.iter().map(|&c| best[c as usize]).sum();
            let split = prob[i]
                * (enter + test * n.children.len() as f64 + if own > 0.0 { range + block * own } else { 0.0 })
                + children;
            let collapsed = prob[i] * (enter + range + block * sub);
            if options.prune && !n.children.is_empty() && collapsed <= split {
                collapse[i] = true;
                best[i] = collapsed;
            } else {
                best[i] = split;
            }
        }

        // Collapsed nodes own their whole subtree (contiguous in the preorder `order`).
        let no_children: &[u32] = &[];
        let (flat, bfs_order, source) = breadth_first(
            0,
            |i| if collapse[i] { no_children } else { &nodes[i].children },
            |i| {
                let n = &nodes[i];
                &order[n.own.0 as usize..if collapse[i] { n.sub_end } else { n.own.1 } as usize]
            },
        );
        let flat_caps: Vec<[f32; 4]> = source.iter().map(|&i| caps[i]).collect();
        let a = assemble(&flat, &flat_caps, &bfs_order, normals);
        let mut h = GaussMapHierarchy {
            base: options.base,
            max_depth,
            nodes: a.nodes,
            widest: a.widest,
            blocks: a.blocks,
            identity: is_identity(&bfs_order),
            flat,
            caps: flat_caps,
            order: bfs_order,
            assigned: Some(assigned),
            predicted_ns: 0.0,
        };
        h.predicted_ns = h.estimate_ns(cost);
        h
    }

    /// Mean modelled cost of a query over 64 fixed directions.
    fn estimate_ns(&self, cost: &CostModel) -> f64 {
        let dirs = sample_directions(64);
        let mut out = EdgeSet::default();
        let total: f64 = dirs.iter().map(|&d| self.query_counted(d, &mut out).cost_ns(cost, true)).sum();
        total / dirs.len() as f64
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    pub fn node_count(&self) -> usize {
        self.flat.len()
    }

    pub fn base(&self) -> BaseSolid {
        self.base
    }

    /// The deepest level that was built (before pruning).
    pub fn max_depth(&self) -> u8 {
        self.max_depth
    }

    /// Arcs and nodes per level as stored (after pruning).
    pub fn histogram(&self) -> LevelHistogram {
        let depth = depths(&self.flat);
        LevelHistogram::from_nodes(self.flat.iter().zip(depth).map(|(n, d)| (d, (n[3] - n[2]) as usize)))
    }

    /// Arcs per level as assigned by the bins, before pruning (Table 2 of the paper); `None` for a
    /// hierarchy loaded from arrays.
    pub fn assigned_histogram(&self) -> Option<&LevelHistogram> {
        self.assigned.as_ref()
    }

    /// Expected time of one query under the cost model used to build it, estimated over fixed
    /// directions (0 when loaded from arrays).
    pub fn predicted_ns_per_query(&self) -> f64 {
        self.predicted_ns
    }

    /// Silhouettes for view direction `direction` into `out` (reset to [`GaussMapHierarchy::len`]).
    pub fn query(&self, direction: Vec3, out: &mut EdgeSet) {
        self.walk::<false>(direction, out);
    }

    /// [`GaussMapHierarchy::query`] that also counts its work.
    pub fn query_counted(&self, direction: Vec3, out: &mut EdgeSet) -> QueryCounts {
        self.walk::<true>(direction, out)
    }

    /// Bits of the nodes `first..first + 4` whose caps meet the great circle of `u`.
    #[inline(always)]
    fn meets4(&self, first: usize, u: Vec3) -> u32 {
        let Some(four) = self.nodes.get(first..first + 4) else { return 0 };
        // Rows of the transpose: x, y, z and threshold of the 4 caps.
        let m = glam::Mat4::from_cols(four[0].cap, four[1].cap, four[2].cap, four[3].cap).transpose();
        let d = m.x_axis * u.x + m.y_axis * u.y + m.z_axis * u.z;
        // Culled iff |c·u| > threshold; NaN compares false and is entered.
        d.abs().cmpgt(m.w_axis).bitmask() ^ 0xF
    }

    /// Answers in storage order (`into_storage_order`) go straight into `out`; otherwise through
    /// a storage-order bitset mapped by `order`.
    #[inline]
    fn walk<const COUNT: bool>(&self, direction: Vec3, out: &mut EdgeSet) -> QueryCounts {
        out.reset(self.len());
        let Some(u) = unit_direction(direction) else { return QueryCounts::default() };
        if self.identity {
            let (words, dirty) = out.words_and_dirty();
            return self.walk_into::<COUNT>(u, words, dirty);
        }
        let mut storage = vec![0u64; self.len().div_ceil(64)];
        let counts = self.walk_into::<COUNT>(u, &mut storage, &mut Vec::new());
        for (w, &word) in storage.iter().enumerate() {
            let mut bits = word;
            while bits != 0 {
                let k = 64 * w + bits.trailing_zeros() as usize;
                bits &= bits - 1;
                out.insert(self.order[k] as usize);
            }
        }
        counts
    }

    /// Breadth-first walk: for the nodes of a level, test their children's caps (4 at a time)
    /// into the next level and collect their own block ranges; then test the ranges in one
    /// stream (the data of a query over a large model is scattered over far more memory than the
    /// caches hold, and a stream keeps the loads in flight). Hits set storage positions in `words`.
    #[inline]
    fn walk_into<const COUNT: bool>(&self, u: Vec3, words: &mut [u64], dirty: &mut Vec<u32>) -> QueryCounts {
        let mut counts = QueryCounts { bounds_tested: usize::from(COUNT), ..Default::default() };
        if self.flat.is_empty() || self.meets4(0, u) & 1 == 0 {
            return counts;
        }
        with_ranges(|ranges| {
            with_levels(self.widest + 4, |level, next| {
                level[0] = 0;
                let mut width = 1;
                while width > 0 {
                    let mut next_width = 0;
                    for &i in &level[..width] {
                        let n = &self.nodes[i as usize];
                        let (first, end) = (n.first_child as usize, (n.first_child + n.child_count) as usize);
                        push_children(next, &mut next_width, first, end, |f| self.meets4(f, u));
                        if n.block_start < n.block_end {
                            ranges.push([n.block_start, n.block_end]);
                        }
                        if COUNT {
                            counts.nodes_entered += 1;
                            counts.bounds_tested += end - first;
                            if n.block_start < n.block_end {
                                let [_, _, start, end] = self.flat[i as usize];
                                counts.ranges += 1;
                                counts.blocks_tested += (n.block_end - n.block_start) as usize;
                                counts.arcs_tested += (end - start) as usize;
                            }
                        }
                    }
                    std::mem::swap(level, next);
                    width = next_width;
                }
            });
            self.blocks.test_ranges(ranges, u, words, dirty);
        });
        counts
    }

    /// The candidate index of each storage position.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The same hierarchy with candidates renumbered in its storage order, and the permutation:
    /// candidate `k` of the result is candidate `permutation[k]` of the input. Reorder the
    /// candidates with it (as [`crate::SilhouetteIndex`] does) and queries write their hits
    /// straight into the answer instead of mapping each through `order`.
    pub fn into_storage_order(mut self) -> (Self, Vec<u32>) {
        let identity = (0..self.order.len() as u32).collect();
        let permutation = std::mem::replace(&mut self.order, identity);
        self.identity = true;
        (self, permutation)
    }

    /// The flat arrays (see [`GaussMapArrays`]).
    pub fn to_arrays(&self) -> GaussMapArrays {
        GaussMapArrays {
            base: self.base.code(),
            max_depth: u32::from(self.max_depth),
            node_caps: self.caps.iter().flatten().copied().collect(),
            nodes: self.flat.iter().flatten().copied().collect(),
            order: self.order.clone(),
        }
    }

    /// Rebuilds a hierarchy from its arrays and the candidates' normals, checking the structure and
    /// that every cap really bounds the endpoints below it (so a corrupted file cannot make a query
    /// drop a silhouette).
    pub fn from_arrays(arrays: &GaussMapArrays, normals: &[[Vec3; 2]]) -> Result<Self, ArraysError> {
        let base = match arrays.base {
            0 => BaseSolid::Octahedron,
            1 => BaseSolid::Icosahedron,
            other => return Err(ArraysError::Value { array: "base", index: 0, value: f64::from(other) }),
        };
        let max_depth = u8::try_from(arrays.max_depth).ok().filter(|&d| d <= 12).ok_or(ArraysError::Value {
            array: "max_depth",
            index: 0,
            value: f64::from(arrays.max_depth),
        })?;
        check_permutation(&arrays.order, normals.len())?;
        let count = arrays.nodes.len() / 4;
        if arrays.nodes.len() != count * 4 || count == 0 {
            return Err(ArraysError::Length { array: "nodes", expected: 4 * count.max(1), found: arrays.nodes.len() });
        }
        if arrays.node_caps.len() != 4 * count {
            return Err(ArraysError::Length { array: "node_caps", expected: 4 * count, found: arrays.node_caps.len() });
        }
        let flat: Vec<[u32; 4]> = arrays.nodes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let caps: Vec<[f32; 4]> = arrays.node_caps.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let parent = check_breadth_first(&flat, normals.len())?;
        let mut centers = Vec::with_capacity(count);
        for (i, cap) in caps.iter().enumerate() {
            if cap.iter().any(|x| !x.is_finite()) {
                return Err(ArraysError::Value { array: "node_caps", index: 4 * i, value: f64::NAN });
            }
            let c = Vec3::new(cap[0], cap[1], cap[2]).as_dvec3();
            if cap[3] < 1.0 && (c.length() - 1.0).abs() > 1e-6 {
                return Err(ArraysError::Value { array: "node_caps", index: 4 * i, value: c.length() });
            }
            centers.push(c.normalize_or_zero());
        }
        let geo = arc_geometry(normals);
        for_each_in_subtrees(&flat, &parent, &arrays.order, |node, a| {
            let threshold = f64::from(caps[node][3]);
            if threshold >= 1.0 {
                return Ok(());
            }
            let c = centers[node];
            let g = &geo[a as usize];
            for p in [g.n1, g.n2] {
                let r = c.cross(p).length().atan2(c.dot(p));
                if r >= std::f64::consts::FRAC_PI_2 || r.sin() + CULL_MARGIN * 0.5 > threshold {
                    return Err(ArraysError::NotConservative { node, candidate: a });
                }
            }
            Ok(())
        })?;
        let a = assemble(&flat, &caps, &arrays.order, normals);
        Ok(GaussMapHierarchy {
            base,
            max_depth,
            nodes: a.nodes,
            widest: a.widest,
            blocks: a.blocks,
            identity: is_identity(&arrays.order),
            flat,
            caps,
            order: arrays.order.clone(),
            assigned: None,
            predicted_ns: 0.0,
        })
    }
}

fn is_identity(order: &[u32]) -> bool {
    order.iter().enumerate().all(|(k, &i)| i as usize == k)
}

fn visit_probabilities(nodes: &[BuildNode], caps: &[[f32; 4]]) -> Vec<f64> {
    let mut prob = vec![1.0f64; nodes.len()];
    // Preorder: parents come before children.
    for i in 0..nodes.len() {
        let own = f64::from(caps[i][3]).min(1.0);
        prob[i] = prob[i].min(own);
        for &c in &nodes[i].children {
            prob[c as usize] = prob[i];
        }
    }
    prob
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base_solids_tile_the_sphere() {
        for (base, faces) in [(BaseSolid::Octahedron, 8), (BaseSolid::Icosahedron, 20)] {
            let cells = base_cells(base);
            assert_eq!(cells.len(), faces);
            // Every direction lies in exactly one cell (up to boundaries).
            let mut s = 1u64;
            for _ in 0..2000 {
                let mut r = || {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
                };
                let p = DVec3::new(r(), r(), r()).normalize();
                let inside = cells.iter().filter(|c| c.score(p) > 1e-12).count();
                assert!(inside <= 1);
                assert!(cells.iter().any(|c| c.score(p) >= -1e-12));
                // The 4 children tile their parent.
                let c = cells.iter().find(|c| c.score(p) >= -1e-12).unwrap();
                assert!(c.children().iter().any(|k| k.score(p) >= -1e-9));
            }
        }
    }

    #[test]
    fn depth_grows_with_count() {
        assert_eq!(depth_for_count(0, BaseSolid::Icosahedron), 0);
        assert!(depth_for_count(150_000, BaseSolid::Icosahedron) >= 5);
        assert_eq!(depth_for_count(usize::MAX / 2, BaseSolid::Icosahedron), 10);
    }
}
