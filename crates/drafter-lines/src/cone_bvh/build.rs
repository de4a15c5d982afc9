//! The build: the tree of normal cells and dual-space trees, every node's bounds, the cost-model
//! pruning over sampled eyes, the widening to 4 children, and the breadth-first layout.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::bounds::{EMPTY_AABB, PlaneBound, bounding_box, cone_and_planes, plane_culls, unit_pair};
use super::normal_split::build_tree;
use super::{ConeBvh, ConeBvhOptions, NormalSplit, Stored, normal_level_for_count};
use crate::gauss::ArcCells;
use crate::sphere::fibonacci_direction;
use crate::tree::{Purpose, breadth_first};
use crate::{CostModel, EdgeSet};

/// The tree as built, in preorder with skip pointers and subtree ranges into `order` (used to
/// estimate visit frequencies and choose collapses before the breadth-first layout).
#[derive(Default)]
pub(super) struct Tree {
    /// start, end, skip, leaf flag.
    pub(super) nodes: Vec<[u32; 4]>,
    pub(super) children: Vec<Vec<u32>>,
    pub(super) order: Vec<u32>,
    /// The split byte of every inner node of the dual-space trees, in preorder.
    pub(super) splits: Vec<u8>,
}

impl Tree {
    pub(super) fn open(&mut self) -> usize {
        let at = self.nodes.len();
        let start = self.order.len() as u32;
        self.nodes.push([start, start, 0, 0]);
        self.children.push(Vec::new());
        at
    }

    pub(super) fn close(&mut self, at: usize, leaf: bool) {
        self.nodes[at][1] = self.order.len() as u32;
        self.nodes[at][2] = self.nodes.len() as u32;
        self.nodes[at][3] = u32::from(leaf);
    }

    /// Appends `sub` (built on its own) as the next child of node `at`: its node indices, skip
    /// pointers and ranges are shifted past this tree's.
    pub(super) fn append_child(&mut self, at: usize, sub: Tree) {
        let node_offset = self.nodes.len() as u32;
        self.children[at].push(node_offset);
        self.extend(sub);
    }

    /// Appends `sub` (built on its own) at the end of this tree, as [`Tree::open`] would start it.
    pub(super) fn extend(&mut self, sub: Tree) {
        let (node_offset, arc_offset) = (self.nodes.len() as u32, self.order.len() as u32);
        self.splits.extend(sub.splits);
        self.nodes.extend(
            sub.nodes
                .into_iter()
                .map(|[start, end, skip, leaf]| [start + arc_offset, end + arc_offset, skip + node_offset, leaf]),
        );
        self.children
            .extend(sub.children.into_iter().map(|c| c.into_iter().map(|k| k + node_offset).collect::<Vec<u32>>()));
        self.order.extend(sub.order);
    }
}

/// Subtrees over more candidates than this are built on the thread pool and appended to their
/// parent; smaller ones in the calling thread. The tree is the same either way.
pub(super) const PARALLEL_CANDIDATES: usize = 32 * 1024;

impl ConeBvh {
    /// Builds the hierarchy over candidates with `normals` and points `points` (one each).
    pub fn build(normals: &[[Vec3; 2]], points: &[Vec3], options: &ConeBvhOptions, cost: &CostModel) -> Self {
        Self::build_with_cells(normals, points, options, cost, None, Purpose::Query)
    }

