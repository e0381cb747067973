//! One bounce of a packet: every live lane's path advanced by one vertex,
//! in the order of `path`'s loop, each plugin called once per packet with
//! the lanes that need it.

use lumis_api::bsdf::{BsdfEvalLanes, BsdfSampleLanes};
use lumis_api::lanes::{Floats, LaneMask, RgbLanes, Vec2Lanes, Vec3Lanes, LANES};
use lumis_api::light::LightSampleLanes;
use lumis_api::{
    Bsdf, BsdfContext, LightKind, LightSampleContext, Ray, RenderStats, Rgb, SampledLight,
    SamplerLanes, Scene, SurfaceInteraction, Vec2,
};

use crate::estimator::{add_unshadowed, bsdf_context, Estimator, SceneView, Vertex, VertexPlan};
use crate::packet::state::PathLanes;
use crate::path::PathIntegrator;

/// The buffers of a bounce, reused from one bounce to the next.
pub struct Bounce<'a, 's> {
    path: &'a PathIntegrator,
    scene: &'a SceneView<'s, dyn Scene + 's>,
    /// The live lanes in increasing order, and the sampler lanes of a
    /// batched request for numbers: the order in which rays and numbers
    /// are batched.
    lanes: Vec<usize>,
    samplers_of: Vec<usize>,
    bsdf_u: Vec<(f32, Vec2)>,
    light_u: Vec<(f32, Vec2)>,
    rays: Vec<Ray>,
    found: Vec<Option<SurfaceInteraction<'s>>>,
    /// Per lane: which entry of `found` is its hit.
    hit_of: [usize; LANES],
    /// Per shaded lane: the BSDF at its hit.
    bsdf_of: [Option<&'s dyn Bsdf>; LANES],
    plans: [VertexPlan; LANES],
    ctx: [BsdfContext; LANES],
    wo: Vec3Lanes,
    u1: Floats,
    u2: Vec2Lanes,
    samples: BsdfSampleLanes,
    /// A round of light samples: each taker's context, the samples, and
    /// the BSDF at their directions (only the takers' lanes are read).
    light_ctx: [LightSampleContext; LANES],
    light_samples: LightSampleLanes,
    evals: BsdfEvalLanes,
    light_sums: RgbLanes,
    shadow_rays: Vec<Ray>,
    shadow_lanes: Vec<(usize, Rgb)>,
    blocked: Vec<bool>,
    numbers: Vec<(f32, Vec2)>,
}

impl<'a, 's> Bounce<'a, 's> {
    pub fn new(path: &'a PathIntegrator, scene: &'a SceneView<'s, dyn Scene + 's>) -> Self {
        Self {
            path,
            scene,
            lanes: Vec::with_capacity(LANES),
            samplers_of: Vec::with_capacity(LANES),
            bsdf_u: Vec::with_capacity(LANES),
            light_u: Vec::with_capacity(LANES),
            rays: Vec::with_capacity(LANES),
            found: Vec::with_capacity(LANES),
            hit_of: [0; LANES],
            bsdf_of: [None; LANES],
            plans: [VertexPlan::UNWEIGHTED; LANES],
            ctx: [BsdfContext::default(); LANES],
            wo: Vec3Lanes::default(),
            u1: [0.0; LANES],
            u2: Vec2Lanes::default(),
            samples: BsdfSampleLanes::default(),
            light_ctx: [LightSampleContext::at(Default::default()); LANES],
            light_samples: LightSampleLanes::default(),
            evals: BsdfEvalLanes::default(),
            light_sums: RgbLanes::default(),
            shadow_rays: Vec::with_capacity(LANES),
            shadow_lanes: Vec::with_capacity(LANES),
            blocked: Vec::with_capacity(LANES),
            numbers: Vec::with_capacity(LANES),
        }
    }

    fn estimator(&self) -> &'a Estimator {
        &self.path.estimator
    }

