//! Where every arc goes: the bin rule's descent from the root, level by level, moving the arcs
//! between two buffers by a stable scatter per node, with the caps and the stop rule of a build
//! or the stored tree a reader follows.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::cap::subtree_cap;
use super::cells::{BaseByOctant, Cell, arc_mid, base_cells, bin_cos, fits_bin};
use super::quad::Quad;
use super::{Bins, CULL_MARGIN, Rule};
use crate::CostModel;

/// An arc as the builder moves it: its candidate and its unit endpoints (zero for a degenerate
/// face). The builder partitions these records in place, level after level, so that every pass
/// reads and writes memory in sequence (carrying indices into a shared array instead cost a cache
/// miss per arc and level on a million-arc mesh). The midpoint is recomputed where it is needed,
/// which is cheaper than moving it along.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Arc {
    pub(super) n1: DVec3,
    pub(super) n2: DVec3,
    pub(super) id: u32,
    /// A lower bound on the visit probability of any node holding the arc ([`StopRule`]'s
    /// `p_a`), in the record's padding.
    pub(super) p: f32,
}

impl Arc {
    /// The arc's midpoint; `None` for a zero or antipodal arc.
    pub(super) fn mid(&self) -> Option<DVec3> {
        arc_mid([self.n1, self.n2])
    }
}

/// The arcs of the candidates with `normals`, as the builder moves them.
fn arc_records(normals: &[[Vec3; 2]]) -> Vec<Arc> {
    normals
        .par_iter()
        .enumerate()
        .map(|(id, &[a, b])| {
            let (n1, n2) = (a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero());
            // The visit probability bound of `StopRule`, rounded down.
            let p = ((n1 - n2).length() * 0.5 + CULL_MARGIN).min(1.0);
            let p32 = p as f32;
            Arc { n1, n2, id: id as u32, p: if f64::from(p32) > p { p32.next_down() } else { p32 } }
        })
        .collect()
}

pub(super) struct BuildNode {
    pub(super) depth: u8,
    /// The node's own arcs, positions in the final arc order.
    pub(super) own: (u32, u32),
    /// End of the subtree's arcs in the final arc order.
    pub(super) sub_end: u32,
    pub(super) children: Vec<u32>,
    /// The cell's digits: base face, then one digit per 4:1 split (unpadded; 0 for the root).
    pub(super) key: u32,
    /// Whether the arcs were offered to the children (false at `max_depth`, at a stored leaf and
    /// where the build stopped because collapsing is optimal, where the bin rule might have taken
    /// them further).
    pub(super) tried: bool,
    /// The cap over the subtree's endpoints ([`cap_of`]); zero when the caller does not
    /// need caps (a reader's guided assignment).
    pub(super) cap: [f32; 4],
}

/// Subtrees holding more arcs than this are built on the thread pool (one task per child cell)
/// and appended to their parent; smaller ones in the calling thread. The tree is the same either
/// way.
pub(super) const PARALLEL_ARCS: usize = 32 * 1024;

/// A cell and the cosine of its bin radius (see [`Bins`]), computed once per cell rather than
/// once per arc tested against it.
#[derive(Clone, Copy)]
pub(super) struct BinCell {
    pub(super) cell: Cell,
    pub(super) cos_bin: f64,
}

/// Arcs per task of [`drafter_core::scatter_in_parallel`] (the root level's scatter touches every
/// arc, too much to leave on one core).
const SCATTER_CHUNK: usize = 1 << 16;

struct Builder {
    bins: Bins,
    max_depth: u8,
    base: Vec<Cell>,
    /// The base cells that may hold a point of each octant ([`BaseByOctant`]).
    by_octant: BaseByOctant,
    /// Compute each node's cap (a build; a reader's guided assignment needs none).
    caps: bool,
    /// Stop descending where collapsing the subtree is provably the cheapest choice of the
    /// cost-model pruning (see [`StopRule`]); `None` builds to `max_depth`.
    stop: Option<StopRule>,
}

/// The pruning's costs (see [`GaussMapHierarchy::build_with_cells`]), used during the build to
/// stop where the pruning would collapse whatever was built below.
///
/// A node with visit probability `p` over `n` arcs costs `p · (enter + range + block · ⌈n/4⌉)`
/// collapsed. Let `p_a` be a lower bound on the visit probability of any node holding arc `a`: a
/// cap holding both endpoints has a radius of at least half the arc, so its threshold is at least
/// `sin(θ/2) + ε = |n1 − n2| / 2 + ε` (or the whole sphere, 1). Any split of the node then costs at
/// least
/// * `p · (enter + test)`: it is entered and tests at least one child;
/// * `min(p · range, (enter + range) · max p_a)`: the arc of largest `p_a` is tested either among
///   the node's own arcs or in a descendant that is entered;
/// * `block · max(max p_a, Σ p_a / 4)`: every arc is tested in some block of 4, and the arc of
///   largest `p_a` in a block of its own at worst.
///
/// Where the collapsed cost is not above that bound, the bottom-up pruning collapses the node
/// whatever its subtree, so the build does not make the subtree. On the dragon (1.3M arcs) the
/// build makes 201k nodes instead of 396k (of which the pruning kept 24k either way).
#[derive(Clone, Copy)]
pub(super) struct StopRule {
    pub(super) enter: f64,
    pub(super) test: f64,
    pub(super) range: f64,
    pub(super) block: f64,
}

