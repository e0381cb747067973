//! `zsobol`: one Sobol' sequence over the image in Morton (Z) order of the
//! pixels, for blue-noise error between neighbouring pixels.
//!
//! Screen-space blue noise after Ahmed and Wonka 2020 (pbrt-v4's default
//! sampler): pixels own consecutive blocks of the sequence in Morton order,
//! the index's base-4 digits randomly permuted (nested), and every dimension
//! pair is padded from Sobol' dimensions 0-1 and Owen-scrambled. A pixel's
//! samples are a (0,m,2)-net and an aligned 2x2 group of pixels a
//! (0,m+2,2)-net, so the errors of neighbouring pixels cancel. Pixels are
//! taken modulo 65536; a `spp` that is not a power of two uses the block of
//! the next power of two.

use lumis_api::{
    ConcreteLanes, ParamChoice, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result,
    Sampler, SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::{
    hash_u64, hash_with, laine_karras_permutation, reversed_to_unit_f32, sobol_reversed_u32,
};

use crate::dimensions::{net_at_powers_of_two, DimensionCursor};
use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "zsobol",
    source: lumis_api::source_file!(),
    doc: "Ahmed and Wonka's screen-space blue noise: pixels take consecutive blocks of one Sobol' sequence in Morton order, with randomly permuted base-4 digits; error is anti-correlated between neighbouring pixels (pbrt-v4's default)",
    params: ZSobolParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct ZSobolParams {
    #[param(flatten)]
    pub spp: SppParams,
    /// owen: Owen-scrambled points and permuted digits; none: the plain
    /// Z-ordered sequence
    #[param(default = Owen)]
    pub randomize: ZSobolRandomize,
}

/// The `randomize` parameter of `zsobol`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum ZSobolRandomize {
    Owen,
    None,
}

/// Pixel coordinates are taken modulo 2^16 per axis.
const PIXEL_BITS: u32 = 16;

/// The 24 permutations of the four children of a quadtree node.
const PERMUTATIONS: [[u8; 4]; 24] = [
    [0, 1, 2, 3],
    [0, 1, 3, 2],
    [0, 2, 1, 3],
    [0, 2, 3, 1],
    [0, 3, 2, 1],
    [0, 3, 1, 2],
    [1, 0, 2, 3],
    [1, 0, 3, 2],
    [1, 2, 0, 3],
    [1, 2, 3, 0],
    [1, 3, 2, 0],
    [1, 3, 0, 2],
    [2, 1, 0, 3],
    [2, 1, 3, 0],
    [2, 0, 1, 3],
    [2, 0, 3, 1],
    [2, 3, 0, 1],
    [2, 3, 1, 0],
    [3, 1, 2, 0],
    [3, 1, 0, 2],
    [3, 2, 1, 0],
    [3, 2, 0, 1],
    [3, 0, 2, 1],
    [3, 0, 1, 2],
];

/// Interleaves the bits of `x` (even positions) and `y` (odd positions).
fn morton_2d(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0xffff_ffff;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    }
    spread(x) | (spread(y) << 1)
}

/// The Z-Sobol sampler (Ahmed and Wonka 2020, "Screen-Space Blue-Noise
/// Diffusion of Monte Carlo Sampling Error via Hierarchical Ordering of
/// Pixels"; pbrt-v4 section 8.7.7). Pixel `p` owns the block of `2^L >= spp`
/// consecutive indices starting at `morton(p) 2^L`, so every aligned 2x2
/// group of pixels owns an aligned block of the (0,2)-sequence and their
/// samples together form a finer net: their errors partly cancel, which
/// pushes the image error to high frequencies. Each base-4 digit of the
/// index is randomly permuted by a hash of the digits above it and the
/// dimension (a nested scramble of the index), which randomises the order
/// without breaking the blocks. Every dimension pair is Sobol' dimensions
/// 0 and 1 (padding), Owen-scrambled per dimension.
#[derive(Debug, Clone)]
pub struct ZSobolSampler {
    spp: u32,
    /// `L = ceil(log2 spp)`: index bits per pixel.
    log2_block: u32,
    owen: bool,
    seed_key: u64,
    morton_index: u64,
    dimension: DimensionCursor,
    /// Per dimension, the permuted index bits above the sample bits: they
    /// depend only on the pixel, so each pixel hashes them once.
    pixel_bits: Vec<u64>,
    pixel_key: Option<(UVec2, u64)>,
}

