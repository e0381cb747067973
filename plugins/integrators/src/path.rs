//! `path`: unidirectional path tracing with next-event estimation, multiple
//! importance sampling and Russian roulette (Veach 1997, ch. 9; pbrt-v4
//! `PathIntegrator`).

use lumis_core::{
    BsdfFlags, Integrator, ParamSpec, ParamType, Params, PluginKind, PluginSpec, Ray, RenderStats,
    Result, Rgb, Sampler, Scene, Vec2,
};

use crate::estimator::{
    self, bsdf_context, BsdfRay, Estimator, Heuristic, SceneView, Strategy, Vertex, VertexPlan,
};
use crate::specialize::Trace;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "path",
    doc: "unidirectional path tracer: BSDF sampling, light sampling, or both combined with MIS",
    params: &[
        ParamSpec::with_default(
            "max_depth",
            ParamType::Int,
            "8",
            "maximum path segments from the camera: 1 = emitters seen directly, 2 = direct lighting",
        ),
        ParamSpec::with_default(
            "rr_depth",
            ParamType::Int,
            "5",
            "Russian roulette may end paths longer than this many segments (unbiased); large = off",
        ),
        estimator::PARAMS[0],
        estimator::PARAMS[1],
        estimator::PARAMS[2],
        estimator::PARAMS[3],
        estimator::PARAMS[4],
        estimator::PARAMS[5],
    ],
};

#[derive(Debug, Clone)]
pub struct PathIntegrator {
    max_depth: u32,
    rr_depth: u32,
    estimator: Estimator,
}

impl PathIntegrator {
    pub fn new(max_depth: u32, rr_depth: u32, strategy: Strategy, heuristic: Heuristic) -> Self {
        Self::with_estimator(max_depth, rr_depth, Estimator::new(strategy, heuristic))
    }

