//! Images: a linear RGB float buffer, EXR and PNG files, and writes that
//! never leave a half-written file behind.

mod atomic;
mod exr_io;
mod png_io;

pub use atomic::write_atomically;
pub use exr_io::{read_exr, write_exr};
pub use png_io::{linear_to_srgb8, write_png, write_rgb8_png};

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
}
