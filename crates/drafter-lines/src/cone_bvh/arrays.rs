//! The flat arrays of a cone BVH, and loading them: the binary tree is built again from the
//! recorded split bytes, and every box and cone is checked against the candidates below it.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::bounds::{PlaneAcc, PlaneBound, unit_pair};
use super::normal_split::build_tree;
use super::{CONE_MARGIN, ConeBvh, ConeBvhArrays, Stored};
use crate::ArraysError;
use crate::gauss::ArcCells;
use crate::sphere::stored_axes;
use crate::tree::check_breadth_first;

impl ConeBvh {
    /// The flat arrays (see [`ConeBvhArrays`]); `None` for a tree without a normal split
    /// ([`NormalSplit::Off`](super::NormalSplit::Off)), whose obvhs build cannot be replayed from split bytes.
    pub fn to_arrays(&self) -> Option<ConeBvhArrays> {
        Some(ConeBvhArrays {
            node_boxes: self.stored.boxes.iter().flatten().copied().collect(),
            node_cones: self.stored.cones.iter().flatten().copied().collect(),
            nodes: self.stored.nodes.iter().flatten().copied().collect(),
            normal_level: u32::from(self.stored.normal_level?),
            leaf_size: self.stored.leaf_size,
            splits: self.stored.splits.clone(),
            split_starts: self.stored.split_starts.clone(),
        })
    }

    /// Rebuilds a hierarchy from its arrays and the candidates: the binary tree is built again by
    /// replaying its recorded splits (which gives the builder's candidate order), the stored
    /// nodes must tile that order, and every box and cone must really bound the candidates below
    /// it, so a corrupted file cannot make a query drop a silhouette.
    pub fn from_arrays(arrays: &ConeBvhArrays, normals: &[[Vec3; 2]], points: &[Vec3]) -> Result<Self, ArraysError> {
        Self::from_arrays_with_cells(arrays, normals, points, None)
    }

