//! Turn plugin interfaces into (sampler, pdf) pairs for [`crate::chi_square()`].

use lumis_core::{Bsdf, BsdfContext, Light, LightSampleContext, Vec2, Vec3};

/// `sample_f` and `pdf` of `bsdf` for a fixed `wo` (local frame). Specular
/// (delta) samples are not part of the density and are dropped.
pub fn bsdf_pair<'a>(
    bsdf: &'a dyn Bsdf,
    wo: Vec3,
) -> (
    impl FnMut(f32, Vec2) -> Option<Vec3> + 'a,
    impl Fn(Vec3) -> f32 + 'a,
) {
    let ctx = BsdfContext::default();
    let sample = move |u1: f32, u2: Vec2| {
        bsdf.sample_f(&ctx, wo, u1, u2)
            .filter(|s| !s.flags.is_specular() && s.pdf > 0.0)
            .map(|s| s.wi)
    };
    let pdf = move |wi: Vec3| bsdf.pdf(&ctx, wo, wi);
    (sample, pdf)
}

/// `sample_li` and `pdf_li` of `light` from the reference point `ctx`.
pub fn light_pair<'a>(
    light: &'a dyn Light,
    ctx: LightSampleContext,
) -> (
    impl FnMut(f32, Vec2) -> Option<Vec3> + 'a,
    impl Fn(Vec3) -> f32 + 'a,
) {
    let sample = move |_u1: f32, u: Vec2| {
        light
            .sample_li(&ctx, u)
            .filter(|s| s.pdf > 0.0)
            .map(|s| s.wi)
    };
    let pdf = move |wi: Vec3| light.pdf_li(&ctx, wi);
    (sample, pdf)
}
