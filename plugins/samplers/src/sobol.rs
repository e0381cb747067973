//! `sobol`: the Sobol' sequence per pixel, Owen-scrambled.

use lumis_core::{
    ParamSpec, ParamType, Params, PluginKind, PluginSpec, Result, Sampler, UVec2, Vec2,
};
use lumis_sampling::{
    fixed_to_unit_f32, hash_with, owen_scramble, owen_scramble_reversed, pixel_key,
    sobol_reversed_pair, sobol_reversed_u32, xor_scramble, SOBOL_DIMENSIONS,
};

use crate::spp::{read_spp, SPP_PARAM};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "sobol",
    doc: "Sobol' points per pixel (the (0,2)-sequence in the film plane, Joe-Kuo dimensions beyond), Owen-scrambled per pixel; progressive: every power-of-two prefix is a (0,m,2)-net",
    params: &[
        SPP_PARAM,
        ParamSpec::with_default(
            "randomize",
            ParamType::String,
            "\"owen\"",
            "owen (nested uniform scrambling), xor (random digital shift) or none (the same points in every pixel)",
        )
        .one_of(&["owen", "xor", "none"]),
        ParamSpec::with_default(
            "dimensions",
            ParamType::String,
            "\"sobol\"",
            "sobol: dimension d is Sobol' dimension d; padded: every 1D/2D request is a shuffled (0,2)-sequence (Burley 2020)",
        )
        .one_of(&["sobol", "padded"]),
    ],
};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Randomize {
    Owen,
    Xor,
    None,
}

/// Which Sobol' dimensions serve dimensions past the film plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimensions {
    /// Sampler dimension `d` is Sobol' dimension `d` (Joe-Kuo matrices);
    /// past 1024 they wrap around with fresh scrambles.
    Sobol,
    /// Every request is dimensions 0 (and 1) of the sequence, with the
    /// sample index Owen-scrambled per request so requests decorrelate while
    /// each stays a (0,2)-sequence (Burley 2020, "Practical Hash-based Owen
    /// Scrambling", section 4, "shuffled scrambled Sobol'").
    Padded,
}

/// Sobol' sampling in the style of pbrt-v4's `PaddedSobolSampler` and
/// `SobolSampler`, per pixel: sample `i` of a pixel is Sobol' point `i`, each
/// dimension scrambled with a seed from (pixel, dimension, seed). Owen
/// scrambling is what makes it unbiased and decorrelates pixels; it keeps the
/// (0,m,2)-net property of every aligned power-of-two block, so any prefix of
/// 2^m samples is as well stratified as the full set.
#[derive(Debug, Clone)]
pub struct SobolSampler {
    spp: u32,
    randomize: Randomize,
    dimensions: Dimensions,
    key: u64,
    index: u32,
    dimension: u32,
    /// Scramble seeds of the current pixel, per dimension, filled lazily:
    /// a pixel's samples are drawn one after another, so each seed is
    /// hashed once per pixel rather than once per sample.
    seeds: Vec<u32>,
}