    /// [`ConeBvh::from_arrays`] over candidates in a Gauss map's storage order, whose arc cells
    /// the normal split reads (`cells`) instead of assigning the arcs again.
    pub(crate) fn from_arrays_with_cells(
        arrays: &ConeBvhArrays,
        normals: &[[Vec3; 2]],
        points: &[Vec3],
        cells: Option<&ArcCells>,
    ) -> Result<Self, ArraysError> {
        if points.len() != normals.len() {
            return Err(ArraysError::Length { array: "points", expected: normals.len(), found: points.len() });
        }
        let normal_level = u8::try_from(arrays.normal_level).ok().filter(|&l| l <= 6).ok_or(ArraysError::Value {
            array: "normal_level",
            index: 0,
            value: f64::from(arrays.normal_level),
        })?;
        if !(1..=4096).contains(&arrays.leaf_size) {
            return Err(ArraysError::Value { array: "leaf_size", index: 0, value: f64::from(arrays.leaf_size) });
        }
        let count = arrays.nodes.len() / 4;
        if count == 0 || arrays.nodes.len() != 4 * count {
            return Err(ArraysError::Length { array: "nodes", expected: 4 * count.max(1), found: arrays.nodes.len() });
        }
        if arrays.node_boxes.len() != 6 * count {
            return Err(ArraysError::Length {
                array: "node_boxes",
                expected: 6 * count,
                found: arrays.node_boxes.len(),
            });
        }
        if arrays.node_cones.len() != 4 * count {
            return Err(ArraysError::Length {
                array: "node_cones",
                expected: 4 * count,
                found: arrays.node_cones.len(),
            });
        }
        let stored: Vec<[u32; 4]> = arrays.nodes.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let boxes: Vec<[f32; 6]> =
            arrays.node_boxes.chunks_exact(6).map(|c| [c[0], c[1], c[2], c[3], c[4], c[5]]).collect();
        let cones: Vec<[f32; 4]> = arrays.node_cones.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
        let unit: Vec<[DVec3; 2]> = normals.par_iter().map(|&n| unit_pair(n)).collect();
        let (tree, _) = build_tree(
            points,
            &unit,
            arrays.leaf_size,
            Some(normal_level),
            Some((&arrays.splits, &arrays.split_starts)),
            cells,
        )?;
        drop(unit);
        let (flat, order) = query_layout(&stored, &tree.order)?;
        check_breadth_first(&flat, normals.len())?;
        let axes = stored_axes(&cones, "node_cones")?;
        // Every stored node's candidates are a range of the replayed preorder: each node checks its
        // range against its box and cone and gathers its plane offsets (not stored: they follow
        // from the boxes and the candidates), all nodes in parallel over contiguous memory.
        let (pre_points, pre_unit): (Vec<Vec3>, Vec<[DVec3; 2]>) =
            tree.order.par_iter().map(|&k| (points[k as usize], unit_pair(normals[k as usize]))).unzip();
        let planes: Vec<PlaneBound> = stored
            .par_iter()
            .enumerate()
            .map(|(node, &[_, _, start, end])| {
                let r = start as usize..end as usize;
                let (b, s, a) = (boxes[node], f64::from(cones[node][3]), axes[node]);
                let mut acc = PlaneAcc::new(&b);
                for (i, (&p, &unit)) in pre_points[r.clone()].iter().zip(&pre_unit[r.clone()]).enumerate() {
                    let inside = b[0] <= p.x && p.x <= b[3] && b[1] <= p.y && p.y <= b[4] && b[2] <= p.z && p.z <= b[5];
                    // Angle below π/2 iff axis·n > 0, and then its sine is |axis × n| (unit vectors).
                    let in_cone = s >= 1.0
                        || unit.iter().all(|&n| {
                            n != DVec3::ZERO && a.dot(n) > 0.0 && a.cross(n).length() + CONE_MARGIN * 0.5 <= s
                        });
                    if !(inside && in_cone) {
                        return Err(ArraysError::NotConservative { node, candidate: tree.order[r.start + i] });
                    }
                    acc.add(unit, p);
                }
                Ok(acc.finish(&cones[node]))
            })
            .collect::<Result<_, _>>()?;
        let stored = Stored {
            nodes: stored,
            boxes,
            cones,
            leaf_size: arrays.leaf_size,
            normal_level: Some(normal_level),
            splits: arrays.splits.clone(),
            split_starts: arrays.split_starts.clone(),
        };
        Ok(Self::assemble(flat, order, stored, &planes, Some((normals, points))))
    }
}

/// The query layout of a stored tree (see [`ConeBvhArrays::nodes`]) over the preorder candidate
/// order `preorder`: the leaves' ranges gathered breadth-first into `order`, each node's own range
/// into it. The stored ranges must tile: the root holds every candidate and each node's children
/// split its range in order, so every candidate lands in exactly one leaf.
fn query_layout(stored: &[[u32; 4]], preorder: &[u32]) -> Result<(Vec<[u32; 4]>, Vec<u32>), ArraysError> {
    let n = preorder.len();
    if stored.first().is_none_or(|r| r[2] != 0 || r[3] as usize != n) {
        return Err(ArraysError::Tree { node: 0 });
    }
    let mut flat = Vec::with_capacity(stored.len());
    let mut order = Vec::with_capacity(n);
    for (i, &[first, count, start, end]) in stored.iter().enumerate() {
        let bad = ArraysError::Tree { node: i };
        if start > end || end as usize > n {
            return Err(bad);
        }
        if count > 0 {
            let kids = stored.get(first as usize..first as usize + count as usize).ok_or(bad.clone())?;
            let mut at = start;
            for kid in kids {
                if kid[2] != at {
                    return Err(bad);
                }
                at = kid[3];
            }
            if at != end {
                return Err(bad);
            }
            flat.push([first, count, order.len() as u32, order.len() as u32]);
        } else {
            let from = order.len() as u32;
            order.extend_from_slice(&preorder[start as usize..end as usize]);
            flat.push([first, count, from, order.len() as u32]);
        }
    }
    Ok((flat, order))
}
