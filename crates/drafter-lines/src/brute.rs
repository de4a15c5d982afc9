//! The silhouette predicate and the brute-force query, the reference every hierarchy must match.
//!
//! # The predicate (the one definition used by every method of this crate)
//!
//! For a candidate with face normals `n1`, `n2` (the `f32` vectors of
//! [`crate::FeatureEdges::candidate_normals`]) and point `v` (its first welded vertex):
//!
//! * orthographic, view direction `d`: let `u = d / |d|` (computed once per view by
//!   [`unit_direction`]); `a = n1·u`, `b = n2·u`;
//! * perspective, eye `e`: let `w = e − v` (componentwise `f32` subtraction); `a = n1·w`, `b = n2·w`;
//!
//! where every dot product is evaluated in `f32` as `(x·x' + y·y') + z·z'` with no fused
//! multiply-add. The edge is a silhouette iff **`a` and `b` have strictly opposite signs**:
//! `(a < 0 ∧ b > 0) ∨ (a > 0 ∧ b < 0)`. This is Gooch et al.'s `(n1·(e−v))·(n2·(e−v)) < 0` with the
//! product replaced by a sign comparison, which is the same in exact arithmetic but cannot underflow.
//!
//! **Tie rule:** if `a` or `b` is zero (or NaN) the edge is *not* a silhouette. A zero or non-finite
//! view direction selects nothing.
//!
//! # The brute force
//!
//! Candidates are stored as a structure of arrays (`n1x, n1y, n1z, n2x, n2y, n2z`, and `vx, vy, vz`
//! for perspective), padded with zero normals to a multiple of 64 (a zero normal never passes the
//! predicate). Each block of 64 candidates is evaluated into 64 bytes that LLVM vectorises with
//! the baseline SSE2 of x86-64, then packed into one word of the answer's bitset by a multiply. Large
//! inputs are split across threads with rayon. A candidate costs about a nanosecond of one core;
//! for a mesh whose arrays do not fit in cache (the dragon's), the stream is bound by memory
//! rather than arithmetic. The `silhouette_bench` example measures both.
//!
//! # The hierarchies' block tests
//!
//! The Gauss map tests the candidates of the cells it enters in blocks of 4 ([`OrthoBlocks`]);
//! the cone BVH its leaves' candidates ([`Stream`]). Both give the brute force's answer bit for
//! bit. The Gauss map's blocks also exist as 16-bit integers on x86-64, a pretest with a proven
//! bound that decides almost every lane exactly and hands the rest to the `f32` test: a query
//! over a large model is bound by the bytes it streams, and this halves them.

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::EdgeSet;

/// A view for a silhouette query.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum View {
    /// Parallel projection looking along `direction` (any length; only its direction matters).
    Orthographic { direction: Vec3 },
    /// Central projection from `eye`.
    Perspective { eye: Vec3 },
}

/// Candidates at or above this count are split across rayon threads by [`BruteForce::query`].
pub const PARALLEL_MIN_CANDIDATES: usize = 1 << 17;

/// The normalised view direction every orthographic query uses, `None` for a zero or non-finite
/// direction (which selects no edge).
#[inline]
pub fn unit_direction(d: Vec3) -> Option<Vec3> {
    let len = (d.x * d.x + d.y * d.y + d.z * d.z).sqrt();
    (len > 0.0 && len.is_finite()).then(|| Vec3::new(d.x / len, d.y / len, d.z / len))
}

/// `n·u` evaluated as every method of this crate evaluates it.
#[inline(always)]
pub fn dot_f32(nx: f32, ny: f32, nz: f32, ux: f32, uy: f32, uz: f32) -> f32 {
    nx * ux + ny * uy + nz * uz
}

/// The tie rule: strictly opposite signs.
#[inline(always)]
pub fn opposite_signs(a: f32, b: f32) -> bool {
    ((a < 0.0) & (b > 0.0)) | ((a > 0.0) & (b < 0.0))
}

/// The orthographic predicate for one candidate; `u` must come from [`unit_direction`].
#[inline(always)]
pub fn is_silhouette_orthographic(n1: Vec3, n2: Vec3, u: Vec3) -> bool {
    opposite_signs(dot_f32(n1.x, n1.y, n1.z, u.x, u.y, u.z), dot_f32(n2.x, n2.y, n2.z, u.x, u.y, u.z))
}

/// The perspective predicate for one candidate with point `v` and eye `e`.
#[inline(always)]
pub fn is_silhouette_perspective(n1: Vec3, n2: Vec3, v: Vec3, e: Vec3) -> bool {
    let (wx, wy, wz) = (e.x - v.x, e.y - v.y, e.z - v.z);
    opposite_signs(dot_f32(n1.x, n1.y, n1.z, wx, wy, wz), dot_f32(n2.x, n2.y, n2.z, wx, wy, wz))
}

/// Candidates as a structure of arrays, in some storage order, padded with zeros to a multiple of
/// 64 entries. `v` arrays are empty when the owner answers orthographic queries only.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Soa {
    pub n: [Vec<f32>; 6],
    pub v: [Vec<f32>; 3],
    pub len: usize,
}

impl Soa {
    /// Candidates `order[k]` for `k` in storage order.
    pub fn gather(normals: &[[Vec3; 2]], points: Option<&[Vec3]>, order: impl ExactSizeIterator<Item = u32>) -> Soa {
        let len = order.len();
        let padded = len.div_ceil(64) * 64;
        let mut n: [Vec<f32>; 6] = Default::default();
        for a in &mut n {
            a.reserve_exact(padded);
        }
        let mut v: [Vec<f32>; 3] = Default::default();
        if points.is_some() {
            for a in &mut v {
                a.reserve_exact(padded);
            }
        }
        for i in order {
            let [n1, n2] = normals[i as usize];
            for (k, x) in [n1.x, n1.y, n1.z, n2.x, n2.y, n2.z].into_iter().enumerate() {
                n[k].push(x);
            }
            if let Some(points) = points {
                let p = points[i as usize];
                v[0].push(p.x);
                v[1].push(p.y);
                v[2].push(p.z);
            }
        }
        for a in n.iter_mut().chain(v.iter_mut().filter(|a| !a.is_empty())) {
            a.resize(padded, 0.0);
        }
        Soa { n, v, len }
    }

    pub fn has_points(&self) -> bool {
        !self.v[0].is_empty() || self.len == 0
    }

    /// Orthographic predicate for the 64 candidates of word `w`, as a bit mask.
    #[inline]
    pub fn ortho_word(&self, w: usize, u: Vec3) -> u64 {
        let r = w * 64..w * 64 + 64;
        let (Some(x1), Some(y1), Some(z1), Some(x2), Some(y2), Some(z2)) = (
            self.n[0][r.clone()].first_chunk::<64>(),
            self.n[1][r.clone()].first_chunk::<64>(),
            self.n[2][r.clone()].first_chunk::<64>(),
            self.n[3][r.clone()].first_chunk::<64>(),
            self.n[4][r.clone()].first_chunk::<64>(),
            self.n[5][r].first_chunk::<64>(),
        ) else {
            return 0;
        };
        let mut bits = [0u8; 64];
        for i in 0..64 {
            let a = dot_f32(x1[i], y1[i], z1[i], u.x, u.y, u.z);
            let b = dot_f32(x2[i], y2[i], z2[i], u.x, u.y, u.z);
            bits[i] = opposite_signs(a, b) as u8;
        }
        pack64(&bits)
    }

