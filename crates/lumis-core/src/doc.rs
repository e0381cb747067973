//! The scene document: TOML text parsed into located values
//! ([`lumis_api::doc`]), and edited by `--set` overrides.

use std::sync::Arc;

use toml::de::{DeTable, DeValue};
use toml::Spanned;

pub use lumis_api::doc::{Entry, Node, Table, Value};

use crate::error::{Error, Location, Result};

/// Maps byte offsets to 1-based line and column.
struct LineIndex {
    path: Arc<str>,
    line_starts: Vec<usize>,
}

impl LineIndex {
    fn new(path: Arc<str>, text: &str) -> Self {
        let mut line_starts = vec![0];
        line_starts.extend(text.match_indices('\n').map(|(i, _)| i + 1));
        Self { path, line_starts }
    }

    fn location(&self, offset: usize) -> Location {
        let line = self.line_starts.partition_point(|&s| s <= offset);
        let column = offset - self.line_starts[line - 1] + 1;
        Location::File {
            path: self.path.clone(),
            line: line as u32,
            column: column as u32,
        }
    }
}

/// Parses TOML text; `path` names the source in every location.
pub fn parse(text: &str, path: &str) -> Result<Table> {
    let index = LineIndex::new(Arc::from(path), text);
    let table = DeTable::parse(text).map_err(|e| {
        let location = e.span().map(|s| index.location(s.start));
        Error {
            location,
            message: format!("invalid TOML: {}", e.message()),
        }
    })?;
    Ok(convert_table(table.get_ref(), &index))
}

fn convert_table(table: &DeTable<'_>, index: &LineIndex) -> Table {
    Table {
        entries: table
            .iter()
            .map(|(k, v)| Entry {
                key: k.get_ref().to_string(),
                key_location: index.location(k.span().start),
                node: convert_value(v, index),
            })
            .collect(),
    }
}

fn convert_value(value: &Spanned<DeValue<'_>>, index: &LineIndex) -> Node {
    let location = index.location(value.span().start);
    let value = match value.get_ref() {
        DeValue::String(s) => Value::String(s.to_string()),
        DeValue::Integer(i) => match i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()) {
            Ok(v) => Value::Int(v),
            // Out of i64 range: keep as float so range checks report it.
            Err(_) => Value::Float(i.as_str().replace('_', "").parse().unwrap_or(f64::INFINITY)),
        },
        DeValue::Float(f) => Value::Float(parse_float(f.as_str())),
        DeValue::Boolean(b) => Value::Bool(*b),
        DeValue::Datetime(d) => Value::Datetime(d.to_string()),
        DeValue::Array(a) => Value::Array(a.iter().map(|v| convert_value(v, index)).collect()),
        DeValue::Table(t) => Value::Table(convert_table(t, index)),
    };
    Node { value, location }
}

fn parse_float(text: &str) -> f64 {
    let text = text.replace('_', "");
    match text.as_str() {
        "nan" | "+nan" | "-nan" => f64::NAN,
        "inf" | "+inf" => f64::INFINITY,
        "-inf" => f64::NEG_INFINITY,
        t => t.parse().unwrap_or(f64::NAN),
    }
}

/// Applies a command-line override `path=value` (like Mitsuba's `-D`).
///
/// `path` is dot-separated. A segment that meets an array of tables selects
/// the element whose `name` equals it, or the element at that index
/// (`bsdf.white.reflectance`, `shape.0.file`). Missing tables are created and
/// missing keys added, so any parameter can be set. `value` is parsed as a
/// TOML value; if it is not one it is taken as a string (`sampler.type=sobol`).
pub fn apply_override(root: &mut Table, assignment: &str) -> Result<()> {
    let location = Location::Override(Arc::from(assignment));
    let (path, value_text) = assignment
        .split_once('=')
        .ok_or_else(|| Error::at(&location, "expected key.path=value"))?;
    let segments: Vec<&str> = path.trim().split('.').collect();
    if segments.iter().any(|s| s.is_empty()) {
        return Err(Error::at(
            &location,
            format!("empty segment in key path '{path}'"),
        ));
    }
    let value = parse_override_value(value_text.trim(), &location);
    let last = segments.len() - 1;
    let mut table = root;
    let mut i = 0;
    while i < last {
        let walked = segments[..=i].join(".");
        if table.get(segments[i]).is_none() {
            let empty = Node {
                value: Value::Table(Table::default()),
                location: location.clone(),
            };
            table.insert(segments[i], empty);
        }
        let node = table.get_mut(segments[i]).expect("inserted above");
        let found = node.value.type_name();
        table = match &mut node.value {
            Value::Table(t) => {
                i += 1;
                t
            }
            Value::Array(items) if i + 1 < last => {
                let selector = segments[i + 1];
                i += 2;
                select_in_array(items, selector).ok_or_else(|| {
                    Error::at(
                        &location,
                        format!("'{walked}' has no table named or numbered '{selector}'"),
                    )
                })?
            }
            Value::Array(_) => {
                return Err(Error::at(
                    &location,
                    format!("'{walked}' is an array: name an element, e.g. '{walked}.0.key=value'"),
                ))
            }
            _ => {
                return Err(Error::at(
                    &location,
                    format!("'{walked}' is {found}, not a table"),
                ))
            }
        };
    }
    table.insert(segments[last], Node { value, location });
    Ok(())
}

