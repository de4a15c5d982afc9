//! The workspace's one small deterministic random-number generator, for tests, fuzzing seeds and
//! benchmarks that need reproducible inputs without a dependency: Marsaglia's xorshift64 (shifts
//! 13, 7, 17; "Xorshift RNGs", Journal of Statistical Software 8(14), 2003). Not for anything that
//! must be unpredictable. The production texture noise uses drafter-textures' `Pcg32` instead.

/// xorshift64 with its state exposed through the mappings the tests use. A state of 0 stays 0:
/// seed with any other number.
#[derive(Clone, Debug)]
pub struct XorShift64(u64);

impl XorShift64 {
    /// The generator whose first output is the step after `seed`.
    pub fn new(seed: u64) -> Self {
        XorShift64(seed)
    }

    /// The next 64 bits.
    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn next(&mut self) -> u64 {
        let mut s = self.0;
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        self.0 = s;
        s
    }

    /// Uniform in [0, 1) with 24 bits (an exact f32).
    pub fn unit_f32(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [−1, 1) with 24 bits.
    pub fn signed_f32(&mut self) -> f32 {
        self.unit_f32() * 2.0 - 1.0
    }

    /// Uniform in [0, 1) with 53 bits (an exact f64).
    pub fn unit_f64(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−1, 1) with 53 bits.
    pub fn signed_f64(&mut self) -> f64 {
        self.unit_f64() * 2.0 - 1.0
    }

    /// The next output modulo `m` (`m` > 0; slightly biased for `m` not a power of two, which a
    /// test's case generator does not mind).
    pub fn below(&mut self, m: u64) -> u64 {
        self.next() % m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_recurrence() {
        // The first outputs from seed 1, stepped by hand: 1 ^ 1<<13 = 0x2001; ^ >>7 = 0x2041;
        // ^ <<17 = 0x4082_2041.
        let mut r = XorShift64::new(1);
        assert_eq!(r.next(), 0x4082_2041);
        let mut zero = XorShift64::new(0);
        assert_eq!(zero.next(), 0, "0 is the fixed point");
        let mut r = XorShift64::new(0x9e37_79b9_7f4a_7c15);
        for _ in 0..10_000 {
            let (u, s) = (r.clone().unit_f64(), r.signed_f32());
            assert!((0.0..1.0).contains(&u) && (-1.0..1.0).contains(&s));
        }
    }
}
