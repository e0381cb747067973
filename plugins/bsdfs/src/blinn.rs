//! `blinn`: the normalised Blinn-Phong microfacet BRDF
//!
//! f(wo, wi) = R D(h) G(wo, wi) / (4 cos theta_o cos theta_i),
//! D(h) = (n + 2) / (2 pi) cos^n theta_h
//!
//! (Blinn 1977; D normalised so that `int D cos theta_h = 1`) with the
//! V-cavity masking of Torrance and Sparrow 1967, `G = min(1, 2 cos theta_h
//! cos theta_o / <wo, h>, 2 cos theta_h cos theta_i / <wo, h>)`, which
//! satisfies the projected-area constraint (Heitz 2014, section 5.2), so
//! the albedo never exceeds `R`. Its own sampling, `sampling = "blinn"`,
//! draws the half vector with `cos theta_h = u^(1/(n+1))`, density
//! `(n + 1)/(2 pi) cos^n theta_h`, and maps it to `wi` with the reflection
//! Jacobian `1 / (4 <wo, h>)`. One-sided.

use std::f32::consts::PI;

use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, ParamChoice, Params, PluginKind, PluginParams,
    PluginSpec, Result, Rgb, TexturedFloat, TexturedRgb, Vec2, Vec3,
};

use crate::fresnel::reflect;
use crate::lobe_sampling::LobeSampling;
use crate::microfacet::{half_vector, NormalSampling};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "blinn",
    source: lumis_api::source_file!(),
    doc: "normalised Blinn-Phong microfacet BRDF with V-cavity masking; half-vector sampling; one-sided",
    params: BlinnParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct BlinnParams {
    /// scale R of the lobe, each channel in [0, 1] (a texture's values
    /// are clamped to it)
    #[param(default = 1.0)]
    pub reflectance: TexturedRgb,
    /// Blinn exponent n in [0, 1e6]; 0 is a uniform distribution of normals
    #[param(default = 100.0, range = (0.0, 1e6))]
    pub exponent: TexturedFloat,
    /// blinn: half vectors from cos^n (the model's own); cosine or uniform
    /// hemisphere, for comparison
    #[param(default = Blinn)]
    pub sampling: BlinnSampling,
}

/// How `blinn` draws directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum BlinnSampling {
    /// Half vectors from `cos^n`, the model's own.
    Blinn,
    Cosine,
    Uniform,
}

impl From<BlinnSampling> for LobeSampling {
    fn from(sampling: BlinnSampling) -> Self {
        match sampling {
            // Blinn has one strategy of its own; `Model` carries it.
            BlinnSampling::Blinn => LobeSampling::Model(NormalSampling::Visible),
            BlinnSampling::Cosine => LobeSampling::Cosine,
            BlinnSampling::Uniform => LobeSampling::Uniform,
        }
    }
}

#[derive(Debug, Clone)]
pub struct Blinn {
    reflectance: TexturedRgb,
    exponent: TexturedFloat,
    sampling: LobeSampling,
}

/// The lobe at one hit: [`Blinn`]'s parameters read there.
#[derive(Debug, Clone, Copy)]
struct Lobe {
    reflectance: Rgb,
    exponent: f32,
    sampling: LobeSampling,
}

impl Blinn {
    pub fn new(
        reflectance: impl Into<TexturedRgb>,
        exponent: impl Into<TexturedFloat>,
        sampling: LobeSampling,
    ) -> Self {
        Self {
            reflectance: reflectance.into(),
            exponent: exponent.into(),
            sampling,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = BlinnParams::read(params)?;
        if let Some(reflectance) = p.reflectance.constant() {
            if !(reflectance.min_component() >= 0.0 && reflectance.max_component() <= 1.0) {
                return Err(params.error(
                    BlinnParams::KEYS.reflectance,
                    format!("each channel must be in [0, 1], got {reflectance}"),
                ));
            }
        }
        Ok(Self::new(p.reflectance, p.exponent, p.sampling.into()))
    }

    /// The lobe at this hit; textures' values clamped to the declared
    /// ranges.
    #[inline]
    fn lobe(&self, ctx: &BsdfContext) -> Lobe {
        let reflectance = match &self.reflectance {
            lumis_api::params::Textured::Constant(r) => *r,
            textured => textured.eval(&ctx.texture).map(|c| c.clamp(0.0, 1.0)),
        };
        let exponent = match &self.exponent {
            lumis_api::params::Textured::Constant(n) => *n,
            textured => textured.eval(&ctx.texture).clamp(0.0, 1e6),
        };
        Lobe {
            reflectance,
            exponent,
            sampling: self.sampling,
        }
    }
}

impl Lobe {
    /// `cos^n theta_h` of the unnormalised half vector `h`, as `exp(n/2
    /// ln(1 - sin^2))` with `sin^2` from the tangential components: exact
    /// near the peak, where `cos theta_h` itself rounds to 1 in f32 long
    /// before `cos^n` stops changing (n = 1e6).
    #[inline]
    fn cos_power(&self, h: Vec3) -> f32 {
        let len2 = h.length_squared();
        let sin2 = ((h.x * h.x + h.y * h.y) / len2).min(1.0);
        if self.exponent == 0.0 {
            return 1.0;
        }
        (0.5 * self.exponent * (-sin2).ln_1p()).exp()
    }

