//! Microfacet normal distributions with Smith masking, and the two ways to
//! sample their normals.
//!
//! Conventions follow Heitz 2014, "Understanding the Masking-Shadowing
//! Function in Microfacet-Based BRDFs" (JCGT 3(2)): `D` is normalised so
//! that `int D(m) cos theta_m dm = 1`, `Lambda` is Smith's auxiliary
//! function and `G1 = 1 / (1 + Lambda)`. Anisotropy stretches the slope
//! space by `(alpha_x, alpha_y)`, so every formula sees the quantity
//! `alpha^2 tan^2 theta` for the direction's own azimuth.

use std::f32::consts::PI;
use std::ops::{Add, Div, Mul};
use std::sync::Arc;

use lumis_api::params::Textured;
use lumis_api::{ParamChoice, PluginParams, TextureQuery, TexturedFloat, Vec2, Vec3};
use lumis_sampling::real::{Real, V3};
use lumis_sampling::special::{erf, erf_inv, erfc, exp, ln, sin_cos_turns, FRAC_1_SQRT_PI};
use wide::f64x4;

/// Below this roughness (largest alpha) a lobe is narrower than a
/// thousandth of a radian and is rendered as the delta lobe it tends to,
/// as pbrt-v4's `EffectivelySmooth` does: the glossy lobe would be too
/// sharp for f32 directions and its pdf would overflow towards 1/alpha^2.
pub const SMOOTH_THRESHOLD: f32 = 1e-3;

/// Which normal distribution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Distribution {
    /// Trowbridge-Reitz, a.k.a. GGX: longer tails (Walter et al. 2007, eq. 33).
    Ggx,
    /// Beckmann-Spizzichino: Gaussian slopes (Walter et al. 2007, eq. 25).
    Beckmann,
}

/// How microfacet normals are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum NormalSampling {
    /// The normals visible from `wo`, `G1(wo) D(m) <wo, m> / cos theta_o`
    /// (Heitz and d'Eon 2014): no sample is wasted on back-facing facets.
    Visible,
    /// The whole distribution, `D(m) cos theta_m` (Walter et al. 2007):
    /// simpler, but at grazing angles many samples reflect below the surface.
    Full,
}

/// The parameters every microfacet BSDF shares (flattened into its own).
#[derive(Debug, Clone, PluginParams)]
pub struct MicrofacetParams {
    /// microfacet normal distribution: ggx (Trowbridge-Reitz) or beckmann
    #[param(default = Ggx)]
    pub distribution: Distribution,
    /// alpha, the RMS slope of the microfacets (Beckmann) or the GGX width;
    /// below 1e-3 the lobe is a delta (a texture's values are held at 1e-3
    /// and above: the lobe stays glossy everywhere)
    #[param(default = 0.1, range = (0.0, 1.0))]
    pub roughness: TexturedFloat,
    /// alpha along the surface's second tangent (anisotropy); default:
    /// roughness; each axis is at least 1e-3 once the other is
    #[param(range = (0.0, 1.0))]
    pub roughness_v: Option<TexturedFloat>,
}

impl MicrofacetParams {
    /// The roughness they describe, sampling visible normals.
    pub fn roughness(&self) -> Roughness {
        let v = self.roughness_v.as_ref().unwrap_or(&self.roughness);
        match (self.roughness.constant(), v.constant()) {
            (Some(alpha_x), Some(alpha_y)) => {
                Microfacet::new(self.distribution, alpha_x, alpha_y).into()
            }
            _ => Roughness::Textured {
                distribution: self.distribution,
                alpha_x: self.roughness.clone(),
                alpha_y: v.clone(),
                sampling: NormalSampling::Visible,
            },
        }
    }
}

