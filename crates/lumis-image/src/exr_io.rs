//! OpenEXR files: linear float32 RGB.

use std::path::Path;

use exr::prelude::{ReadChannels, ReadLayers, SpecificChannels, WritableImage};

use crate::atomic::{flush, write_atomically};
use crate::{Image, ImageError};

/// Writes `image` as a float32 RGB EXR, atomically.
pub fn write_exr(path: &Path, image: &Image) -> Result<(), ImageError> {
    let channels = SpecificChannels::rgb(|pos: exr::math::Vec2<usize>| {
        let [r, g, b] = image.get(pos.x(), pos.y());
        (r, g, b)
    });
    let exr_image = exr::image::Image::from_channels((image.width, image.height), channels);
    write_atomically(path, |w| {
        exr_image
            .write()
            .to_buffered(&mut *w)
            .map_err(|e| e.to_string())?;
        flush(w)
    })
}

/// Reads the RGB channels of the first layer of an EXR file.
pub fn read_exr(path: &Path) -> Result<Image, ImageError> {
    let result = exr::image::read::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |resolution, _| Image::new(resolution.width(), resolution.height()),
            |image: &mut Image, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                image.set(pos.x(), pos.y(), [r, g, b])
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_file(path);
    match result {
        Ok(image) => Ok(image.layer_data.channel_data.pixels),
        Err(exr::error::Error::Io(source)) => Err(ImageError::Io {
            path: path.to_path_buf(),
            source,
        }),
        Err(e) => Err(ImageError::Format {
            path: path.to_path_buf(),
            message: format!("not a readable RGB EXR: {e}"),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact() {
        let mut image = Image::new(3, 2);
        image.set(0, 0, [1.5, -0.0, 1e-7]);
        image.set(2, 1, [1e6, 0.25, 3.0]);
        let path = std::env::temp_dir().join(format!("lumis-exr-{}.exr", std::process::id()));
        write_exr(&path, &image).unwrap();
        let back = read_exr(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back, image);
    }

    #[test]
    fn non_exr_file_is_a_format_error() {
        let path = std::env::temp_dir().join(format!("lumis-not-exr-{}.exr", std::process::id()));
        std::fs::write(&path, b"hello").unwrap();
        let err = read_exr(&path).unwrap_err();
        std::fs::remove_file(&path).unwrap();
        assert!(matches!(err, ImageError::Format { .. }), "{err}");
    }
}
