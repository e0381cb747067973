//! The clamp on each camera sample's radiance, which the render driver
//! applies to every integrator's samples alike
//! (`lumis_api::Rgb::clamp_max_component`): `[film] clamp`. lumis 0.1.0 read it
//! in the integrator's table, `[integrator] clamp`, which still reads,
//! with a warning.

use lumis_core::doc::Table;
use lumis_core::params::FromParam;
use lumis_core::{Error, Result};

/// The key, in `[film]` and in its deprecated place in `[integrator]`.
pub(crate) const CLAMP_KEY: &str = "clamp";

/// `value` as a clamp: positive and finite in `f32`.
pub(crate) fn checked(value: f32) -> std::result::Result<f32, String> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(format!("expected a positive, finite number, found {value}"))
    }
}

/// Takes the deprecated `clamp` out of the integrator's table, before the
/// integrator plugin checks its own parameters: the clamp, with a warning
/// in `warnings`; an error where `[film] clamp` is given too.
pub(crate) fn take_deprecated_clamp(
    integrator: &mut Table,
    film_clamp: Option<f32>,
    warnings: &mut Vec<String>,
) -> Result<Option<f32>> {
    let Some(entry) = integrator.remove(CLAMP_KEY) else {
        return Ok(film_clamp);
    };
    let location = &entry.node.location;
    if film_clamp.is_some() {
        return Err(Error::at(
            &entry.key_location,
            "[integrator] clamp and [film] clamp both given; keep [film] clamp",
        ));
    }
    // Read as `[film] clamp` reads it: the parameters' conversion, then
    // the same check.
    let value = f32::from_node(&entry.node)
        .and_then(checked)
        .map_err(|why| Error::at(location, format!("[integrator] clamp: {why}")))?;
    warnings.push(format!(
        "{location}: [integrator] clamp is deprecated; write it as [film] clamp (--set film.clamp=...)"
    ));
    Ok(Some(value))
}
