//! `[plugins] load = [...]`: plugin libraries the scene needs.

use std::path::PathBuf;

use lumis_core::doc::Table;
use lumis_core::{Error, Location, Params, PluginParams, Result};

use super::document::Located;

/// The keys of `[plugins]`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct PluginsParams {
    /// plugin libraries to load, relative to the scene file
    #[param(default = [])]
    load: Vec<PathBuf>,
}

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
    let params = Params::new(
        "[plugins]",
        &table,
        location.clone(),
        PluginsParams::SPECS,
        &[],
    )?;
    let paths = PluginsParams::read(&params)?.load;
    params.finish()?;
    Ok(PluginLibraries {
        paths,
        location: Some(
            table
                .get(PluginsParams::KEYS.load)
                .map_or(location, |node| node.location.clone()),
        ),
    })
}
