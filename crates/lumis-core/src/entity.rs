//! A plugin to create: its kind, the `type` that names it and the table of
//! its parameters, each with where it was written.
//!
//! Scene files, command-line tools and importers all describe plugins this
//! way, so [`Registry::create`](crate::Registry::create) is the one path by
//! which any plugin is made, and every error it reports can point at the
//! key that caused it.

use crate::doc::{Node, Table, Value};
use crate::error::{Error, Location, Result};
use lumis_api::registrar::PluginKind;

/// One plugin of a scene (or of a tool), before it is created.
#[derive(Debug, Clone, PartialEq)]
pub struct PluginEntity {
    pub kind: PluginKind,
    /// Names the table in messages, e.g. `bsdf "white"` or `integrator`.
    pub owner: String,
    /// The registered plugin name, and where it was written.
    pub type_name: String,
    pub type_location: Location,
    /// The parameters (and any `structural` keys).
    pub table: Table,
    pub location: Location,
    /// Keys of `table` read by whoever describes the plugin (`type`,
    /// `name`), not by the plugin.
    pub structural: &'static [&'static str],
}

/// The `structural` keys of a table that holds a plugin's `type` and
/// parameters, nothing else.
pub const TYPE_KEY: &[&str] = &["type"];

impl PluginEntity {
    /// A plugin table of a document: its `type` names the plugin, and
    /// `structural` lists the keys its describer reads itself (`type` among
    /// them).
    pub fn from_table(
        kind: PluginKind,
        owner: impl Into<String>,
        table: Table,
        location: Location,
        structural: &'static [&'static str],
    ) -> Result<Self> {
        let owner = owner.into();
        let (type_name, type_location) = type_of(&table, &owner)?.ok_or_else(|| {
            // A table an override made (`--spp` sets `sampler.spp`) is
            // missing from the file itself, which is what to fix.
            let missing = match location {
                Location::Override(_) => {
                    ": the scene file has no such table, and an override only changes a key of it (--spp and --seed are applied as overrides)"
                }
                _ => "",
            };
            Error::at(&location, format!("{owner} needs a type = \"...\"{missing}"))
        })?;
        Ok(Self {
            kind,
            owner,
            type_name,
            type_location,
            table,
            location,
            structural,
        })
    }

    /// A plugin table whose `type` may be left out: then it is
    /// `default_type`, said to be written where the table is.
    pub fn from_table_or(
        kind: PluginKind,
        owner: impl Into<String>,
        table: Table,
        location: Location,
        default_type: &str,
    ) -> Result<Self> {
        let owner = owner.into();
        let (type_name, type_location) = type_of(&table, &owner)?
            .unwrap_or_else(|| (default_type.to_string(), location.clone()));
        Ok(Self {
            kind,
            owner,
            type_name,
            type_location,
            table,
            location,
            structural: TYPE_KEY,
        })
    }

    /// A plugin described in code: `table` holds only its parameters, and
    /// `location` is what errors point at (e.g. the key that asked for it).
    pub fn new(
        kind: PluginKind,
        owner: impl Into<String>,
        type_name: impl Into<String>,
        table: Table,
        location: Location,
    ) -> Self {
        Self {
            kind,
            owner: owner.into(),
            type_name: type_name.into(),
            type_location: location.clone(),
            table,
            location,
            structural: &[],
        }
    }
}

/// The `type = "..."` of a table with its location, `None` when absent.
fn type_of(table: &Table, owner: &str) -> Result<Option<(String, Location)>> {
    match table.get("type") {
        Some(Node {
            value: Value::String(s),
            location,
        }) => Ok(Some((s.clone(), location.clone()))),
        Some(node) => Err(Error::at(
            &node.location,
            format!(
                "{owner}: 'type' must be a string, found {}",
                node.value.type_name()
            ),
        )),
        None => Ok(None),
    }
}
