//! `normalmap`: a tangent-space normal map on a reflecting BSDF, as the
//! microfacet-based normal mapping of Schüssler et al. 2017
//! ("Microfacet-based Normal Mapping for Robust Monte Carlo Path Tracing",
//! ACM TOG 36(6)).
//!
//! Tilting the shading normal alone (pbrt-v4's and Mitsuba 3's normal
//! maps) leaves the inner BSDF cut off by the true surface: energy goes
//! missing at grazing angles, black seams appear where the tilted
//! hemisphere dips under the surface, and the adjoint needs a correction
//! that breaks reciprocity. Here each point becomes a microsurface of two
//! facets (section 3): the map's normal `wp`, which carries the inner
//! BSDF, and a mirror `wt` standing perpendicular to the surface, which
//! closes the sawtooth so that the two facets project onto the surface
//! exactly once. With projected areas (eq. 4-5)
//!
//! a_p(w) = <w, wp>+ / <wp, n>,   a_t(w) = <w, wt>+ sin(theta_p) / <wp, n>,
//!
//! a ray from `w` meets `wp` first with probability
//! `lambda_p(w) = a_p / (a_p + a_t)` and leaves unshadowed with
//! `G1(w) = min(1, <w, n> / (a_p + a_t))`. Light reflects once on `wp`,
//! with at most one mirror bounce on `wt` before and one after; those four
//! paths are evaluated in closed form (section 4.3, here with the mirror
//! also after the bounce on `wp`, which makes the model reciprocal), and
//! what would bounce further is absorbed. The model is reciprocal, never
//! creates energy, and samples exactly what it evaluates.
//!
//! What it keeps: a glossy lobe follows the map, since its highlight moves
//! with `wp`. Under a Lambertian facet the mirror's shadowing cancels the
//! facet's cosine on every path, so the surface reflects like a
//! Lambertian one of albedo `cos(theta_p)` times the facet's: a map darkens
//! its tilted texels the same under any light (the longer walks the model
//! absorbs carry the rest, which the full microsurface would return).

use std::sync::Arc;

use lumis_api::math::Frame;
use lumis_api::params::NestedBsdf;
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, TexturedRgb, Vec2, Vec3,
};
use lumis_sampling::rng::{hash_with, Pcg32};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "normalmap",
    source: lumis_api::source_file!(),
    doc: "a tangent-space normal map on a reflecting BSDF, as a two-facet microsurface: reciprocal, never gains energy (Schüssler et al. 2017)",
    params: NormalMapParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct NormalMapParams {
    /// the name of the reflecting bsdf the map tilts, declared before this
    /// one
    pub bsdf: NestedBsdf,
    /// tangent-space normals as colours (n + 1) / 2: x along +u, y toward
    /// the image's up, z out of the surface (glTF's and OpenGL's
    /// convention); an image of them is read with encoding = "linear"
    #[param(default = [0.5, 0.5, 1.0])]
    pub normals: TexturedRgb,
    /// scales the normals' x and y before they are normalised (glTF's
    /// normalTexture.scale)
    #[param(default = 1.0, range = (0.0, 1e3))]
    pub scale: f32,
}

/// A reflecting BSDF under a normal map.
pub struct NormalMap {
    inner: Arc<dyn Bsdf>,
    normals: TexturedRgb,
    scale: f32,
}

/// Below this `sin(theta_p)` the map's normal is the surface's, and the
/// inner BSDF is used as it is.
const FLAT: f32 = 1e-6;

/// The smallest `<wp, n>` a map may tilt to: a normal at or below the
/// horizon (a broken texel) is clamped up to it.
const MIN_COS_P: f32 = 1e-3;

impl NormalMap {
    /// `None` if `inner` transmits: the two facets model a reflecting
    /// surface.
    pub fn new(inner: Arc<dyn Bsdf>, normals: TexturedRgb, scale: f32) -> Option<Self> {
        (!inner.flags().contains(BsdfFlags::TRANSMISSION)).then_some(Self {
            inner,
            normals,
            scale,
        })
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = NormalMapParams::read(params)?;
        if let Some(c) = p.normals.constant() {
            if !(c.min_component() >= 0.0 && c.max_component() <= 1.0) {
                return Err(params.error(
                    NormalMapParams::KEYS.normals,
                    format!("each channel must be in [0, 1], got {c}"),
                ));
            }
        }
        Self::new(p.bsdf.0, p.normals, p.scale).ok_or_else(|| {
            params.error(
                NormalMapParams::KEYS.bsdf,
                "the inner BSDF transmits; normalmap needs a reflecting one",
            )
        })
    }

