//! `wavefront`: the `path` estimator advanced a wave of paths at a time
//! (Laine, Karras and Aila 2013, "Megakernels Considered Harmful:
//! Wavefront Path Tracing on GPUs"; pbrt-v4's `WavefrontPathIntegrator`).
//!
//! # Stages
//!
//! A wave holds `wave_size` paths (256 by default). Each bounce runs as
//! stages over every live path of the wave: draw the vertex's numbers (one
//! batched request per kind, [`SamplerLanes::get_1d_2d_batch`]), trace all
//! rays ([`Scene::intersect_batch`]: SIMD packets in the renderer's scene),
//! add the emission they find, sample every BSDF grouped by material
//! ([`lumis_api::Bsdf::sample_f_batch`]), sample the lights grouped by light
//! ([`lumis_api::Light::sample_li_batch`]), evaluate the BSDFs at the
//! light samples grouped by material ([`lumis_api::Bsdf::eval_batch`]),
//! trace all shadow rays ([`Scene::occluded_batch`]), and continue each
//! path as `path` does ([`PathState`], shared by both). Every stage sees
//! many independent lanes of one kind, which a plugin may compute with SIMD.
//! A lane whose path ends takes the next camera ray, so the wave stays full
//! through the bounces (regeneration, Laine et al. section 4).
//!
//! The render driver hands the integrator its batch of camera rays: a run of
//! a tile's pixels, several samples of each, with one sampler per lane
//! ([`Sampler::lanes`]) that keeps its pixel for all its samples, so that
//! per-pixel work (the Sobol' sampler's scramble seeds) is done once per
//! pixel, as in `path`.
//!
//! # The same image as `path`
//!
//! The batched methods default to loops over the scalar ones, so every
//! plugin works in a wave unchanged; a plugin that overrides them computes
//! its lanes together. The arithmetic of each path is `path`'s, in the same
//! order, and each path draws its sampler's numbers in the same order: with
//! plugins and a scene that keep the scalar defaults, the two integrators
//! give the same image bit for bit (`tests/batched_integrators.rs`). The
//! overrides of the built-in plugins and Embree's packet traversal change
//! only the rounding, and the images agree in the mean; on the bench scenes
//! they are still the same bit for bit, since the conductor's SIMD
//! `eval_batch` and `sample_f_batch` and the sphere light's SIMD
//! `sample_li_batch` repeat the scalar methods' operations on eight lanes,
//! and Embree's packets find the same hits as its single rays.
//!
//! Camera rays go to Embree as coherent packets of eight;
//! `[accel] packets = true` sends bounce and shadow rays as packets too
//! (see [the scene format](scene-format.md#acceleration-structure-accel)).
//! Both integrators run the same furnace, analytic and strategy-agreement
//! tests (`tests/furnace.rs`, `tests/quad_irradiance.rs`,
//! `tests/light_scenes.rs`). What the wave costs and buys on the bench
//! suite is in [Performance](performance.md#the-wavefront-integrator).

mod batched;

use lumis_api::{
    BsdfSample, Integrator, LightKind, LightSample, LightSampleContext, Params, PluginKind,
    PluginParams, PluginSpec, Ray, RenderStats, Result, Rgb, SampledLight, Sampler, SamplerLanes,
    Scene, SurfaceInteraction, Vec2, Vec3,
};

use crate::estimator::{
    add_unshadowed, bsdf_context, extra_sample_ray, SceneView, Vertex, VertexPlan,
};
use crate::path::{PathIntegrator, PathParams};
use crate::path_state::PathState;
use batched::{Batcher, BsdfLane};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "wavefront",
    source: lumis_api::source_file!(),
    doc: "the path tracer run a wave of paths at a time: each bounce traces all rays as packets and calls every BSDF and light once per wave, so plugins may compute lanes with SIMD; same estimate as path",
    params: WavefrontParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct WavefrontParams {
    #[param(flatten)]
    pub path: PathParams,
    /// camera rays (paths) advanced together; more lanes fill the batched
    /// calls better, at the cost of memory
    #[param(default = 256, range = (1, 65536))]
    pub wave_size: usize,
}

