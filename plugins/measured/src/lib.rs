//! Measured BRDFs: the MERL table format (reader, writer, trilinear
//! lookup), the `measured` BSDF plugin and its importance sampling
//! strategies (cosine, the factored representation of Lawrence,
//! Rusinkiewicz and Ramamoorthi 2004, a tabulated 2D distribution per
//! outgoing elevation, the tensor's own factors), the cache of their
//! precomputation, the tensor (CP) approximation of a table the plugin can
//! render from instead, and
//! the tabulation of any lumis BSDF as a MERL table.

pub mod cache;
pub mod compress;
pub mod cp;
pub mod factored;
pub mod grid;
mod measured;
pub mod merl;
pub mod mixture;
pub mod precompute;
pub mod reflectance;
pub mod tabulate;
pub mod tabulated;
pub mod tensor;
pub mod tensor_sampling;

pub use measured::{Measured, MeasuredParams, MeasuredRepresentation, MeasuredSampling, SPEC};
pub use merl::MerlTable;

use std::sync::Arc;

use lumis_api::{Registrar, Result};

/// Registers the `measured` BSDF.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_bsdf(SPEC, |p| Ok(Arc::new(Measured::from_params(p)?)))
}
