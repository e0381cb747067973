//! The direct-lighting estimator shared by `path` and `direct`: which
//! strategies find emission, how many samples each takes at a vertex, and
//! the multiple importance sampling weights that combine them (Veach 1997,
//! chapter 9; Veach and Guibas 1995, "Optimally Combining Sampling
//! Techniques for Monte Carlo Rendering").
//!
//! Strategy f samples the BSDF (`n_f` directions per vertex), strategy g
//! samples the lights (`n_g` points per vertex). The multi-sample estimator
//! (Veach eq. 9.3) is
//!
//! ```text
//! F = sum_i 1/n_i sum_j w_i(X_ij) f(X_ij) / p_i(X_ij),   i in {f, g}
//! ```
//!
//! with `w_i = n_i p_i / sum_k n_k p_k` (balance, eq. 9.4) or
//! `(n_i p_i)^beta / sum_k (n_k p_k)^beta` (power, eq. 9.12). The one-sample
//! estimator (section 9.2.4) draws a single sample from strategy i chosen
//! with probability `c_i = n_i / (n_f + n_g)` and returns
//! `w_i(X) f(X) / (c_i p_i(X))`; the balance heuristic is optimal for it
//! (Theorem 9.4), the power heuristic stays unbiased.
//!
//! Delta lights (pdf_li = 0 for every BSDF direction) and specular BSDFs
//! (no light sample can find their direction) take weight 1 by flags, never
//! by infinite densities.

use lumis_api::bsdf::{BsdfContext, BsdfSample};
use lumis_api::ray::RayOrigins;
use lumis_api::{
    Light, LightIndex, LightKind, LightSample, LightSampleContext, LightSampler, ParamChoice,
    Params, PluginParams, Ray, RenderStats, Result, Rgb, Sampler, SamplerLanes, Scene,
    SurfaceInteraction, Vec2, Vec3,
};
use lumis_sampling::{balance_heuristic, power_heuristic};

/// The parameters every integrator built on [`Estimator`] accepts.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct EstimatorParams {
    /// "bsdf" (emission found by BSDF sampling only), "light" (next-event
    /// estimation only) or "mis" (both, weighted)
    #[param(default = Mis)]
    pub strategy: Strategy,
    /// MIS weights with strategy = "mis": "balance" or "power"
    #[param(default = Power)]
    pub heuristic: HeuristicName,
    /// exponent of the power heuristic
    #[param(default = 2.0)]
    pub beta: f32,
    /// BSDF samples per vertex for direct lighting (the first also continues
    /// the path)
    #[param(default = 1, range = (1, 64))]
    pub n_f: u32,
    /// light samples per vertex (next-event estimation)
    #[param(default = 1, range = (1, 64))]
    pub n_g: u32,
    /// with strategy = "mis": "multi-sample" takes n_f BSDF and n_g light
    /// samples per vertex (Veach eq. 9.3); "one-sample" takes one, from the
    /// BSDF or the lights with probability n_f : n_g (Veach section 9.2.4)
    #[param(default = MultiSample)]
    pub estimator: MisEstimator,
}

/// The `heuristic` choice; [`Heuristic`] adds the power's exponent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum HeuristicName {
    Balance,
    Power,
}

/// The scene as the estimators use it: traversal plus its lights. The
/// light list, the light sampler and the infinite lights are read from the
/// scene once per path instead of through a virtual call at every vertex.
/// `S` is the concrete scene type where the integrator was compiled for it
/// (see [`crate::Specialized`]), else `dyn Scene`.
pub struct SceneView<'a, S: ?Sized = dyn Scene> {
    pub scene: &'a S,
    pub lights: &'a [Box<dyn Light>],
    pub light_sampler: &'a dyn LightSampler,
    pub infinite_lights: &'a [u32],
}

impl<S: ?Sized> Clone for SceneView<'_, S> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<S: ?Sized> Copy for SceneView<'_, S> {}

