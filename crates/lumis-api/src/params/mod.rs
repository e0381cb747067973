//! Typed access to a plugin's TOML table.
//!
//! A plugin declares its parameters once, as a struct deriving
//! [`PluginParams`]: the derive writes both the `&'static [ParamSpec]` that
//! drives validation here (unknown keys, types, defaults, ranges, choices)
//! and the `lumis plugins` listing, and the code that reads the struct.
//! [`Params`] also records which keys were read: [`Params::finish`] rejects
//! keys that were given but not used, so a typo or a setting that does not
//! apply never falls back silently.
//!
//! The scene loader's own tables (`[film]`, `[camera]`, shapes) declare
//! `ParamSpec` lists by hand and read them by name with [`Params::get`].

mod convert;
mod nested;
mod spec;
mod textured;
mod typed;

use std::borrow::Cow;
use std::cell::RefCell;

pub use convert::{FromParam, LocatedTable, Param};
pub use nested::NestedBsdf;
pub use spec::{
    check_unique, concat, declares, override_default, total_len, ParamDefault, ParamSpec,
    ParamType, ParamValue,
};
pub use textured::{Textured, TexturedFloat, TexturedRgb};
pub use typed::{choice_from_node, ParamChoice, PluginParams};

use crate::doc::{Node, Table, Value};
use crate::error::{Error, Location, Result};
use crate::texture::BsdfScope;

/// A plugin's table, checked against its declaration.
pub struct Params<'a> {
    owner: String,
    table: &'a Table,
    location: Location,
    spec: &'a [ParamSpec],
    read: RefCell<Vec<bool>>,
    /// What `{ texture = "name" }` values and BSDF names refer to; `None`
    /// where no references are accepted (every plugin but BSDFs).
    scope: Option<BsdfScope<'a>>,
}

impl<'a> Params<'a> {
    /// Checks that every key of `table` other than `structural` (e.g. `type`,
    /// `name`, read by the scene loader itself) is declared in `spec`.
    /// `owner` names the table in messages, e.g. `bsdf "white" (type = "diffuse")`.
    pub fn new(
        owner: impl Into<String>,
        table: &'a Table,
        location: Location,
        spec: &'a [ParamSpec],
        structural: &[&str],
    ) -> Result<Self> {
        let owner = owner.into();
        for entry in &table.entries {
            if structural.contains(&entry.key.as_str()) {
                continue;
            }
            if !spec.iter().any(|s| s.name == entry.key) {
                return Err(Error::at(
                    &entry.key_location,
                    format!(
                        "unknown key '{}' for {owner}; accepted keys: {}",
                        entry.key,
                        accepted(spec, structural)
                    ),
                ));
            }
        }
        Ok(Self {
            owner,
            table,
            location,
            spec,
            read: RefCell::new(vec![false; spec.len()]),
            scope: None,
        })
    }

    /// Lets textured parameters ([`Textured`]) and BSDF references
    /// ([`NestedBsdf`]) refer to what `scope` holds.
    pub fn with_scope(mut self, scope: BsdfScope<'a>) -> Self {
        self.scope = Some(scope);
        self
    }

    /// A `Params` over a table built in code (tests, programmatic scenes).
    pub fn from_table(
        owner: impl Into<String>,
        table: &'a Table,
        spec: &'a [ParamSpec],
    ) -> Result<Self> {
        Self::new(owner, table, Location::Builtin, spec, &["type", "name"])
    }

    /// The table as written, for messages that repeat it.
    pub fn written(&self) -> &Table {
        self.table
    }

    pub fn owner(&self) -> &str {
        &self.owner
    }

    fn spec_index(&self, name: &str) -> usize {
        self.spec
            .iter()
            .position(|s| s.name == name)
            .unwrap_or_else(|| {
                panic!(
                    "plugin bug: {} reads parameter '{name}' it did not declare",
                    self.owner
                )
            })
    }

