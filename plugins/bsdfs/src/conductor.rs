//! `conductor`: rough metal, the Cook-Torrance microfacet BRDF
//!
//! f(wo, wi) = F(<wo, m>) D(m) G(wo, wi) / (4 cos theta_o cos theta_i),
//! m = normalize(wo + wi)
//!
//! (Walter et al. 2007, "Microfacet Models for Refraction through Rough
//! Surfaces", eq. 20) with Beckmann or GGX normals, height-correlated Smith
//! masking and the complex Fresnel term of the metal. `mirror` is its
//! delta limit, which `conductor` also becomes below a roughness of 1e-3.
//! One-sided, like Mitsuba's: black from behind.

use lumis_core::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, ParamSpec, ParamType, Params, PluginKind, PluginSpec,
    Result, Rgb, Vec2, Vec3,
};

use lumis_sampling::real::F32x4;

use crate::fresnel;
use crate::lobe_sampling::LobeSampling;
use crate::microfacet::{
    half_vector, Microfacet, DISTRIBUTION_PARAM, ROUGHNESS_PARAM, ROUGHNESS_V_PARAM,
};

const METAL_CHOICES: &[&str] = &["none", "Ag", "Al", "Au", "Cr", "Cu", "Fe", "Pt"];

const MATERIAL_PARAM: ParamSpec = ParamSpec::with_default(
    "material",
    ParamType::String,
    "\"none\"",
    "named metal (complex IOR at 650/550/450 nm) or none: a perfect reflector, Fresnel = 1",
)
.one_of(METAL_CHOICES);
const ETA_PARAM: ParamSpec = ParamSpec::optional(
    "eta",
    ParamType::Rgb,
    "real part of the IOR per channel, with k; replaces material",
);
const K_PARAM: ParamSpec = ParamSpec::optional(
    "k",
    ParamType::Rgb,
    "imaginary part (absorption) of the IOR per channel, with eta",
);
const SCALE_PARAM: ParamSpec = ParamSpec::with_default(
    "specular_reflectance",
    ParamType::Rgb,
    "1.0",
    "multiplies the Fresnel term (not physical; for artistic tints), each channel in [0, 1]",
);

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "conductor",
    doc: "rough metal: Cook-Torrance with GGX or Beckmann normals, Smith masking, complex Fresnel; one-sided",
    params: &[
        DISTRIBUTION_PARAM,
        ROUGHNESS_PARAM,
        ROUGHNESS_V_PARAM,
        MATERIAL_PARAM,
        ETA_PARAM,
        K_PARAM,
        SCALE_PARAM,
        ParamSpec::with_default(
            "sampling",
            ParamType::String,
            "\"visible\"",
            "visible normals (Heitz 2018 / Heitz-d'Eon 2014), full D cos, or cosine/uniform hemisphere for comparison",
        )
        .one_of(&["visible", "full", "cosine", "uniform"]),
    ],
};

pub const MIRROR_SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "mirror",
    doc: "smooth metal: delta reflection with the Fresnel term of the metal (conductor with roughness 0)",
    params: &[MATERIAL_PARAM, ETA_PARAM, K_PARAM, SCALE_PARAM],
};

/// The metal's reflectance at each angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConductorFresnel {
    /// Reflects everything at every angle (Fresnel = 1).
    Perfect,
    Complex {
        eta: Rgb,
        k: Rgb,
    },
}

impl ConductorFresnel {
    #[inline]
    pub fn eval(&self, cos_theta: f32) -> Rgb {
        match *self {
            Self::Perfect => Rgb::WHITE,
            Self::Complex { eta, k } => fresnel::conductor(cos_theta, eta, k),
        }
    }

    /// Reads `material`, `eta` and `k`.
    fn from_params(params: &Params) -> Result<Self> {
        let material = params.get_choice("material")?;
        let eta: Option<Rgb> = params.get_opt("eta")?;
        let k: Option<Rgb> = params.get_opt("k")?;
        match (eta, k) {
            (None, None) => Ok(match fresnel::metal(&material) {
                Some(m) => Self::Complex {
                    eta: m.eta.into(),
                    k: m.k.into(),
                },
                None => Self::Perfect,
            }),
            (Some(eta), Some(k)) => {
                if params.is_given("material") {
                    return Err(
                        params.error("material", "give either material or eta and k, not both")
                    );
                }
                if eta.min_component() <= 0.0 || k.min_component() < 0.0 {
                    return Err(params.error(
                        "eta",
                        format!("eta must be > 0 and k >= 0 per channel, got eta {eta:?}, k {k:?}"),
                    ));
                }
                Ok(Self::Complex { eta, k })
            }
            (Some(_), None) => Err(params.error("eta", "needs k too (the absorption)")),
            (None, Some(_)) => Err(params.error("k", "needs eta too (the real part)")),
        }
    }
}