impl SobolSampler {
    pub fn new(spp: u32, randomize: Randomize, dimensions: Dimensions) -> Self {
        Self {
            spp,
            randomize,
            dimensions,
            key: 0,
            index: 0,
            dimension: 0,
            seeds: Vec::new(),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let randomize = match params.get_choice("randomize")?.as_str() {
            "owen" => Randomize::Owen,
            "xor" => Randomize::Xor,
            _ => Randomize::None,
        };
        let dimensions = match params.get_choice("dimensions")?.as_str() {
            "padded" => Dimensions::Padded,
            _ => Dimensions::Sobol,
        };
        Ok(Self::new(read_spp(params)?, randomize, dimensions))
    }

    /// The scramble seed of a dimension (salt 0) or of its index shuffle
    /// (salt 1).
    fn seed(&self, dimension: u32, salt: u64) -> u32 {
        hash_with(self.key, ((dimension as u64) << 2) | salt) as u32
    }

    /// The scramble seed of sampler dimension `dimension`, hashed once per
    /// pixel: the cached fast path stays small enough to inline.
    #[inline(always)]
    fn scramble_seed(&mut self, dimension: u32) -> u32 {
        match self.seeds.get(dimension as usize) {
            Some(&seed) => seed,
            None => self.fill_seeds(dimension),
        }
    }

    #[cold]
    #[inline(never)]
    fn fill_seeds(&mut self, dimension: u32) -> u32 {
        while self.seeds.len() <= dimension as usize {
            let seed = self.seed(self.seeds.len() as u32, 0);
            self.seeds.push(seed);
        }
        self.seeds[dimension as usize]
    }

    /// The sample index a request starting at `dimension` uses: shuffled per
    /// request in padded mode (an Owen scramble of the index is a nested
    /// permutation, so aligned power-of-two blocks map onto themselves).
    #[inline(always)]
    fn index_for(&self, dimension: u32) -> u32 {
        match (self.dimensions, self.randomize) {
            (Dimensions::Padded, Randomize::Owen | Randomize::Xor) if dimension >= 2 => {
                owen_scramble(self.index, self.seed(dimension, 1))
            }
            _ => self.index,
        }
    }

    /// The Sobol' dimension behind sampler dimension `d` (component `c` of
    /// a request that started at `start`).
    #[inline(always)]
    fn sobol_dimension(&self, start: u32, component: u32) -> usize {
        match self.dimensions {
            Dimensions::Sobol => (start + component) as usize % SOBOL_DIMENSIONS,
            Dimensions::Padded => component as usize,
        }
    }

    /// A bit-reversed Sobol' coordinate, randomised with `seed`, as a float.
    #[inline(always)]
    fn randomized(&self, reversed: u32, seed: u32) -> f32 {
        fixed_to_unit_f32(match self.randomize {
            Randomize::Owen => owen_scramble_reversed(reversed, seed),
            Randomize::Xor => xor_scramble(reversed.reverse_bits(), seed),
            Randomize::None => reversed.reverse_bits(),
        })
    }

    #[inline(always)]
    fn sample_1d(&mut self, start: u32) -> f32 {
        let index = self.index_for(start);
        let reversed = sobol_reversed_u32(index, self.sobol_dimension(start, 0));
        let seed = self.scramble_seed(start);
        self.randomized(reversed, seed)
    }

    /// Both components of a 2D request: one index, one pass over its bits.
    #[inline(always)]
    fn sample_2d(&mut self, start: u32) -> Vec2 {
        let index = self.index_for(start);
        let dims = [
            self.sobol_dimension(start, 0),
            self.sobol_dimension(start, 1),
        ];
        let [r0, r1] = sobol_reversed_pair(index, dims);
        // Filling the cache up to `start + 1` fills `start` too.
        let seed1 = self.scramble_seed(start + 1);
        let seed0 = self.seeds[start as usize];
        Vec2::new(self.randomized(r0, seed0), self.randomized(r1, seed1))
    }
}

impl Sampler for SobolSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        let key = pixel_key(pixel.x, pixel.y, seed);
        if key != self.key || self.seeds.is_empty() {
            self.key = key;
            self.seeds.clear();
        }
        self.index = index;
        self.dimension = 2;
    }

    fn get_1d(&mut self) -> f32 {
        let d = self.dimension;
        self.dimension += 1;
        self.sample_1d(d)
    }

    fn get_2d(&mut self) -> Vec2 {
        let d = self.dimension;
        self.dimension += 2;
        self.sample_2d(d)
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.sample_2d(0)
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net_check::is_02_net;

    fn pairs(s: &mut SobolSampler, n: u32, skip_pairs: usize, seed: u64) -> Vec<Vec2> {
        (0..n)
            .map(|i| {
                s.start_pixel_sample(UVec2::new(17, 3), i, seed);
                let mut p = s.get_pixel_2d();
                for _ in 0..skip_pairs {
                    p = s.get_2d();
                }
                p
            })
            .collect()
    }

    /// The film-plane samples of every power-of-two prefix, up to 2^14,
    /// form a (0,m,2)-net for every randomisation; in padded mode so does
    /// every later dimension pair (each is a shuffled (0,2)-sequence).
    #[test]
    fn power_of_two_prefixes_are_02_nets() {
        let max = 1u32 << 14;
        for randomize in [Randomize::None, Randomize::Xor, Randomize::Owen] {
            for (dimensions, skip) in [(Dimensions::Sobol, 0), (Dimensions::Padded, 3)] {
                let mut s = SobolSampler::new(max, randomize, dimensions);
                let points = pairs(&mut s, max, skip, 5);
                for m in [0u32, 1, 2, 5, 8, 11, 14] {
                    assert!(
                        is_02_net(&points[..1 << m], m),
                        "{randomize:?} {dimensions:?} m {m}"
                    );
                }
            }
        }
    }

    #[test]
    fn seeds_and_pixels_change_the_points() {
        let mut s = SobolSampler::new(16, Randomize::Owen, Dimensions::Sobol);
        let a = pairs(&mut s, 4, 1, 1);
        assert_ne!(a, pairs(&mut s, 4, 1, 2));
        let mut t = SobolSampler::new(16, Randomize::None, Dimensions::Sobol);
        assert_eq!(pairs(&mut t, 4, 1, 1), pairs(&mut t, 4, 1, 2));
    }
}
