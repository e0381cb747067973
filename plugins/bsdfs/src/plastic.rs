//! `plastic`: a diffuse base under a smooth or rough dielectric coat
//! (Weidlich and Wilkie 2007's layering, in the closed form of Mitsuba's
//! `plastic` / `roughplastic`).
//!
//! ```text
//! f = F(<wo, m>) D G / (4 cos theta_o cos theta_i)          (rough coat)
//!   + (1 - F(theta_i)) (1 - F(theta_o)) rho' / (pi eta^2)   (base)
//! ```
//!
//! The base term transmits through the coat twice; light reflected back
//! down by the coat's underside returns to the base, a geometric series
//! with the coat's internal diffuse reflectance `F_dr,int`:
//! `rho' = rho / (1 - rho F_dr,int)` (`nonlinear = true`, the physical one;
//! colours get more saturated) or `rho / (1 - F_dr,int)` (default:
//! `diffuse_reflectance` is then the base's albedo seen through the coat
//! at normal incidence, `rho (1 - F(theta_o))`). A smooth coat
//! (`roughness` below 1e-3) reflects as a delta.
//!
//! Sampling picks the coat with probability proportional to its albedo at
//! `wo`, `F(theta_o) s / (F(theta_o) s + (1 - F(theta_o)) rho)` (luminances),
//! else the base (cosine-weighted); `pdf` is the mixture (one-sample MIS
//! between the lobes). One-sided.
//!
//! A textured `diffuse_reflectance` is the base's albedo at each hit,
//! clamped to [0, 1]: the coat stays white, and `f`, `sample_f` and `pdf`
//! derive the base term and the lobe choice from the same texture value.

use std::f32::consts::FRAC_1_PI;

use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, TexturedRgb, Vec2, Vec3,
};
use lumis_sampling::warp;

use crate::fresnel::{self, reflect};
use crate::microfacet::{half_vector, Microfacet, MicrofacetParams, Roughness};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "plastic",
    source: lumis_api::source_file!(),
    doc: "diffuse base under a smooth or rough dielectric coat; lobe choice by albedo; one-sided",
    params: PlasticParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct PlasticParams {
    /// albedo rho of the base, each channel in [0, 1], or a texture
    #[param(default = 0.5)]
    pub diffuse_reflectance: TexturedRgb,
    /// scale of the coat's reflection (1 is physical), in [0, 1]
    #[param(default = 1.0)]
    pub specular_reflectance: TexturedRgb,
    /// index of refraction of the coat (polypropylene 1.49)
    #[param(default = 1.49, range = (1.0, 5.0))]
    pub int_ior: f32,
    /// index of refraction outside
    #[param(default = 1.0, range = (1.0, 5.0))]
    pub ext_ior: f32,
    /// The coat is smooth unless asked otherwise.
    #[param(flatten, default(roughness = 0.0))]
    pub coat: MicrofacetParams,
    /// account for the colour shift of internal scattering (see the module
    /// docs)
    #[param(default = false)]
    pub nonlinear: bool,
}

/// The layers as one hit sees them: the base's albedo, the coat's
/// roughness and its scale, each constant or textured.
#[derive(Debug, Clone, Copy)]
struct Base {
    /// `rho'`, the base's albedo including the internal reflections, over
    /// `pi eta^2`.
    f: Rgb,
    /// Luminance of `rho`, for the lobe choice.
    weight: f32,
    /// The coat's lobe; `None`: smooth.
    coat: Option<Microfacet>,
    /// The coat's scale, and its luminance for the lobe choice.
    specular: Rgb,
    specular_weight: f32,
}

#[derive(Debug, Clone)]
pub struct Plastic {
    /// The layers, precomputed, where no parameter is textured.
    constant: Option<Base>,
    /// `rho`, a constant or a texture.
    diffuse: TexturedRgb,
    /// The coat's scale, a constant or a texture.
    specular: TexturedRgb,
    /// The coat's internal diffuse reflectance `F_dr,int`.
    fdr_int: f32,
    nonlinear: bool,
    eta: f32,
    /// The coat's lobe, fixed or textured; a fixed delta is smooth.
    coat: Roughness,
}

