//! Convergence studies: RMSE of the N-point estimate of a known integral
//! over many randomisations, and its log-log slope; Simpson's rule as the
//! deterministic baseline.

use lumis_core::{Sampler, UVec2};
use rayon::prelude::*;

use crate::integrands::Integrand;
use crate::points::{sample_points, sample_points_1d};

/// Powers of two from `min` to `max` inclusive: every sampler is compared at
/// the counts where the (0,2)-sequences are complete nets.
pub fn powers_of_two(min: u32, max: u32) -> Vec<u32> {
    let mut counts = Vec::new();
    let mut n = min.max(1).next_power_of_two();
    while n <= max {
        counts.push(n);
        n *= 2;
    }
    counts
}

/// RMSE per integrand (rows) and count (columns) of the sample-mean
/// estimate, over `seeds` randomisations. `make_sampler(n)` builds a sampler
/// for `n` samples per pixel (finite sets such as Hammersley depend on it);
/// 2D integrands use dimensions 0-1 (`get_pixel_2d`), 1D ones the first
/// `get_1d` after them.
pub fn sampler_rmse(
    make_sampler: &(dyn Fn(u32) -> Box<dyn Sampler> + Sync),
    integrands: &[Integrand],
    counts: &[u32],
    seeds: u64,
    mut progress: impl FnMut(),
) -> Vec<Vec<f64>> {
    let mut rmse = vec![vec![0.0; counts.len()]; integrands.len()];
    for (c, &count) in counts.iter().enumerate() {
        let sampler = make_sampler(count);
        let squared_errors: Vec<Vec<f64>> = (0..seeds)
            .into_par_iter()
            .map_init(
                || sampler.clone_sampler(),
                |s, seed| {
                    let pixel = UVec2::new(0, 0);
                    let two_d = sample_points(s.as_mut(), count, 2, seed, pixel);
                    let one_d = sample_points_1d(s.as_mut(), count, seed, pixel);
                    integrands
                        .iter()
                        .map(|g| {
                            let points = if g.dims == 1 { &one_d } else { &two_d };
                            let mean = points.points().map(g.f).sum::<f64>() / count as f64;
                            (mean - g.exact).powi(2)
                        })
                        .collect()
                },
            )
            .collect();
        for (i, row) in rmse.iter_mut().enumerate() {
            let mse = squared_errors.iter().map(|e| e[i]).sum::<f64>() / seeds as f64;
            row[c] = mse.sqrt();
        }
        progress();
    }
    rmse
}

