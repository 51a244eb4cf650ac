//! A small deterministic pseudo-random source for mesh jitter, test points
//! and benchmark inputs (no dependency, same sequence on every platform).

/// The SplitMix64 generator (Steele, Lea & Flood 2014), seeded by its
/// state.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Uniform in $[0, 1)$, with 53 random bits.
    pub fn next_unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in $[-1, 1)$.
    pub fn symmetric(&mut self) -> f64 {
        2.0 * self.next_unit() - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_range_and_deterministic() {
        let (mut a, mut b) = (SplitMix64(7), SplitMix64(7));
        let mut mean = 0.0;
        for _ in 0..10_000 {
            let v = a.symmetric();
            assert!((-1.0..1.0).contains(&v));
            assert_eq!(v, b.symmetric());
            mean += v / 10_000.0;
        }
        assert!(mean.abs() < 0.05, "{mean}");
        let u = SplitMix64(1).next_unit();
        assert!((0.0..1.0).contains(&u));
    }
}
