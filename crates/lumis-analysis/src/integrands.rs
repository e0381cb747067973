//! Test integrands on `[0,1]^d` with exact integrals: smooth, discontinuous,
//! linear and oscillating, the cases that separate sampling patterns.

use std::f64::consts::PI;

use statrs::function::erf::erf;

/// A function on `[0,1]^dims` and its exact integral.
#[derive(Debug, Clone, Copy)]
pub struct Integrand {
    pub name: &'static str,
    pub dims: usize,
    pub f: fn(&[f64]) -> f64,
    pub exact: f64,
}

const SIGMA: f64 = 0.2;
const DISK_RADIUS: f64 = 0.4;
const COSINE_FREQUENCY: f64 = 7.0;
const STEP: f64 = 1.0 / 3.0;

fn gaussian(x: f64) -> f64 {
    (-(x - 0.5) * (x - 0.5) / (2.0 * SIGMA * SIGMA)).exp()
}

/// `int_0^1 exp(-(x - 1/2)^2 / (2 s^2)) dx = s sqrt(2 pi) erf(1 / (2 sqrt(2) s))`.
fn gaussian_integral() -> f64 {
    SIGMA * (2.0 * PI).sqrt() * erf(0.5 / (2f64.sqrt() * SIGMA))
}

/// The four 2D integrands of the convergence study.
pub fn integrands_2d() -> Vec<Integrand> {
    vec![
        Integrand {
            name: "gaussian",
            dims: 2,
            f: |p| gaussian(p[0]) * gaussian(p[1]),
            exact: gaussian_integral().powi(2),
        },
        Integrand {
            name: "disk",
            dims: 2,
            f: |p| {
                let (x, y) = (p[0] - 0.5, p[1] - 0.5);
                if x * x + y * y < DISK_RADIUS * DISK_RADIUS {
                    1.0
                } else {
                    0.0
                }
            },
            exact: PI * DISK_RADIUS * DISK_RADIUS,
        },
        Integrand {
            name: "ramp",
            dims: 2,
            f: |p| p[0] + p[1],
            exact: 1.0,
        },
        Integrand {
            name: "cosines",
            dims: 2,
            // A whole number of periods along each axis integrates to zero,
            // so the exact value is 1; 7 periods defeat coarse strata.
            f: |p| {
                (1.0 + (2.0 * PI * COSINE_FREQUENCY * p[0]).cos())
                    * (1.0 + (2.0 * PI * COSINE_FREQUENCY * p[1]).cos())
            },
            exact: 1.0,
        },
    ]
}

/// The 1D integrands: smooth, and a step not aligned with any binary or
/// Simpson grid.
pub fn integrands_1d() -> Vec<Integrand> {
    vec![
        Integrand {
            name: "gaussian-1d",
            dims: 1,
            f: |p| gaussian(p[0]),
            exact: gaussian_integral(),
        },
        Integrand {
            name: "step-1d",
            dims: 1,
            f: |p| if p[0] < STEP { 1.0 } else { 0.0 },
            exact: STEP,
        },
    ]
}

/// The built-in integrand named `name`, in 2D or 1D.
pub fn integrand(name: &str) -> Option<Integrand> {
    integrands_2d()
        .into_iter()
        .chain(integrands_1d())
        .find(|g| g.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each exact integral against a fine midpoint rule.
    #[test]
    fn exact_integrals_match_fine_quadrature() {
        let n = 2000;
        let h = 1.0 / n as f64;
        for g in integrands_2d() {
            let mut sum = 0.0;
            for i in 0..n {
                for j in 0..n {
                    sum += (g.f)(&[(i as f64 + 0.5) * h, (j as f64 + 0.5) * h]);
                }
            }
            let tolerance = if g.name == "disk" { 2e-4 } else { 1e-6 };
            assert!((sum * h * h - g.exact).abs() < tolerance, "{}", g.name);
        }
        for g in integrands_1d() {
            let sum: f64 = (0..n * 100)
                .map(|i| (g.f)(&[(i as f64 + 0.5) * h / 100.0]))
                .sum();
            assert!((sum * h / 100.0 - g.exact).abs() < 1e-5, "{}", g.name);
        }
    }
}
