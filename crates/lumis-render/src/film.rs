//! The film: per-pixel sums of radiance samples in double precision and the
//! number of samples every pixel has taken.
//!
//! The sums, not the means, are the render's state: a render continued from
//! them adds each later sample to the same running sum, in the same order,
//! as an uninterrupted render would, so its image is bit for bit the same.

use lumis_core::{Error, Result, UVec2};
use lumis_image::Image;

#[derive(Debug, Clone, PartialEq)]
pub struct Film {
    pub width: usize,
    pub height: usize,
    /// Row-major from the top-left pixel: the sum of each pixel's finite
    /// samples (a NaN or infinite one counts as a sample of zero).
    pub sums: Vec<[f64; 3]>,
    /// Samples every pixel has taken: indices `0..samples` of the sampler.
    pub samples: u32,
}

impl Film {
    /// An empty film, or an error saying how much memory it needed where
    /// that cannot be allocated.
    pub fn try_new(resolution: UVec2) -> Result<Self> {
        let (width, height) = (resolution.x as usize, resolution.y as usize);
        let too_large = || {
            Error::msg(format!(
                "film resolution {width}x{height}: a {width}x{height} image needs {:.1} GB of memory, which cannot be allocated",
                width as f64 * height as f64 * std::mem::size_of::<[f64; 3]>() as f64 * 1e-9
            ))
        };
        let count = width.checked_mul(height).ok_or_else(too_large)?;
        let mut sums = Vec::new();
        sums.try_reserve_exact(count).map_err(|_| too_large())?;
        sums.resize(count, [0.0; 3]);
        Ok(Self {
            width,
            height,
            sums,
            samples: 0,
        })
    }

    /// The image: each pixel's mean, black before any sample.
    pub fn image(&self) -> Image {
        let inv = if self.samples == 0 {
            0.0
        } else {
            1.0 / self.samples as f64
        };
        Image {
            width: self.width,
            height: self.height,
            pixels: self
                .sums
                .iter()
                .map(|sum| sum.map(|s| (s * inv) as f32))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_image_is_the_mean_and_black_before_any_sample() {
        let mut film = Film::try_new(UVec2::new(2, 1)).unwrap();
        assert_eq!(film.image().pixels, vec![[0.0; 3]; 2]);
        film.sums[1] = [3.0, 6.0, 0.0];
        film.samples = 3;
        assert_eq!(film.image().pixels[1], [1.0, 2.0, 0.0]);
        let err = Film::try_new(UVec2::new(u32::MAX, u32::MAX)).unwrap_err();
        assert!(err.to_string().contains("GB of memory"), "{err}");
    }
}