impl Plastic {
    pub fn new(
        diffuse: impl Into<TexturedRgb>,
        specular: impl Into<TexturedRgb>,
        eta: f32,
        coat: impl Into<Roughness>,
        nonlinear: bool,
    ) -> Self {
        let mut plastic = Self {
            constant: None,
            diffuse: diffuse.into(),
            specular: specular.into(),
            // Light inside the coat meets it from the side of index 1/eta.
            fdr_int: fresnel::diffuse_reflectance(1.0 / eta),
            nonlinear,
            eta,
            coat: coat.into(),
        };
        if let (Some(diffuse), Some(specular), Roughness::Fixed(coat)) = (
            plastic.diffuse.constant(),
            plastic.specular.constant(),
            &plastic.coat,
        ) {
            plastic.constant = Some(plastic.base_of(diffuse, specular, *coat));
        }
        plastic
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = PlasticParams::read(params)?;
        let keys = PlasticParams::KEYS;
        for (key, v) in [
            (keys.diffuse_reflectance, p.diffuse_reflectance.constant()),
            (keys.specular_reflectance, p.specular_reflectance.constant()),
        ] {
            let Some(v) = v else { continue };
            if !(v.min_component() >= 0.0 && v.max_component() <= 1.0) {
                return Err(params.error(key, format!("each channel must be in [0, 1], got {v}")));
            }
        }
        Ok(Self::new(
            p.diffuse_reflectance,
            p.specular_reflectance,
            p.int_ior / p.ext_ior,
            p.coat.roughness(),
            p.nonlinear,
        ))
    }

    /// The layers of base albedo `diffuse`, coat scale `specular` and coat
    /// lobe `coat`.
    #[inline]
    fn base_of(&self, diffuse: Rgb, specular: Rgb, coat: Option<Microfacet>) -> Base {
        let rho = if self.nonlinear {
            diffuse.map(|r| r / (1.0 - r * self.fdr_int))
        } else {
            diffuse / (1.0 - self.fdr_int)
        };
        Base {
            f: rho * (FRAC_1_PI / (self.eta * self.eta)),
            weight: diffuse.luminance(),
            coat,
            specular,
            specular_weight: specular.luminance(),
        }
    }

    /// The layers at this hit: the precomputed ones, or the textures'
    /// values there (colours clamped to [0, 1], where the internal
    /// reflections' series converges).
    #[inline]
    fn base(&self, ctx: &BsdfContext) -> Base {
        if let Some(constant) = self.constant {
            return constant;
        }
        let q = &ctx.texture;
        let unit = |c: Rgb| c.map(|v| v.clamp(0.0, 1.0));
        self.base_of(
            unit(self.diffuse.eval(q)),
            unit(self.specular.eval(q)),
            self.coat.at(q),
        )
    }

    /// Probability of sampling the coat from `wo`, which has Fresnel `fo`.
    #[inline]
    fn coat_probability(&self, base: &Base, fo: f32) -> f32 {
        let coat = fo * base.specular_weight;
        let base = (1.0 - fo) * base.weight;
        if coat + base > 0.0 {
            coat / (coat + base)
        } else {
            0.0
        }
    }

    #[inline]
    fn base_f(&self, base: &Base, fo: f32, wi: Vec3) -> Rgb {
        let fi = fresnel::dielectric(wi.z, self.eta);
        base.f * ((1.0 - fi) * (1.0 - fo))
    }

    /// The coat's value for the half vector `m` (with `<wo, m>`).
    #[inline]
    fn coat_f(
        &self,
        base: &Base,
        mf: &Microfacet,
        (m, wo_m): (Vec3, f32),
        wo: Vec3,
        wi: Vec3,
    ) -> Rgb {
        let d = mf.d(m);
        if d == 0.0 {
            return Rgb::BLACK;
        }
        let f = fresnel::dielectric(wo_m, self.eta);
        base.specular * (f * d * mf.g(wo, wi) / (4.0 * wo.z * wi.z))
    }