impl<'a, S: Scene + ?Sized> SceneView<'a, S> {
    pub fn new(scene: &'a S) -> Self {
        Self {
            scene,
            lights: scene.lights(),
            light_sampler: scene.light_sampler(),
            infinite_lights: scene.infinite_lights(),
        }
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'a>> {
        self.scene.intersect(ray)
    }

    #[inline]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.scene.occluded(ray)
    }
}

/// Which estimator finds emission.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Strategy {
    Bsdf,
    Light,
    Mis,
}

/// How MIS weights the two strategies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heuristic {
    Balance,
    Power { beta: f32 },
}

impl Heuristic {
    /// The weight of a sample of a strategy taking `n_own` samples of
    /// density `p_own`, against `n_other` samples of density `p_other`.
    #[inline]
    pub fn weight(self, n_own: u32, p_own: f32, n_other: u32, p_other: f32) -> f32 {
        match self {
            Heuristic::Balance => balance_heuristic(n_own, p_own, n_other, p_other),
            Heuristic::Power { beta } => power_heuristic(n_own, p_own, n_other, p_other, beta),
        }
    }
}

/// Veach's two ways of combining the strategies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum MisEstimator {
    MultiSample,
    OneSample,
}

/// What one vertex does for direct lighting, decided before sampling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexPlan {
    /// Light samples to take here.
    pub light_samples: u32,
    /// Extra BSDF samples to trace for emission only (beyond the one that
    /// continues the path).
    pub extra_bsdf_samples: u32,
    /// Factor on every light sample's weighted contribution: `1 / n_g`, or
    /// `1 / c_g` for the one-sample estimator.
    pub light_scale: f32,
    /// Factor on emission found by this vertex's BSDF samples: `1 / n_f`,
    /// `1 / c_f`, 0 when the BSDF may not find emission, 1 after a
    /// specular bounce.
    pub bsdf_scale: f32,
}

impl VertexPlan {
    /// What a camera ray or a specular bounce carries: emission counts fully.
    pub const UNWEIGHTED: VertexPlan = VertexPlan {
        light_samples: 0,
        extra_bsdf_samples: 0,
        light_scale: 0.0,
        bsdf_scale: 1.0,
    };
}

/// A path vertex as the estimator sees it: the interaction, where rays
/// leaving it start, and `wo` in its shading frame. Built once per vertex
/// by the integrator and read by every strategy there.
#[derive(Clone, Copy)]
pub struct Vertex<'a> {
    pub hit: &'a SurfaceInteraction<'a>,
    pub origins: RayOrigins,
    pub wo: Vec3,
}

impl Vertex<'_> {
    #[inline]
    pub fn bsdf_context(&self) -> BsdfContext {
        bsdf_context(self.hit)
    }
}

/// What the BSDF at `hit` is evaluated with.
#[inline]
pub fn bsdf_context(hit: &SurfaceInteraction) -> BsdfContext {
    BsdfContext {
        texture: hit.texture,
        ..Default::default()
    }
}

/// The ray that an extra BSDF sample `bs` at `vertex` traces for emission,
/// with its throughput f cos / pdf and how it was sampled; `None` for a
/// sample that leaks below the geometric surface, or a specular one: the
/// specular lobes' emission is the continuation's alone (it counts it with
/// scale 1, as no light sample can find it); counted here too it would be
/// counted 1 + (n_f - 1) P(specular) times. Extra samples estimate the
/// non-specular part, with the continuation, each at 1/n_f.
#[inline]
pub fn extra_sample_ray(
    plan: &VertexPlan,
    vertex: &Vertex,
    bs: &BsdfSample,
) -> Option<(Rgb, Ray, BsdfRay)> {
    if bs.flags.is_specular() {
        return None;
    }
    let hit = vertex.hit;
    let wi = hit.shading.to_world(bs.wi);
    if wi.dot(hit.n()) * bs.wi.z <= 0.0 {
        return None;
    }
    let from = BsdfRay {
        prev: hit.light_context(),
        pdf: bs.pdf,
        specular: false,
        scale: plan.bsdf_scale,
    };
    Some((
        bs.f * (bs.wi.z.abs() / bs.pdf),
        vertex.origins.spawn_ray(wi),
        from,
    ))
}

