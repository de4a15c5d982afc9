//! The plain spatialised hierarchy of [`NormalSplit::Off`](super::NormalSplit::Off): an obvhs
//! BVH2 (PLOC) over the candidates' points, kept as the baseline.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::{BvhBuildParams, aabb::Aabb, bvh2::builder::build_bvh2};

use super::build::Tree;

/// Emits an obvhs BVH2 (PLOC) over the points of `ids`, cut at `leaf_size` ([`NormalSplit::Off`]).
pub(super) fn spatial(tree: &mut Tree, ids: &[u32], points: &[Vec3], leaf_size: u32) {
    if ids.len() <= leaf_size as usize || ids.len() < 2 {
        let at = tree.open();
        tree.order.extend_from_slice(ids);
        tree.close(at, true);
        return;
    }
    let aabbs: Vec<Aabb> = ids.iter().map(|&i| Aabb::from_point(Vec3A::from(points[i as usize]))).collect();
    let params = BvhBuildParams { max_prims_per_leaf: 1, ..BvhBuildParams::fast_build() };
    let bvh = build_bvh2(&aabbs, params, &mut Duration::default());
    // Subtree sizes, children before parents: obvhs places children after their parent.
    let mut size = vec![0u32; bvh.nodes.len()];
    for i in (0..bvh.nodes.len()).rev() {
        let node = &bvh.nodes[i];
        size[i] = if node.is_leaf() {
            node.prim_count
        } else {
            let c = node.first_index as usize;
            size.get(c).copied().unwrap_or(0) + size.get(c + 1).copied().unwrap_or(0)
        };
    }
    emit_bvh_node(tree, &bvh, 0, &size, ids, leaf_size);
}

fn emit_bvh_node(tree: &mut Tree, bvh: &obvhs::bvh2::Bvh2, i: usize, size: &[u32], ids: &[u32], leaf_size: u32) {
    let at = tree.open();
    let node = &bvh.nodes[i];
    let leaf = node.is_leaf() || size[i] <= leaf_size;
    if leaf {
        gather(bvh, i, ids, &mut tree.order);
    } else {
        let c = node.first_index as usize;
        for child in [c, c + 1] {
            let k = tree.nodes.len() as u32;
            emit_bvh_node(tree, bvh, child, size, ids, leaf_size);
            tree.children[at].push(k);
        }
    }
    tree.close(at, leaf);
}

fn gather(bvh: &obvhs::bvh2::Bvh2, i: usize, ids: &[u32], order: &mut Vec<u32>) {
    let node = &bvh.nodes[i];
    if node.is_leaf() {
        let first = node.first_index as usize;
        order.extend(bvh.primitive_indices[first..first + node.prim_count as usize].iter().map(|&p| ids[p as usize]));
    } else {
        gather(bvh, node.first_index as usize, ids, order);
        gather(bvh, node.first_index as usize + 1, ids, order);
    }
}
