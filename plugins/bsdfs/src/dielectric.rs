//! `dielectric`: glass, smooth or rough.
//!
//! Smooth (`roughness` below 1e-3): Fresnel-weighted delta reflection and
//! refraction, each picked with its Fresnel probability. Rough: the
//! microfacet BTDF of Walter et al. 2007 ("Microfacet Models for Refraction
//! through Rough Surfaces", eqs. 20-21) with the generalized half vector
//! `m = normalize(wo + eta' wi)` and the refraction Jacobian
//! `d(omega_m)/d(omega_i) = |<wi, m>| / (<wi, m> + <wo, m>/eta')^2` (eq. 17,
//! as in pbrt-v4 `DielectricBxDF`). Relative indices within 1e-3 of 1 are
//! index-matched and rendered smooth.
//!
//! Radiance crossing into a denser medium is compressed into a smaller
//! solid angle: in radiance transport the transmitted term is divided by
//! `eta'^2`; importance is not (Veach 1997, section 5.2). `eta'` is the
//! relative index along the path: `eta` entering, `1/eta` leaving.

use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, TransportMode, Vec2, Vec3,
};

use crate::fresnel::{self, reflect, refract};
use crate::microfacet::{Microfacet, MicrofacetParams, NormalSampling, Roughness};

/// Relative indices closer to 1 than this are index-matched: reflection
/// is below 3e-7 and the rough transmission lobe narrower than 1e-3 rad,
/// so the interface is rendered as smooth (the rough formulas would divide
/// by the vanishing generalized half vector).
pub const INDEX_MATCHED: f32 = 1e-3;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "dielectric",
    source: lumis_api::source_file!(),
    doc: "glass: Fresnel reflection and refraction, smooth (delta) or rough (Walter et al. 2007)",
    params: DielectricParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct DielectricParams {
    /// index of refraction inside (the side opposite the normal); 1.5 is glass
    #[param(default = 1.5, range = (1.0, 5.0))]
    pub int_ior: f32,
    /// index of refraction outside (the side the normal points to)
    #[param(default = 1.0, range = (1.0, 5.0))]
    pub ext_ior: f32,
    /// Glass is smooth unless asked otherwise.
    #[param(flatten, default(roughness = 0.0))]
    pub microfacet: MicrofacetParams,
    /// microfacet normals: visible (Heitz 2018 / Heitz-d'Eon 2014) or full D cos
    #[param(default = Visible)]
    pub sampling: NormalSampling,
}

/// The generalized half vector of a pair of directions and its cosines.
#[derive(Debug, Clone, Copy)]
struct HalfVector {
    m: Vec3,
    cos_om: f32,
    cos_im: f32,
    /// Relative index along `wi` (1 for reflection).
    etap: f32,
    reflection: bool,
}

#[derive(Debug, Clone)]
pub struct Dielectric {
    /// Inside over outside.
    eta: f32,
    /// Its lobe, fixed or textured; a fixed delta is smooth glass.
    roughness: Roughness,
}

impl Dielectric {
    pub fn new(eta: f32, microfacet: Microfacet) -> Self {
        Self::with_roughness(eta, microfacet.into())
    }

