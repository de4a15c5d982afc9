//! The dual-space trees: a binned surface-area-style split of the 4D points of face planes, and
//! its replay from the recorded split bytes (see the module docs of `cone_bvh`).

use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;

use super::bounds::{anchor, bounding_box};
use super::build::{PARALLEL_CANDIDATES, Tree};
use super::{DUAL_NORMAL_WEIGHT, MEDIAN_SPLIT};
use crate::ArraysError;

/// Bins per axis of the dual-space split search.
const DUAL_BINS: usize = 32;

/// Below this depth the dual-space build takes the heuristic's split; deeper (only for
/// adversarial distributions that peel off a few candidates per split) it splits at the median,
/// which bounds the recursion.
const DUAL_SAH_DEPTH: u32 = 48;

/// A candidate in the dual space of face planes: the 4D box (min, max) of its two planes'
/// points `(k·n̂, n̂·(v − c))` (see the module docs).
pub(super) type DualBox = [[f32; 4]; 2];

/// The frame of the dual space over `points`: the centre `c` of their bounding box and the normal
/// weight `k` (see the module docs).
fn dual_frame(points: &[Vec3]) -> (Vec3, f32) {
    let b = bounding_box(points.iter().copied());
    let (lo, hi) = (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]));
    (anchor(&b), DUAL_NORMAL_WEIGHT * ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE))
}

/// A candidate's [`DualBox`] in the frame `(c, k)` of [`dual_frame`].
fn dual_box((c, k): (Vec3, f32), [n1, n2]: [DVec3; 2], v: Vec3) -> DualBox {
    let d = v - c;
    let plane = |n: DVec3| {
        let n = n.as_vec3();
        [k * n.x, k * n.y, k * n.z, n.dot(d)]
    };
    let (a, b) = (plane(n1), plane(n2));
    [std::array::from_fn(|i| a[i].min(b[i])), std::array::from_fn(|i| a[i].max(b[i]))]
}

/// Every candidate's [`DualBox`].
pub(super) fn dual_points(points: &[Vec3], unit: &[[DVec3; 2]]) -> Vec<DualBox> {
    let frame = dual_frame(points);
    unit.par_iter().zip(points).map(|(&n, &v)| dual_box(frame, n, v)).collect()
}

/// Every candidate's [`DualBox`] centre, as [`DualRecord::centre`] computes it.
pub(super) fn dual_centres(points: &[Vec3], unit: &[[DVec3; 2]]) -> Vec<[f32; 4]> {
    let frame = dual_frame(points);
    unit.par_iter().zip(points).map(|(&n, &v)| box_centre(&dual_box(frame, n, v))).collect()
}

fn box_centre(b: &DualBox) -> [f32; 4] {
    std::array::from_fn(|a| (b[0][a] + b[1][a]) * 0.5)
}

/// Mean-width measure of a 4D box: the sum of its extents.
fn dual_width(b: &DualBox) -> f32 {
    (0..4).map(|i| (b[1][i] - b[0][i]).max(0.0)).sum()
}

const EMPTY_BOX: DualBox = [[f32::INFINITY; 4], [f32::NEG_INFINITY; 4]];

fn grow(a: &mut DualBox, b: &DualBox) {
    for i in 0..4 {
        a[0][i] = a[0][i].min(b[0][i]);
        a[1][i] = a[1][i].max(b[1][i]);
    }
}

/// A candidate as the dual-space build moves it: its box and its index. The build reorders
/// these records in place, so that every pass reads memory in sequence (indices into a shared box
/// array cost a cache miss per candidate and level on a million-candidate mesh).
#[derive(Clone, Copy)]
pub(super) struct DualRecord {
    pub(super) b: DualBox,
    pub(super) id: u32,
}

/// What [`apply_split`] needs of a record: its dual-space box centre and its candidate.
pub(super) trait Centred {
    fn centre(&self) -> [f32; 4];
    fn id(&self) -> u32;
}

impl Centred for DualRecord {
    fn centre(&self) -> [f32; 4] {
        box_centre(&self.b)
    }
    fn id(&self) -> u32 {
        self.id
    }
}

/// A candidate as the replay moves it: the centre of its [`DualBox`] and its index (the replay
/// never needs the box itself).
#[derive(Clone, Copy)]
pub(super) struct CentreRecord {
    pub(super) c: [f32; 4],
    pub(super) id: u32,
}

