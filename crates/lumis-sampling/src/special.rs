//! Special functions the Beckmann distribution needs, in double precision:
//! its masking term uses `erf`, sampling its visible slopes inverts it.

use std::f64::consts::PI;

/// The error function (musl's, through the `libm` crate: correct to an ulp).
#[inline]
pub fn erf(x: f64) -> f64 {
    libm::erf(x)
}

/// The inverse error function on (-1, 1); +-infinity at +-1.
///
/// Giles' single-precision rational approximation ("Approximating the
/// erfinv function", GPU Computing Gems, 2011) as the starting point, then
/// Newton steps on `erf(x) - y` (derivative `2/sqrt(pi) exp(-x^2)`) to full
/// double precision, so that sampling by inversion and the density that
/// uses `erf` agree to rounding.
pub fn erf_inv(y: f64) -> f64 {
    if y <= -1.0 {
        return f64::NEG_INFINITY;
    }
    if y >= 1.0 {
        return f64::INFINITY;
    }
    let w = -((1.0 - y) * (1.0 + y)).ln();
    let mut x = if w < 5.0 {
        let w = w - 2.5;
        let mut p = 2.810_226_36e-08;
        for c in [
            3.432_739_39e-07,
            -3.523_387_7e-06,
            -4.391_506_54e-06,
            0.000_218_580_87,
            -0.001_253_725_03,
            -0.004_177_681_64,
            0.246_640_727,
            1.501_409_41,
        ] {
            p = c + p * w;
        }
        p * y
    } else {
        let w = w.sqrt() - 3.0;
        let mut p = -0.000_200_214_257;
        for c in [
            0.000_100_950_558,
            0.001_349_343_22,
            -0.003_673_428_44,
            0.005_739_507_73,
            -0.007_622_461_3,
            0.009_438_870_47,
            1.001_674_06,
            2.832_976_82,
        ] {
            p = c + p * w;
        }
        p * y
    };
    for _ in 0..3 {
        let slope = 2.0 / PI.sqrt() * (-x * x).exp();
        if slope == 0.0 {
            break;
        }
        x -= (erf(x) - y) / slope;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_inv_inverts_erf_across_the_range() {
        for i in -999..=999 {
            let y = i as f64 / 1000.0;
            let x = erf_inv(y);
            assert!(
                (erf(x) - y).abs() < 1e-14,
                "y = {y}: erf(erf_inv) = {}",
                erf(x)
            );
        }
        for y in [1.0 - 1e-12, -1.0 + 1e-12, 1e-300] {
            assert!((erf(erf_inv(y)) - y).abs() <= 1e-15 * y.abs().max(1e-3));
        }
        assert_eq!(erf_inv(1.0), f64::INFINITY);
        assert_eq!(erf_inv(0.0), 0.0);
    }
}