    fn hit(&self, lane: usize) -> &SurfaceInteraction<'s> {
        self.found[self.hit_of[lane]]
            .as_ref()
            .expect("a shaded lane has a hit")
    }

    fn vertex(&self, lane: usize) -> Vertex<'_> {
        let hit = self.hit(lane);
        Vertex {
            hit,
            origins: hit.point.ray_origins(),
            wo: self.wo.get(lane),
        }
    }

    /// Advances every live lane of `paths` by one vertex; returns the lanes
    /// whose paths ended.
    pub fn run(
        &mut self,
        paths: &mut PathLanes,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
    ) -> LaneMask {
        let estimator = self.estimator();
        self.lanes.clear();
        self.lanes.extend(paths.live.iter());
        self.samplers_of.clear();
        self.samplers_of
            .extend(self.lanes.iter().map(|&lane| paths.path[lane]));
        estimator.vertex_numbers_batch(
            samplers,
            &self.samplers_of,
            &mut self.bsdf_u,
            &mut self.light_u,
        );
        self.rays.clear();
        self.rays
            .extend(self.lanes.iter().map(|&lane| paths.ray(lane)));
        self.found.clear();
        self.found.resize(self.rays.len(), None);
        stats.rays += self.rays.len() as u64;
        self.scene
            .scene
            .intersect_batch(&self.rays, &mut self.found);

        // Emission, then the lanes whose paths go on to a vertex.
        let mut ended = LaneMask::NONE;
        let mut shaded = LaneMask::NONE;
        for (k, &lane) in self.lanes.iter().enumerate() {
            let mut state = paths.get(lane);
            let found = self.found[k].as_ref();
            state.add_emission(
                estimator.emission(self.scene, &state.ray, found, &state.from),
                &self.path.clamp,
                stats,
            );
            paths.radiance.set(lane, state.radiance);
            let Some(hit) = found else {
                ended.set(lane, true);
                continue;
            };
            if state.segments >= self.path.max_depth {
                ended.set(lane, true);
                continue;
            }
            shaded.set(lane, true);
            self.hit_of[lane] = k;
            self.bsdf_of[lane] = Some(hit.bsdf);
            self.plans[lane] = if hit.bsdf_flags.is_non_specular() {
                samplers.with_lane(paths.path[lane], |sampler| estimator.plan(sampler))
            } else {
                VertexPlan::UNWEIGHTED
            };
            self.ctx[lane] = bsdf_context(hit);
            self.wo.set(lane, hit.shading.to_local(-state.ray.d));
            let (u1, u2) = self.bsdf_u[k];
            self.u1[lane] = u1;
            self.u2.set(lane, u2);
        }

        self.sample_bsdfs(shaded);
        self.sample_lights(paths, samplers, shaded, stats);
        let clamp = &self.path.clamp;
        for lane in shaded.iter() {
            let plan = self.plans[lane];
            let mut state = paths.get(lane);
            if plan.light_samples > 0 {
                state.add_vertex_light(self.light_sums.get(lane) * plan.light_scale, clamp);
            }
            if plan.extra_bsdf_samples > 0 {
                let vertex = self.vertex(lane);
                let l = samplers.with_lane(paths.path[lane], |sampler| {
                    estimator.extra_bsdf_samples(&plan, &vertex, self.scene, sampler, stats)
                });
                state.add_vertex_light(l, clamp);
            }
            paths.radiance.set(lane, state.radiance);
        }

        for lane in shaded.iter() {
            let Some(bs) = self.samples.get(lane) else {
                ended.set(lane, true);
                continue;
            };
            let mut state = paths.get(lane);
            let (vertex, plan) = (self.vertex(lane), self.plans[lane]);
            let going_on = samplers.with_lane(paths.path[lane], |sampler| {
                state.continue_path(&vertex, &bs, &plan, self.path.rr_depth, sampler)
            });
            paths.set(lane, &state);
            if !going_on {
                ended.set(lane, true);
            }
        }
        ended
    }

    /// The continuation's BSDF sample of each lane of `lanes`, into
    /// `self.samples`: one call per BSDF.
    fn sample_bsdfs(&mut self, lanes: LaneMask) {
        self.samples.valid = LaneMask::NONE;
        for (bsdf, group) in by_bsdf(lanes, self.bsdf_of) {
            bsdf.sample_f_lanes(
                &self.ctx,
                &self.wo,
                &self.u1,
                &self.u2,
                group,
                &mut self.samples,
            );
        }
    }

    /// Next-event estimation at the vertex of each lane of `lanes`: into
    /// `self.light_sums`, the unscaled sum of its plan's light samples, as
    /// `Estimator::sample_lights` before its scale, in rounds of one sample
    /// per lane.
    fn sample_lights(
        &mut self,
        paths: &PathLanes,
        samplers: &mut dyn SamplerLanes,
        lanes: LaneMask,
        stats: &mut RenderStats,
    ) {
        let (estimator, scene) = (self.estimator(), self.scene);
        self.light_sums = RgbLanes::default();
        let rounds = lanes
            .iter()
            .map(|lane| self.plans[lane].light_samples)
            .max();
        for round in 0..rounds.unwrap_or(0) {
            let takers = mask_where(lanes, |lane| self.plans[lane].light_samples > round);
            // The first round's numbers came with the vertex's; later
            // rounds draw theirs here.
            let mut numbers = [(0.0, Vec2::ZERO); LANES];
            if round == 0 {
                for (k, &lane) in self.lanes.iter().enumerate() {
                    numbers[lane] = self.light_u[k];
                }
            } else {
                self.samplers_of.clear();
                self.samplers_of
                    .extend(takers.iter().map(|lane| paths.path[lane]));
                self.numbers.clear();
                self.numbers
                    .resize(self.samplers_of.len(), (0.0, Vec2::ZERO));
                samplers.get_1d_2d_batch(&self.samplers_of, &mut self.numbers);
                for (lane, &u) in takers.iter().zip(&self.numbers) {
                    numbers[lane] = u;
                }
            }

            // Choose a light per lane, then one call per light chosen.
            let mut chosen = [None::<SampledLight>; LANES];
            let mut u = Vec2Lanes::default();
            for lane in takers.iter() {
                let ctx = self.hit(lane).light_context();
                chosen[lane] = scene.light_sampler.sample(&ctx, numbers[lane].0);
                self.light_ctx[lane] = ctx;
                u.set(lane, numbers[lane].1);
            }
            let light_samples = &mut self.light_samples;
            light_samples.valid = LaneMask::NONE;
            let choosers = mask_where(takers, |lane| chosen[lane].is_some());
            for (first, group) in groups(choosers, |lane| chosen[lane].map(|c| c.index)) {
                let index = chosen[first].expect("a lane that chose a light").index;
                let light = &scene.lights[index as usize];
                light.sample_li_lanes(&self.light_ctx, &u, group, light_samples);
            }

            // The BSDF at each sampled direction, one call per BSDF.
            let sampled = self.light_samples.valid & takers;
            let mut wi = Vec3Lanes::default();
            for lane in sampled.iter() {
                wi.set(
                    lane,
                    self.hit(lane)
                        .shading
                        .to_local(self.light_samples.wi.get(lane)),
                );
            }
            self.evals.valid = LaneMask::NONE;
            for (bsdf, group) in by_bsdf(sampled, self.bsdf_of) {
                bsdf.eval_lanes(&self.ctx, &self.wo, &wi, group, &mut self.evals);
            }

            self.shadow_rays.clear();
            self.shadow_lanes.clear();
            for lane in sampled.iter() {
                let chosen = chosen[lane].expect("a sampled lane chose a light");
                let ls = self.light_samples.get(lane).expect("a sampled lane");
                let delta = scene.lights[chosen.index as usize].kind() == LightKind::DeltaPosition;
                let (f, p_bsdf) = self.evals.get(lane);
                let p_bsdf = if delta { 0.0 } else { p_bsdf };
                let wi_z = wi.z[lane];
                if let Some(unshadowed) =
                    estimator.light_contribution(chosen.pmf, &ls, delta, f, p_bsdf, wi_z)
                {
                    self.shadow_lanes.push((lane, unshadowed()));
                    self.shadow_rays
                        .push(self.hit(lane).point.ray_origins().spawn_ray_to(&ls.p));
                }
            }
            let light_sums = &mut self.light_sums;
            add_unshadowed(
                scene,
                &self.shadow_rays,
                &self.shadow_lanes,
                &mut self.blocked,
                stats,
                |lane, unshadowed| light_sums.set(lane, light_sums.get(lane) + unshadowed),
            );
        }
    }
}