    /// The microsurface at the hit `ctx` looks up; `None` where the map
    /// does not tilt the normal.
    #[inline]
    fn microsurface(&self, ctx: &BsdfContext) -> Option<Microsurface> {
        let c = self.normals.eval(&ctx.texture);
        let n = Vec3::new(
            (2.0 * c.r - 1.0) * self.scale,
            (2.0 * c.g - 1.0) * self.scale,
            (2.0 * c.b - 1.0).max(0.0),
        );
        Microsurface::new(n)
    }
}

/// The two facets of a normal-mapped point, in the shading frame.
#[derive(Debug, Clone, Copy)]
struct Microsurface {
    /// The map's normal.
    wp: Vec3,
    /// The mirror facet's normal: horizontal, facing away from `wp`'s tilt.
    wt: Vec3,
    /// `sin(theta_p) / cos(theta_p)`, the mirror's area per unit surface.
    tan_p: f32,
    /// `wp`'s own frame, `x` the surface's `x` made orthogonal to `wp`, in
    /// which the inner BSDF is evaluated (pbrt-v4's normal mapping keeps
    /// `dp/du` the same way, so anisotropic lobes keep their direction).
    frame: Frame,
}

impl Microsurface {
    /// The facets of the (unnormalised) map normal `n`, or `None` if it is
    /// the surface's normal or not a direction.
    #[inline]
    fn new(n: Vec3) -> Option<Self> {
        let horizontal = Vec2::new(n.x, n.y);
        let h = horizontal.length();
        if !(h.is_finite() && n.z.is_finite()) {
            return None;
        }
        let z = n.z.max(MIN_COS_P * h);
        let length = (h * h + z * z).sqrt();
        if h <= FLAT * length {
            return None;
        }
        let wp = Vec3::new(n.x, n.y, z) / length;
        let wt = Vec3::new(-horizontal.x / h, -horizontal.y / h, 0.0);
        let x = (Vec3::X - wp * wp.x).normalize();
        let frame = Frame {
            x: x.into(),
            y: wp.cross(x).into(),
            z: wp.into(),
        };
        Some(Self {
            wp,
            wt,
            tan_p: h / z,
            frame,
        })
    }

    /// `(a_p(w) + a_t(w)) <wp, n>`, the facets' projected area toward `w`
    /// times the constant `<wp, n>` (eq. 4-5).
    #[inline]
    fn projected(&self, w: Vec3) -> (f32, f32) {
        let ap = w.dot(self.wp).max(0.0);
        let at = w.dot(self.wt).max(0.0) * self.tan_p * self.wp.z;
        (ap, at)
    }

    /// The probability that a ray arriving from `w` meets `wp` first.
    #[inline]
    fn lambda_p(&self, w: Vec3) -> f32 {
        let (ap, at) = self.projected(w);
        if ap + at > 0.0 {
            ap / (ap + at)
        } else {
            0.0
        }
    }

    /// The probability that a ray leaving the microsurface toward `w` is
    /// not shadowed by it (Smith's uncorrelated form, eq. 8).
    #[inline]
    fn g1(&self, w: Vec3) -> f32 {
        let (ap, at) = self.projected(w);
        if w.z <= 0.0 || ap + at <= 0.0 {
            return 0.0;
        }
        (w.z * self.wp.z / (ap + at)).min(1.0)
    }

    /// `w` reflected by the mirror facet.
    #[inline]
    fn mirror(&self, w: Vec3) -> Vec3 {
        w - 2.0 * w.dot(self.wt) * self.wt
    }

    /// The directions light leaves `wp` in to reach the viewer at `wo`,
    /// with their probabilities: straight (`lambda_p`), or by way of the
    /// mirror.
    #[inline]
    fn departures(&self, wo: Vec3) -> [(Vec3, f32); 2] {
        let lambda = self.lambda_p(wo);
        [(wo, lambda), (self.mirror(wo), 1.0 - lambda)]
    }

    /// The directions light arriving at `wi` leaves `wp` in, with the
    /// probabilities that it then reaches `wi`: unshadowed, or shadowed,
    /// mirrored and then unshadowed.
    #[inline]
    fn arrivals(&self, wi: Vec3) -> [(Vec3, f32); 2] {
        let g = self.g1(wi);
        let mirrored = self.mirror(wi);
        [(wi, g), (mirrored, (1.0 - self.g1(mirrored)) * g)]
    }
}

