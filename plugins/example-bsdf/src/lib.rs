//! `phong`: the energy-conserving modified Phong BRDF, as a dynamically
//! loaded plugin.
//!
//! Lafortune and Willems 1994, "Using the Modified Phong Reflectance Model
//! for Physically Based Rendering" (eq. 6):
//!
//! f(wo, wi) = rho_d / pi + rho_s (n + 2) / (2 pi) cos^n(alpha),
//!
//! alpha the angle between wi and the mirror direction of wo. It conserves
//! energy when rho_d + rho_s <= 1 per channel. Sampling picks a lobe with
//! probability proportional to its albedo and draws from it: cosine-weighted
//! for the diffuse lobe, cos^n(alpha) around the mirror direction
//! (`cos alpha = u^(1/(n+1))`, eq. 9) for the glossy one; the pdf is the
//! mixture of both (one-sample MIS between lobes).

use std::f32::consts::{FRAC_1_PI, PI};
use std::sync::Arc;

use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Frame, ParamChoice, Params, PluginKind, PluginParams,
    PluginSpec, Registrar, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "phong",
    source: lumis_api::source_file!(),
    doc: "modified Phong (Lafortune-Willems 1994): diffuse + normalized cos^n lobe, lobe-mixture sampling; one-sided",
    params: PhongParams::SPECS,
};

/// The parameters, declared once: each field is a scene key, its `///`
/// comment the description `lumis plugins` shows.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct PhongParams {
    /// diffuse albedo rho_d
    #[param(default = 0.5)]
    pub diffuse: Rgb,
    /// glossy albedo rho_s; rho_d + rho_s <= 1 per channel
    #[param(default = 0.2)]
    pub specular: Rgb,
    /// Phong exponent n in [0, 1e4]; larger = sharper
    #[param(default = 30.0, range = (0.0, 1e4))]
    pub exponent: f32,
    /// lobes: each lobe's own shape (the model's sampling); cosine or
    /// uniform hemisphere, for comparison
    #[param(default = Lobes)]
    pub sampling: Sampling,
}

/// How `sample_f` draws directions; `pdf` always matches it. The scene
/// names the variants in lower case: `sampling = "cosine"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Sampling {
    /// Pick a lobe by albedo, then sample its own shape.
    Lobes,
    /// Cosine-weighted hemisphere, ignoring the glossy lobe.
    Cosine,
    /// Uniform hemisphere, ignoring both lobes.
    Uniform,
}

/// Registers the plugin; exported through [`lumis_api::lumis_plugin!`].
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_bsdf(SPEC, |p| Ok(Arc::new(Phong::from_params(p)?)))
}

lumis_api::lumis_plugin!(register);

#[derive(Debug, Clone)]
pub struct Phong {
    diffuse: Rgb,
    specular: Rgb,
    exponent: f32,
    /// Probability of sampling the glossy lobe.
    glossy_probability: f32,
    sampling: Sampling,
}

impl Phong {
    pub fn new(diffuse: Rgb, specular: Rgb, exponent: f32) -> Self {
        let (d, s) = (diffuse.luminance(), specular.luminance());
        let glossy_probability = if d + s > 0.0 { s / (d + s) } else { 0.0 };
        Self {
            diffuse,
            specular,
            exponent,
            glossy_probability,
            sampling: Sampling::Lobes,
        }
    }

    /// The same BSDF drawing directions another way.
    pub fn with_sampling(self, sampling: Sampling) -> Self {
        Self { sampling, ..self }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        // Types, ranges and choices are checked by `read`; what only this
        // model can judge is checked here, the error located at the value.
        let p = PhongParams::read(params)?;
        let specular = PhongParams::KEYS.specular;
        if p.diffuse.min_component() < 0.0 || p.specular.min_component() < 0.0 {
            return Err(params.error(specular, "albedos must be non-negative"));
        }
        if (p.diffuse + p.specular).max_component() > 1.0 {
            return Err(params.error(
                specular,
                format!(
                    "diffuse + specular must be <= 1 per channel to conserve energy, got {:?}",
                    p.diffuse + p.specular
                ),
            ));
        }
        Ok(Self::new(p.diffuse, p.specular, p.exponent).with_sampling(p.sampling))
    }

    #[inline]
    fn mirror(wo: Vec3) -> Vec3 {
        Vec3::new(-wo.x, -wo.y, wo.z)
    }

    /// cos^n(alpha), zero behind the lobe; `powf` of a value in [0, 1] never
    /// overflows, even for n = 1e6.
    #[inline]
    fn lobe(&self, wo: Vec3, wi: Vec3) -> f32 {
        let cos_alpha = wi.dot(Self::mirror(wo)).min(1.0);
        if cos_alpha <= 0.0 {
            0.0
        } else {
            cos_alpha.powf(self.exponent)
        }
    }
}

