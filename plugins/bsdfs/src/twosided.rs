//! `twosided`: a reflecting BSDF seen from both sides (Mitsuba 3's
//! `twosided` with one inner BSDF).
//!
//! A hit from behind evaluates the inner BSDF with both directions mirrored
//! to the front (z -> -z), so the back of the surface looks like its front;
//! front hits pass through unchanged. Energy and reciprocity are the inner
//! BSDF's on each side, and a pair of directions on opposite sides
//! (transmission) gets nothing; a transmitting inner BSDF is refused. glTF
//! `doubleSided` materials use it. `lumis check-plugin` sweeps it over three
//! stand-in inner BSDFs (rough plastic, diffuse, rough gold).

use lumis_api::params::NestedBsdf;
use lumis_api::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, Vec2, Vec3,
};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Bsdf,
    name: "twosided",
    source: lumis_api::source_file!(),
    doc: "a reflecting BSDF on both sides of the surface (Mitsuba's twosided)",
    params: TwoSidedParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct TwoSidedParams {
    /// the name of the bsdf seen from both sides, declared before this one; it must
    /// not transmit
    pub bsdf: NestedBsdf,
}

/// A reflecting BSDF on both sides.
pub struct TwoSided {
    inner: std::sync::Arc<dyn Bsdf>,
}

impl TwoSided {
    /// `None` if `inner` transmits: mirroring cannot make a transmitting
    /// BSDF two-sided (each side would see the other's transmission).
    pub fn new(inner: std::sync::Arc<dyn Bsdf>) -> Option<Self> {
        (!inner.flags().contains(BsdfFlags::TRANSMISSION)).then_some(Self { inner })
    }

    pub fn from_params(params: &Params) -> Result<Self> {
        let p = TwoSidedParams::read(params)?;
        Self::new(p.bsdf.0).ok_or_else(|| {
            params.error(
                TwoSidedParams::KEYS.bsdf,
                "the inner BSDF transmits; twosided needs a reflecting one",
            )
        })
    }
}

#[inline]
fn mirrored(v: Vec3) -> Vec3 {
    Vec3::new(v.x, v.y, -v.z)
}

/// `(wo, wi)` as the inner BSDF sees them: mirrored to the front for a hit
/// from behind.
#[inline]
fn to_front(wo: Vec3, wi: Vec3) -> (Vec3, Vec3) {
    if wo.z < 0.0 {
        (mirrored(wo), mirrored(wi))
    } else {
        (wo, wi)
    }
}

impl Bsdf for TwoSided {
    fn flags(&self) -> BsdfFlags {
        self.inner.flags()
    }

    fn uses_tangent_frame(&self) -> bool {
        self.inner.uses_tangent_frame()
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        let (wo, wi) = to_front(wo, wi);
        self.inner.f(ctx, wo, wi)
    }

    #[inline]
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if wo.z >= 0.0 {
            return self.inner.sample_f(ctx, wo, u1, u2);
        }
        let mut s = self.inner.sample_f(ctx, mirrored(wo), u1, u2)?;
        s.wi = mirrored(s.wi);
        Some(s)
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        let (wo, wi) = to_front(wo, wi);
        self.inner.pdf(ctx, wo, wi)
    }

    /// Mirrored once for both values, through the inner model's own `eval`.
    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        let (wo, wi) = to_front(wo, wi);
        self.inner.eval(ctx, wo, wi)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use lumis_sampling::Pcg32;

    use super::*;
    use crate::microfacet::{Distribution, Microfacet};
    use crate::Plastic;

    fn inner() -> Arc<dyn Bsdf> {
        let coat = Microfacet::new(Distribution::Ggx, 0.3, 0.3);
        Arc::new(Plastic::new(
            Rgb::new(0.8, 0.4, 0.1),
            Rgb::WHITE,
            1.5,
            coat,
            true,
        ))
    }

    /// The albedo from `wo`: the mean of f cos / pdf over `sample_f`.
    fn albedo(b: &dyn Bsdf, wo: Vec3, n: u32) -> Rgb {
        let ctx = BsdfContext::default();
        let mut rng = Pcg32::new(7, 9);
        let mut sum = Rgb::BLACK;
        for _ in 0..n {
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(s) = b.sample_f(&ctx, wo, rng.next_f32(), u2) {
                assert_eq!(s.wi.z.signum(), wo.z.signum(), "no transmission");
                sum += s.f * (s.wi.z.abs() / s.pdf);
            }
        }
        sum / n as f32
    }

    #[test]
    fn the_back_reflects_as_the_front_and_conserves_energy() {
        let two = TwoSided::new(inner()).unwrap();
        let ctx = BsdfContext::default();
        let wo = Vec3::new(0.3, -0.2, 0.5).normalize();
        let front = albedo(&two, wo, 200_000);
        let back = albedo(&two, mirrored(wo), 200_000);
        // The same samples, mirrored: equal estimates, below one.
        assert_eq!(front, back);
        assert!(front.max_component() <= 1.0, "{front:?}");
        assert_eq!(front, albedo(&*inner(), wo, 200_000));
        // From behind, nothing crosses to the front.
        let wi = Vec3::new(-0.4, 0.1, 0.9).normalize();
        assert!(two.f(&ctx, mirrored(wo), wi).is_black());
        assert_eq!(two.pdf(&ctx, mirrored(wo), wi), 0.0);
    }

    #[test]
    fn reciprocity_on_both_sides() {
        let two = TwoSided::new(inner()).unwrap();
        let ctx = BsdfContext::default();
        let mut rng = Pcg32::new(1, 3);
        for _ in 0..1000 {
            let a = lumis_sampling::warp::square_to_cosine_hemisphere(Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            let b = lumis_sampling::warp::square_to_cosine_hemisphere(Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            for (a, b) in [(a, b), (mirrored(a), mirrored(b))] {
                let (fab, fba) = (two.f(&ctx, a, b), two.f(&ctx, b, a));
                let tol = 1e-5 * fab.max_component().max(1.0);
                assert!((fab - fba).max_component().abs() <= tol, "{a} {b}");
                assert!((fba - fab).max_component().abs() <= tol, "{a} {b}");
            }
        }
    }

    #[test]
    fn a_transmitting_inner_bsdf_is_refused() {
        let glass = crate::Dielectric::new(1.5, Microfacet::new(Distribution::Ggx, 0.0, 0.0));
        assert!(TwoSided::new(Arc::new(glass)).is_none());
    }
}
