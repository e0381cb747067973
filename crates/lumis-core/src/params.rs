//! Typed access to a plugin's TOML table.
//!
//! A plugin declares its parameters once, as a `&'static [ParamSpec]`; that
//! declaration drives validation here (unknown keys, types, defaults) and the
//! `lumis plugins` listing. [`Params`] also records which keys the plugin
//! read: [`Params::finish`] rejects keys that were given but not used, so a
//! typo or a setting that does not apply never falls back silently.

use std::borrow::Cow;
use std::cell::RefCell;

use glam::{UVec2, Vec2, Vec3};

use crate::doc::{Node, Table, Value};
use crate::error::{Error, Location, Result};
use crate::spectrum::Rgb;

/// The type of a parameter, as shown to users and checked on access.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamType {
    Bool,
    Int,
    Float,
    String,
    /// `[r, g, b]` or one number for grey.
    Rgb,
    Vec2,
    Vec3,
    /// Two non-negative integers, e.g. a resolution.
    UIntPair,
    FloatArray,
    /// `[[x, y, z], ...]`, e.g. mesh positions.
    Vec3Array,
    IntArray,
    StringArray,
    Table,
}

impl ParamType {
    pub fn name(self) -> &'static str {
        match self {
            ParamType::Bool => "bool",
            ParamType::Int => "int",
            ParamType::Float => "float",
            ParamType::String => "string",
            ParamType::Rgb => "rgb",
            ParamType::Vec2 => "vec2",
            ParamType::Vec3 => "vec3",
            ParamType::UIntPair => "[uint, uint]",
            ParamType::FloatArray => "[float]",
            ParamType::Vec3Array => "[vec3]",
            ParamType::IntArray => "[int]",
            ParamType::StringArray => "[string]",
            ParamType::Table => "table",
        }
    }
}

/// Whether a parameter must be given, and what it is when it is not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamDefault {
    Required,
    /// A TOML literal, e.g. `"0.5"`, `"[1.0, 1.0, 1.0]"` or `"\"power\""`.
    Value(&'static str),
    /// May be absent; absence has its own meaning (e.g. no emission).
    Absent,
}

/// One declared parameter of a plugin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParamSpec {
    pub name: &'static str,
    pub ty: ParamType,
    pub default: ParamDefault,
    pub doc: &'static str,
    /// The valid range of a number, `[min, max]`: documents it, and tells
    /// `lumis check-plugin` which extremes to sweep.
    pub range: Option<(f64, f64)>,
    /// The valid values of a string, for the same two purposes.
    pub choices: &'static [&'static str],
}

impl ParamSpec {
    pub const fn required(name: &'static str, ty: ParamType, doc: &'static str) -> Self {
        Self {
            name,
            ty,
            default: ParamDefault::Required,
            doc,
            range: None,
            choices: &[],
        }
    }

    pub const fn with_default(
        name: &'static str,
        ty: ParamType,
        default: &'static str,
        doc: &'static str,
    ) -> Self {
        Self {
            name,
            ty,
            default: ParamDefault::Value(default),
            doc,
            range: None,
            choices: &[],
        }
    }

    pub const fn optional(name: &'static str, ty: ParamType, doc: &'static str) -> Self {
        Self {
            name,
            ty,
            default: ParamDefault::Absent,
            doc,
            range: None,
            choices: &[],
        }
    }

    /// Declares the valid range of a number parameter.
    pub const fn in_range(mut self, min: f64, max: f64) -> Self {
        self.range = Some((min, max));
        self
    }

    /// Declares the valid values of a string parameter.
    pub const fn one_of(mut self, choices: &'static [&'static str]) -> Self {
        self.choices = choices;
        self
    }

    /// The default as a document node, if it has one.
    pub fn default_node(&self) -> Result<Option<Node>> {
        let ParamDefault::Value(text) = self.default else {
            return Ok(None);
        };
        // Parse through a one-key document so defaults use the same converter.
        let table = crate::doc::parse(&format!("v = {text}"), "<default>").map_err(|e| {
            Error::msg(format!(
                "plugin bug: parameter '{}' has an invalid default '{text}': {}",
                self.name, e.message
            ))
        })?;
        let mut node = table
            .get("v")
            .cloned()
            .ok_or_else(|| Error::msg("default lost"))?;
        set_builtin(&mut node);
        Ok(Some(node))
    }
}

fn set_builtin(node: &mut Node) {
    node.location = Location::Builtin;
    match &mut node.value {
        Value::Array(items) => items.iter_mut().for_each(set_builtin),
        Value::Table(t) => t.entries.iter_mut().for_each(|e| {
            e.key_location = Location::Builtin;
            set_builtin(&mut e.node);
        }),
        _ => {}
    }
}

/// A value that can be read from a document node.
pub trait FromParam: Sized {
    /// Converts, or says what was expected.
    fn from_node(node: &Node) -> std::result::Result<Self, String>;
}

