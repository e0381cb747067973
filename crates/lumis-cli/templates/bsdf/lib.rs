//! `{{plugin}}`: the Lambertian BRDF `f = R / pi`, sampled in proportion to
//! `cos theta` (Malley's method: uniform points on the disk projected up to
//! the hemisphere; pbrt-v4 section A.5.3), so that `f cos / pdf = R` and a
//! sample carries no variance of its own.
//!
//! BSDFs work in the local shading frame: the normal is `+z`, `wo` and `wi`
//! point away from the surface, and `cos theta` is a direction's `z`.

use std::f32::consts::FRAC_1_PI;
use std::sync::Arc;

use lumis_api::bsdf::BsdfSampleLanes;
use lumis_api::lanes::{Floats, LaneMask, Vec2Lanes, Vec3Lanes, LANES};
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec,
    Registrar, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::real::F32x8;
use lumis_sampling::{simd, warp};

/// The plugin as a scene names it (`type = "{{plugin}}"`) and as
/// `lumis plugins` lists it.
pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "{{plugin}}",
    source: lumis_api::source_file!(),
    doc: "Lambertian reflection f = R/pi, cosine-weighted sampling; one-sided",
    params: LambertianParams::SPECS,
};

/// The parameters, declared once: each field is a scene key, its `///`
/// comment the description `lumis plugins` shows, and `lumis check-plugin`
/// sweeps them.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct LambertianParams {
    /// albedo R in linear RGB, each channel in [0, 1]
    #[param(default = 0.5)]
    pub reflectance: Rgb,
}

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_bsdf(SPEC, |params| {
        Ok(Arc::new(Lambertian::from_params(params)?))
    })
}

lumis_api::lumis_plugin!(register);

#[derive(Debug, Clone)]
pub struct Lambertian {
    reflectance: Rgb,
}

impl Lambertian {
    pub fn new(reflectance: Rgb) -> Self {
        Self { reflectance }
    }

    /// Reads and checks the parameters. Types and declared ranges are
    /// checked by `read`; what only this model can judge is checked here,
    /// the error located at the value in the scene file.
    pub fn from_params(params: &Params) -> Result<Self> {
        let p = LambertianParams::read(params)?;
        let r = p.reflectance;
        if !(r.min_component() >= 0.0 && r.max_component() <= 1.0) {
            return Err(params.error(
                LambertianParams::KEYS.reflectance,
                format!("each channel must be in [0, 1] to conserve energy, got {r}"),
            ));
        }
        Ok(Self::new(r))
    }
}

impl Lambertian {
    /// The sample of the drawn direction `wi` for `wo`.
    fn sample_from(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Option<BsdfSample> {
        // From behind, or on the horizon: no reflection, so no sample.
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            f: self.f(ctx, wo, wi),
            wi,
            pdf: self.pdf(ctx, wo, wi),
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }
}

impl Bsdf for Lambertian {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.reflectance * FRAC_1_PI
        } else {
            Rgb::BLACK
        }
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        self.sample_from(ctx, wo, warp::square_to_cosine_hemisphere(u2))
    }

    /// Optional: `sample_f` for a packet of eight paths at once, which the
    /// `packet` integrator calls with the lanes that hit this BSDF. The
    /// arguments are arrays of lanes, so the warp runs on all eight
    /// random-number pairs in one pass of SIMD instructions
    /// (`square_to_cosine_hemisphere_lanes`, the same formula as the
    /// scalar warp); without this method the trait's default calls
    /// `sample_f` lane by lane. Write only the lanes of `active`.
    fn sample_f_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        _u1: &Floats,
        u2: &Vec2Lanes,
        active: LaneMask,
        out: &mut BsdfSampleLanes,
    ) {
        // Compiled for SSE2, AVX2 and AVX-512, run with what the CPU has.
        let [x, y, z] = simd::dispatch(|| {
            let wi =
                warp::square_to_cosine_hemisphere_lanes([F32x8::from(u2.x), F32x8::from(u2.y)]);
            [wi.x, wi.y, wi.z].map(F32x8::to_array)
        });
        for i in active.iter() {
            out.set(i, self.sample_from(&ctx[i], wo.get(i), Vec3::new(x[i], y[i], z[i])));
        }
    }

    /// The density of `sample_f`, in solid angle: `cos theta / pi`.
    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            warp::cosine_hemisphere_pdf(wi.z)
        } else {
            0.0
        }
    }
}
