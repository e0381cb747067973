//! Integrators compiled for one concrete scene type as well as `dyn Scene`.
//!
//! Through `&dyn Scene` every closest-hit query is a virtual call that hands
//! its 128-byte interaction back through memory, and the work after the hit
//! waits on it. Compiled for the renderer's own scene type, the query and
//! the construction of the interaction inline into the path loop (pbrt-v4's
//! integrators likewise see one concrete aggregate). This crate cannot name
//! that type (plugins depend only on core and sampling), so the binary,
//! which links both, names it: [`crate::register_specialized`].

use std::marker::PhantomData;

use lumis_api::{Integrator, Ray, RenderStats, Rgb, Sampler, Scene};

use crate::estimator::SceneView;

/// An integrator's estimate for a camera ray, generic over the scene type.
pub trait Trace: Send + Sync {
    fn trace<S: Scene + ?Sized>(
        &self,
        camera_ray: &Ray,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb;
}

/// `Integrator` for a [`Trace`] type: `li` traces through `dyn Scene`.
macro_rules! integrator_by_trace {
    ($integrator:ty) => {
        impl lumis_api::Integrator for $integrator {
            fn li(
                &self,
                camera_ray: &lumis_api::Ray,
                scene: &dyn lumis_api::Scene,
                sampler: &mut dyn lumis_api::Sampler,
                stats: &mut lumis_api::RenderStats,
            ) -> lumis_api::Rgb {
                $crate::specialize::Trace::trace(
                    self,
                    camera_ray,
                    &$crate::estimator::SceneView::new(scene),
                    sampler,
                    stats,
                )
            }
        }
    };
}
pub(crate) use integrator_by_trace;

/// `I` with its loop compiled for scenes of type `S` (found through
/// [`Scene::as_any`]) and for `dyn Scene` (any other scene, such as a
/// wrapper that records queries). Both loops give the same result, bit for
/// bit.
pub struct Specialized<I, S> {
    integrator: I,
    scene: PhantomData<fn(&S)>,
}

impl<I, S> Specialized<I, S> {
    pub fn new(integrator: I) -> Self {
        Self {
            integrator,
            scene: PhantomData,
        }
    }
}

impl<I: Trace, S: Scene + 'static> Integrator for Specialized<I, S> {
    fn li(
        &self,
        camera_ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        match scene.as_any().and_then(|any| any.downcast_ref::<S>()) {
            Some(concrete) => {
                self.integrator
                    .trace(camera_ray, &SceneView::new(concrete), sampler, stats)
            }
            None => self
                .integrator
                .trace(camera_ray, &SceneView::new(scene), sampler, stats),
        }
    }
}
