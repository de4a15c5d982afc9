//! The flat arrays of a Gauss map, and loading them: the arcs are assigned again down the stored
//! tree with the builder's arithmetic, and every cap is checked against the endpoints below it.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::assign::{Arc, assign};
use super::{ArcCells, BaseSolid, Bins, CULL_MARGIN, GaussMapArrays, GaussMapHierarchy, Rule};
use crate::ArraysError;
use crate::sphere::stored_axes;
use crate::tree::{Purpose, breadth_first, check_breadth_first};

impl GaussMapHierarchy {
    /// The flat arrays (see [`GaussMapArrays`]).
    pub fn to_arrays(&self) -> GaussMapArrays {
        GaussMapArrays {
            base: self.rule.base.code(),
            max_depth: u32::from(self.rule.max_depth),
            node_caps: self.caps.iter().flatten().copied().collect(),
            overlap: match self.rule.bins {
                Bins::Strict => 0.0,
                Bins::Overlapping { factor } => factor,
            },
            nodes: self.tree.flat.iter().flatten().copied().collect(),
        }
    }

    /// Rebuilds a hierarchy from its arrays and the candidates' normals: assigns every arc to its
    /// cell with the builder's own arithmetic (the storage order is not stored), checks that the
    /// result has exactly the stored nodes, and that every cap really bounds the endpoints below
    /// it (so a corrupted file cannot make a query drop a silhouette).
    pub fn from_arrays(arrays: &GaussMapArrays, normals: &[[Vec3; 2]]) -> Result<Self, ArraysError> {
        Ok(Self::from_arrays_with_cells(arrays, normals)?.0)
    }

    /// [`GaussMapHierarchy::from_arrays`], also giving where each arc went (in storage order).
    pub(crate) fn from_arrays_with_cells(
        arrays: &GaussMapArrays,
        normals: &[[Vec3; 2]],
    ) -> Result<(Self, ArcCells), ArraysError> {
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
        let bins = match arrays.overlap {
            0.0 => Bins::Strict,
            f if (1.0..=8.0).contains(&f) => Bins::Overlapping { factor: f },
            f => return Err(ArraysError::Value { array: "overlap", index: 0, value: f64::from(f) }),
        };
        let count = arrays.nodes.len() / 4;
        if arrays.nodes.len() != count * 4 || count == 0 {
            return Err(ArraysError::Length { array: "nodes", expected: 4 * count.max(1), found: arrays.nodes.len() });
        }
        if arrays.node_caps.len() != 4 * count {
            return Err(ArraysError::Length { array: "node_caps", expected: 4 * count, found: arrays.node_caps.len() });
        }
        let flat: Vec<[u32; 4]> = arrays.nodes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let caps: Vec<[f32; 4]> = arrays.node_caps.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let parents = check_breadth_first(&flat, normals.len())?;
        let centers = stored_axes(&caps, "node_caps")?;
        let (order, arcs, ranges, by_id) = derived_order(&flat, normals, Rule { base, bins, max_depth })?;
        // Every arc lies in the cap of the node that owns it and in each of that node's ancestors'.
        // Each node checks its own arcs (a range of the builder's preorder) against its chain of
        // caps: all nodes in parallel, every arc read once.
        ranges.par_iter().enumerate().try_for_each(|(node, &(lo, hi))| {
            let mut chain = Vec::new();
            let mut at = node as u32;
            while at != u32::MAX {
                if caps[at as usize][3] < 1.0 {
                    chain.push((at as usize, centers[at as usize], f64::from(caps[at as usize][3])));
                }
                at = parents[at as usize];
            }
            if chain.is_empty() {
                return Ok(());
            }
            for g in &arcs[lo..hi] {
                // For unit vectors the angle r is below π/2 iff c·p > 0, and then sin r = |c × p|
                // (no atan2 per point and ancestor). A zero normal (degenerate face) is inside
                // every cap, as the builder counts it.
                for p in [g.n1, g.n2].into_iter().filter(|p| *p != DVec3::ZERO) {
                    for &(owner, c, threshold) in &chain {
                        if c.dot(p) <= 0.0 || c.cross(p).length() + CULL_MARGIN * 0.5 > threshold {
                            return Err(ArraysError::NotConservative { node: owner, candidate: g.id });
                        }
                    }
                }
            }
            Ok(())
        })?;
        drop(arcs);
        let cells = ArcCells::new(base, bins, &by_id, &order);
        let h = Self::assemble(Rule { base, bins, max_depth }, flat, caps, order, normals, Purpose::Query);
        Ok((h, cells))
    }
}

/// The storage order of a stored tree `flat` (breadth-first, pruned, checked by
/// [`check_breadth_first`]) over `normals`: the arcs are assigned again down the stored tree
/// ([`assign`]), and the breadth-first layout of the result must reproduce `flat` exactly. Also
/// returns the arcs in the builder's preorder, each stored node's range of them (its own arcs) and
/// each arc's cell by candidate ([`ArcCells::by_candidate`]).
type Derived = (Vec<u32>, Vec<Arc>, Vec<(usize, usize)>, Vec<(u32, u8, bool)>);

fn derived_order(flat: &[[u32; 4]], normals: &[[Vec3; 2]], rule: Rule) -> Result<Derived, ArraysError> {
    let (nodes, arcs) = assign(normals, rule, Some(flat), None).ok_or(ArraysError::Tree { node: 0 })?;
    let order: Vec<u32> = arcs.iter().map(|a| a.id).collect();
    let (derived, bfs_order, source) = breadth_first(
        0,
        |i| &nodes[i].children,
        |i| {
            let n = &nodes[i];
            &order[n.own.0 as usize..n.own.1 as usize]
        },
    );
    if let Some(node) = derived.iter().zip(flat).position(|(a, b)| a != b) {
        return Err(ArraysError::Tree { node });
    }
    if derived.len() != flat.len() {
        return Err(ArraysError::Tree { node: derived.len().min(flat.len()) });
    }
    let ranges = source.iter().map(|&i| (nodes[i].own.0 as usize, nodes[i].own.1 as usize)).collect();
    let by_id = ArcCells::by_candidate(&nodes, &arcs);
    Ok((bfs_order, arcs, ranges, by_id))
}