impl Centred for CentreRecord {
    fn centre(&self) -> [f32; 4] {
        self.c
    }
    fn id(&self) -> u32 {
        self.id
    }
}

/// Emits the dual-space tree over `records` (reordered in place), binary, top-down: on each of the
/// 4 axes the candidates' box centres go into [`DUAL_BINS`] bins, and the split between bins
/// that minimises `count_left · width_left + count_right · width_right` is taken (the binned
/// surface-area heuristic of ray tracing, with the mean width that measures how often a random
/// hyperplane crosses a box). Deterministic: in place, ties to the first axis and bin; subtrees
/// of more than [`PARALLEL_CANDIDATES`] are built on the thread pool, which gives the same tree.
/// Candidates whose centres coincide on every axis are split in halves. `bounds` is the box of the
/// records' centres.
pub(super) fn dual_node(tree: &mut Tree, records: &mut [DualRecord], bounds: DualBox, leaf_size: u32, depth: u32) {
    let at = tree.open();
    if records.len() <= leaf_size as usize || records.len() < 2 {
        tree.order.extend(records.iter().map(|r| r.id));
        tree.close(at, true);
        return;
    }
    // Axes whose centres all coincide (or are not finite) offer no split.
    let splittable: [bool; 4] =
        std::array::from_fn(|a| (bounds[1][a] - bounds[0][a]).partial_cmp(&0.0) == Some(std::cmp::Ordering::Greater));
    // (cost, axis, first bin of the right side)
    let mut best: Option<(f32, usize, usize)> = None;
    if depth < DUAL_SAH_DEPTH && splittable.iter().any(|&s| s) {
        // All four axes binned in one pass over the records; on the thread pool for large nodes
        // (counts add and boxes take minima and maxima: the same bins in any split).
        type Bins = ([[usize; DUAL_BINS]; 4], [[DualBox; DUAL_BINS]; 4]);
        let empty = || -> Bins { ([[0usize; DUAL_BINS]; 4], [[EMPTY_BOX; DUAL_BINS]; 4]) };
        let bin = |chunk: &[DualRecord]| {
            let mut acc = empty();
            for r in chunk {
                let bins = bins_of(&bounds, r.centre());
                for a in (0..4).filter(|&a| splittable[a]) {
                    let k = bins[a];
                    acc.0[a][k] += 1;
                    grow(&mut acc.1[a][k], &r.b);
                }
            }
            acc
        };
        let (count, bin_box) = if records.len() > PARALLEL_CANDIDATES {
            records.par_chunks(16 * 1024).map(bin).reduce(empty, |mut x, y| {
                for a in 0..4 {
                    for k in 0..DUAL_BINS {
                        x.0[a][k] += y.0[a][k];
                        grow(&mut x.1[a][k], &y.1[a][k]);
                    }
                }
                x
            })
        } else {
            bin(records)
        };
        for a in (0..4).filter(|&a| splittable[a]) {
            let (count, bin_box) = (&count[a], &bin_box[a]);
            let mut right_cost = [0f32; DUAL_BINS];
            let (mut acc, mut n) = (EMPTY_BOX, 0usize);
            for k in (1..DUAL_BINS).rev() {
                n += count[k];
                grow(&mut acc, &bin_box[k]);
                right_cost[k] = n as f32 * dual_width(&acc);
            }
            let (mut acc, mut n) = (EMPTY_BOX, 0usize);
            for k in 0..DUAL_BINS - 1 {
                n += count[k];
                grow(&mut acc, &bin_box[k]);
                if n == 0 || n == records.len() {
                    continue;
                }
                let cost = n as f32 * dual_width(&acc) + right_cost[k + 1];
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, a, k + 1));
                }
            }
        }
    }
    let split = match best {
        Some((_, a, split)) => (a as u8) << 5 | split as u8,
        None => MEDIAN_SPLIT,
    };
    tree.splits.push(split);
    // The partition pass also gives each side's centre box.
    let (mid, sides) = apply_split(records, &bounds, split);
    let parallel = records.len() > PARALLEL_CANDIDATES;
    let (left, right) = records.split_at_mut(mid);
    if parallel {
        let build = |part: &mut [DualRecord], b: DualBox| {
            let mut sub = Tree::default();
            dual_node(&mut sub, part, b, leaf_size, depth + 1);
            sub
        };
        let (l, r) = rayon::join(|| build(left, sides[0]), || build(right, sides[1]));
        tree.append_child(at, l);
        tree.append_child(at, r);
    } else {
        for (part, b) in [(left, sides[0]), (right, sides[1])] {
            let child = tree.nodes.len() as u32;
            dual_node(tree, part, b, leaf_size, depth + 1);
            tree.children[at].push(child);
        }
    }
    tree.close(at, false);
}

