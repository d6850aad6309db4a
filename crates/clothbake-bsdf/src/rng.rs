//! A small deterministic random number generator (SplitMix64, Steele, Lea & Flood 2014, as in
//! Vigna's reference `splitmix64.c`), used by the ray tracer so that a given seed always gives
//! the same random stream on every platform (integer arithmetic only), with no external crates.
//!
//! SplitMix64 passes BigCrush, has period 2^64 and can be split into independent streams by
//! hashing a stream number into the seed ([`Rng::stream`]).

/// The SplitMix64 golden-ratio increment.
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// The SplitMix64 output function (a strong 64-bit bit mixer, a bijection on `u64`).
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// SplitMix64: 64 bits of state, one addition and one mix per output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rng {
    state: u64,
}

impl Rng {
    /// The generator with state `seed` (the reference implementation's seeding).
    pub fn new(seed: u64) -> Rng {
        Rng { state: seed }
    }

    /// An independent stream `stream` of the generator family `seed`: the seed and the stream
    /// number are hashed together, so neighbouring seeds and streams do not overlap in practice.
    pub fn stream(seed: u64, stream: u64) -> Rng {
        Rng::new(mix64(seed ^ mix64(stream.wrapping_add(GAMMA))))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GAMMA);
        mix64(self.state)
    }

    /// A uniform `f64` in [0, 1): the top 53 bits, so every value is a multiple of 2^-53.
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_reference_splitmix64() {
        // First outputs of Vigna's splitmix64.c with x = 0.
        let mut r = Rng::new(0);
        assert_eq!(r.next_u64(), 0xe220_a839_7b1d_cdaf);
        assert_eq!(r.next_u64(), 0x6e78_9e6a_a1b9_65f4);
        assert_eq!(r.next_u64(), 0x06c4_5d18_8009_454f);
    }

    #[test]
    fn uniform_in_unit_interval() {
        let mut r = Rng::stream(7, 3);
        let n = 200_000;
        let mut bins = [0usize; 10];
        let mut sum = 0.0;
        for _ in 0..n {
            let x = r.next_f64();
            assert!((0.0..1.0).contains(&x));
            sum += x;
            bins[(x * 10.0) as usize] += 1;
        }
        // Mean 1/2 with standard error 1/sqrt(12 n) ~ 6.5e-4.
        assert!((sum / n as f64 - 0.5).abs() < 4e-3, "{}", sum / n as f64);
        // Chi-square with 9 degrees of freedom; 40 is far beyond its 99.99th percentile.
        let e = n as f64 / 10.0;
        let chi2: f64 = bins.iter().map(|&b| (b as f64 - e).powi(2) / e).sum();
        assert!(chi2 < 40.0, "{chi2} {bins:?}");
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u64> = (0..4).map(|_| Rng::stream(1, 0).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        let mut x = Rng::stream(1, 0);
        let mut y = Rng::stream(1, 1);
        let mut z = Rng::stream(2, 0);
        let (x, y, z) = (x.next_u64(), y.next_u64(), z.next_u64());
        assert!(x != y && x != z && y != z);
    }
}
