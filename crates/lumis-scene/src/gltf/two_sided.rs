//! `doubleSided` materials: a one-sided BSDF seen from both sides.

use std::sync::Arc;

use lumis_core::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, Rgb, Vec2, Vec3};

/// Mitsuba's `twosided`: a hit from behind evaluates the inner BSDF with
/// both directions mirrored to the front (z -> -z), so the back of the
/// surface looks like its front. Front hits pass through unchanged.
pub(crate) struct TwoSided {
    pub inner: Arc<dyn Bsdf>,
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
