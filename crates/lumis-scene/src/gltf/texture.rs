//! Base colour textures: PNG and JPEG images of a glTF asset, looked up at the
//! interpolated texture coordinate of a hit (`BsdfContext::uv`).
//!
//! Texels stay 8-bit sRGB in memory (3 bytes each) and are converted to
//! linear through a 256-entry table on lookup. The asset's sampler decides
//! wrapping (repeat, mirrored repeat, clamp) and magnification (bilinear,
//! or nearest); there are no mip maps, so minification filters are not
//! modelled.

use std::sync::Arc;

use lumis_core::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, Light, LightKind, LightSample, LightSampleContext,
    Rgb, Vec2, Vec3,
};

/// How lookups outside [0, 1] map back into the image (glTF sampler
/// `wrapS` / `wrapT`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

impl Wrap {
    fn index(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
            Wrap::Clamp => i.clamp(0, n - 1),
        }) as usize
    }
}

/// An sRGB image with filtered, wrapped lookups.
pub(crate) struct Texture {
    width: usize,
    height: usize,
    texels: Vec<[u8; 3]>,
    to_linear: [f32; 256],
    wrap: [Wrap; 2],
    nearest: bool,
    /// `KHR_texture_transform` as `[a, b, c, d, tx, ty]`:
    /// `u' = a u + b v + tx`, `v' = c u + d v + ty`.
    uv_transform: Option<[f32; 6]>,
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

impl Texture {
    /// Decodes a PNG (any bit depth and colour type; alpha is dropped).
    pub fn from_png(bytes: &[u8]) -> Result<Self, String> {
        let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().map_err(|e| format!("bad PNG: {e}"))?;
        let size = reader
            .output_buffer_size()
            .ok_or("PNG too large to decode")?;
        let mut buf = vec![0u8; size];
        let info = reader
            .next_frame(&mut buf)
            .map_err(|e| format!("bad PNG: {e}"))?;
        let (width, height) = (info.width as usize, info.height as usize);
        let channels = match info.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => return Err("indexed PNG was not expanded".into()),
        };
        let mut texels = Vec::with_capacity(width * height);
        for row in buf.chunks_exact(info.line_size).take(height) {
            for px in row.chunks_exact(channels).take(width) {
                texels.push(if channels < 3 {
                    [px[0]; 3]
                } else {
                    [px[0], px[1], px[2]]
                });
            }
        }
        if width == 0 || height == 0 || texels.len() != width * height {
            return Err(format!("PNG of {width}x{height} pixels could not be read"));
        }
        Ok(Self::from_srgb8(width, height, texels))
    }

    /// Decodes a baseline or progressive JPEG (greyscale or RGB).
    pub fn from_jpeg(bytes: &[u8]) -> Result<Self, String> {
        let mut decoder = jpeg_decoder::Decoder::new(std::io::Cursor::new(bytes));
        let pixels = decoder.decode().map_err(|e| format!("bad JPEG: {e}"))?;
        let info = decoder.info().ok_or("bad JPEG: no frame")?;
        let (width, height) = (info.width as usize, info.height as usize);
        let texels: Vec<[u8; 3]> = match info.pixel_format {
            jpeg_decoder::PixelFormat::L8 => pixels.iter().map(|&l| [l; 3]).collect(),
            // Big-endian 16-bit luminance: the high byte is the 8-bit value.
            jpeg_decoder::PixelFormat::L16 => pixels.chunks_exact(2).map(|l| [l[0]; 3]).collect(),
            jpeg_decoder::PixelFormat::RGB24 => {
                pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect()
            }
            jpeg_decoder::PixelFormat::CMYK32 => return Err("CMYK JPEGs are not supported".into()),
        };
        if width == 0 || height == 0 || texels.len() != width * height {
            return Err(format!("JPEG of {width}x{height} pixels could not be read"));
        }
        Ok(Self::from_srgb8(width, height, texels))
    }

