//! Disjoint-set forests whose roots are always the smallest element of their set, so that the
//! partition and the root of each set do not depend on the order of the unions.
//!
//! [`UnionFind`] is the plain sequential structure; [`ConcurrentUnionFind`] takes unions from many
//! threads at once (Anderson and Woll's wait-free linking: a root is linked under a smaller root
//! with a compare-and-swap, so no cycle can form and a lost race is simply retried).

use std::sync::atomic::{AtomicU32, Ordering};

#[derive(Clone, Debug)]
pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        Self { parent: (0..n as u32).collect() }
    }

    /// The smallest element of `x`'s set.
    #[inline]
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let grand = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = grand;
            x = grand;
        }
        x
    }

    /// Joins the sets of `a` and `b`; returns the new root (the smaller of the two roots).
    #[inline]
    pub(crate) fn union(&mut self, a: u32, b: u32) -> u32 {
        let (ra, rb) = (self.find(a), self.find(b));
        let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        self.parent[hi as usize] = lo;
        lo
    }

    /// For a union-find over labels: the new label of each old label, numbered `0..count` in order
    /// of the first element of `per_face` (each face's old label) whose set it is, and the count.
    /// How merging and crack gluing renumber their sets in order of first face.
    pub(crate) fn relabel_by_first(&mut self, per_face: &[u32]) -> (Vec<u32>, u32) {
        let n = self.parent.len();
        let mut of_root = vec![u32::MAX; n];
        let mut count = 0u32;
        for &l in per_face {
            let r = self.find(l) as usize;
            if of_root[r] == u32::MAX {
                of_root[r] = count;
                count += 1;
            }
        }
        let new_of = (0..n as u32).map(|l| of_root[self.find(l) as usize]).collect();
        (new_of, count)
    }

    /// Dense labels `0..count` numbered in order of each set's smallest element, and the count.
    pub(crate) fn labels(mut self) -> (Vec<u32>, u32) {
        let n = self.parent.len();
        let mut label = vec![0u32; n];
        let mut count = 0u32;
        for x in 0..n {
            let root = self.find(x as u32) as usize;
            // The root is the smallest member, so it is labelled before any other member.
            if root == x {
                label[x] = count;
                count += 1;
            } else {
                label[x] = label[root];
            }
        }
        (label, count)
    }
}

/// A union-find that many threads may join into at once; see the module docs.
#[derive(Debug)]
pub(crate) struct ConcurrentUnionFind {
    parent: Vec<AtomicU32>,
}

impl ConcurrentUnionFind {
    pub(crate) fn new(n: usize) -> Self {
        Self { parent: (0..n as u32).map(AtomicU32::new).collect() }
    }

    /// The current root of `x`'s set (path splitting; safe under concurrent unions because a
    /// parent pointer only ever moves to a smaller element of the same set).
    #[inline]
    pub(crate) fn find(&self, mut x: u32) -> u32 {
        loop {
            let p = self.parent[x as usize].load(Ordering::Acquire);
            if p == x {
                return x;
            }
            let grand = self.parent[p as usize].load(Ordering::Acquire);
            if grand != p {
                let _ = self.parent[x as usize].compare_exchange_weak(p, grand, Ordering::AcqRel, Ordering::Relaxed);
            }
            x = p;
        }
    }

    /// Joins the sets of `a` and `b`.
    #[inline]
    pub(crate) fn union(&self, a: u32, b: u32) {
        let (mut a, mut b) = (a, b);
        loop {
            a = self.find(a);
            b = self.find(b);
            if a == b {
                return;
            }
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            if self.parent[hi as usize].compare_exchange(hi, lo, Ordering::AcqRel, Ordering::Acquire).is_ok() {
                return;
            }
        }
    }

    /// Sequential structure with the same partition, once every union is done.
    pub(crate) fn into_sequential(self) -> UnionFind {
        UnionFind { parent: self.parent.into_iter().map(AtomicU32::into_inner).collect() }
    }
}

#[cfg(test)]
mod tests {
    use rayon::prelude::*;

    use super::*;

    #[test]
    fn labels_follow_smallest_member() {
        let mut uf = UnionFind::new(6);
        uf.union(5, 3);
        uf.union(4, 1);
        uf.union(3, 4);
        let (labels, count) = uf.labels();
        assert_eq!(count, 3);
        assert_eq!(labels, vec![0, 1, 2, 1, 1, 1]);
    }

    #[test]
    fn concurrent_unions_give_the_sequential_partition() {
        let n = 20_000u32;
        let mut rng = drafter_core::rng::Rng::new(0x9e37_79b9_7f4a_7c15);
        let pairs: Vec<(u32, u32)> = (0..15_000)
            .map(|_| {
                let s = rng.next_u64();
                ((s % n as u64) as u32, ((s >> 32) % n as u64) as u32)
            })
            .collect();
        let mut sequential = UnionFind::new(n as usize);
        for &(a, b) in &pairs {
            sequential.union(a, b);
        }
        let concurrent = ConcurrentUnionFind::new(n as usize);
        pairs.par_iter().with_max_len(64).for_each(|&(a, b)| concurrent.union(a, b));
        assert_eq!(concurrent.into_sequential().labels(), sequential.labels());
    }
}
