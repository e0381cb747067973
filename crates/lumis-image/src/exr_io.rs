//! OpenEXR files: linear float32 RGB, with optional named layers beside
//! the colour (`albedo.R`, `depth.Z`).

use std::fs::File;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::Path;

use exr::image::{AnyChannel, AnyChannels, FlatSamples};
use exr::meta::attribute::{AttributeValue, Text};
use exr::meta::MetaData;
use exr::prelude::{ReadChannels, ReadLayers, WritableImage};

use crate::atomic::{flush, stage, StagedFile};
use crate::{limits, open_image, Image, ImageError};

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

/// A named layer written beside an EXR's colour: channel `name.C` for the
/// `i`-th entry `C` of `channels` holds component `i` of `image`'s pixels
/// (the naming of multi-layer EXRs that compositors and denoisers read).
#[derive(Debug, Clone, Copy)]
pub struct ExrLayer<'a> {
    pub name: &'a str,
    pub channels: &'a [&'a str],
    pub image: &'a Image,
}

/// Writes the EXR of [`write_exr_with_metadata`] under a temporary name,
/// to be renamed into place with [`StagedFile::commit`].
pub fn stage_exr(
    path: &Path,
    image: &Image,
    metadata: &[(String, String)],
) -> Result<StagedFile, ImageError> {
    stage_exr_with_layers(path, image, &[], metadata)
}

/// A channel of whole numbers written beside an EXR's colour, one per
/// pixel, row-major: exact where a float channel would round (the bits of
/// a double-precision sum, held in two such channels).
#[derive(Debug, Clone, Copy)]
pub struct ExrUintChannel<'a> {
    pub name: &'a str,
    pub values: &'a [u32],
}

/// [`stage_exr`] with `layers` beside the colour, each the size of
/// `image`.
pub fn stage_exr_with_layers(
    path: &Path,
    image: &Image,
    layers: &[ExrLayer],
    metadata: &[(String, String)],
) -> Result<StagedFile, ImageError> {
    stage_exr_with_channels(path, image, layers, &[], metadata)
}

/// [`stage_exr_with_layers`] with whole-number channels too, each with a
/// value per pixel of `image`.
pub fn stage_exr_with_channels(
    path: &Path,
    image: &Image,
    layers: &[ExrLayer],
    uints: &[ExrUintChannel],
    metadata: &[(String, String)],
) -> Result<StagedFile, ImageError> {
    let format_err = |message: String| ImageError::Format {
        path: path.to_path_buf(),
        message,
    };
    let component = |image: &Image, c: usize| -> FlatSamples {
        FlatSamples::F32(image.pixels.iter().map(|p| p[c]).collect())
    };
    let mut channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(c, name)| AnyChannel::new(*name, component(image, c)))
        .collect();
    for layer in layers {
        if (layer.image.width, layer.image.height) != (image.width, image.height)
            || layer.channels.len() > 3
        {
            return Err(format_err(format!(
                "layer '{}' is {}x{} with {} channels, not {}x{} with at most 3",
                layer.name,
                layer.image.width,
                layer.image.height,
                layer.channels.len(),
                image.width,
                image.height
            )));
        }
        for (c, channel) in layer.channels.iter().enumerate() {
            let name = format!("{}.{channel}", layer.name);
            let text = Text::new_or_none(&name)
                .ok_or_else(|| format_err(format!("'{name}' is not an EXR channel name")))?;
            channels.push(AnyChannel::new(text, component(layer.image, c)));
        }
    }
    for channel in uints {
        if channel.values.len() != image.width * image.height {
            return Err(format_err(format!(
                "channel '{}' has {} values, not one per pixel of a {}x{} image",
                channel.name,
                channel.values.len(),
                image.width,
                image.height
            )));
        }
        let text = Text::new_or_none(channel.name)
            .ok_or_else(|| format_err(format!("'{}' is not an EXR channel name", channel.name)))?;
        channels.push(AnyChannel::new(
            text,
            FlatSamples::U32(channel.values.to_vec()),
        ));
    }
    let channels = AnyChannels::sort(channels.into());
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

/// `e`, from reading the EXR file `path`, as an [`ImageError`].
fn unreadable_exr(path: &Path, e: exr::error::Error) -> ImageError {
    match e {
        exr::error::Error::Io(source) => ImageError::Io {
            path: path.to_path_buf(),
            source,
        },
        e => ImageError::Format {
            path: path.to_path_buf(),
            message: format!("not a readable EXR: {e}"),
        },
    }
}

