//! [`SilhouetteIndex`]: brute force plus whichever hierarchies pay for themselves.

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::tree::Purpose;
use crate::{
    ArraysError, BruteForce, ConeBvh, ConeBvhArrays, ConeBvhOptions, CostModel, EdgeSet, FeatureEdges, GaussMapArrays,
    GaussMapHierarchy, GaussMapOptions, View,
};

/// Default number of candidates below which no hierarchy is built: brute force over so few is
/// quicker than the traversal overhead of either hierarchy (the silhouette charts of
/// docs/bench.md#drafter-bench-on-three-models).
pub const DEFAULT_MIN_HIERARCHY_CANDIDATES: usize = 2048;

/// Default predicted speedup a hierarchy must reach to be stored. Above 1 so that the error of the
/// cost model cannot make a stored hierarchy slower than brute force.
pub const DEFAULT_MIN_SPEEDUP: f32 = 1.5;

/// Options of [`SilhouetteIndex::build`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SilhouetteOptions {
    /// Consider the Gauss-map hierarchy for orthographic views. Default `true`.
    pub orthographic: bool,
    /// Consider the cone BVH for perspective views. Default `true`.
    pub perspective: bool,
    /// No hierarchy below this many candidates. Default [`DEFAULT_MIN_HIERARCHY_CANDIDATES`].
    pub min_candidates: usize,
    /// A hierarchy is kept only if the cost model predicts at least this speedup over brute
    /// force. Default [`DEFAULT_MIN_SPEEDUP`]; 0 keeps every hierarchy that was built.
    pub min_speedup: f32,
    pub gauss: GaussMapOptions,
    pub bvh: ConeBvhOptions,
    pub cost: CostModel,
}

impl Default for SilhouetteOptions {
    fn default() -> Self {
        Self {
            orthographic: true,
            perspective: true,
            min_candidates: DEFAULT_MIN_HIERARCHY_CANDIDATES,
            min_speedup: DEFAULT_MIN_SPEEDUP,
            gauss: GaussMapOptions::default(),
            bvh: ConeBvhOptions::default(),
            cost: CostModel::default(),
        }
    }
}

/// Why no hierarchy was stored.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum BruteForceReason {
    /// Turned off in the options.
    Disabled,
    /// Fewer candidates than [`SilhouetteOptions::min_candidates`].
    TooFewCandidates { candidates: usize, minimum: usize },
    /// The hierarchy was built but the cost model predicts too little gain.
    NotFaster { predicted_speedup: f32 },
}

/// What answers one kind of view, and why.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum HierarchyChoice {
    /// No hierarchy: every query tests every candidate.
    BruteForce(BruteForceReason),
    /// The Gauss-map arc hierarchy (orthographic).
    GaussMap { max_depth: u8, nodes: usize, predicted_speedup: f32 },
    /// The normal-cone BVH (perspective).
    ConeBvh { leaf_size: u32, nodes: usize, predicted_speedup: f32 },
}

/// Everything a writer needs to store an index in glTF buffer views, and
/// [`SilhouetteIndex::from_arrays`] needs to load it back.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SilhouetteArrays {
    /// Topology edge id of each candidate.
    pub candidate_edges: Vec<u32>,
    /// 6 `f32` per candidate: `n1` x, y, z then `n2` x, y, z (full precision).
    pub candidate_normals: Vec<f32>,
    /// 3 `f32` per candidate: the point `v` of the perspective test.
    pub candidate_points: Vec<f32>,
    pub gauss_map: Option<GaussMapArrays>,
    pub cone_bvh: Option<ConeBvhArrays>,
    pub orthographic: HierarchyChoice,
    pub perspective: HierarchyChoice,
}

/// What a file stores of an index besides the candidates themselves: the hierarchies' arrays and
/// what answers each kind of view. [`SilhouetteIndex::stored_hierarchies`] computes it without the
/// query structures; it equals those fields of [`SilhouetteIndex::to_arrays`].
#[derive(Clone, Debug, PartialEq)]
pub struct StoredHierarchies {
    pub gauss_map: Option<GaussMapArrays>,
    pub cone_bvh: Option<ConeBvhArrays>,
    pub orthographic: HierarchyChoice,
    pub perspective: HierarchyChoice,
}

