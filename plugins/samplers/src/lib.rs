//! Standard sample generators.

mod dimensions;
mod halton;
mod hammersley;
mod independent;
#[cfg(test)]
mod net_check;
mod poisson_disk;
mod sobol;
mod spp;
mod stratified;
mod zsobol;

pub use halton::HaltonSampler;
pub use hammersley::HammersleySampler;
pub use independent::IndependentSampler;
pub use poisson_disk::PoissonDiskSampler;
pub use sobol::{
    DimensionMapping as SobolDimensionMapping, Dimensions as SobolDimensions, Randomization,
    Randomize as SobolRandomize, SobolSampler,
};
pub use stratified::{strata_grid, StratifiedSampler};
pub use zsobol::ZSobolSampler;

use lumis_api::{Registrar, Result};

/// Registers every sampler of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_sampler(independent::SPEC, |p| {
        Ok(Box::new(IndependentSampler::from_params(p)?))
    })?;
    registry.add_sampler(stratified::SPEC, |p| {
        Ok(Box::new(StratifiedSampler::from_params(p)?))
    })?;
    registry.add_sampler(halton::SPEC, |p| {
        Ok(Box::new(HaltonSampler::from_params(p)?))
    })?;
    registry.add_sampler(hammersley::SPEC, |p| {
        Ok(Box::new(HammersleySampler::from_params(p)?))
    })?;
    registry.add_sampler(sobol::SPEC, SobolSampler::from_params)?;
    registry.add_sampler(zsobol::SPEC, |p| {
        Ok(Box::new(ZSobolSampler::from_params(p)?))
    })?;
    registry.add_sampler(poisson_disk::SPEC, |p| {
        Ok(Box::new(PoissonDiskSampler::from_params(p)?))
    })
}
