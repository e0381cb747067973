//! `sobol`: the Sobol' sequence per pixel, Owen-scrambled.
//!
//! The film plane takes the (0,2)-sequence and the dimensions beyond take
//! Joe and Kuo's direction numbers (1024 dimensions, then wrap); every
//! dimension is Owen-scrambled per pixel with Burley's hash (2020), so every
//! power-of-two prefix of a pixel's samples is a (0,m,2)-net.
//! `dimensions = "padded"` serves every request from the first two
//! dimensions with an Owen-shuffled index (Burley 2020).

use std::fmt;
use std::marker::PhantomData;

use lumis_api::{
    ConcreteLanes, ParamChoice, Params, PixelPattern, PluginKind, PluginParams, PluginSpec, Result,
    Sampler, SamplerLanes, UVec2, Vec2,
};
use lumis_sampling::{
    hash_with, laine_karras_permutation, owen_scramble, pixel_key, reversed_to_unit_f32,
    sobol_reversed_run, sobol_reversed_tabulated, xor_scramble, SOBOL_DIMENSIONS,
};

use crate::dimensions::{net_at_powers_of_two, DimensionCursor};
use crate::spp::SppParams;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Sampler,
    name: "sobol",
    source: lumis_api::source_file!(),
    doc: "Sobol' points per pixel (the (0,2)-sequence in the film plane, Joe-Kuo dimensions beyond), Owen-scrambled per pixel; progressive: every power-of-two prefix is a (0,m,2)-net",
    params: SobolParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct SobolParams {
    #[param(flatten)]
    pub spp: SppParams,
    /// owen (nested uniform scrambling), xor (random digital shift) or none
    /// (the same points in every pixel)
    #[param(default = Owen)]
    pub randomize: Randomize,
    /// sobol: dimension d is Sobol' dimension d; padded: every 1D/2D request
    /// is a shuffled (0,2)-sequence (Burley 2020)
    #[param(default = Sobol)]
    pub dimensions: Dimensions,
}

/// The `randomize` parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Randomize {
    Owen,
    Xor,
    None,
}

/// Which Sobol' dimensions serve dimensions past the film plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
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

/// How a Sobol' coordinate is randomised: a type parameter of
/// [`SobolSampler`], so the per-sample path has no branch on it.
pub trait Randomization: fmt::Debug + Clone + Send + Sync + 'static {
    /// Whether [`Self::apply`] reads its seed; seeds are not hashed otherwise.
    const SEEDED: bool;

    /// The randomised coordinate, both it and `reversed` bit-reversed
    /// (first digit in bit 0).
    fn apply(reversed: u32, seed: u32) -> u32;
}

/// Owen's nested uniform scrambling, hash-based (Burley 2020).
#[derive(Debug, Clone, Copy, Default)]
pub struct Owen;

impl Randomization for Owen {
    const SEEDED: bool = true;

    #[inline(always)]
    fn apply(reversed: u32, seed: u32) -> u32 {
        laine_karras_permutation(reversed, seed)
    }
}

/// A random digital shift. XOR by `seed` in the reversed domain is the
/// shift by `seed.reverse_bits()`, as uniform a shift as `seed` itself.
#[derive(Debug, Clone, Copy, Default)]
pub struct Xor;

impl Randomization for Xor {
    const SEEDED: bool = true;

    #[inline(always)]
    fn apply(reversed: u32, seed: u32) -> u32 {
        xor_scramble(reversed, seed)
    }
}

/// The bare sequence: the same points in every pixel.
#[derive(Debug, Clone, Copy, Default)]
pub struct Unrandomized;

impl Randomization for Unrandomized {
    const SEEDED: bool = false;

    #[inline(always)]
    fn apply(reversed: u32, _seed: u32) -> u32 {
        reversed
    }
}

/// Which Sobol' dimensions a request uses: a type parameter of
/// [`SobolSampler`], like [`Randomization`].
pub trait DimensionMapping: fmt::Debug + Clone + Send + Sync + 'static {
    /// Whether requests past the film plane shuffle the sample index.
    const SHUFFLED: bool;

    /// The unscrambled, bit-reversed Sobol' coordinates of point `index`
    /// for the `N` components of a request that starts at sampler dimension
    /// `start` (a 1D request takes one, a 2D request two).
    fn reversed_coordinates<const N: usize>(index: u32, start: u32) -> [u32; N];

    /// [`Self::reversed_coordinates`] where they are a read of the
    /// compile-time table of the first points, else `None`.
    fn tabulated_coordinates<const N: usize>(index: u32, start: u32) -> Option<[u32; N]>;
}

