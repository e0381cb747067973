//! Standard lights: point and spot lights, area lights for quads, triangles
//! and spheres (each sampled by area or by solid angle), and environments:
//! constant, or an image.

mod area;
mod constant;
mod emission;
mod envmap;
mod point;
mod quad;
mod sphere;
mod spot;
mod textured;
mod triangle;

pub use area::{AreaLight, Emission, EmissionParams, PlanarShape, Sampling};
pub use constant::ConstantLight;
pub use envmap::{EnvMapLight, EnvSampling, Equirect};
pub use point::PointLight;
pub use quad::{Quad, QuadLight};
pub use sphere::SphereLight;
pub use spot::SpotLight;
pub use textured::TexturedAreaLight;
pub use triangle::{Triangle, TriangleLight};

use lumis_api::{Registrar, Result};

/// Registers every light of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_light(point::SPEC, |p, shape| {
        Ok(Box::new(PointLight::from_params(p, shape)?))
    })?;
    registry.add_light(quad::SPEC, QuadLight::make)?;
    registry.add_light(triangle::SPEC, TriangleLight::make)?;
    registry.add_light(sphere::SPEC, |p, shape| {
        Ok(Box::new(SphereLight::from_params(p, shape)?))
    })?;
    registry.add_light(spot::SPEC, |p, shape| {
        Ok(Box::new(SpotLight::from_params(p, shape)?))
    })?;
    registry.add_light(constant::SPEC, |p, shape| {
        Ok(Box::new(ConstantLight::from_params(p, shape)?))
    })?;
    registry.add_light(envmap::SPEC, |p, shape| {
        Ok(Box::new(EnvMapLight::from_params(p, shape)?))
    })
}
