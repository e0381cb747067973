//! `halton`: the Halton sequence over the whole image, scrambled.
//!
//! Dimension d is the radical inverse in base prime(d) (1000 primes, then
//! wrap); pixels modulo 128 get their own sub-sequence through the Chinese
//! remainder theorem (pbrt-v4 section 8.6). `randomize = "owen"` applies
//! nested digit permutations (a random affine map of each digit keyed by the
//! digits before it); `"digits"`, one random permutation per digit position.

use lumis_api::{
    ConcreteLanes, ParamChoice, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result,
    Sampler, SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::primes::{PRIMES, PRIME_TABLE_SIZE};
use lumis_sampling::{
    hash_u64, hash_with, inverse_radical_inverse, scrambled_radical_inverse, DigitScramble,
};

use crate::dimensions::DimensionCursor;
use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "halton",
    source: lumis_api::source_file!(),
    doc: "one Halton sequence over the image (dimension d in base prime(d)); each pixel gets its own sub-sequence; digits scrambled",
    params: HaltonParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct HaltonParams {
    #[param(flatten)]
    pub spp: SppParams,
    /// digit scrambling: owen (nested), digits (one permutation per digit),
    /// none
    #[param(default = Owen)]
    pub randomize: HaltonRandomize,
}

/// The `randomize` parameter of `halton`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum HaltonRandomize {
    Owen,
    Digits,
    None,
}

impl From<HaltonRandomize> for DigitScramble {
    fn from(randomize: HaltonRandomize) -> Self {
        match randomize {
            HaltonRandomize::Owen => DigitScramble::Owen,
            HaltonRandomize::Digits => DigitScramble::RandomDigits,
            HaltonRandomize::None => DigitScramble::None,
        }
    }
}

/// Pixels are mapped to sub-sequences modulo this many pixels per axis.
const TILE: u32 = 128;
/// The smallest powers of 2 and 3 that cover a tile: 2^7 and 3^5.
const BASE_EXPONENTS: [u32; 2] = [7, 5];
const BASE_SCALES: [u64; 2] = [128, 243];
/// Consecutive samples of a pixel are this far apart in the sequence.
const STRIDE: u64 = BASE_SCALES[0] * BASE_SCALES[1];

/// The Halton sampler of pbrt-v4 (section 8.6): the first two dimensions,
/// scaled by 2^7 and 3^5, cover a 128 x 243 grid, so by the Chinese remainder
/// theorem the points falling in a given pixel are exactly the indices
/// `offset(pixel) + i * 2^7 3^5`; sample `i` of the pixel is that point, and
/// every dimension `d >= 2` uses the radical inverse in the `d`-th prime.
/// Pixel coordinates are taken modulo 128 (as pbrt's maximum resolution),
/// which keeps indices small and needs no film size.
///
/// Scrambling is global per dimension and seed (the sub-sequence mapping
/// already differs per pixel). Beyond the 1000-prime table dimensions wrap
/// to the start with a different scramble.
#[derive(Debug, Clone)]
pub struct HaltonSampler {
    spp: u32,
    scramble: DigitScramble,
    /// `(2^7)^-1 mod 3^5`-style inverses for the Chinese remainder theorem.
    mult_inverse: [u64; 2],
    seed_key: u64,
    halton_index: u64,
    dimension: DimensionCursor,
}

/// `a^-1 mod n` by the extended Euclidean algorithm (`a`, `n` coprime).
fn multiplicative_inverse(a: i64, n: i64) -> u64 {
    let (mut old_r, mut r) = (a, n);
    let (mut old_s, mut s) = (1i64, 0i64);
    while r != 0 {
        let q = old_r / r;
        (old_r, r) = (r, old_r - q * r);
        (old_s, s) = (s, old_s - q * s);
    }
    old_s.rem_euclid(n) as u64
}

