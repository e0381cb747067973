//! Standard BSDFs: diffuse, Blinn, rough conductor and mirror, smooth and
//! rough dielectric, plastic; with the microfacet and Fresnel machinery
//! they share.

mod blinn;
mod conductor;
mod dielectric;
mod diffuse;
pub mod fresnel;
mod lobe_sampling;
pub mod microfacet;
mod plastic;

pub use blinn::Blinn;
pub use conductor::{Conductor, ConductorFresnel};
pub use dielectric::Dielectric;
pub use diffuse::{Diffuse, DiffuseSampling};
pub use lobe_sampling::LobeSampling;
pub use plastic::Plastic;

use std::sync::Arc;

use lumis_core::{Registry, Result};

/// Registers every BSDF of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
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
    registry.add_bsdf(plastic::SPEC, |p| Ok(Arc::new(Plastic::from_params(p)?)))
}