/// A finite number: TOML's `nan` and `inf` are valid floats, but no scene
/// value means them, and a NaN would pass every range check (all its
/// comparisons are false) and poison the render.
fn number(node: &Node) -> std::result::Result<f64, String> {
    let v = match node.value {
        Value::Float(f) => f,
        Value::Int(i) => i as f64,
        ref v => return Err(format!("expected a number, found {}", v.type_name())),
    };
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("expected a finite number, found {v}"))
    }
}

/// A finite number that fits an `f32`.
fn single(node: &Node) -> std::result::Result<f32, String> {
    let v = number(node)?;
    let single = v as f32;
    if single.is_finite() {
        Ok(single)
    } else {
        Err(format!("{v} is beyond the range of a 32-bit float"))
    }
}

/// `N` numbers in an array; `expected` opens every message.
fn floats<const N: usize>(node: &Node, expected: &str) -> std::result::Result<[f32; N], String> {
    let Value::Array(items) = &node.value else {
        return Err(format!("{expected}, found {}", node.value.type_name()));
    };
    if items.len() != N {
        return Err(format!("{expected}, found {} elements", items.len()));
    }
    let mut out = [0.0; N];
    for (i, (o, item)) in out.iter_mut().zip(items).enumerate() {
        *o = single(item).map_err(|e| format!("{expected}; element {i}: {e}"))?;
    }
    Ok(out)
}

impl FromParam for f64 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        number(node)
    }
}

impl FromParam for f32 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        single(node)
    }
}

impl FromParam for i64 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match node.value {
            Value::Int(i) => Ok(i),
            ref v => Err(format!("expected an integer, found {}", v.type_name())),
        }
    }
}

impl FromParam for u32 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        let i = i64::from_node(node)?;
        u32::try_from(i).map_err(|_| format!("expected an integer in [0, {}], found {i}", u32::MAX))
    }
}

impl FromParam for bool {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match node.value {
            Value::Bool(b) => Ok(b),
            ref v => Err(format!("expected true or false, found {}", v.type_name())),
        }
    }
}

impl FromParam for String {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::String(s) => Ok(s.clone()),
            v => Err(format!("expected a string, found {}", v.type_name())),
        }
    }
}

impl FromParam for Rgb {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::Float(_) | Value::Int(_) => Ok(Rgb::splat(single(node)?)),
            Value::Array(_) => floats::<3>(node, "expected [r, g, b] or one number").map(Rgb::from),
            v => Err(format!(
                "expected [r, g, b] or one number, found {}",
                v.type_name()
            )),
        }
    }
}

impl FromParam for Vec3 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        floats::<3>(node, "expected an array of 3 numbers").map(Vec3::from)
    }
}

impl FromParam for Vec2 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        floats::<2>(node, "expected an array of 2 numbers").map(Vec2::from)
    }
}

impl FromParam for UVec2 {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        let expected = "expected an array of 2 non-negative integers";
        let Value::Array(items) = &node.value else {
            return Err(format!("{expected}, found {}", node.value.type_name()));
        };
        match items.as_slice() {
            [a, b] => Ok(UVec2::new(
                u32::from_node(a).map_err(|e| format!("{expected}: {e}"))?,
                u32::from_node(b).map_err(|e| format!("{expected}: {e}"))?,
            )),
            _ => Err(format!("{expected}, found {} elements", items.len())),
        }
    }
}

impl<T: FromParam> FromParam for Vec<T> {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        let Value::Array(items) = &node.value else {
            return Err(format!(
                "expected an array, found {}",
                node.value.type_name()
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, n)| T::from_node(n).map_err(|e| format!("element {i}: {e}")))
            .collect()
    }
}

