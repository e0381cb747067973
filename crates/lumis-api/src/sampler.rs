//! The sample-generator plugin interface.

use glam::{UVec2, Vec2};
use lumis_derive::plugin_interface;

/// Hands out the random numbers of one pixel sample, dimension by dimension.
///
/// Deterministic: the same pixel, sample index and seed give the same numbers
/// on any thread, so renders do not depend on the thread count.
#[plugin_interface(lane_view = Lane)]
pub trait Sampler: Send + Sync {
    #[on_fault(1)]
    fn samples_per_pixel(&self) -> u32;

    /// Starts sample `index` of `pixel`; dimensions restart at zero.
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64);

    #[on_fault(0.5)]
    fn get_1d(&mut self) -> f32;

    #[on_fault(Vec2::splat(0.5))]
    fn get_2d(&mut self) -> Vec2;

    /// `get_1d()` then `get_2d()`, the same three numbers: what a light
    /// sample (which light, which point) and a BSDF sample (which lobe,
    /// which direction) each draw. One call instead of two, so a sampler
    /// can share the work of the three dimensions (a Sobol' sampler walks
    /// the sample index's bits once for all three).
    #[on_fault((0.5, Vec2::splat(0.5)))]
    fn get_1d_2d(&mut self) -> (f32, Vec2) {
        let u = self.get_1d();
        (u, self.get_2d())
    }

    /// The film position within the pixel (the first two dimensions of a
    /// sample, so samplers can stratify them best).
    #[on_fault(Vec2::splat(0.5))]
    fn get_pixel_2d(&mut self) -> Vec2;

    /// An independent copy for another thread.
    #[on_fault(Box::new(FaultedSampler))]
    fn clone_sampler(&self) -> Box<dyn Sampler>;

    /// What the film positions ([`Sampler::get_pixel_2d`]) of a pixel's
    /// `samples_per_pixel()` samples guarantee, for any pixel and seed:
    /// what `lumis check-plugin` verifies exactly. The default promises
    /// nothing beyond uniformity.
    #[on_fault(PixelPattern::Random)]
    fn pixel_pattern(&self) -> PixelPattern {
        PixelPattern::Random
    }

    /// Whether every number, over seeds and pixels, is uniform in [0, 1)
    /// (jittered, scrambled: randomised quasi-Monte Carlo), so that
    /// estimates are unbiased. `false` declares a deterministic point set
    /// (strata centres, an unscrambled sequence): `lumis check-plugin`
    /// does not hold it to uniformity, and says so.
    #[on_fault(true)]
    fn randomized(&self) -> bool {
        true
    }

    /// `n` independent copies, one per lane of a batch of paths. The
    /// default boxes `n` clones and asks them one virtual call at a time;
    /// a `Clone` sampler returns [`ConcreteLanes`] instead, whose batched requests
    /// call it directly.
    #[on_fault(ConcreteLanes::made_by(n, || Box::new(FaultedSampler)))]
    fn lanes(&self, n: usize) -> Box<dyn SamplerLanes> {
        ConcreteLanes::made_by(n, || self.clone_sampler())
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
/// pixel sample's numbers in its own order, asked by lane: a wavefront
/// integrator asks them together. Lane `i` answers exactly what its own
/// sampler would answer asked alone; `with_lane` (on `dyn SamplerLanes`)
/// lends one lane as a [`Sampler`].
#[plugin_interface]
pub trait SamplerLanes: Send + Sync {
    /// How many lanes.
    fn len(&self) -> usize;

    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// [`Sampler::samples_per_pixel`], the same for every lane.
    #[on_fault(1)]
    fn samples_per_pixel(&self) -> u32;

    /// [`Sampler::start_pixel_sample`] of lane `lane`.
    fn start_pixel_sample(&mut self, lane: usize, pixel: UVec2, index: u32, seed: u64);

    /// [`Sampler::get_1d`] of lane `lane`.
    #[on_fault(0.5)]
    fn get_1d(&mut self, lane: usize) -> f32;

    /// [`Sampler::get_2d`] of lane `lane`.
    #[on_fault(Vec2::splat(0.5))]
    fn get_2d(&mut self, lane: usize) -> Vec2;

    /// [`Sampler::get_1d_2d`] of lane `lane`.
    #[on_fault((0.5, Vec2::splat(0.5)))]
    fn get_1d_2d(&mut self, lane: usize) -> (f32, Vec2);

    /// [`Sampler::get_pixel_2d`] of lane `lane`.
    #[on_fault(Vec2::splat(0.5))]
    fn get_pixel_2d(&mut self, lane: usize) -> Vec2;

    /// An independent copy of lane `lane`'s sampler.
    #[on_fault(Box::new(FaultedSampler))]
    fn clone_lane(&self, lane: usize) -> Box<dyn Sampler>;

    /// Lane `lane`'s own sampler, where the lanes can lend it: asked
    /// directly, a request costs one virtual call instead of two (see
    /// `with_lane` on `dyn SamplerLanes`). A wrapper lends nothing:
    /// its requests must pass through it.
    #[wrappers_answer(None)]
    fn own_lane(&mut self, lane: usize) -> Option<&mut dyn Sampler> {
        let _ = lane;
        None
    }

    /// `out[k]` = [`Sampler::get_1d_2d`] of lane `lanes[k]`, in order: the
    /// request each vertex of a wave makes for its BSDF sample and for its
    /// light sample. Each lane gets exactly the numbers it would get asked
    /// alone.
    #[on_fault(out.fill((0.5, Vec2::splat(0.5))))]
    fn get_1d_2d_batch(&mut self, lanes: &[usize], out: &mut [(f32, Vec2)]) {
        for (&i, out) in lanes.iter().zip(out) {
            *out = self.get_1d_2d(i);
        }
    }
}

impl dyn SamplerLanes + '_ {
    /// Runs `f` with lane `index` as a [`Sampler`] of its own: the lane's
    /// own sampler where the lanes lend it, else a view whose requests are
    /// the batch's requests for the lane.
    #[inline]
    pub fn with_lane<R>(&mut self, index: usize, f: impl FnOnce(&mut dyn Sampler) -> R) -> R {
        if let Some(sampler) = self.own_lane(index) {
            return f(sampler);
        }
        f(&mut Lane { lanes: self, index })
    }
}

