//! Denoisers: Intel Open Image Denoise 2 as the `oidn` plugin.
//!
//! `build.rs` provisions the library (system install, `OIDN_DIR`, else the
//! official runtime from the `pyoidn` wheel, cached outside the source
//! tree); `ffi` binds the few C calls needed, the crate's only unsafe code.

mod ffi;
mod oidn;

pub use oidn::{OidnDenoiser, OidnParams, Quality};

use lumis_api::{Registrar, Result};

/// The version of the Open Image Denoise library this process loaded, as
/// `(major, minor, patch)`.
pub fn oidn_version() -> Result<(u32, u32, u32)> {
    let version = ffi::Device::cpu()?.version()?;
    Ok((version / 10000, version / 100 % 100, version % 100))
}

/// Registers every denoiser of this crate.
pub fn register(registry: &mut dyn Registrar) -> Result<()> {
    registry.add_denoiser(oidn::SPEC, oidn::OidnDenoiser::from_params)
}
