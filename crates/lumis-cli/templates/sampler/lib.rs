//! `{{plugin}}`: jittered stratified sampling (Shirley 1991; pbrt-v4
//! `StratifiedSampler`).
//!
//! With `strata = n` a pixel takes `spp = n^2` samples. Each 2D dimension
//! pair is an `n x n` grid of strata and each 1D dimension has `n^2`
//! strata; sample `i` takes one stratum of each and a uniform point inside
//! it, so every stratum holds exactly one of the pixel's samples. Which
//! stratum sample `i` takes in dimension `d` is a random permutation of the
//! strata, drawn per (pixel, dimension, seed): without it sample `i` would
//! sit in the same stratum in every dimension, and the dimensions of a path
//! would be correlated ("padding", pbrt-v4 section 8.5).

use lumis_api::{
    Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Registrar, Result, Sampler, UVec2,
    Vec2,
};
use lumis_sampling::{
    hash_u64, hash_with, permutation_element, pixel_key, Pcg32, ONE_MINUS_EPSILON,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "{{plugin}}",
    source: lumis_api::source_file!(),
    doc: "jittered stratification: strata^2 samples per pixel, an n x n grid in each 2D dimension pair, strata permuted per pixel and dimension",
    params: JitteredParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct JitteredParams {
    /// strata per axis n, in [1, 1024]: n^2 samples per pixel
    #[param(default = 4)]
    pub strata: u32,
}

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_sampler(SPEC, |params| {
        Ok(Box::new(JitteredSampler::from_params(params)?))
    })
}

lumis_api::lumis_plugin!(register);

/// The largest `strata`, so that `strata^2` samples stay well within `u32`.
pub const MAX_STRATA: u32 = 1024;

#[derive(Debug, Clone)]
pub struct JitteredSampler {
    strata: u32,
    spp: u32,
    /// The pixel and seed, hashed: the permutations' key.
    key: u64,
    index: u32,
    dimension: u32,
    rng: Pcg32,
}

impl JitteredSampler {
    pub fn new(strata: u32) -> Self {
        Self {
            strata,
            spp: strata * strata,
            key: 0,
            index: 0,
            dimension: 0,
            rng: Pcg32::new(0, 0),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = JitteredParams::read(params)?;
        if !(1..=MAX_STRATA).contains(&p.strata) {
            return Err(params.error(
                JitteredParams::KEYS.strata,
                format!("must be in [1, {MAX_STRATA}], got {}", p.strata),
            ));
        }
        Ok(Self::new(p.strata))
    }

    /// The stratum the current sample takes in `dimension`.
    fn stratum(&self, dimension: u32) -> u32 {
        let seed = hash_with(self.key, u64::from(dimension)) as u32;
        permutation_element(self.index, self.spp, seed)
    }

    /// A uniform point in the cell `stratum` of the `n x n` grid.
    fn jittered_2d(&mut self, dimension: u32) -> Vec2 {
        let stratum = self.stratum(dimension);
        let (x, y) = (stratum % self.strata, stratum / self.strata);
        let n = self.strata as f32;
        Vec2::new(
            ((x as f32 + self.rng.next_f32()) / n).min(ONE_MINUS_EPSILON),
            ((y as f32 + self.rng.next_f32()) / n).min(ONE_MINUS_EPSILON),
        )
    }
}

impl Sampler for JitteredSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.key = pixel_key(pixel.x, pixel.y, seed);
        self.index = index % self.spp;
        // Dimensions 0 and 1 are the pixel's own (`get_pixel_2d`).
        self.dimension = 2;
        self.rng = Pcg32::new(hash_u64(self.key ^ hash_u64(u64::from(index))), self.key);
    }

    fn get_1d(&mut self) -> f32 {
        let stratum = self.stratum(self.dimension);
        self.dimension += 1;
        ((stratum as f32 + self.rng.next_f32()) / self.spp as f32).min(ONE_MINUS_EPSILON)
    }

    fn get_2d(&mut self) -> Vec2 {
        let dimension = self.dimension;
        self.dimension += 2;
        self.jittered_2d(dimension)
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.jittered_2d(0)
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    /// What `lumis check-plugin` holds the film positions of every pixel
    /// to, exactly: one in each cell of the `n x n` grid.
    fn pixel_pattern(&self) -> PixelPattern {
        PixelPattern::Grid {
            nx: self.strata,
            ny: self.strata,
        }
    }
}