/// The end of next-event estimation for an integrator that batches it:
/// traces the shadow rays `rays` in one batch (`blocked` holds the
/// answers) and hands `add` each light sample `pending[i] = (vertex,
/// unshadowed contribution)` whose ray `rays[i]` reaches its light.
pub fn add_unshadowed<S: Scene + ?Sized>(
    scene: &SceneView<S>,
    rays: &[Ray],
    pending: &[(usize, Rgb)],
    blocked: &mut Vec<bool>,
    stats: &mut RenderStats,
    mut add: impl FnMut(usize, Rgb),
) {
    blocked.clear();
    blocked.resize(rays.len(), false);
    stats.shadow_rays += rays.len() as u64;
    scene.scene.occluded_batch(rays, blocked);
    for (&(vertex, unshadowed), &blocked) in pending.iter().zip(blocked.iter()) {
        if !blocked {
            stats.light_samples += 1;
            add(vertex, unshadowed);
        }
    }
}

/// How a ray was sampled, which is what the MIS weight of emission found
/// along it depends on. In the path loop it is the state carried from one
/// vertex to the next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfRay {
    /// The vertex the ray leaves.
    pub prev: LightSampleContext,
    /// The BSDF's density of the ray's direction.
    pub pdf: f32,
    /// A specular sample: no light sample could find its direction, so the
    /// emission it finds is not weighted.
    pub specular: bool,
    /// Factor on that emission: the plan's `bsdf_scale`, or 1 where a
    /// specular sample continues the path.
    pub scale: f32,
}

impl BsdfRay {
    /// A camera ray from `o`: it counts as specular, what it sees is never
    /// weighted.
    pub fn camera(o: Vec3) -> Self {
        Self {
            prev: LightSampleContext::at(o),
            pdf: 0.0,
            specular: true,
            scale: 1.0,
        }
    }
}

/// The random numbers of a path vertex drawn before its hit
/// ([`Estimator::vertex_numbers`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexNumbers {
    /// The continuation's BSDF sample: lobe, direction.
    pub bsdf: (f32, Vec2),
    /// The first light sample: which light, which point.
    pub light: (f32, Vec2),
}

/// What [`Estimator::plan`] answers: one plan for every vertex, or for the
/// one-sample estimator a choice between its light and its BSDF plan, the
/// light one with probability `c_g`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Plans {
    Fixed(VertexPlan),
    OneSample {
        c_g: f32,
        light: VertexPlan,
        bsdf: VertexPlan,
    },
}

/// Strategy, heuristic and sample counts: the whole direct-lighting
/// estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimator {
    pub strategy: Strategy,
    pub heuristic: Heuristic,
    pub n_f: u32,
    pub n_g: u32,
    pub mode: MisEstimator,
    /// The plans [`Estimator::plan`] hands out, worked out once from the
    /// settings above rather than at every vertex.
    plans: Plans,
}

impl Estimator {
    /// One sample of each strategy per vertex: what the path tracer did
    /// before sample counts existed.
    pub fn new(strategy: Strategy, heuristic: Heuristic) -> Self {
        Self::with_counts(strategy, heuristic, 1, 1, MisEstimator::MultiSample)
    }

