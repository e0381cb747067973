//! `light`: particle tracing, paths started on the lights and each vertex
//! joined to the camera (Veach 1997, section 10.2, the `t = 1` strategy of
//! bidirectional path tracing; Mitsuba 3's `ptracer`; pbrt-v4's light
//! paths in `BDPTIntegrator`).
//!
//! Each camera sample traces one path from a light chosen uniformly (as
//! Mitsuba 3's `Scene::sample_emitter`): a ray from
//! [`lumis_api::Light::sample_le`] carrying `beta = L |cos| / (pmf pdf_pos
//! pdf_dir)`. At every vertex that is not purely specular the path is
//! joined to the pinhole ([`Pinhole::sample_wi`]) and, unoccluded, adds
//! `beta f |cos| We / p` to the film where the vertex lands
//! ([`Integrator::li_splat`]); the BSDF is evaluated and sampled in
//! [`TransportMode::Importance`], with Veach's correction for shading
//! normals (1997, eq. 5.17). The camera ray itself only finds the emission
//! seen directly, so each path length is counted once: length 1 by the
//! camera, every longer one by the light. Point lights seen directly are
//! not drawn, as `path` does not draw them.
//!
//! Caustics seen through specular surfaces (a pool's floor through its
//! water, a lamp behind glass seen by a mirror) are out of reach: a
//! specular vertex cannot be joined to the camera. What the camera sees
//! of a caustic on a diffuse surface is this integrator's strength.

use lumis_api::ray::SurfacePoint;
use lumis_api::{
    BsdfContext, Integrator, Params, Pinhole, PluginKind, PluginParams, PluginSpec, Ray,
    RenderStats, Result, Rgb, Sampler, Scene, SurfaceInteraction, TransportMode, Vec2, Vec3,
};

use crate::estimator::{bsdf_context, BsdfRay, Estimator, Heuristic, SceneView, Strategy};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "light",
    source: lumis_api::source_file!(),
    doc: "particle tracing: paths from the lights, each vertex joined to the camera and added to the film where it lands; the camera ray finds only emission seen directly",
    params: LightTracerParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct LightTracerParams {
    /// maximum path segments, light to camera, counted as path counts
    /// them: 1 = emitters seen directly, 2 = direct lighting
    #[param(default = 8)]
    pub max_depth: u32,
    /// Russian roulette may end paths longer than this many segments
    /// (unbiased); large = off
    #[param(default = 5)]
    pub rr_depth: u32,
}

#[derive(Debug, Clone)]
pub struct LightTracer {
    max_depth: u32,
    rr_depth: u32,
    /// What the camera ray sees directly, unweighted.
    estimator: Estimator,
}