/// The box of the records' centres.
pub(super) fn centre_bounds(records: &[impl Centred]) -> DualBox {
    let mut bounds = EMPTY_BOX;
    for r in records {
        let c = r.centre();
        grow(&mut bounds, &[c, c]);
    }
    bounds
}

/// The bin of centre coordinate `c` on axis `a` of the centre box `bounds`: the rule that
/// [`bins_of`] and [`left_of`] compute faster (and that the tests hold them to).
#[cfg(test)]
fn bin_of(bounds: &DualBox, c: f32, a: usize) -> usize {
    let ext = bounds[1][a] - bounds[0][a];
    // `as` saturates (NaN to 0): no bin index leaves the range.
    (((c - bounds[0][a]) / ext * DUAL_BINS as f32) as usize).min(DUAL_BINS - 1)
}

/// Whether `bin_of` puts centre coordinate `c` on axis `a` below `bin` (≥ 1), decided on the
/// scaled coordinate itself: for `t ≥ 0`, `⌊t⌋ < bin` iff `t < bin`; a negative or NaN `t` is bin
/// 0, and `t` at or past the last bin is at least `bin`. The partition asks this of every record
/// at every level, and the saturating conversion and clamp of `bin_of` cost more than the test.
#[inline]
fn left_of(bounds: &DualBox, c: f32, a: usize, bin: usize) -> bool {
    let ext = bounds[1][a] - bounds[0][a];
    let t = (c - bounds[0][a]) / ext * DUAL_BINS as f32;
    t.partial_cmp(&(bin as f32)).is_none_or(std::cmp::Ordering::is_lt)
}

/// `bin_of` on all four axes at once: the same subtraction, division and product per lane
/// (one vector division instead of four: the binning pass divides for every candidate on every
/// axis at every level, and the scalar rule's line stood out in profiles of a whole bake). The
/// lanes are clamped to the bins as floats, NaN to 0
/// (on x86-64 the vector maximum returns its second operand there; the test
/// `bins_of_is_bin_of_on_each_axis` holds NaN lanes to the rule), so each conversion is a 32-bit
/// one rather than `as usize`'s longer 64-bit sequence. The partition that follows avoids the
/// conversion altogether ([`left_of`]).
#[inline(always)]
fn bins_of(bounds: &DualBox, c: [f32; 4]) -> [usize; 4] {
    let lo = Vec4::from_array(bounds[0]);
    let ext = Vec4::from_array(bounds[1]) - lo;
    let t = (Vec4::from_array(c) - lo) / ext * DUAL_BINS as f32;
    let t = t.max(Vec4::ZERO).min(Vec4::splat((DUAL_BINS - 1) as f32));
    t.to_array().map(|x| x as i32 as usize)
}