    /// `n_f` BSDF and `n_g` light samples per vertex (both at least 1),
    /// combined by `mode` when the strategy is MIS.
    pub fn with_counts(
        strategy: Strategy,
        heuristic: Heuristic,
        n_f: u32,
        n_g: u32,
        mode: MisEstimator,
    ) -> Self {
        assert!(n_f >= 1 && n_g >= 1, "sample counts start at 1");
        let (inv_f, inv_g) = (1.0 / n_f as f32, 1.0 / n_g as f32);
        let plan = |light_samples, extra_bsdf_samples, light_scale, bsdf_scale| VertexPlan {
            light_samples,
            extra_bsdf_samples,
            light_scale,
            bsdf_scale,
        };
        let plans = match (strategy, mode) {
            (Strategy::Bsdf, _) => Plans::Fixed(plan(0, n_f - 1, 0.0, inv_f)),
            (Strategy::Light, _) => Plans::Fixed(plan(n_g, 0, inv_g, 0.0)),
            (Strategy::Mis, MisEstimator::MultiSample) => {
                Plans::Fixed(plan(n_g, n_f - 1, inv_g, inv_f))
            }
            (Strategy::Mis, MisEstimator::OneSample) => {
                let c_g = n_g as f32 / (n_f + n_g) as f32;
                Plans::OneSample {
                    c_g,
                    light: plan(1, 0, 1.0 / c_g, 0.0),
                    bsdf: plan(0, 0, 0.0, 1.0 / (1.0 - c_g)),
                }
            }
        };
        Self {
            strategy,
            heuristic,
            n_f,
            n_g,
            mode,
            plans,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        Self::from_read(&EstimatorParams::read(params)?, params)
    }

    /// The estimator `p` describes; `params` locates errors.
    pub fn from_read(p: &EstimatorParams, params: &Params) -> Result<Self> {
        let keys = EstimatorParams::KEYS;
        // Heuristic and beta are validated whatever the strategy, so that
        // `--set integrator.strategy=bsdf` works on a scene that sets them;
        // they only change the estimate when strategy = "mis".
        let heuristic = match p.heuristic {
            HeuristicName::Balance => {
                if params.is_given(keys.beta) {
                    return Err(params.error(keys.beta, "only applies to heuristic = \"power\""));
                }
                Heuristic::Balance
            }
            HeuristicName::Power => {
                if !(p.beta > 0.0 && p.beta.is_finite()) {
                    return Err(params.error(
                        keys.beta,
                        format!("must be a positive finite number, got {}", p.beta),
                    ));
                }
                Heuristic::Power { beta: p.beta }
            }
        };
        Ok(Self::with_counts(
            p.strategy,
            heuristic,
            p.n_f,
            p.n_g,
            p.estimator,
        ))
    }

    /// Whether any vertex takes light samples.
    #[inline]
    pub fn samples_lights(&self) -> bool {
        self.strategy != Strategy::Bsdf
    }

    /// The plan at a vertex whose BSDF has a non-specular component; the
    /// one-sample estimator draws its choice from `sampler` (only then).
    #[inline]
    pub fn plan(&self, sampler: &mut dyn Sampler) -> VertexPlan {
        match self.plans {
            Plans::Fixed(plan) => plan,
            Plans::OneSample { c_g, light, bsdf } => {
                if sampler.get_1d() < c_g {
                    light
                } else {
                    bsdf
                }
            }
        }
    }

    /// MIS weight of a light sample of density `p_light` (light pmf times
    /// solid-angle pdf) whose direction the BSDF samples with `p_bsdf`.
    #[inline]
    pub fn light_weight(&self, p_light: f32, p_bsdf: f32, delta: bool) -> f32 {
        if delta || self.strategy == Strategy::Light {
            1.0
        } else {
            self.heuristic.weight(self.n_g, p_light, self.n_f, p_bsdf)
        }
    }

    /// MIS weight of emission found by a BSDF sample of density `p_bsdf`
    /// from `prev`, on light `index` that samples that direction with
    /// `pdf_li`; the plan's scale is applied by the caller.
    #[inline]
    pub fn bsdf_weight<S: Scene + ?Sized>(
        &self,
        scene: &SceneView<S>,
        index: u32,
        prev: &LightSampleContext,
        wi: Vec3,
        p_bsdf: f32,
        specular: bool,
    ) -> f32 {
        if specular || self.strategy == Strategy::Bsdf {
            return 1.0;
        }
        if self.strategy == Strategy::Light {
            return 0.0;
        }
        let light = &scene.lights[index as usize];
        let p_light = scene.light_sampler.pmf(prev, index) * light.pdf_li(prev, wi);
        self.heuristic.weight(self.n_f, p_bsdf, self.n_g, p_light)
    }

    /// Next-event estimation at `vertex`: `plan.light_samples` lights chosen
    /// by the light sampler, one point on each, weighted and scaled. The
    /// first sample's numbers `first` (light choice, point on the light)
    /// are drawn by the caller, which may draw them before it knows the
    /// hit; further samples draw theirs from `sampler`.
    pub fn sample_lights<S: Scene + ?Sized>(
        &self,
        plan: &VertexPlan,
        vertex: &Vertex,
        scene: &SceneView<S>,
        first: (f32, Vec2),
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        // The first sample outside the loop: with the loop around every
        // sample the compiler hoisted (and spilled) the whole interaction
        // before it.
        let mut sum = self.sample_one_light(vertex, scene, first, stats);
        for _ in 1..plan.light_samples {
            sum += self.sample_one_light(vertex, scene, sampler.get_1d_2d(), stats);
        }
        sum * plan.light_scale
    }

    fn sample_one_light<S: Scene + ?Sized>(
        &self,
        vertex: &Vertex,
        scene: &SceneView<S>,
        (u_light, u): (f32, Vec2),
        stats: &mut RenderStats,
    ) -> Rgb {
        let hit = vertex.hit;
        let ctx = hit.light_context();
        let Some(chosen) = scene.light_sampler.sample(&ctx, u_light) else {
            return Rgb::BLACK;
        };
        let light = &scene.lights[chosen.index as usize];
        let Some(ls) = light.sample_li(&ctx, u) else {
            return Rgb::BLACK;
        };
        let wi = hit.shading.to_local(ls.wi);
        let bsdf_ctx = vertex.bsdf_context();
        // The MIS weight needs the BSDF's pdf too (one call for both), except
        // for a delta light, whose samples take weight 1.
        let delta = light.kind() == LightKind::DeltaPosition;
        let (f, p_bsdf) = if delta {
            (hit.bsdf.f(&bsdf_ctx, vertex.wo, wi), 0.0)
        } else {
            hit.bsdf.eval(&bsdf_ctx, vertex.wo, wi)
        };
        let Some(unshadowed) = self.light_contribution(chosen.pmf, &ls, delta, f, p_bsdf, wi.z)
        else {
            return Rgb::BLACK;
        };
        stats.shadow_rays += 1;
        if scene.occluded(&vertex.origins.spawn_ray_to(&ls.p)) {
            return Rgb::BLACK;
        }
        stats.light_samples += 1;
        unshadowed()
    }

    /// The weighted contribution of light sample `ls` (of light chosen with
    /// probability `pmf`) if nothing blocks it, given the BSDF's value `f`
    /// and density `p_bsdf` for its direction, whose cosine with the
    /// shading normal is `cos_theta`, as a closure; `None` where the BSDF
    /// gives it no weight, so that no shadow ray is traced for it.
    #[inline]
    pub fn light_contribution(
        &self,
        pmf: f32,
        ls: &LightSample,
        delta: bool,
        f: Rgb,
        p_bsdf: f32,
        cos_theta: f32,
    ) -> Option<impl FnOnce() -> Rgb + '_> {
        let f = f * cos_theta.abs();
        if f.is_black() {
            return None;
        }
        // Worked out when asked, after the shadow ray in `path`.
        let (l, pdf) = (ls.l, ls.pdf);
        Some(move || {
            let p_light = pmf * pdf;
            f * l * (self.light_weight(p_light, p_bsdf, delta) / p_light)
        })
    }

