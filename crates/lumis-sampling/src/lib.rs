//! Sampling building blocks: warps from the unit square to shapes and
//! directions, each with its density; random number generation; the
//! low-discrepancy sequences and their randomisations; and the multiple
//! importance sampling heuristics; piecewise-constant distributions; the
//! half/difference and projected-deviation parameterizations of direction
//! pairs and their Jacobians.

pub mod distribution;
pub mod distribution2d;
pub mod guide_table;
pub mod halfdiff;
pub mod mis;
pub mod pdv;
pub mod permutation;
pub mod poisson_disk;
pub mod primes;
pub mod radical_inverse;
pub mod real;
pub mod rng;
pub mod scramble;
pub mod simd;
pub mod sobol;
pub mod special;
pub mod spherical_rectangle;
pub mod spherical_triangle;
pub mod warp;

pub use distribution::Distribution1D;
pub use distribution2d::Distribution2D;
pub use guide_table::GuideTable;
pub use mis::{balance_heuristic, power_heuristic};
pub use permutation::permutation_element;
pub use radical_inverse::{
    inverse_radical_inverse, radical_inverse, scrambled_radical_inverse, DigitScramble,
    ONE_MINUS_EPSILON,
};
pub use rng::{hash_u64, hash_with, pixel_key, Pcg32};
pub use scramble::{
    fixed_to_unit_f32, laine_karras_permutation, owen_scramble, reversed_to_unit_f32, xor_scramble,
};
pub use sobol::{
    sobol_reversed_columns, sobol_reversed_run, sobol_reversed_tabulated, sobol_reversed_u32,
    sobol_u32, SOBOL_DIMENSIONS,
};
pub use spherical_rectangle::SphericalRectangle;
pub use spherical_triangle::{
    SphericalTriangle, MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA,
};
