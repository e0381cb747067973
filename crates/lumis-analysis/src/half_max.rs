//! The lecture's example of a biased estimator that beats the unbiased
//! one: the mean `1/2` of a variable uniform on [0, 1], estimated by half
//! the largest of `N` draws.
//!
//! The maximum `M` of `N` independent uniform values has density
//! `N m^(N-1)` on [0, 1], so `E[M] = N / (N + 1)` and
//! `E[M^2] = N / (N + 2)`. The estimator `H_N = M / 2` therefore has
//!
//! ```text
//! bias      E[H_N] - 1/2 = -1 / (2 (N + 1))
//! variance  N / (4 (N + 1)^2 (N + 2))
//! MSE       bias^2 + variance = 1 / (2 (N + 1) (N + 2))     O(1/N^2)
//! ```
//!
//! while the sample mean `F_N` is unbiased with variance, and so MSE,
//! `1 / (12 N)`, O(1/N). `MSE(H_N) < MSE(F_N)` exactly when
//! `(N - 1)(N - 2) > 0`: the two are equal at `N = 1` and `N = 2` and the
//! biased estimator is better from `N = 3` on, by a factor that grows like
//! `N / 6`. It is consistent (bias and variance both vanish) and uses what
//! the sample mean ignores, that the distribution ends at 1 (Owen 2013,
//! "Monte Carlo theory, methods and examples", ch. 2, on bias and
//! consistency; the order statistics are those of Casella and Berger,
//! "Statistical Inference", 2nd ed., 5.4).

use lumis_sampling::Pcg32;
use rayon::prelude::*;

use crate::convergence::loglog_slope;

/// The quantity both estimators estimate, `E[X]` for `X ~ U[0, 1]`.
pub const MEAN: f64 = 0.5;

/// `E[H_N] - 1/2 = -1 / (2 (N + 1))`.
pub fn bias(n: u32) -> f64 {
    -1.0 / (2.0 * (f64::from(n) + 1.0))
}

/// `N / (4 (N + 1)^2 (N + 2))`.
pub fn variance(n: u32) -> f64 {
    let n = f64::from(n);
    n / (4.0 * (n + 1.0).powi(2) * (n + 2.0))
}

/// `1 / (2 (N + 1) (N + 2))`, which is `bias^2 + variance`.
pub fn mse(n: u32) -> f64 {
    let n = f64::from(n);
    1.0 / (2.0 * (n + 1.0) * (n + 2.0))
}

/// The sample mean's MSE (its variance), `1 / (12 N)`.
pub fn sample_mean_mse(n: u32) -> f64 {
    1.0 / (12.0 * f64::from(n))
}

/// The smallest `N` from which `H_N`'s MSE is below the sample mean's for
/// every larger `N` too (the roots of `(N - 1)(N - 2)` lie below it).
pub fn first_n_below() -> u32 {
    (1..)
        .find(|&n| mse(n) < sample_mean_mse(n))
        .expect("the MSE ratio falls like 6 / N")
}

/// Both estimates from each of `runs` independent sets of `n` uniform
/// draws, the same draws for both (common random numbers, so their MSE
/// ratio is measured precisely): `(sample means, halves of the maxima)`.
pub fn simulate(n: u32, runs: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
    (0..runs as u64)
        .into_par_iter()
        .map(|r| {
            let mut rng = Pcg32::new(r, seed);
            let (mut sum, mut max) = (0.0f64, 0.0f64);
            for _ in 0..n {
                // 32 random bits: the maximum of 10^4 draws stays resolved.
                let x = f64::from(rng.next_u32()) * (1.0 / 4_294_967_296.0);
                sum += x;
                max = max.max(x);
            }
            (sum / f64::from(n), 0.5 * max)
        })
        .unzip()
}

/// The log-log slopes of the sample mean's and `H_N`'s MSE against `N`,
/// fitted from `N = 100` on: below it `H_N`'s curve is still bending
/// towards its asymptote (its exact slope over 10 .. 10^4 is -1.97, over
/// 100 .. 10^4 -1.994).
pub fn asymptotic_slopes(counts: &[u32], mse_mean: &[f64], mse_half_max: &[f64]) -> (f64, f64) {
    let from = counts.iter().position(|&n| n >= 100).unwrap_or(0);
    let ns: Vec<f64> = counts[from..].iter().map(|&n| f64::from(n)).collect();
    let fit = |mse: &[f64]| loglog_slope(&ns, &mse[from..]).unwrap_or(f64::NAN);
    (fit(mse_mean), fit(mse_half_max))
}

/// The mean squared error of `estimates` of [`MEAN`].
pub fn measured_mse(estimates: &[f64]) -> f64 {
    estimates.iter().map(|x| (x - MEAN).powi(2)).sum::<f64>() / estimates.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sample_variance::SampleVariance;

    #[test]
    fn the_formulas_add_up_and_cross_at_three() {
        for n in [1, 2, 3, 10, 10_000] {
            let sum = bias(n).powi(2) + variance(n);
            assert!((sum - mse(n)).abs() <= 1e-15 * mse(n), "N = {n}");
        }
        for n in [1, 2] {
            assert!((mse(n) - sample_mean_mse(n)).abs() < 1e-15, "N = {n}");
        }
        assert_eq!(first_n_below(), 3);
        assert!(mse(3) < sample_mean_mse(3));
    }

    /// Measured over 4000 runs at each N, the bias and variance of `H_N`
    /// and the sample mean's variance agree with the closed forms, and the
    /// log-log slopes of the two MSEs are -2 and -1.
    #[test]
    fn measured_errors_follow_the_closed_forms_and_their_slopes() {
        let counts = [1u32, 3, 10, 30, 100, 300, 1000, 3000, 10_000];
        let runs = 4000;
        let alpha = lumis_check::corrected_significance(0.01, 3 * counts.len());
        let (mut mse_mean, mut mse_half_max) = (Vec::new(), Vec::new());
        for (k, &n) in counts.iter().enumerate() {
            let (means, half_max) = simulate(n, runs, 7 + k as u64);
            let h = SampleVariance::of(&half_max).unwrap();
            let f = SampleVariance::of(&means).unwrap();
            assert!(h.mean_agrees(MEAN + bias(n), alpha), "N = {n}: {h:?}");
            assert!(h.variance_agrees(variance(n), alpha), "N = {n}: {h:?}");
            assert!(
                f.variance_agrees(sample_mean_mse(n), alpha),
                "N = {n}: {f:?}"
            );
            mse_mean.push(measured_mse(&means));
            mse_half_max.push(measured_mse(&half_max));
        }
        let (slope_mean, slope_half_max) = asymptotic_slopes(&counts, &mse_mean, &mse_half_max);
        assert!((slope_mean + 1.0).abs() < 0.05, "sample mean: {slope_mean}");
        assert!(
            (slope_half_max + 2.0).abs() < 0.05,
            "half max: {slope_half_max}"
        );
        // From N = 10 on the measured MSEs are ordered as the formulas say,
        // by far more than their noise (a factor 2.2 at N = 10).
        for (i, &n) in counts.iter().enumerate().filter(|(_, &n)| n >= 10) {
            assert!(mse_half_max[i] < mse_mean[i], "N = {n}");
        }
    }
}