    /// The node for `name` (given, or its default), marking it read.
    /// Borrowed when the table has it, so large values (mesh positions) are
    /// not copied before conversion; defaults are converted on demand.
    fn node(&self, name: &str) -> Result<Option<Cow<'a, Node>>> {
        let i = self.spec_index(name);
        self.read.borrow_mut()[i] = true;
        if let Some(node) = self.table.get(name) {
            return Ok(Some(Cow::Borrowed(node)));
        }
        match self.spec[i].default {
            ParamDefault::Required => Err(Error::at(
                &self.location,
                format!(
                    "{} needs '{name}' ({}: {})",
                    self.owner,
                    self.spec[i].ty.name(),
                    self.spec[i].doc
                ),
            )),
            ParamDefault::Absent => Ok(None),
            ParamDefault::Value(value) => Ok(Some(Cow::Owned(value.to_node()))),
        }
    }

    fn convert<T: FromParam>(&self, name: &str, node: &Node) -> Result<T> {
        T::from_node(node)
            .map_err(|e| Error::at(&node.location, format!("{} key '{name}': {e}", self.owner)))
    }

    /// The value of `name`, or its declared default.
    pub fn get<T: FromParam>(&self, name: &str) -> Result<T> {
        match self.node(name)? {
            Some(node) => self.convert(name, &node),
            None => Err(Error::at(
                &self.location,
                format!(
                    "plugin bug: {} reads optional '{name}' with get(); use get_opt()",
                    self.owner
                ),
            )),
        }
    }

    /// The value of `name` if given (or defaulted), `None` if absent.
    pub fn get_opt<T: FromParam>(&self, name: &str) -> Result<Option<T>> {
        match self.node(name)? {
            Some(node) => self.convert(name, &node).map(Some),
            None => Ok(None),
        }
    }

    /// A declared parameter's value, or its default, checked against its
    /// declared range: what `#[derive(PluginParams)]` reads a field with.
    pub fn value<T: Param>(&self, name: &str) -> Result<T> {
        match self.optional_value(name)? {
            Some(v) => Ok(v),
            None => Err(Error::at(
                &self.location,
                format!(
                    "plugin bug: {} reads optional '{name}' as required; declare it as an Option",
                    self.owner
                ),
            )),
        }
    }

    /// [`Self::value`] for a parameter that may be absent.
    pub fn optional_value<T: Param>(&self, name: &str) -> Result<Option<T>> {
        let Some(node) = self.node(name)? else {
            return Ok(None);
        };
        let v = T::read_node(self, name, &node)?;
        self.check_range(name, &v)?;
        Ok(Some(v))
    }

    fn check_range<T: Param>(&self, name: &str, v: &T) -> Result<()> {
        match self.spec[self.spec_index(name)].range {
            Some(range) => v.check_range(range).map_err(|e| self.error(name, e)),
            None => Ok(()),
        }
    }

    /// Marks `name` as not read, for a parameter that does not apply with
    /// the other values given: [`Self::finish`] then rejects it if the
    /// scene gave it.
    pub fn unread(&self, name: &str) {
        let i = self.spec_index(name);
        self.read.borrow_mut()[i] = false;
    }

    /// Whether the scene gave `name` explicitly (marks it read).
    pub fn is_given(&self, name: &str) -> bool {
        let i = self.spec_index(name);
        self.read.borrow_mut()[i] = true;
        self.table.get(name).is_some()
    }

    /// A nested table parameter, with its location.
    pub fn table(&self, name: &str) -> Result<Option<(&'a Table, Location)>> {
        let i = self.spec_index(name);
        self.read.borrow_mut()[i] = true;
        match self.table.get(name) {
            None => Ok(None),
            Some(Node {
                value: Value::Table(t),
                location,
            }) => Ok(Some((t, location.clone()))),
            Some(node) => Err(Error::at(
                &node.location,
                format!(
                    "{} key '{name}': expected a table, found {}",
                    self.owner,
                    node.value.type_name()
                ),
            )),
        }
    }

    /// A number within the range the spec declares (`ParamSpec::in_range`).
    pub fn get_in_range(&self, name: &str) -> Result<f32> {
        let v: f32 = self.get(name)?;
        let range = self.spec[self.spec_index(name)]
            .range
            .unwrap_or_else(|| panic!("plugin bug: '{name}' of {} declares no range", self.owner));
        v.check_range(range).map_err(|e| self.error(name, e))?;
        Ok(v)
    }

    /// A float that must be finite and > 0.
    pub fn get_positive(&self, name: &str) -> Result<f32> {
        let v: f32 = self.get(name)?;
        if !(v > 0.0 && v.is_finite()) {
            return Err(self.error(name, format!("must be a positive finite number, got {v}")));
        }
        Ok(v)
    }

    /// One of the strings the spec declares (`ParamSpec::one_of`).
    pub fn get_choice(&self, name: &str) -> Result<String> {
        let v: String = self.get(name)?;
        let choices = self.spec[self.spec_index(name)].choices;
        if !choices.contains(&v.as_str()) {
            return Err(self.error(
                name,
                format!("must be one of {}, got \"{v}\"", quoted(choices)),
            ));
        }
        Ok(v)
    }

    /// An error about `name`, located at its value (or at the table).
    pub fn error(&self, name: &str, message: impl std::fmt::Display) -> Error {
        let location = self.table.get(name).map_or(&self.location, |n| &n.location);
        Error::at(location, format!("{} key '{name}': {message}", self.owner))
    }

    /// Rejects keys that were given but never read by the plugin.
    pub fn finish(self) -> Result<()> {
        let read = self.read.borrow();
        for entry in &self.table.entries {
            if let Some(i) = self.spec.iter().position(|s| s.name == entry.key) {
                if !read[i] {
                    return Err(Error::at(
                        &entry.key_location,
                        format!(
                            "key '{}' is not used by {} with the other values given; remove it",
                            entry.key, self.owner
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

fn quoted(choices: &[&str]) -> String {
    choices
        .iter()
        .map(|c| format!("\"{c}\""))
        .collect::<Vec<_>>()
        .join(", ")
}

fn accepted(spec: &[ParamSpec], structural: &[&str]) -> String {
    let names: Vec<&str> = structural
        .iter()
        .copied()
        .chain(spec.iter().map(|s| s.name))
        .collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}