    /// Perspective predicate for the 64 candidates of word `w`, as a bit mask.
    #[inline]
    pub fn perspective_word(&self, w: usize, e: Vec3) -> u64 {
        let r = w * 64..w * 64 + 64;
        let (Some(x1), Some(y1), Some(z1), Some(x2), Some(y2), Some(z2), Some(vx), Some(vy), Some(vz)) = (
            self.n[0][r.clone()].first_chunk::<64>(),
            self.n[1][r.clone()].first_chunk::<64>(),
            self.n[2][r.clone()].first_chunk::<64>(),
            self.n[3][r.clone()].first_chunk::<64>(),
            self.n[4][r.clone()].first_chunk::<64>(),
            self.n[5][r.clone()].first_chunk::<64>(),
            self.v[0][r.clone()].first_chunk::<64>(),
            self.v[1][r.clone()].first_chunk::<64>(),
            self.v[2][r].first_chunk::<64>(),
        ) else {
            return 0;
        };
        let mut bits = [0u8; 64];
        for i in 0..64 {
            let (wx, wy, wz) = (e.x - vx[i], e.y - vy[i], e.z - vz[i]);
            let a = dot_f32(x1[i], y1[i], z1[i], wx, wy, wz);
            let b = dot_f32(x2[i], y2[i], z2[i], wx, wy, wz);
            bits[i] = opposite_signs(a, b) as u8;
        }
        pack64(&bits)
    }
}

/// Cache lines [`prefetch`] asks for at the start of a cone-BVH leaf.
const PREFETCH_LINES: usize = 8;

/// How many blocks ahead of the one being tested [`Stream::perspective`] prefetches.
const PREFETCH_BLOCKS: usize = 8;

/// The fewest candidates for which a cone BVH's [`Stream`] keeps the 16-bit copy of its blocks
/// ([`FixedBlock`]). The pretest halves the bytes a leaf's test reads, which pays where a view
/// tests many blocks streamed from beyond the caches, and costs a little where it tests few
/// (`silhouette_bench` on meshes of several sizes, with and without the pretest:
/// docs/bench.md#a-16-bit-pretest-for-the-cone-bvhs-leaves). So the copy is built for the largest
/// meshes only, where views are likeliest to test many blocks.
pub(crate) const PRETEST_MIN_CANDIDATES: usize = 1 << 20;

#[cfg(test)]
thread_local! {
    /// Builds the 16-bit copy whatever the size (tests of the whole walk on small meshes).
    pub(crate) static FORCE_PRETEST: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether a cone BVH over `candidates` keeps the 16-bit copy (see [`PRETEST_MIN_CANDIDATES`]).
pub(crate) fn keeps_pretest(candidates: usize) -> bool {
    #[cfg(test)]
    if FORCE_PRETEST.with(std::cell::Cell::get) {
        return true;
    }
    candidates >= PRETEST_MIN_CANDIDATES
}

/// Quads (16 bytes) per block of a cone BVH's [`Stream`].
const BLOCK_QUADS: usize = 10;

/// How many cache lines ahead of the block being tested [`OrthoBlocks::test_ranges`] requests.
const STREAM_AHEAD_LINES: usize = 48;

/// Asks the CPU to start loading the first `lines` cache lines of `items` (16-byte items, 4 a
/// line), so that a hierarchy walk overlaps the memory latency of data it will test soon with
/// testing the current data. A walk's ranges are short (tens of blocks) and scattered over arrays
/// far larger than the caches, so their first lines miss before the hardware prefetcher sees a
/// stream. A hint only ([`drafter_core::prefetch`]).
#[inline(always)]
pub(crate) fn prefetch<T>(items: &[T], lines: usize) {
    const { assert!(std::mem::size_of::<T>() == 16) };
    for line in items.chunks(4).take(lines) {
        drafter_core::prefetch(&line[0]);
    }
}

/// A position in the concatenation of block ranges, walked one cache line at a time ahead of the
/// test: requesting the data of the next ranges as one stream keeps a steady number of loads in
/// flight, where per-range bursts either come too late or overflow the miss buffers.
struct PrefetchCursor<'a> {
    ranges: &'a [[u32; 2]],
    /// 16-byte items per block of the array streamed.
    per_block: usize,
    /// The next range to start.
    next: usize,
    /// Current item and end of the current range, in items.
    at: usize,
    end: usize,
}

impl<'a> PrefetchCursor<'a> {
    fn new(ranges: &'a [[u32; 2]], per_block: usize) -> Self {
        Self { ranges, per_block, next: 0, at: 0, end: 0 }
    }

    /// Requests the next `lines` cache lines of the stream.
    #[inline(always)]
    fn advance<T>(&mut self, items: &[T], mut lines: usize) {
        while lines > 0 {
            if self.at >= self.end {
                let Some(&[b0, b1]) = self.ranges.get(self.next) else { return };
                self.next += 1;
                self.at = self.per_block * b0 as usize;
                self.end = self.per_block * b1 as usize;
                continue;
            }
            if let Some(line) = items.get(self.at..self.end) {
                prefetch(line, 1);
            }
            self.at += 4;
            lines -= 1;
        }
    }
}

/// A Gauss map's candidates in its storage order, in blocks of 4 lanes (array of structures of
/// arrays: 6 quads `n1x, n1y, n1z, n2x, n2y, n2z` per block). Lane `k` of block `b` is storage
/// position `4b + k`, so a block's hits are 4 bits ORed at once into the answer, no index needed.
/// The last block is padded with zero normals, which never pass the predicate.
///
/// On x86-64 the blocks also have a 16-bit copy (see [`Quantized`]) that a walk streams instead:
/// half the bytes, and a query over a large model is bound by memory, not arithmetic.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct OrthoBlocks {
    quads: Vec<[f32; 4]>,
    #[cfg(target_arch = "x86_64")]
    quantized: Quantized,
}

impl OrthoBlocks {
    /// Candidates `order[k]` at storage position `k`.
    pub fn new(order: &[u32], normals: &[[Vec3; 2]]) -> Self {
        // Blocks are independent: built on the thread pool (a million-candidate map at load).
        let blocks: Vec<[[f32; 4]; 6]> = order
            .par_chunks(4)
            .map(|chunk| {
                let mut rows = [[0f32; 4]; 6];
                for (lane, &i) in chunk.iter().enumerate() {
                    let [n1, n2] = normals[i as usize];
                    for (r, x) in [n1.x, n1.y, n1.z, n2.x, n2.y, n2.z].into_iter().enumerate() {
                        rows[r][lane] = x;
                    }
                }
                rows
            })
            .collect();
        let quads: Vec<[f32; 4]> = blocks.into_iter().flatten().collect();
        Self {
            #[cfg(target_arch = "x86_64")]
            quantized: Quantized::new(&quads),
            quads,
        }
    }

    /// [`OrthoBlocks::test`] on each of `ranges`, with the memory of later ranges requested a
    /// fixed distance ahead of the test, as one stream over their concatenation. On x86-64 the
    /// 16-bit pretest decides almost every lane and the exact test settles the rest.
    pub fn test_ranges(&self, ranges: &[[u32; 2]], u: Vec3, out: &mut [u64], dirty: &mut Vec<u32>) {
        #[cfg(target_arch = "x86_64")]
        if !self.quantized.blocks.is_empty() {
            return self.quantized.test_ranges(&self.quads, ranges, u, out, dirty);
        }
        let mut cursor = PrefetchCursor::new(ranges, 6);
        cursor.advance(&self.quads, STREAM_AHEAD_LINES);
        for &[b0, b1] in ranges {
            cursor.advance(&self.quads, (6 * (b1 - b0) as usize).div_ceil(4));
            self.test(b0 as usize, b1 as usize, u, out, dirty);
        }
    }

    /// The orthographic predicate on blocks `b0..b1`; hits set their storage positions in `out`.
    #[inline]
    pub fn test(&self, b0: usize, b1: usize, u: Vec3, out: &mut [u64], dirty: &mut Vec<u32>) {
        let (ux, uy, uz) = (Vec4::splat(u.x), Vec4::splat(u.y), Vec4::splat(u.z));
        let Some(all) = self.quads.get(6 * b0..6 * b1) else { return };
        let mut bits = WordBits::new(b0);
        for (k, r) in all.chunks_exact(6).enumerate() {
            bits.push(b0 + k, ortho_block(r, ux, uy, uz), out, dirty);
        }
        bits.flush(out, dirty);
    }
}

