//! `[[bsdf]]` tables: named BSDF plugins that shapes refer to.

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, PluginEntity, PluginKind, Result};

use super::document::Located;

/// Keys of a `[[bsdf]]` the scene reads itself.
const BSDF_STRUCTURAL: &[&str] = &["type", "name"];

/// A `[[bsdf]]`: its name and the plugin it describes.
pub(crate) struct NamedBsdf {
    pub name: String,
    pub entity: PluginEntity,
}

/// Describes every `[[bsdf]]`, checking names are present and unique.
pub(crate) fn named_bsdfs(tables: Vec<Located<Table>>) -> Result<Vec<NamedBsdf>> {
    let mut out: Vec<NamedBsdf> = Vec::with_capacity(tables.len());
    for (i, (table, location)) in tables.into_iter().enumerate() {
        let name = match table.get("name") {
            Some(Node {
                value: Value::String(s),
                location,
            }) => {
                if out.iter().any(|b| b.name == *s) {
                    return Err(Error::at(
                        location,
                        format!("a [[bsdf]] named \"{s}\" already exists"),
                    ));
                }
                s.clone()
            }
            Some(node) => return Err(Error::at(&node.location, "[[bsdf]] name must be a string")),
            None => {
                return Err(Error::at(
                    &location,
                    format!("[[bsdf]] #{i} needs a name = \"...\" that shapes refer to"),
                ))
            }
        };
        let entity = PluginEntity::from_table(
            PluginKind::Bsdf,
            format!("bsdf \"{name}\""),
            table,
            location,
            BSDF_STRUCTURAL,
        )?;
        out.push(NamedBsdf { name, entity });
    }
    Ok(out)
}
