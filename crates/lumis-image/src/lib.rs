//! Images: a linear RGB float buffer, EXR and PNG files with metadata in
//! the EXR header, Radiance `.hdr` files read, texture images (PNG, JPEG,
//! EXR) decoded with their memory bounded, writes that never leave a
//! half-written file behind, and a lock that keeps two processes from
//! writing one output.

mod atomic;
mod exr_io;
mod hdr_io;
pub mod limits;
mod output_lock;
mod png_io;
mod process;
pub mod texture_decode;

pub use atomic::{remove_stale_temporaries, stage, write_atomically, StagedFile};
pub use exr_io::{
    read_exr, read_exr_channels, read_exr_metadata, read_exr_uint_channels, stage_exr,
    stage_exr_with_channels, stage_exr_with_layers, write_exr, write_exr_with_metadata, ExrLayer,
    ExrMetadata, ExrUintChannel, ExrUintChannels,
};
pub use hdr_io::{is_hdr, read_hdr};
pub use output_lock::{lock_path, OutputLock};
pub use png_io::{encode_png, linear_to_srgb8, stage_png, write_png, write_rgb8_png};
pub use process::{process_is_running, process_start};

use std::path::PathBuf;

/// A linear RGB image, row-major from the top-left pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            pixels: vec![[0.0; 3]; width * height],
        }
    }

    /// A black image, or an error saying how much memory it needed where
    /// that cannot be allocated (instead of the process aborting).
    pub fn try_new(width: usize, height: usize) -> Result<Self, String> {
        let too_large = || {
            let bytes = width as f64 * height as f64 * std::mem::size_of::<[f32; 3]>() as f64;
            format!(
                "a {width}x{height} image needs {:.1} GB of memory, which cannot be allocated",
                bytes * 1e-9
            )
        };
        let count = width.checked_mul(height).ok_or_else(too_large)?;
        let mut pixels = Vec::new();
        pixels.try_reserve_exact(count).map_err(|_| too_large())?;
        pixels.resize(count, [0.0; 3]);
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    #[inline]
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        self.pixels[y * self.width + x]
    }

    #[inline]
    pub fn set(&mut self, x: usize, y: usize, v: [f32; 3]) {
        self.pixels[y * self.width + x] = v;
    }

    /// Mean of each channel over all pixels.
    pub fn mean(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                sum[c] += p[c] as f64;
            }
        }
        sum.map(|s| s / self.pixels.len().max(1) as f64)
    }
}

/// An image file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Format { path: PathBuf, message: String },
    /// A file lumis does not read: not a regular file, past its kind's
    /// size bound, or an image claiming more pixels than lumis decodes
    /// ([`limits`]).
    #[error("{path}: {message}")]
    Refused { path: PathBuf, message: String },
}

/// Opens the image file `path` for reading: a missing file is the
/// system's error, a file lumis does not read (`lumis_files`) is
/// [`ImageError::Refused`].
pub(crate) fn open_image(path: &std::path::Path) -> Result<(std::fs::File, u64), ImageError> {
    if let Err(source) = std::fs::metadata(path) {
        return Err(ImageError::Io {
            path: path.to_path_buf(),
            source,
        });
    }
    lumis_files::open_bounded(path, lumis_files::IMAGE_FILE).map_err(|message| {
        ImageError::Refused {
            path: path.to_path_buf(),
            message,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn try_new_refuses_what_cannot_be_allocated() {
        let image = Image::try_new(3, 2).unwrap();
        assert_eq!(image, Image::new(3, 2));
        // The pixel count overflows; then the byte count exceeds isize::MAX.
        for (w, h) in [(usize::MAX / 2, 3), (1 << 32, 1 << 30)] {
            let err = Image::try_new(w, h).unwrap_err();
            assert!(err.contains("GB of memory"), "{err}");
        }
    }
}
