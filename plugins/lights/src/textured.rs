//! Area lights whose radiance a texture gives over the surface (pbrt-v4's
//! `DiffuseAreaLight` with an image, Mitsuba 3's `area` emitter with a
//! textured `radiance`): a glTF `emissiveTexture`, or a TOML shape's
//! `emission = { radiance = { texture = ".." } }`.

use std::sync::Arc;

use lumis_api::light::EmissionSample;
use lumis_api::{
    Light, LightBounds, LightKind, LightSample, LightSampleContext, Rgb, Texture, TextureQuery,
    Vec2, Vec3,
};

use crate::area::{planar_bounds, AreaLight, PlanarShape};

/// An area light of white radiance, scaled by `texture` at each point.
///
/// Sampling is the plain light's (by area or solid angle, not by the
/// texture's brightness), so estimates stay unbiased: a sample's radiance
/// is the texture's at the sampled point.
pub struct TexturedAreaLight<S> {
    light: AreaLight<S>,
    texture: Arc<dyn Texture>,
    /// The texture's mean over the surface, estimated at load: what the
    /// light's power, and so the power light sampler, goes by.
    mean: Rgb,
}

/// Points per side of the grid the mean is estimated on.
const MEAN_GRID: u32 = 8;

impl<S: PlanarShape> TexturedAreaLight<S> {
    pub fn new(light: AreaLight<S>, texture: Arc<dyn Texture>) -> Self {
        let n = MEAN_GRID;
        let mut sum = Rgb::BLACK;
        for i in 0..n * n {
            let u = Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) / n as f32;
            let p = light.shape.sample_point(u).p;
            sum += texture.eval(&TextureQuery::at(light.shape.uv_at(p)));
        }
        Self {
            mean: sum * (1.0 / (n * n) as f32),
            light,
            texture,
        }
    }

    /// The texture at `uv` (light samples have no pixel footprint).
    #[inline]
    fn at(&self, uv: Vec2) -> Rgb {
        self.texture.eval(&TextureQuery::at(uv))
    }
}

impl<S: PlanarShape> Light for TexturedAreaLight<S> {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let mut s = self.light.sample_li(ctx, u)?;
        s.l = self.at(self.light.shape.uv_at(s.p.p)) * s.l;
        Some(s)
    }

    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let mut s = self.light.sample_le(u_pos, u_dir)?;
        s.l = self.at(self.light.shape.uv_at(s.p.p)) * s.l;
        Some(s)
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.light.pdf_li(ctx, wi)
    }

    /// `uv` is the hit's, interpolated as its mesh's.
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        self.at(uv) * self.light.l(p, n, uv, w)
    }

    fn power(&self) -> Rgb {
        self.mean * self.light.power()
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(planar_bounds(
            &self.light.shape,
            self.power(),
            &self.light.emission,
        ))
    }
}

/// `light` as a light plugin: textured by `texture` if there is one.
pub fn boxed<S: PlanarShape + 'static>(
    light: AreaLight<S>,
    texture: Option<Arc<dyn Texture>>,
) -> Box<dyn Light> {
    match texture {
        Some(texture) => Box::new(TexturedAreaLight::new(light, texture)),
        None => Box::new(light),
    }
}