/// Camera rays per wave lane that one [`Integrator::li_batch`] call takes.
const REGENERATIONS: usize = 8;

pub struct WavefrontIntegrator {
    /// The estimator's settings, and the scalar loop for a single ray.
    path: PathIntegrator,
    wave_size: usize,
}

impl WavefrontIntegrator {
    pub fn new(path: PathIntegrator, wave_size: usize) -> Self {
        Self {
            path,
            wave_size: wave_size.max(1),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = WavefrontParams::read(params)?;
        Ok(Self::new(
            PathIntegrator::from_read(&p.path, params)?,
            p.wave_size,
        ))
    }
}

/// A path vertex of the wave: its lane and what `path` knows there, the
/// hit left where the scene query wrote it (`Wave::found[found]`): moved,
/// it would cost a `memcpy` per vertex.
struct WaveVertex {
    lane: usize,
    found: usize,
    wo: Vec3,
    plan: VertexPlan,
}

impl WaveVertex {
    fn vertex<'a>(&self, hit: &'a SurfaceInteraction) -> Vertex<'a> {
        Vertex {
            hit,
            origins: hit.point.ray_origins(),
            wo: self.wo,
        }
    }

    fn bsdf_lane<'s>(&self, hit: &SurfaceInteraction<'s>) -> BsdfLane<'s> {
        BsdfLane {
            bsdf: hit.bsdf,
            ctx: bsdf_context(hit),
            wo: self.wo,
        }
    }
}

/// The hit of `v`, which every vertex has.
fn hit_of<'a, 's>(
    found: &'a [Option<SurfaceInteraction<'s>>],
    v: &WaveVertex,
) -> &'a SurfaceInteraction<'s> {
    found[v.found].as_ref().expect("a wave vertex is a hit")
}

/// Everything a wave keeps between stages and bounces, allocated once per
/// wave: the paths, and the buffers each stage fills for the next.
struct Wave<'s> {
    paths: Vec<PathState>,
    live: Vec<usize>,
    rays: Vec<Ray>,
    found: Vec<Option<SurfaceInteraction<'s>>>,
    vertices: Vec<WaveVertex>,
    bsdf_lanes: Vec<BsdfLane<'s>>,
    /// The vertices' numbers (`Estimator::vertex_numbers_batch`): the
    /// BSDF sample's and the first light sample's.
    bsdf_u: Vec<(f32, Vec2)>,
    light_u: Vec<(f32, Vec2)>,
    continuations: Vec<Option<BsdfSample>>,
    light_sums: Vec<Rgb>,
    extra_sums: Vec<Rgb>,
    lights: LightStage,
    batcher: Batcher,
}

/// The buffers of one round of light samples.
#[derive(Default)]
struct LightStage {
    /// The lanes drawing a later round's numbers, and the numbers.
    lanes: Vec<usize>,
    numbers: Vec<(f32, Vec2)>,
    takers: Vec<usize>,
    chosen: Vec<SampledLight>,
    ctx: Vec<LightSampleContext>,
    u: Vec<Vec2>,
    light_of: Vec<u32>,
    samples: Vec<Option<LightSample>>,
    sampled: Vec<usize>,
    /// The vertex of each sampled light sample.
    vertex_of: Vec<usize>,
    wi: Vec<Vec3>,
    evals: Vec<(Rgb, f32)>,
    /// The light samples waiting for their shadow rays: (vertex,
    /// unshadowed contribution).
    pending: Vec<(usize, Rgb)>,
    shadow_rays: Vec<Ray>,
    blocked: Vec<bool>,
}

