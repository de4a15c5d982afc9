//! The in-memory model every drafter stage works on.
//!
//! * [`Scene`]: meshes stored once, instances (mesh + world transform + name), materials and the node
//!   hierarchy they came from.
//! * [`Topology`]: a mesh's welded connectivity (edges with their incident faces, face and vertex
//!   adjacency, components), built in O(n log n) with sorts rather than hash maps so that it is fast and
//!   deterministic.
//! * [`gradient`]: the gradient function ω(i, q, f, p) and intensity transfer γ of Lux et al. 2013,
//!   shared by the stages that bake them (bounds, textures) and the viewer that evaluates them.
//! * [`Diagnostic`]: recoverable problems of the input, aggregated by kind with a count and a first
//!   example. Flawed input is data, not a failure.
//!
//! Invariant: nothing in this crate reads or writes files.

mod diagnostic;
pub mod env_map;
pub mod gradient;
pub mod hierarchy;
mod ids;
mod obb_method;
mod param;
pub mod rng;
mod scene;
pub mod snorm;
mod topology;

pub use diagnostic::{Diagnostic, DiagnosticKind, DiagnosticSummary, Diagnostics, summarize, thousands};
pub use ids::{EdgeId, InstanceId, MaterialId, MeshId, NodeId, PartId};
pub use obb_method::ObbMethod;
pub use param::ParamError;
pub use scene::{Aabb, Instance, Material, Mesh, Node, Scene, SourceDocument, SourceFormat, TriangleGroup};
pub use snorm::{
    VALIDATOR_UNIT_TOLERANCE, snorm8_decode, snorm8_encode, snorm8_encode_direction, snorm8_encode_unit,
    snorm16_decode, snorm16_encode,
};
pub use topology::{DEFAULT_SNAP_FRACTION, EDGE_NONE, Topology, Weld, robust_diagonal};

/// Asks the CPU to start loading the cache line that holds `item`, so that a loop overlaps the
/// memory latency of data it will read soon with its work on the current data. A hint only: no
/// effect on results, and nothing on targets without one. Hand-written because std has no safe
/// prefetch; the workspace's only prefetch (the topology's walk, the normals' vertex layout and
/// sweep order, [`gather`], the silhouette queries' block streams).
#[inline(always)]
#[allow(unsafe_code)]
pub fn prefetch<T>(item: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: SSE is part of the x86_64 baseline, and a prefetch never faults (the pointer
        // comes from a reference anyway).
        unsafe { _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(item).cast()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = item;
}

/// `len` copies of `value`, written on the thread pool. For arrays of tens of megabytes whose
/// elements are all overwritten later, but whose first writes must come first: the first touch of
/// each page costs more than the write itself, and `vec![value; len]` does all of it on one core.
pub fn filled_in_parallel<T: Copy + Send + Sync>(len: usize, value: T) -> Vec<T> {
    use rayon::prelude::*;
    let mut items = Vec::new();
    (0..len).into_par_iter().map(|_| value).collect_into_vec(&mut items);
    items
}

/// `items[order[k]]` for every `k`, on the thread pool, each read prefetched [`GATHER_AHEAD`]
/// items ahead: where `order` scatters its reads over arrays far larger than the cache, every
/// read is a miss, and the prefetches keep several in flight. Panics where `order` holds an index
/// out of `items`.
pub fn gather<T: Copy + Send + Sync>(items: &[T], order: &[u32]) -> Vec<T> {
    use rayon::prelude::*;
    let mut out = Vec::new();
    order
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .map(|(k, &i)| {
            if let Some(&ahead) = order.get(k + GATHER_AHEAD) {
                prefetch(&items[ahead as usize]);
            }
            items[i as usize]
        })
        .collect_into_vec(&mut out);
    out
}

/// How many items ahead [`gather`] prefetches.
const GATHER_AHEAD: usize = 16;

/// The slices `items[r]` for every range `r` of `ranges`, as mutable slices that can go to
/// different threads; `None` unless the ranges are in increasing order, disjoint and within
/// `items` (gaps between them are left out).
pub fn disjoint_slices_mut<'a, T>(items: &'a mut [T], ranges: &[std::ops::Range<usize>]) -> Option<Vec<&'a mut [T]>> {
    let ordered = ranges.iter().try_fold(0usize, |at, r| (at <= r.start && r.start <= r.end).then_some(r.end));
    if ordered.is_none_or(|end| end > items.len()) {
        return None;
    }
    let mut slices = Vec::with_capacity(ranges.len());
    let (mut rest, mut at) = (items, 0usize);
    for r in ranges {
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(r.start - at);
        let (slice, tail) = tail.split_at_mut(r.end - r.start);
        slices.push(slice);
        (rest, at) = (tail, r.end);
    }
    Some(slices)
}

