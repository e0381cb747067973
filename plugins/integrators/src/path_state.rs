//! What a path carries from one vertex to the next (pbrt-v4
//! `PathIntegrator::Li`'s loop variables): the scalar `path` integrator
//! keeps one, the wavefront integrator one per lane, and both advance it
//! with the same steps.

use lumis_api::{BsdfFlags, BsdfSample, Ray, RenderStats, Rgb, Sampler};

use crate::estimator::{BsdfRay, Vertex, VertexPlan};

/// Caps on the light a path adds to its pixel, by how many bounces the
/// light took (Cycles' "Clamp Direct" and "Clamp Indirect"): contributions
/// whose largest component exceeds the cap are scaled down to it
/// ([`Rgb::clamp_max_component`]). Biased, darker where the cap binds; it
/// buys the variance of rare bright paths. Light the camera sees directly
/// is left to the film's clamp (`[film] clamp`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BounceClamp {
    /// The cap on direct lighting: light over two segments, one bounce.
    pub direct: f32,
    /// The cap on indirect light: three segments or more.
    pub indirect: f32,
}

impl BounceClamp {
    pub const NONE: Self = Self {
        direct: f32::INFINITY,
        indirect: f32::INFINITY,
    };

    /// `contribution`, light that reached the camera over `segments`
    /// segments, capped. Without caps (the default) it is one predictable
    /// branch: the unclamped path tracer keeps its instruction count.
    #[inline]
    pub fn apply(&self, contribution: Rgb, segments: u32) -> Rgb {
        if *self == Self::NONE {
            return contribution;
        }
        match segments {
            0 | 1 => contribution,
            2 => contribution.clamp_max_component(self.direct),
            _ => contribution.clamp_max_component(self.indirect),
        }
    }
}

/// One path's state between vertices.
#[derive(Clone, Copy)]
pub struct PathState {
    /// Radiance gathered so far.
    pub radiance: Rgb,
    /// Throughput: the product of f cos / pdf (and roulette reweighting)
    /// over the vertices so far.
    pub beta: Rgb,
    /// The ray to the next vertex.
    pub ray: Ray,
    /// How `ray` was sampled: what weights the emission it finds.
    pub from: BsdfRay,
    /// The product of eta'^2 over the refractions so far: radiance
    /// transport divides the throughput by it, and leaving the medium will
    /// multiply it back, so Russian roulette judges the throughput without
    /// it (pbrt-v4's `etaScale`).
    pub eta_scale: f32,
    /// Path segments so far, `ray` included.
    pub segments: u32,
}

impl PathState {
    pub fn new(camera_ray: &Ray) -> Self {
        Self {
            radiance: Rgb::BLACK,
            beta: Rgb::WHITE,
            ray: *camera_ray,
            from: BsdfRay::camera(camera_ray.o),
            eta_scale: 1.0,
            segments: 1,
        }
    }

    /// Adds the emission `ray` found, as [`crate::Estimator::emission`]
    /// answers it: weighted radiance and the number of emitters.
    #[inline]
    pub fn add_emission(
        &mut self,
        (le, emitters): (Rgb, u64),
        clamp: &BounceClamp,
        stats: &mut RenderStats,
    ) {
        if emitters > 0 {
            self.radiance += clamp.apply(self.beta * le, self.segments);
            // What the camera sees is not found by BSDF sampling.
            if self.segments > 1 {
                stats.bsdf_light_hits += emitters;
            }
        }
    }

    /// Adds light `l` gathered at the vertex `ray` reaches (next-event
    /// estimation, extra BSDF samples): paths one segment longer.
    #[inline]
    pub fn add_vertex_light(&mut self, l: Rgb, clamp: &BounceClamp) {
        self.radiance += clamp.apply(self.beta * l, self.segments + 1);
    }

    /// Continues the path from `vertex` along its BSDF sample `bs`, then
    /// plays Russian roulette past `rr_depth` segments; `false`: the path
    /// ends here.
    #[inline]
    pub fn continue_path(
        &mut self,
        vertex: &Vertex,
        bs: &BsdfSample,
        plan: &VertexPlan,
        rr_depth: u32,
        sampler: &mut dyn Sampler,
    ) -> bool {
        let hit = vertex.hit;
        let wi = hit.shading.to_world(bs.wi);
        // A direction below the geometric surface would leak through it.
        if wi.dot(hit.n()) * bs.wi.z <= 0.0 {
            return false;
        }
        self.beta *= bs.f * (bs.wi.z.abs() / bs.pdf);
        if bs.flags.contains(BsdfFlags::TRANSMISSION) {
            self.eta_scale *= bs.eta * bs.eta;
        }
        let specular = bs.flags.is_specular();
        self.from = BsdfRay {
            prev: hit.light_context(),
            pdf: bs.pdf,
            specular,
            scale: if specular { 1.0 } else { plan.bsdf_scale },
        };
        self.ray = vertex.origins.spawn_ray(wi);
        self.segments += 1;
        if self.segments > rr_depth {
            // Survive with probability max(beta eta_scale) (pbrt-v4): paths
            // that carry little weight stop early; survivors are reweighted.
            let q = (1.0 - (self.beta * self.eta_scale).max_component()).max(0.0);
            if sampler.get_1d() < q {
                return false;
            }
            self.beta /= 1.0 - q;
        }
        !self.beta.is_black()
    }
}