    #[inline]
    fn coat_pdf(mf: &Microfacet, (m, wo_m): (Vec3, f32), wo: Vec3) -> f32 {
        mf.pdf_normal(wo, m, wo_m) / (4.0 * wo_m)
    }

    /// `f` for directions both above the surface; `fo` is the Fresnel
    /// term at `wo`, `half` the half vector (if any) for a rough coat.
    #[inline]
    fn f_above(&self, base: &Base, fo: f32, half: Option<(Vec3, f32)>, wo: Vec3, wi: Vec3) -> Rgb {
        let f = self.base_f(base, fo, wi);
        match (&base.coat, half) {
            (Some(mf), Some(half)) => f + self.coat_f(base, mf, half, wo, wi),
            _ => f,
        }
    }

    /// `pdf` for directions both above the surface, as [`Self::f_above`].
    #[inline]
    fn pdf_above(
        &self,
        base: &Base,
        fo: f32,
        half: Option<(Vec3, f32)>,
        wo: Vec3,
        wi: Vec3,
    ) -> f32 {
        let p = self.coat_probability(base, fo);
        let diffuse = (1.0 - p) * warp::cosine_hemisphere_pdf(wi.z);
        match (&base.coat, half) {
            (Some(mf), Some(half)) => diffuse + p * Self::coat_pdf(mf, half, wo),
            _ => diffuse,
        }
    }

    /// What `f` and `pdf` share: `None` below the surface, else the Fresnel
    /// term at `wo` and the rough coat's half vector.
    #[inline]
    fn geometry(&self, base: &Base, wo: Vec3, wi: Vec3) -> Option<(f32, Option<(Vec3, f32)>)> {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        let fo = fresnel::dielectric(wo.z, self.eta);
        let half = base.coat.as_ref().and_then(|_| half_vector(wo, wi));
        Some((fo, half))
    }

    #[inline]
    fn eval_f(&self, base: &Base, wo: Vec3, wi: Vec3) -> Rgb {
        match self.geometry(base, wo, wi) {
            Some((fo, half)) => self.f_above(base, fo, half, wo, wi),
            None => Rgb::BLACK,
        }
    }

    #[inline]
    fn eval_pdf(&self, base: &Base, wo: Vec3, wi: Vec3) -> f32 {
        match self.geometry(base, wo, wi) {
            Some((fo, half)) => self.pdf_above(base, fo, half, wo, wi),
            None => 0.0,
        }
    }
}

impl Bsdf for Plastic {
    fn flags(&self) -> BsdfFlags {
        let base = BsdfFlags::DIFFUSE_REFLECTION;
        if self.coat.is_delta() {
            base | BsdfFlags::SPECULAR
        } else {
            base | BsdfFlags::GLOSSY
        }
    }

    fn uses_tangent_frame(&self) -> bool {
        self.coat.is_anisotropic()
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval_f(&self.base(ctx), wo, wi)
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let base = self.base(ctx);
        let fo = fresnel::dielectric(wo.z, self.eta);
        let p = self.coat_probability(&base, fo);
        let wi = if u1 < p {
            let Some(mf) = &base.coat else {
                let wi = Vec3::new(-wo.x, -wo.y, wo.z);
                return Some(BsdfSample {
                    f: base.specular * (fo / wi.z),
                    wi,
                    pdf: p,
                    flags: BsdfFlags::SPECULAR | BsdfFlags::REFLECTION,
                    eta: 1.0,
                });
            };
            let m = mf.sample_normal(wo, u2);
            if wo.dot(m) <= 0.0 {
                return None;
            }
            reflect(wo, m)
        } else {
            warp::square_to_cosine_hemisphere(u2)
        };
        let flags = if base.coat.is_some() && u1 < p {
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION
        } else {
            BsdfFlags::DIFFUSE_REFLECTION
        };
        // `pdf` and `f` as `Self::eval` gives them (`reflection` rejects
        // `wi` below the surface first), sharing `fo` and the half vector.
        let half = base.coat.as_ref().and_then(|_| half_vector(wo, wi));
        BsdfSample::reflection(
            wi,
            flags,
            |wi| self.pdf_above(&base, fo, half, wo, wi),
            |wi| self.f_above(&base, fo, half, wo, wi),
        )
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.eval_pdf(&self.base(ctx), wo, wi)
    }