/// The orthographic predicate on the 4 lanes of one block of 6 quads, as a 4-bit mask.
#[inline(always)]
fn ortho_block(r: &[[f32; 4]], ux: Vec4, uy: Vec4, uz: Vec4) -> u32 {
    let a = Vec4::from(r[0]) * ux + Vec4::from(r[1]) * uy + Vec4::from(r[2]) * uz;
    let c = Vec4::from(r[3]) * ux + Vec4::from(r[4]) * uy + Vec4::from(r[5]) * uz;
    let hit = (a.cmplt(Vec4::ZERO) & c.cmpgt(Vec4::ZERO)) | (a.cmpgt(Vec4::ZERO) & c.cmplt(Vec4::ZERO));
    hit.bitmask()
}

/// Hits of consecutive blocks gathered in a register and written once per word of the answer (16
/// blocks): ORing every block into memory would chain each block's store to the next one's load.
struct WordBits {
    word: usize,
    bits: u64,
}

impl WordBits {
    #[inline(always)]
    fn new(block: usize) -> Self {
        Self { word: block / 16, bits: 0 }
    }

    /// The 4-bit `mask` of `block` (blocks pushed in increasing order, one word at a time).
    #[inline(always)]
    fn push(&mut self, block: usize, mask: u32, out: &mut [u64], dirty: &mut Vec<u32>) {
        self.bits |= u64::from(mask) << (4 * (block % 16));
        if block % 16 == 15 {
            self.flush(out, dirty);
            self.word += 1;
        }
    }

    #[inline(always)]
    fn flush(&mut self, out: &mut [u64], dirty: &mut Vec<u32>) {
        if self.bits != 0
            && let Some(w) = out.get_mut(self.word)
        {
            *w |= self.bits;
            dirty.push(self.word as u32);
        }
        self.bits = 0;
    }
}

/// The 16-bit pretest of the orthographic predicate (x86-64, SSE2 integer arithmetic).
///
/// Each normal component is stored as `q = round(S·n)` with `S` = [`Quantized::SCALE`], the view
/// direction likewise as `q_u = round(S·u)`, and `D = q·q_u` is computed exactly in 32-bit integers
/// (`pmaddwd`). With `|δ|, |δ_u| ≤ ½` per component, `|n| ≤ 1.01`, `|u| ≤ 1 + 10⁻⁶`:
///
/// `|n·u − D/S²| ≤ (|n|·|δ_u| + |δ|·|u|)/S + |δ|·|δ_u|/S² ≤ 1.7407/S + 0.75/S²`,
///
/// and the brute force's `f32` dot product is within `γ₃·|n|·|u| ≤ 1.81·10⁻⁷` of `n·u` (Higham's
/// bound for a 3-term sum of products). So where `|D| > T` = [`Quantized::SURE`], `T/S² ≥` the
/// two bounds added, the brute force's value is non-zero with the sign of `D`: the lane is decided
/// exactly. Lanes with `|D| ≤ T` on either side (a small share of the lanes a query tests:
/// normals within 6·10⁻⁵ of the view's great circle) are tested again in `f32` on the exact
/// normals, after the stream, their blocks prefetched together. Normals that are not finite or
/// longer than 1.01 are stored as zero, which is never decided, so they always take the exact
/// path. The answer is therefore identical to the brute force's, bit for bit; the tests compare
/// them over thousands of views.
///
/// Written with `std::arch` because no crate offers a 16-bit integer dot product (glam is `f32`).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Debug, Default, PartialEq)]
struct Quantized {
    /// 3 vectors of 8 `i16` per block of 4 lanes: `(x1, y1)` pairs, `(x2, y2)` pairs, `(z1, z2)`
    /// pairs, lane after lane: 48 bytes where the `f32` block has 96.
    blocks: Vec<Lanes>,
}

/// `round(scale·n)` per coordinate, or zero for a normal that is not finite or longer than 1.01
/// (what the 16-bit pretests send to their exact path).
fn quantize_normal(n: Vec3, scale: f32) -> [i16; 3] {
    if !n.is_finite() || n.length() > 1.01 {
        return [0; 3];
    }
    let q = |x: f32| (x * scale).round() as i16;
    [q(n.x), q(n.y), q(n.z)]
}

/// One SSE register's worth of `i16`, aligned so that it loads in one instruction.
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Lanes([i16; 8]);

#[cfg(target_arch = "x86_64")]
impl Quantized {
    /// `S`: normals at `|n| ≤ 1.01` stay within `i16` (`1.01·S < 32767`), and `|D| ≤ 1.01·S²`
    /// within `i32`.
    const SCALE: f32 = 32000.0;
    /// `T`: `(1.7407/S + 0.75/S² + 1.81·10⁻⁷)·S² = 55,889` rounded up with room to spare.
    const SURE: i32 = 57_000;

    fn quantize(n: Vec3) -> [i16; 3] {
        quantize_normal(n, Self::SCALE)
    }

    /// From the `f32` blocks (6 quads per block).
    fn new(quads: &[[f32; 4]]) -> Self {
        let triples: Vec<[Lanes; 3]> = quads
            .par_chunks_exact(6)
            .map(|r| {
                let lane = |l: usize| {
                    let n1 = Self::quantize(Vec3::new(r[0][l], r[1][l], r[2][l]));
                    let n2 = Self::quantize(Vec3::new(r[3][l], r[4][l], r[5][l]));
                    (n1, n2)
                };
                let [(a0, b0), (a1, b1), (a2, b2), (a3, b3)] = [lane(0), lane(1), lane(2), lane(3)];
                [
                    Lanes([a0[0], a0[1], a1[0], a1[1], a2[0], a2[1], a3[0], a3[1]]),
                    Lanes([b0[0], b0[1], b1[0], b1[1], b2[0], b2[1], b3[0], b3[1]]),
                    Lanes([a0[2], b0[2], a1[2], b1[2], a2[2], b2[2], a3[2], b3[2]]),
                ]
            })
            .collect();
        Self { blocks: triples.into_iter().flatten().collect() }
    }

    #[allow(unsafe_code)]
    fn test_ranges(&self, quads: &[[f32; 4]], ranges: &[[u32; 2]], u: Vec3, out: &mut [u64], dirty: &mut Vec<u32>) {
        // SAFETY: SSE2 is part of the x86_64 baseline, so the feature the kernel is compiled
        // with is present on every machine this code runs on.
        unsafe { self.test_ranges_sse2(quads, ranges, u, out, dirty) }
    }

