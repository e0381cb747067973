//! The BSDF wrappers of glTF materials (base colour texture, `doubleSided`)
//! forward `eval` to the wrapped model: it must agree bit for bit with their
//! own `f` and `pdf`, whichever way the texture reaches the model.

use std::sync::Arc;

use lumis_core::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, Rgb, Vec2, Vec3};

use super::texture::{AlbedoTextured, Texture};
use super::two_sided::TwoSided;

/// A one-sided model whose `f` and `pdf` depend on both directions and, if
/// it takes one, on the albedo scale, with its own `eval` override.
struct Probe {
    takes_albedo_scale: bool,
}

impl Probe {
    fn albedo(&self, ctx: &BsdfContext) -> Rgb {
        match (self.takes_albedo_scale, ctx.albedo_scale) {
            (true, Some(scale)) => scale,
            _ => Rgb::new(0.5, 0.25, 0.125),
        }
    }
}

impl Bsdf for Probe {
    fn flags(&self) -> BsdfFlags {
        BsdfFlags::DIFFUSE_REFLECTION
    }

    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        if wo.z > 0.0 && wi.z > 0.0 {
            self.albedo(ctx) * (wo.z + 2.0 * wi.z)
        } else {
            Rgb::BLACK
        }
    }

    fn sample_f(&self, _: &BsdfContext, _: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
        None
    }

    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z > 0.0 && wi.z > 0.0 {
            wi.z * (1.0 + wo.x) * self.albedo(ctx).g
        } else {
            0.0
        }
    }

    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        (self.f(ctx, wo, wi), self.pdf(ctx, wo, wi))
    }

    fn takes_albedo_scale(&self) -> bool {
        self.takes_albedo_scale
    }
}

#[test]
fn wrappers_eval_matches_their_f_and_pdf() {
    let texture = Arc::new(Texture::from_srgb8(
        2,
        2,
        vec![[255, 0, 0], [0, 255, 0], [0, 0, 255], [200, 100, 50]],
    ));
    let ctx = BsdfContext {
        texture: lumis_core::TextureQuery::at(Vec2::new(0.3, 0.7)),
        ..Default::default()
    };
    let directions = [
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, 0.8)),
        (Vec3::new(0.6, 0.0, -0.8), Vec3::new(0.0, -0.6, -0.8)),
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, -0.8)),
    ];
    for takes_albedo_scale in [false, true] {
        let probe: Arc<dyn Bsdf> = Arc::new(Probe { takes_albedo_scale });
        let two_sided: Arc<dyn Bsdf> = Arc::new(TwoSided {
            inner: probe.clone(),
        });
        let wrappers: [Arc<dyn Bsdf>; 3] = [
            two_sided.clone(),
            Arc::new(AlbedoTextured::new(probe, texture.clone())),
            Arc::new(AlbedoTextured::new(two_sided, texture.clone())),
        ];
        for (k, bsdf) in wrappers.iter().enumerate() {
            for (wo, wi) in directions {
                let (f, pdf) = bsdf.eval(&ctx, wo, wi);
                assert_eq!(f, bsdf.f(&ctx, wo, wi), "wrapper {k}, {wo} {wi}");
                assert_eq!(
                    pdf.to_bits(),
                    bsdf.pdf(&ctx, wo, wi).to_bits(),
                    "wrapper {k}, {wo} {wi}"
                );
            }
        }
    }
}
