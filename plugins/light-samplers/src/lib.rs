//! Standard light-selection strategies.

mod uniform;

pub use uniform::UniformLightSampler;

use lumis_core::{Registry, Result};

/// Registers every light sampler of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_light_sampler(uniform::SPEC, |_p, lights| {
        Ok(Box::new(UniformLightSampler::new(lights.len())))
    })
}
