//! Random numbers: PCG32 and a 64-bit mixing hash.
//!
//! Own implementations because sampling is the subject of this project and
//! both are a few lines; they are checked against the published reference
//! output below.

/// PCG-XSH-RR 64/32 (O'Neill 2014, "PCG: A Family of Simple Fast
/// Space-Efficient Statistically Good Algorithms for Random Number Generation").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

const MULTIPLIER: u64 = 6364136223846793005;

impl Pcg32 {
    /// `pcg32_srandom_r(initstate, initseq)` of the reference implementation.
    pub fn new(init_state: u64, init_seq: u64) -> Self {
        let mut rng = Self {
            state: 0,
            inc: (init_seq << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(init_state);
        rng.next_u32();
        rng
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in `[0, 1)`: the top 24 bits, so every value is exact in f32
    /// and 1.0 is never returned.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Jumps `delta` steps ahead in O(log delta) (Brown 1994, "Random Number
    /// Generation with Arbitrary Strides").
    pub fn advance(&mut self, delta: u64) {
        let (mut cur_mult, mut cur_plus) = (MULTIPLIER, self.inc);
        let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
        let mut delta = delta;
        while delta > 0 {
            if delta & 1 == 1 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            delta >>= 1;
        }
        self.state = acc_mult.wrapping_mul(self.state).wrapping_add(acc_plus);
    }
}

/// A 64-bit finaliser with good avalanche (splitmix64's, Steele et al. 2014),
/// used to turn (pixel, sample index, seed) into independent streams.
#[inline]
pub fn hash_u64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Output `counter` of the splitmix64 stream with state `key`: a cheap
/// family of independent hashes, one per counter value (per dimension, per
/// sample index...), each costing a single mix.
#[inline]
pub fn hash_with(key: u64, counter: u64) -> u64 {
    hash_u64(key.wrapping_add(counter.wrapping_mul(0x9e37_79b9_7f4a_7c15)))
}

/// One key per (pixel, seed): the root from which samplers derive the
/// per-pixel streams, permutations and scrambles.
#[inline]
pub fn pixel_key(x: u32, y: u32, seed: u64) -> u64 {
    hash_u64((((x as u64) << 32) | y as u64) ^ hash_u64(seed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_reference_pcg32_demo_output() {
        // pcg32-demo from pcg-c-basic: pcg32_srandom_r(&rng, 42u, 54u),
        // first six outputs.
        let mut rng = Pcg32::new(42, 54);
        let expected = [
            0xa15c02b7u32,
            0x7b47f409,
            0xba1d3330,
            0x83d2f293,
            0xbfa4784b,
            0xcbed606e,
        ];
        for e in expected {
            assert_eq!(rng.next_u32(), e);
        }
    }

    #[test]
    fn advance_equals_stepping() {
        let mut a = Pcg32::new(7, 3);
        let mut b = a;
        for _ in 0..1000 {
            a.next_u32();
        }
        b.advance(1000);
        assert_eq!(a, b);
    }

    #[test]
    fn floats_are_in_unit_interval_with_right_mean() {
        let mut rng = Pcg32::new(1, 1);
        let n = 1_000_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = rng.next_f32();
            assert!((0.0..1.0).contains(&u));
            sum += u as f64;
        }
        // Standard error of the mean of U(0,1) is 1/sqrt(12 n) ~ 2.9e-4.
        assert!((sum / n as f64 - 0.5).abs() < 5.0 * 2.9e-4);
    }
}