/// [`Dimensions::Sobol`]: consecutive sampler dimensions are consecutive
/// Sobol' dimensions, so a 1D request and the 2D request after it are three
/// consecutive coordinates of one point.
#[derive(Debug, Clone, Copy, Default)]
pub struct SobolOrder;

impl DimensionMapping for SobolOrder {
    const SHUFFLED: bool = false;

    #[inline(always)]
    fn reversed_coordinates<const N: usize>(index: u32, start: u32) -> [u32; N] {
        sobol_reversed_run(index, start as usize % SOBOL_DIMENSIONS)
    }

    #[inline(always)]
    fn tabulated_coordinates<const N: usize>(index: u32, start: u32) -> Option<[u32; N]> {
        sobol_reversed_tabulated(index, start as usize)
    }
}

/// [`Dimensions::Padded`].
#[derive(Debug, Clone, Copy, Default)]
pub struct Padded;

impl DimensionMapping for Padded {
    const SHUFFLED: bool = true;

    #[inline(always)]
    fn reversed_coordinates<const N: usize>(index: u32, _start: u32) -> [u32; N] {
        sobol_reversed_run(index, 0)
    }

    /// Never: each padded request shuffles its index first.
    #[inline(always)]
    fn tabulated_coordinates<const N: usize>(_index: u32, _start: u32) -> Option<[u32; N]> {
        None
    }
}

/// Request dimensions whose seed hashes a pixel caches: one bit each in a
/// `u64`, enough for the camera and seven vertices of a path tracer's
/// requests.
const SEED_CACHE: usize = 64;

/// Sobol' sampling in the style of pbrt-v4's `PaddedSobolSampler` and
/// `SobolSampler`, per pixel: sample `i` of a pixel is Sobol' point `i`, each
/// dimension scrambled with a seed from (pixel, dimension, seed). Owen
/// scrambling is what makes it unbiased and decorrelates pixels; it keeps the
/// (0,m,2)-net property of every aligned power-of-two block, so any prefix of
/// 2^m samples is as well stratified as the full set.
///
/// Generic over the randomisation and the dimension mapping so each of the
/// six combinations compiles to its own straight-line code;
/// [`SobolSampler::boxed`] picks one at run time.
#[derive(Debug, Clone)]
pub struct SobolSampler<R = Owen, D = SobolOrder> {
    spp: u32,
    /// The (pixel, seed) that `key` was derived from.
    keyed: Option<(UVec2, u64)>,
    /// The pixel's key, hashed with each request's dimension into its seeds.
    key: u64,
    /// The seed hashes of this pixel's first [`SEED_CACHE`] request
    /// dimensions, valid where `cached` has the dimension's bit: a pixel's
    /// samples are drawn one after another and share their seeds, so at
    /// 64 spp each is hashed once instead of 64 times, and a new pixel costs
    /// one store to invalidate.
    seed_hashes: [u64; SEED_CACHE],
    cached: u64,
    index: u32,
    dimension: DimensionCursor,
    strategy: PhantomData<(R, D)>,
}

impl<R: Randomization, D: DimensionMapping> SobolSampler<R, D> {
    pub fn new(spp: u32) -> Self {
        Self {
            spp,
            keyed: None,
            key: 0,
            seed_hashes: [0; SEED_CACHE],
            cached: 0,
            index: 0,
            dimension: DimensionCursor::default(),
            strategy: PhantomData,
        }
    }

    /// The scramble seeds of the two components of the request starting at
    /// sampler dimension `start` (a 1D request uses the first): the halves of
    /// one 64-bit hash of (pixel key, start), as pbrt-v4's
    /// `PaddedSobolSampler::Get2D` does, cached for the pixel's later samples.
    /// Zero, and never hashed, for a randomisation that takes no seed.
    #[inline(always)]
    fn scramble_seeds(&mut self, start: u32) -> [u32; 2] {
        if !R::SEEDED {
            return [0, 0];
        }
        let h = self.seed_hash(start);
        [h as u32, (h >> 32) as u32]
    }

    /// The hash behind the seeds of the request at `start`: cached, or
    /// hashed now by the pixel's first sample to reach it.
    #[inline(always)]
    fn seed_hash(&mut self, start: u32) -> u64 {
        if start < SEED_CACHE as u32 && self.cached >> start & 1 != 0 {
            self.seed_hashes[start as usize]
        } else {
            self.hash_seeds(start)
        }
    }