/// Composite Simpson's rule with the largest even number of intervals (odd
/// number of nodes, >= 3) per axis whose tensor grid does not exceed
/// `budget` evaluations. Returns the estimate and the evaluations used.
pub fn simpson(integrand: &Integrand, budget: u32) -> (f64, u32) {
    let per_axis = match integrand.dims {
        1 => budget as f64,
        d => (budget as f64).powf(1.0 / d as f64) + 1e-9,
    } as u32;
    let mut nodes = per_axis.max(3);
    if nodes.is_multiple_of(2) {
        nodes -= 1;
    }
    let h = 1.0 / (nodes - 1) as f64;
    // Weights h/3 (1, 4, 2, 4, ..., 2, 4, 1).
    let weight = |i: u32| -> f64 {
        let w = if i == 0 || i == nodes - 1 {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        w * h / 3.0
    };
    let estimate = match integrand.dims {
        1 => (0..nodes)
            .map(|i| weight(i) * (integrand.f)(&[i as f64 * h]))
            .sum(),
        _ => (0..nodes)
            .flat_map(|i| (0..nodes).map(move |j| (i, j)))
            .map(|(i, j)| weight(i) * weight(j) * (integrand.f)(&[i as f64 * h, j as f64 * h]))
            .sum(),
    };
    (estimate, nodes.pow(integrand.dims as u32))
}

/// Simpson's absolute error at each budget, with the evaluations it used
/// (budgets that round to the same grid are reported once).
pub fn simpson_errors(integrand: &Integrand, budgets: &[u32]) -> Vec<(u32, f64)> {
    let mut errors: Vec<(u32, f64)> = budgets
        .iter()
        .map(|&b| {
            let (estimate, evaluations) = simpson(integrand, b);
            (evaluations, (estimate - integrand.exact).abs())
        })
        .collect();
    errors.dedup_by_key(|e| e.0);
    errors
}

/// Errors at or below this are at the rounding floor of an f64 sum of up to
/// 65536 terms and carry no rate (fitting them would flatten the slope).
pub const EXACT: f64 = 1e-11;

/// Least-squares slope of `ln y` against `ln x`, ignoring exact results;
/// `None` with fewer than two usable points.
pub fn loglog_slope(xs: &[f64], ys: &[f64]) -> Option<f64> {
    let pts: Vec<(f64, f64)> = xs
        .iter()
        .zip(ys)
        .filter(|(x, y)| **x > 0.0 && **y > EXACT)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    Some(sxy / sxx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrands::{integrands_1d, integrands_2d};
    use lumis_core::Vec2;
    use lumis_sampling::Pcg32;

    /// Uniform random numbers, as the `independent` plugin draws them.
    #[derive(Clone)]
    struct Random(Pcg32);

    impl Sampler for Random {
        fn samples_per_pixel(&self) -> u32 {
            1
        }
        fn start_pixel_sample(&mut self, _: UVec2, index: u32, seed: u64) {
            self.0 = Pcg32::new(index as u64, seed);
        }
        fn get_1d(&mut self) -> f32 {
            self.0.next_f32()
        }
        fn get_2d(&mut self) -> Vec2 {
            Vec2::new(self.0.next_f32(), self.0.next_f32())
        }
        fn get_pixel_2d(&mut self) -> Vec2 {
            self.get_2d()
        }
        fn clone_sampler(&self) -> Box<dyn Sampler> {
            Box::new(self.clone())
        }
    }

    #[test]
    fn slope_of_exact_power_laws() {
        let xs = [1.0, 2.0, 4.0, 8.0];
        let ys: Vec<f64> = xs.iter().map(|x: &f64| 3.0 * x.powf(-1.5)).collect();
        assert!((loglog_slope(&xs, &ys).unwrap() + 1.5).abs() < 1e-12);
        assert_eq!(loglog_slope(&xs, &[0.0; 4]), None);
    }

    #[test]
    fn random_points_converge_at_minus_one_half() {
        let counts = powers_of_two(16, 4096);
        let rmse = sampler_rmse(
            &|_| Box::new(Random(Pcg32::new(0, 0))),
            &integrands_2d()[..1],
            &counts,
            256,
            || {},
        );
        let xs: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
        let slope = loglog_slope(&xs, &rmse[0]).unwrap();
        assert!((slope + 0.5).abs() < 0.1, "{slope}");
    }

    /// Simpson's rule: error O(h^4) = O(N^-4) on a smooth 1D integrand, but
    /// only O(N^-1) on a step, where it is no better than a Riemann sum.
    #[test]
    fn simpson_rates_smooth_and_discontinuous() {
        let budgets = powers_of_two(8, 1024);
        let [smooth, step] = [integrands_1d()[0], integrands_1d()[1]];
        let slope = |g: &Integrand| {
            let e = simpson_errors(g, &budgets);
            let xs: Vec<f64> = e.iter().map(|p| p.0 as f64).collect();
            let ys: Vec<f64> = e.iter().map(|p| p.1).collect();
            loglog_slope(&xs, &ys).unwrap()
        };
        assert!((slope(&smooth) + 4.0).abs() < 0.3, "{}", slope(&smooth));
        let s = slope(&step);
        assert!(s > -1.5 && s < -0.5, "{s}");
    }

    #[test]
    fn simpson_is_exact_on_the_ramp() {
        let ramp = integrands_2d()[2];
        assert!(simpson_errors(&ramp, &[9, 100])
            .iter()
            .all(|(_, e)| *e < EXACT));
    }
}