/// The lanes of `lanes` where `holds`.
fn mask_where(lanes: LaneMask, holds: impl Fn(usize) -> bool) -> LaneMask {
    let mut mask = LaneMask::NONE;
    for lane in lanes.iter() {
        mask.set(lane, holds(lane));
    }
    mask
}

/// The lanes of `lanes` grouped by `key`, each group as its first lane and
/// its mask, in the order of their first lanes.
fn groups<K: PartialEq>(
    lanes: LaneMask,
    key: impl Fn(usize) -> K,
) -> impl Iterator<Item = (usize, LaneMask)> {
    let mut rest = lanes;
    std::iter::from_fn(move || {
        let first = rest.iter().next()?;
        let first_key = key(first);
        let group = mask_where(rest, |lane| key(lane) == first_key);
        rest = rest & !group;
        Some((first, group))
    })
}

/// The lanes of `lanes` grouped by their BSDF (`bsdf_of`), each BSDF with
/// the mask of its lanes.
fn by_bsdf(
    lanes: LaneMask,
    bsdf_of: [Option<&dyn Bsdf>; LANES],
) -> impl Iterator<Item = (&dyn Bsdf, LaneMask)> {
    let identity =
        move |lane: usize| bsdf_of[lane].map(|bsdf| (bsdf as *const dyn Bsdf).cast::<()>());
    groups(lanes, identity)
        .map(move |(first, group)| (bsdf_of[first].expect("a shaded lane has a BSDF"), group))
}