/// The EXR file `path`, opened where it is a regular file within an
/// image's size bound, with its header.
fn open_exr(path: &Path) -> Result<(BufReader<File>, MetaData), ImageError> {
    let (file, _) = open_image(path)?;
    let mut reader = BufReader::new(file);
    let meta =
        MetaData::read_from_buffered(&mut reader, false).map_err(|e| unreadable_exr(path, e))?;
    reader
        .seek(SeekFrom::Start(0))
        .map_err(|source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    Ok((reader, meta))
}

/// [`open_exr`], for reading the pixels: refused where the header claims
/// more than lumis decodes ([`crate::limits`]), before any is allocated.
fn open_exr_pixels(path: &Path) -> Result<BufReader<File>, ImageError> {
    let (reader, meta) = open_exr(path)?;
    let refused = |message: String| ImageError::Refused {
        path: path.to_path_buf(),
        message,
    };
    let sizes: Vec<(u64, u64)> = meta
        .headers
        .iter()
        .map(|h| (h.layer_size.width() as u64, h.layer_size.height() as u64))
        .collect();
    for &(width, height) in &sizes {
        limits::check_claimed_size("EXR", width, height).map_err(refused)?;
    }
    let pixels = sizes
        .iter()
        .map(|&(w, h)| w * h)
        .fold(0u64, u64::saturating_add);
    limits::check_claimed_pixels(
        &format!("its EXR header claims {} layers", sizes.len()),
        pixels,
    )
    .map_err(refused)?;
    Ok(reader)
}

/// The text attributes of an EXR file's header (not its pixels).
pub fn read_exr_metadata(path: &Path) -> Result<ExrMetadata, ImageError> {
    let (_, meta) = open_exr(path)?;
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

/// Every channel of an EXR file's layers, by full name (`R`,
/// `albedo.G`), row-major, converted to `f32`.
pub fn read_exr_channels(path: &Path) -> Result<Vec<(String, Vec<f32>)>, ImageError> {
    let image = read_flat_layers(path)?;
    let mut out = Vec::new();
    for layer in &image.layer_data {
        let prefix = layer
            .attributes
            .layer_name
            .as_ref()
            .map(|n| format!("{n}."))
            .unwrap_or_default();
        for channel in &layer.channel_data.list {
            let values = channel.sample_data.values_as_f32().collect();
            out.push((format!("{prefix}{}", channel.name), values));
        }
    }
    Ok(out)
}

/// An EXR file's resolution `(width, height)` and its whole-number
/// channels, by full name, exactly as written ([`ExrUintChannel`]); float
/// channels are left out.
pub type ExrUintChannels = ((usize, usize), Vec<(String, Vec<u32>)>);

/// Reads the [`ExrUintChannels`] of an EXR file.
pub fn read_exr_uint_channels(path: &Path) -> Result<ExrUintChannels, ImageError> {
    let image = read_flat_layers(path)?;
    let size = image.attributes.display_window.size;
    let mut out = Vec::new();
    for layer in &image.layer_data {
        for channel in &layer.channel_data.list {
            if let FlatSamples::U32(values) = &channel.sample_data {
                out.push((channel.name.to_string(), values.clone()));
            }
        }
    }
    Ok(((size.width(), size.height()), out))
}

/// Every layer and channel of an EXR file, at its largest resolution.
fn read_flat_layers(path: &Path) -> Result<exr::image::FlatImage, ImageError> {
    exr::image::read::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(open_exr_pixels(path)?)
        .map_err(|e| unreadable_exr(path, e))
}

/// Reads the RGB channels of the first layer of an EXR file.
pub fn read_exr(path: &Path) -> Result<Image, ImageError> {
    let reader = open_exr_pixels(path)?;
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
        .from_buffered(reader);
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
    fn layers_are_written_beside_the_colour() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("layers.exr");
        let mut colour = Image::new(2, 1);
        colour.set(1, 0, [1.0, 2.0, 3.0]);
        let mut normal = Image::new(2, 1);
        normal.set(0, 0, [0.0, -1.0, 0.5]);
        let depth = Image {
            width: 2,
            height: 1,
            pixels: vec![[4.0; 3], [0.0; 3]],
        };
        let layers = [
            ExrLayer {
                name: "normal",
                channels: &["X", "Y", "Z"],
                image: &normal,
            },
            ExrLayer {
                name: "depth",
                channels: &["Z"],
                image: &depth,
            },
        ];
        stage_exr_with_layers(&path, &colour, &layers, &[])
            .unwrap()
            .commit()
            .unwrap();
        assert_eq!(read_exr(&path).unwrap(), colour);
        let mut channels = read_exr_channels(&path).unwrap();
        channels.sort_by(|a, b| a.0.cmp(&b.0));
        let expected: Vec<(String, Vec<f32>)> = [
            ("B", vec![0.0, 3.0]),
            ("G", vec![0.0, 2.0]),
            ("R", vec![0.0, 1.0]),
            ("depth.Z", vec![4.0, 0.0]),
            ("normal.X", vec![0.0, 0.0]),
            ("normal.Y", vec![-1.0, 0.0]),
            ("normal.Z", vec![0.5, 0.0]),
        ]
        .into_iter()
        .map(|(n, v)| (n.to_string(), v))
        .collect();
        assert_eq!(channels, expected);
        let wrong = Image::new(1, 1);
        let err = stage_exr_with_layers(
            &path,
            &colour,
            &[ExrLayer {
                name: "spp",
                channels: &["Y"],
                image: &wrong,
            }],
            &[],
        )
        .err()
        .unwrap();
        assert!(err.to_string().contains("layer 'spp'"), "{err}");
    }

    #[test]
    fn whole_number_channels_round_trip_exactly() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("uint.exr");
        let colour = Image::new(2, 1);
        let values = [u32::MAX, 0x7ff8_0001];
        let channels = [ExrUintChannel {
            name: "bits.hi",
            values: &values,
        }];
        stage_exr_with_channels(&path, &colour, &[], &channels, &[])
            .unwrap()
            .commit()
            .unwrap();
        assert_eq!(
            read_exr_uint_channels(&path).unwrap(),
            ((2, 1), vec![("bits.hi".to_string(), values.to_vec())])
        );
        assert_eq!(read_exr(&path).unwrap(), colour);
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