impl Wave<'_> {
    /// A wave of `n` lanes over `camera_rays`, none started yet.
    fn new(camera_rays: &[Ray], n: usize) -> Self {
        Self {
            paths: camera_rays.iter().map(PathState::new).collect(),
            live: Vec::with_capacity(n),
            rays: Vec::with_capacity(n),
            found: Vec::with_capacity(n),
            vertices: Vec::with_capacity(n),
            bsdf_lanes: Vec::with_capacity(n),
            bsdf_u: Vec::with_capacity(n),
            light_u: Vec::with_capacity(n),
            continuations: Vec::with_capacity(n),
            light_sums: Vec::with_capacity(n),
            extra_sums: Vec::with_capacity(n),
            lights: LightStage::default(),
            batcher: Batcher::default(),
        }
    }
}

impl Integrator for WavefrontIntegrator {
    /// A single ray is a wave of one: `path`'s scalar loop.
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        self.path.li(ray, scene, sampler, stats)
    }

    /// Several waves' worth: a lane whose path ends takes the next camera
    /// ray, so the wave stays full through the bounces (Laine et al. 2013,
    /// section 4: regeneration) and its buffers serve many paths.
    fn batch_size(&self) -> usize {
        self.wave_size * REGENERATIONS
    }

    fn li_batch(
        &self,
        rays: &[Ray],
        scene: &dyn Scene,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
        out: &mut [Rgb],
    ) {
        let scene = SceneView::new(scene);
        let mut wave = Wave::new(rays, self.wave_size);
        let mut unstarted = 0..rays.len();
        loop {
            let room = self.wave_size - wave.live.len();
            wave.live.extend(unstarted.by_ref().take(room));
            if wave.live.is_empty() {
                break;
            }
            self.bounce(&scene, &mut wave, samplers, stats);
        }
        for (out, path) in out.iter_mut().zip(&wave.paths) {
            *out = path.radiance;
        }
    }
}

