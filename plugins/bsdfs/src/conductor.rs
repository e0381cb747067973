//! `conductor`: rough metal, the Cook-Torrance microfacet BRDF
//!
//! f(wo, wi) = F(<wo, m>) D(m) G(wo, wi) / (4 cos theta_o cos theta_i),
//! m = normalize(wo + wi)
//!
//! (Walter et al. 2007, "Microfacet Models for Refraction through Rough
//! Surfaces", eq. 20) with Beckmann or GGX normals, height-correlated Smith
//! masking and the complex Fresnel term of the metal, from a named
//! `material` or from `eta` and `k`. `mirror` is its delta limit, with the
//! same Fresnel term (`material`, `eta`, `k` and `specular_reflectance`);
//! `conductor` also becomes it below a roughness of 1e-3. One-sided, like
//! Mitsuba's: black from behind.
//!
//! `roughness_v` makes the lobe anisotropic. `sampling = "visible"` draws
//! visible normals (Heitz 2018 for GGX, Heitz and d'Eon 2014 for Beckmann);
//! `"full"` draws from `D cos theta_m`. A textured `specular_reflectance`
//! multiplies the whole value, which is exact since `f` is linear in it and
//! sampling ignores it. [BSDF sampling](studies/bsdfs.md) has the microfacet
//! code shared with `dielectric` and `plastic`, and the choices made at the
//! extremes.

use lumis_api::bsdf::{
    eval_each, eval_lanes_by_batch, sample_f_each, sample_f_lanes_by_batch, BsdfEvalLanes,
    BsdfSampleLanes,
};
use lumis_api::lanes::{Floats, LaneMask, Vec2Lanes, Vec3Lanes, LANES};
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, TexturedRgb, Vec2, Vec3,
};

use lumis_sampling::real::{load, F32x8, Real, V3};
use lumis_sampling::simd;

use crate::fresnel;
use crate::lobe_sampling::{LobeSampling, MicrofacetLobeSampling};
use crate::metal_fresnel::{ConductorFresnel, MetalFresnel};
use crate::metal_params::MetalParams;
use crate::microfacet::{
    half_vector, half_vector_lanes, Microfacet, MicrofacetParams, NormalSampling, Roughness,
};

/// The SIMD lanes of the batched methods: eight, two SSE2 halves without
/// `-C target-cpu`, which interleave two independent chains of the
/// special functions' and Newton's serial steps. Measured with
/// `cargo bench -p lumis-bsdfs --bench eval_batch` against four lanes:
/// 1.3 to 1.5 times faster for `eval_batch` and 1.4 to 1.5 times for
/// `sample_f_batch`. Sixteen sampled faster again but evaluated GGX
/// slower, and waste more of the last chunk of a material's lanes.
type Lanes = F32x8;

/// The widest [`Lanes`] the batched methods' per-chunk arrays hold.
const MAX_LANES: usize = 8;
const _: () = assert!(Lanes::LANES <= MAX_LANES);

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "conductor",
    source: lumis_api::source_file!(),
    doc: "rough metal: Cook-Torrance with GGX or Beckmann normals, Smith masking, complex Fresnel; one-sided",
    params: ConductorParams::SPECS,
};

pub const MIRROR_SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "mirror",
    source: lumis_api::source_file!(),
    doc: "smooth metal: delta reflection with the Fresnel term of the metal (conductor with roughness 0)",
    params: MetalParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct ConductorParams {
    #[param(flatten)]
    pub microfacet: MicrofacetParams,
    #[param(flatten)]
    pub metal: MetalParams,
    /// visible normals (Heitz 2018 / Heitz-d'Eon 2014), full D cos, or
    /// cosine/uniform hemisphere for comparison
    #[param(default = Visible)]
    pub sampling: MicrofacetLobeSampling,
}

#[derive(Debug, Clone)]
pub struct Conductor {
    /// Its lobe, fixed or textured; a fixed delta is a mirror.
    roughness: Roughness,
    fresnel: MetalFresnel,
    scale: Rgb,
    /// A textured `specular_reflectance`, which multiplies every value.
    tint: Option<TexturedRgb>,
    sampling: LobeSampling,
}

impl Conductor {
    /// A rough conductor; a delta mirror if `microfacet` is smooth.
    pub fn new(microfacet: Microfacet, fresnel: ConductorFresnel, sampling: LobeSampling) -> Self {
        Self::with_roughness(microfacet.into(), fresnel.into(), sampling)
    }

