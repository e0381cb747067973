//! Standard light-selection strategies.

mod bvh;
mod power;
mod uniform;

pub use bvh::BvhLightSampler;
pub use power::PowerLightSampler;
pub use uniform::UniformLightSampler;

use lumis_api::{Registrar, Result};

/// Registers every light sampler of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_light_sampler(uniform::SPEC, |_p, lights| {
        Ok(Box::new(UniformLightSampler::new(lights.len())))
    })?;
    registry.add_light_sampler(power::SPEC, |_p, lights| {
        Ok(Box::new(PowerLightSampler::new(lights)))
    })?;
    registry.add_light_sampler(bvh::SPEC, |_p, lights| {
        Ok(Box::new(BvhLightSampler::new(lights)))
    })
}