    #[target_feature(enable = "sse2")]
    fn test_ranges_sse2(
        &self,
        quads: &[[f32; 4]],
        ranges: &[[u32; 2]],
        u: Vec3,
        out: &mut [u64],
        dirty: &mut Vec<u32>,
    ) {
        use std::arch::x86_64::*;
        let load = |v: &Lanes| {
            let [a, b, c, d, e, f, g, h] = v.0;
            _mm_setr_epi16(a, b, c, d, e, f, g, h)
        };
        // |u| = 1 (unit_direction), so every component rounds into i16.
        let q = |x: f32| (x * Self::SCALE).round() as i16;
        let (ux, uy, uz) = (q(u.x), q(u.y), q(u.z));
        let uxy = _mm_setr_epi16(ux, uy, ux, uy, ux, uy, ux, uy);
        let uz1 = _mm_setr_epi16(uz, 0, uz, 0, uz, 0, uz, 0);
        let uz2 = _mm_setr_epi16(0, uz, 0, uz, 0, uz, 0, uz);
        // |d| ≤ T as one unsigned compare, (d + T) ≤ 2T, done signed with the sign bit flipped
        // (SSE2 has neither an absolute value nor unsigned compares).
        let shift = _mm_set1_epi32(Self::SURE);
        let flip = _mm_set1_epi32(i32::MIN);
        let limit = _mm_set1_epi32((2 * Self::SURE + 1) ^ i32::MIN);
        let undecided_lanes = |d: __m128i| _mm_cmpgt_epi32(limit, _mm_xor_si128(_mm_add_epi32(d, shift), flip));
        // (word, 4-bit groups of its blocks with undecided lanes), for the exact pass.
        let mut undecided: Vec<(usize, u64)> = Vec::new();
        let mut cursor = PrefetchCursor::new(ranges, 3);
        cursor.advance(&self.blocks, STREAM_AHEAD_LINES);
        for &[b0, b1] in ranges {
            let (b0, b1) = (b0 as usize, b1 as usize);
            cursor.advance(&self.blocks, (3 * (b1 - b0)).div_ceil(4));
            let Some(all) = self.blocks.get(3 * b0..3 * b1) else { continue };
            // Masks gather in registers and go to memory once per word (16 blocks); nothing in
            // the loop calls out, so the constants stay in registers.
            let (mut word, mut hits, mut opens) = (b0 / 16, 0u64, 0u64);
            let mut flush = |word: usize, hits: u64, opens: u64| {
                if hits != 0
                    && let Some(w) = out.get_mut(word)
                {
                    *w |= hits;
                    dirty.push(word as u32);
                }
                if opens != 0 {
                    undecided.push((word, opens));
                }
            };
            for (k, r) in all.chunks_exact(3).enumerate() {
                let (xy1, xy2, z12) = (load(&r[0]), load(&r[1]), load(&r[2]));
                let d1 = _mm_add_epi32(_mm_madd_epi16(xy1, uxy), _mm_madd_epi16(z12, uz1));
                let d2 = _mm_add_epi32(_mm_madd_epi16(xy2, uxy), _mm_madd_epi16(z12, uz2));
                // Decided lanes have |d| > T on both sides, so neither is zero and opposite
                // signs are a silhouette; undecided lanes are left to the exact pass.
                let open = _mm_movemask_ps(_mm_castsi128_ps(_mm_or_si128(undecided_lanes(d1), undecided_lanes(d2))));
                let opposite = _mm_movemask_ps(_mm_castsi128_ps(_mm_xor_si128(d1, d2)));
                let shift = 4 * ((b0 + k) % 16);
                hits |= u64::from((opposite & !open) as u32) << shift;
                opens |= u64::from(open as u32) << shift;
                if (b0 + k) % 16 == 15 {
                    flush(word, hits, opens);
                    (word, hits, opens) = (word + 1, 0, 0);
                }
            }
            flush(word, hits, opens);
        }
        // The exact test on the blocks with undecided lanes, their data requested first so the
        // misses overlap: its mask is right for every lane of the block (decided lanes agree with
        // it by the bound above), so ORing it in is enough.
        let blocks_of = |word: usize, opens: u64| {
            (0..16).filter(move |g| opens >> (4 * g) & 0xF != 0).map(move |g| (16 * word + g, 4 * g))
        };
        for &(word, opens) in &undecided {
            for (b, _) in blocks_of(word, opens) {
                if let Some(r) = quads.get(6 * b..6 * b + 6) {
                    prefetch(r, 2);
                }
            }
        }
        let (vx, vy, vz) = (Vec4::splat(u.x), Vec4::splat(u.y), Vec4::splat(u.z));
        for &(word, opens) in &undecided {
            let mut hits = 0u64;
            for (b, shift) in blocks_of(word, opens) {
                if let Some(r) = quads.get(6 * b..6 * b + 6) {
                    hits |= u64::from(ortho_block(r, vx, vy, vz)) << shift;
                }
            }
            if hits != 0
                && let Some(w) = out.get_mut(word)
            {
                *w |= hits;
                dirty.push(word as u32);
            }
        }
    }
}

/// A cone BVH's candidates in blocks of 4 (array of structures of arrays), leaf after leaf: each
/// block is 9 quads of 4 lanes (`n1x, n1y, n1z, n2x, n2y, n2z, vx, vy, vz`) and one quad of
/// candidate indices stored as `f32` bits (moved, never computed with). A leaf's candidates thus
/// sit in a few cache lines and take one SIMD pass per block. Unused lanes have zero normals,
/// which never pass the predicate, and index 0.
///
/// A stream built for queries ([`Stream::from_ranges`]) also holds the same blocks in 16 bits
/// ([`FixedBlock`], half the bytes), which a leaf's test reads first (see
/// [`Stream::perspective_leaf`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Stream {
    quads: Vec<[f32; 4]>,
    /// Block for block the same candidates as `quads` (empty where the pretest is not compiled,
    /// or for a stream built block by block).
    fixed: Vec<FixedBlock>,
}

/// A block of the perspective pretest: per lane, each face normal `n` as `round(S·n)` (`S` =
/// [`FixedBlock::SCALE`]) and its plane's offset from the leaf's anchor `p₀`, `h = n·(v − p₀)`,
/// as `round(S·h/R)` (`R` the leaf's reach, `|v − p₀| ≤ R`), so that one `pmaddwd` pairs
/// `(x, y)` with the view's `(u_x, u_y)` and another `(z, h)` with `(u_z, −c)`; then the candidate
/// indices. 80 bytes where the `f32` block has 160: the walk's block tests read half the bytes,
/// and do integer multiply-adds instead of subtractions and products in `f32` (an earlier copy
/// with 16-bit points, decoded to `f32`, was slower than the `f32` blocks:
/// docs/bench.md#what-did-not-help).
///
/// # Why a decided lane is exact
///
/// For an eye `e` with `w₀ = e − p₀`, take any `L` within a factor `1 ± 2⁻¹⁰` of `|w₀|` (the
/// query uses the reciprocal square root estimate) with `R ≤ L`, and let `u = w₀/L`, `c = R/L
/// ≤ 1`. The predicate's value is `n·(e − v) = n·w₀ − h = L·(n·u − c·h/R)`, and the integers
/// give `D = n_q·u_q − h_q·c_q ≈ S²·(n·u − c·h/R)`, a positive multiple of it, with every factor
/// rounded to the nearest integer (`u_q = round(S·u)`, `c_q = round(S·c)`, each computed in
/// `f32` from `w₀` rounded once per coordinate: within 0.506 of its target). The roundings move
/// `D` by at most `(√3/2)·|u_q| + (√3/2)·0.506·S·|n|` = 56,066 (`|u_q| ≤ 1.001·S`, `|n| ≤
/// 1.01`) plus `½c_q + 0.506·S·|h|/R + ¼` ≤ 32,291: 88,357 in all. The brute force's `f32`
/// value of `n·(e − v)` errs by at most `4.01·2⁻²⁴·|n|·|e − v|` (a rounded subtraction per
/// coordinate, then a 3-term dot product), and `|e − v| ≤ |w₀| + R ≤ 2.001·L`: at most 497 in
/// units of `D`. So where `|D| > T` = [`FixedBlock::SURE`] `= 90,000`, the brute force's value is
/// non-zero with the sign of `D`.
///
/// A block with a lane that is not decided on both normals is tested again in `f32` (the result
/// of [`Stream::perspective`]): a small share of the blocks a view tests, since the candidates a
/// walk reaches lie near the silhouette but few lie that near the tie
/// (docs/bench.md#a-16-bit-pretest-for-the-cone-bvhs-leaves). A leaf the eye is
/// within `R` of, or with a non-finite point, is tested in `f32` alone. Normals that are not
/// finite, longer than 1.01, or whose components all round to zero are stored as zero with a
/// zero offset, so `D = 0` and their block always takes the exact path. Unused lanes store the
/// same normal twice, so they are decided equal or sent to the exact path, which rejects them.
/// The answer is therefore identical to the brute force's, bit for bit. The test
/// `leaf_test_matches_predicate_near_the_planes` fails with `T` at 45,000 (and passes at 60,000:
/// the bound is for the worst case).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct FixedBlock {
    /// `(x₁, y₁)`, `(z₁, h₁)`, `(x₂, y₂)`, `(z₂, h₂)` pairs, lane after lane.
    rows: [Lanes; 4],
    ids: [u32; 4],
}

