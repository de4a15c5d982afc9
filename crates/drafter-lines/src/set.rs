//! [`EdgeSet`]: the answer of a silhouette query, a bitset over candidate indices.

use serde::{Deserialize, Serialize};

/// A set of candidate indices (`0..len`), stored as a bitset so that every query method can fill it
/// in any order and two answers compare in `len / 64` word comparisons.
///
/// Invariant: bits at or above `len` are zero.
///
/// A set also remembers, when it can, which of its words may be non-zero (`dirty`): the
/// hierarchies record the words they write, so that emptying the set for the next query clears a
/// few hundred words instead of all of them (the dragon's 1.3M candidates are 20k words, a memset
/// worth several percent of an orthographic query). Equality, hashing and serialisation look at
/// the members only.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct EdgeSet {
    words: Vec<u64>,
    len: usize,
    #[serde(skip)]
    dirty: Dirty,
}

/// Which words may be non-zero: `listed` is true when every non-zero word is in `words`.
#[derive(Clone, Debug, Default)]
struct Dirty {
    listed: bool,
    words: Vec<u32>,
}

impl PartialEq for EdgeSet {
    fn eq(&self, other: &Self) -> bool {
        self.len == other.len && self.words == other.words
    }
}

impl Eq for EdgeSet {}

impl std::hash::Hash for EdgeSet {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.words.hash(state);
        self.len.hash(state);
    }
}

impl EdgeSet {
    /// An empty set over `len` candidates.
    pub fn new(len: usize) -> Self {
        Self { words: vec![0; len.div_ceil(64)], len, dirty: Dirty { listed: true, words: Vec::new() } }
    }

    /// Empties the set and makes it range over `len` candidates, keeping the allocation.
    pub fn reset(&mut self, len: usize) {
        let count = len.div_ceil(64);
        if self.dirty.listed && self.words.len() == count {
            for &w in &self.dirty.words {
                if let Some(word) = self.words.get_mut(w as usize) {
                    *word = 0;
                }
            }
        } else {
            self.words.clear();
            self.words.resize(count, 0);
        }
        self.dirty.words.clear();
        self.dirty.listed = true;
        self.len = len;
    }

    /// The number of candidates the set ranges over (not the number of members: see [`EdgeSet::count`]).
    pub fn universe(&self) -> usize {
        self.len
    }

    /// Number of members.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|&w| w == 0)
    }

    /// Whether candidate `i` is a member (`false` outside the universe).
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        i < self.len && self.words[i / 64] >> (i % 64) & 1 == 1
    }

    /// Adds candidate `i`. Panics if `i` is outside the universe (an internal bug).
    #[inline]
    pub fn insert(&mut self, i: usize) {
        assert!(i < self.len, "candidate {i} outside a set of {}", self.len);
        self.words[i / 64] |= 1 << (i % 64);
        self.dirty.listed = false;
    }

    /// Members in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = u32> + '_ {
        self.words.iter().enumerate().flat_map(|(w, &word)| BitIter { word, base: (w * 64) as u32 })
    }

    /// Members in increasing order, collected.
    pub fn to_vec(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.count());
        out.extend(self.iter());
        out
    }

    /// The 64-bit words, least significant bit first (candidate `i` is bit `i % 64` of word `i / 64`).
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    /// Mutable words for the query kernels; callers keep bits at or above `len` zero.
    #[inline]
    pub(crate) fn words_mut(&mut self) -> &mut [u64] {
        self.dirty.listed = false;
        &mut self.words
    }

    /// Mutable words and the list of possibly non-zero words: the caller pushes the index of
    /// every word it makes non-zero (duplicates are harmless).
    #[inline]
    pub(crate) fn words_and_dirty(&mut self) -> (&mut [u64], &mut Vec<u32>) {
        (&mut self.words, &mut self.dirty.words)
    }

    /// Members of `self` that are not in `other`, and members of `other` not in `self`
    /// (for reports of mismatches).
    pub fn symmetric_difference(&self, other: &EdgeSet) -> Vec<u32> {
        let n = self.words.len().max(other.words.len());
        let mut out = Vec::new();
        for w in 0..n {
            let a = self.words.get(w).copied().unwrap_or(0);
            let b = other.words.get(w).copied().unwrap_or(0);
            out.extend(BitIter { word: a ^ b, base: (w * 64) as u32 });
        }
        out
    }
}

struct BitIter {
    word: u64,
    base: u32,
}

impl Iterator for BitIter {
    type Item = u32;

    #[inline]
    fn next(&mut self) -> Option<u32> {
        if self.word == 0 {
            return None;
        }
        let bit = self.word.trailing_zeros();
        self.word &= self.word - 1;
        Some(self.base + bit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_clears_listed_and_unlisted_writes() {
        let mut s = EdgeSet::new(1000);
        {
            let (words, dirty) = s.words_and_dirty();
            words[3] = 0b101;
            dirty.push(3);
        }
        assert_eq!(s.count(), 2);
        s.reset(1000);
        assert!(s.is_empty());
        // A kernel that does not list its words forces a full clear.
        s.words_mut()[7] = 1;
        s.words_mut()[15] = 1 << 39;
        s.reset(1000);
        assert!(s.is_empty());
        s.insert(999);
        s.reset(1000);
        assert!(s.is_empty());
        // Equality ignores the bookkeeping.
        let mut t = EdgeSet::new(1000);
        t.insert(5);
        s.insert(5);
        assert_eq!(s, t);
    }

    #[test]
    fn insert_iterate_reset() {
        let mut s = EdgeSet::new(130);
        for i in [0, 5, 63, 64, 129] {
            s.insert(i);
        }
        assert_eq!(s.to_vec(), vec![0, 5, 63, 64, 129]);
        assert_eq!(s.count(), 5);
        assert!(s.contains(64) && !s.contains(65) && !s.contains(1000));
        let mut t = EdgeSet::new(130);
        t.insert(5);
        t.insert(7);
        assert_eq!(s.symmetric_difference(&t), vec![0, 7, 63, 64, 129]);
        s.reset(10);
        assert!(s.is_empty());
        assert_eq!(s.universe(), 10);
    }
}
