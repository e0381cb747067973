//! `[[bsdf]]` and `[[texture]]` tables: named plugins that other tables
//! refer to (shapes name BSDFs, BSDF parameters name textures).

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, PluginEntity, PluginKind, Result};

use super::document::Located;

/// Keys of a named plugin's table the scene reads itself.
const NAMED_STRUCTURAL: &[&str] = &["type", "name"];

/// A `[[bsdf]]` or `[[texture]]`: its name and the plugin it describes.
pub(crate) struct NamedPlugin {
    pub name: String,
    pub entity: PluginEntity,
}

/// Describes every `[[<kind>]]` table, checking names are present and
/// unique; `referrers` says who refers to them, for the message about a
/// missing name.
pub(crate) fn named_plugins(
    kind: PluginKind,
    referrers: &str,
    tables: Vec<Located<Table>>,
) -> Result<Vec<NamedPlugin>> {
    let mut out: Vec<NamedPlugin> = Vec::with_capacity(tables.len());
    for (i, (table, location)) in tables.into_iter().enumerate() {
        let name = match table.get("name") {
            Some(Node {
                value: Value::String(s),
                location,
            }) => {
                if out.iter().any(|b| b.name == *s) {
                    return Err(Error::at(
                        location,
                        format!("a [[{kind}]] named \"{s}\" already exists"),
                    ));
                }
                s.clone()
            }
            Some(node) => {
                return Err(Error::at(
                    &node.location,
                    format!("[[{kind}]] name must be a string"),
                ))
            }
            None => {
                return Err(Error::at(
                    &location,
                    format!("[[{kind}]] #{i} needs a name = \"...\" that {referrers} refer to"),
                ))
            }
        };
        let entity = PluginEntity::from_table(
            kind,
            format!("{kind} \"{name}\""),
            table,
            location,
            NAMED_STRUCTURAL,
        )?;
        out.push(NamedPlugin { name, entity });
    }
    Ok(out)
}
