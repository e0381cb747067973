//! `hammersley`: the finite Hammersley point set of the pixel's samples,
//! Owen-scrambled per pixel.
//!
//! Sample i of a pixel is (i/spp, phi_2(i), phi_3(i), phi_5(i), ...), phi_b
//! the radical inverse in base b, each dimension with its own scramble; the
//! set is a (0,m,2)-net in the film plane when spp = 2^m.

use lumis_api::{
    ConcreteLanes, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result, Sampler,
    SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::primes::{PRIMES, PRIME_TABLE_SIZE};
use lumis_sampling::{
    hash_with, laine_karras_permutation, pixel_key, reversed_to_unit_f32,
    scrambled_radical_inverse, DigitScramble,
};

use crate::dimensions::{net_at_powers_of_two, DimensionCursor};
use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "hammersley",
    source: lumis_api::source_file!(),
    doc: "the Hammersley set (i/spp, radical inverses in 2, 3, 5, ...) of each pixel, Owen-scrambled per pixel; a (0,m,2)-net in the pixel when spp = 2^m",
    params: SppParams::SPECS,
};

/// Sample `i` of `N = spp` is `(i/N, phi_2(i), phi_3(i), phi_5(i), ...)`
/// (Hammersley 1960): dimension 0 is the regular grid `i/N`, dimension
/// `d >= 1` the radical inverse in the `d`-th prime. Unlike Halton it is a
/// finite set: it needs N in advance and has no good prefixes, but its first
/// two dimensions have lower discrepancy. Each pixel scrambles every
/// dimension with its own Owen scramble, so pixels get independent,
/// unbiased copies. Base-2 Owen scrambling of `i/N` keeps the net structure
/// when `N` is a power of two; for other `N` the set is still a scrambled
/// low-discrepancy set, but no longer one point per `1/N` stratum.
#[derive(Debug, Clone)]
pub struct HammersleySampler {
    spp: u32,
    key: u64,
    index: u32,
    dimension: DimensionCursor,
}

impl HammersleySampler {
    pub fn new(spp: u32) -> Self {
        Self {
            spp,
            key: 0,
            index: 0,
            dimension: DimensionCursor::default(),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        Ok(Self::new(SppParams::read(params)?.checked(params)?))
    }

    fn dimension_seed(&self, dimension: u32) -> u64 {
        hash_with(self.key, dimension as u64)
    }

    fn sample_dimension(&self, dimension: u32) -> f32 {
        let seed = self.dimension_seed(dimension);
        match dimension {
            // i / N as a 32-bit binary fraction, scrambled like the rest.
            0 => {
                let fixed = ((self.index as u64) << 32) / self.spp as u64;
                let reversed = (fixed as u32).reverse_bits();
                reversed_to_unit_f32(laine_karras_permutation(reversed, seed as u32))
            }
            // The radical inverse of the index in base 2 is the index
            // bit-reversed: in the reversed domain it is the index itself.
            1 => reversed_to_unit_f32(laine_karras_permutation(self.index, seed as u32)),
            d => {
                let prime = PRIMES[1 + (d as usize - 2) % (PRIME_TABLE_SIZE - 1)];
                scrambled_radical_inverse(prime, self.index as u64, seed, DigitScramble::Owen)
            }
        }
    }
}

impl Sampler for HammersleySampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.key = pixel_key(pixel.x, pixel.y, seed);
        self.index = index % self.spp;
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

    fn get_pixel_2d(&mut self) -> Vec2 {
        Vec2::new(self.sample_dimension(0), self.sample_dimension(1))
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    /// The scrambled Hammersley set of a power-of-two count is a net.
    fn pixel_pattern(&self) -> PixelPattern {
        net_at_powers_of_two(self.spp)
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net_check::is_02_net;

    /// For N = 2^m the scrambled first two dimensions are a (0,m,2)-net:
    /// each 2^a x 2^(m-a) cell holds one point.
    #[test]
    fn pixel_dimensions_form_a_net_for_powers_of_two() {
        for m in [0u32, 3, 6, 10] {
            let n = 1u32 << m;
            let mut s = HammersleySampler::new(n);
            let points: Vec<Vec2> = (0..n)
                .map(|i| {
                    s.start_pixel_sample(UVec2::new(3, 4), i, 11);
                    s.get_pixel_2d()
                })
                .collect();
            assert!(is_02_net(&points, m), "m {m}");
        }
    }
}
