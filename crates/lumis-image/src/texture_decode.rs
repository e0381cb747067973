//! Image files to texels: PNG (8 or 16 bits, grey or colour, alpha
//! dropped), baseline or progressive JPEG, and the RGB channels of an EXR.
//! The format is told by the file's first bytes, not its name.

use std::path::Path;

use crate::limits::{check_claimed_size, check_expansion, DEFLATE_MAX_RATIO};
use lumis_api::{DecodedImage, ImageValues, Rgb};
use lumis_files::{read_bounded, read_prefix, IMAGE_FILE};

const PNG_MAGIC: &[u8] = b"\x89PNG\r\n\x1a\n";
const JPEG_MAGIC: &[u8] = &[0xff, 0xd8, 0xff];
const EXR_MAGIC: &[u8] = &[0x76, 0x2f, 0x31, 0x01];

/// Reads `path`; the message says what failed, not which file (the caller
/// names it).
pub fn read(path: &Path) -> Result<DecodedImage, String> {
    let cannot = |e: String| format!("cannot read the file: {e}");
    // An EXR is read by its own reader, header first: its bytes are not
    // read here (they would be held twice while it decodes).
    let magic = read_prefix(path, EXR_MAGIC.len() as u64, IMAGE_FILE).map_err(cannot)?;
    if magic == EXR_MAGIC {
        return exr(path);
    }
    decode(&read_bounded(path, IMAGE_FILE).map_err(cannot)?)
}

/// Decodes PNG or JPEG bytes (an image embedded in an asset).
pub fn decode(bytes: &[u8]) -> Result<DecodedImage, String> {
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

fn png(bytes: &[u8]) -> Result<DecodedImage, String> {
    let mut decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::EXPAND);
    let mut reader = decoder.read_info().map_err(|e| format!("bad PNG: {e}"))?;
    // The header's claim, checked before the pixels are allocated: the
    // pixel count, and the bytes they take against what deflate can
    // expand the file to.
    let info = reader.info();
    let (width, height) = (u64::from(info.width), u64::from(info.height));
    check_claimed_size("PNG", width, height)?;
    let bits_per_pixel = info.color_type.samples() as u64 * info.bit_depth as u64;
    let packed = width.saturating_mul(height).saturating_mul(bits_per_pixel) / 8;
    check_expansion("PNG", packed, bytes.len() as u64, DEFLATE_MAX_RATIO)?;
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
    let pixels = buf
        .chunks_exact(info.line_size)
        .take(height)
        .flat_map(|row| row.chunks_exact(channels * bytes_per_sample).take(width));
    // Grey expands to three equal channels; alpha is dropped.
    let rgb = |c: &dyn Fn(usize) -> u16| {
        if channels < 3 {
            [c(0); 3]
        } else {
            [c(0), c(1), c(2)]
        }
    };
    let values = if wide {
        let values: Vec<Rgb> = pixels
            .map(|px| rgb(&|i| u16::from_be_bytes([px[2 * i], px[2 * i + 1]])))
            .map(|c| Rgb::new(c[0] as f32, c[1] as f32, c[2] as f32) / 65535.0)
            .collect();
        (
            values.len(),
            ImageValues::Floats {
                values,
                is_float: false,
            },
        )
    } else {
        let values: Vec<[u8; 3]> = pixels
            .map(|px| rgb(&|i| px[i] as u16).map(|c| c as u8))
            .collect();
        (values.len(), ImageValues::Bytes(values))
    };
    if values.0 != width * height {
        return Err(format!(
            "bad PNG: {width}x{height} pixels could not be read"
        ));
    }
    Ok(DecodedImage {
        width,
        height,
        values: values.1,
    })
}

fn jpeg(bytes: &[u8]) -> Result<DecodedImage, String> {
    let mut decoder = jpeg_decoder::Decoder::new(std::io::Cursor::new(bytes));
    decoder.read_info().map_err(|e| format!("bad JPEG: {e}"))?;
    let claimed = decoder.info().ok_or("bad JPEG: no frame")?;
    check_claimed_size("JPEG", claimed.width.into(), claimed.height.into())?;
    let pixels = decoder.decode().map_err(|e| format!("bad JPEG: {e}"))?;
    let info = decoder.info().ok_or("bad JPEG: no frame")?;
    let (width, height) = (info.width as usize, info.height as usize);
    let (count, values) = match info.pixel_format {
        jpeg_decoder::PixelFormat::L8 => {
            let v: Vec<[u8; 3]> = pixels.iter().map(|&l| [l; 3]).collect();
            (v.len(), ImageValues::Bytes(v))
        }
        jpeg_decoder::PixelFormat::L16 => {
            let v: Vec<Rgb> = pixels
                .chunks_exact(2)
                .map(|l| Rgb::splat(u16::from_be_bytes([l[0], l[1]]) as f32 / 65535.0))
                .collect();
            (
                v.len(),
                ImageValues::Floats {
                    values: v,
                    is_float: false,
                },
            )
        }
        jpeg_decoder::PixelFormat::RGB24 => {
            let v: Vec<[u8; 3]> = pixels.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
            (v.len(), ImageValues::Bytes(v))
        }
        jpeg_decoder::PixelFormat::CMYK32 => return Err("CMYK JPEGs are not supported".into()),
    };
    if count != width * height {
        return Err(format!(
            "bad JPEG: {width}x{height} pixels could not be read"
        ));
    }
    Ok(DecodedImage {
        width,
        height,
        values,
    })
}

fn exr(path: &Path) -> Result<DecodedImage, String> {
    let image = crate::read_exr(path).map_err(|e| e.to_string())?;
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
    Ok(DecodedImage {
        width: image.width,
        height: image.height,
        values: ImageValues::Floats {
            values: image.pixels.into_iter().map(Rgb::from).collect(),
            is_float: true,
        },
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