/// One lane of a batch of samplers, as a [`Sampler`]: its requests are the
/// batch's requests for the lane, and its declarations those of the lane's
/// own sampler (the implementation is generated with [`Sampler`]'s).
struct Lane<'a> {
    lanes: &'a mut dyn SamplerLanes,
    index: usize,
}

/// Lanes of one sampler type: for a concrete `S`, the batched requests
/// call `S`'s methods without a virtual call per lane, so they inline into
/// one loop; `ConcreteLanes<Box<dyn Sampler>>` is what any sampler's
/// clones make ([`Sampler::lanes`]'s default).
pub struct ConcreteLanes<S>(Vec<S>);

impl<S: Sampler + Clone + 'static> ConcreteLanes<S> {
    /// `n` copies of `sampler`, boxed for [`Sampler::lanes`].
    pub fn boxed(sampler: &S, n: usize) -> Box<dyn SamplerLanes> {
        Box::new(Self(vec![sampler.clone(); n]))
    }
}

impl ConcreteLanes<Box<dyn Sampler>> {
    /// `n` lanes, each a sampler `make` makes.
    fn made_by(n: usize, mut make: impl FnMut() -> Box<dyn Sampler>) -> Box<dyn SamplerLanes> {
        Box::new(Self((0..n).map(|_| make()).collect()))
    }
}

/// What one lane of [`ConcreteLanes`] holds: a sampler of a concrete type,
/// called without a virtual call, or a boxed one.
pub trait LaneSlot: Send + Sync + 'static {
    type Sampler: Sampler + ?Sized;
    fn sampler(&self) -> &Self::Sampler;
    fn sampler_mut(&mut self) -> &mut Self::Sampler;
    /// The sampler as `&mut dyn Sampler`, to lend it.
    fn as_dyn(&mut self) -> &mut dyn Sampler;
}

impl<S: Sampler + 'static> LaneSlot for S {
    type Sampler = S;
    #[inline]
    fn sampler(&self) -> &S {
        self
    }
    #[inline]
    fn sampler_mut(&mut self) -> &mut S {
        self
    }
    #[inline]
    fn as_dyn(&mut self) -> &mut dyn Sampler {
        self
    }
}

impl LaneSlot for Box<dyn Sampler> {
    type Sampler = dyn Sampler;
    #[inline]
    fn sampler(&self) -> &Self::Sampler {
        self.as_ref()
    }
    #[inline]
    fn sampler_mut(&mut self) -> &mut Self::Sampler {
        self.as_mut()
    }
    #[inline]
    fn as_dyn(&mut self) -> &mut dyn Sampler {
        self.as_mut()
    }
}

impl<S: LaneSlot> SamplerLanes for ConcreteLanes<S> {
    fn len(&self) -> usize {
        self.0.len()
    }
    fn samples_per_pixel(&self) -> u32 {
        self.0
            .first()
            .map_or(1, |s| s.sampler().samples_per_pixel())
    }
    fn start_pixel_sample(&mut self, lane: usize, pixel: UVec2, index: u32, seed: u64) {
        self.0[lane]
            .sampler_mut()
            .start_pixel_sample(pixel, index, seed)
    }
    #[inline]
    fn get_1d(&mut self, lane: usize) -> f32 {
        self.0[lane].sampler_mut().get_1d()
    }
    #[inline]
    fn get_2d(&mut self, lane: usize) -> Vec2 {
        self.0[lane].sampler_mut().get_2d()
    }
    #[inline]
    fn get_1d_2d(&mut self, lane: usize) -> (f32, Vec2) {
        self.0[lane].sampler_mut().get_1d_2d()
    }
    #[inline]
    fn get_pixel_2d(&mut self, lane: usize) -> Vec2 {
        self.0[lane].sampler_mut().get_pixel_2d()
    }
    fn clone_lane(&self, lane: usize) -> Box<dyn Sampler> {
        self.0[lane].sampler().clone_sampler()
    }
    #[inline]
    fn own_lane(&mut self, lane: usize) -> Option<&mut dyn Sampler> {
        Some(self.0[lane].as_dyn())
    }
    fn get_1d_2d_batch(&mut self, lanes: &[usize], out: &mut [(f32, Vec2)]) {
        for (&i, out) in lanes.iter().zip(out) {
            *out = self.0[i].sampler_mut().get_1d_2d();
        }
    }
}

/// What a wrapped sampler whose clone faulted draws: the centre of every
/// dimension, one sample per pixel, until the host stops at the recorded
/// fault.
struct FaultedSampler;

impl Sampler for FaultedSampler {
    fn samples_per_pixel(&self) -> u32 {
        1
    }
    fn start_pixel_sample(&mut self, _: UVec2, _: u32, _: u64) {}
    fn get_1d(&mut self) -> f32 {
        0.5
    }
    fn get_2d(&mut self) -> Vec2 {
        Vec2::splat(0.5)
    }
    fn get_pixel_2d(&mut self) -> Vec2 {
        Vec2::splat(0.5)
    }
    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(FaultedSampler)
    }
}