// Defined on every target (a stream elsewhere holds no copy); built and read on x86_64 only.
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
impl FixedBlock {
    /// `S`: as `Quantized::SCALE`, so that `|D| ≤ 2.07·10⁹` stays within `i32`.
    const SCALE: f64 = 32000.0;
    /// `T` (see the type's docs).
    const SURE: i32 = 90_000;

    /// `x` rounded to the nearest integer, ties away from zero, for `|x| ≤ 32767`. `f64::round` is
    /// a library call without SSE4.1, and a conversion truncates: so ½ is added with the value's
    /// sign first (exact at these magnitudes).
    #[inline(always)]
    fn nearest(x: f64) -> i16 {
        (x + 0.5f64.copysign(x)) as i16
    }

    /// The blocks of candidates `ids` around the anchor `p0`, and the leaf's reach `R` (`NaN`
    /// where a point is not finite: such a leaf is always tested in `f32`).
    fn leaf(ids: &[u32], p0: Vec3, normals: &[[Vec3; 2]], points: &[Vec3], out: &mut [FixedBlock]) -> f32 {
        let anchor = p0.as_dvec3();
        let mut reach_squared = 0f64;
        for &i in ids {
            let d = points[i as usize].as_dvec3() - anchor;
            reach_squared = if d.is_finite() { reach_squared.max(d.length_squared()) } else { f64::NAN };
            if reach_squared.is_nan() {
                break;
            }
        }
        // Rounded up, with room for the offsets' own rounding: |h| ≤ |n|·R.
        let reach = {
            let r = reach_squared.sqrt() * (1.0 + 1e-12);
            let y = r as f32;
            if f64::from(y) < r { y.next_up() } else { y }
        };
        let r = f64::from(reach);
        let lane = |n: Vec3, d: glam::DVec3| -> ([i16; 3], i16) {
            let q = quantize_normal(n, Self::SCALE as f32);
            if q == [0; 3] || r == 0.0 || r.is_nan() {
                return (q, 0);
            }
            (q, Self::nearest(Self::SCALE * n.as_dvec3().dot(d) / r))
        };
        // Unused lanes: the same normal twice (see the type's docs).
        let unused = ([Self::SCALE as i16, 0, 0], 0);
        for (chunk, block) in ids.chunks(4).zip(out) {
            for l in 0..4 {
                let (([x1, y1, z1], h1), ([x2, y2, z2], h2)) = match chunk.get(l) {
                    Some(&i) => {
                        let [n1, n2] = normals[i as usize];
                        let d = points[i as usize].as_dvec3() - anchor;
                        block.ids[l] = i;
                        (lane(n1, d), lane(n2, d))
                    }
                    None => (unused, unused),
                };
                for (row, pair) in block.rows.iter_mut().zip([[x1, y1], [z1, h1], [x2, y2], [z2, h2]]) {
                    row.0[2 * l..2 * l + 2].copy_from_slice(&pair);
                }
            }
        }
        reach
    }
}

impl Stream {
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the stream has no 16-bit copy.
    #[cfg(test)]
    pub fn fixed_is_empty(&self) -> bool {
        self.fixed.is_empty()
    }

