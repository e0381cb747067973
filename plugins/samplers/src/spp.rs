//! The `spp` parameter every sampler shares.

use lumis_api::{Params, PluginParams, Result};

/// Flattened into every sampler's parameters.
#[derive(Debug, Clone, Copy, PluginParams)]
pub struct SppParams {
    /// samples per pixel
    #[param(default = 16)]
    pub spp: u32,
}

impl SppParams {
    /// `spp`, refusing zero.
    pub fn checked(&self, params: &Params) -> Result<u32> {
        if self.spp == 0 {
            return Err(params.error(Self::KEYS.spp, "must be at least 1"));
        }
        Ok(self.spp)
    }
}
