//! The normal split: candidates grouped by the Gauss-map cell their arc is stored in, a
//! dual-space tree per group, and the tree of cells around them.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::build::Tree;
use super::dual::{CentreRecord, DualRecord, centre_bounds, dual_centres, dual_node, dual_points, replay_dual_node};
use super::spatial::spatial;
use crate::ArraysError;
use crate::gauss::{ArcCells, BaseSolid, DEFAULT_OVERLAP, arc_paths, base_cells};

/// The whole tree: normal cells (if any) on top, a spatial BVH below each. With `replay`
/// (`splits`, `split_starts` of [`ConeBvhArrays`]) the dual-space trees take the recorded splits
/// instead of searching for them (only with a normal level: the obvhs tree of
/// [`NormalSplit::Off`] cannot be replayed).
pub(super) fn build_tree(
    points: &[Vec3],
    unit: &[[DVec3; 2]],
    leaf_size: u32,
    normal_level: Option<u8>,
    replay: Option<(&[u8], &[u32])>,
    cells: Option<&ArcCells>,
) -> Result<(Tree, Vec<u32>), ArraysError> {
    let mut tree = Tree::default();
    let ids: Vec<u32> = (0..points.len() as u32).collect();
    let Some(level) = normal_level else {
        if replay.is_some() {
            return Err(ArraysError::Value { array: "normal_level", index: 0, value: f64::NAN });
        }
        spatial(&mut tree, &ids, points, leaf_size);
        return Ok((tree, Vec::new()));
    };
    let factor = f64::from(DEFAULT_OVERLAP);
    let paths = match cells.and_then(|c| c.paths(unit, level, factor)) {
        Some(paths) => paths,
        None => arc_paths(unit, &base_cells(BaseSolid::Icosahedron), level, factor),
    };
    let split = NormalSplitter { level };
    let records: Vec<u64> = paths.par_iter().enumerate().map(|(id, &path)| path_record(id as u32, path)).collect();
    drop(paths);
    // Three passes: the normal split lists its dual-space trees and records the tree around
    // them as steps, the dual-space trees are built (or replayed) on the thread pool, and the
    // steps are replayed, splicing them in where they were asked for.
    let mut jobs: Vec<Vec<u32>> = Vec::new();
    let mut plan: Vec<Step> = Vec::new();
    split.node(records, 0, leaf_size, &mut plan, &mut jobs);
    let built: Vec<Tree> = match replay {
        None => {
            let dual = dual_points(points, unit);
            let records = |ids: &[u32]| -> Vec<DualRecord> {
                ids.iter().map(|&id| DualRecord { b: dual[id as usize], id }).collect()
            };
            jobs.par_iter()
                .map(|ids| {
                    let mut sub = Tree::default();
                    let mut records = records(ids);
                    let bounds = centre_bounds(&records);
                    dual_node(&mut sub, &mut records, bounds, leaf_size, 0);
                    sub
                })
                .collect()
        }
        Some((splits, starts)) => {
            // The replay needs only the boxes' centres: records of 20 bytes instead of 36.
            let centres = dual_centres(points, unit);
            let records = |ids: &[u32]| -> Vec<CentreRecord> {
                ids.iter().map(|&id| CentreRecord { c: centres[id as usize], id }).collect()
            };
            if starts.len() != jobs.len() {
                return Err(ArraysError::Length { array: "split_starts", expected: jobs.len(), found: starts.len() });
            }
            let bad = |index: usize| ArraysError::Value { array: "split_starts", index, value: f64::NAN };
            jobs.par_iter()
                .enumerate()
                .map(|(j, ids)| {
                    let from = starts[j] as usize;
                    let to = starts.get(j + 1).map_or(splits.len(), |&e| e as usize);
                    let script = splits.get(from..to).ok_or_else(|| bad(j))?;
                    let mut sub = Tree::default();
                    let mut at = 0;
                    let mut records = records(ids);
                    let bounds = centre_bounds(&records);
                    replay_dual_node(&mut sub, &mut records, bounds, leaf_size, script, &mut at)?;
                    if at != script.len() { Err(bad(j)) } else { Ok(sub) }
                })
                .collect::<Result<_, _>>()?
        }
    };
    let mut starts = Vec::with_capacity(built.len());
    let mut built = built.into_iter();
    replay_plan(&mut tree, &plan, &mut |tree| {
        if let Some(sub) = built.next() {
            starts.push(tree.splits.len() as u32);
            tree.extend(sub);
        }
    });
    Ok((tree, starts))
}