    /// The numbers a path vertex draws before its hit is known: the BSDF
    /// sample's (lobe, direction) and, where the estimator samples lights,
    /// the first light sample's (which light, which point). Drawn before
    /// the intersection, their latency overlaps it; BSDF-only paths keep
    /// their dimensions.
    #[inline]
    pub fn vertex_numbers(&self, sampler: &mut dyn Sampler) -> VertexNumbers {
        let bsdf = sampler.get_1d_2d();
        let light = if self.samples_lights() {
            sampler.get_1d_2d()
        } else {
            (0.0, Vec2::ZERO)
        };
        VertexNumbers { bsdf, light }
    }

    /// [`Self::vertex_numbers`] of each lane of `lanes`, as batched
    /// requests: `bsdf[k]` and `light[k]` for lane `lanes[k]`, each lane
    /// drawing them in `vertex_numbers`'s order.
    pub fn vertex_numbers_batch(
        &self,
        samplers: &mut dyn SamplerLanes,
        lanes: &[usize],
        bsdf: &mut Vec<(f32, Vec2)>,
        light: &mut Vec<(f32, Vec2)>,
    ) {
        for numbers in [&mut *bsdf, &mut *light] {
            numbers.clear();
            numbers.resize(lanes.len(), (0.0, Vec2::ZERO));
        }
        samplers.get_1d_2d_batch(lanes, bsdf);
        if self.samples_lights() {
            samplers.get_1d_2d_batch(lanes, light);
        }
    }