    /// The seeds of a 1D request at `start` and the 2D request after it,
    /// where both are cached (one test of the two cache bits), else `None`.
    #[inline(always)]
    fn cached_seeds_1d_2d(&self, start: u32) -> Option<[u32; 3]> {
        if !R::SEEDED {
            return Some([0; 3]);
        }
        if start >= SEED_CACHE as u32 - 1 || self.cached >> start & 3 != 3 {
            return None;
        }
        let (h0, h1) = (
            self.seed_hashes[start as usize],
            self.seed_hashes[start as usize + 1],
        );
        Some([h0 as u32, h1 as u32, (h1 >> 32) as u32])
    }

    /// [`Self::cached_seeds_1d_2d`], hashing what is not cached yet.
    #[inline(always)]
    fn scramble_seeds_1d_2d(&mut self, start: u32) -> [u32; 3] {
        if let Some(seeds) = self.cached_seeds_1d_2d(start) {
            return seeds;
        }
        let (h0, h1) = (self.seed_hash(start), self.seed_hash(start.wrapping_add(1)));
        [h0 as u32, h1 as u32, (h1 >> 32) as u32]
    }

    /// The 1D+2D request at `d` in the common case: its point in the
    /// compile-time table and its seeds in the pixel's cache, else `None`.
    /// Kept apart from the general case (the loop over the index bits, the
    /// seed hashing), it needs fewer registers: the request saves three
    /// callee-saved ones instead of six (lumis 0.5-1% faster).
    #[inline(always)]
    fn tabulated_1d_2d(&self, d: u32) -> Option<(f32, Vec2)> {
        let reversed = D::tabulated_coordinates(self.index, d)?;
        let seeds = self.cached_seeds_1d_2d(d)?;
        Some(unit_1d_2d::<R>(reversed, seeds))
    }

    /// The 1D+2D request at `d` in general: in Sobol' order one table row
    /// or one pass over the index bits for its three dimensions; padded
    /// requests each shuffle the index their own way, so they stay two.
    #[inline(never)]
    fn general_1d_2d(&mut self, d: u32) -> (f32, Vec2) {
        if D::SHUFFLED {
            return (self.sample_1d(d), self.sample_2d(d.wrapping_add(1)));
        }
        let reversed = D::reversed_coordinates(self.index, d);
        unit_1d_2d::<R>(reversed, self.scramble_seeds_1d_2d(d))
    }

    /// The first sample of a pixel to reach a dimension hashes its seeds.
    #[cold]
    #[inline(never)]
    fn hash_seeds(&mut self, start: u32) -> u64 {
        let h = hash_with(self.key, start as u64);
        if start < SEED_CACHE as u32 {
            self.seed_hashes[start as usize] = h;
            self.cached |= 1 << start;
        }
        h
    }

    /// The seed of the sample-index shuffle of a (padded) request: counters
    /// past 2^32 never meet a scramble seed's.
    #[inline(always)]
    fn shuffle_seed(&self, start: u32) -> u32 {
        hash_with(self.key, 1 << 32 | start as u64) as u32
    }

    /// The sample index a request starting at `dimension` uses: shuffled per
    /// request in padded mode (an Owen scramble of the index is a nested
    /// permutation, so aligned power-of-two blocks map onto themselves).
    #[inline(always)]
    fn index_for(&self, dimension: u32) -> u32 {
        if D::SHUFFLED && R::SEEDED && dimension >= 2 {
            owen_scramble(self.index, self.shuffle_seed(dimension))
        } else {
            self.index
        }
    }

    #[inline(always)]
    fn sample_1d(&mut self, start: u32) -> f32 {
        let [reversed] = D::reversed_coordinates(self.index_for(start), start);
        let [seed, _] = self.scramble_seeds(start);
        reversed_to_unit_f32(R::apply(reversed, seed))
    }

    /// Both components of a 2D request: one pass over the index bits (or
    /// one table row).
    #[inline(always)]
    fn sample_2d(&mut self, start: u32) -> Vec2 {
        let [r0, r1] = D::reversed_coordinates(self.index_for(start), start);
        let [s0, s1] = self.scramble_seeds(start);
        Vec2::new(
            reversed_to_unit_f32(R::apply(r0, s0)),
            reversed_to_unit_f32(R::apply(r1, s1)),
        )
    }
}

