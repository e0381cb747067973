//! The L2-star discrepancy: how far a point set's empirical distribution is
//! from uniform, averaged over all boxes anchored at the origin.

use rayon::prelude::*;

use crate::points::PointSet;

/// Exact L2-star discrepancy by Warnock's formula (Warnock 1972,
/// "Computational investigations of low-discrepancy point sets"):
///
/// T^2 = 3^-d - (2^(1-d) / N) sum_i prod_k (1 - x_ik^2)
///       + (1 / N^2) sum_i sum_j prod_k (1 - max(x_ik, x_jk)).
///
/// O(N^2 d); the double sum runs in parallel and in f64.
pub fn l2_star_discrepancy(points: &PointSet) -> f64 {
    let (n, d) = (points.len() as f64, points.dims as i32);
    if points.is_empty() {
        return 0.0;
    }
    let single: f64 = points
        .points()
        .map(|p| p.iter().map(|x| 1.0 - x * x).product::<f64>())
        .sum();
    let double: f64 = (0..points.len())
        .into_par_iter()
        .map(|i| {
            let a = points.point(i);
            points
                .points()
                .map(|b| {
                    a.iter()
                        .zip(b)
                        .map(|(x, y)| 1.0 - x.max(*y))
                        .product::<f64>()
                })
                .sum::<f64>()
        })
        .sum();
    let t2 = 3f64.powi(-d) - 2f64.powi(1 - d) / n * single + double / (n * n);
    t2.max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    #[test]
    fn one_point_closed_forms() {
        // 1D, one point x: T^2 = int_0^1 (1[x < t] - t)^2 dt
        //                      = int_0^x t^2 dt + int_x^1 (1 - t)^2 dt.
        for x in [0.0, 0.25, 0.5, 0.9] {
            let p = PointSet {
                dims: 1,
                coords: vec![x],
            };
            let exact = (x.powi(3) / 3.0 + (1.0 - x).powi(3) / 3.0).sqrt();
            assert!((l2_star_discrepancy(&p) - exact).abs() < 1e-12, "{x}");
        }
        // 2D, the point (1/2, 1/2): int (1[t > 1/2] - t1 t2)^2 dt
        // = int t1^2 t2^2 - 2 int_{t > 1/2} t1 t2 + int_{t > 1/2} 1.
        let p = PointSet {
            dims: 2,
            coords: vec![0.5, 0.5],
        };
        let t2 = 1.0 / 9.0 - 2.0 * (3.0f64 / 8.0).powi(2) + 0.25;
        assert!((l2_star_discrepancy(&p) - t2.sqrt()).abs() < 1e-12);
    }

    /// Against a Monte Carlo estimate of the defining integral
    /// int_[0,1]^2 (#{x_i in [0,t)} / N - t_1 t_2)^2 dt.
    #[test]
    fn matches_monte_carlo_of_the_definition() {
        let mut rng = Pcg32::new(4, 5);
        let coords: Vec<f64> = (0..40).map(|_| rng.next_f32() as f64).collect();
        let p = PointSet { dims: 2, coords };
        let m = 400_000;
        let mut sum = 0.0;
        let mut sum2 = 0.0;
        for _ in 0..m {
            let t = [rng.next_f32() as f64, rng.next_f32() as f64];
            let inside = p.points().filter(|q| q[0] < t[0] && q[1] < t[1]).count() as f64;
            let v = (inside / p.len() as f64 - t[0] * t[1]).powi(2);
            sum += v;
            sum2 += v * v;
        }
        let mean = sum / m as f64;
        let se = ((sum2 / m as f64 - mean * mean) / m as f64).sqrt();
        let exact = l2_star_discrepancy(&p).powi(2);
        assert!(
            (mean - exact).abs() < 5.0 * se,
            "{mean} vs {exact} (se {se})"
        );
    }
}
