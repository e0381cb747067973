//! Standard integrators.

mod path;

pub use path::{Heuristic, PathIntegrator, Strategy};

use lumis_core::{Registry, Result};

/// Registers every integrator of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_integrator(path::SPEC, |p| {
        Ok(Box::new(PathIntegrator::from_params(p)?))
    })
}
