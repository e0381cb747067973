//! `packet`: the `path` estimator run on a packet of [`LANES`] paths at a
//! time, one path per lane (the layout of OSPRay's path tracer and of
//! Embree's ISPC path-tracing tutorial, where a `varying` path is one
//! lane of a SIMD register).
//!
//! # A bounce
//!
//! The paths' state (throughput, radiance, ray, how the ray was sampled,
//! `eta_scale`, depth, camera ray) is held as structure of arrays
//! ([`PathLanes`], `state.rs`), and a [`lumis_api::lanes::LaneMask`] says
//! which lanes are live. Each bounce (`shade.rs`) draws the live lanes'
//! numbers with one batched request, traces their rays as one packet
//! ([`Scene::intersect_batch`]) and adds the emission they find. It then
//! hands every BSDF present in the packet the lanes that hit it, in one
//! [`lumis_api::Bsdf::sample_f_lanes`] and one
//! [`lumis_api::Bsdf::eval_lanes`] call, and every light the lanes that
//! chose it, in one [`lumis_api::Light::sample_li_lanes`] call, with their
//! arguments as lane arrays and the lanes as a mask: material divergence
//! is handled by running each material under its mask. Shadow rays go to
//! one [`Scene::occluded_batch`], and each lane continues as in `path`,
//! with the same `PathState` steps.
//!
//! A lane whose path ends takes the next camera ray of the batch while
//! fewer than `refill_below` lanes are live (8 by default: every free lane
//! refills; 1, 4 and 8 are within the machine's noise of one another on the
//! Cornell box, 1.02-1.10 Msamples/s on one thread).
//!
//! # The same image as `path`
//!
//! A plugin that overrides the lane methods computes the lanes with SIMD;
//! one that does not answers lane by lane through the trait's defaults.
//! Each path draws its sampler's numbers in `path`'s order, so with the
//! defaults the two integrators give the same image bit for bit, and lane
//! overrides change it only by their rounding. The built-in overrides keep
//! it: `diffuse` overrides `sample_f_lanes` with the cosine warp on eight
//! SIMD lanes, `conductor` answers its lanes through its SIMD batched
//! methods and `sphere` through its SIMD `sample_li_batch`, and every
//! lane's answer is the scalar method's, bit for bit. So `packet` renders
//! `path`'s image and counters bit for bit (`tests/batched_integrators.rs`,
//! also with packets refilled only below five live lanes), and the same
//! mean block by block with Embree packets; it runs in the furnace,
//! analytic and integrator-check tests. What it costs and buys is in
//! [Performance](performance.md#the-packet-integrator).

mod shade;
mod state;

use lumis_api::lanes::LANES;
use lumis_api::{
    Integrator, Params, PluginKind, PluginParams, PluginSpec, Ray, RenderStats, Result, Rgb,
    Sampler, SamplerLanes, Scene,
};

use crate::estimator::SceneView;
use crate::path::{PathIntegrator, PathParams};
use shade::Bounce;
use state::PathLanes;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "packet",
    source: lumis_api::source_file!(),
    doc: "the path tracer run on a packet of 8 paths, one per lane: rays traced as packets, each BSDF and light called once per packet with the lanes that need it (SIMD where the plugin overrides the lane methods); same estimate as path",
    params: PacketParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct PacketParams {
    #[param(flatten)]
    pub path: PathParams,
    /// a lane whose path ended takes a new camera ray while fewer than this
    /// many lanes are live: 8 keeps every lane busy, 1 runs each packet's
    /// paths to their end before starting new ones
    #[param(default = 8, range = (1, 8))]
    pub refill_below: u32,
}

/// Camera rays per [`Integrator::li_batch`] call: enough for the lanes to
/// refill many times from one batch.
const BATCH: usize = 32 * LANES;

pub struct PacketIntegrator {
    /// The estimator's settings, and the scalar loop for a single ray.
    path: PathIntegrator,
    refill_below: u32,
}

impl PacketIntegrator {
    pub fn new(path: PathIntegrator, refill_below: u32) -> Self {
        Self {
            path,
            refill_below: refill_below.clamp(1, LANES as u32),
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = PacketParams::read(params)?;
        Ok(Self::new(
            PathIntegrator::from_read(&p.path, params)?,
            p.refill_below,
        ))
    }
}

impl Integrator for PacketIntegrator {
    /// A single ray is a packet of one: `path`'s scalar loop.
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        self.path.li(ray, scene, sampler, stats)
    }

    fn batch_size(&self) -> usize {
        BATCH
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
        let mut paths = PathLanes::default();
        let mut bounce = Bounce::new(&self.path, &scene);
        let mut unstarted = 0..rays.len();
        loop {
            if paths.live.count() < self.refill_below {
                for lane in (!paths.live).iter() {
                    let Some(path) = unstarted.next() else {
                        break;
                    };
                    paths.start(lane, path, &rays[path]);
                }
            }
            if paths.live.is_empty() {
                break;
            }
            let ended = bounce.run(&mut paths, samplers, stats);
            for lane in ended.iter() {
                out[paths.path[lane]] = paths.radiance(lane);
            }
            paths.live = paths.live & !ended;
        }
    }
}
