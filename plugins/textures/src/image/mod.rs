//! `image`: a texture read from a PNG, JPEG or EXR file, wrapped and
//! filtered.

mod decode;
mod mipmap;
mod texels;

use std::path::PathBuf;

use lumis_api::{
    ParamChoice, Params, PluginKind, PluginParams, PluginSpec, Result, Rgb, Texture, TextureQuery,
    UvTransform,
};

pub use decode::{decode, srgb_to_linear, Stored, StoredValues};
pub use texels::{Texels, Wrap};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Texture,
    name: "image",
    file: file!(),
    doc: "an image file (PNG, JPEG or EXR); uv (0, 0) is its top-left corner",
    params: ImageParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct ImageParams {
    /// the image file (PNG, JPEG or EXR), relative to the scene file
    pub filename: PathBuf,
    /// how the stored values encode linear ones: "auto" (sRGB for PNG and
    /// JPEG, linear for EXR), "srgb" or "linear"
    #[param(default = Auto)]
    pub encoding: Encoding,
    /// lookups outside [0, 1]: "repeat", "mirror" or "clamp"
    #[param(default = Repeat)]
    pub wrap: Wrap,
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
        let stored = decode::read(&p.filename)
            .map_err(|e| params.error(keys.filename, format!("{}: {e}", p.filename.display())))?;
        Ok(Self::new(
            stored,
            p.encoding,
            [p.wrap; 2],
            p.filter,
            p.transform,
            p.scale,
        ))
    }

    /// A texture of decoded image data (e.g. an image embedded in an
    /// asset), wrapped in u and in v by `wrap`.
    pub fn new(
        stored: Stored,
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
            StoredValues::Bytes(texels) => {
                Texels::bytes(width, height, texels, |b| decode(b as f32 / 255.0))
            }
            StoredValues::Floats { values, .. } => Texels::linear(
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