    /// Emission found by `plan.extra_bsdf_samples` BSDF samples at `vertex`
    /// that only look for emitters (they do not continue the path),
    /// weighted and scaled by the plan's `bsdf_scale`.
    pub fn extra_bsdf_samples<S: Scene + ?Sized>(
        &self,
        plan: &VertexPlan,
        vertex: &Vertex,
        scene: &SceneView<S>,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        let hit = vertex.hit;
        let mut sum = Rgb::BLACK;
        for _ in 0..plan.extra_bsdf_samples {
            let (u1, u2) = sampler.get_1d_2d();
            let Some(bs) = hit.bsdf.sample_f(&vertex.bsdf_context(), vertex.wo, u1, u2) else {
                continue;
            };
            let Some((throughput, ray, from)) = extra_sample_ray(plan, vertex, &bs) else {
                continue;
            };
            stats.rays += 1;
            sum += throughput * self.emission_along(scene, &ray, &from, stats);
        }
        sum
    }

    /// Weighted, scaled emission seen along a BSDF-sampled `ray`, traced
    /// here. The caller counts the ray.
    pub fn emission_along<S: Scene + ?Sized>(
        &self,
        scene: &SceneView<S>,
        ray: &Ray,
        from: &BsdfRay,
        stats: &mut RenderStats,
    ) -> Rgb {
        let found = scene.intersect(ray);
        let (le, emitters) = self.emission(scene, ray, found.as_ref(), from);
        stats.bsdf_light_hits += emitters;
        le
    }

    /// Emission that `ray`, sampled as `from` says, finds: the emitter it
    /// hit (`found`, the caller's intersection), or the infinite lights if
    /// it escaped; each weighted by [`Estimator::bsdf_weight`] and the
    /// scale. Also returns how many emitters contributed.
    #[inline]
    pub fn emission<S: Scene + ?Sized>(
        &self,
        scene: &SceneView<S>,
        ray: &Ray,
        found: Option<&SurfaceInteraction>,
        from: &BsdfRay,
    ) -> (Rgb, u64) {
        let mut sum = Rgb::BLACK;
        let mut emitters = 0;
        match found {
            Some(hit) => {
                if let Some(emitter) = hit.light.map(LightIndex::get) {
                    let le =
                        scene.lights[emitter as usize].l(hit.p(), hit.n(), hit.texture.uv, -ray.d);
                    if !le.is_black() {
                        let w = from.scale
                            * self.bsdf_weight(
                                scene,
                                emitter,
                                &from.prev,
                                ray.d,
                                from.pdf,
                                from.specular,
                            );
                        if w > 0.0 {
                            sum += le * w;
                            emitters += 1;
                        }
                    }
                }
            }
            None => {
                for &index in scene.infinite_lights {
                    let light = &scene.lights[index as usize];
                    let le = light.l(ray.o, Vec3::ZERO, Default::default(), ray.d);
                    let w = from.scale
                        * self.bsdf_weight(
                            scene,
                            index,
                            &from.prev,
                            ray.d,
                            from.pdf,
                            from.specular,
                        );
                    if w > 0.0 && !le.is_black() {
                        sum += le * w;
                        emitters += 1;
                    }
                }
            }
        }
        (sum, emitters)
    }
}
