//! The `spp` parameter every sampler shares.

use lumis_core::{ParamSpec, ParamType, Params, Result};

pub const SPP_PARAM: ParamSpec =
    ParamSpec::with_default("spp", ParamType::Int, "16", "samples per pixel");

/// Reads `spp`, refusing zero.
pub fn read_spp(params: &Params) -> Result<u32> {
    let spp: u32 = params.get("spp")?;
    if spp == 0 {
        return Err(params.error("spp", "must be at least 1"));
    }
    Ok(spp)
}