/// A surface's microfacet lobe: one distribution everywhere, or one per
/// hit from roughness textures (pbrt-v4's materials evaluate their
/// roughness textures per hit the same way).
#[derive(Debug, Clone)]
pub enum Roughness {
    /// The same lobe everywhere; `None` for a delta.
    Fixed(Option<Microfacet>),
    /// The widths read at each hit, held at [`SMOOTH_THRESHOLD`] and above
    /// so that the lobe is glossy everywhere, as the BSDF's flags say.
    Textured {
        distribution: Distribution,
        alpha_x: TexturedFloat,
        alpha_y: TexturedFloat,
        sampling: NormalSampling,
    },
}

/// A fixed lobe; a delta if it is smooth.
impl From<Microfacet> for Roughness {
    fn from(mf: Microfacet) -> Self {
        Roughness::Fixed((!mf.is_smooth()).then_some(mf))
    }
}

impl Roughness {
    /// The lobe at the hit `query` looks up; `None` for a delta.
    #[inline]
    pub fn at(&self, query: &TextureQuery) -> Option<Microfacet> {
        match self {
            Roughness::Fixed(mf) => *mf,
            Roughness::Textured {
                distribution,
                alpha_x,
                alpha_y,
                sampling,
            } => {
                let alpha = |t: &TexturedFloat| t.eval(query).clamp(SMOOTH_THRESHOLD, 1.0);
                Some(
                    Microfacet::new(*distribution, alpha(alpha_x), alpha(alpha_y))
                        .with_sampling(*sampling),
                )
            }
        }
    }

    /// The lobe if it is the same everywhere and not a delta: what the
    /// batched methods work on lanes with.
    #[inline]
    pub fn fixed(&self) -> Option<&Microfacet> {
        match self {
            Roughness::Fixed(mf) => mf.as_ref(),
            Roughness::Textured { .. } => None,
        }
    }

    /// Whether the lobe's width differs between the tangents: it then
    /// needs a frame whose `x` follows `dp/du` (pbrt-v4 orients `alpha_x`
    /// the same way).
    pub fn is_anisotropic(&self) -> bool {
        match self {
            Roughness::Fixed(mf) => mf.is_some_and(|mf| mf.alpha_x != mf.alpha_y),
            Roughness::Textured {
                alpha_x, alpha_y, ..
            } => match (alpha_x, alpha_y) {
                (Textured::Constant(x), Textured::Constant(y)) => x != y,
                (Textured::Texture(x), Textured::Texture(y)) => !Arc::ptr_eq(x, y),
                _ => true,
            },
        }
    }

    /// Whether the lobe is a delta (everywhere).
    pub fn is_delta(&self) -> bool {
        matches!(self, Roughness::Fixed(None))
    }

    /// How its normals are drawn; a delta has none to draw.
    pub fn with_sampling(self, with: NormalSampling) -> Self {
        match self {
            Roughness::Fixed(mf) => Roughness::Fixed(mf.map(|mf| mf.with_sampling(with))),
            Roughness::Textured {
                distribution,
                alpha_x,
                alpha_y,
                ..
            } => Roughness::Textured {
                distribution,
                alpha_x,
                alpha_y,
                sampling: with,
            },
        }
    }
}

/// The half vector `h` of unit `wo`, `wi` and `<wo, h> = <wi, h> = |wo +
/// wi| / 2`; `None` if they are opposite.
///
/// Formed in f64 from the f32 directions normalised in f64: near
/// retro-reflection at grazing angles `|wo + wi|` is ~1e-4, where both the
/// f32 sum and the inputs' own deviation from unit length (~1e-7) would
/// tilt `h` by ~1e-3 rad, the width of a lobe of roughness 1e-3, and could
/// even make `<wo, h>` negative. The cosine is returned rather than
/// recomputed for the same reason, and it is symmetric in `wo` and `wi` by
/// construction, so models built on it are reciprocal to the last bit.
#[inline]
pub fn half_vector(wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
    let f64s = |v: Vec3| v.as_dvec3().to_array();
    let (m, len) = half_vector_f64(f64s(wo), f64s(wi));
    (len > 0.0).then(|| {
        (
            Vec3::new(m[0] as f32, m[1] as f32, m[2] as f32),
            (0.5 * len) as f32,
        )
    })
}