    /// [`ConeBvh::build`] over candidates in a Gauss map's storage order, whose arc cells the
    /// normal split reads (`cells`) instead of assigning the arcs again. A [`Purpose::Storage`]
    /// build has no candidate stream and cannot answer queries; only its arrays and predicted
    /// cost are used.
    pub(crate) fn build_with_cells(
        normals: &[[Vec3; 2]],
        points: &[Vec3],
        options: &ConeBvhOptions,
        cost: &CostModel,
        cells: Option<&ArcCells>,
        purpose: Purpose,
    ) -> Self {
        let n = normals.len().min(points.len());
        let (normals, points) = (&normals[..n], &points[..n]);
        let leaf_size = options.leaf_size.clamp(1, 4096);
        let unit: Vec<[DVec3; 2]> = normals.par_iter().map(|&n| unit_pair(n)).collect();
        let normal_level = match options.normal_split {
            NormalSplit::Off => None,
            NormalSplit::Level(l) => Some(l.min(6)),
            NormalSplit::Auto => Some(normal_level_for_count(n)),
        };
        let (tree, split_starts) = match build_tree(points, &unit, leaf_size, normal_level, None, cells) {
            Ok(built) => built,
            Err(_) => unreachable!("a build without a replay script does not fail"),
        };
        let (boxes, cones, planes) = node_bounds(&tree, points, unit);
        let eyes = sample_eyes(points, options.sample_eyes);
        let mut leaf: Vec<bool> = tree.nodes.iter().map(|n| n[3] == 1).collect();
        if !eyes.is_empty() && options.prune {
            let (visits, passes) = visit_frequencies(&tree.nodes, &boxes, &cones, &planes, &eyes);
            for (i, c) in collapse_by_cost(&tree.nodes, &tree.children, &visits, &passes, cost).into_iter().enumerate()
            {
                leaf[i] |= c;
            }
        }
        let wide = widen(&tree, &leaf);
        let (flat, order, source) = breadth_first(
            0,
            |i| &wide[i],
            |i| if leaf[i] { &tree.order[tree.nodes[i][0] as usize..tree.nodes[i][1] as usize] } else { &[] },
        );
        let boxes: Vec<[f32; 6]> = source.iter().map(|&i| boxes[i]).collect();
        let cones: Vec<[f32; 4]> = source.iter().map(|&i| cones[i]).collect();
        let planes: Vec<PlaneBound> = source.iter().map(|&i| planes[i]).collect();
        let stored: Vec<[u32; 4]> = flat
            .iter()
            .zip(&source)
            .map(|(&[first, count, _, _], &i)| [first, count, tree.nodes[i][0], tree.nodes[i][1]])
            .collect();
        let stored = Stored { nodes: stored, boxes, cones, leaf_size, normal_level, splits: tree.splits, split_starts };
        let candidates = (purpose == Purpose::Query).then_some((normals, points));
        let mut bvh = Self::assemble(flat, order, stored, &planes, candidates);
        if !eyes.is_empty() {
            // On the thread pool, summed in eye order: the same figure at any thread count.
            let costs: Vec<f64> = eyes
                .par_iter()
                .map(|&e| bvh.walk::<true, false>(e, &mut EdgeSet::default()).cost_ns(cost, false))
                .collect();
            bvh.predicted_ns = costs.iter().sum::<f64>() / eyes.len() as f64;
        }
        bvh
    }
}

/// Every node's box, normal cone and plane bound over its candidates (`points`, unit normals
/// `unit`, in input order), for the tree as built.
fn node_bounds(tree: &Tree, points: &[Vec3], unit: Vec<[DVec3; 2]>) -> (Vec<[f32; 6]>, Vec<[f32; 4]>, Vec<PlaneBound>) {
    // The candidates in tree order, so that every node's bounds read one contiguous range
    // (gathering through `order` per node and level missed the cache on every candidate).
    let (tree_points, tree_unit) =
        (drafter_core::gather(points, &tree.order), drafter_core::gather(&unit, &tree.order));
    drop(unit);
    let range = |start: u32, end: u32| start as usize..end as usize;
    // Boxes bottom-up: a leaf's from its points, an inner node's the union of its children's
    // (whose ranges tile its own), the same box as from its points at a fraction of the work.
    let mut boxes: Vec<[f32; 6]> = tree
        .nodes
        .par_iter()
        .map(
            |&[start, end, _, leaf]| {
                if leaf == 1 { bounding_box(tree_points[range(start, end)].iter().copied()) } else { EMPTY_AABB }
            },
        )
        .collect();
    for i in (0..tree.nodes.len()).rev() {
        for &c in &tree.children[i] {
            let b = boxes[c as usize];
            let a = &mut boxes[i];
            for k in 0..3 {
                a[k] = a[k].min(b[k]);
                a[k + 3] = a[k + 3].max(b[k + 3]);
            }
        }
    }
    let (cones, planes): (Vec<[f32; 4]>, Vec<PlaneBound>) = tree
        .nodes
        .par_iter()
        .enumerate()
        .map(|(i, &[start, end, _, _])| {
            let r = range(start, end);
            cone_and_planes(&tree_unit[r.clone()], &tree_points[r], &boxes[i])
        })
        .unzip();
    (boxes, cones, planes)
}

