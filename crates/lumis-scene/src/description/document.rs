//! Taking the scene document apart: its tables, each with its location.

use lumis_core::doc::{Node, Table, Value};
use lumis_core::{Error, Location, Result};

/// A table of the document and where it was written.
pub(crate) type Located<T> = (T, Location);

/// The table a node holds; `what` names it in the error.
pub(crate) fn into_table(node: Node, what: &str) -> Result<Located<Table>> {
    match node.value {
        Value::Table(t) => Ok((t, node.location)),
        v => Err(Error::at(
            &node.location,
            format!("{what}: expected a table, found {}", v.type_name()),
        )),
    }
}

/// Takes the table `key` out of `root`, if it is there.
pub(crate) fn take_table(root: &mut Table, key: &str) -> Result<Option<Located<Table>>> {
    root.remove(key)
        .map(|entry| into_table(entry.node, key))
        .transpose()
}

/// Takes the table `key` out of `root`; the scene must have it.
pub(crate) fn take_required_table(
    root: &mut Table,
    key: &str,
    file: &Location,
) -> Result<Located<Table>> {
    take_table(root, key)?
        .ok_or_else(|| Error::at(file, format!("the scene needs a [{key}] table with a type")))
}

/// Takes the array of tables `key` (`[[shape]]`) out of `root`.
pub(crate) fn take_tables(root: &mut Table, key: &str) -> Result<Vec<Located<Table>>> {
    let Some(entry) = root.remove(key) else {
        return Ok(Vec::new());
    };
    let Value::Array(items) = entry.node.value else {
        return Err(Error::at(
            &entry.node.location,
            format!("'{key}' must be an array of tables: write [[{key}]]"),
        ));
    };
    items.into_iter().map(|n| into_table(n, key)).collect()
}

/// The `type = "..."` of a table that is not a plugin (a shape, the
/// camera, a pixel filter), with its location.
pub(crate) fn type_of<'a>(
    table: &'a Table,
    location: &Location,
    owner: &str,
) -> Result<(&'a str, Location)> {
    match table.get("type") {
        Some(Node {
            value: Value::String(s),
            location,
        }) => Ok((s.as_str(), location.clone())),
        Some(node) => Err(Error::at(
            &node.location,
            format!(
                "{owner}: 'type' must be a string, found {}",
                node.value.type_name()
            ),
        )),
        None => Err(Error::at(
            location,
            format!("{owner} needs a type = \"...\""),
        )),
    }
}

/// Where `key` of `table` was written (the table's own location if absent).
pub(crate) fn location_of(table: &Table, key: &str, fallback: &Location) -> Location {
    table
        .get(key)
        .map_or_else(|| fallback.clone(), |n| n.location.clone())
}

/// The string written at `key` of `table`, for messages that repeat it;
/// empty where there is none (callers have read it as a string already).
pub(crate) fn written_string(table: &Table, key: &str) -> String {
    match table.get(key).map(|node| &node.value) {
        Some(Value::String(text)) => text.clone(),
        _ => String::new(),
    }
}
