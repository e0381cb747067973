//! The lecture's example of a biased but consistent estimator: the sample
//! mean scaled by `N / (N + 1)`.
//!
//! For the sample mean `F_N` of `N` independent values with mean `I` and
//! variance `sigma^2`, `F'_N = N / (N + 1) F_N` has bias `-I / (N + 1)`,
//! variance `(N / (N + 1))^2 sigma^2 / N` and so
//! `MSE = (I^2 + N sigma^2) / (N + 1)^2`; both vanish as `N` grows, so it is
//! consistent (Owen 2013, "Monte Carlo theory, methods and examples",
//! ch. 2; Veach 1997, thesis, section 2.4.3). Its MSE is below the
//! unbiased `sigma^2 / N` exactly when `N (I^2 - 2 sigma^2) < sigma^2`:
//! always if `sigma^2 >= I^2 / 2`, otherwise for `N < sigma^2 / (I^2 - 2 sigma^2)`
//! (shrinking towards zero trades a little bias for less variance).

/// The formulas for `N / (N + 1) F_N`, given `I` and `sigma^2` of one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaledMean {
    pub integral: f64,
    pub sample_variance: f64,
}

impl ScaledMean {
    fn scale(n: u32) -> f64 {
        n as f64 / (n as f64 + 1.0)
    }

    /// Applies the scale to a sample mean of `n` values.
    pub fn estimate(n: u32, sample_mean: f64) -> f64 {
        Self::scale(n) * sample_mean
    }

    /// `E[F'_N] - I = -I / (N + 1)`.
    pub fn bias(&self, n: u32) -> f64 {
        -self.integral / (n as f64 + 1.0)
    }

    /// `(N / (N + 1))^2 sigma^2 / N`.
    pub fn variance(&self, n: u32) -> f64 {
        Self::scale(n).powi(2) * self.sample_variance / n as f64
    }

    /// `bias^2 + variance`.
    pub fn mse(&self, n: u32) -> f64 {
        self.bias(n).powi(2) + self.variance(n)
    }

    /// The unbiased sample mean's MSE, `sigma^2 / N`.
    pub fn unbiased_mse(&self, n: u32) -> f64 {
        self.sample_variance / n as f64
    }

    /// The `N` below which the scaled mean has the lower MSE,
    /// `sigma^2 / (I^2 - 2 sigma^2)`; `None` when it is lower for every `N`.
    pub fn crossover(&self) -> Option<f64> {
        let d = self.integral.powi(2) - 2.0 * self.sample_variance;
        (d > 0.0).then(|| self.sample_variance / d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrands::integrands_1d;
    use crate::sample_variance::SampleVariance;
    use crate::stratification::{plain_estimate, repeated, Strata, StratumMoments};

    #[test]
    fn the_mse_comparison_flips_at_the_crossover() {
        let m = ScaledMean {
            integral: 1.0,
            sample_variance: 0.4,
        };
        let n_star = m.crossover().unwrap();
        assert!((n_star - 2.0).abs() < 1e-12);
        assert!(m.mse(1) < m.unbiased_mse(1));
        assert!(m.mse(3) > m.unbiased_mse(3));
        assert!((m.mse(2) - m.unbiased_mse(2)).abs() < 1e-15);
        let wide = ScaledMean {
            integral: 1.0,
            sample_variance: 0.5,
        };
        assert_eq!(wide.crossover(), None);
    }

    /// The measured bias and variance of `N/(N+1) F_N` on the 1D Gaussian
    /// over 20000 runs agree with `-I/(N+1)` and
    /// `(N/(N+1))^2 sigma^2 / N` at N = 1, 4, 16.
    #[test]
    fn measured_bias_and_variance_match_the_formulas() {
        let g = integrands_1d()[0];
        let whole = Strata {
            per_axis: 1,
            dims: 1,
        };
        let moments = StratumMoments::of(&g, whole, 1 << 16);
        let model = ScaledMean {
            integral: g.exact,
            sample_variance: moments.total_variance(),
        };
        let counts = [1u32, 4, 16];
        let alpha = lumis_check::corrected_significance(0.01, 2 * counts.len());
        for (k, &n) in counts.iter().enumerate() {
            let estimates = repeated(20000, 100 + k as u64, |rng| {
                ScaledMean::estimate(n, plain_estimate(&g, n as usize, rng))
            });
            let s = SampleVariance::of(&estimates).unwrap();
            let expected_mean = g.exact + model.bias(n);
            assert!(
                s.mean_agrees(expected_mean, alpha),
                "N = {n}: bias {} vs {}",
                s.mean - g.exact,
                model.bias(n)
            );
            assert!(
                s.variance_agrees(model.variance(n), alpha),
                "N = {n}: variance {} vs {}",
                s.variance,
                model.variance(n)
            );
        }
    }
}
