//! What integrators may ask of a scene: ray queries and the lights.

use lumis_derive::plugin_interface;
use std::any::Any;

use crate::interaction::SurfaceInteraction;
use crate::light::Light;
use crate::light_sampler::LightSampler;
use crate::ray::Ray;

/// A render-ready scene as integrators see it.
#[plugin_interface]
pub trait Scene: Sync {
    /// The closest surface hit along `ray` within `[0, ray.t_max]`.
    /// `ray.d` must be unit length (camera and BSDF rays are), so the hit's
    /// `wo` is `-ray.d` without renormalising.
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>>;

    /// Whether anything blocks `ray` within `[0, ray.t_max]` (shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;

    /// [`Scene::intersect`] for each ray of a batch. The default loops; a
    /// scene may trace the batch as SIMD packets (Embree's
    /// `rtcIntersect4/8/16`) and must find the same hits up to rounding.
    /// `out` has the length of `rays`.
    #[on_fault(out.iter_mut().for_each(|o| *o = None))]
    fn intersect_batch<'s>(&'s self, rays: &[Ray], out: &mut [Option<SurfaceInteraction<'s>>]) {
        for (ray, out) in rays.iter().zip(out) {
            *out = self.intersect(ray);
        }
    }

    /// [`Scene::occluded`] for each ray of a batch, as
    /// [`Scene::intersect_batch`].
    #[on_fault(out.fill(true))]
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        for (ray, out) in rays.iter().zip(out) {
            *out = self.occluded(ray);
        }
    }

    fn lights(&self) -> &[Box<dyn Light>];

    /// Indices into [`Scene::lights`] of the infinite lights, which escaping
    /// rays see.
    fn infinite_lights(&self) -> &[u32];

    #[on_fault(&crate::light_sampler::NoLights)]
    fn light_sampler(&self) -> &dyn LightSampler;

    /// The scene as its concrete type, for integrators that compile their
    /// path loop for the renderer's own scene: its queries then inline into
    /// the loop instead of returning each interaction through memory from a
    /// virtual call. Wrappers (a recording scene in a benchmark, a test
    /// double) keep the default and get the loop over `dyn Scene`.
    #[wrappers_answer(None)]
    fn as_any(&self) -> Option<&dyn Any> {
        None
    }
}