    /// Glass of relative index `eta` and fixed or textured `roughness`;
    /// smooth where the indices match, whatever the roughness.
    pub fn with_roughness(eta: f32, roughness: Roughness) -> Self {
        let matched = (eta - 1.0).abs() < INDEX_MATCHED;
        Self {
            eta,
            roughness: if matched {
                Roughness::Fixed(None)
            } else {
                roughness
            },
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = DielectricParams::read(params)?;
        let roughness = p.microfacet.roughness().with_sampling(p.sampling);
        Ok(Self::with_roughness(p.int_ior / p.ext_ior, roughness))
    }

    fn sample_smooth(&self, ctx: &BsdfContext, wo: Vec3, u1: f32) -> Option<BsdfSample> {
        let r = fresnel::dielectric(wo.z, self.eta);
        let t = 1.0 - r;
        if u1 < r / (r + t) {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: Rgb::splat(r / wi.z.abs()),
                wi,
                pdf: r / (r + t),
                flags: BsdfFlags::SPECULAR | BsdfFlags::REFLECTION,
                eta: 1.0,
            });
        }
        let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
        if wi.z == 0.0 {
            return None;
        }
        let mut ft = t / wi.z.abs();
        if ctx.mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        Some(BsdfSample {
            f: Rgb::splat(ft),
            wi,
            pdf: t / (r + t),
            flags: BsdfFlags::SPECULAR | BsdfFlags::TRANSMISSION,
            eta: etap,
        })
    }

    /// The generalized half vector of `(wo, wi)` on the upper side, with
    /// the relative index along `wi` and whether the pair is a reflection;
    /// `None` if no microfacet connects them from the front.
    #[inline]
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<HalfVector> {
        let (cos_o, cos_i) = (wo.z, wi.z);
        if cos_o == 0.0 || cos_i == 0.0 {
            return None;
        }
        let reflection = cos_o * cos_i > 0.0;
        let etap = if reflection {
            1.0
        } else if cos_o > 0.0 {
            self.eta
        } else {
            1.0 / self.eta
        };
        // In f64 from normalised inputs, and the cosines with it, for the
        // reasons of `microfacet::half_vector`: at grazing angles (and for
        // eta near 1 in transmission) the two terms nearly cancel.
        let (o, i) = (wo.as_dvec3().normalize(), wi.as_dvec3().normalize());
        let m = i * etap as f64 + o;
        if m.length_squared() == 0.0 {
            return None;
        }
        let m = m.normalize();
        let m = if m.z < 0.0 { -m } else { m };
        let (cos_om, cos_im) = (o.dot(m), i.dot(m));
        // Back-facing microfacets (seen from behind by either direction).
        if cos_im * cos_i as f64 <= 0.0 || cos_om * cos_o as f64 <= 0.0 {
            return None;
        }
        Some(HalfVector {
            m: m.as_vec3(),
            cos_om: cos_om as f32,
            cos_im: cos_im as f32,
            etap,
            reflection,
        })
    }

    fn rough_f(&self, mf: &Microfacet, mode: TransportMode, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let d = mf.d(h.m);
        let g = mf.g(wo, wi);
        let f = fresnel::dielectric(h.cos_om, self.eta);
        let (cos_o, cos_i) = (wo.z, wi.z);
        if h.reflection {
            return d * g * f / (4.0 * cos_i * cos_o).abs();
        }
        let denom = (h.cos_im + h.cos_om / h.etap).powi(2) * cos_i * cos_o;
        let mut ft = d * (1.0 - f) * g * (h.cos_im * h.cos_om / denom).abs();
        if mode == TransportMode::Radiance {
            ft /= h.etap * h.etap;
        }
        ft
    }

    fn rough_pdf(&self, mf: &Microfacet, wo: Vec3, wi: Vec3) -> f32 {
        let Some(h) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = fresnel::dielectric(h.cos_om, self.eta);
        let t = 1.0 - r;
        let pdf_m = mf.pdf_normal(wo, h.m, h.cos_om);
        if h.reflection {
            pdf_m / (4.0 * h.cos_om.abs()) * r / (r + t)
        } else {
            let denom = (h.cos_im + h.cos_om / h.etap).powi(2);
            pdf_m * (h.cos_im.abs() / denom) * t / (r + t)
        }
    }

    fn sample_rough(
        &self,
        mf: &Microfacet,
        ctx: &BsdfContext,
        wo: Vec3,
        u1: f32,
        u2: Vec2,
    ) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let m = mf.sample_normal(wo, u2);
        // Only facets that face wo can scatter it (full sampling draws others).
        if wo.dot(m) * wo.z <= 0.0 {
            return None;
        }
        let r = fresnel::dielectric(wo.dot(m), self.eta);
        let t = 1.0 - r;
        let (wi, flags, eta) = if u1 < r / (r + t) {
            let wi = reflect(wo, m);
            if wi.z * wo.z <= 0.0 {
                return None;
            }
            (wi, BsdfFlags::GLOSSY | BsdfFlags::REFLECTION, 1.0)
        } else {
            let (wi, etap) = refract(wo, m, self.eta)?;
            if wi.z * wo.z >= 0.0 {
                return None;
            }
            (wi, BsdfFlags::GLOSSY | BsdfFlags::TRANSMISSION, etap)
        };
        let pdf = self.rough_pdf(mf, wo, wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(BsdfSample {
            f: Rgb::splat(self.rough_f(mf, ctx.mode, wo, wi)),
            wi,
            pdf,
            flags,
            eta,
        })
    }
}

