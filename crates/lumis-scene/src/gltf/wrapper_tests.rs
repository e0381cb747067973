//! The BSDF wrapper of glTF `doubleSided` materials forwards `eval` to the
//! wrapped model: it must agree bit for bit with its own `f` and `pdf`.

use std::sync::Arc;

use lumis_core::{Bsdf, BsdfContext, BsdfFlags, BsdfSample, Rgb, Vec2, Vec3};

use super::two_sided::TwoSided;

/// A one-sided model whose `f` and `pdf` depend on both directions and on
/// the hit's uv, with its own `eval` override.
struct Probe;

impl Probe {
    fn albedo(&self, ctx: &BsdfContext) -> Rgb {
        Rgb::new(0.5, 0.25, 0.125) * (1.0 + ctx.texture.uv.x)
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
}

#[test]
fn wrappers_eval_matches_their_f_and_pdf() {
    let ctx = BsdfContext {
        texture: lumis_core::TextureQuery::at(Vec2::new(0.3, 0.7)),
        ..Default::default()
    };
    let directions = [
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, 0.8)),
        (Vec3::new(0.6, 0.0, -0.8), Vec3::new(0.0, -0.6, -0.8)),
        (Vec3::new(0.6, 0.0, 0.8), Vec3::new(0.0, 0.6, -0.8)),
    ];
    let bsdf: Arc<dyn Bsdf> = Arc::new(TwoSided {
        inner: Arc::new(Probe),
    });
    for (wo, wi) in directions {
        let (f, pdf) = bsdf.eval(&ctx, wo, wi);
        assert_eq!(f, bsdf.f(&ctx, wo, wi), "{wo} {wi}");
        assert_eq!(pdf.to_bits(), bsdf.pdf(&ctx, wo, wi).to_bits(), "{wo} {wi}");
    }
}
