//! Sample-pattern analysis: where a sampler puts its points and what that
//! buys. Discrepancy ([`discrepancy`]), power spectra ([`spectrum`]),
//! convergence on integrands with known integrals against Simpson's rule
//! ([`convergence`], [`integrands`]), image error metrics against a
//! reference ([`image_error`]) and its split into bias² and variance
//! ([`bias_variance`]), and the PNG plots ([`plot`]).

pub mod bias_variance;
pub mod convergence;
pub mod discrepancy;
pub mod image_error;
pub mod integrands;
pub mod plot;
pub mod points;
pub mod spectrum;

pub use discrepancy::l2_star_discrepancy;
pub use points::{sample_points, sample_points_1d, PointSet};