/// Each node's children in the widened tree: none for a leaf (`leaf`), and up to 4 otherwise, the
/// binary tree's inner children absorbed into their parent, the largest first.
fn widen(tree: &Tree, leaf: &[bool]) -> Vec<Vec<u32>> {
    // Up to 4 children per node: absorb the largest inner children into their parent.
    let size = |i: usize| tree.nodes[i][1] - tree.nodes[i][0];
    (0..tree.nodes.len())
        .map(|i| {
            if leaf[i] {
                return Vec::new();
            }
            let mut kids = tree.children[i].clone();
            while kids.len() < 4 {
                let Some((k, _)) = kids
                    .iter()
                    .enumerate()
                    .filter(|&(_, &c)| !leaf[c as usize] && kids.len() - 1 + tree.children[c as usize].len() <= 4)
                    .max_by_key(|&(_, &c)| size(c as usize))
                else {
                    break;
                };
                let c = kids.remove(k) as usize;
                kids.splice(k..k, tree.children[c].iter().copied());
            }
            kids
        })
        .collect()
}

/// For each node, the fraction of `eyes` that test its bound and the fraction for which it is not
/// culled.
fn visit_frequencies(
    flat: &[[u32; 4]],
    boxes: &[[f32; 6]],
    cones: &[[f32; 4]],
    planes: &[PlaneBound],
    eyes: &[Vec3],
) -> (Vec<f64>, Vec<f64>) {
    let n = flat.len();
    let counts = eyes
        .par_iter()
        .fold(
            || vec![[0u32; 2]; n],
            |mut acc, &eye| {
                let mut i = 0;
                while i < n {
                    let [_, _, skip, leaf] = flat[i];
                    acc[i][0] += 1;
                    if plane_culls(&boxes[i], &cones[i], &planes[i], eye) {
                        i = skip as usize;
                        continue;
                    }
                    acc[i][1] += 1;
                    i = if leaf == 1 { skip as usize } else { i + 1 };
                }
                acc
            },
        )
        .reduce(|| vec![[0u32; 2]; n], |a, b| a.iter().zip(&b).map(|(x, y)| [x[0] + y[0], x[1] + y[1]]).collect());
    let k = eyes.len() as f64;
    counts.iter().map(|c| (f64::from(c[0]) / k, f64::from(c[1]) / k)).unzip()
}

/// Bottom-up choice of the nodes to turn into leaves, by expected cost over the sampled eyes
/// (on the preorder tree, before it is widened).
fn collapse_by_cost(
    nodes: &[[u32; 4]],
    children: &[Vec<u32>],
    visits: &[f64],
    passes: &[f64],
    cost: &CostModel,
) -> Vec<bool> {
    let n = nodes.len();
    let enter = f64::from(cost.bvh_enter_ns);
    let test = f64::from(cost.bvh_test_ns);
    let range = f64::from(cost.bvh_range_ns);
    let block = f64::from(cost.bvh_block_ns);
    let mut best = vec![0.0f64; n];
    let mut collapse = vec![false; n];
    for i in (0..n).rev() {
        let [start, end, _, leaf] = nodes[i];
        let blocks = f64::from((end - start).div_ceil(4));
        // Tested by the parent on every visit; entered and its range read when it passes.
        let leaf_cost = visits[i] * test + passes[i] * (enter + range + block * blocks);
        if leaf == 1 {
            best[i] = leaf_cost;
            continue;
        }
        let split = visits[i] * test + passes[i] * enter + children[i].iter().map(|&c| best[c as usize]).sum::<f64>();
        if leaf_cost < split {
            collapse[i] = true;
            best[i] = leaf_cost;
        } else {
            best[i] = split;
        }
    }
    collapse
}

/// Deterministic eyes on spheres around the points' bounding box, 1.2 to 4 half-diagonals from its
/// centre (always outside the box).
pub(crate) fn sample_eyes(points: &[Vec3], count: u32) -> Vec<Vec3> {
    if points.is_empty() || count == 0 {
        return Vec::new();
    }
    let b = bounding_box(points.iter().copied());
    let (lo, hi) = (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]));
    let center = (lo + hi) * 0.5;
    let half = ((hi - lo) * 0.5).length().max(1e-6);
    (0..count)
        .map(|k| {
            // Fibonacci sphere directions, radii cycling through [1.2, 4].
            let dir = fibonacci_direction(k, count);
            let dist = half * (1.2 + 2.8 * ((k as f32 * 0.618_034) % 1.0));
            center + dir * dist
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eyes_are_outside_the_box() {
        let pts = [Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)];
        for e in sample_eyes(&pts, 50) {
            assert!(!(e.cmpge(Vec3::ZERO).all() && e.cmple(Vec3::new(1.0, 2.0, 3.0)).all()));
        }
    }
}
