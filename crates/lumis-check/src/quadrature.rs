//! Gauss-Legendre quadrature of any order, for the deterministic integrals
//! that statistical tests compare against (albedos, image means).

/// Nodes and weights of the `n`-point Gauss-Legendre rule on `[-1, 1]`:
/// the roots of `P_n` by Newton's method from Tricomi's initial guesses,
/// `P_n` and `P_n'` by the three-term recurrence, weights `2 / ((1 - x^2)
/// P_n'(x)^2)` (Abramowitz and Stegun 25.4.29). Exact for polynomials of
/// degree `2n - 1`.
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    use std::f64::consts::PI;
    let mut rule = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0f64, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 0 { 1.0 } else { p1 };
            let pn_1 = if n == 1 { 1.0 } else { p0 };
            derivative = n as f64 * (x * pn - pn_1) / (x * x - 1.0);
            let step = pn / derivative;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * derivative * derivative)));
    }
    rule
}

/// `int_a^b f` by the `n`-point Gauss-Legendre rule.
pub fn integrate(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
    gauss_legendre(n)
        .iter()
        .map(|&(x, w)| w * f(mid + half * x))
        .sum::<f64>()
        * half
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_are_exact_to_degree_2n_minus_1() {
        for n in [1, 2, 5, 16, 64] {
            let rule = gauss_legendre(n);
            let weights: f64 = rule.iter().map(|r| r.1).sum();
            assert!((weights - 2.0).abs() < 1e-12, "n {n}: {weights}");
            // int_{-1}^{1} x^(2n-2) = 2 / (2n - 1); odd powers vanish.
            let degree = 2 * n - 2;
            let even: f64 = rule.iter().map(|&(x, w)| w * x.powi(degree as i32)).sum();
            assert!(
                (even - 2.0 / (degree as f64 + 1.0)).abs() < 1e-12,
                "n {n}: {even}"
            );
            let odd: f64 = rule
                .iter()
                .map(|&(x, w)| w * x.powi(2 * n as i32 - 1))
                .sum();
            assert!(odd.abs() < 1e-12, "n {n}: {odd}");
        }
        // The 5-point nodes of Abramowitz and Stegun table 25.4.
        let five = gauss_legendre(5);
        assert!(five
            .iter()
            .any(|&(x, _)| (x - 0.906_179_845_938_664).abs() < 1e-14));
        assert!((integrate(f64::sin, 0.0, std::f64::consts::PI, 16) - 2.0).abs() < 1e-13);
    }
}
