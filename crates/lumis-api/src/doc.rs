//! Parameter values as a scene gives them: a tree of TOML values in which
//! every key and value remembers the file, line and column it came from
//! (or the `--set` override that put it there), so every error can point at
//! its cause. A plugin reads them through [`Params`](crate::Params); the
//! host parses and edits the document they come from.

use std::sync::Arc;

use crate::error::Location;
use crate::image::DecodedImage;

/// A value with its origin.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    pub value: Value,
    pub location: Location,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    Int(i64),
    Float(f64),
    String(String),
    Array(Vec<Node>),
    Table(Table),
    /// Dates are valid TOML but mean nothing in a scene; kept to be rejected
    /// with a located error.
    Datetime(String),
    /// Decoded texels a host passes to a plugin (an image embedded in an
    /// asset); no scene file can write one.
    Image(Arc<DecodedImage>),
}

impl Value {
    /// The TOML type name, for "expected X, found Y" messages.
    pub fn type_name(&self) -> &'static str {
        match self {
            Value::Bool(_) => "a boolean",
            Value::Int(_) => "an integer",
            Value::Float(_) => "a float",
            Value::String(_) => "a string",
            Value::Array(_) => "an array",
            Value::Table(_) => "a table",
            Value::Datetime(_) => "a date",
            Value::Image(_) => "an image",
        }
    }
}

/// TOML-like text of a value, for messages that repeat what was written.
impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Bool(b) => write!(f, "{b}"),
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x:?}"),
            Value::String(s) | Value::Datetime(s) => write!(f, "{s:?}"),
            Value::Array(items) => {
                f.write_str("[")?;
                for (i, item) in items.iter().enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    write!(f, "{sep}{}", item.value)?;
                }
                f.write_str("]")
            }
            Value::Table(table) => write!(f, "{{ {table} }}"),
            Value::Image(image) => write!(f, "{image:?}"),
        }
    }
}

/// `key = value, ...`: a table's entries in the order written.
impl std::fmt::Display for Table {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, entry) in self.entries.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}{} = {}", entry.key, entry.node.value)?;
        }
        Ok(())
    }
}

/// One `key = value` of a table.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub key: String,
    pub key_location: Location,
    pub node: Node,
}

/// An ordered TOML table.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    pub entries: Vec<Entry>,
}

impl Table {
    pub fn get(&self, key: &str) -> Option<&Node> {
        self.entries.iter().find(|e| e.key == key).map(|e| &e.node)
    }

    pub fn get_mut(&mut self, key: &str) -> Option<&mut Node> {
        self.entries
            .iter_mut()
            .find(|e| e.key == key)
            .map(|e| &mut e.node)
    }

    pub fn entry(&self, key: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.key == key)
    }

    /// Sets `key`, replacing any previous value.
    pub fn insert(&mut self, key: &str, node: Node) {
        match self.entries.iter_mut().find(|e| e.key == key) {
            Some(e) => {
                e.key_location = node.location.clone();
                e.node = node;
            }
            None => self.entries.push(Entry {
                key: key.to_string(),
                key_location: node.location.clone(),
                node,
            }),
        }
    }

    pub fn keys(&self) -> impl Iterator<Item = &str> {
        self.entries.iter().map(|e| e.key.as_str())
    }

    /// Takes `key` out of the table.
    pub fn remove(&mut self, key: &str) -> Option<Entry> {
        let i = self.entries.iter().position(|e| e.key == key)?;
        Some(self.entries.remove(i))
    }

    /// A table built in code: every key and value (nested ones too) is
    /// said to come from `location`.
    pub fn built<'k>(
        location: &Location,
        entries: impl IntoIterator<Item = (&'k str, Value)>,
    ) -> Table {
        let mut table = Table::default();
        for (key, value) in entries {
            let mut node = Node {
                value,
                location: location.clone(),
            };
            node.relocate(location);
            table.insert(key, node);
        }
        table
    }
}

impl From<bool> for Value {
    fn from(b: bool) -> Self {
        Value::Bool(b)
    }
}

impl From<f32> for Value {
    /// Exact: reading the value back as an `f32` gives `f`.
    fn from(f: f32) -> Self {
        Value::Float(f64::from(f))
    }
}

impl From<&str> for Value {
    fn from(s: &str) -> Self {
        Value::String(s.to_string())
    }
}

impl<const N: usize> From<[f32; N]> for Value {
    /// An array of `N` numbers (located by [`Table::built`]).
    fn from(v: [f32; N]) -> Self {
        Value::Array(
            v.into_iter()
                .map(|c| Node {
                    value: c.into(),
                    location: Location::Builtin,
                })
                .collect(),
        )
    }
}

impl Node {
    /// Gives this node, and every node and key inside it, `location`: a
    /// value built in code or put there by an override comes from one
    /// place.
    pub fn relocate(&mut self, location: &Location) {
        self.location = location.clone();
        match &mut self.value {
            Value::Array(items) => items.iter_mut().for_each(|n| n.relocate(location)),
            Value::Table(t) => t.entries.iter_mut().for_each(|e| {
                e.key_location = location.clone();
                e.node.relocate(location);
            }),
            _ => {}
        }
    }
}

#[cfg(test)]
mod built_tables {
    use std::sync::Arc;

    use super::*;

    #[test]
    fn built_values_are_exact_and_located() {
        let at = Location::Override(Arc::from("here"));
        let third = 1.0f32 / 3.0;
        let table = Table::built(
            &at,
            [
                ("x", Value::from(third)),
                ("rgb", Value::from([0.1f32, 0.2, 0.3])),
            ],
        );
        let Value::Float(x) = table.get("x").unwrap().value else {
            panic!("a float")
        };
        assert_eq!(x as f32, third);
        let Value::Array(rgb) = &table.get("rgb").unwrap().value else {
            panic!("an array")
        };
        assert!(rgb.iter().all(|n| n.location == at));
        assert_eq!(table.entry("rgb").unwrap().key_location, at);
    }
}
