//! Stratified sampling of an integral over `[0,1]^d`: the estimator, its
//! variance, and how samples are allocated to strata.
//!
//! With strata of volumes `v_i`, `n_i` uniform samples in stratum `i` and
//! `sigma_i^2` the variance of `f` over it, the estimator
//! `F = sum_i v_i (1/n_i) sum_j f(X_ij)` is unbiased with
//! `Var F = sum_i v_i^2 sigma_i^2 / n_i` (Owen 2013, "Monte Carlo theory,
//! methods and examples", section 8.4; Cochran 1977, "Sampling
//! Techniques", theorem 5.3). For a total of `N` samples it is smallest
//! with Neyman's allocation `n_i ∝ v_i sigma_i` (Owen section 8.4), giving
//! `(sum_i v_i sigma_i)^2 / N`; proportional allocation `n_i ∝ v_i` gives
//! `sum_i v_i sigma_i^2 / N`, never more than plain Monte Carlo's
//! `sigma^2 / N` (ibid.).

use lumis_sampling::Pcg32;
use rayon::prelude::*;

use crate::integrands::Integrand;

/// `per_axis^dims` equal cells of `[0,1]^dims`, `dims` 1 or 2, numbered
/// row-major.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Strata {
    pub per_axis: usize,
    pub dims: usize,
}

impl Strata {
    pub fn len(&self) -> usize {
        self.per_axis.pow(self.dims as u32)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The volume `v_i` of every cell.
    pub fn volume(&self) -> f64 {
        1.0 / self.len() as f64
    }

    /// The point of cell `i` at local coordinates `u` in `[0,1)^dims`.
    fn point(&self, i: usize, u: [f64; 2]) -> [f64; 2] {
        let h = 1.0 / self.per_axis as f64;
        let (x, y) = (i % self.per_axis, i / self.per_axis);
        [(x as f64 + u[0]) * h, (y as f64 + u[1]) * h]
    }
}

/// The mean and variance of `f` over each stratum, by the midpoint rule on
/// `resolution^dims` nodes per stratum.
#[derive(Debug, Clone, PartialEq)]
pub struct StratumMoments {
    pub strata: Strata,
    pub mean: Vec<f64>,
    pub variance: Vec<f64>,
}

impl StratumMoments {
    pub fn of(integrand: &Integrand, strata: Strata, resolution: usize) -> Self {
        let nodes = resolution.pow(strata.dims as u32);
        let (mean, variance) = (0..strata.len())
            .into_par_iter()
            .map(|i| {
                let (mut sum, mut sum2) = (0.0, 0.0);
                for k in 0..nodes {
                    let u = [
                        ((k % resolution) as f64 + 0.5) / resolution as f64,
                        ((k / resolution) as f64 + 0.5) / resolution as f64,
                    ];
                    let v = (integrand.f)(&strata.point(i, u)[..strata.dims]);
                    sum += v;
                    sum2 += v * v;
                }
                let m = sum / nodes as f64;
                (m, (sum2 / nodes as f64 - m * m).max(0.0))
            })
            .unzip();
        Self {
            strata,
            mean,
            variance,
        }
    }

    /// The integral, `sum_i v_i mu_i`.
    pub fn integral(&self) -> f64 {
        self.mean.iter().sum::<f64>() * self.strata.volume()
    }

    /// The variance of `f` over the whole domain,
    /// `sum_i v_i (sigma_i^2 + mu_i^2) - I^2`.
    pub fn total_variance(&self) -> f64 {
        let v = self.strata.volume();
        let second: f64 = self
            .mean
            .iter()
            .zip(&self.variance)
            .map(|(m, s2)| v * (s2 + m * m))
            .sum();
        second - self.integral().powi(2)
    }

    /// `sum_i v_i^2 sigma_i^2 / n_i` for the allocation `counts`.
    pub fn stratified_variance(&self, counts: &[usize]) -> f64 {
        let v2 = self.strata.volume().powi(2);
        self.variance
            .iter()
            .zip(counts)
            .map(|(s2, &n)| v2 * s2 / n as f64)
            .sum()
    }
}

/// How the samples of a stratified estimate are spread over the strata.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Allocation {
    /// `n_i ∝ v_i`.
    Proportional,
    /// `n_i ∝ v_i sigma_i`, with `sigma_i` from a pilot run.
    Neyman,
}