    pub(crate) fn from_srgb8(width: usize, height: usize, texels: Vec<[u8; 3]>) -> Self {
        Self {
            width,
            height,
            texels,
            to_linear: std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0)),
            wrap: [Wrap::Repeat; 2],
            nearest: false,
            uv_transform: None,
        }
    }

    /// Applies `KHR_texture_transform` before every lookup: scale, then
    /// rotate by `rotation` radians (counter-clockwise in uv, i.e. the image
    /// turns clockwise), then offset. The extension's GLSL snippet has the
    /// rotation's sign flipped against its own prose and examples; this
    /// follows the examples (an offset of [0, 1], rotation pi/2 and scale
    /// 0.5 selects the image's lower left quadrant).
    pub fn with_uv_transform(mut self, offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> Self {
        let (s, c) = rotation.sin_cos();
        self.uv_transform = Some([
            c * scale[0],
            s * scale[1],
            -s * scale[0],
            c * scale[1],
            offset[0],
            offset[1],
        ]);
        self
    }

    fn transformed(&self, uv: Vec2) -> Vec2 {
        match self.uv_transform {
            Some([a, b, c, d, tx, ty]) => {
                Vec2::new(a * uv.x + b * uv.y + tx, c * uv.x + d * uv.y + ty)
            }
            None => uv,
        }
    }

    /// Sets the sampler: wrap modes for u and v, and nearest (instead of
    /// bilinear) magnification.
    pub fn with_sampler(mut self, wrap: [Wrap; 2], nearest: bool) -> Self {
        self.wrap = wrap;
        self.nearest = nearest;
        self
    }

    fn texel(&self, x: i64, y: i64) -> Rgb {
        let x = self.wrap[0].index(x, self.width);
        let y = self.wrap[1].index(y, self.height);
        let [r, g, b] = self.texels[y * self.width + x];
        Rgb::new(
            self.to_linear[r as usize],
            self.to_linear[g as usize],
            self.to_linear[b as usize],
        )
    }

    /// Linear RGB at `uv` (glTF convention: (0, 0) is the image's top-left
    /// corner), bilinear between texel centres (or the nearest texel).
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let uv = self.transformed(uv);
        if !uv.is_finite() {
            return self.texel(0, 0);
        }
        if self.nearest {
            let x = (uv.x * self.width as f32).floor() as i64;
            let y = (uv.y * self.height as f32).floor() as i64;
            return self.texel(x, y);
        }
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        (1.0 - fy) * ((1.0 - fx) * self.texel(x0, y0) + fx * self.texel(x0 + 1, y0))
            + fy * ((1.0 - fx) * self.texel(x0, y0 + 1) + fx * self.texel(x0 + 1, y0 + 1))
    }

    pub fn byte_size(&self) -> usize {
        self.texels.capacity() * 3
    }
}

/// A BSDF whose colour a texture scales at the hit's uv.
///
/// A BSDF that takes an albedo scale (`plastic`, whose coat stays white
/// and whose lobe choice follows the tinted base) gets the texel through
/// [`BsdfContext::albedo_scale`], so that `f`, `sample_f` and `pdf` all see
/// the same value. Any other BSDF (`diffuse`, `conductor`) is linear in its
/// colour and samples independently of it: the texel scales `f` and leaves
/// `pdf` and the sampled directions alone.
pub(crate) struct AlbedoTextured {
    inner: Arc<dyn Bsdf>,
    texture: Arc<Texture>,
    /// `inner.takes_albedo_scale()`, asked once.
    through_context: bool,
}

impl AlbedoTextured {
    pub fn new(inner: Arc<dyn Bsdf>, texture: Arc<Texture>) -> Self {
        Self {
            through_context: inner.takes_albedo_scale(),
            inner,
            texture,
        }
    }

    /// The context with the texel at its uv as the albedo scale.
    #[inline]
    fn textured(&self, ctx: &BsdfContext) -> BsdfContext {
        let texel = self.texture.lookup(ctx.texture.uv);
        BsdfContext {
            albedo_scale: Some(ctx.albedo_scale.map_or(texel, |s| s * texel)),
            ..*ctx
        }
    }
}

impl Bsdf for AlbedoTextured {
    fn flags(&self) -> BsdfFlags {
        self.inner.flags()
    }