    /// Length in quads.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.quads.len()
    }

    /// The blocks of each of `ranges` of `ids`, one range after the other (each range padded to
    /// whole blocks), with their 16-bit copy around each range's
    /// anchor in `anchors` where `pretest` asks for it, built on the thread pool; also each
    /// range's first quad and block count, and its reach from its anchor (see [`FixedBlock`]; 0
    /// where no copy is built).
    pub fn from_ranges(
        ranges: &[(usize, usize)],
        anchors: &[Vec3],
        ids: &[u32],
        (normals, points): (&[[Vec3; 2]], &[Vec3]),
        pretest: bool,
    ) -> (Self, Vec<(u32, u32)>, Vec<f32>) {
        let at = Self::layout(ranges);
        let blocks = at.last().map_or(0, |&(q, b)| q as usize / BLOCK_QUADS + b as usize);
        // Filled in place, range by range on the pool: no second copy at the peak.
        let mut quads = vec![[0f32; 4]; BLOCK_QUADS * blocks];
        let mut fixed = if pretest && cfg!(target_arch = "x86_64") {
            drafter_core::filled_in_parallel(blocks, FixedBlock::default())
        } else {
            Vec::new()
        };
        let per_block = usize::from(!fixed.is_empty());
        let mut jobs = Vec::with_capacity(ranges.len());
        let (mut quads_left, mut fixed_left) = (&mut quads[..], &mut fixed[..]);
        for (&range, &(_, count)) in ranges.iter().zip(&at) {
            let count = count as usize;
            let (q, rest) = std::mem::take(&mut quads_left).split_at_mut(BLOCK_QUADS * count);
            quads_left = rest;
            let (f, rest) = std::mem::take(&mut fixed_left).split_at_mut(per_block * count);
            fixed_left = rest;
            jobs.push((range, q, f));
        }
        let reaches: Vec<f32> = jobs
            .into_par_iter()
            .zip(anchors)
            .map(|(((start, end), q, f), &p0)| {
                write_blocks(&ids[start..end], normals, points, q);
                if f.is_empty() { 0.0 } else { FixedBlock::leaf(&ids[start..end], p0, normals, points, f) }
            })
            .collect();
        (Stream { quads, fixed }, at, reaches)
    }

    /// Where [`Stream::from_ranges`] puts each range: its first quad and its number of blocks.
    pub fn layout(ranges: &[(usize, usize)]) -> Vec<(u32, u32)> {
        let mut at = Vec::with_capacity(ranges.len());
        let mut quads = 0usize;
        for &(start, end) in ranges {
            let blocks = (end - start).div_ceil(4);
            at.push((quads as u32, blocks as u32));
            quads += BLOCK_QUADS * blocks;
        }
        at
    }

    /// Appends candidates `ids` as whole blocks (without their 16-bit copy); returns the number
    /// of blocks.
    #[cfg(test)]
    pub fn push_blocks(&mut self, ids: &[u32], normals: &[[Vec3; 2]], points: &[Vec3]) -> u32 {
        let blocks = ids.len().div_ceil(4);
        let start = self.quads.len();
        self.quads.resize(start + BLOCK_QUADS * blocks, [0.0; 4]);
        write_blocks(ids, normals, points, &mut self.quads[start..]);
        blocks as u32
    }

    /// Starts loading the first cache lines of `count` blocks at quad `q` (see [`prefetch`]): of
    /// the 16-bit copy where there is one.
    #[inline(always)]
    pub fn prefetch(&self, q: usize, count: u32) {
        let b = q / BLOCK_QUADS;
        if let Some(blocks) = self.fixed.get(b..b + count as usize) {
            // 80-byte blocks: each block's start and its indices (64 bytes in) cover its lines.
            for block in blocks.iter().take(PREFETCH_LINES * 4 / 5) {
                drafter_core::prefetch(&block.rows[0]);
                drafter_core::prefetch(&block.ids);
            }
        } else if let Some(range) = self.quads.get(q..q + count as usize * BLOCK_QUADS) {
            prefetch(range, PREFETCH_LINES);
        }
    }

    /// Perspective predicate over `count` blocks starting at quad `q` (blocks with points), in
    /// `f32`: the brute force's arithmetic.
    #[inline]
    pub fn perspective(&self, q: usize, count: u32, e: Vec3, out: &mut [u64]) {
        let (ex, ey, ez) = (Vec4::splat(e.x), Vec4::splat(e.y), Vec4::splat(e.z));
        let Some(all) = self.quads.get(q..q + count as usize * BLOCK_QUADS) else { return };
        for (k, r) in all.as_chunks::<BLOCK_QUADS>().0.iter().enumerate() {
            // A block is 2.5 cache lines; blocks with points stream slower than the hardware
            // prefetcher follows them (see `prefetch`).
            let ahead = q + (k + PREFETCH_BLOCKS) * BLOCK_QUADS;
            if let Some(next) = self.quads.get(ahead..ahead + BLOCK_QUADS) {
                prefetch(next, 3);
            }
            emit_mask(perspective_mask(r, ex, ey, ez), r[9].map(f32::to_bits), out);
        }
    }

    /// [`Stream::perspective`] over a leaf's blocks whose anchor is `p0` and reach `reach` (as
    /// [`Stream::from_ranges`] gave it): through the 16-bit pretest where there is one and the
    /// eye is farther than the reach from the anchor (see [`FixedBlock`]). Same answer.
    ///
    /// Blocks whose pretest leaves a lane open get their decided lanes' hits now, and their range
    /// of quads `[first, end)` in `pending`: [`Stream::perspective_pending`] tests them in `f32`
    /// later, together, so that their loads overlap.
    #[inline]
    pub fn perspective_leaf(
        &self,
        q: usize,
        count: u32,
        (p0, reach): (Vec3, f32),
        e: Vec3,
        out: &mut [u64],
        pending: &mut Vec<[u32; 2]>,
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            let b = q / BLOCK_QUADS;
            #[allow(unsafe_code)]
            if let Some(blocks) = self.fixed.get(b..b + count as usize)
                // SAFETY: SSE2 is part of the x86_64 baseline, so the feature the kernel is
                // compiled with is present on every machine this code runs on.
                && unsafe { self.perspective_fixed_sse2(blocks, q, (p0, reach), e, out, pending) }
            {
                return;
            }
        }
        let _ = (p0, reach, &pending);
        self.perspective(q, count, e, out);
    }

    /// The 16-bit pretest on `blocks` (the blocks from quad `q` on) of a leaf with anchor `p0`
    /// and reach `reach`, for the eye `e` (see [`FixedBlock`]); `false`, having done nothing,
    /// where the eye is within the reach (or the distance is not a normal `f32`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse2")]
    fn perspective_fixed_sse2(
        &self,
        blocks: &[FixedBlock],
        q: usize,
        (p0, reach): (Vec3, f32),
        e: Vec3,
        out: &mut [u64],
        pending: &mut Vec<[u32; 2]>,
    ) -> bool {
        use std::arch::x86_64::*;
        // The view: `w₀ = e − p₀` (each coordinate rounded once) times `S·r`, `r` ≈ 1/|w₀| from
        // the reciprocal square root estimate: any `r` within 2⁻¹⁰ of it keeps the bound (see
        // `FixedBlock`), so no square root or division sits between the leaves.
        let w = e - p0;
        let len2 = w.length_squared();
        if len2.is_nan() || len2.is_infinite() || len2 < f32::MIN_POSITIVE {
            return false;
        }
        let r = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(len2)));
        if reach.is_nan() || reach * r > 1.0 {
            return false;
        }
        let v = _mm_mul_ps(_mm_setr_ps(w.x, w.y, w.z, -reach), _mm_set1_ps(FixedBlock::SCALE as f32 * r));
        // To the nearest integer, ties away from zero: ±½ (exact below 2¹⁵), then truncation.
        let half = _mm_or_ps(_mm_and_ps(v, _mm_set1_ps(-0.0)), _mm_set1_ps(0.5));
        let view = _mm_cvttps_epi32(_mm_add_ps(v, half));
        // 16-bit lanes u_x, u_y, u_z, −c: pairs (u_x, u_y) and (u_z, −c) repeated.
        let view = _mm_packs_epi32(view, view);
        let uxy = _mm_shuffle_epi32::<0b00_00_00_00>(view);
        let uzc = _mm_shuffle_epi32::<0b01_01_01_01>(view);
        let load = |v: &Lanes| {
            let [a, b, c, d, e, f, g, h] = v.0;
            _mm_setr_epi16(a, b, c, d, e, f, g, h)
        };
        // |d| ≤ T as one unsigned compare, as in `Quantized`.
        let shift = _mm_set1_epi32(FixedBlock::SURE);
        let flip = _mm_set1_epi32(i32::MIN);
        let limit = _mm_set1_epi32((2 * FixedBlock::SURE + 1) ^ i32::MIN);
        let undecided_lanes = |d: __m128i| _mm_cmpgt_epi32(limit, _mm_xor_si128(_mm_add_epi32(d, shift), flip));
        for (k, block) in blocks.iter().enumerate() {
            if let Some(next) = blocks.get(k + PREFETCH_BLOCKS) {
                drafter_core::prefetch(&next.rows[0]);
                drafter_core::prefetch(&next.ids);
            }
            let [xy1, zh1, xy2, zh2] = block.rows.each_ref().map(load);
            let d1 = _mm_add_epi32(_mm_madd_epi16(xy1, uxy), _mm_madd_epi16(zh1, uzc));
            let d2 = _mm_add_epi32(_mm_madd_epi16(xy2, uxy), _mm_madd_epi16(zh2, uzc));
            let open = _mm_movemask_ps(_mm_castsi128_ps(_mm_or_si128(undecided_lanes(d1), undecided_lanes(d2))));
            let mask = (_mm_movemask_ps(_mm_castsi128_ps(_mm_xor_si128(d1, d2))) & !open) as u32;
            if open != 0 {
                let at = (q + k * BLOCK_QUADS) as u32;
                pending.push([at, at + BLOCK_QUADS as u32]);
            }
            emit_mask(mask, block.ids, out);
        }
        true
    }
}

impl Stream {
    /// The `f32` test of the blocks at the quad ranges `pending` (see [`Stream::perspective_leaf`]), their
    /// data requested first so that the misses overlap. ORing in each block's whole mask is enough:
    /// its decided lanes agree with it.
    pub fn perspective_pending(&self, pending: &[[u32; 2]], e: Vec3, out: &mut [u64]) {
        for &[q0, q1] in pending {
            if let Some(r) = self.quads.get(q0 as usize..q1 as usize) {
                prefetch(r, 3);
            }
        }
        let (ex, ey, ez) = (Vec4::splat(e.x), Vec4::splat(e.y), Vec4::splat(e.z));
        for &[q0, q1] in pending {
            if let Some(r) = self.quads.get(q0 as usize..q1 as usize).and_then(|r| r.as_array()) {
                emit_mask(perspective_mask(r, ex, ey, ez), r[9].map(f32::to_bits), out);
            }
        }
    }
}

/// Writes candidates `ids` as blocks of [`Stream`] into `out` (zeros, one block per 4 candidates).
fn write_blocks(ids: &[u32], normals: &[[Vec3; 2]], points: &[Vec3], out: &mut [[f32; 4]]) {
    for (chunk, rows) in ids.chunks(4).zip(out.as_chunks_mut::<BLOCK_QUADS>().0) {
        let mut slots = [0u32; 4];
        for (lane, &i) in chunk.iter().enumerate() {
            let [n1, n2] = normals[i as usize];
            for (r, x) in [n1.x, n1.y, n1.z, n2.x, n2.y, n2.z].into_iter().enumerate() {
                rows[r][lane] = x;
            }
            let p = points[i as usize];
            rows[6][lane] = p.x;
            rows[7][lane] = p.y;
            rows[8][lane] = p.z;
            slots[lane] = i;
        }
        rows[9] = slots.map(f32::from_bits);
    }
}

/// The perspective predicate on the 4 lanes of a block (see [`Stream`]), as a 4-bit mask.
#[inline(always)]
fn perspective_mask(r: &[[f32; 4]; BLOCK_QUADS], ex: Vec4, ey: Vec4, ez: Vec4) -> u32 {
    let (wx, wy, wz) = (ex - Vec4::from(r[6]), ey - Vec4::from(r[7]), ez - Vec4::from(r[8]));
    let a = Vec4::from(r[0]) * wx + Vec4::from(r[1]) * wy + Vec4::from(r[2]) * wz;
    let c = Vec4::from(r[3]) * wx + Vec4::from(r[4]) * wy + Vec4::from(r[5]) * wz;
    let hit = (a.cmplt(Vec4::ZERO) & c.cmpgt(Vec4::ZERO)) | (a.cmpgt(Vec4::ZERO) & c.cmplt(Vec4::ZERO));
    hit.bitmask()
}

