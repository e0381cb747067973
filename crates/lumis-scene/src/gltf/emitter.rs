//! Emissive textures: a triangle light whose radiance an `emissiveTexture`
//! (an `image` texture plugin) scales at each point.

use std::sync::Arc;

use lumis_core::{
    Light, LightKind, LightSample, LightSampleContext, Rgb, Texture, TextureQuery, Vec2, Vec3,
};

/// A triangle light whose radiance is multiplied by a texture
/// (`emissiveTexture`) at the point's uv.
///
/// Sampling is the inner light's (by area or solid angle, not by texture
/// brightness), so estimates stay unbiased: the sample's radiance is scaled
/// by the texel at the sampled point, whose uv comes from its barycentric
/// coordinates. `power` uses the texture's mean at the corners and the
/// centroid, which only steers the power light sampler's choice.
pub(crate) struct TexturedEmitter {
    pub inner: Box<dyn Light>,
    pub texture: Arc<dyn Texture>,
    pub p: [Vec3; 3],
    pub uv: [Vec2; 3],
}

impl TexturedEmitter {
    /// The texture's value at `uv` (no footprint: light samples have none).
    fn lookup(&self, uv: Vec2) -> Rgb {
        self.texture.eval(&TextureQuery::at(uv))
    }

    /// The uv at a point on the triangle (projected onto its plane).
    fn uv_at(&self, q: Vec3) -> Vec2 {
        let [p0, p1, p2] = self.p;
        let (e1, e2, d) = (p1 - p0, p2 - p0, q - p0);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d1, d2) = (d.dot(e1), d.dot(e2));
        let det = d11 * d22 - d12 * d12;
        let b1 = (d22 * d1 - d12 * d2) / det;
        let b2 = (d11 * d2 - d12 * d1) / det;
        let [t0, t1, t2] = self.uv;
        t0 * (1.0 - b1 - b2) + t1 * b1 + t2 * b2
    }
}

impl Light for TexturedEmitter {
    fn kind(&self) -> LightKind {
        self.inner.kind()
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let mut s = self.inner.sample_li(ctx, u)?;
        s.l = self.lookup(self.uv_at(s.p.p)) * s.l;
        Some(s)
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.inner.pdf_li(ctx, wi)
    }

    /// `uv` is the hit's interpolated texture coordinate (meshes with an
    /// emissive texture store their uvs).
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        self.lookup(uv) * self.inner.l(p, n, uv, w)
    }

    fn power(&self) -> Rgb {
        let [t0, t1, t2] = self.uv;
        let mean = 0.25
            * (self.lookup(t0)
                + self.lookup(t1)
                + self.lookup(t2)
                + self.lookup((t0 + t1 + t2) / 3.0));
        mean * self.inner.power()
    }

    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        self.inner.preprocess(scene_center, scene_radius)
    }
}
