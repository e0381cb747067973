//! Standard lights: a point light, area lights for quads and triangles, and
//! a constant environment.

mod area;
mod constant;
mod point;
mod quad;
mod triangle;

pub use area::{AreaLight, Emission, PlanarShape};
pub use constant::ConstantLight;
pub use point::PointLight;
pub use quad::{Quad, QuadLight};
pub use triangle::{Triangle, TriangleLight};

use lumis_core::{Registry, Result};

/// Registers every light of this crate.
pub fn register(registry: &mut Registry) -> Result<()> {
    registry.add_light(point::SPEC, |p, shape| {
        Ok(Box::new(PointLight::from_params(p, shape)?))
    })?;
    registry.add_light(quad::SPEC, |p, shape| {
        Ok(Box::new(QuadLight::from_params(p, shape)?))
    })?;
    registry.add_light(triangle::SPEC, |p, shape| {
        Ok(Box::new(TriangleLight::from_params(p, shape)?))
    })?;
    registry.add_light(constant::SPEC, |p, shape| {
        Ok(Box::new(ConstantLight::from_params(p, shape)?))
    })
}
