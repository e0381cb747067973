//! `[sampler] adaptive = { min_spp, max_spp, threshold }`: adaptive
//! sampling, which the render driver does for every sampler alike
//! (`lumis_render::AdaptiveSampling`), so no sampler declares it.

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, Location, ParamSpec, ParamType, Params, Result};

const ADAPTIVE_KEY: &str = "adaptive";

pub(crate) const ADAPTIVE_PARAMS: &[ParamSpec] = &[
    ParamSpec::required(
        "min_spp",
        ParamType::Int,
        "samples every pixel takes before it may stop, and between checks (at least 2)",
    ),
    ParamSpec::optional(
        "max_spp",
        ParamType::Int,
        "samples no pixel goes beyond (default: the sampler's spp, which it sets)",
    ),
    ParamSpec::required(
        "threshold",
        ParamType::Float,
        "relative error under which a pixel stops",
    ),
];

/// `adaptive` as written; `max_spp` is settled against the sampler's
/// `spp` once the sampler exists.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AdaptiveDescription {
    pub min_spp: u32,
    pub max_spp: Option<u32>,
    pub threshold: f32,
    pub location: Location,
}

/// Takes `adaptive` out of the sampler's table, and gives the sampler
/// `spp = max_spp` where the table sets no `spp` (one that sets another is
/// an error).
pub(crate) fn take_adaptive(sampler: &mut Table) -> Result<Option<AdaptiveDescription>> {
    let Some(entry) = sampler.remove(ADAPTIVE_KEY) else {
        return Ok(None);
    };
    let location = entry.node.location.clone();
    let Value::Table(table) = &entry.node.value else {
        return Err(Error::at(
            &location,
            format!(
                "[sampler] adaptive: expected a table {{ min_spp = N, max_spp = M, threshold = T }}, found {}",
                entry.node.value.type_name()
            ),
        ));
    };
    let params = Params::new(
        "[sampler] adaptive",
        table,
        location.clone(),
        ADAPTIVE_PARAMS,
        &[],
    )?;
    let min_spp: u32 = params.get("min_spp")?;
    let max_spp: Option<u32> = params.get_opt("max_spp")?;
    let threshold: f32 = params.get("threshold")?;
    params.finish()?;
    if let Some(max_spp) = max_spp {
        match sampler.get("spp") {
            None => sampler.insert(
                "spp",
                Node {
                    value: Value::Int(max_spp as i64),
                    location: location.clone(),
                },
            ),
            Some(Node {
                value: Value::Int(spp),
                ..
            }) if *spp == max_spp as i64 => {}
            Some(node) => {
                return Err(Error::at(
                    &node.location,
                    format!(
                        "[sampler] spp and adaptive.max_spp = {max_spp} disagree: give one of them (--spp sets spp)"
                    ),
                ))
            }
        }
    }
    Ok(Some(AdaptiveDescription {
        min_spp,
        max_spp,
        threshold,
        location,
    }))
}