/// [`half_vector`] of each pair `(wo[i], wi[i])` on lanes (at most
/// eight): `(m, <wo, m>, bits)` with bit `i` of `bits` set where pair `i`
/// has a half vector; lanes past the pairs hold the normal. Four pairs per
/// SIMD operation in f64 (two SSE2 halves): the same IEEE operations, so
/// the same bits.
#[inline(always)]
pub fn half_vector_lanes<F: Real>(wo: &[Vec3], wi: &[Vec3]) -> (V3<F>, F, u32) {
    debug_assert!(wo.len() <= F::LANES && F::LANES <= 8 && wi.len() == wo.len());
    // Pairs `start..start + 4`, padded with the pair (z, z) whose half
    // vector is z.
    let block = |start: usize| {
        let lanes = |v: &[Vec3]| {
            let v = v.get(start..).unwrap_or(&[]);
            // Full blocks with one bounds check, for the reason of `load`.
            let v: [Vec3; 4] = match v.get(..4) {
                Some(v) => [v[0], v[1], v[2], v[3]],
                None => std::array::from_fn(|i| v.get(i).copied().unwrap_or(Vec3::Z)),
            };
            let column = |get: fn(Vec3) -> f32| f64x4::new(v.map(|v| get(v) as f64));
            [column(|v| v.x), column(|v| v.y), column(|v| v.z)]
        };
        let (m, len) = half_vector_f64(lanes(wo), lanes(wi));
        (m.map(f64x4::to_array), len.to_array())
    };
    let low = block(0);
    let high = if F::LANES > 4 { block(4) } else { low };
    let lane = |i: usize| if i < 4 { (&low, i) } else { (&high, i - 4) };
    let mut bits = 0;
    for i in 0..wo.len() {
        let (block, j) = lane(i);
        bits |= ((block.1[j] > 0.0) as u32) << i;
    }
    let m = |axis: usize| {
        F::from_fn(|i| {
            let (block, j) = lane(i);
            block.0[axis][j] as f32
        })
    };
    let cos = F::from_fn(|i| {
        let (block, j) = lane(i);
        (0.5 * block.1[j]) as f32
    });
    (V3::new(m(0), m(1), m(2)), cos, bits)
}

/// The f64 arithmetic [`half_vector`] needs, for one pair or four.
trait F64: Copy + Add<Output = Self> + Mul<Output = Self> + Div<Output = Self> {
    fn one() -> Self;
    fn sqrt(self) -> Self;
}

