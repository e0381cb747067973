//! `direct`: direct lighting only (emission seen by the camera, plus light
//! reaching the first surface straight from an emitter), with the same
//! strategy switches and sample counts as `path`. This is the estimator the
//! MIS literature compares (Veach 1997, figure 9.2; pbrt-v3
//! `DirectLightingIntegrator`): no indirect light dilutes the difference
//! between the strategies.

use lumis_core::bsdf::BsdfContext;
use lumis_core::{
    Integrator, LightIndex, ParamSpec, Params, PluginKind, PluginSpec, Ray, RenderStats, Result,
    Rgb, Sampler, Scene, Vec3,
};

use crate::estimator::{self, Estimator, SceneView, VertexPlan};
use crate::specialize::Trace;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "direct",
    doc: "direct lighting at the first hit: n_f BSDF and n_g light samples combined by MIS (or one strategy alone); specular surfaces pass one BSDF sample on to the emitter it hits",
    params: &PARAMS,
};

const PARAMS: [ParamSpec; 6] = estimator::PARAMS;

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

impl Integrator for DirectIntegrator {
    fn li(
        &self,
        camera_ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        self.trace(camera_ray, &SceneView::new(scene), sampler, stats)
    }
}

impl Trace for DirectIntegrator {
    fn trace<S: Scene + ?Sized>(
        &self,
        camera_ray: &Ray,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        // What the camera sees directly counts fully (a specular "bounce").
        stats.rays += 1;
        let Some(hit) = scene.intersect(camera_ray) else {
            let mut le = Rgb::BLACK;
            for &index in scene.infinite_lights {
                le += scene.lights[index as usize].l(
                    camera_ray.o,
                    Vec3::ZERO,
                    Default::default(),
                    camera_ray.d,
                );
            }
            return le;
        };
        let mut radiance = match hit.light.map(LightIndex::get) {
            Some(emitter) => scene.lights[emitter as usize].l(hit.p(), hit.n(), hit.uv, hit.wo),
            None => Rgb::BLACK,
        };
        let wo = hit.shading.to_local(hit.wo);
        let plan = if hit.bsdf_flags.is_non_specular() {
            self.estimator.plan(sampler)
        } else {
            VertexPlan::UNWEIGHTED
        };
        let origins = hit.point.ray_origins();
        if plan.light_samples > 0 {
            let u_light = sampler.get_1d_2d();
            radiance += self
                .estimator
                .sample_lights(&plan, &hit, &origins, wo, scene, u_light, sampler, stats);
        }
        // The first BSDF sample, then the extra ones: all only look for
        // emission. A specular sample's emission is not weighted.
        if plan.bsdf_scale > 0.0 {
            let bsdf_ctx = BsdfContext {
                uv: hit.uv,
                ..Default::default()
            };
            let (u1, u2) = sampler.get_1d_2d();
            if let Some(bs) = hit.bsdf.sample_f(&bsdf_ctx, wo, u1, u2) {
                let wi = hit.shading.to_world(bs.wi);
                if wi.dot(hit.n()) * bs.wi.z > 0.0 {
                    let specular = bs.flags.is_specular();
                    let scale = if specular { 1.0 } else { plan.bsdf_scale };
                    stats.rays += 1;
                    let le = self.estimator.emission_along(
                        scene,
                        &origins.spawn_ray(wi),
                        &hit.light_context(),
                        bs.pdf,
                        specular,
                        stats,
                    );
                    radiance += bs.f * (bs.wi.z.abs() / bs.pdf) * le * scale;
                }
            }
            radiance += self
                .estimator
                .extra_bsdf_samples(&plan, &hit, &origins, wo, scene, sampler, stats);
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