    /// A conductor of fixed or textured `roughness`.
    pub fn with_roughness(
        roughness: Roughness,
        fresnel: MetalFresnel,
        sampling: LobeSampling,
    ) -> Self {
        Self {
            roughness: match sampling {
                LobeSampling::Model(s) => roughness.with_sampling(s),
                _ => roughness,
            },
            fresnel,
            scale: Rgb::WHITE,
            tint: None,
            sampling,
        }
    }

    pub fn mirror(fresnel: impl Into<MetalFresnel>) -> Self {
        Self {
            roughness: Roughness::Fixed(None),
            fresnel: fresnel.into(),
            scale: Rgb::WHITE,
            tint: None,
            sampling: LobeSampling::Cosine,
        }
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = ConductorParams::read(params)?;
        let fresnel = p.metal.fresnel(params)?;
        Ok(Self {
            scale: p.metal.scale(params)?,
            tint: p.metal.tint(),
            ..Self::with_roughness(p.microfacet.roughness(), fresnel, p.sampling.into())
        })
    }

    pub fn mirror_from_params(params: &Params) -> Result<Self> {
        let metal = MetalParams::read(params)?;
        Ok(Self {
            scale: metal.scale(params)?,
            tint: metal.tint(),
            ..Self::mirror(metal.fresnel(params)?)
        })
    }

    /// [`Bsdf::sample_f`] before a textured tint.
    fn sample_untinted(&self, ctx: &BsdfContext, wo: Vec3, u2: Vec2) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let Some(mf) = &self.roughness.at(&ctx.texture) else {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: self.scale * self.fresnel.at(&ctx.texture).eval(wo.z) / wo.z,
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
        let (f, pdf) = self.rough_eval(mf, self.fresnel.at(&ctx.texture), &lobe, wi);
        BsdfSample::reflection(
            wi,
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
            |_| pdf,
            |_| f,
        )
    }

    /// `f` times the textured tint at this hit, if there is one.
    #[inline]
    fn tinted(&self, ctx: &BsdfContext, f: Rgb) -> Rgb {
        match &self.tint {
            Some(tint) => tint.eval(&ctx.texture) * f,
            None => f,
        }
    }

    /// `f` of the rough lobe (one pair, or a pair per lane) from what it
    /// shares with the density, and `Lambda(wi)` and the Fresnel term,
    /// asked for only where `D` is not zero: zero where it is.
    #[inline(always)]
    fn rough_f<F: Real>(
        &self,
        lobe: &LobeTerms<F>,
        wi_z: F,
        lambda_i: impl FnOnce() -> F,
        fresnel: impl FnOnce() -> [F; 3],
    ) -> [F; 3] {
        let zero = F::splat(0.0);
        let black = lobe.d.eq(zero);
        if F::all(black) {
            return [zero; 3];
        }
        // Height-correlated masking-shadowing (Heitz 2014, eq. 99).
        let g = F::splat(1.0) / (F::splat(1.0) + lobe.lambda_o + lambda_i());
        let value = lobe.d * g / (F::splat(4.0) * lobe.wo_z * wi_z);
        let fresnel = fresnel();
        let scale = self.scale.to_array();
        std::array::from_fn(|c| F::select(black, zero, F::splat(scale[c]) * fresnel[c] * value))
    }

    /// The density of the rough lobe's sampling at `wi` (one pair, or a
    /// pair per lane).
    #[inline(always)]
    fn rough_pdf<F: Real>(&self, mf: &Microfacet, lobe: &LobeTerms<F>, wi_z: F) -> F {
        match self.sampling {
            // Reflection Jacobian d(omega_m)/d(omega_i) = 1 / (4 <wo, m>)
            // (Walter et al. 2007, eq. 14).
            LobeSampling::Model(_) => {
                mf.pdf_normal_lanes(lobe.wo_z, lobe.m_z, lobe.wo_m, lobe.d, lobe.lambda_o)
                    / (F::splat(4.0) * lobe.wo_m)
            }
            baseline => F::from_fn(|i| baseline.baseline_pdf(wi_z.lane(i))),
        }
    }

