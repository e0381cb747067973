//! The sample-generator plugin interface.

use glam::{UVec2, Vec2};

/// Hands out the random numbers of one pixel sample, dimension by dimension.
///
/// Deterministic: the same pixel, sample index and seed give the same numbers
/// on any thread, so renders do not depend on the thread count.
pub trait Sampler: Send + Sync {
    fn samples_per_pixel(&self) -> u32;

    /// Starts sample `index` of `pixel`; dimensions restart at zero.
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64);

    fn get_1d(&mut self) -> f32;

    fn get_2d(&mut self) -> Vec2;

    /// `get_1d()` then `get_2d()`, the same three numbers: what a light
    /// sample (which light, which point) and a BSDF sample (which lobe,
    /// which direction) each draw. One call instead of two, so a sampler
    /// can share the work of the three dimensions (a Sobol' sampler walks
    /// the sample index's bits once for all three).
    fn get_1d_2d(&mut self) -> (f32, Vec2) {
        let u = self.get_1d();
        (u, self.get_2d())
    }

    /// The film position within the pixel (the first two dimensions of a
    /// sample, so samplers can stratify them best).
    fn get_pixel_2d(&mut self) -> Vec2;

    /// An independent copy for another thread.
    fn clone_sampler(&self) -> Box<dyn Sampler>;

    /// What the film positions ([`Sampler::get_pixel_2d`]) of a pixel's
    /// `samples_per_pixel()` samples guarantee, for any pixel and seed:
    /// what `lumis check-plugin` verifies exactly. The default promises
    /// nothing beyond uniformity.
    fn pixel_pattern(&self) -> PixelPattern {
        PixelPattern::Random
    }

    /// Whether every number, over seeds and pixels, is uniform in [0, 1)
    /// (jittered, scrambled: randomised quasi-Monte Carlo), so that
    /// estimates are unbiased. `false` declares a deterministic point set
    /// (strata centres, an unscrambled sequence): `lumis check-plugin`
    /// does not hold it to uniformity, and says so.
    fn randomized(&self) -> bool {
        true
    }

    /// `n` independent copies, one per lane of a batch of paths. The
    /// default boxes `n` clones and asks them one virtual call at a time;
    /// a `Clone` sampler returns [`ConcreteLanes`] instead, whose batched requests
    /// call it directly.
    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        Box::new(BoxedLanes((0..n).map(|_| self.clone_sampler()).collect()))
    }
}

/// A structure that the film positions of one pixel's samples have.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PixelPattern {
    /// Uniform and nothing more (independent samples).
    Random,
    /// One position in each cell of an `nx x ny` grid over the pixel
    /// (jittered or centred strata; `ny = 1`: one per column).
    Grid { nx: u32, ny: u32 },
    /// A (0, m, 2)-net in base 2 (`2^m` samples): every elementary
    /// interval of area `2^-m`, `2^a x 2^(m-a)` cells for every `a`, holds
    /// exactly one position (Sobol', Niederreiter and Xing 1996).
    Net02,
    /// Positions at least this far apart on the torus of the pixel
    /// (a Poisson disk pattern), in pixels.
    MinDistance(f32),
}

/// The samplers of a batch of paths, one per lane, each drawing its own
/// pixel sample's numbers in its own order; a wavefront integrator asks
/// them together.
pub trait SamplerLanes: Send {
    /// How many lanes.
    fn len(&self) -> usize;

    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Lane `i`'s sampler, for a request of one lane.
    fn lane(&mut self, i: usize) -> &mut dyn Sampler;

    /// `out[k]` = [`Sampler::get_1d_2d`] of lane `lanes[k]`, in order: the
    /// request each vertex of a wave makes for its BSDF sample and for its
    /// light sample. Each lane gets exactly the numbers it would get asked
    /// alone.
    fn get_1d_2d_batch(&mut self, lanes: &[usize], out: &mut [(f32, Vec2)]) {
        for (&i, out) in lanes.iter().zip(out) {
            *out = self.lane(i).get_1d_2d();
        }
    }
}

/// The default [`Sampler::lanes`]: boxed clones.
struct BoxedLanes(Vec<Box<dyn Sampler>>);

impl SamplerLanes for BoxedLanes {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn lane(&mut self, i: usize) -> &mut dyn Sampler {
        self.0[i].as_mut()
    }
}

/// Lanes of a concrete sampler type: the batched requests call `S`'s
/// methods without a virtual call per lane, so they inline into one loop.
pub struct ConcreteLanes<S>(pub Vec<S>);

impl<S: Sampler + Clone + 'static> ConcreteLanes<S> {
    /// `n` copies of `sampler`, boxed for [`Sampler::lanes`].
    pub fn boxed(sampler: &S, n: usize) -> Box<dyn SamplerLanes> {
        Box::new(Self(vec![sampler.clone(); n]))
    }
}

impl<S: Sampler + 'static> SamplerLanes for ConcreteLanes<S> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn lane(&mut self, i: usize) -> &mut dyn Sampler {
        &mut self.0[i]
    }
    fn get_1d_2d_batch(&mut self, lanes: &[usize], out: &mut [(f32, Vec2)]) {
        for (&i, out) in lanes.iter().zip(out) {
            *out = self.0[i].get_1d_2d();
        }
    }
}