#[derive(Debug, Clone)]
pub struct Conductor {
    /// `None`: a delta mirror.
    microfacet: Option<Microfacet>,
    fresnel: ConductorFresnel,
    scale: Rgb,
    sampling: LobeSampling,
}

fn scale_from_params(params: &Params) -> Result<Rgb> {
    let scale: Rgb = params.get("specular_reflectance")?;
    if !(scale.min_component() >= 0.0 && scale.max_component() <= 1.0) {
        return Err(params.error(
            "specular_reflectance",
            format!("each channel must be in [0, 1], got {scale:?}"),
        ));
    }
    Ok(scale)
}

impl Conductor {
    /// A rough conductor; a delta mirror if `microfacet` is smooth.
    pub fn new(microfacet: Microfacet, fresnel: ConductorFresnel, sampling: LobeSampling) -> Self {
        Self {
            microfacet: (!microfacet.is_smooth()).then_some(match sampling {
                LobeSampling::Model(s) => microfacet.with_sampling(s),
                _ => microfacet,
            }),
            fresnel,
            scale: Rgb::WHITE,
            sampling,
        }
    }

    pub fn mirror(fresnel: ConductorFresnel) -> Self {
        Self {
            microfacet: None,
            fresnel,
            scale: Rgb::WHITE,
            sampling: LobeSampling::Cosine,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let microfacet = Microfacet::from_params(params)?;
        let fresnel = ConductorFresnel::from_params(params)?;
        let sampling = LobeSampling::parse(&params.get_choice("sampling")?);
        Ok(Self {
            scale: scale_from_params(params)?,
            ..Self::new(microfacet, fresnel, sampling)
        })
    }

    pub fn mirror_from_params(params: &Params) -> Result<Self> {
        Ok(Self {
            scale: scale_from_params(params)?,
            ..Self::mirror(ConductorFresnel::from_params(params)?)
        })
    }

    /// `f` of the rough lobe from what it shares with the density, and
    /// `Lambda(wi)`, asked for only where `D` is not zero.
    #[inline]
    fn rough_f(&self, lobe: &LobeTerms, wi: Vec3, lambda_i: impl FnOnce() -> f32) -> Rgb {
        if lobe.d == 0.0 {
            return Rgb::BLACK;
        }
        // Height-correlated masking-shadowing (Heitz 2014, eq. 99).
        let g = 1.0 / (1.0 + lobe.lambda_o + lambda_i());
        self.scale * self.fresnel.eval(lobe.wo_m) * (lobe.d * g / (4.0 * lobe.wo.z * wi.z))
    }

    /// The density of the rough lobe's sampling at `wi`.
    #[inline]
    fn rough_pdf(&self, mf: &Microfacet, lobe: &LobeTerms, wi: Vec3) -> f32 {
        match self.sampling {
            // Reflection Jacobian d(omega_m)/d(omega_i) = 1 / (4 <wo, m>)
            // (Walter et al. 2007, eq. 14).
            LobeSampling::Model(_) => {
                mf.pdf_normal_from(lobe.wo, lobe.m, lobe.wo_m, lobe.d, lobe.lambda_o)
                    / (4.0 * lobe.wo_m)
            }
            baseline => baseline.baseline_pdf(wi.z),
        }
    }
}

/// What `f` and `pdf` of the rough lobe share at one pair of directions
/// (both above the surface): the half vector, `D` and `Lambda(wo)`, so
/// that `eval` and `sample_f` compute them once.
struct LobeTerms {
    wo: Vec3,
    m: Vec3,
    wo_m: f32,
    d: f32,
    lambda_o: f32,
}

impl LobeTerms {
    /// `None` where the lobe is zero: a direction at or below the horizon,
    /// or opposite directions (no half vector).
    #[inline]
    fn at(mf: &Microfacet, wo: Vec3, wi: Vec3) -> Option<Self> {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        let (m, wo_m) = half_vector(wo, wi)?;
        Some(Self {
            wo,
            m,
            wo_m,
            d: mf.d(m),
            lambda_o: mf.lambda(wo),
        })
    }
}

impl Bsdf for Conductor {
    fn flags(&self) -> BsdfFlags {
        match self.microfacet {
            Some(_) => BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
            None => BsdfFlags::SPECULAR | BsdfFlags::REFLECTION,
        }
    }