/// Sets the bits of a block's hits (`mask`) at their candidates `slots`.
#[inline(always)]
fn emit_mask(mask: u32, slots: [u32; 4], out: &mut [u64]) {
    if mask == 0 {
        return;
    }
    // Branch-free within a block: every lane ORs its bit (0 for a miss; padding lanes point at
    // candidate 0 and never hit), cheaper than mispredicting per hit.
    for (lane, &i) in slots.iter().enumerate() {
        let i = i as usize;
        if let Some(w) = out.get_mut(i / 64) {
            *w |= u64::from((mask >> lane) & 1) << (i % 64);
        }
    }
}

/// Packs eight 0/1 bytes into the low bits of a byte (byte `i` → bit `i`): the multiply moves each
/// byte's bit to position 56 + i without carries.
#[inline(always)]
fn pack8(bits: &[u8; 8]) -> u8 {
    (u64::from_le_bytes(*bits).wrapping_mul(0x0102_0408_1020_4080) >> 56) as u8
}

#[inline(always)]
fn pack64(bits: &[u8; 64]) -> u64 {
    let mut m = 0u64;
    for (k, c) in bits.as_chunks::<8>().0.iter().enumerate() {
        m |= u64::from(pack8(c)) << (8 * k);
    }
    m
}

/// The brute-force query: every candidate, every view. The reference for the hierarchies and the
/// fallback when no hierarchy is worth storing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BruteForce {
    soa: Soa,
}

impl BruteForce {
    /// Candidates in their given order; `points` (one per candidate) are needed for perspective
    /// queries and may be empty for orthographic-only use.
    pub fn new(normals: &[[Vec3; 2]], points: &[Vec3]) -> Self {
        let points = (points.len() == normals.len() && !normals.is_empty()).then_some(points);
        Self { soa: Soa::gather(normals, points, 0..normals.len() as u32) }
    }

    pub fn len(&self) -> usize {
        self.soa.len
    }

    pub fn is_empty(&self) -> bool {
        self.soa.len == 0
    }

    /// Whether perspective queries are possible (points were given).
    pub fn supports_perspective(&self) -> bool {
        self.soa.has_points()
    }

    /// Silhouettes of `view` into `out` (reset to this candidate count), using all threads when
    /// there are at least [`PARALLEL_MIN_CANDIDATES`] candidates.
    pub fn query(&self, view: View, out: &mut EdgeSet) {
        self.run(view, out, self.soa.len >= PARALLEL_MIN_CANDIDATES);
    }

    /// Like [`BruteForce::query`] on the calling thread only.
    pub fn query_serial(&self, view: View, out: &mut EdgeSet) {
        self.run(view, out, false);
    }

    fn run(&self, view: View, out: &mut EdgeSet, parallel: bool) {
        out.reset(self.soa.len);
        let words = out.words_mut();
        let soa = &self.soa;
        match view {
            View::Orthographic { direction } => {
                let Some(u) = unit_direction(direction) else { return };
                fill(words, parallel, |w| soa.ortho_word(w, u));
            }
            View::Perspective { eye } => {
                if !soa.has_points() {
                    return;
                }
                fill(words, parallel, |w| soa.perspective_word(w, eye));
            }
        }
        // Padding candidates have zero normals and never pass, so no bit above `len` is set.
    }
}

