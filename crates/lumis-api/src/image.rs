//! Decoded image data that a host hands to a plugin as a parameter value:
//! an image embedded in an asset (a glTF texture) reaches the `image`
//! texture already decoded, made through the registry like any texture.

use crate::spectrum::Rgb;

/// An image as stored: its texel values before any decoding of their
/// encoding (sRGB or linear), row-major from the top-left texel.
#[derive(Clone, PartialEq)]
pub struct DecodedImage {
    pub width: usize,
    pub height: usize,
    pub values: ImageValues,
}

/// Texel values as the file stores them.
#[derive(Clone, PartialEq)]
pub enum ImageValues {
    /// 8 bits per channel (PNG, JPEG): kept as bytes, a quarter of the
    /// memory of float RGB, and decoded by a table at each lookup.
    Bytes(Vec<[u8; 3]>),
    /// 16-bit integers scaled to `[0, 1]`, or floating point (EXR, linear).
    Floats { values: Vec<Rgb>, is_float: bool },
}

impl DecodedImage {
    /// Whether the file stores floating-point values (EXR), which are linear.
    pub fn is_float(&self) -> bool {
        matches!(self.values, ImageValues::Floats { is_float: true, .. })
    }

    /// The values as floats in `[0, 1]` (or as stored, for floating point).
    pub fn floats(&self) -> Vec<Rgb> {
        match &self.values {
            ImageValues::Bytes(b) => b
                .iter()
                .map(|p| Rgb::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0)
                .collect(),
            ImageValues::Floats { values, .. } => values.clone(),
        }
    }

    /// Bytes its texel values hold.
    pub fn byte_size(&self) -> usize {
        match &self.values {
            ImageValues::Bytes(b) => std::mem::size_of_val(b.as_slice()),
            ImageValues::Floats { values, .. } => std::mem::size_of_val(values.as_slice()),
        }
    }
}

/// The size and kind, not the texels: a parameter table's debug print
/// must not spell out megabytes.
impl std::fmt::Debug for DecodedImage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.values {
            ImageValues::Bytes(_) => "8-bit",
            ImageValues::Floats {
                is_float: false, ..
            } => "16-bit",
            ImageValues::Floats { is_float: true, .. } => "float",
        };
        write!(f, "DecodedImage({}x{} {kind})", self.width, self.height)
    }
}