/// Silhouette queries over one mesh's candidates. See the crate docs.
#[derive(Clone, Debug)]
pub struct SilhouetteIndex {
    candidate_edges: Vec<u32>,
    normals: Vec<[Vec3; 2]>,
    points: Vec<Vec3>,
    /// Built on first use: a reader whose file stores both hierarchies never needs it (an SoA
    /// copy of every candidate's normals and point).
    brute: std::sync::OnceLock<BruteForce>,
    gauss: Option<GaussMapHierarchy>,
    bvh: Option<ConeBvh>,
    orthographic: HierarchyChoice,
    perspective: HierarchyChoice,
}

impl SilhouetteIndex {
    /// Index over the candidates of `lines`.
    pub fn build(lines: &FeatureEdges, options: &SilhouetteOptions) -> Self {
        Self::from_candidates(
            lines.candidates.clone(),
            lines.candidate_normals.clone(),
            lines.candidate_points.clone(),
            options,
        )
    }

    /// Index over explicit candidates (edge ids, two normals and a point each). When a Gauss map
    /// is stored, the candidates are renumbered in its storage order (see
    /// [`GaussMapHierarchy::into_storage_order`]): answers are indices into
    /// [`SilhouetteIndex::candidate_edges`], which keeps the edge id of each.
    pub fn from_candidates(
        candidate_edges: Vec<u32>,
        normals: Vec<[Vec3; 2]>,
        points: Vec<Vec3>,
        options: &SilhouetteOptions,
    ) -> Self {
        Self::build_for(candidate_edges, normals, points, options, Purpose::Query)
    }

    /// What a file stores of the index over these candidates (see [`StoredHierarchies`]): the
    /// same hierarchies as [`SilhouetteIndex::from_candidates`], built without what only a query
    /// reads (the arc blocks and the candidate stream, which would cost a bake time and peak memory
    /// for nothing) and without copying the candidates back out.
    pub fn stored_hierarchies(
        normals: Vec<[Vec3; 2]>,
        points: Vec<Vec3>,
        options: &SilhouetteOptions,
    ) -> StoredHierarchies {
        Self::build_for(Vec::new(), normals, points, options, Purpose::Storage).hierarchies()
    }

    /// [`SilhouetteIndex::from_candidates`]; a [`Purpose::Storage`] index must not be queried
    /// (its hierarchies have no query layout), only turned into arrays.
    fn build_for(
        candidate_edges: Vec<u32>,
        normals: Vec<[Vec3; 2]>,
        points: Vec<Vec3>,
        options: &SilhouetteOptions,
        purpose: Purpose,
    ) -> Self {
        let n = normals.len();
        let (mut candidate_edges, mut normals, mut points) = (candidate_edges, normals, points);
        let too_few = BruteForceReason::TooFewCandidates { candidates: n, minimum: options.min_candidates };
        let cost = &options.cost;

        let (gauss, orthographic) = if !options.orthographic {
            (None, HierarchyChoice::BruteForce(BruteForceReason::Disabled))
        } else if n < options.min_candidates {
            (None, HierarchyChoice::BruteForce(too_few))
        } else {
            let (g, cells) = GaussMapHierarchy::build_with_cells(&normals, &options.gauss, cost, purpose);
            let speedup = speedup(n as f64 * f64::from(cost.brute_ortho_ns), g.predicted_ns_per_query());
            if speedup >= options.min_speedup {
                let choice = HierarchyChoice::GaussMap {
                    max_depth: g.max_depth(),
                    nodes: g.node_count(),
                    predicted_speedup: speedup,
                };
                let (g, permutation) = g.into_storage_order();
                // Gathers of up to millions of candidates, a cache miss apiece unless prefetched
                // (`drafter_core::gather` prefetches).
                if candidate_edges.len() == n {
                    candidate_edges = drafter_core::gather(&candidate_edges, &permutation);
                }
                normals = drafter_core::gather(&normals, &permutation);
                if points.len() == n {
                    points = drafter_core::gather(&points, &permutation);
                }
                (Some((g, cells)), choice)
            } else {
                (None, HierarchyChoice::BruteForce(BruteForceReason::NotFaster { predicted_speedup: speedup }))
            }
        };
        // The BVH's normal split reads the Gauss map's cells (the candidates are in its order).
        let (gauss, cells) = gauss.unzip();
        let brute = std::sync::OnceLock::new();

        let (bvh, perspective) = if !options.perspective || points.len() != n {
            (None, HierarchyChoice::BruteForce(BruteForceReason::Disabled))
        } else if n < options.min_candidates {
            (None, HierarchyChoice::BruteForce(too_few))
        } else {
            let b = ConeBvh::build_with_cells(&normals, &points, &options.bvh, cost, cells.as_ref(), purpose);
            let speedup = speedup(n as f64 * f64::from(cost.brute_perspective_ns), b.predicted_ns_per_query());
            if speedup >= options.min_speedup {
                let choice = HierarchyChoice::ConeBvh {
                    leaf_size: b.leaf_size(),
                    nodes: b.node_count(),
                    predicted_speedup: speedup,
                };
                (Some(b), choice)
            } else {
                (None, HierarchyChoice::BruteForce(BruteForceReason::NotFaster { predicted_speedup: speedup }))
            }
        };

        Self { candidate_edges, normals, points, brute, gauss, bvh, orthographic, perspective }
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.normals.len()
    }

