//! `path`: unidirectional path tracing with next-event estimation, multiple
//! importance sampling and Russian roulette (Veach 1997, ch. 9; pbrt-v4
//! `PathIntegrator`).

use lumis_core::bsdf::BsdfContext;
use lumis_core::{
    Integrator, LightKind, LightSampleContext, ParamSpec, ParamType, Params, PluginKind,
    PluginSpec, Ray, RenderStats, Result, Rgb, Sampler, Scene, SurfaceInteraction, Vec3,
};
use lumis_sampling::{balance_heuristic, power_heuristic};

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
        ParamSpec::with_default(
            "strategy",
            ParamType::String,
            "\"mis\"",
            "\"bsdf\" (emission found by BSDF sampling only), \"light\" (next-event estimation only) or \"mis\" (both, weighted)",
        )
        .one_of(&["bsdf", "light", "mis"]),
        ParamSpec::with_default(
            "heuristic",
            ParamType::String,
            "\"power\"",
            "MIS weights with strategy = \"mis\": \"balance\" or \"power\"",
        )
        .one_of(&["balance", "power"]),
        ParamSpec::with_default("beta", ParamType::Float, "2.0", "exponent of the power heuristic"),
    ],
};

/// Which estimator finds emission.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Strategy {
    Bsdf,
    Light,
    Mis,
}

/// How MIS weights the two strategies (one sample of each per vertex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heuristic {
    Balance,
    Power { beta: f32 },
}

impl Heuristic {
    #[inline]
    fn weight(self, pf: f32, pg: f32) -> f32 {
        match self {
            Heuristic::Balance => balance_heuristic(1, pf, 1, pg),
            Heuristic::Power { beta } => power_heuristic(1, pf, 1, pg, beta),
        }
    }
}

#[derive(Debug, Clone)]
pub struct PathIntegrator {
    max_depth: u32,
    rr_depth: u32,
    strategy: Strategy,
    heuristic: Heuristic,
}