impl ZSobolSampler {
    pub fn new(spp: u32, owen: bool) -> Self {
        Self {
            spp,
            log2_block: spp.next_power_of_two().trailing_zeros(),
            owen,
            seed_key: 0,
            morton_index: 0,
            dimension: DimensionCursor::default(),
            pixel_bits: Vec::new(),
            pixel_key: None,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = ZSobolParams::read(params)?;
        let owen = match p.randomize {
            ZSobolRandomize::Owen => true,
            ZSobolRandomize::None => false,
        };
        Ok(Self::new(p.spp.checked(params)?, owen))
    }

    /// Permutes the base-4 digit of `self.morton_index` at bit `shift`,
    /// choosing the permutation from the digits above it.
    fn permuted_digit(&self, shift: u32, dimension: u32) -> u64 {
        let digit = (self.morton_index >> shift) & 3;
        let higher = self.morton_index >> (shift + 2);
        let p = (hash_with(higher ^ self.seed_key, dimension as u64) >> 40) % 24;
        PERMUTATIONS[p as usize][digit as usize] as u64
    }

    /// Base-4 digits start at bit `odd` (an odd `L` leaves a lone base-2
    /// digit at bit 0).
    fn digit_shifts(&self, range: std::ops::Range<u32>) -> impl Iterator<Item = u32> {
        let odd = self.log2_block & 1;
        range.map(move |j| odd + 2 * j)
    }

    /// The permuted index bits at and above bit `L`, for `dimension`.
    fn permuted_pixel_bits(&mut self, dimension: u32) -> u64 {
        let d = dimension as usize;
        while self.pixel_bits.len() <= d {
            let dim = self.pixel_bits.len() as u32;
            let first = self.log2_block / 2;
            let digits = PIXEL_BITS + first;
            let bits = if self.owen {
                self.digit_shifts(first..digits)
                    .map(|shift| self.permuted_digit(shift, dim) << shift)
                    .fold(0, |a, b| a | b)
            } else {
                self.morton_index >> self.log2_block << self.log2_block
            };
            self.pixel_bits.push(bits);
        }
        self.pixel_bits[d]
    }

    /// The sequence index of the current sample in `dimension`.
    fn sample_index(&mut self, dimension: u32) -> u64 {
        let high = self.permuted_pixel_bits(dimension);
        if !self.owen {
            return self.morton_index;
        }
        let mut low = self
            .digit_shifts(0..self.log2_block / 2)
            .map(|shift| self.permuted_digit(shift, dimension) << shift)
            .fold(0, |a, b| a | b);
        if self.log2_block & 1 == 1 {
            let flip = hash_with((self.morton_index >> 1) ^ self.seed_key, dimension as u64) >> 63;
            low |= (self.morton_index & 1) ^ flip;
        }
        high | low
    }

    fn sample_2d(&mut self, dimension: u32) -> Vec2 {
        // Bits past 32 only move points below 2^-32: the 32-bit index keeps
        // every block intact.
        let index = self.sample_index(dimension) as u32;
        // Scrambled and converted in the bit-reversed domain, where the
        // Sobol' columns are stored: no bit reversal on the way.
        let coordinate = |component: usize| {
            let reversed = sobol_reversed_u32(index, component);
            if self.owen {
                let seed = hash_with(self.seed_key, 2 * dimension as u64 + component as u64);
                reversed_to_unit_f32(laine_karras_permutation(reversed, seed as u32))
            } else {
                reversed_to_unit_f32(reversed)
            }
        };
        Vec2::new(coordinate(0), coordinate(1))
    }
}

impl Sampler for ZSobolSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        let mask = (1 << PIXEL_BITS) - 1;
        if self.pixel_key != Some((pixel, seed)) {
            self.pixel_key = Some((pixel, seed));
            self.pixel_bits.clear();
        }
        self.seed_key = hash_u64(seed);
        self.morton_index = (morton_2d(pixel.x & mask, pixel.y & mask) << self.log2_block)
            | (index as u64 & ((1 << self.log2_block) - 1));
        self.dimension = DimensionCursor::START;
    }

    fn get_1d(&mut self) -> f32 {
        let d = self.dimension.take(1);
        self.sample_2d(d).x
    }

    fn get_2d(&mut self) -> Vec2 {
        let d = self.dimension.take(2);
        self.sample_2d(d)
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.sample_2d(0)
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    /// Each pixel's power-of-two block of the sequence is a net.
    fn pixel_pattern(&self) -> PixelPattern {
        net_at_powers_of_two(self.spp)
    }

    fn randomized(&self) -> bool {
        self.owen
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net_check::is_02_net;

    fn pixel_points(s: &mut ZSobolSampler, pixel: UVec2, pair: usize) -> Vec<Vec2> {
        (0..s.spp)
            .map(|i| {
                s.start_pixel_sample(pixel, i, 3);
                let mut p = s.get_pixel_2d();
                for _ in 0..pair {
                    p = s.get_2d();
                }
                p
            })
            .collect()
    }

    #[test]
    fn morton_interleaves() {
        assert_eq!(morton_2d(0b11, 0), 0b0101);
        assert_eq!(morton_2d(0, 0b11), 0b1010);
        assert_eq!(morton_2d(5, 9), 0b1001_0011);
    }

    /// A pixel's samples are an aligned block of the sequence, so a
    /// (0,m,2)-net; an aligned 2x2 group of pixels together forms a
    /// (0,m+2,2)-net, which is the blue-noise mechanism.
    #[test]
    fn pixels_and_pixel_quads_are_nets() {
        for (spp, m) in [(16u32, 4u32), (32, 5), (8, 3)] {
            for owen in [true, false] {
                let mut s = ZSobolSampler::new(spp, owen);
                for pair in [0, 3] {
                    let mut quad = Vec::new();
                    for (x, y) in [(6u32, 10u32), (7, 10), (6, 11), (7, 11)] {
                        let points = pixel_points(&mut s, UVec2::new(x, y), pair);
                        assert!(is_02_net(&points, m), "spp {spp} owen {owen} pixel {x},{y}");
                        quad.extend(points);
                    }
                    assert!(is_02_net(&quad, m + 2), "spp {spp} owen {owen} quad");
                }
            }
        }
    }

    #[test]
    fn neighbouring_pixels_get_different_points() {
        let mut s = ZSobolSampler::new(16, true);
        let a = pixel_points(&mut s, UVec2::new(6, 10), 1);
        let b = pixel_points(&mut s, UVec2::new(7, 10), 1);
        assert_ne!(a, b);
    }
}