impl Bsdf for Phong {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION | BsdfFlags::GLOSSY
    }

    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::BLACK;
        }
        let glossy = (self.exponent + 2.0) * 0.5 * FRAC_1_PI * self.lobe(wo, wi);
        self.diffuse * FRAC_1_PI + self.specular * glossy
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 || self.diffuse.is_black() && self.specular.is_black() {
            return None;
        }
        let glossy = self.sampling == Sampling::Lobes && u1 < self.glossy_probability;
        let wi = if self.sampling == Sampling::Uniform {
            warp::square_to_uniform_hemisphere(u2)
        } else if glossy {
            let cos_alpha = u2.x.powf(1.0 / (self.exponent + 1.0));
            let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
            let phi = 2.0 * PI * u2.y;
            let local = Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha);
            Frame::from_z(Self::mirror(wo)).to_world(local)
        } else {
            warp::square_to_cosine_hemisphere(u2)
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf(ctx, wo, wi);
        (pdf > 0.0).then(|| BsdfSample {
            f: self.f(ctx, wo, wi),
            wi,
            pdf,
            flags: if glossy || self.sampling != Sampling::Lobes {
                BsdfFlags::GLOSSY | BsdfFlags::REFLECTION
            } else {
                BsdfFlags::DIFFUSE_REFLECTION
            },
            eta: 1.0,
        })
    }

    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match self.sampling {
            Sampling::Uniform => warp::uniform_hemisphere_pdf(wi.z),
            Sampling::Cosine => warp::cosine_hemisphere_pdf(wi.z),
            Sampling::Lobes => {
                let glossy = (self.exponent + 1.0) * 0.5 * FRAC_1_PI * self.lobe(wo, wi);
                (1.0 - self.glossy_probability) * warp::cosine_hemisphere_pdf(wi.z)
                    + self.glossy_probability * glossy
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_check::adapters::bsdf_pair;
    use lumis_check::{chi_square, corrected_significance, ChiSquareConfig};
    use lumis_sampling::Pcg32;

    fn dir(cos_theta: f32, phi: f32) -> Vec3 {
        let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
    }

    const EXPONENTS: [f32; 4] = [0.0, 1.0, 30.0, 300.0];
    const COSINES: [f32; 4] = [1e-4, 0.1, 0.5, 1.0];

    #[test]
    fn reciprocal_finite_and_energy_conserving() {
        let ctx = BsdfContext::default();
        let mut rng = Pcg32::new(4, 4);
        for n in EXPONENTS.into_iter().chain([1e6]) {
            let bsdf = Phong::new(Rgb::splat(0.4), Rgb::splat(0.6), n);
            for cos_o in COSINES {
                let wo = dir(cos_o, 0.4);
                let wi = dir(0.7, 2.0);
                let (a, b) = (bsdf.f(&ctx, wo, wi), bsdf.f(&ctx, wi, wo));
                assert!(
                    (a - b).max_component().abs() <= 1e-5 * a.max_component().max(1.0),
                    "reciprocity"
                );
                // White furnace per direction: albedo <= 1 when rho_d + rho_s = 1.
                let samples = 100_000;
                let mut albedo = 0.0f64;
                for _ in 0..samples {
                    let u = Vec2::new(rng.next_f32(), rng.next_f32());
                    if let Some(s) = bsdf.sample_f(&ctx, wo, rng.next_f32(), u) {
                        let v = s.f.r * s.wi.z / s.pdf;
                        assert!(v.is_finite() && v >= 0.0, "n {n} cos {cos_o}: {s:?}");
                        albedo += v as f64;
                    }
                }
                albedo /= samples as f64;
                assert!(
                    albedo <= 1.0 + 5e-3,
                    "n {n}, cos_o {cos_o}: albedo {albedo}"
                );
            }
        }
    }

    #[test]
    fn sampling_matches_pdf() {
        let cfg = ChiSquareConfig {
            significance: corrected_significance(0.01, EXPONENTS.len() * COSINES.len()),
            ..Default::default()
        };
        for n in EXPONENTS {
            let bsdf = Phong::new(Rgb::splat(0.3), Rgb::splat(0.5), n);
            for c in COSINES {
                let (sample, pdf) = bsdf_pair(&bsdf, dir(c, 1.3));
                let report = chi_square(sample, pdf, &cfg);
                assert!(report.passed, "n {n} cos {c}: {report:?}");
                assert!(report.pdf_integral <= 1.0 + 1e-3);
            }
        }
    }
}