impl NormalMap {
    /// `(f, pdf)` of the four paths through the microsurface `s`:
    ///
    /// f(wo, wi) = sum over departures (w1, P1) and arrivals (w2, P2) of
    ///             P1 P2 f_p(w1, w2) <w2, wp> / <wi, n>,
    ///
    /// and the density of `sample_f`'s walk, the same sum of
    /// `P1 P2 pdf_p(w1, w2)` (the mirror keeps solid angle).
    #[inline]
    fn eval_paths(&self, ctx: &BsdfContext, s: &Microsurface, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let (mut f, mut pdf) = (Rgb::BLACK, 0.0);
        for (w1, p1) in s.departures(wo) {
            let cos1 = w1.dot(s.wp);
            if p1 <= 0.0 || cos1 <= 0.0 {
                continue;
            }
            let local1 = s.frame.to_local(w1);
            for (w2, p2) in s.arrivals(wi) {
                let cos2 = w2.dot(s.wp);
                if p2 <= 0.0 || cos2 <= 0.0 {
                    continue;
                }
                let (fp, pdfp) = self.inner.eval(ctx, local1, s.frame.to_local(w2));
                f += fp * (p1 * p2 * cos2);
                pdf += p1 * p2 * pdfp;
            }
        }
        (f * (1.0 / wi.z), pdf)
    }
}

/// Two numbers for the walk's choices, decorrelated from `u1` and `u2`
/// which the inner BSDF consumes (pbrt-v4's layered BSDFs seed their walks
/// the same way).
#[inline]
fn walk_rng(wo: Vec3, u1: f32, u2: Vec2) -> Pcg32 {
    let key = (u64::from(u1.to_bits()) << 32) | u64::from(u2.x.to_bits());
    let dir = (u64::from(wo.x.to_bits()) << 32) | u64::from(wo.y.to_bits());
    Pcg32::new(hash_with(key, u64::from(u2.y.to_bits())), hash_with(dir, 1))
}

impl Bsdf for NormalMap {
    fn flags(&self) -> BsdfFlags {
        self.inner.flags()
    }

    fn uses_tangent_frame(&self) -> bool {
        true
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.eval(ctx, wo, wi).0
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.eval(ctx, wo, wi).1
    }

    /// The map tilts the front; from behind, or where it is flat, the
    /// inner BSDF answers alone.
    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        match self.microsurface(ctx) {
            Some(s) if wo.z > 0.0 => {
                if wi.z <= 0.0 {
                    return (Rgb::BLACK, 0.0);
                }
                self.eval_paths(ctx, &s, wo, wi)
            }
            _ => self.inner.eval(ctx, wo, wi),
        }
    }

    /// The random walk the four paths describe: enter by `wp` or by the
    /// mirror, sample the inner BSDF on `wp`, leave unshadowed or by the
    /// mirror (section 4.2).
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        let s = match self.microsurface(ctx) {
            Some(s) if wo.z > 0.0 => s,
            _ => return self.inner.sample_f(ctx, wo, u1, u2),
        };
        let mut rng = walk_rng(wo, u1, u2);
        let [(wo_p, lambda), (wo_t, _)] = s.departures(wo);
        let (w1, p1) = if rng.next_f32() < lambda {
            (wo_p, lambda)
        } else {
            (wo_t, 1.0 - lambda)
        };
        let inner = self.inner.sample_f(ctx, s.frame.to_local(w1), u1, u2)?;
        if inner.wi.z <= 0.0 {
            return None;
        }
        let w2 = s.frame.to_world(inner.wi);
        let escape = s.g1(w2);
        let (wi, p2) = if rng.next_f32() < escape {
            (w2, escape)
        } else {
            let wi = s.mirror(w2);
            let g = s.g1(wi);
            if rng.next_f32() >= g {
                return None;
            }
            (wi, (1.0 - escape) * g)
        };
        if wi.z <= 0.0 {
            return None;
        }
        if inner.flags.is_specular() {
            // A delta lobe: the walk's probability and its weight
            // f cos / pdf, which the facets' own choices leave unchanged.
            let pdf = p1 * inner.pdf * p2;
            let weight = inner.f * (inner.wi.z / inner.pdf);
            return Some(BsdfSample {
                f: weight * (pdf / wi.z),
                wi,
                pdf,
                flags: inner.flags,
                eta: 1.0,
            });
        }
        let (f, pdf) = self.eval_paths(ctx, &s, wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then_some(BsdfSample {
            f,
            wi,
            pdf,
            flags: inner.flags,
            eta: 1.0,
        })
    }
}

#[cfg(test)]
mod tests {
    use lumis_api::params::Textured;
    use lumis_sampling::warp;

    use super::*;
    use crate::microfacet::{Distribution, Microfacet};
    use crate::{Conductor, ConductorFresnel, Diffuse, DiffuseSampling, LobeSampling};

    fn tilted(inner: Arc<dyn Bsdf>, normal: Vec3) -> NormalMap {
        let c = (normal.normalize() + Vec3::ONE) * 0.5;
        NormalMap::new(inner, Textured::Constant(Rgb::new(c.x, c.y, c.z)), 1.0).unwrap()
    }

    fn white() -> Arc<dyn Bsdf> {
        Arc::new(Diffuse::new(Rgb::WHITE, false, DiffuseSampling::Cosine))
    }

