//! Helpers shared by the loader's tests (the loader does not depend on clothbake-core, whose
//! `rng::Rng` is the same generator).

/// A deterministic stream of uniforms in [0, 1) (SplitMix64).
pub struct Rng(pub u64);

impl Rng {
    /// The next uniform in [0, 1): the top 53 bits of SplitMix64's next output.
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