fn fill(words: &mut [u64], parallel: bool, word: impl Fn(usize) -> u64 + Sync) {
    const WORDS_PER_TASK: usize = 256;
    if parallel {
        words.par_chunks_mut(WORDS_PER_TASK).enumerate().for_each(|(c, chunk)| {
            for (i, slot) in chunk.iter_mut().enumerate() {
                *slot = word(c * WORDS_PER_TASK + i);
            }
        });
    } else {
        for (w, slot) in words.iter_mut().enumerate() {
            *slot = word(w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use glam::Quat;

    use crate::measure::signed_uniform;

    /// The walk's block test (the 16-bit pretest on x86-64) against the scalar predicate, on
    /// normals placed at distances from the view's great circle around the pretest's threshold
    /// (|n·u| ≈ 5.6·10⁻⁵), exactly on it, and on normals the pretest must refuse (too long, NaN,
    /// zero), in ranges that start and end inside words.
    #[test]
    fn block_test_matches_predicate_near_the_circle() {
        let mut r = signed_uniform(0x5eed);
        let offsets = [0.0, 1e-9, 1e-7, 1e-6, 1e-5, 3e-5, 5e-5, 5.4e-5, 5.5e-5, 5.6e-5, 5.7e-5, 6e-5, 1e-4, 1e-3, 0.3];
        let mut checked = 0usize;
        for _ in 0..400 {
            let u = unit_direction(Vec3::new(r(), r(), r())).unwrap_or(Vec3::Z);
            let side = u.any_orthonormal_vector();
            let normal = |r: &mut dyn FnMut() -> f32| -> Vec3 {
                let k = ((r() * 0.5 + 0.5) * 17.0) as usize;
                let angle = r() * std::f32::consts::PI;
                let p = Quat::from_axis_angle(u, angle) * side;
                match k {
                    0..=14 => {
                        let e: f32 = offsets[k] * if r() < 0.0 { -1.0 } else { 1.0 };
                        p * (1.0 - e * e).sqrt() + u * e
                    }
                    15 => Vec3::new(r(), r(), r()) * 1.02,
                    _ => [Vec3::ZERO, Vec3::NAN, Vec3::new(r(), r(), r())][((r() * 0.5 + 0.5) * 2.99) as usize],
                }
            };
            let n = 64 + ((r() * 0.5 + 0.5) * 200.0) as usize;
            let normals: Vec<[Vec3; 2]> = (0..n).map(|_| [normal(&mut r), normal(&mut r)]).collect();
            let order: Vec<u32> = (0..n as u32).collect();
            let blocks = OrthoBlocks::new(&order, &normals);
            let nb = n.div_ceil(4) as u32;
            let cut = |r: &mut dyn FnMut() -> f32| ((r() * 0.5 + 0.5) * nb as f32) as u32;
            let (a, b) = (cut(&mut r), cut(&mut r));
            let (a, b) = (a.min(b), a.max(b));
            let ranges = [[0, a], [a, b], [b, nb]];
            let mut words = vec![0u64; n.div_ceil(64)];
            let mut dirty = Vec::new();
            blocks.test_ranges(&ranges, u, &mut words, &mut dirty);
            for (i, [n1, n2]) in normals.iter().enumerate() {
                let got = words[i / 64] >> (i % 64) & 1 == 1;
                assert_eq!(got, is_silhouette_orthographic(*n1, *n2, u), "candidate {i}: {n1} {n2} u {u}");
                checked += 1;
            }
            assert!(words.iter().enumerate().all(|(w, &x)| x == 0 || dirty.contains(&(w as u32))));
        }
        assert!(checked > 40_000);
    }

    /// A cone BVH leaf's test (the 16-bit pretest on x86-64, then the pending blocks in `f32`)
    /// against the scalar predicate: normals placed at distances from the plane through the eye
    /// around the pretest's threshold (`|D| ≤ T`, about 8.8·10⁻⁵ of the eye's distance), exactly
    /// on it, and normals the pretest must refuse (too long, too short, NaN, zero); leaves far
    /// from the origin (10⁶), small and large, eyes near and far (some within the leaf's reach,
    /// which the pretest leaves to `f32`), a leaf with a non-finite point.
    #[test]
    fn leaf_test_matches_predicate_near_the_planes() {
        let mut r = signed_uniform(0xface);
        let offsets = [0.0, 1e-9, 1e-7, 1e-6, 1e-5, 5e-5, 8e-5, 8.8e-5, 9e-5, 1e-4, 3e-4, 1e-3, 0.3];
        let (mut checked, mut pretested, mut pending_blocks) = (0usize, 0usize, 0usize);
        for trial in 0..300 {
            let centre = Vec3::new(r(), r(), r()) * if trial % 3 == 0 { 1e6 } else { 10.0 };
            let size = 10f32.powf(r() * 3.0);
            let distance = size * 10f32.powf(r() * 2.0 + 0.5) * if trial % 7 == 0 { 0.1 } else { 1.0 };
            let eye = centre + Vec3::new(r(), r(), r()).normalize_or(Vec3::X) * distance;
            let n = 64 + ((r() * 0.5 + 0.5) * 200.0) as usize;
            let mut points: Vec<Vec3> = (0..n).map(|_| centre + Vec3::new(r(), r(), r()) * size).collect();
            if trial % 11 == 5 {
                points[n / 2].y = f32::NAN;
            }
            let normal = |v: Vec3, r: &mut dyn FnMut() -> f32| -> Vec3 {
                let w = (eye - v).normalize_or(Vec3::Z);
                let side = Quat::from_axis_angle(w, r() * std::f32::consts::PI) * w.any_orthonormal_vector();
                let k = ((r() * 0.5 + 0.5) * 16.0) as usize;
                match k {
                    0..=12 => {
                        let e: f32 = offsets[k] * if r() < 0.0 { -1.0 } else { 1.0 };
                        side * (1.0 - e * e).sqrt() + w * e
                    }
                    13 => (side + w * r() * 1e-4) * [1.01, 1.02, 1e-6][((r() * 0.5 + 0.5) * 2.99) as usize],
                    _ => [Vec3::ZERO, Vec3::NAN, Vec3::new(r(), r(), r())][((r() * 0.5 + 0.5) * 2.99) as usize],
                }
            };
            let normals: Vec<[Vec3; 2]> = points.iter().map(|&v| [normal(v, &mut r), normal(v, &mut r)]).collect();
            // Up to three leaves, each anchored at the centre of its points' box.
            let ids: Vec<u32> = (0..n as u32).rev().collect();
            let cut = |r: &mut dyn FnMut() -> f32| ((r() * 0.5 + 0.5) * n as f32) as usize;
            let (a, b) = (cut(&mut r), cut(&mut r));
            let ranges = [(0, a.min(b)), (a.min(b), a.max(b)), (a.max(b), n)];
            let anchors: Vec<Vec3> = ranges
                .iter()
                .map(|&(s, e)| {
                    let (lo, hi) = ids[s..e].iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &i| {
                        (lo.min(points[i as usize]), hi.max(points[i as usize]))
                    });
                    (lo + hi) * 0.5
                })
                .collect();
            let (stream, at, reaches) = Stream::from_ranges(&ranges, &anchors, &ids, (&normals, &points), true);
            let mut words = vec![0u64; n.div_ceil(64)];
            let mut pending = Vec::new();
            for (k, &(q, count)) in at.iter().enumerate() {
                let far = (eye.as_dvec3() - anchors[k].as_dvec3()).length() >= f64::from(reaches[k]);
                pretested += usize::from(cfg!(target_arch = "x86_64") && far && count > 0);
                stream.perspective_leaf(q as usize, count, (anchors[k], reaches[k]), eye, &mut words, &mut pending);
            }
            pending_blocks += pending.len();
            stream.perspective_pending(&pending, eye, &mut words);
            for (i, [n1, n2]) in normals.iter().enumerate() {
                let got = words[i / 64] >> (i % 64) & 1 == 1;
                let expected = is_silhouette_perspective(*n1, *n2, points[i], eye);
                assert_eq!(got, expected, "trial {trial}, candidate {i}: {n1} {n2} at {} eye {eye}", points[i]);
                checked += 1;
            }
        }
        assert!(checked > 40_000);
        if cfg!(target_arch = "x86_64") {
            assert!(pretested > 300 && pending_blocks > 1000, "{pretested} leaves pretested, {pending_blocks} pending");
        }
    }

    #[test]
    fn pack_matches_bit_order() {
        let mut bits = [0u8; 8];
        for m in 0..=255u8 {
            for (i, b) in bits.iter_mut().enumerate() {
                *b = (m >> i) & 1;
            }
            assert_eq!(pack8(&bits), m);
        }
    }

    #[test]
    fn tie_rule() {
        assert!(opposite_signs(-1.0, 1.0) && opposite_signs(1e-30, -1e-30));
        assert!(!opposite_signs(0.0, 1.0) && !opposite_signs(-0.0, -1.0) && !opposite_signs(0.0, -0.0));
        assert!(!opposite_signs(f32::NAN, 1.0) && !opposite_signs(2.0, 3.0));
        assert_eq!(unit_direction(Vec3::ZERO), None);
        assert_eq!(unit_direction(Vec3::new(f32::INFINITY, 0.0, 0.0)), None);
    }

    /// The chunked kernels agree with the scalar predicate on every candidate, for lengths that
    /// exercise padding, and serial equals parallel.
    #[test]
    fn kernels_match_scalar_predicate() {
        let mut r = signed_uniform(7);
        for n in [0usize, 1, 63, 64, 65, 1000, PARALLEL_MIN_CANDIDATES + 3] {
            let normals: Vec<[Vec3; 2]> =
                (0..n).map(|_| [Vec3::new(r(), r(), r()).normalize(), Vec3::new(r(), r(), r()).normalize()]).collect();
            let points: Vec<Vec3> = (0..n).map(|_| Vec3::new(r(), r(), r())).collect();
            let brute = BruteForce::new(&normals, &points);
            let mut serial = EdgeSet::default();
            let mut parallel = EdgeSet::default();
            for _ in 0..3 {
                let d = Vec3::new(r(), r(), r());
                let e = Vec3::new(r(), r(), r()) * 3.0;
                for view in [View::Orthographic { direction: d }, View::Perspective { eye: e }] {
                    brute.query_serial(view, &mut serial);
                    brute.query(view, &mut parallel);
                    assert_eq!(serial, parallel);
                    let u = unit_direction(d).unwrap();
                    let expected: Vec<u32> = (0..n as u32)
                        .filter(|&i| {
                            let [n1, n2] = normals[i as usize];
                            match view {
                                View::Orthographic { .. } => is_silhouette_orthographic(n1, n2, u),
                                View::Perspective { eye } => is_silhouette_perspective(n1, n2, points[i as usize], eye),
                            }
                        })
                        .collect();
                    assert_eq!(serial.to_vec(), expected);
                }
            }
            // Blocks of a permutation, split in two groups, agree with brute force.
            let order: Vec<u32> = (0..n as u32).rev().collect();
            let (head, tail) = order.split_at(n / 3);
            let mut stream = Stream::new();
            let q1 = stream.len();
            let b1 = stream.push_blocks(head, &normals, &points);
            let q2 = stream.len();
            let b2 = stream.push_blocks(tail, &normals, &points);
            let e = Vec3::new(2.0, 1.0, -3.0);
            let mut words = vec![0u64; n.div_ceil(64)];
            stream.perspective(q1, b1, e, &mut words);
            stream.perspective(q2, b2, e, &mut words);
            brute.query_serial(View::Perspective { eye: e }, &mut serial);
            assert_eq!(words, serial.words());
            // Position-addressed blocks in storage order, tested in two runs: bits are storage
            // positions, so map them back through the order.
            let blocks = OrthoBlocks::new(&order, &normals);
            let d = Vec3::new(0.3, -0.2, 0.9);
            let u = unit_direction(d).unwrap();
            let mut positions = vec![0u64; n.div_ceil(64)];
            let nb = n.div_ceil(4);
            let mut dirty = Vec::new();
            blocks.test(0, nb / 2, u, &mut positions, &mut dirty);
            blocks.test(nb / 2, nb, u, &mut positions, &mut dirty);
            assert!(positions.iter().enumerate().all(|(w, &x)| x == 0 || dirty.contains(&(w as u32))));
            brute.query_serial(View::Orthographic { direction: d }, &mut serial);
            let mapped: Vec<u32> =
                (0..n).filter(|&k| positions[k / 64] >> (k % 64) & 1 == 1).map(|k| order[k]).collect::<Vec<_>>();
            let mut mapped = mapped;
            mapped.sort_unstable();
            assert_eq!(mapped, serial.to_vec());
        }
    }
}
