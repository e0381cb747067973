//! Sampling building blocks: warps from the unit square to shapes and
//! directions, each with its density; random number generation; and the
//! multiple importance sampling heuristics.

pub mod mis;
pub mod rng;
pub mod warp;

pub use mis::{balance_heuristic, power_heuristic};
pub use rng::{hash_u64, Pcg32};
