//! Error metrics between a rendered image and a reference, over the whole
//! image or a region: the numbers `lumis diff` prints and `converge` plots.

use lumis_image::{linear_to_srgb8, Image};

/// Added to the squared reference value in relMSE (and to its magnitude in
/// the relative errors) so black pixels do not dominate; the convention of
/// the Mitsuba / Rousselle et al. comparisons and of this project's targets.
pub const RELATIVE_EPSILON: f64 = 1e-2;

/// A pixel rectangle `[min, max)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rect {
    pub min: [usize; 2],
    pub max: [usize; 2],
}

/// Errors of `a` against the reference `b`, over every channel of the
/// pixels considered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorMetrics {
    pub mse: f64,
    pub rmse: f64,
    /// mean of (a - b)^2 / (b^2 + 0.01).
    pub rel_mse: f64,
    /// mean of |a - b| / (|b| + 0.01).
    pub mean_abs_rel_error: f64,
    /// mean of (a - b) / (|b| + 0.01): a bias shows up here, noise averages out.
    pub mean_signed_rel_error: f64,
    /// 10 log10(1 / MSE) of the sRGB-encoded, `[0, 1]`-clamped values.
    pub psnr_db: f64,
    /// Channel values compared.
    pub count: usize,
}

/// Refuses images of different sizes with both sizes in the message.
pub fn check_same_size(a: &Image, b: &Image) -> Result<(), String> {
    if (a.width, a.height) == (b.width, b.height) {
        Ok(())
    } else {
        Err(format!(
            "images differ in size: {}x{} vs {}x{}",
            a.width, a.height, b.width, b.height
        ))
    }
}

/// Metrics over `region` (or the whole image). Sizes must match.
pub fn error_metrics(a: &Image, b: &Image, region: Option<Rect>) -> ErrorMetrics {
    let r = region.unwrap_or(Rect {
        min: [0, 0],
        max: [a.width, a.height],
    });
    let (mut se, mut rel_se, mut abs_rel, mut signed_rel, mut tone_se) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut count = 0usize;
    for y in r.min[1]..r.max[1].min(a.height) {
        for x in r.min[0]..r.max[0].min(a.width) {
            let (p, q) = (a.get(x, y), b.get(x, y));
            for c in 0..3 {
                let (u, v) = (p[c] as f64, q[c] as f64);
                let d = u - v;
                se += d * d;
                rel_se += d * d / (v * v + RELATIVE_EPSILON);
                abs_rel += d.abs() / (v.abs() + RELATIVE_EPSILON);
                signed_rel += d / (v.abs() + RELATIVE_EPSILON);
                let t = (linear_to_srgb8(p[c]) as f64 - linear_to_srgb8(q[c]) as f64) / 255.0;
                tone_se += t * t;
                count += 1;
            }
        }
    }
    let n = count.max(1) as f64;
    let tone_mse = tone_se / n;
    ErrorMetrics {
        mse: se / n,
        rmse: (se / n).sqrt(),
        rel_mse: rel_se / n,
        mean_abs_rel_error: abs_rel / n,
        mean_signed_rel_error: signed_rel / n,
        psnr_db: if tone_mse > 0.0 {
            10.0 * (1.0 / tone_mse).log10()
        } else {
            f64::INFINITY
        },
        count,
    }
}

/// Per-pixel relative squared error (averaged over channels), the quantity
/// the false-colour error image shows.
pub fn rel_error_map(a: &Image, b: &Image) -> Vec<f64> {
    a.pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            (0..3)
                .map(|c| {
                    let (u, v) = (p[c] as f64, q[c] as f64);
                    (u - v) * (u - v) / (v * v + RELATIVE_EPSILON)
                })
                .sum::<f64>()
                / 3.0
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, values: &[f32]) -> Image {
        let mut img = Image::new(w, h);
        for (p, v) in img.pixels.iter_mut().zip(values) {
            *p = [*v; 3];
        }
        img
    }

    /// Two pixels, reference (1, 0), image (1.5, 0.1), all channels equal:
    /// differences 0.5 and 0.1.
    #[test]
    fn hand_computed_two_pixel_case() {
        let a = image(2, 1, &[1.5, 0.1]);
        let b = image(2, 1, &[1.0, 0.0]);
        let m = error_metrics(&a, &b, None);
        assert_eq!(m.count, 6);
        assert!((m.mse - (0.25 + 0.01) / 2.0).abs() < 1e-7);
        assert!((m.rmse - 0.13f64.sqrt()).abs() < 1e-7);
        // 0.25 / 1.01 and 0.01 / 0.01 = 1.
        assert!((m.rel_mse - (0.25 / 1.01 + 1.0) / 2.0).abs() < 1e-6);
        // 0.5 / 1.01 and 0.1 / 0.01 = 10.
        assert!((m.mean_abs_rel_error - (0.5 / 1.01 + 10.0) / 2.0).abs() < 1e-5);
        assert!((m.mean_signed_rel_error - m.mean_abs_rel_error).abs() < 1e-12);
        // Tone-mapped: 1.5 and 1.0 both clamp to 255; 0.1 -> 89, 0 -> 0.
        let t: f64 = 89.0 / 255.0;
        assert_eq!(linear_to_srgb8(0.1), 89);
        assert!((m.psnr_db - 10.0 * (1.0 / (t * t / 2.0)).log10()).abs() < 1e-9);
    }

    #[test]
    fn signed_error_cancels_for_noise_but_not_for_bias() {
        let b = image(2, 1, &[1.0, 1.0]);
        let noisy = error_metrics(&image(2, 1, &[1.2, 0.8]), &b, None);
        assert!(noisy.mean_signed_rel_error.abs() < 1e-7);
        let biased = error_metrics(&image(2, 1, &[1.2, 1.2]), &b, None);
        assert!((biased.mean_signed_rel_error - 0.2 / 1.01).abs() < 1e-6);
    }

    #[test]
    fn identical_images_and_regions() {
        let a = image(3, 2, &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
        let m = error_metrics(&a, &a, None);
        assert_eq!((m.mse, m.rel_mse), (0.0, 0.0));
        assert!(m.psnr_db.is_infinite());
        let mut b = a.clone();
        b.pixels[5] = [1.6; 3];
        let region = Rect {
            min: [0, 0],
            max: [2, 2],
        };
        assert_eq!(error_metrics(&a, &b, Some(region)).mse, 0.0);
        assert!((error_metrics(&a, &b, None).mse - 1.0 / 6.0).abs() < 1e-6);
        assert!(check_same_size(&a, &image(2, 3, &[0.0; 6])).is_err());
    }
}
