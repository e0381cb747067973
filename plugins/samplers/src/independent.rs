//! `independent`: uniform random numbers, no stratification.
//!
//! The numbers come from PCG32 (lumis's own implementation, checked against
//! the reference output of pcg-c-basic), one generator per (pixel, sample
//! index, seed), seeded by splitmix64 hashes. It is the baseline the other
//! samplers are measured against; [Samplers](studies/samplers.md) measures
//! what each buys.

use lumis_api::{
    ConcreteLanes, Params, PluginKind, PluginParams, PluginSpec, Result, Sampler, SamplerLanes,
    UVec2, Vec2,
};
use lumis_sampling::{hash_u64, pixel_key, Pcg32};

use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "independent",
    source: lumis_api::source_file!(),
    doc: "uniform random samples (PCG32, one stream per pixel); the baseline every other sampler is measured against",
    params: SppParams::SPECS,
};

/// Uniform random samples from PCG32. Each (pixel, sample index, seed)
/// seeds its own generator: the pixel and seed pick the stream, and the
/// hashed sample index the starting state, so any sample of any pixel is
/// reproducible on any thread. (pbrt-v4 instead jumps `index * 65536`
/// steps ahead in one stream; seeding costs two PCG steps instead of a
/// logarithmic jump.)
#[derive(Debug, Clone)]
pub struct IndependentSampler {
    spp: u32,
    rng: Pcg32,
}

impl IndependentSampler {
    pub fn new(spp: u32) -> Self {
        Self {
            spp,
            rng: Pcg32::new(0, 0),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        Ok(Self::new(SppParams::read(params)?.checked(params)?))
    }
}

impl Sampler for IndependentSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        let stream = pixel_key(pixel.x, pixel.y, seed);
        self.rng = Pcg32::new(hash_u64(stream ^ hash_u64(index as u64)), stream);
    }

    #[inline]
    fn get_1d(&mut self) -> f32 {
        self.rng.next_f32()
    }

    #[inline]
    fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.next_f32();
        Vec2::new(x, self.rng.next_f32())
    }

    #[inline]
    fn get_pixel_2d(&mut self) -> Vec2 {
        self.get_2d()
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn first(s: &mut IndependentSampler, pixel: UVec2, index: u32, seed: u64) -> [f32; 4] {
        s.start_pixel_sample(pixel, index, seed);
        [s.get_1d(), s.get_1d(), s.get_1d(), s.get_1d()]
    }

    #[test]
    fn deterministic_per_pixel_index_and_seed() {
        let mut a = IndependentSampler::new(4);
        let mut b = IndependentSampler::new(4);
        let p = UVec2::new(3, 7);
        // Same triple, same numbers, whatever was drawn before.
        let x = first(&mut a, p, 2, 9);
        first(&mut b, UVec2::new(0, 0), 0, 0);
        assert_eq!(x, first(&mut b, p, 2, 9));
        assert_ne!(x, first(&mut b, p, 3, 9));
        assert_ne!(x, first(&mut b, p, 2, 10));
        assert_ne!(x, first(&mut b, UVec2::new(7, 3), 2, 9));
    }

    #[test]
    fn neighbouring_pixels_are_uncorrelated() {
        // Correlation of the first dimension across horizontally adjacent
        // pixels: for independent streams it is ~N(0, 1/n).
        let mut s = IndependentSampler::new(1);
        let n = 20_000u32;
        let mut xs = Vec::with_capacity(n as usize + 1);
        for x in 0..=n {
            s.start_pixel_sample(UVec2::new(x, 5), 0, 1);
            xs.push(s.get_1d() as f64 - 0.5);
        }
        let cov: f64 = xs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / n as f64;
        let corr = cov / (1.0 / 12.0);
        assert!(corr.abs() < 4.0 / (n as f64).sqrt(), "{corr}");
    }
}
