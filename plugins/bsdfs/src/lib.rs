//! Standard BSDFs: diffuse, Blinn, rough conductor and mirror, smooth and
//! rough dielectric, plastic; the `twosided` and `normalmap` adapters;
//! with the microfacet and Fresnel machinery they share.

mod blinn;
mod conductor;
mod dielectric;
mod diffuse;
pub mod fresnel;
mod lobe_sampling;
mod metal_fresnel;
mod metal_params;
pub mod microfacet;
mod normalmap;
mod plastic;
mod twosided;

pub use blinn::{Blinn, BlinnParams, BlinnSampling};
pub use conductor::{Conductor, ConductorParams};
pub use dielectric::{Dielectric, DielectricParams};
pub use diffuse::{Diffuse, DiffuseParams, DiffuseSampling};
pub use lobe_sampling::{LobeSampling, MicrofacetLobeSampling};
pub use metal_fresnel::{ConductorFresnel, MetalFresnel};
pub use metal_params::{MetalName, MetalParams};
pub use normalmap::{NormalMap, NormalMapParams};
pub use plastic::{Plastic, PlasticParams};
pub use twosided::{TwoSided, TwoSidedParams};

use std::sync::Arc;

use lumis_api::{Registrar, Result};

/// Registers every BSDF of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_bsdf(diffuse::SPEC, |p| Ok(Arc::new(Diffuse::from_params(p)?)))?;
    registry.add_bsdf(blinn::SPEC, |p| Ok(Arc::new(Blinn::from_params(p)?)))?;
    registry.add_bsdf(conductor::SPEC, |p| {
        Ok(Arc::new(Conductor::from_params(p)?))
    })?;
    registry.add_bsdf(conductor::MIRROR_SPEC, |p| {
        Ok(Arc::new(Conductor::mirror_from_params(p)?))
    })?;
    registry.add_bsdf(dielectric::SPEC, |p| {
        Ok(Arc::new(Dielectric::from_params(p)?))
    })?;
    registry.add_bsdf(plastic::SPEC, |p| Ok(Arc::new(Plastic::from_params(p)?)))?;
    registry.add_bsdf(twosided::SPEC, |p| Ok(Arc::new(TwoSided::from_params(p)?)))?;
    registry.add_bsdf(normalmap::SPEC, |p| {
        Ok(Arc::new(NormalMap::from_params(p)?))
    })
}