impl PathIntegrator {
    pub fn new(max_depth: u32, rr_depth: u32, strategy: Strategy, heuristic: Heuristic) -> Self {
        Self {
            max_depth,
            rr_depth,
            strategy,
            heuristic,
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
        let strategy = match params.get_choice("strategy")?.as_str() {
            "bsdf" => Strategy::Bsdf,
            "light" => Strategy::Light,
            _ => Strategy::Mis,
        };
        // Heuristic and beta are validated whatever the strategy, so that
        // `--set integrator.strategy=bsdf` works on a scene that sets them;
        // they only change the estimate when strategy = "mis".
        let heuristic = match params.get_choice("heuristic")?.as_str() {
            "balance" => Heuristic::Balance,
            _ => Heuristic::Power {
                beta: params.get_positive("beta")?,
            },
        };
        if params.is_given("beta") && heuristic == Heuristic::Balance {
            return Err(params.error("beta", "only applies to heuristic = \"power\""));
        }
        Ok(Self::new(max_depth, rr_depth, strategy, heuristic))
    }

    /// Next-event estimation at `hit`: one light chosen by the light
    /// sampler, one point on it, weighted against BSDF sampling under MIS.
    fn sample_direct(
        &self,
        hit: &SurfaceInteraction,
        wo: Vec3,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        let u_light = sampler.get_1d();
        let u = sampler.get_2d();
        let ctx = hit.light_context();
        let Some(chosen) = scene.light_sampler().sample(&ctx, u_light) else {
            return Rgb::BLACK;
        };
        let light = &scene.lights()[chosen.index as usize];
        let Some(ls) = light.sample_li(&ctx, u) else {
            return Rgb::BLACK;
        };
        let wi = hit.shading.to_local(ls.wi);
        let bsdf_ctx = BsdfContext {
            uv: hit.uv,
            ..Default::default()
        };
        let f = hit.bsdf.f(&bsdf_ctx, wo, wi) * wi.z.abs();
        if f.is_black() {
            return Rgb::BLACK;
        }
        stats.shadow_rays += 1;
        if scene.occluded(&hit.point.spawn_ray_to(&ls.p)) {
            return Rgb::BLACK;
        }
        stats.light_samples += 1;
        let p_light = chosen.pmf * ls.pdf;
        let weight = if light.kind() == LightKind::DeltaPosition || self.strategy == Strategy::Light
        {
            1.0
        } else {
            self.heuristic
                .weight(p_light, hit.bsdf.pdf(&bsdf_ctx, wo, wi))
        };
        f * ls.l * (weight / p_light)
    }

    /// The weight of emission found by BSDF sampling, given the density of
    /// the BSDF sample that found it.
    #[inline]
    fn emission_weight(
        &self,
        scene: &dyn Scene,
        light_index: u32,
        prev: &LightSampleContext,
        wi: Vec3,
        bsdf_pdf: f32,
        specular: bool,
    ) -> f32 {
        if specular || self.strategy == Strategy::Bsdf {
            return 1.0;
        }
        if self.strategy == Strategy::Light {
            return 0.0;
        }
        let light = &scene.lights()[light_index as usize];
        let p_light = scene.light_sampler().pmf(prev, light_index) * light.pdf_li(prev, wi);
        self.heuristic.weight(bsdf_pdf, p_light)
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
        let mut radiance = Rgb::BLACK;
        let mut beta = Rgb::WHITE;
        let mut ray = *camera_ray;
        // The camera ray counts as specular: what it sees is never weighted.
        let mut specular = true;
        let mut bsdf_pdf = 0.0;
        let mut prev = LightSampleContext::at(ray.o);
        let mut segments = 1;
        loop {
            stats.rays += 1;
            let Some(hit) = scene.intersect(&ray) else {
                for &index in scene.infinite_lights() {
                    let light = &scene.lights()[index as usize];
                    let le = light.l(ray.o, Vec3::ZERO, Default::default(), ray.d);
                    let w = self.emission_weight(scene, index, &prev, ray.d, bsdf_pdf, specular);
                    if w > 0.0 && !le.is_black() {
                        radiance += beta * le * w;
                        stats.bsdf_light_hits += u64::from(segments > 1);
                    }
                }
                break;
            };
            if let Some(emitter) = hit.light {
                let le = emitter.light.l(hit.p(), hit.n(), hit.uv, hit.wo);
                if !le.is_black() {
                    let w = self.emission_weight(
                        scene,
                        emitter.index,
                        &prev,
                        ray.d,
                        bsdf_pdf,
                        specular,
                    );
                    if w > 0.0 {
                        radiance += beta * le * w;
                        stats.bsdf_light_hits += u64::from(segments > 1);
                    }
                }
            }
            if segments >= self.max_depth {
                break;
            }
            let wo = hit.shading.to_local(hit.wo);
            if self.strategy != Strategy::Bsdf && hit.bsdf.flags().is_non_specular() {
                radiance += beta * self.sample_direct(&hit, wo, scene, sampler, stats);
            }

            let bsdf_ctx = BsdfContext {
                uv: hit.uv,
                ..Default::default()
            };
            let u1 = sampler.get_1d();
            let u2 = sampler.get_2d();
            let Some(bs) = hit.bsdf.sample_f(&bsdf_ctx, wo, u1, u2) else {
                break;
            };
            let wi = hit.shading.to_world(bs.wi);
            // A direction below the geometric surface would leak through it.
            if wi.dot(hit.n()) * bs.wi.z <= 0.0 {
                break;
            }
            beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
            specular = bs.flags.is_specular();
            bsdf_pdf = bs.pdf;
            prev = hit.light_context();
            ray = hit.spawn_ray(wi);
            segments += 1;

            if segments > self.rr_depth {
                // Survive with probability max(beta) (pbrt-v4): paths that
                // carry little weight stop early; survivors are reweighted.
                let q = (1.0 - beta.max_component()).max(0.0);
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
        assert_eq!(p.heuristic, Heuristic::Balance);
        assert_eq!(p.max_depth, 3);
        assert_eq!(build("").unwrap().heuristic, Heuristic::Power { beta: 2.0 });
        let err = build("heuristic = \"balance\"\nbeta = 3.0\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("'beta': only applies"), "{err}");
        assert_eq!(
            build("strategy = \"bsdf\"\nheuristic = \"power\"\n")
                .unwrap()
                .strategy,
            Strategy::Bsdf
        );
        assert!(build("max_depth = 0\n").is_err());
        assert!(build("strategy = \"nee\"\n").is_err());
    }
}