    /// `(f, pdf)` of the rough lobe of Fresnel term `fresnel` at one pair
    /// above the surface.
    #[inline]
    fn rough_eval(
        &self,
        mf: &Microfacet,
        fresnel: ConductorFresnel,
        lobe: &LobeTerms<f32>,
        wi: Vec3,
    ) -> (Rgb, f32) {
        let f = self.rough_f(
            lobe,
            wi.z,
            || mf.lambda(wi),
            || fresnel.eval(lobe.wo_m).to_array(),
        );
        (f.into(), self.rough_pdf(mf, lobe, wi.z))
    }

    /// `(f, pdf)` of the rough lobe at up to [`Lanes`] pairs `(wo[i],
    /// wi[i])`, as lanes: the half vectors four at a time in f64, the rest
    /// (`D`, both `Lambda`s, the Fresnel term, `f` and the density) on
    /// SIMD lanes, each lane the bits [`Bsdf::eval`] gives; zero where
    /// there is no lobe.
    #[inline(always)]
    fn eval_lanes<L: Real>(
        &self,
        mf: &Microfacet,
        fresnel: ConductorFresnel,
        wo: &[Vec3],
        wi: &[Vec3],
    ) -> ([L; 3], L) {
        let zero = L::splat(0.0);
        let (m, wo_m, mut bits) = half_vector_lanes::<L>(wo, wi);
        for i in 0..wo.len() {
            if !(wo[i].z > 0.0 && wi[i].z > 0.0) {
                bits &= !(1 << i);
            }
        }
        if bits == 0 {
            return ([zero; 3], zero);
        }
        let lobe = L::mask_from_bits(bits);
        let (wo, wi) = (V3::<L>::load(wo, Vec3::Z), V3::<L>::load(wi, Vec3::Z));
        let d = L::select(lobe, mf.d_lanes([m.x, m.y, m.z]), zero);
        // Lambda(wo) only where D is not zero, as in `LobeTerms::at`.
        let live = !d.eq(zero);
        let lambda_o = if L::all(!live) {
            zero
        } else {
            L::select(live, mf.lambda_lanes([wo.x, wo.y, wo.z]), zero)
        };
        let terms = LobeTerms {
            wo_z: wo.z,
            m_z: m.z,
            wo_m,
            d,
            lambda_o,
        };
        let f = self.rough_f(
            &terms,
            wi.z,
            || mf.lambda_lanes([wi.x, wi.y, wi.z]),
            || fresnel.eval_lanes(wo_m),
        );
        let pdf = L::select(lobe, self.rough_pdf(mf, &terms, wi.z), zero);
        (f, pdf)
    }
}

/// What `f` and `pdf` of the rough lobe share at one pair of directions
/// (both above the surface), or at a pair per lane: cosines of `wo` and of
/// the half vector `m`, `<wo, m>`, `D(m)` and `Lambda(wo)`, so that `eval`
/// and `sample_f` compute them once.
struct LobeTerms<F> {
    wo_z: F,
    m_z: F,
    wo_m: F,
    d: F,
    /// `Lambda(wo)`; left 0 where `D` is zero, since `f` and the density
    /// are zero there whatever it is (it is finite and non-negative, and
    /// the density uses `D / (1 + Lambda)`).
    lambda_o: F,
}

impl LobeTerms<f32> {
    /// `None` where the lobe is zero: a direction at or below the horizon,
    /// or opposite directions (no half vector).
    #[inline]
    fn at(mf: &Microfacet, wo: Vec3, wi: Vec3) -> Option<Self> {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        let (m, wo_m) = half_vector(wo, wi)?;
        let d = mf.d(m);
        Some(Self {
            wo_z: wo.z,
            m_z: m.z,
            wo_m,
            d,
            lambda_o: if d == 0.0 { 0.0 } else { mf.lambda(wo) },
        })
    }
}

impl Bsdf for Conductor {
    fn flags(&self) -> BsdfFlags {
        if self.roughness.is_delta() {
            BsdfFlags::SPECULAR | BsdfFlags::REFLECTION
        } else {
            BsdfFlags::GLOSSY | BsdfFlags::REFLECTION
        }
    }