    #[inline]
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        if self.through_context {
            self.inner.f(&self.textured(ctx), wo, wi)
        } else {
            self.texture.lookup(ctx.texture.uv) * self.inner.f(ctx, wo, wi)
        }
    }

    #[inline]
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        if self.through_context {
            return self.inner.sample_f(&self.textured(ctx), wo, u1, u2);
        }
        let mut s = self.inner.sample_f(ctx, wo, u1, u2)?;
        s.f = self.texture.lookup(ctx.texture.uv) * s.f;
        Some(s)
    }

    #[inline]
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        if self.through_context {
            self.inner.pdf(&self.textured(ctx), wo, wi)
        } else {
            self.inner.pdf(ctx, wo, wi)
        }
    }

    /// One texel lookup for both values, and the inner model's own `eval`.
    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        if self.through_context {
            return self.inner.eval(&self.textured(ctx), wo, wi);
        }
        let (f, pdf) = self.inner.eval(ctx, wo, wi);
        (self.texture.lookup(ctx.texture.uv) * f, pdf)
    }
}

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
    pub texture: Arc<Texture>,
    pub p: [Vec3; 3],
    pub uv: [Vec2; 3],
}

impl TexturedEmitter {
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
        s.l = self.texture.lookup(self.uv_at(s.p.p)) * s.l;
        Some(s)
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.inner.pdf_li(ctx, wi)
    }

    /// `uv` is the hit's interpolated texture coordinate (meshes with an
    /// emissive texture store their uvs).
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        self.texture.lookup(uv) * self.inner.l(p, n, uv, w)
    }

    fn power(&self) -> Rgb {
        let [t0, t1, t2] = self.uv;
        let mean = 0.25
            * (self.texture.lookup(t0)
                + self.texture.lookup(t1)
                + self.texture.lookup(t2)
                + self.texture.lookup((t0 + t1 + t2) / 3.0));
        mean * self.inner.power()
    }

    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        self.inner.preprocess(scene_center, scene_radius)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        Texture::from_srgb8(
            2,
            2,
            vec![[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]],
        )
    }

    #[test]
    fn texture_transform_follows_the_extension_examples() {
        // "utilizes only the lower left quadrant of the source image,
        // rotated clockwise 90 degrees".
        let t = checker().with_uv_transform([0.0, 1.0], std::f32::consts::FRAC_PI_2, [0.5, 0.5]);
        for (uv, expected) in [
            ((0.0, 0.0), (0.0, 1.0)),
            ((1.0, 0.0), (0.0, 0.5)),
            ((0.0, 1.0), (0.5, 1.0)),
            ((1.0, 1.0), (0.5, 0.5)),
        ] {
            let got = t.transformed(Vec2::new(uv.0, uv.1));
            assert!(
                (got - Vec2::new(expected.0, expected.1)).length() < 1e-6,
                "{uv:?} -> {got}"
            );
        }
        // "inverts the T axis": offset [0, 1], scale [1, -1].
        let flip = checker().with_uv_transform([0.0, 1.0], 0.0, [1.0, -1.0]);
        assert_eq!(flip.lookup(Vec2::new(0.25, 0.25)), Rgb::new(0.0, 0.0, 1.0));
    }

    #[test]
    fn wrap_modes_and_nearest() {
        let t = checker().with_sampler([Wrap::Clamp, Wrap::Mirror], true);
        // Clamped in u: far right is the right column; mirrored in v: v in
        // (1, 1.5) reflects to the bottom row, (1.5, 2) to the top.
        assert_eq!(t.lookup(Vec2::new(7.0, 0.2)), Rgb::new(0.0, 1.0, 0.0));
        assert_eq!(t.lookup(Vec2::new(-3.0, 1.2)), Rgb::new(0.0, 0.0, 1.0));
        assert_eq!(t.lookup(Vec2::new(0.2, 1.7)), Rgb::new(1.0, 0.0, 0.0));
        // Nearest: no blend halfway between red and green.
        assert_eq!(t.lookup(Vec2::new(0.49, 0.25)), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(t.lookup(Vec2::new(0.51, 0.25)), Rgb::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn texel_centres_and_wrapping() {
        let t = checker();
        assert_eq!(t.lookup(Vec2::new(0.25, 0.25)), Rgb::new(1.0, 0.0, 0.0));
        assert_eq!(t.lookup(Vec2::new(0.75, 0.25)), Rgb::new(0.0, 1.0, 0.0));
        assert_eq!(t.lookup(Vec2::new(0.25, 0.75)), Rgb::new(0.0, 0.0, 1.0));
        assert_eq!(t.lookup(Vec2::new(1.75, -0.25)), Rgb::new(1.0, 1.0, 1.0));
        // Halfway between red and green.
        let mid = t.lookup(Vec2::new(0.5, 0.25));
        assert!(
            (mid.r - 0.5).abs() < 1e-6 && (mid.g - 0.5).abs() < 1e-6,
            "{mid:?}"
        );
    }
}