impl StopRule {
    /// The Gauss-map costs of `cost`.
    pub(super) fn of(cost: &CostModel) -> Self {
        StopRule {
            enter: f64::from(cost.gauss_enter_ns),
            test: f64::from(cost.gauss_test_ns),
            range: f64::from(cost.gauss_range_ns),
            block: f64::from(cost.gauss_block_ns),
        }
    }
}

/// A stored breadth-first tree and a node's index in it, which a reader's assignment follows.
type Guide<'a> = Option<(&'a [[u32; 4]], usize)>;

/// Where an arc goes at a node: it stays there.
pub(super) const STAY: u8 = u8::MAX;

impl Builder {
    fn bin_cell(&self, cell: Cell) -> BinCell {
        let cos_bin = match self.bins {
            Bins::Strict => 0.0,
            Bins::Overlapping { factor } => bin_cos(&cell, f64::from(factor)),
        };
        BinCell { cell, cos_bin }
    }

    #[inline]
    fn fits(&self, bin: &BinCell, arc: &Arc) -> bool {
        match self.bins {
            Bins::Strict => bin.cell.score(arc.n1) >= 0.0 && bin.cell.score(arc.n2) >= 0.0,
            Bins::Overlapping { .. } => fits_bin(&bin.cell, bin.cos_bin, [arc.n1, arc.n2]),
        }
    }

    /// The cap over the endpoints of the node's `arcs` (`cell`: its cell, `None` for the root), its
    /// visit probability (at most `parent_prob`), and whether the stop rule ends the descent here
    /// (see [`StopRule`]); no cap, and no stop, where the builder computes no caps.
    fn measure(&self, cell: Option<Cell>, arcs: &[Arc], parent_prob: f64) -> ([f32; 4], f64, bool) {
        if self.caps {
            let m = subtree_cap(arcs, cell.map(|c| c.center));
            let prob = parent_prob.min(f64::from(m.cap[3]).min(1.0));
            let stop = self.stop.is_some_and(|r| {
                let n = arcs.len() as f64;
                let collapsed = prob * (r.enter + r.range + r.block * (n / 4.0).ceil());
                let split_at_least = prob * (r.enter + r.test)
                    + (prob * r.range).min((r.enter + r.range) * m.p_max)
                    + r.block * m.p_max.max(m.p_sum / 4.0);
                collapsed <= split_at_least * (1.0 - 1e-9)
            });
            (m.cap, prob, stop)
        } else {
            ([0.0; 4], parent_prob, false)
        }
    }

    /// The child of `children` each arc of `arcs` goes to, or [`STAY`].
    fn targets(&self, children: &[BinCell], arcs: &[Arc]) -> Vec<u8> {
        let quad = (children.len() == 4).then(|| Quad::of(children));
        let overlapping = matches!(self.bins, Bins::Overlapping { .. });
        // The general rule (the root's base cells, strict bins); `Quad::targets` for a 4:1 split
        // under overlapping bins, the bulk of the work.
        let target = |g: &Arc| {
            g.mid()
                .and_then(|m| {
                    let best = match &quad {
                        Some(q) => q.most_inside(m),
                        None => self.by_octant.most_inside(&self.base, m),
                    };
                    (best < children.len() && self.fits(&children[best], g)).then_some(best as u8)
                })
                .unwrap_or(STAY)
        };
        match &quad {
            Some(q) if overlapping => {
                let mut t = vec![0u8; arcs.len()];
                if arcs.len() > PARALLEL_ARCS {
                    t.par_chunks_mut(4096).zip(arcs.par_chunks(4096)).for_each(|(t, a)| q.targets(children, a, t));
                } else {
                    q.targets(children, arcs, &mut t);
                }
                t
            }
            _ if arcs.len() > PARALLEL_ARCS => arcs.par_iter().with_min_len(4096).map(target).collect(),
            _ => arcs.iter().map(target).collect(),
        }
    }