impl Allocation {
    pub fn name(&self) -> &'static str {
        match self {
            Self::Proportional => "proportional",
            Self::Neyman => "neyman",
        }
    }

    /// The counts of `total` samples over `strata`; `sigma` is the
    /// per-stratum standard deviation Neyman's allocation weighs by.
    pub fn counts(&self, strata: Strata, sigma: &[f64], total: usize) -> Option<Vec<usize>> {
        let weights: Vec<f64> = match self {
            Self::Proportional => vec![strata.volume(); strata.len()],
            Self::Neyman => sigma.iter().map(|s| s * strata.volume()).collect(),
        };
        allocate(&weights, total)
    }
}

/// `total` samples in proportion to `weights`, at least one per stratum
/// (a stratum's mean needs a sample even when the pilot saw no variation
/// in it); the remainders go to the largest fractional parts (Hamilton's
/// method). `None` when `total` is below the number of strata.
pub fn allocate(weights: &[f64], total: usize) -> Option<Vec<usize>> {
    let k = weights.len();
    if k == 0 || total < k {
        return None;
    }
    let sum: f64 = weights.iter().sum();
    let uniform = !(sum > 0.0 && sum.is_finite());
    let free = (total - k) as f64;
    let share: Vec<f64> = weights
        .iter()
        .map(|w| {
            if uniform {
                free / k as f64
            } else {
                free * w / sum
            }
        })
        .collect();
    let mut counts: Vec<usize> = share.iter().map(|s| 1 + s.floor() as usize).collect();
    let mut order: Vec<usize> = (0..k).collect();
    order.sort_by(|&a, &b| (share[b] - share[b].floor()).total_cmp(&(share[a] - share[a].floor())));
    let left = total - counts.iter().sum::<usize>();
    for &i in order.iter().take(left) {
        counts[i] += 1;
    }
    Some(counts)
}

/// A uniform point of stratum `i`.
fn sample_in(strata: Strata, i: usize, rng: &mut Pcg32) -> [f64; 2] {
    strata.point(i, [rng.next_f32() as f64, rng.next_f32() as f64])
}

/// The pilot run of Neyman allocation: the sample standard deviation of `f`
/// in each stratum from `per_stratum` uniform samples. Its samples are not
/// reused, so the final estimate stays unbiased and its variance is the
/// formula's for the allocation the pilot chose.
pub fn pilot_sigma(
    integrand: &Integrand,
    strata: Strata,
    per_stratum: usize,
    seed: u64,
) -> Vec<f64> {
    let mut rng = Pcg32::new(seed, 0x9170);
    (0..strata.len())
        .map(|i| {
            let values: Vec<f64> = (0..per_stratum)
                .map(|_| (integrand.f)(&sample_in(strata, i, &mut rng)[..strata.dims]))
                .collect();
            let n = values.len() as f64;
            let mean = values.iter().sum::<f64>() / n;
            let ss: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
            (ss / (n - 1.0).max(1.0)).sqrt()
        })
        .collect()
}

/// The stratified estimate with `counts[i]` samples in stratum `i`.
pub fn stratified_estimate(
    integrand: &Integrand,
    strata: Strata,
    counts: &[usize],
    rng: &mut Pcg32,
) -> f64 {
    let total: f64 = counts
        .iter()
        .enumerate()
        .map(|(i, &n)| {
            let sum: f64 = (0..n)
                .map(|_| (integrand.f)(&sample_in(strata, i, rng)[..strata.dims]))
                .sum();
            sum / n as f64
        })
        .sum();
    total * strata.volume()
}

/// Plain Monte Carlo: the mean of `f` at `n` uniform points.
pub fn plain_estimate(integrand: &Integrand, n: usize, rng: &mut Pcg32) -> f64 {
    let whole = Strata {
        per_axis: 1,
        dims: integrand.dims,
    };
    stratified_estimate(integrand, whole, &[n], rng)
}

