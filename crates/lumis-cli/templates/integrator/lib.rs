//! `{{plugin}}`: unidirectional path tracing with BSDF sampling only
//! (Kajiya 1986; Veach 1997, section 3.7).
//!
//! From the camera ray, each vertex adds the emission its ray finds (an
//! area light it hits, or the infinite lights if it escapes), weighted by
//! the path throughput `beta = prod f cos / pdf`, then continues in a
//! direction its BSDF samples. Every path of up to `max_depth` segments is
//! counted once, so the estimate has the mean of the built-in `path`
//! integrator with the same `max_depth`; without light sampling it is
//! noisier, and it cannot see point lights (which no ray hits).

use lumis_api::{
    BsdfContext, Integrator, Params, PluginKind, PluginParams, PluginSpec, Ray, Registrar,
    RenderStats, Result, Rgb, Sampler, Scene, Vec3,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "{{plugin}}",
    source: lumis_api::source_file!(),
    doc: "path tracer with BSDF sampling only: emission found by the rays the BSDFs sample",
    params: BsdfPathParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct BsdfPathParams {
    /// maximum path segments from the camera: 1 = emitters seen directly, 2
    /// = direct lighting
    #[param(default = 8)]
    pub max_depth: u32,
}

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_integrator(SPEC, |params| {
        Ok(Box::new(BsdfPathTracer::from_params(params)?))
    })
}

lumis_api::lumis_plugin!(register);

#[derive(Debug, Clone)]
pub struct BsdfPathTracer {
    max_depth: u32,
}

impl BsdfPathTracer {
    pub fn new(max_depth: u32) -> Self {
        Self { max_depth }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = BsdfPathParams::read(params)?;
        if p.max_depth == 0 {
            return Err(params.error(
                BsdfPathParams::KEYS.max_depth,
                "must be at least 1 (1 = emitters seen directly)",
            ));
        }
        Ok(Self::new(p.max_depth))
    }
}

impl Integrator for BsdfPathTracer {
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
        for segment in 1..=self.max_depth {
            stats.rays += 1;
            let Some(hit) = scene.intersect(&ray) else {
                // Infinite lights are seen along the direction that escaped.
                for &index in scene.infinite_lights() {
                    let light = &scene.lights()[index as usize];
                    radiance += beta * light.l(ray.o, Vec3::ZERO, Default::default(), ray.d);
                }
                break;
            };
            if let Some(index) = hit.light {
                let light = &scene.lights()[index.get() as usize];
                radiance += beta * light.l(hit.p(), hit.n(), hit.texture.uv, -ray.d);
            }
            if segment == self.max_depth {
                break;
            }
            // BSDFs work in the shading frame, where the normal is +z; their
            // textures are looked up where the hit says (uv and footprint).
            let ctx = BsdfContext {
                texture: hit.texture,
                ..Default::default()
            };
            let wo = hit.shading.to_local(-ray.d);
            let (u1, u2) = sampler.get_1d_2d();
            let Some(sample) = hit.bsdf.sample_f(&ctx, wo, u1, u2) else {
                break;
            };
            // f cos / pdf; a specular sample's f and pdf share a delta
            // that cancels.
            beta *= sample.f * (sample.wi.z.abs() / sample.pdf);
            if beta.is_black() || !beta.is_finite() {
                break;
            }
            ray = hit.spawn_ray(hit.shading.to_world(sample.wi));
        }
        radiance
    }
}