fn parse_override_value(text: &str, location: &Location) -> Value {
    let index = LineIndex::new(Arc::from("--set"), text);
    match DeValue::parse(text) {
        Ok(v) => {
            let mut node = convert_value(&v, &index);
            node.relocate(location);
            node.value
        }
        Err(_) => Value::String(text.to_string()),
    }
}

/// Resolves `array.selector` for arrays of tables: by `name` or by index.
pub fn select_in_array<'t>(items: &'t mut [Node], selector: &str) -> Option<&'t mut Table> {
    let by_index = selector.parse::<usize>().ok();
    let position = items.iter().position(|n| match &n.value {
        Value::Table(t) => {
            matches!(t.get("name"), Some(Node { value: Value::String(s), .. }) if s == selector)
        }
        _ => false,
    });
    let i = position.or(by_index)?;
    match &mut items.get_mut(i)?.value {
        Value::Table(t) => Some(t),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = "[film]\nresolution = [4, 2]\n\n[[bsdf]]\nname = \"white\"\nreflectance = 0.5\n\n[[bsdf]]\nname = \"red\"\nreflectance = [0.5, 0.0, 0.0]\n";

    #[test]
    fn locations_point_at_lines() {
        let doc = parse(SCENE, "s.toml").unwrap();
        let film = doc.entry("film").unwrap();
        let Value::Table(film) = &film.node.value else {
            panic!()
        };
        let res = film.entry("resolution").unwrap();
        assert_eq!(res.key_location.to_string(), "s.toml:2:1");
        assert_eq!(res.node.location.to_string(), "s.toml:2:14");
    }

    #[test]
    fn bad_toml_is_located() {
        let err = parse("[film]\nresolution = [4, \n", "bad.toml").unwrap_err();
        assert!(err.to_string().starts_with("bad.toml:"), "{err}");
        assert!(err.message.contains("invalid TOML"));
    }

    #[test]
    fn overrides_reach_nested_and_named_entries() {
        let mut doc = parse(SCENE, "s.toml").unwrap();
        apply_override(&mut doc, "film.resolution=[8, 8]").unwrap();
        apply_override(&mut doc, "bsdf.red.reflectance=0.25").unwrap();
        apply_override(&mut doc, "bsdf.0.reflectance=0.75").unwrap();
        apply_override(&mut doc, "sampler.type=sobol").unwrap();
        let Value::Table(film) = &doc.get("film").unwrap().value else {
            panic!()
        };
        assert!(matches!(&film.get("resolution").unwrap().value, Value::Array(a) if a.len() == 2));
        let Value::Array(bsdfs) = &doc.get("bsdf").unwrap().value else {
            panic!()
        };
        let Value::Table(white) = &bsdfs[0].value else {
            panic!()
        };
        assert_eq!(white.get("reflectance").unwrap().value, Value::Float(0.75));
        let Value::Table(red) = &bsdfs[1].value else {
            panic!()
        };
        let r = red.get("reflectance").unwrap();
        assert_eq!(r.value, Value::Float(0.25));
        assert_eq!(r.location.to_string(), "--set bsdf.red.reflectance=0.25");
        let Value::Table(sampler) = &doc.get("sampler").unwrap().value else {
            panic!()
        };
        assert_eq!(
            sampler.get("type").unwrap().value,
            Value::String("sobol".into())
        );
    }

    #[test]
    fn bad_overrides_are_errors() {
        let mut doc = parse(SCENE, "s.toml").unwrap();
        assert!(apply_override(&mut doc, "film.resolution").is_err());
        assert!(apply_override(&mut doc, "bsdf.blue.reflectance=1").is_err());
        assert!(apply_override(&mut doc, "film.resolution.x=1").is_err());
        assert!(apply_override(&mut doc, "film..x=1").is_err());
    }
}