/// A 1D+2D request's numbers from its three unscrambled coordinates and
/// their seeds.
#[inline(always)]
fn unit_1d_2d<R: Randomization>(reversed: [u32; 3], seeds: [u32; 3]) -> (f32, Vec2) {
    let unit = |k: usize| reversed_to_unit_f32(R::apply(reversed[k], seeds[k]));
    (unit(0), Vec2::new(unit(1), unit(2)))
}

impl SobolSampler {
    /// The sampler with the given randomisation and dimension mapping.
    pub fn boxed(spp: u32, randomize: Randomize, dimensions: Dimensions) -> Box<dyn Sampler> {
        fn make<R: Randomization, D: DimensionMapping>(spp: u32) -> Box<dyn Sampler> {
            Box::new(SobolSampler::<R, D>::new(spp))
        }
        match (randomize, dimensions) {
            (Randomize::Owen, Dimensions::Sobol) => make::<Owen, SobolOrder>(spp),
            (Randomize::Owen, Dimensions::Padded) => make::<Owen, Padded>(spp),
            (Randomize::Xor, Dimensions::Sobol) => make::<Xor, SobolOrder>(spp),
            (Randomize::Xor, Dimensions::Padded) => make::<Xor, Padded>(spp),
            (Randomize::None, Dimensions::Sobol) => make::<Unrandomized, SobolOrder>(spp),
            (Randomize::None, Dimensions::Padded) => make::<Unrandomized, Padded>(spp),
        }
    }

    pub fn from_params(params: &Params) -> Result<Box<dyn Sampler>> {
        let p = SobolParams::read(params)?;
        Ok(Self::boxed(
            p.spp.checked(params)?,
            p.randomize,
            p.dimensions,
        ))
    }
}