impl Bsdf for Dielectric {
    fn flags(&self) -> BsdfFlags {
        let lobes = BsdfFlags::REFLECTION | BsdfFlags::TRANSMISSION;
        if self.roughness.is_delta() {
            lobes | BsdfFlags::SPECULAR
        } else {
            lobes | BsdfFlags::GLOSSY
        }
    }

    fn uses_tangent_frame(&self) -> bool {
        self.roughness.is_anisotropic()
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        match &self.roughness.at(&ctx.texture) {
            Some(mf) => Rgb::splat(self.rough_f(mf, ctx.mode, wo, wi)),
            None => Rgb::BLACK,
        }
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        match &self.roughness.at(&ctx.texture) {
            Some(mf) => self.sample_rough(mf, ctx, wo, u1, u2),
            None => self.sample_smooth(ctx, wo, u1),
        }
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        match &self.roughness.at(&ctx.texture) {
            Some(mf) => self.rough_pdf(mf, wo, wi),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Distribution;

    fn glass(alpha: f32) -> Dielectric {
        Dielectric::new(1.5, Microfacet::new(Distribution::Ggx, alpha, alpha))
    }

    #[test]
    fn smooth_glass_splits_energy_by_fresnel_and_scales_radiance() {
        let g = glass(0.0);
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let r = fresnel::dielectric(0.8, 1.5);
        let radiance = BsdfContext::default();
        let refl = g.sample_f(&radiance, wo, 0.0, Vec2::ZERO).unwrap();
        assert!((refl.pdf - r).abs() < 1e-6);
        assert!((refl.f.r * refl.wi.z / refl.pdf - 1.0).abs() < 1e-5);
        let tr = g.sample_f(&radiance, wo, 0.999, Vec2::ZERO).unwrap();
        assert!(tr.wi.z < 0.0 && tr.eta == 1.5);
        // Throughput f |cos| / pdf = 1 / eta^2 in radiance mode, 1 in importance mode.
        let w = tr.f.r * tr.wi.z.abs() / tr.pdf;
        assert!((w - 1.0 / 2.25).abs() < 1e-5, "{w}");
        let importance = BsdfContext {
            mode: TransportMode::Importance,
            ..Default::default()
        };
        let ti = g.sample_f(&importance, wo, 0.999, Vec2::ZERO).unwrap();
        assert!((ti.f.r * ti.wi.z.abs() / ti.pdf - 1.0).abs() < 1e-5);
    }

    #[test]
    fn index_matched_glass_is_smooth_and_transparent() {
        let g = Dielectric::new(1.0001, Microfacet::new(Distribution::Ggx, 0.5, 0.5));
        assert!(g.flags().is_specular());
        let wo = Vec3::new(0.0, 0.6, 0.8);
        let s = g
            .sample_f(&BsdfContext::default(), wo, 0.5, Vec2::splat(0.5))
            .unwrap();
        assert!((s.wi + wo).length() < 1e-3, "passes straight through");
    }

    #[test]
    fn rough_transmission_is_reciprocal_up_to_eta_squared() {
        // Without the radiance scaling, f_t(out, in) = eta^2 f_t(in, out)
        // (Veach 1997, eq. 5.14, with the outside index 1): the
        // generalized half-vector denominator picks up eta^2 on swapping.
        let g = glass(0.3);
        let mf = *g.roughness.fixed().unwrap();
        let above = Vec3::new(0.3, 0.1, 0.9).normalize();
        let below = Vec3::new(-0.2, 0.05, -0.95).normalize();
        let a = g.rough_f(&mf, TransportMode::Importance, above, below);
        let b = g.rough_f(&mf, TransportMode::Importance, below, above);
        assert!(a > 0.0 && b > 0.0);
        assert!((a / b - 1.5f32.powi(2)).abs() < 1e-3 * 2.25, "{a} / {b}");
    }
}