impl LightTracer {
    pub fn new(max_depth: u32, rr_depth: u32) -> Self {
        Self {
            max_depth,
            rr_depth,
            // Emission found by the camera ray alone: weight 1.
            estimator: Estimator::new(Strategy::Bsdf, Heuristic::Balance),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = LightTracerParams::read(params)?;
        Ok(Self::new(p.max_depth, p.rr_depth))
    }

    /// One path from the lights, its vertices added to the film through
    /// `splat`.
    fn trace_light_path(
        &self,
        scene: &dyn Scene,
        camera: &Pinhole,
        sampler: &mut dyn Sampler,
        splat: &mut dyn FnMut(Vec2, Rgb),
        stats: &mut RenderStats,
    ) {
        let lights = scene.lights();
        let u_light = sampler.get_1d();
        let (u_pos, u_dir) = (sampler.get_2d(), sampler.get_2d());
        if lights.is_empty() || self.max_depth < 2 {
            return;
        }
        let count = lights.len();
        let light = &lights[((u_light * count as f32) as usize).min(count - 1)];
        let Some(emitted) = light.sample_le(u_pos, u_dir) else {
            return;
        };
        let mut beta = emitted.beta() * count as f32;
        let mut ray = emitted.p.spawn_ray(emitted.d);
        // The light path's segments so far; joined to the camera, one more.
        for segments in 1..self.max_depth {
            if !(beta.is_finite() && beta.max_component() > 0.0) {
                return;
            }
            stats.rays += 1;
            let Some(hit) = scene.intersect(&ray) else {
                return;
            };
            let to_light = -ray.d;
            let ctx = BsdfContext {
                mode: TransportMode::Importance,
                ..bsdf_context(&hit)
            };
            let wo = hit.shading.to_local(to_light);
            // Light arriving from below the geometric surface, as the
            // shading frame has it above (or the reverse): `path` never
            // samples that direction (it would leak), so no path does.
            if to_light.dot(hit.point.n) * wo.z <= 0.0 {
                return;
            }
            if hit.bsdf_flags.is_non_specular() {
                if let Some(l) = self.seen_by_camera(&hit, &ctx, wo, to_light, camera, scene, stats)
                {
                    splat(l.0, beta * l.1);
                }
            }
            if segments + 1 >= self.max_depth {
                return;
            }
            let (u1, u2) = sampler.get_1d_2d();
            let Some(sample) = hit.bsdf.sample_f(&ctx, wo, u1, u2) else {
                return;
            };
            if sample.pdf.is_nan() || sample.pdf <= 0.0 {
                return;
            }
            let wi = hit.shading.to_world(sample.wi);
            beta *= sample.f
                * (shading_correction(&hit, to_light, wi) * sample.wi.z.abs() / sample.pdf);
            if segments + 1 > self.rr_depth {
                // Russian roulette on the carried power (pbrt-v4).
                let q = (1.0 - beta.max_component()).max(0.0);
                if sampler.get_1d() < q {
                    return;
                }
                beta *= 1.0 / (1.0 - q);
            }
            ray = hit.point.spawn_ray(wi);
        }
    }

    /// The camera seen from `hit`, where light arrives from `to_light`
    /// (`wo` in the shading frame): the film position and the factor `f
    /// |cos| We / p` the carried power takes there, if nothing blocks the
    /// way.
    #[allow(clippy::too_many_arguments)]
    fn seen_by_camera(
        &self,
        hit: &SurfaceInteraction,
        ctx: &BsdfContext,
        wo: Vec3,
        to_light: Vec3,
        camera: &Pinhole,
        scene: &dyn Scene,
        stats: &mut RenderStats,
    ) -> Option<(Vec2, Rgb)> {
        let seen = camera.sample_wi(hit.point.p)?;
        let wi = hit.shading.to_local(seen.wi);
        let f = hit.bsdf.f(ctx, wo, wi);
        if f.is_black() {
            return None;
        }
        let factor = shading_correction(hit, to_light, seen.wi) * wi.z.abs() * seen.weight;
        stats.shadow_rays += 1;
        let lens = SurfacePoint::isolated(camera.origin);
        if scene.occluded(&hit.point.spawn_ray_to(&lens)) {
            return None;
        }
        Some((seen.raster, f * factor))
    }
}

/// Veach's correction of the adjoint BSDF for shading normals (1997, eq.
/// 5.17; pbrt-v3 `CorrectShadingNormal`): light arriving from `to_light`
/// and leaving along `out` is weighted by `|to_light . ns| |out . ng| /
/// (|to_light . ng| |out . ns|)`, so that a path from the lights carries
/// what a path from the camera would; 0 for light arriving in the
/// geometric surface's plane.
fn shading_correction(hit: &SurfaceInteraction, to_light: Vec3, out: Vec3) -> f32 {
    let (ng, ns) = (hit.point.n, Vec3::from(hit.shading.z));
    let denominator = to_light.dot(ng).abs() * out.dot(ns).abs();
    if denominator == 0.0 {
        return 0.0;
    }
    to_light.dot(ns).abs() * out.dot(ng).abs() / denominator
}

impl Integrator for LightTracer {
    /// What the camera sees directly along `ray`: the rest of the estimate
    /// is what [`Integrator::li_splat`] adds to the film.
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        _sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        stats.rays += 1;
        let view = SceneView::new(scene);
        self.estimator
            .emission_along(&view, ray, &BsdfRay::camera(ray.o), stats)
    }

    fn splats(&self) -> bool {
        true
    }

    fn li_splat(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        camera: &Pinhole,
        sampler: &mut dyn Sampler,
        splat: &mut dyn FnMut(Vec2, Rgb),
        stats: &mut RenderStats,
    ) -> Rgb {
        let seen = self.li(ray, scene, sampler, stats);
        self.trace_light_path(scene, camera, sampler, splat, stats);
        seen
    }
}