    pub fn is_empty(&self) -> bool {
        self.normals.is_empty()
    }

    /// What answers orthographic queries.
    pub fn orthographic_choice(&self) -> HierarchyChoice {
        self.orthographic
    }

    /// What answers perspective queries.
    pub fn perspective_choice(&self) -> HierarchyChoice {
        self.perspective
    }

    /// Brute force over the candidates (built on the first call).
    pub fn brute_force(&self) -> &BruteForce {
        self.brute.get_or_init(|| BruteForce::new(&self.normals, &self.points))
    }

    pub fn gauss_map(&self) -> Option<&GaussMapHierarchy> {
        self.gauss.as_ref()
    }

    pub fn cone_bvh(&self) -> Option<&ConeBvh> {
        self.bvh.as_ref()
    }

    /// Topology edge id of each candidate, in the index's candidate order (the Gauss map's
    /// storage order when one is stored, else the order given).
    pub fn candidate_edges(&self) -> &[u32] {
        &self.candidate_edges
    }

    /// The two normals of each candidate, in the index's candidate order.
    pub fn candidate_normals(&self) -> &[[Vec3; 2]] {
        &self.normals
    }

    /// The point of each candidate, in the index's candidate order.
    pub fn candidate_points(&self) -> &[Vec3] {
        &self.points
    }

    /// Silhouettes of `view` into `out` (candidate indices), by the stored hierarchy or, without
    /// one, by brute force (multithreaded for large counts). Identical to brute force either way.
    pub fn query(&self, view: View, out: &mut EdgeSet) {
        match (view, &self.gauss, &self.bvh) {
            (View::Orthographic { direction }, Some(g), _) => g.query(direction, out),
            (View::Perspective { eye }, _, Some(b)) => b.query(eye, out),
            _ => self.brute_force().query(view, out),
        }
    }

    /// [`SilhouetteIndex::query`] on the calling thread only (brute force included): what a
    /// benchmark compares with [`BruteForce::query_serial`].
    pub fn query_serial(&self, view: View, out: &mut EdgeSet) {
        match (view, &self.gauss, &self.bvh) {
            (View::Orthographic { direction }, Some(g), _) => g.query(direction, out),
            (View::Perspective { eye }, _, Some(b)) => b.query(eye, out),
            _ => self.brute_force().query_serial(view, out),
        }
    }

    /// Topology edge ids of the members of `set`, increasing.
    pub fn edge_ids<'a>(&'a self, set: &'a EdgeSet) -> impl Iterator<Item = u32> + 'a {
        set.iter().filter_map(|c| self.candidate_edges.get(c as usize).copied())
    }

    /// The flat arrays (see [`SilhouetteArrays`]).
    pub fn to_arrays(&self) -> SilhouetteArrays {
        let StoredHierarchies { gauss_map, cone_bvh, orthographic, perspective } = self.hierarchies();
        SilhouetteArrays {
            candidate_edges: self.candidate_edges.clone(),
            candidate_normals: self.normals.iter().flat_map(|[a, b]| [a.x, a.y, a.z, b.x, b.y, b.z]).collect(),
            candidate_points: self.points.iter().flat_map(|p| p.to_array()).collect(),
            gauss_map,
            cone_bvh,
            orthographic,
            perspective,
        }
    }