/// Reorders `records` (centre box `bounds`) by the split byte `split` (see
/// [`ConeBvhArrays::splits`]) and returns the size of the left side and the centre boxes of both
/// sides: the records in bins below `bin` on `axis`, or for [`MEDIAN_SPLIT`] the lower half by
/// centre on the widest axis (ties by candidate). The one definition both the build and the
/// replay use; the order it leaves depends only on the records' centres and candidates, not on
/// the record type.
fn apply_split(records: &mut [impl Centred], bounds: &DualBox, split: u8) -> (usize, [DualBox; 2]) {
    let mut sides = [EMPTY_BOX; 2];
    if split != MEDIAN_SPLIT {
        let (a, bin) = (usize::from(split >> 5), usize::from(split & 31));
        let mut left = 0;
        for j in 0..records.len() {
            let c = records[j].centre();
            if left_of(bounds, c[a], a, bin) {
                grow(&mut sides[0], &[c, c]);
                records.swap(left, j);
                left += 1;
            } else {
                grow(&mut sides[1], &[c, c]);
            }
        }
        return (left, sides);
    }
    // Median of the widest axis of centres (all equal: any halves): the key of rank `mid` is
    // found on a copy of the keys, then the records are partitioned against it in one pass.
    let a =
        (0..4).max_by(|&x, &y| (bounds[1][x] - bounds[0][x]).total_cmp(&(bounds[1][y] - bounds[0][y])).then(y.cmp(&x)));
    let mid = records.len() / 2;
    let key = |r: &dyn Centred| (r.centre()[a.unwrap_or(0)], r.id());
    let before = |x: (f32, u32), y: (f32, u32)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
    let mut keys: Vec<(f32, u32)> = records.iter().map(|r| key(r)).collect();
    if keys.is_empty() {
        return (0, sides);
    }
    let (_, &mut pivot, _) = keys.select_nth_unstable_by(mid, |&x, &y| before(x, y));
    drop(keys);
    let mut left = 0;
    for j in 0..records.len() {
        let c = records[j].centre();
        if before(key(&records[j]), pivot).is_lt() {
            grow(&mut sides[0], &[c, c]);
            records.swap(left, j);
            left += 1;
        } else {
            grow(&mut sides[1], &[c, c]);
        }
    }
    (left, sides)
}

