//! Choosing which light to sample.

use crate::interaction::LightSampleContext;

/// A light picked by a [`LightSampler`] with its probability.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledLight {
    /// Index into [`crate::Scene::lights`].
    pub index: u32,
    pub pmf: f32,
}

/// Picks one light for next-event estimation.
pub trait LightSampler: Send + Sync {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight>;

    /// Probability that `sample` from `ctx` returns the light `index`.
    fn pmf(&self, ctx: &LightSampleContext, index: u32) -> f32;
}
