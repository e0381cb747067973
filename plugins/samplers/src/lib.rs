//! Standard sample generators.

mod independent;

pub use independent::IndependentSampler;

use lumis_core::{Registry, Result};

/// Registers every sampler of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_sampler(independent::SPEC, |p| {
        Ok(Box::new(IndependentSampler::from_params(p)?))
    })
}