    pub fn with_estimator(max_depth: u32, rr_depth: u32, estimator: Estimator) -> Self {
        Self {
            max_depth,
            rr_depth,
            estimator,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let max_depth: u32 = params.get("max_depth")?;
        if max_depth == 0 {
            return Err(params.error(
                "max_depth",
                "must be at least 1 (1 = emitters seen directly)",
            ));
        }
        let rr_depth: u32 = params.get("rr_depth")?;
        Ok(Self::with_estimator(
            max_depth,
            rr_depth,
            Estimator::from_params(params)?,
        ))
    }
}

impl Integrator for PathIntegrator {
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

impl Trace for PathIntegrator {
    fn trace<S: Scene + ?Sized>(
        &self,
        camera_ray: &Ray,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        let mut radiance = Rgb::BLACK;
        let mut beta = Rgb::WHITE;
        let mut ray = *camera_ray;
        // How the ray to the next vertex was sampled: what weights the
        // emission it finds.
        let mut from = BsdfRay::camera(ray.o);
        // The product of eta'^2 over the refractions so far: radiance
        // transport divides the throughput by it, and leaving the medium
        // will multiply it back, so Russian roulette judges the throughput
        // without it (pbrt-v4's `etaScale`).
        let mut eta_scale = 1.0f32;
        let mut segments = 1;
        loop {
            stats.rays += 1;
            // The continuation's and the light sample's numbers do not
            // depend on the hit: drawn before the intersection, their
            // latency overlaps it instead of delaying what follows it (the
            // light sample's only where the estimator samples lights, so
            // BSDF-only paths keep their dimensions).
            let (u1, u2) = sampler.get_1d_2d();
            let u_light = if self.estimator.samples_lights() {
                sampler.get_1d_2d()
            } else {
                (0.0, Vec2::ZERO)
            };
            // Borrowed where `intersect` wrote it, not moved out of the
            // Option: that move is a 128-byte copy per vertex.
            let found = scene.intersect(&ray);
            let (le, emitters) = self.estimator.emission(scene, &ray, found.as_ref(), &from);
            if emitters > 0 {
                radiance += beta * le;
                // What the camera sees is not found by BSDF sampling.
                if segments > 1 {
                    stats.bsdf_light_hits += emitters;
                }
            }
            let Some(hit) = &found else {
                break;
            };
            if segments >= self.max_depth {
                break;
            }
            // `-ray.d` is the hit's `wo` (the `Scene::intersect` contract),
            // still in registers: the copy in the interaction was stored in
            // pieces and reloads as one vector, which the CPU cannot forward
            // from the stores and waits for.
            let wo = hit.shading.to_local(-ray.d);
            let plan = if hit.bsdf_flags.is_non_specular() {
                self.estimator.plan(sampler)
            } else {
                VertexPlan::UNWEIGHTED
            };
            // The continuation's BSDF sample first: it is a chain of
            // dependent latencies (a division, a polynomial, a square root)
            // that the next ray waits on, and issued before next-event
            // estimation it runs alongside the light sample. Moving the
            // frame change and ray offset up as well measured slower (see
            // docs/performance-log.md).
            let sampled = hit.bsdf.sample_f(&bsdf_context(hit), wo, u1, u2);
            // Both offset origins as soon as the hit is known: the shadow
            // rays and the continuation then only pick one.
            let vertex = Vertex {
                hit,
                origins: hit.point.ray_origins(),
                wo,
            };
            if plan.light_samples > 0 {
                radiance += beta
                    * self
                        .estimator
                        .sample_lights(&plan, &vertex, scene, u_light, sampler, stats);
            }
            if plan.extra_bsdf_samples > 0 {
                radiance += beta
                    * self
                        .estimator
                        .extra_bsdf_samples(&plan, &vertex, scene, sampler, stats);
            }
            let Some(bs) = sampled else {
                break;
            };
            let wi = hit.shading.to_world(bs.wi);
            // A direction below the geometric surface would leak through it.
            if wi.dot(hit.n()) * bs.wi.z <= 0.0 {
                break;
            }
            beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            if bs.flags.contains(BsdfFlags::TRANSMISSION) {
                eta_scale *= bs.eta * bs.eta;
            }
            let specular = bs.flags.is_specular();
            from = BsdfRay {
                prev: hit.light_context(),
                pdf: bs.pdf,
                specular,
                scale: if specular { 1.0 } else { plan.bsdf_scale },
            };
            ray = vertex.origins.spawn_ray(wi);
            segments += 1;

            if segments > self.rr_depth {
                // Survive with probability max(beta eta_scale) (pbrt-v4):
                // paths that carry little weight stop early; survivors are
                // reweighted.
                let q = (1.0 - (beta * eta_scale).max_component()).max(0.0);
                if sampler.get_1d() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
            if beta.is_black() {
                break;
            }
        }
        radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::doc;

    fn build(text: &str) -> Result<PathIntegrator> {
        let table = doc::parse(text, "i.toml")?;
        let params = Params::from_table("integrator", &table, SPEC.params)?;
        let made = PathIntegrator::from_params(&params)?;
        params.finish()?;
        Ok(made)
    }

    #[test]
    fn parameters_and_their_dependencies() {
        let p = build("max_depth = 3\nheuristic = \"balance\"\n").unwrap();
        assert_eq!(p.estimator.heuristic, Heuristic::Balance);
        assert_eq!(p.max_depth, 3);
        let default = build("").unwrap().estimator;
        assert_eq!(
            default,
            Estimator::new(Strategy::Mis, Heuristic::Power { beta: 2.0 })
        );
        let counts = build("n_f = 2\nn_g = 4\nestimator = \"one-sample\"\n").unwrap();
        assert_eq!((counts.estimator.n_f, counts.estimator.n_g), (2, 4));
        assert!(build("n_g = 0\n").is_err());
        let err = build("heuristic = \"balance\"\nbeta = 3.0\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("'beta': only applies"), "{err}");
        assert_eq!(
            build("strategy = \"bsdf\"\nheuristic = \"power\"\n")
                .unwrap()
                .estimator
                .strategy,
            Strategy::Bsdf
        );
        assert!(build("max_depth = 0\n").is_err());
        assert!(build("strategy = \"nee\"\n").is_err());
    }
}
