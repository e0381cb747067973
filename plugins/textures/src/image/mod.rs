//! `image`: a texture read from a PNG, JPEG or EXR file, wrapped and
//! filtered.
//!
//! A glTF asset's textures are made by this plugin too, through the
//! registry like a scene's: the importer decodes each image (the
//! metallic-roughness texture's green channel already turned into the GGX
//! alpha) and passes the texels as `texels`, with the asset sampler's wrap
//! modes (`wrap`, `wrap_v`), its filter and the `KHR_texture_transform`.
//! 8-bit images keep their bytes (3 a texel) and decode sRGB through a
//! table at each lookup; `trilinear` and `ewa` build a mip map, the others
//! read the image alone.

mod mipmap;
mod texels;

use std::path::PathBuf;
use std::sync::Arc;

use lumis_api::{
    DecodedImage, ImageValues, ParamChoice, Params, PluginKind, PluginParams, PluginSpec, Result,
    Rgb, Texture, TextureQuery, UvTransform,
};
use lumis_image::texture_decode::{self, srgb_to_linear};

pub use texels::{Texels, Wrap};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Texture,
    name: "image",
    source: lumis_api::source_file!(),
    doc: "an image file (PNG, JPEG or EXR); uv (0, 0) is its top-left corner",
    params: ImageParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct ImageParams {
    /// the image file (PNG, JPEG or EXR), relative to the scene file;
    /// required unless the host gives `texels`
    pub filename: Option<PathBuf>,
    /// decoded texels in place of a file: what a glTF asset's embedded or
    /// referenced image becomes (a scene file names a `filename`)
    pub texels: Option<Arc<DecodedImage>>,
    /// how the stored values encode linear ones: "auto" (sRGB for PNG and
    /// JPEG, linear for EXR), "srgb" or "linear"
    #[param(default = Auto)]
    pub encoding: Encoding,
    /// lookups outside [0, 1]: "repeat", "mirror" or "clamp"
    #[param(default = Repeat)]
    pub wrap: Wrap,
    /// lookups outside [0, 1] in v, where they differ from u (glTF's
    /// `wrapT`); absent, `wrap` applies to both
    pub wrap_v: Option<Wrap>,
    /// filtering: "nearest", "bilinear", or over the hit's footprint
    /// through a mip map, "trilinear" or "ewa" (bilinear where a hit has
    /// no footprint)
    #[param(default = Bilinear)]
    pub filter: ImageFilter,
    /// multiplies every texel after decoding (pbrt-v4's scale; a glTF
    /// material's colour factor)
    #[param(default = 1.0)]
    pub scale: Rgb,
    #[param(flatten)]
    pub transform: UvTransform,
}

/// How stored texel values encode linear RGB.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Encoding {
    /// sRGB for integer formats (PNG, JPEG), linear for floating point.
    Auto,
    /// The sRGB transfer function (IEC 61966-2-1).
    Srgb,
    /// The values are linear.
    Linear,
}

/// How a lookup is filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum ImageFilter {
    /// The texel that covers the point.
    Nearest,
    /// The four texel centres around the point.
    Bilinear,
    /// Two mip-map levels chosen by the footprint's larger extent, each
    /// bilinear, blended.
    Trilinear,
    /// An elliptical Gaussian over the footprint on the mip-map level of
    /// its minor axis.
    Ewa,
}

/// An image texture.
#[derive(Debug, Clone)]
pub struct ImageTexture {
    /// The image, then its mip-map levels for the filters that use them.
    levels: Vec<Texels>,
    /// In u and in v.
    wrap: [Wrap; 2],
    filter: ImageFilter,
    transform: UvTransform,
    /// Multiplies every lookup (the `scale` parameter, a glTF factor).
    scale: Rgb,
}

impl ImageTexture {
    pub fn from_params(params: &Params) -> Result<Self> {
        let p = ImageParams::read(params)?;
        let keys = ImageParams::KEYS;
        let image = match (p.filename, p.texels) {
            (Some(path), None) => texture_decode::read(&path)
                .map_err(|e| params.error(keys.filename, format!("{}: {e}", path.display())))?,
            (None, Some(texels)) => Arc::unwrap_or_clone(texels),
            (Some(_), Some(_)) => {
                return Err(params.error(keys.texels, "give a filename or texels, not both"))
            }
            (None, None) => {
                return Err(params.error(keys.filename, "required: the image file to read"))
            }
        };
        let wrap = [p.wrap, p.wrap_v.unwrap_or(p.wrap)];
        Ok(Self::new(
            image,
            p.encoding,
            wrap,
            p.filter,
            p.transform,
            p.scale,
        ))
    }

    /// A texture of decoded image data, wrapped in u and in v by `wrap`.
    fn new(
        stored: DecodedImage,
        encoding: Encoding,
        wrap: [Wrap; 2],
        filter: ImageFilter,
        transform: UvTransform,
        scale: Rgb,
    ) -> Self {
        let srgb = match encoding {
            Encoding::Auto => !stored.is_float(),
            Encoding::Srgb => true,
            Encoding::Linear => false,
        };
        let decode = |v: f32| if srgb { srgb_to_linear(v) } else { v };
        let (width, height) = (stored.width, stored.height);
        let base = match stored.values {
            ImageValues::Bytes(texels) => {
                Texels::bytes(width, height, texels, |b| decode(b as f32 / 255.0))
            }
            ImageValues::Floats { values, .. } => Texels::linear(
                width,
                height,
                values.into_iter().map(|v| v.map(decode)).collect(),
            ),
        };
        let levels = match filter {
            ImageFilter::Trilinear | ImageFilter::Ewa => mipmap::pyramid(base, wrap),
            ImageFilter::Nearest | ImageFilter::Bilinear => vec![base],
        };
        Self {
            levels,
            wrap,
            filter,
            transform,
            scale,
        }
    }

    /// The linear texels.
    pub fn texels(&self) -> &Texels {
        &self.levels[0]
    }

    /// Bytes held by the texels and mip-map levels.
    pub fn byte_size(&self) -> usize {
        self.levels.iter().map(Texels::byte_size).sum()
    }
}

impl Texture for ImageTexture {
    fn uses_footprint(&self) -> bool {
        matches!(self.filter, ImageFilter::Trilinear | ImageFilter::Ewa)
    }

    fn memory_bytes(&self) -> usize {
        self.byte_size()
    }

    #[inline]
    fn eval(&self, query: &TextureQuery) -> Rgb {
        let query = self.transform.apply(query);
        let uv = query.uv;
        let base = &self.levels[0];
        // A non-finite uv (a degenerate parameterization) reads one texel
        // rather than indexing with a NaN.
        if !uv.is_finite() {
            return base.texel(0, 0, self.wrap);
        }
        let value = match self.filter {
            ImageFilter::Nearest => base.nearest(uv, self.wrap),
            ImageFilter::Bilinear => base.bilinear(uv, self.wrap),
            ImageFilter::Trilinear => mipmap::trilinear(&self.levels, &query, uv, self.wrap),
            ImageFilter::Ewa => mipmap::ewa(&self.levels, &query, uv, self.wrap),
        };
        if self.scale == Rgb::WHITE {
            value
        } else {
            value * self.scale
        }
    }
}

#[cfg(test)]
mod tests;
