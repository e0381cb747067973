//! `stratified`: jittered strata in every dimension pair, decorrelated
//! across dimensions by per-pixel random permutations (padding).
//!
//! Each 1D dimension has `spp` strata and each 2D pair an `nx x ny = spp`
//! grid, `nx` the largest divisor of `spp` not above its square root (32
//! gives 4 x 8; a prime `spp` gives 1 x `spp` strips, stratified along one
//! axis only). Each dimension gets its own per-pixel random permutation of
//! the strata (Kensler's hash permutation), so high dimensions stay
//! stratified and uncorrelated.

use lumis_api::{
    ConcreteLanes, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result, Sampler,
    SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::{
    hash_u64, hash_with, permutation_element, pixel_key, Pcg32, ONE_MINUS_EPSILON,
};

use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "stratified",
    source: lumis_api::source_file!(),
    doc: "jittered stratification: spp strata in 1D, an nx x ny grid (nx the largest divisor of spp <= sqrt(spp)) in 2D; dimensions padded by per-pixel permutations",
    params: StratifiedParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct StratifiedParams {
    #[param(flatten)]
    pub spp: SppParams,
    /// a random point in each stratum (false: its centre, which aliases)
    #[param(default = true)]
    pub jitter: bool,
}

/// Stratified sampling with padding (pbrt-v4 `StratifiedSampler`; Shirley
/// 1991, "Discrepancy as a Quality Measure for Sample Distributions").
///
/// Every 1D dimension has `spp` strata and every 2D dimension pair an
/// `nx x ny = spp` grid. Sample `i` of a pixel takes stratum `pi_d(i)` in
/// dimension `d`, with `pi_d` a random permutation per (pixel, dimension,
/// seed): without it, sample `i` would sit in the same stratum in every
/// dimension and the dimensions would be perfectly correlated.
///
/// When `spp` is not a perfect square the 2D grid is the factorisation
/// closest to square: 32 -> 4 x 8 strata (each 1/4 wide, 1/8 tall); a prime
/// `spp` gives 1 x spp strips, stratified along one axis only.
#[derive(Debug, Clone)]
pub struct StratifiedSampler {
    spp: u32,
    nx: u32,
    ny: u32,
    jitter: bool,
    key: u64,
    index: u32,
    dimension: u32,
    rng: Pcg32,
}

/// The factorisation `spp = nx * ny` with `nx <= ny` closest to square.
pub fn strata_grid(spp: u32) -> (u32, u32) {
    let mut nx = (spp as f64).sqrt() as u32;
    while nx > 1 && !spp.is_multiple_of(nx) {
        nx -= 1;
    }
    let nx = nx.max(1);
    (nx, spp / nx)
}

impl StratifiedSampler {
    pub fn new(spp: u32, jitter: bool) -> Self {
        let (nx, ny) = strata_grid(spp);
        Self {
            spp,
            nx,
            ny,
            jitter,
            key: 0,
            index: 0,
            dimension: 0,
            rng: Pcg32::new(0, 0),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = StratifiedParams::read(params)?;
        Ok(Self::new(p.spp.checked(params)?, p.jitter))
    }

    /// The stratum sample `index` takes in `dimension`.
    fn stratum(&self, dimension: u32) -> u32 {
        let seed = hash_with(self.key, dimension as u64) as u32;
        permutation_element(self.index % self.spp, self.spp, seed)
    }

    fn offset(&mut self) -> f32 {
        if self.jitter {
            self.rng.next_f32()
        } else {
            0.5
        }
    }

    fn sample_2d(&mut self, dimension: u32) -> Vec2 {
        let stratum = self.stratum(dimension);
        let (x, y) = (stratum % self.nx, stratum / self.nx);
        let (dx, dy) = (self.offset(), self.offset());
        Vec2::new(
            ((x as f32 + dx) / self.nx as f32).min(ONE_MINUS_EPSILON),
            ((y as f32 + dy) / self.ny as f32).min(ONE_MINUS_EPSILON),
        )
    }
}

impl Sampler for StratifiedSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.key = pixel_key(pixel.x, pixel.y, seed);
        self.index = index;
        self.dimension = 2;
        self.rng = Pcg32::new(hash_u64(self.key ^ hash_u64(index as u64)), self.key);
    }

    fn get_1d(&mut self) -> f32 {
        let stratum = self.stratum(self.dimension);
        self.dimension += 1;
        let delta = self.offset();
        ((stratum as f32 + delta) / self.spp as f32).min(ONE_MINUS_EPSILON)
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

    fn pixel_pattern(&self) -> PixelPattern {
        PixelPattern::Grid {
            nx: self.nx,
            ny: self.ny,
        }
    }

    /// Without jitter every sample sits at its stratum's centre.
    fn randomized(&self) -> bool {
        self.jitter
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_is_closest_to_square() {
        assert_eq!(strata_grid(16), (4, 4));
        assert_eq!(strata_grid(32), (4, 8));
        assert_eq!(strata_grid(12), (3, 4));
        assert_eq!(strata_grid(7), (1, 7));
        assert_eq!(strata_grid(1), (1, 1));
    }

    /// Each 2D stratum of each dimension pair, and each 1D stratum, holds
    /// exactly one of the pixel's samples.
    #[test]
    fn every_stratum_holds_one_sample_per_dimension() {
        for spp in [1u32, 7, 16, 32, 64] {
            let (nx, ny) = strata_grid(spp);
            let mut s = StratifiedSampler::new(spp, true);
            let pixel = UVec2::new(5, 9);
            let mut cells_2d = vec![vec![0u32; spp as usize]; 3];
            let mut cells_1d = vec![vec![0u32; spp as usize]; 2];
            for i in 0..spp {
                s.start_pixel_sample(pixel, i, 3);
                let pairs = [s.get_pixel_2d(), s.get_2d(), {
                    let _ = s.get_1d();
                    s.get_2d()
                }];
                for (d, p) in pairs.iter().enumerate() {
                    let cell = (p.y * ny as f32) as u32 * nx + (p.x * nx as f32) as u32;
                    cells_2d[d][cell as usize] += 1;
                }
                for cells in cells_1d.iter_mut() {
                    cells[(s.get_1d() * spp as f32) as usize] += 1;
                }
            }
            for cells in cells_2d.iter().chain(&cells_1d) {
                assert!(cells.iter().all(|&c| c == 1), "spp {spp}: {cells:?}");
            }
        }
    }

    #[test]
    fn dimensions_are_decorrelated() {
        // Without padding, dims 2 and 3 of sample i would sit in the same
        // stratum. Correlation of two 1D dimensions over many pixels:
        // ~N(0, 1/n) when decorrelated.
        let spp = 16;
        let mut s = StratifiedSampler::new(spp, true);
        let (mut sum, mut n) = (0.0f64, 0.0f64);
        for px in 0..400 {
            for i in 0..spp {
                s.start_pixel_sample(UVec2::new(px, 0), i, 1);
                let (a, b) = (s.get_1d() as f64 - 0.5, s.get_1d() as f64 - 0.5);
                sum += a * b;
                n += 1.0;
            }
        }
        let corr = sum / n * 12.0;
        assert!(corr.abs() < 4.0 / n.sqrt(), "{corr}");
    }
}
