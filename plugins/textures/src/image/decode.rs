//! Image files to texels: PNG (8 or 16 bits, grey or colour, alpha
//! dropped), baseline or progressive JPEG, and the RGB channels of an EXR.
//! The format is told by the file's first bytes, not its name.

use std::path::Path;

use lumis_core::files::{read_bounded, IMAGE_FILE};
use lumis_core::Rgb;

/// An image as stored: its texel values before any decoding of their
/// encoding, in `[0, 1]` for integer formats.
pub struct Stored {
    pub width: usize,
    pub height: usize,
    pub values: Vec<Rgb>,
    /// Whether the file stores floating-point values (EXR), which are linear.
    pub is_float: bool,
}

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
const JPEG_MAGIC: &[u8] = &[0xff, 0xd8, 0xff];
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Reads `path`; the message says what failed, not which file (the caller
/// names it).
pub fn read(path: &Path) -> Result<Stored, String> {
    let bytes = read_bounded(path, IMAGE_FILE).map_err(|e| format!("cannot read the file: {e}"))?;
    if bytes.starts_with(EXR_MAGIC) {
        return exr(path);
    }
    decode(&bytes)
}

/// Decodes PNG or JPEG bytes (an image embedded in an asset).
pub fn decode(bytes: &[u8]) -> Result<Stored, String> {
    let stored = if bytes.starts_with(PNG_MAGIC) {
        png(bytes)?
    } else if bytes.starts_with(JPEG_MAGIC) {
        jpeg(bytes)?
    } else {
        return Err("not a PNG, JPEG or EXR image".into());
    };
    if stored.width == 0 || stored.height == 0 {
        return Err("the image has no pixels".into());
    }
    Ok(stored)
}

fn png(bytes: &[u8]) -> Result<Stored, String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
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
        png::ColorType::Indexed => return Err("bad PNG: palette not expanded".into()),
    };
    let wide = info.bit_depth == png::BitDepth::Sixteen;
    let bytes_per_sample = if wide { 2 } else { 1 };
    let sample = |s: &[u8]| -> f32 {
        if wide {
            u16::from_be_bytes([s[0], s[1]]) as f32 / 65535.0
        } else {
            s[0] as f32 / 255.0
        }
    };
    let mut values = Vec::with_capacity(width * height);
    for row in buf.chunks_exact(info.line_size).take(height) {
        for px in row.chunks_exact(channels * bytes_per_sample).take(width) {
            let c = |i: usize| sample(&px[i * bytes_per_sample..]);
            values.push(if channels < 3 {
                Rgb::splat(c(0))
            } else {
                Rgb::new(c(0), c(1), c(2))
            });
        }
    }
    if values.len() != width * height {
        return Err(format!(
            "bad PNG: {width}x{height} pixels could not be read"
        ));
    }
    Ok(Stored {
        width,
        height,
        values,
        is_float: false,
    })
}

fn jpeg(bytes: &[u8]) -> Result<Stored, String> {
    let mut decoder = jpeg_decoder::Decoder::new(std::io::Cursor::new(bytes));
    let pixels = decoder.decode().map_err(|e| format!("bad JPEG: {e}"))?;
    let info = decoder.info().ok_or("bad JPEG: no frame")?;
    let (width, height) = (info.width as usize, info.height as usize);
    let byte = |v: u8| v as f32 / 255.0;
    let values: Vec<Rgb> = match info.pixel_format {
        jpeg_decoder::PixelFormat::L8 => pixels.iter().map(|&l| Rgb::splat(byte(l))).collect(),
        jpeg_decoder::PixelFormat::L16 => pixels
            .chunks_exact(2)
            .map(|l| Rgb::splat(u16::from_be_bytes([l[0], l[1]]) as f32 / 65535.0))
            .collect(),
        jpeg_decoder::PixelFormat::RGB24 => pixels
            .chunks_exact(3)
            .map(|p| Rgb::new(byte(p[0]), byte(p[1]), byte(p[2])))
            .collect(),
        jpeg_decoder::PixelFormat::CMYK32 => return Err("CMYK JPEGs are not supported".into()),
    };
    if values.len() != width * height {
        return Err(format!(
            "bad JPEG: {width}x{height} pixels could not be read"
        ));
    }
    Ok(Stored {
        width,
        height,
        values,
        is_float: false,
    })
}

fn exr(path: &Path) -> Result<Stored, String> {
    let image = lumis_image::read_exr(path).map_err(|e| e.to_string())?;
    if image.width == 0 || image.height == 0 {
        return Err("the image has no pixels".into());
    }
    if let Some(bad) = image
        .pixels
        .iter()
        .find(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(format!(
            "the EXR holds a value that is not finite ({bad:?}); a texture must be finite everywhere"
        ));
    }
    Ok(Stored {
        width: image.width,
        height: image.height,
        values: image.pixels.into_iter().map(Rgb::from).collect(),
        is_float: true,
    })
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): an encoded value
/// in `[0, 1]` to linear.
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_decodes_known_values() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert_eq!(srgb_to_linear(1.0), 1.0);
        // 0.04045 is where the linear segment meets the power curve.
        assert!((srgb_to_linear(0.04045) - 0.04045 / 12.92).abs() < 1e-9);
        // 8-bit 128 is 21.586% linear; 8-bit 188 is 50.0%.
        assert!((srgb_to_linear(128.0 / 255.0) - 0.215_861).abs() < 1e-5);
        assert!((srgb_to_linear(188.0 / 255.0) - 0.502_886).abs() < 1e-5);
    }

    #[test]
    fn unknown_bytes_are_refused() {
        let err = decode(b"GIF89a....").err().unwrap();
        assert!(err.contains("not a PNG, JPEG or EXR"), "{err}");
        let err = decode(PNG_MAGIC).err().unwrap();
        assert!(err.contains("bad PNG"), "{err}");
    }
}
