//! `[plugins] load = [...]`: plugin libraries the scene needs.

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::{Error, Location, ParamSpec, ParamType, ParamValue, Params, Result};

use super::document::Located;

pub(crate) const PLUGINS_PARAMS: &[ParamSpec] = &[ParamSpec::with_default(
    "load",
    ParamType::StringArray,
    ParamValue::Array(&[]),
    "plugin libraries to load, relative to the scene file",
)];

/// The libraries of `[plugins] load`, resolved against the scene's directory.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct PluginLibraries {
    pub paths: Vec<PathBuf>,
    /// Where `load` was written.
    pub location: Option<Location>,
}

impl PluginLibraries {
    /// An error about loading one of the libraries, located at `load`.
    pub fn error(&self, message: impl std::fmt::Display) -> Error {
        let message = format!("[plugins] key 'load': {message}");
        match &self.location {
            Some(location) => Error::at(location, message),
            None => Error::msg(message),
        }
    }
}

/// Reads `[plugins]` (no libraries when absent).
pub(crate) fn plugin_libraries(table: Option<Located<Table>>) -> Result<PluginLibraries> {
    let Some((table, location)) = table else {
        return Ok(PluginLibraries::default());
    };
    let params = Params::new("[plugins]", &table, location.clone(), PLUGINS_PARAMS, &[])?;
    let paths: Vec<PathBuf> = params.get("load")?;
    params.finish()?;
    Ok(PluginLibraries {
        paths,
        location: Some(
            table
                .get("load")
                .map_or(location, |node| node.location.clone()),
        ),
    })
}