impl HaltonSampler {
    pub fn new(spp: u32, scramble: DigitScramble) -> Self {
        Self {
            spp,
            scramble,
            mult_inverse: [
                multiplicative_inverse(BASE_SCALES[1] as i64, BASE_SCALES[0] as i64),
                multiplicative_inverse(BASE_SCALES[0] as i64, BASE_SCALES[1] as i64),
            ],
            seed_key: 0,
            halton_index: 0,
            dimension: DimensionCursor::default(),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = HaltonParams::read(params)?;
        Ok(Self::new(p.spp.checked(params)?, p.randomize.into()))
    }

    fn sample_dimension(&self, dimension: u32) -> f32 {
        let wrapped = 2 + (dimension as usize - 2) % (PRIME_TABLE_SIZE - 2);
        let seed = hash_with(self.seed_key, dimension as u64);
        scrambled_radical_inverse(PRIMES[wrapped], self.halton_index, seed, self.scramble)
    }
}

impl Sampler for HaltonSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        // The index whose first 7 base-2 digits name column x and first 5
        // base-3 digits row y, combined by the Chinese remainder theorem.
        let p = [pixel.x % TILE, pixel.y % TILE];
        let mut offset = 0;
        for i in 0..2 {
            let digits = inverse_radical_inverse(p[i] as u64, [2, 3][i], BASE_EXPONENTS[i]);
            offset += digits * (STRIDE / BASE_SCALES[i]) * self.mult_inverse[i];
        }
        self.halton_index = offset % STRIDE + index as u64 * STRIDE;
        self.seed_key = hash_u64(seed);
        self.dimension = DimensionCursor::START;
    }

    fn get_1d(&mut self) -> f32 {
        let d = self.dimension.take(1);
        self.sample_dimension(d)
    }

    fn get_2d(&mut self) -> Vec2 {
        let d = self.dimension.take(2);
        Vec2::new(self.sample_dimension(d), self.sample_dimension(d + 1))
    }

    /// The position inside the pixel: the digits of the index past those
    /// that chose the pixel.
    fn get_pixel_2d(&mut self) -> Vec2 {
        let s = |d: u64| hash_with(self.seed_key, d);
        Vec2::new(
            scrambled_radical_inverse(
                2,
                self.halton_index >> BASE_EXPONENTS[0],
                s(0),
                self.scramble,
            ),
            scrambled_radical_inverse(3, self.halton_index / BASE_SCALES[1], s(1), self.scramble),
        )
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    /// The first coordinate of consecutive Halton points in base 2: one
    /// per column of a power-of-two count.
    fn pixel_pattern(&self) -> PixelPattern {
        if self.spp.is_power_of_two() {
            PixelPattern::Grid {
                nx: self.spp,
                ny: 1,
            }
        } else {
            PixelPattern::Random
        }
    }

    fn randomized(&self) -> bool {
        self.scramble != DigitScramble::None
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::radical_inverse;

    #[test]
    fn pixel_sub_sequence_lands_in_its_pixel() {
        // Unscrambled: point `halton_index` of the global sequence, scaled
        // by (128, 243), falls in the pixel that asked for it.
        let mut s = HaltonSampler::new(8, DigitScramble::None);
        for (x, y) in [(0u32, 0u32), (5, 7), (127, 127), (64, 3)] {
            for i in 0..8 {
                s.start_pixel_sample(UVec2::new(x, y), i, 0);
                let h = s.halton_index;
                assert_eq!((radical_inverse(2, h) as f64 * 128.0) as u32, x);
                assert_eq!((radical_inverse(3, h) as f64 * 243.0) as u32, y);
            }
        }
    }

    #[test]
    fn pixel_samples_are_stratified_inside_the_pixel() {
        // The within-pixel positions of 2^k samples are the van der Corput
        // points of consecutive indices: one per 1/2^k interval in x.
        let mut s = HaltonSampler::new(16, DigitScramble::Owen);
        let mut seen = [false; 16];
        for i in 0..16 {
            s.start_pixel_sample(UVec2::new(9, 4), i, 7);
            let x = s.get_pixel_2d().x;
            let cell = (x * 16.0) as usize;
            assert!(!seen[cell]);
            seen[cell] = true;
        }
    }

    #[test]
    fn seeds_change_the_scramble() {
        let mut s = HaltonSampler::new(4, DigitScramble::Owen);
        s.start_pixel_sample(UVec2::new(1, 2), 0, 1);
        let a = (s.get_pixel_2d(), s.get_2d());
        s.start_pixel_sample(UVec2::new(1, 2), 0, 2);
        let b = (s.get_pixel_2d(), s.get_2d());
        assert_ne!(a, b);
    }
}