    /// Appends to `out` the subtree, in preorder, for `cell` (`None`: the root) holding `arcs`,
    /// which start at position `offset` of the final order, and leaves the arcs in that order: the
    /// node's own arcs, then each child's subtree (stable: input order within each).
    ///
    /// The arcs move between two buffers, one scatter per level (ping-pong): `arcs` holds them on
    /// entry and `spare` is free, as long as `arcs`. `flipped` says that `arcs` is the caller's
    /// scratch buffer and `spare` its arc buffer, where the final order must end up.
    ///
    /// With `guide` (a stored breadth-first tree and this node's index in it) the descent follows
    /// the stored tree instead of going to `max_depth`: a stored leaf keeps all its arcs (in input
    /// order, as the build stores a collapsed subtree), and a stored inner node must split into
    /// exactly its stored children. Returns false where the arcs do not split as stored.
    #[allow(clippy::too_many_arguments)]
    fn node(
        &self,
        cell: Option<Cell>,
        depth: u8,
        arcs: &mut [Arc],
        spare: &mut [Arc],
        flipped: bool,
        offset: u32,
        out: &mut Vec<BuildNode>,
        (key, guide): (u32, Guide<'_>),
        parent_prob: f64,
    ) -> bool {
        let index = out.len();
        let (cap, prob, stop) = self.measure(cell, arcs, parent_prob);
        out.push(BuildNode {
            depth,
            own: (offset, offset),
            sub_end: offset + arcs.len() as u32,
            children: Vec::new(),
            key,
            tried: false,
            cap,
        });
        let stored_children = guide.map(|(tree, at)| tree[at][1]);
        let children: Vec<BinCell> = match cell {
            _ if stored_children == Some(0) || stop => Vec::new(),
            None => self.base.iter().map(|&c| self.bin_cell(c)).collect(),
            // Depth 1 is level 0; a cell at level `depth - 1` splits while that is below max_depth.
            Some(c) if depth <= self.max_depth => c.children().iter().map(|&c| self.bin_cell(c)).collect(),
            Some(_) => Vec::new(),
        };
        if children.is_empty() {
            out[index].own.1 = offset + arcs.len() as u32;
            if flipped {
                spare.copy_from_slice(arcs);
            }
            return stored_children.is_none_or(|c| c == 0);
        }
        out[index].tried = true;
        // Where each arc goes, then a stable counting scatter: own arcs first, then by child.
        let targets = self.targets(&children, arcs);
        // At most the 20 base cells, the own arcs and an end: on the stack (one node per cell).
        let mut starts = [0usize; 22];
        let starts = &mut starts[..children.len() + 2];
        scatter(arcs, &targets, spare, starts);
        drop(targets);
        // The arcs are now in `spare`; the own ones stay there if that is the final buffer.
        if !flipped {
            arcs[..starts[1]].copy_from_slice(&spare[..starts[1]]);
        }
        out[index].own.1 = offset + starts[1] as u32;
        let filled = (0..children.len()).filter(|&k| starts[k + 2] > starts[k + 1]).count();
        if stored_children.is_some_and(|c| c as usize != filled) {
            return false;
        }

        // The children's ranges, split off the two buffers in order; the roles swap below.
        let parallel = arcs.len() > PARALLEL_ARCS;
        let mut work = Vec::new();
        let (mut rest, mut rest_spare) = (&mut spare[starts[1]..], &mut arcs[starts[1]..]);
        for k in 0..children.len() {
            let len = starts[k + 2] - starts[k + 1];
            let (these, tail) = rest.split_at_mut(len);
            let (these_spare, tail_spare) = rest_spare.split_at_mut(len);
            (rest, rest_spare) = (tail, tail_spare);
            if len > 0 {
                let child_guide = guide.map(|(tree, at)| (tree, tree[at][0] as usize + work.len()));
                let child_key = if cell.is_none() { k as u32 } else { key * 4 + k as u32 };
                work.push((
                    children[k].cell,
                    these,
                    these_spare,
                    offset + starts[k + 1] as u32,
                    (child_key, child_guide),
                ));
            }
        }
        if parallel {
            let subtrees: Vec<(Vec<BuildNode>, bool)> = work
                .into_par_iter()
                .map(|(cell, these, these_spare, at, g)| {
                    let mut sub = Vec::new();
                    let ok = self.node(Some(cell), depth + 1, these, these_spare, !flipped, at, &mut sub, g, prob);
                    (sub, ok)
                })
                .collect();
            let mut ok = true;
            for (sub, fine) in subtrees {
                ok &= fine;
                let node_offset = out.len() as u32;
                out[index].children.push(node_offset);
                out.extend(sub.into_iter().map(|mut n| {
                    n.children.iter_mut().for_each(|c| *c += node_offset);
                    n
                }));
            }
            ok
        } else {
            for (cell, these, these_spare, at, g) in work {
                let child = out.len() as u32;
                if !self.node(Some(cell), depth + 1, these, these_spare, !flipped, at, out, g, prob) {
                    return false;
                }
                out[index].children.push(child);
            }
            true
        }
    }
}

/// The stable counting scatter of `arcs` into `spare` by `targets`: the arcs that stay first, then
/// child by child, input order within each; `starts` (zero, one entry per bucket and an end)
/// receives where each bucket starts.
fn scatter(arcs: &[Arc], targets: &[u8], spare: &mut [Arc], starts: &mut [usize]) {
    let bucket = |t: u8| if t == STAY { 0 } else { usize::from(t) + 1 };
    if arcs.len() > PARALLEL_ARCS {
        drafter_core::scatter_in_parallel(arcs, |i| bucket(targets[i]), SCATTER_CHUNK, spare, starts);
    } else {
        for &t in targets {
            starts[bucket(t) + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        let mut next = [0usize; 22];
        next[..starts.len()].copy_from_slice(starts);
        for (g, &t) in arcs.iter().zip(targets) {
            let b = bucket(t);
            spare[next[b]] = *g;
            next[b] += 1;
        }
    }
}

/// Every arc assigned to its cell by the bin rule: the builder's nodes in preorder and the arcs in
/// preorder storage order (each node's own arcs, then its children's subtrees; input order within
/// each). The one definition of where an arc goes, used by the build and by
/// [`GaussMapHierarchy::from_arrays`], so that both find the same cells bit for bit. With `guide`
/// (a stored breadth-first tree, already checked by [`check_breadth_first`]) the descent stops at
/// the stored leaves, whose arcs stay in input order; `None` where the arcs do not split as stored.
/// Without `guide`, every node's cap is computed, and with `stop` the descent ends where the
/// pruning would collapse the node whatever lies below (see [`StopRule`]).
pub(super) fn assign(
    normals: &[[Vec3; 2]],
    rule: Rule,
    guide: Option<&[[u32; 4]]>,
    stop: Option<StopRule>,
) -> Option<(Vec<BuildNode>, Vec<Arc>)> {
    let mut arcs = arc_records(normals);
    let base = base_cells(rule.base);
    let builder = Builder {
        bins: rule.bins,
        max_depth: rule.max_depth,
        by_octant: BaseByOctant::new(&base),
        base,
        caps: guide.is_none(),
        stop,
    };
    let mut nodes = Vec::new();
    let mut scratch = drafter_core::filled_in_parallel(arcs.len(), Arc::default());
    let guide = (0, guide.map(|g| (g, 0)));
    let ok = builder.node(None, 0, &mut arcs, &mut scratch, false, 0, &mut nodes, guide, 1.0);
    ok.then_some((nodes, arcs))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The chunked scatter puts every arc where the serial stable scatter does, with the same
    /// bucket starts, for 4 and 20 children and counts around the chunk size.
    #[test]
    fn parallel_scatter_is_the_serial_scatter() {
        let mut rng = drafter_core::rng::Rng::new(9);
        for (len, children) in [(SCATTER_CHUNK * 3 + 17, 20usize), (SCATTER_CHUNK + 1, 4), (SCATTER_CHUNK - 1, 4)] {
            let arcs: Vec<Arc> = (0..len as u32).map(|id| Arc { id, ..Arc::default() }).collect();
            let targets: Vec<u8> = (0..len)
                .map(|_| {
                    let k = (rng.unit_f32() * (children + 1) as f32) as usize;
                    if k >= children { STAY } else { k as u8 }
                })
                .collect();
            let bucket = |t: u8| if t == STAY { 0 } else { usize::from(t) + 1 };
            let mut expected_starts = vec![0usize; children + 2];
            for &t in &targets {
                expected_starts[bucket(t) + 1] += 1;
            }
            for k in 1..expected_starts.len() {
                expected_starts[k] += expected_starts[k - 1];
            }
            let mut expected: Vec<u32> = Vec::with_capacity(len);
            for b in 0..=children {
                expected.extend(arcs.iter().zip(&targets).filter(|(_, t)| bucket(**t) == b).map(|(a, _)| a.id));
            }
            let mut spare = vec![Arc { id: u32::MAX, ..Arc::default() }; len];
            let mut starts = vec![0usize; children + 2];
            drafter_core::scatter_in_parallel(&arcs, |i| bucket(targets[i]), SCATTER_CHUNK, &mut spare, &mut starts);
            assert_eq!(starts, expected_starts);
            assert!(spare.iter().map(|a| a.id).eq(expected.iter().copied()), "{len} arcs, {children} children");
        }
    }
}