    #[inline]
    fn f(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(mf) = &self.microfacet else {
            return Rgb::BLACK;
        };
        LobeTerms::at(mf, wo, wi)
            .map_or(Rgb::BLACK, |lobe| self.rough_f(&lobe, wi, || mf.lambda(wi)))
    }

    fn sample_f(&self, _ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let Some(mf) = &self.microfacet else {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: self.scale * self.fresnel.eval(wo.z) / wo.z,
                wi,
                pdf: 1.0,
                flags: BsdfFlags::SPECULAR | BsdfFlags::REFLECTION,
                eta: 1.0,
            });
        };
        let wi = match self.sampling {
            LobeSampling::Model(_) => {
                let m = mf.sample_normal(wo, u2);
                // A facet facing away from wo would reflect into itself.
                if wo.dot(m) <= 0.0 {
                    return None;
                }
                fresnel::reflect(wo, m)
            }
            baseline => baseline.sample_baseline(u2)?,
        };
        let lobe = LobeTerms::at(mf, wo, wi)?;
        BsdfSample::reflection(
            wi,
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
            |wi| self.rough_pdf(mf, &lobe, wi),
            |wi| self.rough_f(&lobe, wi, || mf.lambda(wi)),
        )
    }

    #[inline]
    fn pdf(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        let Some(mf) = &self.microfacet else {
            return 0.0;
        };
        LobeTerms::at(mf, wo, wi).map_or(0.0, |lobe| self.rough_pdf(mf, &lobe, wi))
    }

    #[inline]
    fn eval(&self, _ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(mf) = &self.microfacet else {
            return (Rgb::BLACK, 0.0);
        };
        LobeTerms::at(mf, wo, wi).map_or((Rgb::BLACK, 0.0), |lobe| {
            (
                self.rough_f(&lobe, wi, || mf.lambda(wi)),
                self.rough_pdf(mf, &lobe, wi),
            )
        })
    }

    /// [`Bsdf::eval`] four lanes at a time: `D(m)`, `Lambda(wo)` and
    /// `Lambda(wi)`, the transcendental part, on SIMD lanes; the half
    /// vectors (in f64) and the rest per lane, in `eval`'s order, so each
    /// lane is bit for bit `eval`'s answer.
    fn eval_batch(&self, _ctx: &[BsdfContext], wo: &[Vec3], wi: &[Vec3], out: &mut [(Rgb, f32)]) {
        let Some(mf) = &self.microfacet else {
            out.fill((Rgb::BLACK, 0.0));
            return;
        };
        for ((wo, wi), out) in wo.chunks(4).zip(wi.chunks(4)).zip(out.chunks_mut(4)) {
            let n = out.len();
            // Per lane: the half vector, and the three directions as
            // columns; padding lanes (and lanes without a lobe) take the
            // normal.
            let mut halves = [None; 4];
            let mut columns = [[[0.0, 0.0, 1.0]; 4]; 3];
            for i in 0..n {
                halves[i] = (wo[i].z > 0.0 && wi[i].z > 0.0)
                    .then(|| half_vector(wo[i], wi[i]))
                    .flatten();
                let m = halves[i].map_or(Vec3::Z, |(m, _)| m);
                for (column, v) in columns.iter_mut().zip([m, wo[i], wi[i]]) {
                    column[i] = v.to_array();
                }
            }
            let lanes = |column: &[[f32; 3]; 4]| -> [F32x4; 3] {
                std::array::from_fn(|axis| F32x4::new(column.map(|v| v[axis])))
            };
            let d = mf.d_lanes(lanes(&columns[0])).to_array();
            let lambda_o = mf.lambda_lanes(lanes(&columns[1])).to_array();
            // `f` needs Lambda(wi) only where D is not zero, which for a
            // narrow lobe is the exception.
            let lambda_i = if d.iter().any(|&d| d != 0.0) {
                mf.lambda_lanes(lanes(&columns[2])).to_array()
            } else {
                [0.0; 4]
            };
            for (i, out) in out.iter_mut().enumerate() {
                *out = match halves[i] {
                    None => (Rgb::BLACK, 0.0),
                    Some((m, wo_m)) => {
                        let lobe = LobeTerms {
                            wo: wo[i],
                            m,
                            wo_m,
                            d: d[i],
                            lambda_o: lambda_o[i],
                        };
                        (
                            self.rough_f(&lobe, wi[i], || lambda_i[i]),
                            self.rough_pdf(mf, &lobe, wi[i]),
                        )
                    }
                };
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Distribution;

    #[test]
    fn below_the_threshold_roughness_is_a_mirror() {
        let ctx = BsdfContext::default();
        let c = Conductor::new(
            Microfacet::new(Distribution::Ggx, 1e-4, 1e-4),
            ConductorFresnel::Perfect,
            LobeSampling::parse("visible"),
        );
        assert!(c.flags().is_specular());
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let s = c.sample_f(&ctx, wo, 0.5, Vec2::splat(0.5)).unwrap();
        assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8));
        assert!((s.f.r * s.wi.z / s.pdf - 1.0).abs() < 1e-6, "reflects all");
        assert_eq!(c.pdf(&ctx, wo, s.wi), 0.0);
    }

    /// The SIMD `eval_batch` gives `eval`'s answer bit for bit, for both
    /// distributions from roughness 1e-3 to 1, anisotropic too, with
    /// directions from cos theta 1e-4 to 1, below the horizon and opposite,
    /// in batches that do and do not fill the last four lanes.
    #[test]
    fn eval_batch_is_eval_bit_for_bit() {
        let mut wo = Vec::new();
        let mut wi = Vec::new();
        for (i, cos_o) in [1e-4f32, 0.01, 0.3, 0.9, 1.0, -0.5].into_iter().enumerate() {
            for (j, cos_i) in [1e-4f32, 0.2, 0.7, 1.0, -0.1].into_iter().enumerate() {
                let dir = |c: f32, phi: f32| {
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    Vec3::new(s * phi.cos(), s * phi.sin(), c)
                };
                let o = dir(cos_o, 0.3 + i as f32);
                wo.push(o);
                wi.push(dir(cos_i, 2.9 + 0.5 * j as f32));
                // Near the mirror direction, where D is largest.
                wo.push(o);
                wi.push(Vec3::new(-o.x, -o.y, o.z.abs()).normalize());
            }
        }
        wo.push(Vec3::Z);
        wi.push(-Vec3::Z);
        let n = wo.len();
        let ctx = vec![BsdfContext::default(); n];
        for distribution in [Distribution::Beckmann, Distribution::Ggx] {
            for (ax, ay) in [(1e-3, 1e-3), (0.05, 0.05), (1.0, 1.0), (0.02, 0.5)] {
                let c = Conductor::new(
                    Microfacet::new(distribution, ax, ay),
                    ConductorFresnel::Complex {
                        eta: Rgb::new(0.2, 0.9, 1.1),
                        k: Rgb::new(3.9, 2.4, 2.2),
                    },
                    LobeSampling::parse("visible"),
                );
                for len in [0, 1, 7, 9, 33, n] {
                    let mut out = vec![(Rgb::splat(-1.0), -1.0); len];
                    c.eval_batch(&ctx[..len], &wo[..len], &wi[..len], &mut out);
                    for k in 0..len {
                        let (f, pdf) = c.eval(&ctx[k], wo[k], wi[k]);
                        let bits = |(f, pdf): (Rgb, f32)| [f.r, f.g, f.b, pdf].map(f32::to_bits);
                        assert_eq!(
                            bits(out[k]),
                            bits((f, pdf)),
                            "{distribution:?} {ax} {ay}: lane {k}, wo {:?}, wi {:?}",
                            wo[k],
                            wi[k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn metal_names_are_the_choices() {
        let names: Vec<&str> = fresnel::METALS.iter().map(|m| m.name).collect();
        assert_eq!(&METAL_CHOICES[1..], names.as_slice());
    }
}