impl WavefrontIntegrator {
    /// Advances every live path of `wave` by one vertex.
    fn bounce<'s>(
        &self,
        scene: &SceneView<'s, dyn Scene + 's>,
        wave: &mut Wave<'s>,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
    ) {
        let estimator = &self.path.estimator;
        estimator.vertex_numbers_batch(samplers, &wave.live, &mut wave.bsdf_u, &mut wave.light_u);
        wave.rays.clear();
        wave.rays
            .extend(wave.live.iter().map(|&lane| wave.paths[lane].ray));
        wave.found.clear();
        wave.found.resize(wave.rays.len(), None);
        stats.rays += wave.rays.len() as u64;
        scene.scene.intersect_batch(&wave.rays, &mut wave.found);

        // Emission, then the vertices where the paths go on; their numbers
        // follow them.
        wave.vertices.clear();
        let mut kept = 0;
        for (k, found) in wave.found.iter().enumerate() {
            let lane = wave.live[k];
            let path = &mut wave.paths[lane];
            path.add_emission(
                estimator.emission(scene, &path.ray, found.as_ref(), &path.from),
                &self.path.clamp,
                stats,
            );
            let Some(hit) = found else {
                continue;
            };
            if path.segments >= self.path.max_depth {
                continue;
            }
            let plan = if hit.bsdf_flags.is_non_specular() {
                samplers.with_lane(lane, |sampler| estimator.plan(sampler))
            } else {
                VertexPlan::UNWEIGHTED
            };
            wave.vertices.push(WaveVertex {
                lane,
                found: k,
                wo: hit.shading.to_local(-path.ray.d),
                plan,
            });
            wave.bsdf_u[kept] = wave.bsdf_u[k];
            wave.light_u[kept] = wave.light_u[k];
            kept += 1;
        }
        wave.bsdf_u.truncate(kept);
        wave.light_u.truncate(kept);
        wave.bsdf_lanes.clear();
        let found = &wave.found;
        wave.bsdf_lanes
            .extend(wave.vertices.iter().map(|v| v.bsdf_lane(hit_of(found, v))));
        wave.batcher
            .sample_f(&wave.bsdf_lanes, &wave.bsdf_u, &mut wave.continuations);

        self.sample_lights(scene, wave, samplers, stats);
        self.extra_bsdf_samples(scene, wave, samplers, stats);
        for (k, v) in wave.vertices.iter().enumerate() {
            let path = &mut wave.paths[v.lane];
            let clamp = &self.path.clamp;
            if v.plan.light_samples > 0 {
                path.add_vertex_light(wave.light_sums[k] * v.plan.light_scale, clamp);
            }
            if v.plan.extra_bsdf_samples > 0 {
                path.add_vertex_light(wave.extra_sums[k], clamp);
            }
        }

        wave.live.clear();
        for (v, sampled) in wave.vertices.iter().zip(&wave.continuations) {
            let hit = hit_of(&wave.found, v);
            let Some(bs) = sampled else {
                continue;
            };
            let path = &mut wave.paths[v.lane];
            let (vertex, rr_depth) = (v.vertex(hit), self.path.rr_depth);
            let going_on = samplers.with_lane(v.lane, |sampler| {
                path.continue_path(&vertex, bs, &v.plan, rr_depth, sampler)
            });
            if going_on {
                wave.live.push(v.lane);
            }
        }
    }

    /// Next-event estimation at every vertex of the wave: into
    /// `wave.light_sums`, the unscaled sum of its plan's light samples (as
    /// `Estimator::sample_lights` before its scale), taken in rounds of one
    /// sample per vertex.
    fn sample_lights<'s>(
        &self,
        scene: &SceneView<'s, dyn Scene + 's>,
        wave: &mut Wave<'s>,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
    ) {
        let estimator = &self.path.estimator;
        let vertices = &wave.vertices;
        let stage = &mut wave.lights;
        wave.light_sums.clear();
        wave.light_sums.resize(vertices.len(), Rgb::BLACK);
        let rounds = vertices.iter().map(|v| v.plan.light_samples).max();
        for round in 0..rounds.unwrap_or(0) {
            // Choose a light at every vertex taking a sample this round.
            stage.takers.clear();
            stage.chosen.clear();
            stage.ctx.clear();
            stage.u.clear();
            // The first round's numbers came with the vertex's; the later
            // rounds' are drawn here, one batched request per round.
            if round > 0 {
                stage.lanes.clear();
                stage.lanes.extend(
                    vertices
                        .iter()
                        .filter(|v| v.plan.light_samples > round)
                        .map(|v| v.lane),
                );
                stage.numbers.resize(stage.lanes.len(), (0.0, Vec2::ZERO));
                samplers.get_1d_2d_batch(&stage.lanes, &mut stage.numbers);
            }
            let mut later_numbers = stage.numbers.iter();
            for (k, v) in vertices.iter().enumerate() {
                if v.plan.light_samples <= round {
                    continue;
                }
                let (u_light, u_point) = match round {
                    0 => wave.light_u[k],
                    _ => *later_numbers.next().expect("one per taker"),
                };
                let here = hit_of(&wave.found, v).light_context();
                if let Some(light) = scene.light_sampler.sample(&here, u_light) {
                    stage.takers.push(k);
                    stage.chosen.push(light);
                    stage.ctx.push(here);
                    stage.u.push(u_point);
                }
            }
            stage.light_of.clear();
            stage.light_of.extend(stage.chosen.iter().map(|c| c.index));
            wave.batcher.sample_li(
                scene.lights,
                &stage.light_of,
                &stage.ctx,
                &stage.u,
                &mut stage.samples,
            );

            // The BSDF at each sampled direction.
            stage.sampled.clear();
            stage.vertex_of.clear();
            stage.wi.clear();
            for (j, ls) in stage.samples.iter().enumerate() {
                if let Some(ls) = ls {
                    let k = stage.takers[j];
                    stage.sampled.push(j);
                    stage.vertex_of.push(k);
                    stage
                        .wi
                        .push(hit_of(&wave.found, &vertices[k]).shading.to_local(ls.wi));
                }
            }
            wave.batcher.eval(
                &wave.bsdf_lanes,
                &stage.vertex_of,
                &stage.wi,
                &mut stage.evals,
            );

            stage.pending.clear();
            stage.shadow_rays.clear();
            for ((&j, &(f, p_bsdf)), wi) in stage.sampled.iter().zip(&stage.evals).zip(&stage.wi) {
                let k = stage.takers[j];
                let Some(ls) = &stage.samples[j] else {
                    continue;
                };
                let chosen = stage.chosen[j];
                let delta = scene.lights[chosen.index as usize].kind() == LightKind::DeltaPosition;
                let p_bsdf = if delta { 0.0 } else { p_bsdf };
                if let Some(unshadowed) =
                    estimator.light_contribution(chosen.pmf, ls, delta, f, p_bsdf, wi.z)
                {
                    stage.pending.push((k, unshadowed()));
                    stage.shadow_rays.push(
                        hit_of(&wave.found, &vertices[k])
                            .point
                            .ray_origins()
                            .spawn_ray_to(&ls.p),
                    );
                }
            }
            let light_sums = &mut wave.light_sums;
            add_unshadowed(
                scene,
                &stage.shadow_rays,
                &stage.pending,
                &mut stage.blocked,
                stats,
                |k, unshadowed| light_sums[k] += unshadowed,
            );
        }
    }

    /// Into `wave.extra_sums`, the emission found by every vertex's extra
    /// BSDF samples (as `Estimator::extra_bsdf_samples`), in rounds of one
    /// per vertex. Only `n_f > 1` takes them, so the buffers are the
    /// round's own.
    fn extra_bsdf_samples<'s>(
        &self,
        scene: &SceneView<'s, dyn Scene + 's>,
        wave: &mut Wave<'s>,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
    ) {
        let estimator = &self.path.estimator;
        let vertices = &wave.vertices;
        wave.extra_sums.clear();
        wave.extra_sums.resize(vertices.len(), Rgb::BLACK);
        let rounds = vertices.iter().map(|v| v.plan.extra_bsdf_samples).max();
        for round in 0..rounds.unwrap_or(0) {
            let takers: Vec<usize> = (0..vertices.len())
                .filter(|&k| vertices[k].plan.extra_bsdf_samples > round)
                .collect();
            let taker_lanes: Vec<usize> = takers.iter().map(|&k| vertices[k].lane).collect();
            let mut u = vec![(0.0, Vec2::ZERO); takers.len()];
            samplers.get_1d_2d_batch(&taker_lanes, &mut u);
            let lanes: Vec<BsdfLane> = takers.iter().map(|&k| wave.bsdf_lanes[k].clone()).collect();
            let mut bsdf_samples = Vec::new();
            wave.batcher.sample_f(&lanes, &u, &mut bsdf_samples);
            let mut traced = Vec::new();
            for (&k, bs) in takers.iter().zip(&bsdf_samples) {
                let v = &vertices[k];
                if let Some(ray) = bs
                    .as_ref()
                    .and_then(|bs| extra_sample_ray(&v.plan, &v.vertex(hit_of(&wave.found, v)), bs))
                {
                    traced.push((k, ray));
                }
            }
            let rays: Vec<Ray> = traced.iter().map(|(_, (_, ray, _))| *ray).collect();
            let mut found = vec![None; rays.len()];
            stats.rays += rays.len() as u64;
            scene.scene.intersect_batch(&rays, &mut found);
            for ((k, (throughput, ray, from)), found) in traced.iter().zip(&found) {
                let (le, emitters) = estimator.emission(scene, ray, found.as_ref(), from);
                stats.bsdf_light_hits += emitters;
                wave.extra_sums[*k] += *throughput * le;
            }
        }
    }
}
