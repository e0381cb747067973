//! Standard textures: `constant`, `checkerboard` and `image` (PNG, JPEG or
//! EXR, wrapped and filtered). Every texture but `constant` takes the
//! [`UvTransform`](lumis_api::UvTransform) keys.

mod checkerboard;
mod constant;
pub mod image;

pub use checkerboard::{Checkerboard, CheckerboardParams};
pub use constant::{Constant, ConstantParams};
pub use image::{Encoding, ImageFilter, ImageParams, ImageTexture, Texels, Wrap};

use std::sync::Arc;

use lumis_api::{Registrar, Result};

/// Registers every texture of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_texture(constant::SPEC, |p| Ok(Arc::new(Constant::from_params(p)?)))?;
    registry.add_texture(checkerboard::SPEC, |p| {
        Ok(Arc::new(Checkerboard::from_params(p)?))
    })?;
    registry.add_texture(image::SPEC, |p| Ok(Arc::new(ImageTexture::from_params(p)?)))
}
