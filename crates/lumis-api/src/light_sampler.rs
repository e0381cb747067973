//! Choosing which light to sample.

use crate::interaction::LightSampleContext;
use lumis_derive::plugin_interface;

/// A light picked by a [`LightSampler`] with its probability.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledLight {
    /// Index into [`crate::Scene::lights`].
    pub index: u32,
    pub pmf: f32,
}

/// Picks one light for next-event estimation.
///
/// The pmf over all lights sums to 1, or less where the sampler knows some
/// lights cannot reach `ctx`: it may leave those out, and `sample` then
/// returns `None` with the probability left over. A light that sends any
/// light to `ctx` must have a positive pmf there, or estimates are biased.
#[plugin_interface]
pub trait LightSampler: Send + Sync {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight>;

    /// Probability that `sample` from `ctx` returns the light `index`.
    fn pmf(&self, ctx: &LightSampleContext, index: u32) -> f32;
}

/// Picks no light: a scene without lights, and the answer of a wrapped
/// scene whose call faulted.
pub struct NoLights;

impl LightSampler for NoLights {
    fn sample(&self, _: &LightSampleContext, _: f32) -> Option<SampledLight> {
        None
    }
    fn pmf(&self, _: &LightSampleContext, _: u32) -> f32 {
        0.0
    }
}
