//! The integrator plugin interface.

use crate::ray::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::Rgb;
use crate::stats::RenderStats;

/// Estimates the radiance arriving along a camera ray.
///
/// The render driver owns tiles, film and threads; an integrator only turns
/// one camera ray into one radiance estimate, counting the rays it traces.
pub trait Integrator: Send + Sync {
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb;
}