impl F64 for f64 {
    #[inline(always)]
    fn one() -> Self {
        1.0
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

impl F64 for f64x4 {
    #[inline(always)]
    fn one() -> Self {
        f64x4::splat(1.0)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64x4::sqrt(self)
    }
}

/// `(sum / |sum|, |sum|)` for `sum = wo / |wo| + wi / |wi|`, in glam's
/// `DVec3` order of operations (`normalize` multiplies by the reciprocal
/// length, the final division divides).
#[inline(always)]
fn half_vector_f64<D: F64>(wo: [D; 3], wi: [D; 3]) -> ([D; 3], D) {
    let length = |[x, y, z]: [D; 3]| ((x * x + y * y) + z * z).sqrt();
    let normalize = |v: [D; 3]| {
        let r = D::one() / length(v);
        v.map(|c| c * r)
    };
    let (a, b) = (normalize(wo), normalize(wi));
    let sum = [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    let len = length(sum);
    (sum.map(|c| c / len), len)
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Microfacet {
    pub distribution: Distribution,
    pub alpha_x: f32,
    pub alpha_y: f32,
    pub sampling: NormalSampling,
}

impl Microfacet {
    /// A distribution of widths `alpha_x`, `alpha_y`. Once either is above
    /// [`SMOOTH_THRESHOLD`] (a glossy lobe), the other is raised to at least
    /// the threshold, as pbrt-v4's `TrowbridgeReitzDistribution` clamps
    /// alpha: `D` divides by each alpha, and an anisotropic lobe cannot be
    /// a delta along one axis only.
    pub fn new(distribution: Distribution, alpha_x: f32, alpha_y: f32) -> Self {
        let (alpha_x, alpha_y) = if alpha_x.max(alpha_y) >= SMOOTH_THRESHOLD {
            (alpha_x.max(SMOOTH_THRESHOLD), alpha_y.max(SMOOTH_THRESHOLD))
        } else {
            (alpha_x, alpha_y)
        };
        Self {
            distribution,
            alpha_x,
            alpha_y,
            sampling: NormalSampling::Visible,
        }
    }

    pub fn with_sampling(self, sampling: NormalSampling) -> Self {
        Self { sampling, ..self }
    }

    /// Whether the lobe is too narrow to be anything but a delta.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < SMOOTH_THRESHOLD
    }

    /// The normal distribution `D(m)`; zero below the surface.
    #[inline]
    pub fn d(&self, m: Vec3) -> f32 {
        self.d_lanes([m.x, m.y, m.z])
    }

    /// [`Self::d`] of the normal with components `m`, lane by lane.
    #[inline(always)]
    pub fn d_lanes<F: Real>(&self, [mx, my, mz]: [F; 3]) -> F {
        let s = F::splat;
        let below = mz.le(s(0.0));
        if F::all(below) {
            return s(0.0);
        }
        let z2 = mz * mz;
        // (x^2/alpha_x^2 + y^2/alpha_y^2): the stretched squared slope of m
        // times cos^2 theta_m.
        let (x, y) = (mx / s(self.alpha_x), my / s(self.alpha_y));
        let stretched_sin2 = x * x + y * y;
        let norm = s(PI * self.alpha_x * self.alpha_y);
        let d = match self.distribution {
            // exp(-tan^2/alpha^2) / (pi alpha^2 cos^4).
            Distribution::Beckmann => {
                let e = stretched_sin2 / z2;
                let negligible = e.gt(s(80.0));
                if F::all(negligible | below) {
                    return s(0.0);
                }
                // Negligible lanes are worked on as e = 0: their e^-e
                // would be subnormal, slow on every SIMD operation.
                let e = F::select(negligible, s(0.0), e);
                F::select(negligible, s(0.0), exp(-e) / (norm * z2 * z2))
            }
            // 1 / (pi alpha^2 cos^4 (1 + tan^2/alpha^2)^2), with the cos^4
            // folded into the square so that it stays finite at the horizon.
            Distribution::Ggx => {
                let t = z2 + stretched_sin2;
                s(1.0) / (norm * t * t)
            }
        };
        F::select(below, s(0.0), d)
    }

    /// Smith's `Lambda(w)`, the same above and below the surface.
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        self.lambda_lanes([w.x, w.y, w.z])
    }

    /// [`Self::lambda`] of the direction with components `w`, lane by lane.
    #[inline(always)]
    pub fn lambda_lanes<F: Real>(&self, [wx, wy, wz]: [F; 3]) -> F {
        let s = F::splat;
        let z2 = wz * wz;
        let (x, y) = (wx * s(self.alpha_x), wy * s(self.alpha_y));
        let a2t2 = (x * x + y * y) / z2; // alpha^2 tan^2 theta
                                         // Grazing (or degenerate) directions are fully masked.
        let finite = a2t2.abs().lt(s(f32::INFINITY));
        if F::all(!finite) {
            return s(f32::INFINITY);
        }
        let lambda = match self.distribution {
            // (sqrt(1 + alpha^2 tan^2) - 1) / 2 (Walter et al. 2007, eq. 35).
            Distribution::Ggx => s(0.5) * ((s(1.0) + a2t2).sqrt() - s(1.0)),
            // With a = 1 / (alpha tan): (exp(-a^2)/(a sqrt(pi)) - erfc(a))/2
            // (Walter et al. 2007, eq. 27 before its rational fit: exact).
            // The difference cancels by a factor 2 a^2 at large a, where
            // Lambda < 1e-7 no longer changes G1 in f32.
            Distribution::Beckmann => {
                // Beyond a = 5 (alpha^2 tan^2 < 1/25), Lambda < 4e-14 (it
                // falls as e^(-a^2) / (2 sqrt(pi) a^3)), so 1 + Lambda
                // rounds to 1 and 0 gives the same G1 and G to the last
                // bit; it skips the exponentials of nearly every direction
                // of a narrow lobe, and their subnormal range (a > 9.3),
                // which is slow in scalar and SIMD code alike.
                let negligible = a2t2.lt(s(1.0 / 25.0));
                if F::all(negligible | !finite) {
                    return F::select(finite, s(0.0), s(f32::INFINITY));
                }
                let a = s(1.0) / F::select(negligible, s(1.0), a2t2).sqrt();
                let l = s(0.5) * (exp(-a * a) * s(FRAC_1_SQRT_PI) / a - erfc(a));
                F::select(negligible, s(0.0), l.max(s(0.0)))
            }
        };
        F::select(finite, lambda, s(f32::INFINITY))
    }

    /// Smith masking `G1(w) = 1 / (1 + Lambda(w))`.
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing (Heitz 2014, eq. 99).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// The distribution of normals visible from `w`, `G1(w) D(m) <w, m>^+ /
    /// cos theta_w` (Heitz 2014, eq. 38), with `cos_wm = <w, m>` from the
    /// caller (see [`half_vector`] for why it is not recomputed); `w` below
    /// the surface is flipped up, as `sample_normal` does.
    #[inline]
    pub fn d_visible(&self, w: Vec3, m: Vec3, cos_wm: f32) -> f32 {
        let (w, cos_wm) = if w.z < 0.0 {
            (-w, -cos_wm)
        } else {
            (w, cos_wm)
        };
        if w.z == 0.0 || cos_wm <= 0.0 {
            return 0.0;
        }
        self.g1(w) * self.d(m) * cos_wm / w.z
    }

    /// Density of `sample_normal(w, ..)` at `m`, w.r.t. solid angle;
    /// `cos_wm = <w, m>` as for [`Self::d_visible`].
    #[inline]
    pub fn pdf_normal(&self, w: Vec3, m: Vec3, cos_wm: f32) -> f32 {
        match self.sampling {
            NormalSampling::Visible => self.d_visible(w, m, cos_wm),
            NormalSampling::Full => self.d(m) * m.z.max(0.0),
        }
    }

    /// [`Self::pdf_normal`] for `w` above the surface, from `d = D(m)` and
    /// `lambda_w = Lambda(w)` that the caller has already evaluated (a
    /// BSDF's `f` needs both too): the same arithmetic, so the same bits.
    #[inline]
    pub fn pdf_normal_from(&self, w: Vec3, m: Vec3, cos_wm: f32, d: f32, lambda_w: f32) -> f32 {
        debug_assert!(w.z >= 0.0);
        self.pdf_normal_lanes(w.z, m.z, cos_wm, d, lambda_w)
    }

    /// [`Self::pdf_normal_from`] lane by lane, from the cosines of `w` and
    /// `m`.
    #[inline]
    pub fn pdf_normal_lanes<F: Real>(&self, w_z: F, m_z: F, cos_wm: F, d: F, lambda_w: F) -> F {
        let s = F::splat;
        match self.sampling {
            NormalSampling::Visible => {
                let zero = w_z.eq(s(0.0)) | cos_wm.le(s(0.0));
                if F::all(zero) {
                    return s(0.0);
                }
                let pdf = s(1.0) / (s(1.0) + lambda_w) * d * cos_wm / w_z;
                F::select(zero, s(0.0), pdf)
            }
            NormalSampling::Full => d * m_z.max(s(0.0)),
        }
    }

    /// Draws a microfacet normal (upper hemisphere) for the direction `w`
    /// (flipped to the upper hemisphere if it is below).
    pub fn sample_normal(&self, w: Vec3, u: Vec2) -> Vec3 {
        match self.sampling {
            NormalSampling::Full => self.sample_full(u),
            NormalSampling::Visible => {
                let w = if w.z < 0.0 { -w } else { w };
                self.sample_visible(V3::from(w), [u.x, u.y]).into()
            }
        }
    }

    /// A normal drawn from the normals visible from `w` (above the
    /// surface), lane by lane: [`Self::sample_normal`]'s `Visible` case.
    #[inline]
    pub fn sample_visible<F: Real>(&self, w: V3<F>, u: [F; 2]) -> V3<F> {
        match self.distribution {
            Distribution::Ggx => self.sample_visible_ggx(w, u),
            Distribution::Beckmann => self.sample_visible_beckmann(w, u),
        }
    }

    /// The normal with slope `-(slope_x, slope_y)` (Heitz 2014, eq. 2).
    #[inline]
    fn normal_from_slope<F: Real>(sx: F, sy: F) -> V3<F> {
        V3::new(-sx, -sy, F::splat(1.0)).normalize()
    }

    /// `D(m) cos theta_m` is the slope density `P22` times the Jacobian, so
    /// drawing the stretched slope from the unit-roughness `P22` and
    /// scaling it by alpha samples it, anisotropic or not: Gaussian slopes
    /// for Beckmann (`r^2 = -ln(1 - u)`, i.e. `tan^2 theta = -alpha^2
    /// ln(1 - u)`), `P22 = 1 / (pi (1 + r^2)^2)` for GGX (`r^2 = u/(1-u)`).
    fn sample_full(&self, u: Vec2) -> Vec3 {
        let u1 = u.x.min(1.0 - f32::EPSILON);
        let r2 = match self.distribution {
            Distribution::Beckmann => -(-u1).ln_1p(),
            Distribution::Ggx => u1 / (1.0 - u1),
        };
        let r = r2.sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u.y);
        Self::normal_from_slope(self.alpha_x * r * cos_phi, self.alpha_y * r * sin_phi).into()
    }

    /// Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
    /// (JCGT 7(4), listing 1): stretch to unit roughness, sample the
    /// projected hemisphere as a warped disk, unstretch.
    #[inline(always)]
    fn sample_visible_ggx<F: Real>(&self, w: V3<F>, [u1, u2]: [F; 2]) -> V3<F> {
        let c = F::splat;
        let (ax, ay) = (c(self.alpha_x), c(self.alpha_y));
        let wh = V3::new(ax * w.x, ay * w.y, w.z).normalize();
        let len2 = wh.x * wh.x + wh.y * wh.y;
        let t1 = V3::select(
            len2.gt(c(0.0)),
            V3::new(-wh.y, wh.x, c(0.0)) / len2.sqrt(),
            V3::new(c(1.0), c(0.0), c(0.0)),
        );
        let t2 = wh.cross(t1);
        let r = u1.sqrt();
        let (sin_phi, cos_phi) = sin_cos_turns(u2);
        let p1 = r * cos_phi;
        let s = c(0.5) * (c(1.0) + wh.z);
        let p2 = (c(1.0) - s) * (c(1.0) - p1 * p1).max(c(0.0)).sqrt() + s * r * sin_phi;
        let pz = (c(1.0) - p1 * p1 - p2 * p2).max(c(0.0)).sqrt();
        let nh = t1 * p1 + t2 * p2 + wh * pz;
        V3::new(ax * nh.x, ay * nh.y, nh.z.max(c(1e-6))).normalize()
    }

    /// Heitz and d'Eon 2014, "Importance Sampling Microfacet-Based BSDFs
    /// using the Distribution of Visible Normals", section 4 and appendix:
    /// stretch `w` to unit roughness, rotate it into the xz-plane, sample
    /// the visible slopes there, rotate back and unstretch.
    #[inline(always)]
    fn sample_visible_beckmann<F: Real>(&self, w: V3<F>, u: [F; 2]) -> V3<F> {
        let c = F::splat;
        let (ax, ay) = (c(self.alpha_x), c(self.alpha_y));
        let ws = V3::new(ax * w.x, ay * w.y, w.z).normalize();
        let (sx, sy) = beckmann_visible_slopes(ws.z, u);
        let len = (ws.x * ws.x + ws.y * ws.y).sqrt();
        let tilted = len.gt(c(0.0));
        let cos_phi = F::select(tilted, ws.x / len, c(1.0));
        let sin_phi = F::select(tilted, ws.y / len, c(0.0));
        let rx = cos_phi * sx - sin_phi * sy;
        let ry = sin_phi * sx + cos_phi * sy;
        Self::normal_from_slope(ax * rx, ay * ry)
    }
}

/// Visible slopes of the unit-roughness Beckmann surface seen from a
/// direction in the xz-plane with `cos theta = cos_theta`.
///
/// The slope `x` along the view azimuth has density proportional to
/// `exp(-x^2) (1 - x tan theta)` for `x < cot theta` (projected area of the
/// facet); in `b = erf(x)` its unnormalised CDF is `F(b) = 1 + b + tan
/// theta exp(-x^2) / sqrt(pi)`, inverted by Newton's method safeguarded by
/// bisection (pbrt-v3 `BeckmannSample11`) from Jakob's fitted starting
/// point `b0 = erf(cot) - (1 + erf(cot)) erf(sqrt(-ln u))` ("An Improved
/// Visible Normal Sampling Routine for the Beckmann Distribution", 2014),
/// which leaves two or three steps to f32 precision. The other slope is
/// independent and Gaussian: `y = erfinv(2 u - 1)`.
///
/// Lane by lane: each lane stops its iteration where the scalar one would
/// (its value frozen from then on) and the loop ends when all have.
#[inline(always)]
fn beckmann_visible_slopes<F: Real>(cos_theta: F, [u1, u2]: [F; 2]) -> (F, F) {
    const EPS: f32 = 1e-6;
    let c = F::splat;
    let u1 = u1.max(c(EPS)).min(c(1.0 - EPS));
    let u2 = u2.max(c(EPS)).min(c(1.0 - EPS));
    let sin_theta = (c(1.0) - cos_theta * cos_theta).max(c(0.0)).sqrt();
    let tan_theta = sin_theta / cos_theta;
    let cot_theta = cos_theta / sin_theta; // +inf at normal incidence
    let normal = tan_theta.eq(c(0.0));
    let tail = |x: F| {
        if F::all(normal) {
            c(0.0)
        } else {
            F::select(normal, c(0.0), c(FRAC_1_SQRT_PI) * tan_theta * exp(-x * x))
        }
    };
    let (mut lo, mut hi) = (c(-1.0), erf(cot_theta));
    let total = c(1.0) + hi + tail(cot_theta);
    let target = u1 * total;
    let mut b = (hi - (c(1.0) + hi) * erf((-ln(u1)).sqrt())).max(lo).min(hi);
    let mut x = erf_inv(b);
    let mut done = F::mask_splat(false);
    for _ in 0..32 {
        let value = c(1.0) + b + tail(x) - target;
        done = done | value.abs().le(c(1e-6) * total);
        if F::all(done) {
            break;
        }
        let above = value.gt(c(0.0));
        let (new_lo, new_hi) = (F::select(above, lo, b), F::select(above, b, hi));
        // dF/db: 1 - x tan theta (the facet's projected area).
        let derivative = c(1.0) - x * tan_theta;
        let newton = b - value / derivative;
        let inside = derivative.gt(c(0.0)) & newton.gt(new_lo) & newton.lt(new_hi);
        let new_b = F::select(inside, newton, c(0.5) * (new_lo + new_hi));
        lo = F::select(done, lo, new_lo);
        hi = F::select(done, hi, new_hi);
        b = F::select(done, b, new_b);
        x = F::select(done, x, erf_inv(b));
    }
    (x, erf_inv(c(2.0) * u2 - c(1.0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    fn all() -> Vec<Microfacet> {
        let mut v = Vec::new();
        for d in [Distribution::Beckmann, Distribution::Ggx] {
            for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.05, 0.5)] {
                v.push(Microfacet::new(d, ax, ay));
            }
        }
        v
    }

    fn direction(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    /// Midpoint quadrature over the hemisphere in (theta, phi) with theta
    /// refined near the pole where narrow lobes live.
    fn hemisphere_integral(f: impl Fn(Vec3) -> f64) -> f64 {
        let (nt, np) = (4000, 256);
        let mut sum = 0.0;
        for i in 0..nt {
            // theta = (pi/2) t^3 concentrates nodes near the pole.
            let t = (i as f64 + 0.5) / nt as f64;
            let theta = std::f64::consts::FRAC_PI_2 * t * t * t;
            let dtheta = std::f64::consts::FRAC_PI_2 * 3.0 * t * t / nt as f64;
            for j in 0..np {
                let phi = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                let w = direction(theta as f32, phi as f32);
                sum += f(w) * theta.sin() * dtheta * (2.0 * std::f64::consts::PI / np as f64);
            }
        }
        sum
    }

    #[test]
    fn d_is_normalised_over_projected_area() {
        for m in all() {
            let total = hemisphere_integral(|n| (m.d(n) * n.z) as f64);
            assert!((total - 1.0).abs() < 2e-3, "{m:?}: {total}");
        }
    }

    #[test]
    fn smith_lambda_satisfies_the_projected_area_constraint() {
        // int G1(w) D(m) <w, m>^+ dm = cos theta_w (Heitz 2014, eq. 20):
        // the visible distribution is a density.
        for m in all() {
            for theta in [0.0f32, 0.7, 1.3, 1.55] {
                let w = direction(theta, 0.4);
                let total = hemisphere_integral(|n| m.d_visible(w, n, w.dot(n)) as f64);
                assert!((total - 1.0).abs() < 3e-3, "{m:?} theta {theta}: {total}");
            }
        }
    }

    #[test]
    fn sampled_normals_have_the_density_pdf_normal_reports() {
        // Mean of 1/pdf over samples estimates the area of the support
        // (2 pi for the hemisphere when the pdf is positive everywhere):
        // a cheap consistency check; the chi-square tests of the BSDFs are
        // the thorough one.
        let mut rng = Pcg32::new(3, 5);
        for m in all() {
            for sampling in [NormalSampling::Full, NormalSampling::Visible] {
                let m = m.with_sampling(sampling);
                let w = direction(1.0, 0.2);
                let n = 200_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let u = Vec2::new(rng.next_f32(), rng.next_f32());
                    let wm = m.sample_normal(w, u);
                    assert!(wm.is_finite() && wm.z > 0.0, "{m:?}: {wm:?}");
                    // Weight <w, m> G1 / cos theta_w / pdf integrates to 1
                    // exactly for visible sampling; to the projected-area
                    // constraint for full sampling.
                    let p = m.pdf_normal(w, wm, w.dot(wm)) as f64;
                    sum += (m.d_visible(w, wm, w.dot(wm)) as f64) / p;
                }
                let mean = sum / n as f64;
                assert!((mean - 1.0).abs() < 0.02, "{m:?}: {mean}");
            }
        }
    }

    #[test]
    fn beckmann_visible_slopes_reduce_to_gaussians_at_normal_incidence() {
        let (x, y) = beckmann_visible_slopes(1.0f32, [0.5, 0.5]);
        assert!(x.abs() < 1e-6 && y.abs() < 1e-6, "{x} {y}");
        // At grazing incidence the slope x must stay below cot theta.
        for c in [1e-4f32, 0.01, 0.5] {
            for u in [1e-6, 0.3, 0.999999] {
                let (x, _) = beckmann_visible_slopes(c, [u, 0.5]);
                let cot = c / (1.0 - c * c).sqrt();
                assert!(x.is_finite() && x <= cot * (1.0 + 1e-5), "{c} {u}: {x}");
            }
        }
    }
}
