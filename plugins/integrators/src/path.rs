//! `path`: unidirectional path tracing with next-event estimation, multiple
//! importance sampling and Russian roulette (Veach 1997, ch. 9; pbrt-v4
//! `PathIntegrator`).
//!
//! Each vertex takes `n_g` light samples (next-event estimation) and `n_f`
//! BSDF samples: the first continues the path, the other `n_f - 1` only
//! look for emitters. MIS combines the two strategies, with weights from
//! [`lumis_sampling::mis`]: `estimator = "multi-sample"` takes all of them
//! (Veach eq. 9.3), `"one-sample"` one strategy per vertex, chosen with
//! probability `n_f : n_g` (Veach section 9.2.4). The estimator, shared with
//! `direct`, lives in `plugins/integrators/src/estimator.rs`. Delta lights
//! and specular lobes are told apart by flags, never by infinite pdfs. Rays
//! leave a vertex from origins offset by pbrt-v4's floating-point error
//! bounds, with no scene-scale epsilon. Russian roulette ends a path with
//! survival probability `max(beta)` after `rr_depth` segments. NaN or
//! infinite samples are counted, reported and dropped. `clamp_direct` and
//! `clamp_indirect` cap what direct and indirect light may add to a path's
//! radiance, as Cycles' clamps do (`BounceClamp`, in `path_state.rs`).
//!
//! The built-in integrators are compiled for lumis's own scene type as well
//! as for `dyn Scene` (`plugins/integrators/src/specialize.rs`), so the
//! closest-hit query inlines into the path loop; both loops give the same
//! image, bit for bit.
//!
//! The order of the loop is chosen for speed where the estimator allows
//! (the [performance log](performance-log.md) has the measurements): a
//! vertex's numbers are drawn before its intersection, whose latency they
//! then overlap; the interaction is borrowed where `intersect` wrote it
//! (moving it out of the `Option` copies 128 bytes); `wo` comes from
//! `-ray.d`, still in registers, rather than from the interaction's copy,
//! which the CPU cannot forward from the stores that wrote it; the
//! continuation's BSDF sample, a chain of dependent latencies the next ray
//! waits on, is issued before next-event estimation so that the two
//! overlap; and both offset ray origins are worked out once per vertex and
//! shared by its continuation and shadow rays.

use lumis_api::{
    Params, PluginKind, PluginParams, PluginSpec, Ray, RenderStats, Result, Rgb, Sampler, Scene,
};

use crate::estimator::{
    bsdf_context, Estimator, EstimatorParams, Heuristic, SceneView, Strategy, Vertex, VertexPlan,
};
use crate::path_state::{BounceClamp, PathState};
use crate::specialize::{integrator_by_trace, Trace};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "path",
    source: lumis_api::source_file!(),
    doc: "unidirectional path tracer: BSDF sampling, light sampling, or both combined with MIS",
    params: PathParams::SPECS,
};

/// The parameters of a path tracer, which the wavefront one shares.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct PathParams {
    /// maximum path segments from the camera: 1 = emitters seen directly, 2
    /// = direct lighting
    #[param(default = 8)]
    pub max_depth: u32,
    /// Russian roulette may end paths longer than this many segments
    /// (unbiased); large = off
    #[param(default = 5)]
    pub rr_depth: u32,
    /// largest component of direct lighting (light after one bounce) a
    /// path may add per vertex; larger contributions are scaled down
    /// (Cycles' "Clamp Direct"). Biased: trades fireflies' variance for
    /// darker highlights. Unset: no clamp
    pub clamp_direct: Option<f32>,
    /// largest component of indirect light (after two bounces or more) a
    /// path may add per vertex, as clamp_direct (Cycles' "Clamp Indirect").
    /// Unset: no clamp
    pub clamp_indirect: Option<f32>,
    #[param(flatten)]
    pub estimator: EstimatorParams,
}

#[derive(Debug, Clone)]
pub struct PathIntegrator {
    pub(crate) max_depth: u32,
    pub(crate) rr_depth: u32,
    pub(crate) clamp: BounceClamp,
    pub(crate) estimator: Estimator,
}

