//! OpenEXR files: linear float32 RGB.

use std::path::Path;

use exr::prelude::{ReadChannels, ReadLayers, SpecificChannels, WritableImage};

use exr::meta::attribute::{AttributeValue, Text};

use crate::atomic::{flush, stage, StagedFile};
use crate::{Image, ImageError};

/// Text attributes of an EXR header, `(name, value)`: what an image was
/// made from, kept in the file itself so image and description cannot
/// disagree.
pub type ExrMetadata = Vec<(String, String)>;

/// Writes `image` as a float32 RGB EXR, atomically.
pub fn write_exr(path: &Path, image: &Image) -> Result<(), ImageError> {
    stage_exr(path, image, &[])?.commit()
}

/// Writes `image` as a float32 RGB EXR with `metadata` as text attributes
/// of its header, atomically.
pub fn write_exr_with_metadata(
    path: &Path,
    image: &Image,
    metadata: &[(String, String)],
) -> Result<(), ImageError> {
    stage_exr(path, image, metadata)?.commit()
}

/// Writes the EXR of [`write_exr_with_metadata`] under a temporary name,
/// to be renamed into place with [`StagedFile::commit`].
pub fn stage_exr(
    path: &Path,
    image: &Image,
    metadata: &[(String, String)],
) -> Result<StagedFile, ImageError> {
    let format_err = |message: String| ImageError::Format {
        path: path.to_path_buf(),
        message,
    };
    let channels = SpecificChannels::rgb(|pos: exr::math::Vec2<usize>| {
        let [r, g, b] = image.get(pos.x(), pos.y());
        (r, g, b)
    });
    let mut exr_image = exr::image::Image::from_channels((image.width, image.height), channels);
    for (name, value) in metadata {
        let text = |s: &str| {
            Text::new_or_none(s).ok_or_else(|| {
                format_err(format!(
                    "EXR attribute '{name}' = '{value}' is not text an EXR header can hold"
                ))
            })
        };
        exr_image
            .layer_data
            .attributes
            .other
            .insert(text(name)?, AttributeValue::Text(text(value)?));
    }
    stage(path, |w| {
        exr_image
            .write()
            .to_buffered(&mut *w)
            .map_err(|e| e.to_string())?;
        flush(w)
    })
}

/// The text attributes of an EXR file's header (not its pixels).
pub fn read_exr_metadata(path: &Path) -> Result<ExrMetadata, ImageError> {
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| match e {
        exr::error::Error::Io(source) => ImageError::Io {
            path: path.to_path_buf(),
            source,
        },
        e => ImageError::Format {
            path: path.to_path_buf(),
            message: format!("not a readable EXR: {e}"),
        },
    })?;
    let mut out = ExrMetadata::new();
    for header in &meta.headers {
        let attributes = header
            .own_attributes
            .other
            .iter()
            .chain(&header.shared_attributes.other);
        for (name, value) in attributes {
            if let AttributeValue::Text(text) = value {
                out.push((name.to_string(), text.to_string()));
            }
        }
    }
    out.sort();
    Ok(out)
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
    fn metadata_round_trips_in_the_header() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("meta.exr");
        let image = Image::new(2, 2);
        let metadata = vec![
            ("lumis.seed".to_string(), "18446744073709551615".to_string()),
            ("lumis.spp".to_string(), "64".to_string()),
        ];
        write_exr_with_metadata(&path, &image, &metadata).unwrap();
        assert_eq!(read_exr_metadata(&path).unwrap(), metadata);
        assert_eq!(read_exr(&path).unwrap(), image);
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
