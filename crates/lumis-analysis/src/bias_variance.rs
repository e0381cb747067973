//! The error of a renderer split into squared bias and variance, from
//! several renders of one scene that differ only in their seed.
//!
//! With `n` renders `x_1 .. x_n` of a pixel channel whose reference value is
//! `r`, mean `m` and unbiased variance `s^2` (divisor `n - 1`), the mean over
//! the renders of the squared error splits exactly as
//!
//! ```text
//! (1/n) sum_i (x_i - r)^2 = (m - r)^2 + ((n - 1) / n) s^2
//!                         = [(m - r)^2 - s^2 / n] + s^2.
//! ```
//!
//! The second line names the parts. Since `E[(m - r)^2] = b^2 + sigma^2 / n`
//! (the bias `b = E[x] - r` plus the variance of a mean of `n`) and
//! `E[s^2] = sigma^2`, the first bracket is an unbiased estimate of the
//! squared bias `b^2` and `s^2` one of the variance `sigma^2` of a single
//! render: the textbook bias-variance decomposition of the mean squared
//! error (e.g. Hastie, Tibshirani and Friedman, *The Elements of
//! Statistical Learning*, 2nd ed., eq. 7.9), with the plug-in `(m - r)^2`
//! corrected for the noise left in the mean of `n` seeds. Averaged over the
//! pixels, bias² + variance is the mean MSE of one render, exactly.
//!
//! The bias estimate can come out slightly negative when the true bias is
//! far below the noise; it is reported as it is, not clamped, so that it
//! stays unbiased and the parts still add up.

use lumis_image::Image;

use crate::image_error::RELATIVE_EPSILON;

/// One error measure (MSE or relMSE) and its two parts, each with a
/// standard error over the pixels (valid when the pixels' errors are
/// independent, as for a per-pixel estimator; a denoiser correlates
/// neighbours, and these standard errors then understate the spread).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split {
    /// bias² + variance: the mean error of one render.
    pub total: f64,
    pub bias2: f64,
    pub bias2_se: f64,
    pub variance: f64,
    pub variance_se: f64,
}

/// The split of the MSE and of the relMSE (each channel's squared error
/// over `reference^2 + 0.01`, as in [`crate::image_error::error_metrics`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BiasVariance {
    pub mse: Split,
    pub rel_mse: Split,
    /// Renders the split was computed from.
    pub renders: usize,
}

/// Running mean and unbiased variance of per-channel terms.
#[derive(Default)]
struct Moments {
    count: f64,
    mean: f64,
    m2: f64,
}

impl Moments {
    /// Welford's update: stable for the millions of terms of an image.
    fn add(&mut self, x: f64) {
        self.count += 1.0;
        let delta = x - self.mean;
        self.mean += delta / self.count;
        self.m2 += delta * (x - self.mean);
    }

    fn mean_se(&self) -> (f64, f64) {
        if self.count < 2.0 {
            return (self.mean, f64::NAN);
        }
        let variance = self.m2 / (self.count - 1.0);
        (self.mean, (variance / self.count).sqrt())
    }
}

fn split(bias2: &Moments, variance: &Moments) -> Split {
    let (bias2, bias2_se) = bias2.mean_se();
    let (variance, variance_se) = variance.mean_se();
    Split {
        total: bias2 + variance,
        bias2,
        bias2_se,
        variance,
        variance_se,
    }
}