    /// Density of the sampled half vector w.r.t. solid angle.
    #[inline]
    fn half_vector_pdf(&self, h: Vec3) -> f32 {
        (self.exponent + 1.0) / (2.0 * PI) * self.cos_power(h)
    }

    #[inline]
    fn eval(&self, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let Some((h, wo_h)) = half_vector(wo, wi) else {
            return Rgb::BLACK;
        };
        let d = (self.exponent + 2.0) / (2.0 * PI) * self.cos_power(h);
        let cos_h = h.z;
        let g = (2.0 * cos_h * wo.z.min(wi.z) / wo_h).min(1.0);
        self.reflectance * (d * g / (4.0 * wo.z * wi.z))
    }

    #[inline]
    fn eval_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match self.sampling {
            LobeSampling::Model(_) => {
                let Some((h, wo_h)) = half_vector(wo, wi) else {
                    return 0.0;
                };
                self.half_vector_pdf(h) / (4.0 * wo_h)
            }
            baseline => baseline.baseline_pdf(wi.z),
        }
    }

    /// `cos theta_h = u^(1/(n+1))`, with `1 - cos` from `expm1` so that
    /// the tiny angles of huge exponents keep their precision.
    fn sample_half_vector(&self, u: Vec2) -> Vec3 {
        let log_cos = u.x.ln() as f64 / (self.exponent as f64 + 1.0);
        let one_minus_cos = -log_cos.exp_m1();
        let cos = 1.0 - one_minus_cos;
        let sin = (one_minus_cos * (1.0 + cos)).max(0.0).sqrt();
        let phi = 2.0 * std::f64::consts::PI * u.y as f64;
        Vec3::new(
            (sin * phi.cos()) as f32,
            (sin * phi.sin()) as f32,
            cos as f32,
        )
    }
}

impl Bsdf for Blinn {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::GLOSSY | BsdfFlags::REFLECTION
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.lobe(ctx).eval(wo, wi)
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let lobe = self.lobe(ctx);
        let wi = match lobe.sampling {
            LobeSampling::Model(_) => {
                let h = lobe.sample_half_vector(u2);
                if wo.dot(h) <= 0.0 {
                    return None;
                }
                reflect(wo, h)
            }
            baseline => baseline.sample_baseline(u2)?,
        };
        BsdfSample::reflection(
            wi,
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
            |wi| lobe.eval_pdf(wo, wi),
            |wi| lobe.eval(wo, wi),
        )
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.lobe(ctx).eval_pdf(wo, wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_exponent_stays_finite_and_peaked() {
        let b = Blinn::new(Rgb::WHITE, 1e6, BlinnSampling::Blinn.into());
        let ctx = BsdfContext::default();
        let wo = Vec3::new(0.0, 0.6, 0.8);
        let mirror = Vec3::new(0.0, -0.6, 0.8);
        let peak = b.f(&ctx, wo, mirror);
        assert!(peak.is_finite() && peak.r > 1e4, "{peak:?}");
        let s = b.sample_f(&ctx, wo, 0.5, Vec2::new(0.5, 0.25)).unwrap();
        assert!((s.wi - mirror).length() < 0.01 && s.pdf.is_finite());
        // Grazing on both sides: finite and non-negative, no 0/0.
        let grazing = Vec3::new(1.0, 0.0, 1e-6).normalize();
        let v = b.f(&ctx, grazing, Vec3::new(-1.0, 1e-3, 1e-6).normalize());
        assert!(v.is_finite() && v.r >= 0.0, "{v:?}");
        assert!(b.pdf(&ctx, grazing, mirror).is_finite());
    }
}