    fn hierarchies(&self) -> StoredHierarchies {
        StoredHierarchies {
            gauss_map: self.gauss.as_ref().map(GaussMapHierarchy::to_arrays),
            cone_bvh: self.bvh.as_ref().and_then(ConeBvh::to_arrays),
            orthographic: self.orthographic,
            // A tree that cannot be stored (no normal split) leaves brute force to the reader.
            perspective: match self.bvh.as_ref().map(ConeBvh::normal_level) {
                Some(None) => HierarchyChoice::BruteForce(BruteForceReason::Disabled),
                _ => self.perspective,
            },
        }
    }

    /// Loads an index from its arrays, validating every hierarchy against the candidates.
    ///
    /// The candidates may come in any order (a file keeps the Khronos encoding order): the
    /// hierarchies store no permutation. The Gauss map assigns the arcs to its cells again,
    /// which gives its storage order; the candidates are renumbered in it, as
    /// [`SilhouetteIndex::from_candidates`] does after a build, and the cone BVH replays its
    /// splits over the renumbered candidates, as it was built over them. Queries then run on the
    /// same memory layout as after a build, and answer in the renumbered order
    /// ([`SilhouetteIndex::candidate_edges`] gives each answer's edge or corner).
    pub fn from_arrays(arrays: &SilhouetteArrays) -> Result<Self, ArraysError> {
        let n = arrays.candidate_edges.len();
        if arrays.candidate_normals.len() != 6 * n {
            return Err(ArraysError::Length {
                array: "candidate_normals",
                expected: 6 * n,
                found: arrays.candidate_normals.len(),
            });
        }
        if !arrays.candidate_points.is_empty() && arrays.candidate_points.len() != 3 * n {
            return Err(ArraysError::Length {
                array: "candidate_points",
                expected: 3 * n,
                found: arrays.candidate_points.len(),
            });
        }
        if let Some(k) = arrays.candidate_normals.iter().chain(&arrays.candidate_points).position(|x| !x.is_finite()) {
            return Err(ArraysError::Value { array: "candidate_normals/points", index: k, value: f64::NAN });
        }
        let mut normals: Vec<[Vec3; 2]> = arrays
            .candidate_normals
            .chunks_exact(6)
            .map(|c| [Vec3::new(c[0], c[1], c[2]), Vec3::new(c[3], c[4], c[5])])
            .collect();
        let mut points: Vec<Vec3> =
            arrays.candidate_points.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
        let mut candidate_edges = arrays.candidate_edges.clone();
        let gauss = match &arrays.gauss_map {
            Some(g) => {
                let (g, cells) = GaussMapHierarchy::from_arrays_with_cells(g, &normals)?;
                let (g, permutation) = g.into_storage_order();
                let pick = |k: &u32| *k as usize;
                candidate_edges = permutation.iter().map(|k| candidate_edges[pick(k)]).collect();
                normals = permutation.iter().map(|k| normals[pick(k)]).collect();
                if points.len() == n {
                    points = permutation.iter().map(|k| points[pick(k)]).collect();
                }
                Some((g, cells))
            }
            None => None,
        };
        let (gauss, cells) = gauss.unzip();
        let bvh = arrays
            .cone_bvh
            .as_ref()
            .map(|b| ConeBvh::from_arrays_with_cells(b, &normals, &points, cells.as_ref()))
            .transpose()?;
        // The choices as the arrays give them, with the structure of what was loaded: a reader
        // stores no node counts or leaf size (nor a predicted speedup, which stays as given).
        let orthographic = match (arrays.orthographic, &gauss) {
            (HierarchyChoice::GaussMap { predicted_speedup, .. }, Some(g)) => {
                HierarchyChoice::GaussMap { max_depth: g.max_depth(), nodes: g.node_count(), predicted_speedup }
            }
            (choice, _) => choice,
        };
        let perspective = match (arrays.perspective, &bvh) {
            (HierarchyChoice::ConeBvh { predicted_speedup, .. }, Some(b)) => {
                HierarchyChoice::ConeBvh { leaf_size: b.leaf_size(), nodes: b.node_count(), predicted_speedup }
            }
            (choice, _) => choice,
        };
        Ok(Self {
            candidate_edges,
            brute: std::sync::OnceLock::new(),
            normals,
            points,
            gauss,
            bvh,
            orthographic,
            perspective,
        })
    }
}

fn speedup(brute_ns: f64, hierarchy_ns: f64) -> f32 {
    if hierarchy_ns > 0.0 { (brute_ns / hierarchy_ns) as f32 } else { 0.0 }
}
