//! PNG files: 8-bit sRGB, for looking at renders.

use std::path::Path;

use crate::atomic::{flush, stage, StagedFile};
use crate::{Image, ImageError};

/// Clamps linear `v` to [0, 1] and applies the sRGB transfer function
/// (IEC 61966-2-1), rounding to 8 bits. NaN maps to 0.
#[inline]
pub fn linear_to_srgb8(v: f32) -> u8 {
    let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    let s = if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0 + 0.5) as u8
}

/// Writes `image` tone-mapped (clamped, sRGB-encoded) to an 8-bit PNG, atomically.
pub fn write_png(path: &Path, image: &Image) -> Result<(), ImageError> {
    stage_png(path, image)?.commit()
}

/// Writes the PNG of [`write_png`] under a temporary name, to be renamed
/// into place with [`StagedFile::commit`].
pub fn stage_png(path: &Path, image: &Image) -> Result<StagedFile, ImageError> {
    stage_rgb8_png(path, image.width, image.height, &srgb8(image))
}

/// The bytes of the PNG [`write_png`] writes: an image shown where no file
/// is wanted (a notebook's cell).
pub fn encode_png(image: &Image) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    encode_rgb8_png(&mut bytes, image.width, image.height, &srgb8(image))?;
    Ok(bytes)
}

/// The image tone-mapped to 8-bit sRGB rows.
fn srgb8(image: &Image) -> Vec<u8> {
    image
        .pixels
        .iter()
        .flat_map(|p| p.map(linear_to_srgb8))
        .collect()
}

/// Writes 8-bit sRGB RGB rows (e.g. a drawn plot) to a PNG, atomically.
pub fn write_rgb8_png(
    path: &Path,
    width: usize,
    height: usize,
    data: &[u8],
) -> Result<(), ImageError> {
    stage_rgb8_png(path, width, height, data)?.commit()
}

fn stage_rgb8_png(
    path: &Path,
    width: usize,
    height: usize,
    data: &[u8],
) -> Result<StagedFile, ImageError> {
    stage(path, |w| {
        encode_rgb8_png(&mut *w, width, height, data)?;
        flush(w)
    })
}

/// Encodes 8-bit sRGB RGB rows as a PNG into `w`.
fn encode_rgb8_png(
    w: impl std::io::Write,
    width: usize,
    height: usize,
    data: &[u8],
) -> Result<(), String> {
    let mut encoder = png::Encoder::new(w, width as u32, height as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
    writer.write_image_data(data).map_err(|e| e.to_string())?;
    writer.finish().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints_and_midpoint() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(7.0), 255);
        assert_eq!(linear_to_srgb8(f32::NAN), 0);
        // 18% grey encodes to ~118 in sRGB.
        assert_eq!(linear_to_srgb8(0.18), 118);
    }

    #[test]
    fn writes_a_decodable_png() {
        let mut image = Image::new(4, 3);
        image.set(1, 2, [1.0, 0.5, 0.0]);
        let path = std::env::temp_dir().join(format!("lumis-png-{}.png", std::process::id()));
        write_png(&path, &image).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
        let reader = decoder.read_info().unwrap();
        assert_eq!((reader.info().width, reader.info().height), (4, 3));
        std::fs::remove_file(&path).unwrap();
    }
}
