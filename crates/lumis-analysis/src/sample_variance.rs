//! The mean and variance of repeated independent estimates, and a
//! confidence interval for the true variance: what a measured variance is
//! compared with a formula by.

use statrs::distribution::{ChiSquared, ContinuousCDF};

/// Summary of `runs` independent estimates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleVariance {
    pub runs: usize,
    pub mean: f64,
    /// The unbiased sample variance `s^2` (denominator `runs - 1`).
    pub variance: f64,
    /// The sample kurtosis `m4 / m2^2` (3 for a normal distribution).
    pub kurtosis: f64,
}

impl SampleVariance {
    /// `None` with fewer than two estimates.
    pub fn of(estimates: &[f64]) -> Option<Self> {
        let runs = estimates.len();
        if runs < 2 {
            return None;
        }
        let n = runs as f64;
        let mean = estimates.iter().sum::<f64>() / n;
        let (m2, m4) = estimates.iter().fold((0.0, 0.0), |(m2, m4), x| {
            let d = (x - mean) * (x - mean);
            (m2 + d / n, m4 + d * d / n)
        });
        Some(Self {
            runs,
            mean,
            variance: m2 * n / (n - 1.0),
            kurtosis: if m2 > 0.0 { m4 / (m2 * m2) } else { 3.0 },
        })
    }

    /// The standard error of the mean, `s / sqrt(runs)`.
    pub fn standard_error(&self) -> f64 {
        (self.variance / self.runs as f64).sqrt()
    }

    /// The effective degrees of freedom of `s^2`: `s^2 / sigma^2` is taken
    /// as `chi^2_d / d` with `d = 2 / Var(s^2 / sigma^2)` and
    /// `Var(s^2 / sigma^2) = (kurtosis - 1) / n + 2 / (n (n - 1))`
    /// (Cramer 1946, "Mathematical Methods of Statistics", ch. 27;
    /// Satterthwaite 1946). For normal estimates
    /// (kurtosis 3) `d = n - 1`, the textbook chi-square interval; heavier
    /// tails (a stratum with one sample of a discontinuous integrand) give
    /// fewer degrees of freedom and a wider interval.
    pub fn degrees_of_freedom(&self) -> f64 {
        let n = self.runs as f64;
        let relative = (self.kurtosis - 1.0).max(0.0) / n + 2.0 / (n * (n - 1.0));
        2.0 / relative
    }

    /// The two-sided `1 - alpha` confidence interval of the true variance,
    /// `[d s^2 / chi^2_{d, 1 - alpha/2}, d s^2 / chi^2_{d, alpha/2}]`.
    pub fn variance_interval(&self, alpha: f64) -> (f64, f64) {
        let d = self.degrees_of_freedom();
        let chi = ChiSquared::new(d).expect("positive degrees of freedom");
        let scaled = d * self.variance;
        (
            scaled / chi.inverse_cdf(1.0 - alpha / 2.0),
            scaled / chi.inverse_cdf(alpha / 2.0),
        )
    }

    /// Whether `predicted` lies in [`Self::variance_interval`].
    pub fn variance_agrees(&self, predicted: f64, alpha: f64) -> bool {
        let (lo, hi) = self.variance_interval(alpha);
        (lo..=hi).contains(&predicted)
    }

    /// Whether `predicted` lies within the normal two-sided `1 - alpha`
    /// interval of the mean, `mean +- z s / sqrt(runs)`.
    pub fn mean_agrees(&self, predicted: f64, alpha: f64) -> bool {
        use statrs::distribution::Normal;
        let z = Normal::standard().inverse_cdf(1.0 - alpha / 2.0);
        (self.mean - predicted).abs() <= z * self.standard_error()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    #[test]
    fn moments_of_a_known_set() {
        let s = SampleVariance::of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!(s.mean, 2.5);
        assert!((s.variance - 5.0 / 3.0).abs() < 1e-12);
        // m2 = 1.25, m4 = (2 * 5.0625 + 2 * 0.0625) / 4 = 2.5625.
        assert!((s.kurtosis - 2.5625 / 1.5625).abs() < 1e-12);
        assert!(SampleVariance::of(&[1.0]).is_none());
    }

    /// Uniform variates (variance 1/12, kurtosis 1.8): the 99% interval
    /// holds 1/12 and excludes 1.1/12 with 20000 draws (the relative
    /// standard error of s^2 is sqrt(0.8 / 20000) = 0.6%).
    #[test]
    fn the_interval_covers_the_true_variance_and_is_tight() {
        let mut rng = Pcg32::new(7, 3);
        let x: Vec<f64> = (0..20000).map(|_| rng.next_f32() as f64).collect();
        let s = SampleVariance::of(&x).unwrap();
        assert!(s.variance_agrees(1.0 / 12.0, 0.01), "{s:?}");
        assert!(!s.variance_agrees(1.1 / 12.0, 0.01), "{s:?}");
        assert!(!s.variance_agrees(0.9 / 12.0, 0.01), "{s:?}");
        assert!(s.mean_agrees(0.5, 0.01));
        assert!(!s.mean_agrees(0.51, 0.01));
    }
}