    fn uses_tangent_frame(&self) -> bool {
        self.roughness.is_anisotropic()
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        let Some(mf) = &self.roughness.at(&ctx.texture) else {
            return Rgb::BLACK;
        };
        LobeTerms::at(mf, wo, wi).map_or(Rgb::BLACK, |lobe| {
            let fresnel = || self.fresnel.at(&ctx.texture).eval(lobe.wo_m).to_array();
            self.tinted(
                ctx,
                self.rough_f(&lobe, wi.z, || mf.lambda(wi), fresnel).into(),
            )
        })
    }

    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let mut s = self.sample_untinted(ctx, wo, u2)?;
        s.f = self.tinted(ctx, s.f);
        Some(s)
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        let Some(mf) = &self.roughness.at(&ctx.texture) else {
            return 0.0;
        };
        LobeTerms::at(mf, wo, wi).map_or(0.0, |lobe| self.rough_pdf(mf, &lobe, wi.z))
    }

    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let Some(mf) = &self.roughness.at(&ctx.texture) else {
            return (Rgb::BLACK, 0.0);
        };
        LobeTerms::at(mf, wo, wi).map_or((Rgb::BLACK, 0.0), |lobe| {
            let (f, pdf) = self.rough_eval(mf, self.fresnel.at(&ctx.texture), &lobe, wi);
            (self.tinted(ctx, f), pdf)
        })
    }

    /// [`Bsdf::eval`] a SIMD chunk of lanes at a time
    /// (`Conductor::eval_lanes`), each lane bit for bit `eval`'s answer.
    fn eval_batch(&self, ctx: &[BsdfContext], wo: &[Vec3], wi: &[Vec3], out: &mut [(Rgb, f32)]) {
        if self.roughness.is_delta() {
            out.fill((Rgb::BLACK, 0.0));
            return;
        }
        let (Some(mf), Some(fresnel), None) =
            (self.roughness.fixed(), self.fresnel.fixed(), &self.tint)
        else {
            return eval_each(self, ctx, wo, wi, out);
        };
        let width = Lanes::LANES;
        simd::dispatch(|| {
            for ((wo, wi), out) in wo
                .chunks(width)
                .zip(wi.chunks(width))
                .zip(out.chunks_mut(width))
            {
                let (f, pdf) = self.eval_lanes::<Lanes>(mf, fresnel, wo, wi);
                let (f, pdf) = (f.map(Lanes::to_array), pdf.to_array());
                for (i, out) in out.iter_mut().enumerate() {
                    *out = (Rgb::new(f[0][i], f[1][i], f[2][i]), pdf[i]);
                }
            }
        })
    }

    /// A packet's lanes through the SIMD [`Bsdf::eval_batch`].
    fn eval_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        wi: &Vec3Lanes,
        active: LaneMask,
        out: &mut BsdfEvalLanes,
    ) {
        eval_lanes_by_batch(self, ctx, wo, wi, active, out)
    }

    /// A packet's lanes through the SIMD [`Bsdf::sample_f_batch`].
    fn sample_f_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        u1: &Floats,
        u2: &Vec2Lanes,
        active: LaneMask,
        out: &mut BsdfSampleLanes,
    ) {
        sample_f_lanes_by_batch(self, ctx, wo, u1, u2, active, out)
    }

    /// [`Bsdf::sample_f`] a SIMD chunk of lanes at a time, for the
    /// visible-normal sampling of the rough lobe: the normals drawn on SIMD
    /// lanes (`Microfacet::sample_visible`, the scalar's own formulas),
    /// reflected per lane, and the value and density of each lane's
    /// direction from `Conductor::eval_lanes`; bit for bit `sample_f`'s
    /// answer. The mirror and the other strategies loop over `sample_f`.
    fn sample_f_batch(
        &self,
        ctx: &[BsdfContext],
        wo: &[Vec3],
        u1: &[f32],
        u2: &[Vec2],
        out: &mut [Option<BsdfSample>],
    ) {
        let (mf, fresnel) = match (self.roughness.fixed(), self.fresnel.fixed(), self.sampling) {
            (Some(mf), Some(fresnel), LobeSampling::Model(_))
                if mf.sampling == NormalSampling::Visible && self.tint.is_none() =>
            {
                (mf, fresnel)
            }
            _ => return sample_f_each(self, ctx, wo, u1, u2, out),
        };
        let width = Lanes::LANES;
        simd::dispatch(|| {
            for ((wo, u2), out) in wo
                .chunks(width)
                .zip(u2.chunks(width))
                .zip(out.chunks_mut(width))
            {
                let n = out.len();
                // Lanes below the surface (no sample) draw for the normal.
                let w = V3::<Lanes>::load(wo, Vec3::Z);
                let w = V3::select(w.z.gt(Lanes::splat(0.0)), w, V3::splat(Vec3::Z));
                let u = [
                    load(u2, Vec2::splat(0.5), |u| u.x),
                    load(u2, Vec2::splat(0.5), |u| u.y),
                ];
                let m = mf.sample_visible(w, u);
                let above = |i: usize| wo[i].z > 0.0;
                // A lane without a sample gets a direction below the surface,
                // which has no lobe.
                let mut wi = [-Vec3::Z; MAX_LANES];
                for (i, wi) in wi[..n].iter_mut().enumerate() {
                    let m = m.lane(i);
                    // A facet facing away from wo would reflect into itself.
                    if above(i) && wo[i].dot(m) > 0.0 {
                        *wi = fresnel::reflect(wo[i], m);
                    }
                }
                let (f, pdf) = self.eval_lanes::<Lanes>(mf, fresnel, wo, &wi[..n]);
                let (f, pdf) = (f.map(Lanes::to_array), pdf.to_array());
                for (i, out) in out.iter_mut().enumerate() {
                    *out = BsdfSample::reflection(
                        wi[i],
                        BsdfFlags::GLOSSY | BsdfFlags::REFLECTION,
                        |_| pdf[i],
                        |_| Rgb::new(f[0][i], f[1][i], f[2][i]),
                    );
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::microfacet::Distribution;
    use lumis_api::TextureQuery;

    /// A texture that is `c` times `(1 + u)`.
    struct UvRamp(Rgb);

    impl lumis_api::Texture for UvRamp {
        fn eval(&self, q: &lumis_api::TextureQuery) -> Rgb {
            self.0 * (1.0 + q.uv.x)
        }
    }

    /// Textured `eta` and `k` give at each hit the conductor of that
    /// hit's values, the batched methods included.
    #[test]
    fn a_textured_ior_is_the_metal_of_each_texel() {
        let mf = Microfacet::new(Distribution::Ggx, 0.3, 0.3);
        let sampling: LobeSampling = MicrofacetLobeSampling::Visible.into();
        let (eta, k) = (Rgb::new(0.2, 0.9, 1.1), Rgb::new(3.9, 2.4, 1.9));
        let ramp = |c: Rgb| lumis_api::params::Textured::Texture(std::sync::Arc::new(UvRamp(c)));
        let fresnel = MetalFresnel::Textured {
            eta: ramp(eta),
            k: ramp(k),
        };
        let textured = Conductor::with_roughness(mf.into(), fresnel, sampling);
        let (wo, wi) = (
            Vec3::new(0.3, 0.1, 0.95).normalize(),
            Vec3::new(-0.4, 0.2, 0.9).normalize(),
        );
        let ctx: Vec<BsdfContext> = [0.0f32, 0.5, 1.0]
            .iter()
            .map(|&u| BsdfContext {
                texture: TextureQuery::at(Vec2::new(u, 0.0)),
                ..BsdfContext::default()
            })
            .collect();
        let mut batch = vec![(Rgb::BLACK, 0.0); ctx.len()];
        textured.eval_batch(&ctx, &[wo; 3], &[wi; 3], &mut batch);
        for (ctx, batch) in ctx.iter().zip(batch) {
            let s = 1.0 + ctx.texture.uv.x;
            let texel = ConductorFresnel::Complex {
                eta: eta * s,
                k: k * s,
            };
            let plain = Conductor::new(mf, texel, sampling);
            let at = BsdfContext::default();
            assert_eq!(textured.eval(ctx, wo, wi), plain.eval(&at, wo, wi));
            assert_eq!(batch, plain.eval(&at, wo, wi));
            let u2 = Vec2::new(0.3, 0.6);
            assert_eq!(
                textured.sample_f(ctx, wo, 0.5, u2),
                plain.sample_f(&at, wo, 0.5, u2)
            );
        }
        assert!(textured.eval(&ctx[0], wo, wi).0 != textured.eval(&ctx[2], wo, wi).0);
    }

    #[test]
    fn a_textured_tint_multiplies_every_value_and_leaves_sampling_alone() {
        let mf = Microfacet::new(Distribution::Ggx, 0.3, 0.3);
        let sampling: LobeSampling = MicrofacetLobeSampling::Visible.into();
        let plain = Conductor::new(mf, ConductorFresnel::Perfect, sampling);
        let tint = Rgb::new(0.5, 0.25, 0.125);
        let tinted = Conductor {
            tint: Some(lumis_api::params::Textured::Texture(std::sync::Arc::new(
                UvRamp(tint),
            ))),
            ..plain.clone()
        };
        let n = 16;
        let ctx: Vec<BsdfContext> = (0..n)
            .map(|i| BsdfContext {
                texture: lumis_api::TextureQuery::at(Vec2::new(i as f32 / n as f32, 0.5)),
                ..Default::default()
            })
            .collect();
        let mut rng = lumis_sampling::Pcg32::new(5, 6);
        let wo: Vec<Vec3> = (0..n)
            .map(|_| {
                lumis_sampling::warp::square_to_cosine_hemisphere(Vec2::new(
                    rng.next_f32(),
                    rng.next_f32(),
                ))
            })
            .collect();
        let u2: Vec<Vec2> = (0..n)
            .map(|_| Vec2::new(rng.next_f32(), rng.next_f32()))
            .collect();
        let mut batch = vec![None; n];
        tinted.sample_f_batch(&ctx, &wo, &vec![0.5; n], &u2, &mut batch);
        for i in 0..n {
            let scale = tint * (1.0 + ctx[i].texture.uv.x);
            let want = plain.sample_f(&ctx[i], wo[i], 0.5, u2[i]);
            let got = tinted.sample_f(&ctx[i], wo[i], 0.5, u2[i]);
            assert_eq!(got.map(|s| (s.wi, s.pdf)), want.map(|s| (s.wi, s.pdf)));
            assert_eq!(got.map(|s| s.f), want.map(|s| scale * s.f));
            assert_eq!(batch[i], got, "lane {i}");
            let wi = Vec3::new(-wo[i].x, 0.1, wo[i].z).normalize();
            assert_eq!(
                tinted.eval(&ctx[i], wo[i], wi).0,
                scale * plain.f(&ctx[i], wo[i], wi)
            );
            assert_eq!(
                tinted.pdf(&ctx[i], wo[i], wi),
                plain.pdf(&ctx[i], wo[i], wi)
            );
        }
    }

    #[test]
    fn below_the_threshold_roughness_is_a_mirror() {
        let ctx = BsdfContext::default();
        let c = Conductor::new(
            Microfacet::new(Distribution::Ggx, 1e-4, 1e-4),
            ConductorFresnel::Perfect,
            MicrofacetLobeSampling::Visible.into(),
        );
        assert!(c.flags().is_specular());
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let s = c.sample_f(&ctx, wo, 0.5, Vec2::splat(0.5)).unwrap();
        assert_eq!(s.wi, Vec3::new(-0.6, 0.0, 0.8));
        assert!((s.f.r * s.wi.z / s.pdf - 1.0).abs() < 1e-6, "reflects all");
        assert_eq!(c.pdf(&ctx, wo, s.wi), 0.0);
    }

    /// Directions from cos theta 1e-4 to 1, below the horizon, opposite
    /// pairs and near-mirror pairs (where `D` is largest): `(wo, wi)`.
    fn direction_pairs() -> (Vec<Vec3>, Vec<Vec3>) {
        let mut wo = Vec::new();
        let mut wi = Vec::new();
        let dir = |c: f32, phi: f32| {
            let s = (1.0 - c * c).max(0.0).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), c)
        };
        for (i, cos_o) in [1e-4f32, 0.01, 0.3, 0.9, 1.0, -0.5, -1e-4, 0.0]
            .into_iter()
            .enumerate()
        {
            for (j, cos_i) in [1e-4f32, 0.2, 0.7, 1.0, -0.1].into_iter().enumerate() {
                let o = dir(cos_o, 0.3 + i as f32);
                wo.push(o);
                wi.push(dir(cos_i, 2.9 + 0.5 * j as f32));
                wo.push(o);
                wi.push(Vec3::new(-o.x, -o.y, o.z.abs()).normalize());
            }
        }
        wo.push(Vec3::Z);
        wi.push(-Vec3::Z);
        wo.push(Vec3::new(0.6, 0.0, 0.8));
        wi.push(Vec3::new(-0.6, 0.0, -0.8));
        (wo, wi)
    }

    /// Every distribution from roughness 1e-3 to 1, anisotropic too, with
    /// the Fresnel term of a metal and the perfect one, under each sampling
    /// strategy (the batched sampling is SIMD for `visible` only).
    fn conductors() -> Vec<Conductor> {
        let mut all = Vec::new();
        for distribution in [Distribution::Beckmann, Distribution::Ggx] {
            for (ax, ay) in [
                (1e-3, 1e-3),
                (0.005, 0.005),
                (0.05, 0.05),
                (1.0, 1.0),
                (0.02, 0.5),
            ] {
                for (fresnel, sampling) in [
                    (
                        ConductorFresnel::Complex {
                            eta: Rgb::new(0.2, 0.9, 1.1),
                            k: Rgb::new(3.9, 2.4, 2.2),
                        },
                        MicrofacetLobeSampling::Visible,
                    ),
                    (ConductorFresnel::Perfect, MicrofacetLobeSampling::Visible),
                    (ConductorFresnel::Perfect, MicrofacetLobeSampling::Full),
                    (ConductorFresnel::Perfect, MicrofacetLobeSampling::Cosine),
                    (ConductorFresnel::Perfect, MicrofacetLobeSampling::Uniform),
                ] {
                    all.push(Conductor::new(
                        Microfacet::new(distribution, ax, ay),
                        fresnel,
                        sampling.into(),
                    ));
                }
            }
        }
        all.push(Conductor::mirror(ConductorFresnel::Perfect));
        all
    }

    /// The batch lengths: empty, one lane, a partial chunk, just over one
    /// or several chunks of four or eight, and all.
    fn lengths(n: usize) -> [usize; 6] {
        [0, 1, 7, 9, 33, n]
    }

    /// The SIMD `eval_batch` gives `eval`'s answer bit for bit (so within
    /// any tolerance the special functions' errors would call for: the
    /// lanes run the scalar's own operations), zero where `eval` is zero.
    #[test]
    fn eval_batch_is_eval_bit_for_bit() {
        let (wo, wi) = direction_pairs();
        let n = wo.len();
        let ctx = vec![BsdfContext::default(); n];
        let bits = |(f, pdf): (Rgb, f32)| [f.r, f.g, f.b, pdf].map(f32::to_bits);
        for c in conductors() {
            for len in lengths(n) {
                let mut out = vec![(Rgb::splat(-1.0), -1.0); len];
                c.eval_batch(&ctx[..len], &wo[..len], &wi[..len], &mut out);
                for k in 0..len {
                    assert_eq!(
                        bits(out[k]),
                        bits(c.eval(&ctx[k], wo[k], wi[k])),
                        "{c:?}: lane {k} of {len}, wo {:?}, wi {:?}",
                        wo[k],
                        wi[k]
                    );
                }
            }
        }
    }

    /// The SIMD `sample_f_batch` gives `sample_f`'s answer bit for bit,
    /// `None` exactly where it is `None`, with random numbers including 0
    /// and the largest below 1.
    #[test]
    fn sample_f_batch_is_sample_f_bit_for_bit() {
        let (wo, _) = direction_pairs();
        let mut rng = lumis_sampling::Pcg32::new(5, 7);
        let mut wos = Vec::new();
        let mut u1 = Vec::new();
        let mut u2 = Vec::new();
        for (k, &w) in wo.iter().cycle().take(4 * wo.len()).enumerate() {
            wos.push(w);
            u1.push(rng.next_f32());
            u2.push(match k % 9 {
                0 => Vec2::ZERO,
                1 => Vec2::splat(1.0 - f32::EPSILON / 2.0),
                2 => Vec2::new(0.5, 0.0),
                _ => Vec2::new(rng.next_f32(), rng.next_f32()),
            });
        }
        let n = wos.len();
        let ctx = vec![BsdfContext::default(); n];
        let bits = |s: Option<BsdfSample>| {
            s.map(|s| {
                (
                    [s.f.r, s.f.g, s.f.b, s.pdf, s.wi.x, s.wi.y, s.wi.z, s.eta].map(f32::to_bits),
                    s.flags,
                )
            })
        };
        for c in conductors() {
            let mut some = 0;
            for len in lengths(n) {
                let mut out = vec![None; len];
                c.sample_f_batch(&ctx[..len], &wos[..len], &u1[..len], &u2[..len], &mut out);
                for k in 0..len {
                    let scalar = c.sample_f(&ctx[k], wos[k], u1[k], u2[k]);
                    some += scalar.is_some() as usize;
                    assert_eq!(
                        bits(out[k]),
                        bits(scalar),
                        "{c:?}: lane {k} of {len}, wo {:?}, u {:?}",
                        wos[k],
                        u2[k]
                    );
                }
            }
            assert!(some > n / 4, "{c:?}: too few samples to compare ({some})");
        }
    }
}
