//! The statistical test kit of lumis.
//!
//! [`chi_square()`] checks that a routine drawing directions is distributed
//! exactly as the pdf it claims, with Pearson's chi-square test over a grid
//! of equal-solid-angle bins (the approach of Mitsuba's and pbrt's sampling
//! tests). [`adapters`] turn a BSDF's `sample_f`/`pdf` or a light's
//! `sample_li`/`pdf_li` into such a pair. [`uniformity_2d`] tests that
//! randomised sample points are uniform.

pub mod adapters;
pub mod bsdf_suite;
pub mod chi_square;
#[cfg(feature = "integrators")]
pub mod integrator_suite;
pub mod light_sampler_suite;
pub mod light_suite;
pub mod lobe_zoom;
pub mod outcome;
#[cfg(feature = "integrators")]
pub mod plugins;
pub mod quadrature;
pub mod sampler_suite;
pub mod sweep;
pub mod test_map;
pub mod uniformity;

pub use chi_square::{chi_square, ChiSquareConfig, ChiSquareReport};
pub use lobe_zoom::chi_square_zoomed;
pub use uniformity::{uniformity_2d, UniformityReport};

/// The per-test significance level that keeps the chance of any false
/// alarm among `tests` tests at `alpha` (Šidák correction).
pub fn corrected_significance(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sidak_correction() {
        assert!((corrected_significance(0.01, 1) - 0.01).abs() < 1e-12);
        let a = corrected_significance(0.01, 100);
        assert!((1.0 - (1.0 - a).powi(100) - 0.01).abs() < 1e-9);
    }
}