    /// One base (texture), one Fresnel term at `wo`, one half vector.
    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let base = self.base(ctx);
        let Some((fo, half)) = self.geometry(&base, wo, wi) else {
            return (Rgb::BLACK, 0.0);
        };
        (
            self.f_above(&base, fo, half, wo, wi),
            self.pdf_above(&base, fo, half, wo, wi),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Distribution;

    #[test]
    fn smooth_plastic_albedo_is_coat_plus_base_through_it() {
        // Linear mode: albedo = F(theta_o) + rho (1 - F(theta_o)) exactly.
        let rho = Rgb::new(0.2, 0.5, 0.8);
        let p = Plastic::new(
            rho,
            Rgb::WHITE,
            1.5,
            Microfacet::new(Distribution::Ggx, 0.0, 0.0),
            false,
        );
        let ctx = BsdfContext::default();
        let wo = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let fo = fresnel::dielectric(wo.z, 1.5);
        let mut rng = lumis_sampling::Pcg32::new(1, 2);
        let n = 400_000;
        let mut sum = Rgb::BLACK;
        for _ in 0..n {
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = p.sample_f(&ctx, wo, rng.next_f32(), u2) {
                sum += s.f * (s.wi.z / s.pdf);
            }
        }
        let albedo = sum / n as f32;
        let want = Rgb::splat(fo) + rho * (1.0 - fo);
        assert!(
            (albedo - want).map(f32::abs).max_component() < 4e-3,
            "{albedo:?} vs {want:?}"
        );
    }

    /// A texture of constant value `c`.
    struct Flat(Rgb);

    impl lumis_api::Texture for Flat {
        fn eval(&self, _: &lumis_api::TextureQuery) -> Rgb {
            self.0
        }
    }

    #[test]
    fn a_textured_base_is_the_plastic_of_the_texture_value() {
        // f, pdf and every sample (lobe choice included) of a base textured
        // with c equal those of the plastic built with c, to the bit, so the
        // chi-square coverage of the untextured model carries over.
        let rho = Rgb::new(0.9, 0.15, 0.0);
        for (alpha, nonlinear) in [(0.0, false), (0.3, false), (0.3, true)] {
            let coat = Microfacet::new(Distribution::Ggx, alpha, alpha);
            let texture = lumis_api::params::Textured::Texture(std::sync::Arc::new(Flat(rho)));
            let textured = Plastic::new(texture, Rgb::WHITE, 1.5, coat, nonlinear);
            let constant = Plastic::new(rho, Rgb::WHITE, 1.5, coat, nonlinear);
            let ctx = BsdfContext::default();
            let mut rng = lumis_sampling::Pcg32::new(3, 4);
            for _ in 0..2000 {
                let wo =
                    warp::square_to_cosine_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                let wi =
                    warp::square_to_cosine_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
                assert_eq!(textured.f(&ctx, wo, wi), constant.f(&ctx, wo, wi));
                assert_eq!(textured.pdf(&ctx, wo, wi), constant.pdf(&ctx, wo, wi));
                let (u1, u2) = (rng.next_f32(), Vec2::new(rng.next_f32(), rng.next_f32()));
                assert_eq!(
                    textured.sample_f(&ctx, wo, u1, u2),
                    constant.sample_f(&ctx, wo, u1, u2)
                );
            }
            // The coat is not tinted: the smooth coat's mirror sample is
            // white under a base without blue.
            if alpha == 0.0 {
                let wo = Vec3::new(0.6, 0.0, 0.8);
                let s = textured.sample_f(&ctx, wo, 0.0, Vec2::splat(0.5)).unwrap();
                assert!(s.flags.is_specular());
                assert!(s.f.r == s.f.g && s.f.g == s.f.b && s.f.b > 0.0, "{:?}", s.f);
            }
        }
    }
}
