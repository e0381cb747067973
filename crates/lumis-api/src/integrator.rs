//! The integrator plugin interface.

use crate::camera::Pinhole;
use crate::ray::Ray;
use crate::sampler::{Sampler, SamplerLanes};
use crate::scene::Scene;
use crate::spectrum::Rgb;
use crate::stats::RenderStats;
use glam::Vec2;
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

    /// Whether the integrator adds light to the film beyond each camera
    /// ray's own pixel, with [`Integrator::li_splat`] (paths from the
    /// lights, seen by the camera where they land): the driver then calls
    /// `li_splat` for every camera ray, and the film keeps the splats.
    /// False by default.
    #[on_fault(false)]
    fn splats(&self) -> bool {
        false
    }

    /// [`Integrator::li`] for an integrator that [`Integrator::splats`]:
    /// the estimate along `ray`, and the light found elsewhere on the film
    /// through `camera`, each added with `splat(raster, radiance)`. The
    /// film divides the splats by its samples per pixel, so each call
    /// stands for one pixel sample of the film (pbrt-v4 `Film::AddSplat`).
    /// The default is `li`, splatting nothing.
    #[on_fault(Rgb::BLACK)]
    fn li_splat(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        camera: &Pinhole,
        sampler: &mut dyn Sampler,
        splat: &mut dyn FnMut(Vec2, Rgb),
        stats: &mut RenderStats,
    ) -> Rgb {
        let _ = (camera, splat);
        self.li(ray, scene, sampler, stats)
    }

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
