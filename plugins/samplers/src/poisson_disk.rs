//! `poisson-disk`: Poisson disk patterns for the film plane.
//!
//! Film-plane positions come from a pool of toroidal dart-throwing patterns,
//! one picked and randomly shifted per pixel; the other dimensions are
//! independent. A `min_distance` too large to place `spp` points is an error
//! that names the largest usable one.

use lumis_api::{
    ConcreteLanes, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result, Sampler,
    SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::poisson_disk::{max_packing_distance, poisson_disk_pattern};
use lumis_sampling::{hash_u64, pixel_key, Pcg32};

use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "poisson-disk",
    source: lumis_api::source_file!(),
    doc: "film-plane positions from toroidal Poisson disk patterns (dart throwing), randomly chosen and shifted per pixel; other dimensions independent",
    params: PoissonDiskParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct PoissonDiskParams {
    #[param(flatten)]
    pub spp: SppParams,
    /// minimum distance between a pixel's samples, in pixels (default 0.7 x
    /// the hexagonal packing distance sqrt(2 / (sqrt(3) spp)))
    pub min_distance: Option<f32>,
}

/// Relative radius used when `min_distance` is not given: dart throwing
/// saturates near 0.77 (Lagae and Dutre 2008), 0.7 still fills reliably.
pub const DEFAULT_RELATIVE_DISTANCE: f32 = 0.7;

/// Total points of the precomputed patterns (so large spp gets fewer).
const PATTERN_POINT_BUDGET: usize = 1 << 20;
const MAX_PATTERNS: usize = 64;

/// Film-plane samples from a pool of Poisson disk patterns on the torus
/// (Cook 1986; Mitchell 1987 for why blue noise hides aliasing). Each pixel
/// and seed picks a pattern and a random toroidal shift (which keeps the
/// minimum distance), so pixels are independent and the estimate unbiased.
/// Sample `i` is the `i`-th accepted dart. Dimensions past the film plane
/// are independent uniform numbers (PCG32, as `independent`): Poisson disk
/// sampling has no good high-dimensional form.
#[derive(Debug, Clone)]
pub struct PoissonDiskSampler {
    spp: u32,
    min_distance: f32,
    patterns: std::sync::Arc<Vec<Vec<Vec2>>>,
    pixel_point: Vec2,
    rng: Pcg32,
}

impl PoissonDiskSampler {
    /// Precomputes the patterns; `None` if `min_distance` is too large for
    /// `spp` points.
    pub fn new(spp: u32, min_distance: f32) -> Option<Self> {
        let count = (PATTERN_POINT_BUDGET / spp as usize).clamp(1, MAX_PATTERNS);
        let patterns = (0..count as u64)
            .map(|k| poisson_disk_pattern(spp as usize, min_distance, &mut Pcg32::new(k, 0x5eed)))
            .collect::<Option<Vec<_>>>()?;
        Some(Self {
            spp,
            min_distance,
            patterns: std::sync::Arc::new(patterns),
            pixel_point: Vec2::ZERO,
            rng: Pcg32::new(0, 0),
        })
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = PoissonDiskParams::read(params)?;
        let key = PoissonDiskParams::KEYS.min_distance;
        let spp = p.spp.checked(params)?;
        let packing = max_packing_distance(spp as usize);
        let min_distance = match p.min_distance {
            Some(d) if !(d >= 0.0 && d.is_finite()) => {
                return Err(params.error(key, format!("must be >= 0, got {d}")))
            }
            Some(d) => d,
            None => DEFAULT_RELATIVE_DISTANCE * packing,
        };
        Self::new(spp, min_distance).ok_or_else(|| {
            params.error(
                key,
                format!(
                    "{min_distance} is too large for {spp} samples per pixel: dart throwing \
                     cannot place them; use at most about {:.4} (0.75 x the densest packing \
                     distance {packing:.4})",
                    0.75 * packing
                ),
            )
        })
    }

    pub fn min_distance(&self) -> f32 {
        self.min_distance
    }
}

impl Sampler for PoissonDiskSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        let key = pixel_key(pixel.x, pixel.y, seed);
        let choice = hash_u64(key);
        let pattern = &self.patterns[(choice % self.patterns.len() as u64) as usize];
        let mut shift_rng = Pcg32::new(choice, key);
        let shift = Vec2::new(shift_rng.next_f32(), shift_rng.next_f32());
        let p = pattern[(index % self.spp) as usize] + shift;
        self.pixel_point = p - p.floor();
        self.rng = Pcg32::new(hash_u64(key ^ hash_u64(index as u64)), key);
    }

    fn get_1d(&mut self) -> f32 {
        self.rng.next_f32()
    }

    fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.next_f32();
        Vec2::new(x, self.rng.next_f32())
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        // `p - floor(p)` can round to 1.0 for p just below an integer.
        self.pixel_point
            .min(Vec2::splat(lumis_sampling::ONE_MINUS_EPSILON))
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    fn pixel_pattern(&self) -> PixelPattern {
        PixelPattern::MinDistance(self.min_distance)
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_samples_keep_their_distance_on_the_torus() {
        let spp = 64;
        let r = 0.7 * max_packing_distance(spp);
        let mut s = PoissonDiskSampler::new(spp as u32, r).unwrap();
        let points: Vec<Vec2> = (0..spp as u32)
            .map(|i| {
                s.start_pixel_sample(UVec2::new(4, 2), i, 9);
                s.get_pixel_2d()
            })
            .collect();
        for (i, p) in points.iter().enumerate() {
            for q in &points[i + 1..] {
                let d = (*p - *q).abs();
                assert!(d.min(Vec2::ONE - d).length() >= r * 0.9999);
            }
        }
    }
}
