//! Sample-pattern analysis: where a sampler puts its points and what that
//! buys. Discrepancy ([`discrepancy`]), power spectra ([`spectrum`]),
//! convergence on integrands with known integrals against Simpson's rule
//! ([`convergence`], [`integrands`]), image error metrics against a
//! reference ([`image_error`]) and its split into bias² and variance
//! ([`bias_variance`]), stratified sampling and its allocations
//! ([`stratification`]), the lecture's biased estimators (half the sample
//! maximum, [`half_max`]; the `N/(N+1)` mean, [`scaled_mean`]), the
//! check of a measured variance against a formula ([`sample_variance`]),
//! and the PNG plots ([`plot`]).

pub mod bias_variance;
pub mod convergence;
pub mod discrepancy;
pub mod half_max;
pub mod image_error;
pub mod integrands;
pub mod plot;
pub mod points;
pub mod sample_variance;
pub mod scaled_mean;
pub mod spectrum;
pub mod stratification;

pub use discrepancy::l2_star_discrepancy;
pub use points::{sample_points, sample_points_1d, PointSet};