/// Splits candidates by the Gauss-map cell their arc is stored in (see [`arc_paths`]), given as
/// [`path_record`]s.
struct NormalSplitter {
    level: u8,
}

/// Candidate `id` with its path `(key, cells)` ([`arc_paths`]) in one word: the key above bit 40,
/// the cell count in bits 32–39, the id below. The split moves these records instead of ids, so
/// no level reads a path table at random (a cache miss per candidate and level).
fn path_record(id: u32, (key, cells): (u32, u8)) -> u64 {
    u64::from(key) << 40 | u64::from(cells) << 32 | u64::from(id)
}

/// The normal split's tree as [`NormalSplitter::node`] built it, step by step, so that it is
/// built again around the dual-space trees without partitioning the candidates a second time
/// (a serial pass over every candidate).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// [`Tree::open`] a node.
    Open,
    /// A child of the open node starts here.
    Child,
    /// The child started last ends: it becomes a child of the open node.
    EndChild,
    /// The next dual-space tree goes here.
    Dual,
    /// [`Tree::close`] the open node.
    Close,
}

/// Builds the tree of `plan` in `tree`, calling `dual` wherever a dual-space tree goes.
fn replay_plan(tree: &mut Tree, plan: &[Step], dual: &mut dyn FnMut(&mut Tree)) {
    let (mut open, mut children) = (Vec::new(), Vec::new());
    for step in plan {
        match step {
            Step::Open => open.push(tree.open()),
            Step::Child => children.push(tree.nodes.len() as u32),
            Step::EndChild => {
                if let (Some(&at), Some(child)) = (open.last(), children.pop()) {
                    tree.children[at].push(child);
                }
            }
            Step::Dual => dual(tree),
            Step::Close => {
                if let Some(at) = open.pop() {
                    tree.close(at, false);
                }
            }
        }
    }
}

impl NormalSplitter {
    /// Plans the subtree of `records`, whose arcs all went down at least `depth` cells and share
    /// their first `depth` digits: arcs that stop here get a dual-space tree of their own (their
    /// ids go to `jobs`, a [`Step::Dual`] to `plan`), the others are grouped by their next cell.
    fn node(&self, records: Vec<u64>, depth: u8, leaf_size: u32, plan: &mut Vec<Step>, jobs: &mut Vec<Vec<u32>>) {
        let mut sink = |records: Vec<u64>, plan: &mut Vec<Step>| {
            plan.push(Step::Dual);
            jobs.push(records.into_iter().map(|r| r as u32).collect());
        };
        if depth > self.level || records.len() <= leaf_size as usize {
            sink(records, plan);
            return;
        }
        // The key's digit at this depth: a shift, not a division by 4^k (this runs for every
        // candidate at every level, twice).
        let shift = 40 + 2 * u32::from(self.level - depth);
        let digit = |r: u64| if depth == 0 { r >> shift } else { (r >> shift) & 3 };
        let mut stay = Vec::new();
        let mut groups: Vec<Vec<u64>> = vec![Vec::new(); if depth == 0 { 20 } else { 4 }];
        for r in records {
            if (r >> 32) as u8 <= depth {
                stay.push(r);
            } else {
                groups[digit(r) as usize].push(r);
            }
        }
        let parts = usize::from(!stay.is_empty()) + groups.iter().filter(|g| !g.is_empty()).count();
        if parts == 1 && stay.is_empty() {
            let only = groups.into_iter().find(|g| !g.is_empty()).unwrap_or_default();
            self.node(only, depth + 1, leaf_size, plan, jobs);
            return;
        }
        if parts == 1 {
            sink(stay, plan);
            return;
        }
        plan.push(Step::Open);
        if !stay.is_empty() {
            plan.push(Step::Child);
            sink(stay, plan);
            plan.push(Step::EndChild);
        }
        for g in groups.into_iter().filter(|g| !g.is_empty()) {
            plan.push(Step::Child);
            self.node(g, depth + 1, leaf_size, plan, jobs);
            plan.push(Step::EndChild);
        }
        plan.push(Step::Close);
    }
}