/// [`dual_node`] with the recorded split bytes `script` (read from `at`) instead of the
/// heuristic's search: the same tree over the same records, whose centre box is `bounds`. Serial;
/// a split byte that does not split (an empty side, an axis or bin out of range) or a script that
/// ends early is refused.
pub(super) fn replay_dual_node(
    tree: &mut Tree,
    records: &mut [CentreRecord],
    bounds: DualBox,
    leaf_size: u32,
    script: &[u8],
    at: &mut usize,
) -> Result<(), ArraysError> {
    let node = tree.open();
    if records.len() <= leaf_size as usize || records.len() < 2 {
        tree.order.extend(records.iter().map(|r| r.id));
        tree.close(node, true);
        return Ok(());
    }
    let bad = ArraysError::Value { array: "splits", index: *at, value: f64::NAN };
    let split = *script.get(*at).ok_or(bad.clone())?;
    *at += 1;
    if split != MEDIAN_SPLIT && (split >> 5 > 3 || usize::from(split & 31) == 0) {
        return Err(bad);
    }
    tree.splits.push(split);
    let (mid, sides) = apply_split(records, &bounds, split);
    if mid == 0 || mid == records.len() {
        return Err(bad);
    }
    let (left, right) = records.split_at_mut(mid);
    for (part, b) in [(left, sides[0]), (right, sides[1])] {
        let child = tree.nodes.len() as u32;
        replay_dual_node(tree, part, b, leaf_size, script, at)?;
        tree.children[node].push(child);
    }
    tree.close(node, false);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::normal_split::build_tree;
    use super::*;

    /// The four-lane binning gives each axis the bin of the scalar rule, and the partition's test
    /// agrees with it at every bin, also for coordinates on and past the box's faces, flat axes
    /// and non-finite ones.
    #[test]
    fn bins_of_is_bin_of_on_each_axis() {
        let mut rng = drafter_core::rng::Rng::new(5);
        for case in 0..20_000 {
            let lo: [f32; 4] = std::array::from_fn(|_| rng.unit_f32() * 10.0);
            let hi: [f32; 4] =
                std::array::from_fn(|a| if case % 7 == a { lo[a] } else { lo[a] + rng.unit_f32().abs() * 5.0 });
            let bounds = [lo, hi];
            let c: [f32; 4] = std::array::from_fn(|a| match (case + a) % 9 {
                0 => lo[a],
                1 => hi[a],
                2 => f32::NAN,
                3 => lo[a] - 1.0,
                4 => f32::INFINITY,
                _ => lo[a] + (hi[a] - lo[a]) * rng.unit_f32().abs(),
            });
            let bins = bins_of(&bounds, c);
            for a in 0..4 {
                assert_eq!(bins[a], bin_of(&bounds, c[a], a), "case {case} axis {a}");
                for bin in 1..DUAL_BINS {
                    assert_eq!(left_of(&bounds, c[a], a, bin), bins[a] < bin, "case {case} axis {a} bin {bin}");
                }
            }
        }
    }
    /// Depth of every node of a preorder [`Tree`] (children lists index the nodes).
    fn depths(tree: &Tree) -> Vec<u32> {
        let mut depth = vec![0u32; tree.nodes.len()];
        for i in 0..tree.nodes.len() {
            for &c in &tree.children[i] {
                depth[c as usize] = depth[i] + 1;
            }
        }
        depth
    }
    /// The dual-space build is a partition into leaves of at most `leaf_size`, and stays shallow
    /// on inputs that defeat the heuristic: values spread geometrically (each split can peel off
    /// one candidate), exact duplicates, zero and NaN normals.
    #[test]
    fn dual_tree_partitions_with_bounded_depth() {
        let n = 3000usize;
        let mut normals = Vec::new();
        let mut points = Vec::new();
        for i in 0..n {
            let x = 2f32.powi(-((i % 120) as i32));
            let (n1, n2) = match i % 7 {
                0 => (Vec3::ZERO, Vec3::Z),
                1 => (Vec3::new(f32::NAN, 0.0, 1.0), Vec3::Z),
                2 => (Vec3::Z, Vec3::Z),
                _ => (Vec3::new(x, 0.0, 1.0).normalize(), Vec3::new(0.0, x, 1.0).normalize()),
            };
            normals.push([n1, n2]);
            points.push(if i % 5 == 0 { Vec3::ONE } else { Vec3::new(x, x * x, 1.0 - x) });
        }
        let unit: Vec<[DVec3; 2]> = normals
            .iter()
            .map(|&[a, b]| [a.as_dvec3().normalize_or_zero(), b.as_dvec3().normalize_or_zero()])
            .collect();
        for (leaf, level) in [(1u32, Some(1u8)), (4, Some(3)), (16, Some(2))] {
            let (tree, starts) = build_tree(&points, &unit, leaf, level, None, None).unwrap();
            // Replaying the recorded splits gives the same tree, node for node.
            let (again, starts_again) =
                build_tree(&points, &unit, leaf, level, Some((&tree.splits, &starts)), None).unwrap();
            assert_eq!((&again.nodes, &again.order, &again.splits), (&tree.nodes, &tree.order, &tree.splits));
            assert_eq!(starts_again, starts);
            // A script cut short, or with a split that empties a side, is refused.
            if let Some((_, short)) = tree.splits.split_last() {
                assert!(build_tree(&points, &unit, leaf, level, Some((short, &starts)), None).is_err());
            }
            let mut seen = tree.order.clone();
            seen.sort_unstable();
            assert_eq!(seen, (0..n as u32).collect::<Vec<_>>(), "not a permutation");
            let bound = DUAL_SAH_DEPTH + 2 * (n as f64).log2().ceil() as u32 + 8;
            assert!(depths(&tree).into_iter().max().unwrap_or(0) <= bound);
            for &[start, end, _, is_leaf] in &tree.nodes {
                if is_leaf == 1 {
                    assert!(end - start <= leaf, "a leaf of {} candidates, leaf size {leaf}", end - start);
                }
            }
        }
    }
    /// Faces on two parallel planes 0.01 apart, interleaved over a 10 × 10 square: close in space
    /// but far apart as planes. Every dual-space leaf holds faces of one plane only.
    #[test]
    fn dual_tree_separates_parallel_planes() {
        let mut normals = Vec::new();
        let mut points = Vec::new();
        for i in 0..1024u32 {
            let (x, y) = ((i % 32) as f32 * 0.3, (i / 32) as f32 * 0.3);
            normals.push([Vec3::Z, Vec3::Z]);
            points.push(Vec3::new(x, y, if i % 2 == 0 { 0.0 } else { 0.01 }));
        }
        let unit: Vec<[DVec3; 2]> = normals.iter().map(|&[a, b]| [a.as_dvec3(), b.as_dvec3()]).collect();
        let (tree, _) = build_tree(&points, &unit, 8, Some(1), None, None).unwrap();
        for &[start, end, _, is_leaf] in &tree.nodes {
            if is_leaf == 1 {
                let leaf = &tree.order[start as usize..end as usize];
                assert!(leaf.iter().all(|&i| i % 2 == leaf[0] % 2), "a leaf mixes the two planes");
            }
        }
    }
}