/// A plugin's table, checked against its declaration.
pub struct Params<'a> {
    owner: String,
    table: &'a Table,
    location: Location,
    spec: &'a [ParamSpec],
    read: RefCell<Vec<bool>>,
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
        })
    }

    /// A `Params` over a table built in code (tests, programmatic scenes).
    pub fn from_table(
        owner: impl Into<String>,
        table: &'a Table,
        spec: &'a [ParamSpec],
    ) -> Result<Self> {
        Self::new(owner, table, Location::Builtin, spec, &["type", "name"])
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
    /// not copied before conversion; defaults are parsed on demand.
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
            ParamDefault::Value(_) => Ok(self.spec[i].default_node()?.map(Cow::Owned)),
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

    /// A file path. A relative path is resolved against the directory of
    /// the scene file that wrote it, so a scene and its assets move
    /// together; given with `--set` (or built in), it is relative to the
    /// working directory.
    pub fn get_path(&self, name: &str) -> Result<std::path::PathBuf> {
        let Some(node) = self.node(name)? else {
            return Err(self.error(name, "plugin bug: optional path read with get_path()"));
        };
        let text: String = self.convert(name, &node)?;
        if text.is_empty() {
            return Err(self.error(name, "expected a file path, found an empty string"));
        }
        let path = std::path::PathBuf::from(&text);
        Ok(match &node.location {
            Location::File { path: scene, .. } if path.is_relative() => {
                std::path::Path::new(&**scene)
                    .parent()
                    .map_or(path.clone(), |dir| dir.join(&path))
            }
            _ => path,
        })
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
        let (min, max) = self.spec[self.spec_index(name)]
            .range
            .unwrap_or_else(|| panic!("plugin bug: '{name}' of {} declares no range", self.owner));
        if !(v as f64 >= min && v as f64 <= max) {
            return Err(self.error(name, format!("must be in [{min}, {max}], got {v}")));
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: &[ParamSpec] = &[
        ParamSpec::required("reflectance", ParamType::Rgb, "albedo"),
        ParamSpec::with_default("max_depth", ParamType::Int, "8", "path segments"),
        ParamSpec::with_default("heuristic", ParamType::String, "\"power\"", "MIS heuristic")
            .one_of(&["balance", "power"]),
        ParamSpec::optional("beta", ParamType::Float, "power heuristic exponent"),
    ];

    fn params(text: &str) -> Table {
        crate::doc::parse(text, "t.toml").unwrap()
    }

    #[test]
    fn reads_values_and_defaults() {
        let t = params("type = \"x\"\nreflectance = 0.5\n");
        let p = Params::new("bsdf \"w\"", &t, Location::Builtin, SPEC, &["type"]).unwrap();
        assert_eq!(p.get::<Rgb>("reflectance").unwrap(), Rgb::splat(0.5));
        assert_eq!(p.get::<i64>("max_depth").unwrap(), 8);
        assert_eq!(p.get::<String>("heuristic").unwrap(), "power");
        assert_eq!(p.get_opt::<f32>("beta").unwrap(), None);
        p.finish().unwrap();
    }

    #[test]
    fn unknown_key_names_key_owner_and_accepted_keys() {
        let t = params("reflectance = 0.5\nreflectence = 0.5\n");
        let err = Params::new("bsdf \"w\"", &t, Location::Builtin, SPEC, &["type"])
            .err()
            .unwrap();
        let text = err.to_string();
        assert!(text.starts_with("t.toml:2:1"), "{text}");
        assert!(
            text.contains("'reflectence'") && text.contains("bsdf \"w\""),
            "{text}"
        );
        assert!(
            text.contains("reflectance, max_depth, heuristic, beta"),
            "{text}"
        );
    }

    #[test]
    fn wrong_type_is_located_at_the_value() {
        let t = params("reflectance = \"red\"\n");
        let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
        let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
        assert!(
            err.starts_with("t.toml:1:15") && err.contains("expected [r, g, b]"),
            "{err}"
        );
    }

    #[test]
    fn nan_infinity_and_f32_overflow_are_refused() {
        for (text, says) in [
            ("reflectance = nan\n", "expected a finite number, found NaN"),
            (
                "reflectance = [0.5, nan, 0.5]\n",
                "element 1: expected a finite number",
            ),
            ("reflectance = [0.5, 0.5, -inf]\n", "found -inf"),
            (
                "reflectance = 1e300\n",
                "beyond the range of a 32-bit float",
            ),
        ] {
            let t = params(text);
            let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
            let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
            assert!(
                err.starts_with("t.toml:1:15") && err.contains(says),
                "{text}: {err}"
            );
        }
        let t = params("reflectance = 0.5\nbeta = inf\n");
        let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
        let err = p.get::<f32>("beta").unwrap_err().to_string();
        assert!(err.contains("'beta'") && err.contains("found inf"), "{err}");
    }

    #[test]
    fn missing_required_key_is_an_error() {
        let t = params("max_depth = 3\n");
        let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
        let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
        assert!(err.contains("needs 'reflectance'"), "{err}");
    }

    #[test]
    fn unused_key_is_an_error() {
        let t = params("reflectance = 1\nbeta = 2\n");
        let p = Params::new("integrator", &t, Location::Builtin, SPEC, &[]).unwrap();
        p.get::<Rgb>("reflectance").unwrap();
        let err = p.finish().unwrap_err().to_string();
        assert!(err.contains("'beta' is not used"), "{err}");
    }

    #[test]
    fn paths_are_relative_to_the_scene_file() {
        const FILE: &[ParamSpec] = &[ParamSpec::required("file", ParamType::String, "a file")];
        let t = crate::doc::parse("file = \"tables/a.binary\"\n", "/scenes/s.toml").unwrap();
        let p = Params::new("bsdf", &t, Location::Builtin, FILE, &[]).unwrap();
        assert_eq!(
            p.get_path("file").unwrap(),
            std::path::Path::new("/scenes/tables/a.binary")
        );
        let t = crate::doc::parse("file = \"/abs/a.binary\"\n", "/scenes/s.toml").unwrap();
        let p = Params::new("bsdf", &t, Location::Builtin, FILE, &[]).unwrap();
        assert_eq!(
            p.get_path("file").unwrap(),
            std::path::Path::new("/abs/a.binary")
        );
    }

    #[test]
    fn range_and_choice_checks() {
        let t = params("reflectance = -1\nheuristic = \"max\"\n");
        let p = Params::new("x", &t, Location::Builtin, SPEC, &[]).unwrap();
        assert!(p
            .get_positive("reflectance")
            .unwrap_err()
            .to_string()
            .contains("positive"));
        let err = p.get_choice("heuristic").unwrap_err().to_string();
        assert!(err.contains("\"balance\", \"power\""), "{err}");
    }
}
