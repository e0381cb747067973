//! `[integrator] clamp`: the cap on each camera sample's radiance, which
//! the render driver applies to every integrator's samples alike
//! (`lumis_render::clamp_radiance`), so no integrator declares it.

use lumis_core::doc::{Table, Value};
use lumis_core::{Error, ParamSpec, ParamType, Result};

/// The key, taken out of the `[integrator]` table before the integrator
/// plugin checks its own parameters.
pub(crate) const CLAMP_KEY: &str = "clamp";

pub(crate) const CLAMP_PARAMS: &[ParamSpec] = &[ParamSpec::optional(
    CLAMP_KEY,
    ParamType::Float,
    "the largest component a camera sample's radiance may have, a positive number",
)];

/// Takes `clamp` out of the integrator's table: a positive, finite
/// number, or absent (no clamping).
pub(crate) fn take_clamp(integrator: &mut Table) -> Result<Option<f32>> {
    let Some(entry) = integrator.remove(CLAMP_KEY) else {
        return Ok(None);
    };
    let value = match entry.node.value {
        Value::Float(v) => v,
        Value::Int(v) => v as f64,
        ref other => {
            return Err(Error::at(
                &entry.node.location,
                format!(
                    "[integrator] clamp: expected a positive number (the largest component a sample's radiance may have), found {}",
                    other.type_name()
                ),
            ))
        }
    };
    if !(value > 0.0 && (value as f32).is_finite()) {
        return Err(Error::at(
            &entry.node.location,
            format!("[integrator] clamp = {value}: expected a positive, finite number"),
        ));
    }
    Ok(Some(value as f32))
}