    /// The albedo from `wo`, `E[f cos / pdf]` over `sample_f`, and the
    /// same integral by uniform hemisphere samples of `f`.
    fn albedos(b: &dyn Bsdf, wo: Vec3, n: u32) -> (f32, f32) {
        let ctx = BsdfContext::default();
        let mut rng = Pcg32::new(3, 5);
        let (mut sampled, mut integrated) = (0.0, 0.0);
        for _ in 0..n {
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = b.sample_f(&ctx, wo, rng.next_f32(), u2) {
                sampled += s.f.g * s.wi.z / s.pdf;
            }
            let wi = warp::square_to_uniform_hemisphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            integrated += b.f(&ctx, wo, wi).g * wi.z / (2.0 * warp::UNIFORM_SPHERE_PDF);
        }
        (sampled / n as f32, integrated / n as f32)
    }

    #[test]
    fn a_flat_map_is_the_inner_bsdf() {
        let ctx = BsdfContext::default();
        let flat = tilted(white(), Vec3::Z);
        let (wo, wi) = (Vec3::new(0.3, 0.1, 0.9), Vec3::new(-0.5, 0.2, 0.7));
        assert_eq!(flat.eval(&ctx, wo, wi), white().eval(&ctx, wo, wi));
        assert_eq!(flat.sample_f(&ctx, wo, 0.3, Vec2::new(0.2, 0.9)), {
            white().sample_f(&ctx, wo, 0.3, Vec2::new(0.2, 0.9))
        });
    }

    /// Under a white Lambertian facet every path's value is the same,
    /// `cos(theta_p) / pi` (the mirror's shadowing cancels the facet's
    /// cosine), so the albedo is `cos(theta_p)` from every direction: the
    /// sampled and the integrated albedo both find it.
    #[test]
    fn a_white_facet_has_the_albedo_cos_theta_p_from_every_direction() {
        for degrees in [10.0f32, 30.0, 50.0, 80.0] {
            let t = degrees.to_radians();
            let b = tilted(white(), Vec3::new(t.sin(), 0.0, t.cos()));
            for wo in [
                Vec3::Z,
                Vec3::new(0.7, 0.0, 0.714),
                Vec3::new(-0.7, 0.2, 0.714),
            ] {
                let wo = wo.normalize();
                let (sampled, integrated) = albedos(&b, wo, 200_000);
                let at = format!("{degrees} degrees from {wo}: {sampled} {integrated}");
                assert!((sampled - t.cos()).abs() < 0.005, "{at}");
                assert!((integrated - t.cos()).abs() < 0.01, "{at}");
            }
        }
    }

    #[test]
    fn reciprocal_for_every_tilt() {
        let ctx = BsdfContext::default();
        let rough: Arc<dyn Bsdf> = Arc::new(Conductor::new(
            Microfacet::new(Distribution::Ggx, 0.3, 0.3),
            ConductorFresnel::Perfect,
            LobeSampling::Model(crate::microfacet::NormalSampling::Visible),
        ));
        let mut rng = Pcg32::new(11, 13);
        for inner in [white(), rough] {
            for tilt in [0.2f32, 0.8, 1.4] {
                let n = Vec3::new(tilt.sin() * 0.6, tilt.sin() * 0.8, tilt.cos());
                let b = tilted(inner.clone(), n);
                for _ in 0..2000 {
                    let mut dir = || {
                        warp::square_to_uniform_hemisphere(Vec2::new(
                            rng.next_f32(),
                            rng.next_f32(),
                        ))
                    };
                    let (a, c) = (dir(), dir());
                    let (fac, fca) = (b.f(&ctx, a, c), b.f(&ctx, c, a));
                    let tol = 1e-4 * fac.max_component().max(1.0);
                    assert!(
                        (fac - fca).max_component().abs() <= tol,
                        "{tilt} {a} {c}: {fac:?} {fca:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_transmitting_inner_bsdf_is_refused() {
        let glass = crate::Dielectric::new(1.5, Microfacet::new(Distribution::Ggx, 0.0, 0.0));
        let normals = Textured::Constant(Rgb::new(0.5, 0.5, 1.0));
        assert!(NormalMap::new(Arc::new(glass), normals, 1.0).is_none());
    }

    #[test]
    fn a_normal_below_the_horizon_is_clamped_to_it() {
        let s = Microsurface::new(Vec3::new(1.0, 0.0, -0.5)).unwrap();
        assert!(s.wp.z > 0.0 && s.wp.z < 2e-3, "{:?}", s.wp);
        assert!(Microsurface::new(Vec3::new(0.0, 0.0, 1.0)).is_none());
        assert!(Microsurface::new(Vec3::new(f32::NAN, 0.0, 1.0)).is_none());
    }
}