impl<R: Randomization, D: DimensionMapping> Sampler for SobolSampler<R, D> {
    fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        // A pixel's samples come one after another: hash its key once.
        if self.keyed != Some((pixel, seed)) {
            self.keyed = Some((pixel, seed));
            self.key = pixel_key(pixel.x, pixel.y, seed);
            self.cached = 0;
        }
        self.index = index;
        self.dimension = DimensionCursor::START;
    }

    fn get_1d(&mut self) -> f32 {
        let d = self.dimension.take(1);
        self.sample_1d(d)
    }

    fn get_2d(&mut self) -> Vec2 {
        let d = self.dimension.take(2);
        self.sample_2d(d)
    }

    fn get_1d_2d(&mut self) -> (f32, Vec2) {
        let d = self.dimension.take(3);
        match self.tabulated_1d_2d(d) {
            Some(request) => request,
            None => self.general_1d_2d(d),
        }
    }

    fn get_pixel_2d(&mut self) -> Vec2 {
        self.sample_2d(0)
    }

    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }

    /// A pixel's first power-of-two points of a (0, 2)-sequence are a net.
    fn pixel_pattern(&self) -> PixelPattern {
        net_at_powers_of_two(self.spp)
    }

    fn randomized(&self) -> bool {
        R::SEEDED
    }

    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::boxed(self, n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::net_check::is_02_net;

    fn pairs(s: &mut dyn Sampler, n: u32, skip_pairs: usize, seed: u64) -> Vec<Vec2> {
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
                let mut s = SobolSampler::boxed(max, randomize, dimensions);
                let points = pairs(s.as_mut(), max, skip, 5);
                for m in [0u32, 1, 2, 5, 8, 11, 14] {
                    assert!(
                        is_02_net(&points[..1 << m], m),
                        "{randomize:?} {dimensions:?} m {m}"
                    );
                }
            }
        }
    }

    fn correlation(a: &[f32], b: &[f32]) -> f64 {
        let n = a.len() as f64;
        let mean = |v: &[f32]| v.iter().map(|&x| x as f64).sum::<f64>() / n;
        let (ma, mb) = (mean(a), mean(b));
        let (mut ab, mut aa, mut bb) = (0.0, 0.0, 0.0);
        for (&x, &y) in a.iter().zip(b) {
            let (x, y) = (x as f64 - ma, y as f64 - mb);
            ab += x * y;
            aa += x * x;
            bb += y * y;
        }
        ab / (aa * bb).sqrt()
    }

    /// The first sample's values of a request pattern like a path's (film
    /// plane, 1D, 2D, 1D, 2D), one row per pixel of a 128-wide image.
    fn first_samples(s: &mut dyn Sampler, pixels: u32, seed: u64) -> Vec<Vec<f32>> {
        let mut columns = vec![Vec::new(); 8];
        for i in 0..pixels {
            s.start_pixel_sample(UVec2::new(i % 128, i / 128), 0, seed);
            let (p, a, b, c, d) = (
                s.get_pixel_2d(),
                s.get_1d(),
                s.get_2d(),
                s.get_1d(),
                s.get_2d(),
            );
            for (column, v) in columns.iter_mut().zip([p.x, p.y, a, b.x, b.y, c, d.x, d.y]) {
                column.push(v);
            }
        }
        columns
    }

    /// Scramble seeds are hashed from (pixel, dimension, seed): across
    /// pixels, every pair of dimensions of a sample is uncorrelated, and so
    /// is each dimension between horizontal neighbours and between scene
    /// seeds. In Sobol' order sample 0 is the origin in every dimension, so
    /// its values are the scrambles alone.
    #[test]
    fn seeds_decorrelate_dimensions_pixels_and_scene_seeds() {
        let n = 1u32 << 14;
        // |r| < 5 sd of the null distribution (sd = 1/sqrt(n)).
        let bound = 5.0 / (n as f64).sqrt();
        for randomize in [Randomize::Owen, Randomize::Xor] {
            for dimensions in [Dimensions::Sobol, Dimensions::Padded] {
                let mut s = SobolSampler::boxed(16, randomize, dimensions);
                let v = first_samples(s.as_mut(), n, 7);
                let w = first_samples(s.as_mut(), n, 8);
                let label = format!("{randomize:?} {dimensions:?}");
                for i in 0..v.len() {
                    for j in i + 1..v.len() {
                        let r = correlation(&v[i], &v[j]);
                        assert!(r.abs() < bound, "{label}: dims {i} {j}: {r}");
                    }
                    let r = correlation(&v[i][1..], &v[i][..n as usize - 1]);
                    assert!(r.abs() < bound, "{label}: dim {i}, neighbours: {r}");
                    let r = correlation(&v[i], &w[i]);
                    assert!(r.abs() < bound, "{label}: dim {i}, seeds: {r}");
                }
            }
        }
    }

    /// Every instantiation [`SobolSampler::boxed`] picks is the one asked
    /// for: the randomisations differ, padded differs from Sobol' order past
    /// the film plane only.
    #[test]
    fn boxed_picks_the_requested_strategies() {
        let draw = |randomize, dimensions| {
            let mut s = SobolSampler::boxed(16, randomize, dimensions);
            s.start_pixel_sample(UVec2::new(3, 4), 5, 1);
            [s.get_pixel_2d(), s.get_2d()]
        };
        let none = draw(Randomize::None, Dimensions::Sobol);
        // Sobol' point 5 of dimensions 0..4, unscrambled.
        let point = |d| sobol_u32_unit(5, d);
        assert_eq!(
            none,
            [Vec2::new(point(0), point(1)), Vec2::new(point(2), point(3))]
        );
        let none_padded = draw(Randomize::None, Dimensions::Padded);
        assert_eq!(none_padded, [none[0], none[0]]);
        let owen = draw(Randomize::Owen, Dimensions::Sobol);
        let xor = draw(Randomize::Xor, Dimensions::Sobol);
        let owen_padded = draw(Randomize::Owen, Dimensions::Padded);
        assert_ne!(owen, none);
        assert_ne!(xor, none);
        assert_ne!(owen, xor);
        assert_eq!(owen_padded[0], owen[0]);
        assert_ne!(owen_padded[1], owen[1]);
    }

    fn sobol_u32_unit(index: u32, dim: usize) -> f32 {
        lumis_sampling::fixed_to_unit_f32(lumis_sampling::sobol_u32(index, dim))
    }

    #[test]
    fn seeds_and_pixels_change_the_points() {
        let mut s = SobolSampler::boxed(16, Randomize::Owen, Dimensions::Sobol);
        let a = pairs(s.as_mut(), 4, 1, 1);
        assert_ne!(a, pairs(s.as_mut(), 4, 1, 2));
        let mut t = SobolSampler::boxed(16, Randomize::None, Dimensions::Sobol);
        assert_eq!(pairs(t.as_mut(), 4, 1, 1), pairs(t.as_mut(), 4, 1, 2));
    }
}
