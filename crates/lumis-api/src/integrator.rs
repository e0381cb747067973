//! The integrator plugin interface.

use crate::ray::Ray;
use crate::sampler::{Sampler, SamplerLanes};
use crate::scene::Scene;
use crate::spectrum::Rgb;
use crate::stats::RenderStats;
use lumis_derive::plugin_interface;

/// Estimates the radiance arriving along a camera ray.
///
/// The render driver owns tiles, film and threads; an integrator only turns
/// one camera ray into one radiance estimate, counting the rays it traces.
#[plugin_interface]
pub trait Integrator: Send + Sync {
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb;

    /// How many camera rays [`Integrator::li_batch`] wants at once; 1 (the
    /// default): the driver calls [`Integrator::li`] ray by ray.
    #[on_fault(1)]
    fn batch_size(&self) -> usize {
        1
    }

    /// The estimates for a batch of camera rays: `out[i]` for `rays[i]`,
    /// whose pixel sample lane `i` of `samplers` has started (its camera
    /// dimensions drawn). A wavefront integrator advances the paths
    /// together; the default traces them one by one with `li`.
    #[on_fault(out.fill(Rgb::BLACK))]
    fn li_batch(
        &self,
        rays: &[Ray],
        scene: &dyn Scene,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
        out: &mut [Rgb],
    ) {
        for (i, (ray, out)) in rays.iter().zip(out).enumerate() {
            *out = samplers.with_lane(i, |sampler| self.li(ray, scene, sampler, stats));
        }
    }
}