/// The stable counting scatter of `items` into `out` (as long) by `bucket_of(i)`, the bucket of
/// item `i` (below `starts.len() - 1`), on the thread pool: each chunk of `chunk` items counts its
/// buckets, then writes its own slice of every bucket, the slices laid out bucket by bucket and
/// chunk by chunk, which is the order a serial stable scatter gives, at any thread count. Sets
/// `starts[b]` to where bucket `b` begins, the last entry to the total. Written here because rayon
/// has no stable partition into many buckets; used by the weld and the Gauss map's build.
pub fn scatter_in_parallel<T: Copy + Send + Sync>(
    items: &[T],
    bucket_of: impl Fn(usize) -> usize + Sync,
    chunk: usize,
    out: &mut [T],
    starts: &mut [usize],
) {
    use rayon::prelude::*;
    let (buckets, chunk) = (starts.len() - 1, chunk.max(1));
    let counts: Vec<Vec<usize>> = (0..items.len().div_ceil(chunk))
        .into_par_iter()
        .map(|c| {
            let mut count = vec![0usize; buckets];
            for i in c * chunk..((c + 1) * chunk).min(items.len()) {
                count[bucket_of(i)] += 1;
            }
            count
        })
        .collect();
    starts[0] = 0;
    for b in 0..buckets {
        starts[b + 1] = starts[b] + counts.iter().map(|c| c[b]).sum::<usize>();
    }
    let mut pieces: Vec<Vec<&mut [T]>> = counts.iter().map(|_| Vec::with_capacity(buckets)).collect();
    let mut rest = &mut out[..];
    for b in 0..buckets {
        for (count, chunk_pieces) in counts.iter().zip(&mut pieces) {
            let (piece, tail) = std::mem::take(&mut rest).split_at_mut(count[b]);
            chunk_pieces.push(piece);
            rest = tail;
        }
    }
    items.par_chunks(chunk).zip(pieces).enumerate().for_each(|(c, (items, mut pieces))| {
        let mut next = vec![0usize; buckets];
        for (k, item) in items.iter().enumerate() {
            let b = bucket_of(c * chunk + k);
            pieces[b][next[b]] = *item;
            next[b] += 1;
        }
    });
}

#[cfg(test)]
mod tests {
    /// Increasing disjoint ranges (gaps and empty ranges allowed) give exactly those slices;
    /// unordered, overlapping or out-of-bounds ranges give none.
    #[test]
    fn disjoint_slices_are_the_ranges() {
        let mut items: Vec<u32> = (0..10).collect();
        let slices = super::disjoint_slices_mut(&mut items, &[0..2, 2..2, 4..7, 9..10]).expect("valid ranges");
        let got: Vec<Vec<u32>> = slices.iter().map(|s| s.to_vec()).collect();
        assert_eq!(got, [vec![0, 1], vec![], vec![4, 5, 6], vec![9]]);
        let r = |start: usize, end: usize| start..end;
        for bad in [vec![r(3, 5), r(0, 2)], vec![r(0, 5), r(4, 6)], vec![r(8, 11)], vec![r(5, 4)]] {
            assert!(super::disjoint_slices_mut(&mut items, &bad).is_none(), "{bad:?}");
        }
    }

    /// The prefetched gather is the plain one: empty, shorter and longer than the prefetch
    /// distance, with repeats, over chunk boundaries of the thread pool.
    #[test]
    fn gather_is_the_indexed_map() {
        let items: Vec<[u32; 3]> = (0..50_000u32).map(|i| [i, i.wrapping_mul(2_654_435_761), !i]).collect();
        let mut rng = crate::rng::Rng::new(7);
        for len in [0usize, 1, 15, 16, 17, 4095, 4097, 100_000] {
            let order: Vec<u32> = (0..len).map(|_| rng.index(items.len()) as u32).collect();
            let expected: Vec<[u32; 3]> = order.iter().map(|&i| items[i as usize]).collect();
            assert_eq!(super::gather(&items, &order), expected, "length {len}");
        }
    }
}