/// Splits the error of `renders` (at least two, all the reference's size)
/// against `reference`; an error names what was wrong.
pub fn bias_variance(renders: &[&Image], reference: &Image) -> Result<BiasVariance, String> {
    if renders.len() < 2 {
        return Err(format!(
            "the bias/variance split needs at least 2 renders (seeds), got {}",
            renders.len()
        ));
    }
    for image in renders {
        crate::image_error::check_same_size(image, reference)?;
    }
    let n = renders.len() as f64;
    let (mut bias2, mut variance) = (Moments::default(), Moments::default());
    let (mut rel_bias2, mut rel_variance) = (Moments::default(), Moments::default());
    let mut values = vec![0.0f64; renders.len()];
    for (p, r) in reference.pixels.iter().enumerate() {
        for (c, &reference_value) in r.iter().enumerate() {
            for (v, image) in values.iter_mut().zip(renders) {
                *v = image.pixels[p][c] as f64;
            }
            let reference_value = reference_value as f64;
            let mean = values.iter().sum::<f64>() / n;
            let s2 = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
            let b2 = (mean - reference_value).powi(2) - s2 / n;
            let weight = 1.0 / (reference_value * reference_value + RELATIVE_EPSILON);
            bias2.add(b2);
            variance.add(s2);
            rel_bias2.add(weight * b2);
            rel_variance.add(weight * s2);
        }
    }
    Ok(BiasVariance {
        mse: split(&bias2, &variance),
        rel_mse: split(&rel_bias2, &rel_variance),
        renders: renders.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image_error::error_metrics;
    use lumis_sampling::rng::Pcg32;
    use statrs::distribution::{ContinuousCDF, Normal};

    const SIZE: usize = 64;

    /// A smooth reference with dark and bright pixels, so that the relMSE
    /// weights differ from pixel to pixel.
    fn reference() -> Image {
        let mut image = Image::new(SIZE, SIZE);
        for (i, p) in image.pixels.iter_mut().enumerate() {
            let (x, y) = ((i % SIZE) as f32, (i / SIZE) as f32);
            *p = [0.05 + x / SIZE as f32, 0.5 + y / SIZE as f32, 2.0];
        }
        image
    }

    /// `seeds` renders: the reference plus `offset`, plus independent
    /// uniform noise of standard deviation `sigma`.
    fn renders(reference: &Image, seeds: u64, offset: f32, sigma: f32) -> Vec<Image> {
        (0..seeds)
            .map(|seed| {
                let mut rng = Pcg32::new(seed, 7);
                let mut image = reference.clone();
                for p in &mut image.pixels {
                    for v in p.iter_mut() {
                        let u = rng.next_f32() * 2.0 - 1.0;
                        *v += offset + sigma * 3f32.sqrt() * u;
                    }
                }
                image
            })
            .collect()
    }

    fn split_of(images: &[Image], reference: &Image) -> BiasVariance {
        let refs: Vec<&Image> = images.iter().collect();
        bias_variance(&refs, reference).unwrap()
    }

    /// Two-sided normal quantile at the significance 0.001, Sidak-corrected
    /// for the 4 estimates this module's tests check against known values.
    fn z_bound() -> f64 {
        let alpha = 1.0 - (1.0 - 1e-3f64).powf(1.0 / 4.0);
        Normal::standard().inverse_cdf(1.0 - alpha / 2.0)
    }

    /// Known bias 0.1 and standard deviation 0.3: both parts found within
    /// their standard errors, and the parts add up to the mean MSE.
    #[test]
    fn known_bias_and_variance_are_recovered() {
        let reference = reference();
        let (offset, sigma) = (0.1f32, 0.3f32);
        let images = renders(&reference, 5, offset, sigma);
        let split = split_of(&images, &reference);
        let z = z_bound();
        let (b2, var) = ((offset as f64).powi(2), (sigma as f64).powi(2));
        assert!(
            (split.mse.bias2 - b2).abs() < z * split.mse.bias2_se,
            "bias² {} +- {} vs {b2}",
            split.mse.bias2,
            split.mse.bias2_se
        );
        assert!(
            (split.mse.variance - var).abs() < z * split.mse.variance_se,
            "variance {} +- {} vs {var}",
            split.mse.variance,
            split.mse.variance_se
        );
        let mean_mse = images
            .iter()
            .map(|i| error_metrics(i, &reference, None).mse)
            .sum::<f64>()
            / images.len() as f64;
        assert!((split.mse.total - mean_mse).abs() < 1e-9 * mean_mse);
        let mean_rel = images
            .iter()
            .map(|i| error_metrics(i, &reference, None).rel_mse)
            .sum::<f64>()
            / images.len() as f64;
        assert!((split.rel_mse.total - mean_rel).abs() < 1e-9 * mean_rel);
    }

    /// Renders that all differ from the reference by the same offset have
    /// no variance: their whole error is bias.
    #[test]
    fn a_constant_offset_is_all_bias() {
        let reference = reference();
        let images = renders(&reference, 3, 0.25, 0.0);
        let split = split_of(&images, &reference);
        assert_eq!(split.mse.variance, 0.0);
        assert!((split.mse.bias2 - 0.0625).abs() < 1e-6, "{split:?}");
        assert_eq!(split.rel_mse.variance, 0.0);
        assert!(split.rel_mse.bias2 > 0.0);
    }

    /// Unbiased noise: the variance is found and the bias is zero within
    /// its standard error.
    #[test]
    fn independent_noise_is_all_variance() {
        let reference = reference();
        let sigma = 0.2f64;
        let images = renders(&reference, 4, 0.0, sigma as f32);
        let split = split_of(&images, &reference);
        let z = z_bound();
        assert!(split.mse.bias2.abs() < z * split.mse.bias2_se, "{split:?}");
        assert!(
            (split.mse.variance - sigma * sigma).abs() < z * split.mse.variance_se,
            "{split:?}"
        );
        assert!(split.mse.bias2.abs() < 0.02 * split.mse.variance);
    }

    #[test]
    fn too_few_renders_or_a_size_mismatch_are_refused() {
        let reference = reference();
        let one = renders(&reference, 1, 0.0, 0.1);
        let err = bias_variance(&[&one[0]], &reference).unwrap_err();
        assert!(err.contains("at least 2"), "{err}");
        let small = Image::new(2, 2);
        let err = bias_variance(&[&small, &small], &reference).unwrap_err();
        assert!(err.contains("differ in size"), "{err}");
    }
}
