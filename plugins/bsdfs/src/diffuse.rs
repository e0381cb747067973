//! `diffuse`: the Lambertian BRDF `f = R / pi`.
//!
//! One-sided unless `two_sided`: as in Mitsuba, a one-sided surface is black
//! from behind. `sampling = "cosine"` is Malley's method (a uniform point on
//! the disk, lifted to the hemisphere).

use std::f32::consts::FRAC_1_PI;

use lumis_api::bsdf::{sample_f_each_lane, BsdfSampleLanes};
use lumis_api::lanes::{Floats, LaneMask, Vec2Lanes, Vec3Lanes, LANES};
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, ParamChoice, Params, PluginKind, PluginParams,
    PluginSpec, Result, Rgb, TexturedRgb, Vec2, Vec3,
};
use lumis_sampling::real::F32x8;
use lumis_sampling::{simd, warp};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "diffuse",
    source: lumis_api::source_file!(),
    doc: "Lambertian reflection f = R/pi, one-sided unless two_sided",
    params: DiffuseParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct DiffuseParams {
    /// albedo R in linear RGB, each channel in [0, 1], or a texture
    pub reflectance: TexturedRgb,
    /// reflect on both sides (one-sided surfaces are black from behind,
    /// like Mitsuba's)
    #[param(default = false)]
    pub two_sided: bool,
    /// "cosine" (Malley: pdf cos/pi, zero variance for f cos) or "uniform"
    /// (pdf 1/(2 pi), for comparison)
    #[param(default = Cosine)]
    pub sampling: DiffuseSampling,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum DiffuseSampling {
    Cosine,
    Uniform,
}

#[derive(Debug, Clone)]
pub struct Diffuse {
    reflectance: TexturedRgb,
    two_sided: bool,
    sampling: DiffuseSampling,
}

impl Diffuse {
    pub fn new(
        reflectance: impl Into<TexturedRgb>,
        two_sided: bool,
        sampling: DiffuseSampling,
    ) -> Self {
        Self {
            reflectance: reflectance.into(),
            two_sided,
            sampling,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = DiffuseParams::read(params)?;
        if let Some(r) = p.reflectance.constant() {
            if !(r.min_component() >= 0.0 && r.max_component() <= 1.0) {
                return Err(params.error(
                    DiffuseParams::KEYS.reflectance,
                    format!("each channel must be in [0, 1] (energy conservation), got {r}"),
                ));
            }
        }
        Ok(Self::new(p.reflectance, p.two_sided, p.sampling))
    }

    /// Maps `(wo, wi)` into the upper hemisphere if this side reflects;
    /// `None` when the pair gets no reflection.
    #[inline]
    fn oriented(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
        if wo.z > 0.0 && wi.z > 0.0 {
            Some((wo, wi))
        } else if self.two_sided && wo.z < 0.0 && wi.z < 0.0 {
            Some((-wo, -wi))
        } else {
            None
        }
    }

    /// The factor on `z` that takes the upper hemisphere to `wo`'s side: 1
    /// above, -1 below where both sides reflect; `None` where `wo`'s side
    /// does not reflect.
    #[inline(always)]
    fn side(&self, wo: Vec3) -> Option<f32> {
        if wo.z > 0.0 {
            Some(1.0)
        } else if self.two_sided && wo.z < 0.0 {
            Some(-1.0)
        } else {
            None
        }
    }

    /// The sample of direction `local`, drawn in the upper hemisphere, its
    /// `z` multiplied by `flip` ([`Diffuse::side`]).
    #[inline(always)]
    fn sample_from(&self, ctx: &BsdfContext, flip: f32, local: Vec3) -> Option<BsdfSample> {
        // A direction on the horizon (z = 0 exactly, reachable with u = 0)
        // has no reflection: f() is zero there, so no sample either.
        if local.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf_upper(local.z);
        Some(BsdfSample {
            f: self.reflectance.eval(&ctx.texture) * FRAC_1_PI,
            wi: Vec3::new(local.x, local.y, local.z * flip),
            pdf,
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        })
    }

    #[inline]
    fn pdf_upper(&self, cos_theta: f32) -> f32 {
        match self.sampling {
            DiffuseSampling::Cosine => warp::cosine_hemisphere_pdf(cos_theta),
            DiffuseSampling::Uniform => warp::uniform_hemisphere_pdf(cos_theta),
        }
    }
}

impl Bsdf for Diffuse {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        match self.oriented(wo, wi) {
            Some(_) => self.reflectance.eval(&ctx.texture) * FRAC_1_PI,
            None => Rgb::BLACK,
        }
    }

    #[inline]
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let flip = self.side(wo)?;
        let local = match self.sampling {
            DiffuseSampling::Cosine => warp::square_to_cosine_hemisphere(u2),
            DiffuseSampling::Uniform => warp::square_to_uniform_hemisphere(u2),
        };
        self.sample_from(ctx, flip, local)
    }

    /// A packet's lanes with the cosine map on SIMD lanes, read from and
    /// written to the lane arrays as whole registers
    /// (`warp::square_to_cosine_hemisphere_lanes`, the scalar map's bits);
    /// the reflectance per lane. Each lane is `sample_f`'s answer.
    fn sample_f_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        u1: &Floats,
        u2: &Vec2Lanes,
        active: LaneMask,
        out: &mut BsdfSampleLanes,
    ) {
        if self.sampling != DiffuseSampling::Cosine {
            return sample_f_each_lane(self, ctx, wo, u1, u2, active, out);
        }
        let [x, y, z] = simd::dispatch(|| {
            let local =
                warp::square_to_cosine_hemisphere_lanes([F32x8::from(u2.x), F32x8::from(u2.y)]);
            [local.x, local.y, local.z].map(F32x8::to_array)
        });
        for i in active.iter() {
            let local = Vec3::new(x[i], y[i], z[i]);
            let sample = self
                .side(wo.get(i))
                .and_then(|flip| self.sample_from(&ctx[i], flip, local));
            out.set(i, sample);
        }
    }

    #[inline]
    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        match self.oriented(wo, wi) {
            Some((_, wi)) => self.pdf_upper(wi.z),
            None => 0.0,
        }
    }

    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        match self.oriented(wo, wi) {
            Some((_, wi)) => (
                self.reflectance.eval(&ctx.texture) * FRAC_1_PI,
                self.pdf_upper(wi.z),
            ),
            None => (Rgb::BLACK, 0.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    fn estimate_albedo(bsdf: &Diffuse, wo: Vec3, n: u32) -> Rgb {
        let mut rng = Pcg32::new(11, 13);
        let ctx = BsdfContext::default();
        let mut sum = Rgb::BLACK;
        for _ in 0..n {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = bsdf.sample_f(&ctx, wo, rng.next_f32(), u) {
                assert!((s.pdf - bsdf.pdf(&ctx, wo, s.wi)).abs() < 1e-5 * s.pdf.max(1.0));
                assert_eq!(s.f, bsdf.f(&ctx, wo, s.wi));
                sum += s.f * s.wi.z.abs() / s.pdf;
            }
        }
        sum / n as f32
    }

    #[test]
    fn albedo_is_reflectance_for_both_sampling_modes() {
        let r = Rgb::new(0.2, 0.5, 0.9);
        let wo = Vec3::new(0.3, 0.1, 0.9).normalize();
        let cosine = estimate_albedo(&Diffuse::new(r, false, DiffuseSampling::Cosine), wo, 10_000);
        // Cosine sampling of a Lambertian has zero variance: f cos / pdf = R.
        assert!((cosine - r).max_component().abs() < 1e-5, "{cosine:?}");
        let uniform = estimate_albedo(
            &Diffuse::new(r, false, DiffuseSampling::Uniform),
            wo,
            400_000,
        );
        // Uniform: estimator 2 R cos, std of mean = R sqrt(1/3)/sqrt(n) ~ 1e-3 R.
        assert!(
            ((uniform - r) / r).map(f32::abs).max_component() < 5e-3,
            "{uniform:?}"
        );
    }

    #[test]
    fn one_sided_is_black_from_behind_two_sided_is_not() {
        let ctx = BsdfContext::default();
        let below = Vec3::new(0.0, 0.6, -0.8);
        let one = Diffuse::new(Rgb::WHITE, false, DiffuseSampling::Cosine);
        assert!(one.sample_f(&ctx, below, 0.5, Vec2::splat(0.3)).is_none());
        assert!(one.f(&ctx, below, -Vec3::Z).is_black());
        let two = Diffuse::new(Rgb::WHITE, true, DiffuseSampling::Cosine);
        let s = two.sample_f(&ctx, below, 0.5, Vec2::splat(0.3)).unwrap();
        assert!(s.wi.z < 0.0 && s.pdf > 0.0);
        assert!(two.f(&ctx, Vec3::Z, -Vec3::Z).is_black(), "no transmission");
    }

    #[test]
    fn reciprocity() {
        let ctx = BsdfContext::default();
        let b = Diffuse::new(Rgb::splat(0.7), true, DiffuseSampling::Cosine);
        let (a, c) = (
            Vec3::new(0.1, 0.2, 0.97).normalize(),
            Vec3::new(-0.6, 0.0, 0.8),
        );
        assert_eq!(b.f(&ctx, a, c), b.f(&ctx, c, a));
    }
}
