//! The workspace's one seeded random-number generator, for tests, fuzzing and benchmarks that need
//! reproducible inputs without a dependency: SplitMix64 (Steele, Lea and Flood, "Fast splittable
//! pseudorandom number generators", OOPSLA 2014), with the samplers the tests and benchmarks draw
//! from it (unit and signed floats, ranges, directions, rotations, permutations). Any seed is good,
//! 0 included, and the sequence is the same on every platform. Not for anything that must be
//! unpredictable. The production texture noise uses drafter-textures' `Pcg32`, whose sequence is
//! part of the baked files' bytes.

use glam::{DQuat, DVec3, Vec3};

/// SplitMix64: a 64-bit counter stepped by the golden ratio and mixed by a finalizer.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    /// The generator whose first output mixes `seed` plus one step.
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The next 64 bits.
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1) with 24 bits (an exact f32).
    pub fn unit_f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [−1, 1) with 24 bits.
    pub fn signed_f32(&mut self) -> f32 {
        self.unit_f32() * 2.0 - 1.0
    }

    /// Uniform in [0, 1) with 53 bits (an exact f64).
    pub fn unit_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−1, 1) with 53 bits.
    pub fn signed_f64(&mut self) -> f64 {
        self.unit_f64() * 2.0 - 1.0
    }

    /// Uniform in [lo, hi).
    pub fn range_f32(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit_f32()
    }

    /// Uniform in [lo, hi).
    pub fn range_f64(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit_f64()
    }

    /// The next output modulo `n` (0 counts as 1; slightly biased for `n` not a power of two,
    /// which a test's case generator does not mind).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n.max(1)
    }

    /// A uniformly random index into something of `len` items (`len` > 0).
    pub fn index(&mut self, len: usize) -> usize {
        self.below(len as u64) as usize
    }

    /// Standard normal (Box and Muller, 1958).
    pub fn normal(&mut self) -> f64 {
        let u = self.unit_f64().max(1e-300);
        let v = self.unit_f64();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// A uniformly random unit vector.
    pub fn direction(&mut self) -> DVec3 {
        let z = self.unit_f64() * 2.0 - 1.0;
        let a = self.unit_f64() * std::f64::consts::TAU;
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * a.cos(), r * a.sin(), z)
    }

    /// A uniformly random unit vector, in `f32`.
    pub fn direction_f32(&mut self) -> Vec3 {
        let z = 2.0 * self.unit_f32() - 1.0;
        let phi = std::f32::consts::TAU * self.unit_f32();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    /// A uniformly random rotation (Shoemake, "Uniform random rotations", Graphics Gems III, 1992).
    pub fn rotation(&mut self) -> DQuat {
        let tau = std::f64::consts::TAU;
        let (u1, u2, u3) = (self.unit_f64(), self.unit_f64() * tau, self.unit_f64() * tau);
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        DQuat::from_xyzw(a * u2.sin(), a * u2.cos(), b * u3.sin(), b * u3.cos()).normalize()
    }

    /// A random permutation of 0..n (Fisher–Yates): `p[i]` is where `i` goes.
    pub fn permutation(&mut self, n: usize) -> Vec<u32> {
        let mut p: Vec<u32> = (0..n as u32).collect();
        for i in (1..n).rev() {
            let j = self.below(i as u64 + 1) as usize;
            p.swap(i, j);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_sequence() {
        // SplitMix64 from seed 0: the first outputs of the reference implementation
        // (Vigna's splitmix64.c), as other ports publish them.
        let mut r = Rng::new(0);
        assert_eq!(r.next_u64(), 0xe220_a839_7b1d_cdaf);
        assert_eq!(r.next_u64(), 0x6e78_9e6a_a1b9_65f4);
        assert_eq!(r.next_u64(), 0x06c4_5d18_8009_454f);
        let mut r = Rng::new(0x9e37_79b9_7f4a_7c15);
        for _ in 0..10_000 {
            let (u, s) = (r.clone().unit_f64(), r.signed_f32());
            assert!((0.0..1.0).contains(&u) && (-1.0..1.0).contains(&s));
            assert!((r.direction().length() - 1.0).abs() < 1e-12);
            assert!((r.rotation().length() - 1.0).abs() < 1e-12);
            assert!(r.below(7) < 7 && r.below(0) == 0);
        }
        let mut p = r.permutation(100);
        p.sort_unstable();
        assert!(p.iter().enumerate().all(|(i, &v)| v as usize == i));
    }
}
