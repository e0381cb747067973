//! Standard integrators: `path` (unidirectional path tracing) and `direct`
//! (direct lighting only), sharing one direct-lighting estimator.

mod direct;
mod estimator;
mod path;

pub use direct::DirectIntegrator;
pub use estimator::{Estimator, Heuristic, MisEstimator, Strategy, VertexPlan};
pub use path::PathIntegrator;

use lumis_core::{Registry, Result};

/// Registers every integrator of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_integrator(path::SPEC, |p| {
        Ok(Box::new(PathIntegrator::from_params(p)?))
    })?;
    registry.add_integrator(direct::SPEC, |p| {
        Ok(Box::new(DirectIntegrator::from_params(p)?))
    })
}
