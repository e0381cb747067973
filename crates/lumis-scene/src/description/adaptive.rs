//! `[adaptive]`: adaptive sampling, which the render driver does for every
//! sampler alike (`lumis_render::AdaptiveSampling`), so no sampler
//! declares it. lumis 0.1.0 read it inside the sampler's table,
//! `[sampler] adaptive = { ... }`, which still reads, with a warning.

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, Location, Params, PluginParams, Result};

use super::document::Located;

/// The table's name, and the key of its deprecated place in `[sampler]`.
pub(crate) const ADAPTIVE_KEY: &str = "adaptive";

/// The keys of `[adaptive]`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct AdaptiveParams {
    /// samples every pixel takes before it may stop, and between checks
    /// (at least 2)
    min_spp: u32,
    /// samples no pixel goes beyond (default: the sampler's spp, which it
    /// sets)
    max_spp: Option<u32>,
    /// relative error under which a pixel stops
    threshold: f32,
}

/// `adaptive` as written; `max_spp` is settled against the sampler's
/// `spp` once the sampler exists.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AdaptiveDescription {
    pub min_spp: u32,
    pub max_spp: Option<u32>,
    pub threshold: f32,
    pub location: Location,
}

/// Reads `[adaptive]`, or the deprecated `[sampler] adaptive` (with a
/// warning in `warnings`; both is an error), and gives the sampler `spp =
/// max_spp` where its table sets no `spp` (one that sets another is an
/// error).
pub(crate) fn take_adaptive(
    adaptive: Option<Located<Table>>,
    sampler: &mut Table,
    warnings: &mut Vec<String>,
) -> Result<Option<AdaptiveDescription>> {
    let deprecated = sampler.remove(ADAPTIVE_KEY);
    let (table, location) = match (adaptive, deprecated) {
        (None, None) => return Ok(None),
        (Some(located), None) => located,
        (Some(_), Some(entry)) => {
            return Err(Error::at(
                &entry.key_location,
                "[sampler] adaptive and an [adaptive] table both given; keep the [adaptive] table",
            ))
        }
        (None, Some(entry)) => {
            let location = entry.node.location.clone();
            let Value::Table(table) = entry.node.value else {
                return Err(Error::at(
                    &location,
                    format!(
                        "[sampler] adaptive: expected a table {{ min_spp = N, max_spp = M, threshold = T }}, found {}",
                        entry.node.value.type_name()
                    ),
                ));
            };
            warnings.push(format!(
                "{location}: [sampler] adaptive is deprecated; write its keys as an [adaptive] table (--set adaptive.min_spp=...)"
            ));
            (table, location)
        }
    };
    let table = &table;
    let params = Params::new(
        "[adaptive]",
        table,
        location.clone(),
        AdaptiveParams::SPECS,
        &[],
    )?;
    let AdaptiveParams {
        min_spp,
        max_spp,
        threshold,
    } = AdaptiveParams::read(&params)?;
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
                        "[sampler] spp and [adaptive] max_spp = {max_spp} disagree: give one of them (--spp sets spp)"
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