impl PathIntegrator {
    pub fn new(max_depth: u32, rr_depth: u32, strategy: Strategy, heuristic: Heuristic) -> Self {
        Self::with_estimator(max_depth, rr_depth, Estimator::new(strategy, heuristic))
    }

    pub fn with_estimator(max_depth: u32, rr_depth: u32, estimator: Estimator) -> Self {
        Self {
            max_depth,
            rr_depth,
            clamp: BounceClamp::NONE,
            estimator,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        Self::from_read(&PathParams::read(params)?, params)
    }

    /// The path tracer `p` describes; `params` locates errors.
    pub fn from_read(p: &PathParams, params: &Params) -> Result<Self> {
        if p.max_depth == 0 {
            return Err(params.error(
                PathParams::KEYS.max_depth,
                "must be at least 1 (1 = emitters seen directly)",
            ));
        }
        let clamp = |max: Option<f32>, key| match max {
            None => Ok(f32::INFINITY),
            Some(max) if max > 0.0 => Ok(max),
            Some(_) => Err(params.error(key, "must be positive (leave it out for no clamp)")),
        };
        Ok(Self {
            clamp: BounceClamp {
                direct: clamp(p.clamp_direct, PathParams::KEYS.clamp_direct)?,
                indirect: clamp(p.clamp_indirect, PathParams::KEYS.clamp_indirect)?,
            },
            ..Self::with_estimator(
                p.max_depth,
                p.rr_depth,
                Estimator::from_read(&p.estimator, params)?,
            )
        })
    }
}

integrator_by_trace!(PathIntegrator);

impl Trace for PathIntegrator {
    fn trace<S: Scene + ?Sized>(
        &self,
        camera_ray: &Ray,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        let mut path = PathState::new(camera_ray);
        loop {
            stats.rays += 1;
            let numbers = self.estimator.vertex_numbers(sampler);
            let found = scene.intersect(&path.ray);
            path.add_emission(
                self.estimator
                    .emission(scene, &path.ray, found.as_ref(), &path.from),
                &self.clamp,
                stats,
            );
            let Some(hit) = &found else {
                break;
            };
            if path.segments >= self.max_depth {
                break;
            }
            let wo = hit.shading.to_local(-path.ray.d);
            let plan = if hit.bsdf_flags.is_non_specular() {
                self.estimator.plan(sampler)
            } else {
                VertexPlan::UNWEIGHTED
            };
            let (u1, u2) = numbers.bsdf;
            let sampled = hit.bsdf.sample_f(&bsdf_context(hit), wo, u1, u2);
            let vertex = Vertex {
                hit,
                origins: hit.point.ray_origins(),
                wo,
            };
            if plan.light_samples > 0 {
                let l = self.estimator.sample_lights(
                    &plan,
                    &vertex,
                    scene,
                    numbers.light,
                    sampler,
                    stats,
                );
                path.add_vertex_light(l, &self.clamp);
            }
            if plan.extra_bsdf_samples > 0 {
                let l = self
                    .estimator
                    .extra_bsdf_samples(&plan, &vertex, scene, sampler, stats);
                path.add_vertex_light(l, &self.clamp);
            }
            let Some(bs) = sampled else {
                break;
            };
            if !path.continue_path(&vertex, &bs, &plan, self.rr_depth, sampler) {
                break;
            }
        }
        path.radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::doc;

    fn default_clamp() -> BounceClamp {
        build("").unwrap().clamp
    }

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
        assert_eq!(default_clamp(), BounceClamp::NONE);
        let clamp = build("clamp_direct = 4.0\nclamp_indirect = 0.5\n")
            .unwrap()
            .clamp;
        assert_eq!((clamp.direct, clamp.indirect), (4.0, 0.5));
        for (bad, key) in [
            ("clamp_direct = 0.0", "'clamp_direct': must be positive"),
            (
                "clamp_indirect = -1.0",
                "'clamp_indirect': must be positive",
            ),
            (
                "clamp_indirect = nan",
                "'clamp_indirect': expected a finite number",
            ),
        ] {
            let err = build(bad).unwrap_err().to_string();
            assert!(err.contains(key), "{bad}: {err}");
        }
        assert!(build("strategy = \"nee\"\n").is_err());
    }
}
