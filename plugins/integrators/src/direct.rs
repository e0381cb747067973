//! `direct`: direct lighting only (emission seen by the camera, plus light
//! reaching the first surface straight from an emitter), with the same
//! strategy switches and sample counts as `path`.
//!
//! This is the estimator the MIS literature compares (Veach 1997, figure
//! 9.2; pbrt-v3 `DirectLightingIntegrator`): no indirect light dilutes the
//! difference between the strategies.

use lumis_api::{
    Params, PluginKind, PluginParams, PluginSpec, Ray, RenderStats, Result, Rgb, Sampler, Scene,
};

use crate::estimator::{BsdfRay, Estimator, EstimatorParams, SceneView, Vertex, VertexPlan};
use crate::specialize::{integrator_by_trace, Trace};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "direct",
    source: lumis_api::source_file!(),
    doc: "direct lighting at the first hit: n_f BSDF and n_g light samples combined by MIS (or one strategy alone); specular surfaces pass one BSDF sample on to the emitter it hits",
    params: EstimatorParams::SPECS,
};

#[derive(Debug, Clone)]
pub struct DirectIntegrator {
    estimator: Estimator,
}

impl DirectIntegrator {
    pub fn new(estimator: Estimator) -> Self {
        Self { estimator }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        Ok(Self::new(Estimator::from_params(params)?))
    }
}

integrator_by_trace!(DirectIntegrator);

impl Trace for DirectIntegrator {
    fn trace<S: Scene + ?Sized>(
        &self,
        camera_ray: &Ray,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        // What the camera sees directly counts fully (a specular "bounce");
        // it is not counted as found by BSDF sampling.
        stats.rays += 1;
        let found = scene.intersect(camera_ray);
        let (mut radiance, _) = self.estimator.emission(
            scene,
            camera_ray,
            found.as_ref(),
            &BsdfRay::camera(camera_ray.o),
        );
        let Some(hit) = &found else {
            return radiance;
        };
        let plan = if hit.bsdf_flags.is_non_specular() {
            self.estimator.plan(sampler)
        } else {
            VertexPlan::UNWEIGHTED
        };
        let vertex = Vertex {
            hit,
            origins: hit.point.ray_origins(),
            wo: hit.shading.to_local(-camera_ray.d),
        };
        if plan.light_samples > 0 {
            let u_light = sampler.get_1d_2d();
            radiance += self
                .estimator
                .sample_lights(&plan, &vertex, scene, u_light, sampler, stats);
        }
        // The first BSDF sample, then the extra ones: all only look for
        // emission. A specular sample's emission is not weighted.
        if plan.bsdf_scale > 0.0 {
            let (u1, u2) = sampler.get_1d_2d();
            if let Some(bs) = hit.bsdf.sample_f(&vertex.bsdf_context(), vertex.wo, u1, u2) {
                let wi = hit.shading.to_world(bs.wi);
                if wi.dot(hit.n()) * bs.wi.z > 0.0 {
                    let specular = bs.flags.is_specular();
                    let from = BsdfRay {
                        prev: hit.light_context(),
                        pdf: bs.pdf,
                        specular,
                        scale: if specular { 1.0 } else { plan.bsdf_scale },
                    };
                    stats.rays += 1;
                    let le = self.estimator.emission_along(
                        scene,
                        &vertex.origins.spawn_ray(wi),
                        &from,
                        stats,
                    );
                    radiance += bs.f * (bs.wi.z.abs() / bs.pdf) * le;
                }
            }
            radiance += self
                .estimator
                .extra_bsdf_samples(&plan, &vertex, scene, sampler, stats);
        }
        radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::{Heuristic, MisEstimator, Strategy};
    use lumis_core::doc;

    fn build(text: &str) -> Result<DirectIntegrator> {
        let table = doc::parse(text, "i.toml")?;
        let params = Params::from_table("integrator", &table, SPEC.params)?;
        let made = DirectIntegrator::from_params(&params)?;
        params.finish()?;
        Ok(made)
    }

    #[test]
    fn parameters() {
        let d = build("strategy = \"mis\"\nheuristic = \"balance\"\nn_f = 3\nn_g = 2\nestimator = \"one-sample\"\n")
            .unwrap()
            .estimator;
        assert_eq!(d.strategy, Strategy::Mis);
        assert_eq!(d.heuristic, Heuristic::Balance);
        assert_eq!((d.n_f, d.n_g, d.mode), (3, 2, MisEstimator::OneSample));
        assert!(build("max_depth = 2\n").is_err(), "direct has no depth");
    }
}