/// `runs` independent estimates from `estimate(rng)`, run `r` drawing from
/// its own stream of `seed`.
pub fn repeated(runs: usize, seed: u64, estimate: impl Fn(&mut Pcg32) -> f64 + Sync) -> Vec<f64> {
    (0..runs as u64)
        .into_par_iter()
        .map(|r| estimate(&mut Pcg32::new(r, seed)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrands::integrands_2d;
    use crate::sample_variance::SampleVariance;

    #[test]
    fn allocation_sums_to_the_total_with_one_sample_at_least() {
        assert_eq!(allocate(&[1.0; 4], 16), Some(vec![4; 4]));
        assert_eq!(allocate(&[0.0, 0.0, 3.0, 1.0], 10), Some(vec![1, 1, 6, 2]));
        assert_eq!(allocate(&[0.0; 3], 7).map(|c| c.iter().sum()), Some(7));
        assert_eq!(allocate(&[1.0; 4], 3), None);
        let c = allocate(&[0.3, 0.1, 0.6], 20).unwrap();
        assert_eq!(c.iter().sum::<usize>(), 20);
    }

    #[test]
    fn moments_recover_the_integral_and_variance() {
        // The ramp x + y: I = 1, Var = 1/12 + 1/12.
        let ramp = integrands_2d()[2];
        let m = StratumMoments::of(
            &ramp,
            Strata {
                per_axis: 4,
                dims: 2,
            },
            64,
        );
        assert!((m.integral() - 1.0).abs() < 1e-12);
        assert!((m.total_variance() - 1.0 / 6.0).abs() < 1e-4);
        // Per stratum, (h^2 / 12) * 2 with h = 1/4.
        assert!(m
            .variance
            .iter()
            .all(|v| (v - 2.0 / (12.0 * 16.0)).abs() < 1e-4));
    }

    /// The measured variance of plain, proportional and Neyman estimates
    /// over 4000 runs agrees with `sigma^2 / N` and
    /// `sum v_i^2 sigma_i^2 / n_i`, on a smooth integrand and on one with a
    /// discontinuity, at N = 64 with 4x4 strata.
    #[test]
    fn measured_variance_matches_the_formula() {
        let strata = Strata {
            per_axis: 4,
            dims: 2,
        };
        let (n, runs) = (64, 4000);
        let integrands: Vec<Integrand> = integrands_2d()
            .into_iter()
            .filter(|g| g.name == "gaussian" || g.name == "disk")
            .collect();
        let tests = integrands.len() * 3;
        let alpha = lumis_check::corrected_significance(0.01, tests);
        for (k, g) in integrands.iter().enumerate() {
            let moments = StratumMoments::of(g, strata, 256);
            let sigma = pilot_sigma(g, strata, 16, 99);
            let proportional = Allocation::Proportional.counts(strata, &sigma, n).unwrap();
            let neyman = Allocation::Neyman.counts(strata, &sigma, n).unwrap();
            let cases = [
                ("plain", moments.total_variance() / n as f64, None),
                (
                    "proportional",
                    moments.stratified_variance(&proportional),
                    Some(&proportional),
                ),
                (
                    "neyman",
                    moments.stratified_variance(&neyman),
                    Some(&neyman),
                ),
            ];
            for (c, (name, predicted, counts)) in cases.into_iter().enumerate() {
                let seed = (k * 3 + c) as u64;
                let estimates = repeated(runs, seed, |rng| match counts {
                    None => plain_estimate(g, n, rng),
                    Some(counts) => stratified_estimate(g, strata, counts, rng),
                });
                let s = SampleVariance::of(&estimates).unwrap();
                assert!(
                    s.variance_agrees(predicted, alpha),
                    "{} {name}: measured {} (interval {:?}), predicted {predicted}",
                    g.name,
                    s.variance,
                    s.variance_interval(alpha)
                );
                assert!(
                    s.mean_agrees(g.exact, alpha),
                    "{} {name}: mean {}",
                    g.name,
                    s.mean
                );
            }
            // Neyman's allocation from a pilot beats proportional here.
            assert!(
                moments.stratified_variance(&neyman) < moments.stratified_variance(&proportional)
            );
        }
    }
}
