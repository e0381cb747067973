//! Standard BSDFs.

mod diffuse;

pub use diffuse::{Diffuse, DiffuseSampling};

use std::sync::Arc;

use lumis_core::{Registry, Result};

/// Registers every BSDF of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_bsdf(diffuse::SPEC, |p| Ok(Arc::new(Diffuse::from_params(p)?)))
}
