//! The declaration of one parameter: its name, type, typed default, valid
//! range or choices and meaning.
//!
//! Every constructor is a `const fn` that checks what it is given (a
//! default of the wrong type, outside its range or among no choice), so a
//! wrong declaration in a `const` fails to compile.

use std::fmt;

use crate::doc::{Node, Value};
use crate::error::Location;

/// The type of a parameter, as shown to users and checked on access.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamType {
    Bool,
    Int,
    Float,
    String,
    /// A file, relative to the scene file that names it.
    Path,
    /// `[r, g, b]` or one number for grey.
    Rgb,
    /// An `rgb`, or `{ texture = "name" }`.
    TexturedRgb,
    /// A `float`, or `{ texture = "name" }`.
    TexturedFloat,
    /// The name of a `[[bsdf]]` declared before.
    Bsdf,
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
    /// Decoded texels, given by the host (an image embedded in an asset).
    Image,
}

impl ParamType {
    pub fn name(self) -> &'static str {
        match self {
            ParamType::Bool => "bool",
            ParamType::Int => "int",
            ParamType::Float => "float",
            ParamType::String => "string",
            ParamType::Path => "path",
            ParamType::Rgb => "rgb",
            ParamType::TexturedRgb => "rgb or texture",
            ParamType::TexturedFloat => "float or texture",
            ParamType::Bsdf => "bsdf name",
            ParamType::Vec2 => "vec2",
            ParamType::Vec3 => "vec3",
            ParamType::UIntPair => "[uint, uint]",
            ParamType::FloatArray => "[float]",
            ParamType::Vec3Array => "[vec3]",
            ParamType::IntArray => "[int]",
            ParamType::StringArray => "[string]",
            ParamType::Table => "table",
            ParamType::Image => "decoded image (from the host)",
        }
    }

    /// Whether a range can apply to it.
    const fn is_number(self) -> bool {
        matches!(
            self,
            ParamType::Int | ParamType::Float | ParamType::TexturedFloat
        )
    }
}

/// A default value, shaped as a scene file writes it: `0.5` is a grey for
/// an `rgb` parameter as it would be in a scene, and `lumis plugins` prints
/// it as written. Reading converts it exactly as it converts a scene's
/// value, so a default means what the same text in a scene would.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamValue {
    Bool(bool),
    Int(i64),
    Float(f64),
    Str(&'static str),
    Array(&'static [ParamValue]),
}

impl ParamValue {
    /// The value as a document node, located in lumis itself.
    pub fn to_node(self) -> Node {
        let value = match self {
            ParamValue::Bool(b) => Value::Bool(b),
            ParamValue::Int(i) => Value::Int(i),
            ParamValue::Float(f) => Value::Float(f),
            ParamValue::Str(s) => Value::String(s.to_string()),
            ParamValue::Array(items) => Value::Array(items.iter().map(|v| v.to_node()).collect()),
        };
        Node {
            value,
            location: Location::Builtin,
        }
    }

    /// Whether a parameter of type `ty` accepts this value; a `const fn`
    /// so that declarations are checked when they compile.
    pub const fn fits(self, ty: ParamType) -> bool {
        match ty {
            ParamType::Bool => matches!(self, ParamValue::Bool(_)),
            ParamType::Int => matches!(self, ParamValue::Int(_)),
            ParamType::Float | ParamType::TexturedFloat => self.is_number(),
            ParamType::String | ParamType::Path | ParamType::Bsdf => {
                matches!(self, ParamValue::Str(_))
            }
            ParamType::Rgb | ParamType::TexturedRgb => self.is_number() || self.is_numbers(3),
            ParamType::Vec2 => self.is_numbers(2),
            ParamType::Vec3 => self.is_numbers(3),
            ParamType::UIntPair => match self {
                ParamValue::Array(&[ParamValue::Int(a), ParamValue::Int(b)]) => {
                    a >= 0 && b >= 0 && a <= u32::MAX as i64 && b <= u32::MAX as i64
                }
                _ => false,
            },
            ParamType::FloatArray => self.all(ParamType::Float),
            ParamType::Vec3Array => self.all(ParamType::Vec3),
            ParamType::IntArray => self.all(ParamType::Int),
            ParamType::StringArray => self.all(ParamType::String),
            ParamType::Table | ParamType::Image => false,
        }
    }

    const fn is_number(self) -> bool {
        matches!(self, ParamValue::Int(_) | ParamValue::Float(_))
    }

    const fn is_numbers(self, n: usize) -> bool {
        match self {
            ParamValue::Array(items) => {
                items.len() == n && Self::Array(items).all(ParamType::Float)
            }
            _ => false,
        }
    }

    /// An array whose every element fits `ty`.
    const fn all(self, ty: ParamType) -> bool {
        let ParamValue::Array(items) = self else {
            return false;
        };
        let mut i = 0;
        while i < items.len() {
            if !items[i].fits(ty) {
                return false;
            }
            i += 1;
        }
        true
    }

    const fn within(self, (min, max): (f64, f64)) -> bool {
        match self {
            ParamValue::Int(i) => i as f64 >= min && i as f64 <= max,
            ParamValue::Float(f) => f >= min && f <= max,
            ParamValue::Bool(_) | ParamValue::Str(_) | ParamValue::Array(_) => false,
        }
    }
}

/// As TOML writes it: `0.5`, `"power"`, `[0.0, 1.0, 0.0]`.
impl fmt::Display for ParamValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            ParamValue::Bool(b) => write!(f, "{b}"),
            ParamValue::Int(i) => write!(f, "{i}"),
            // Debug keeps the point of a whole float: `1.0`, not `1`.
            ParamValue::Float(x) => write!(f, "{x:?}"),
            ParamValue::Str(s) => write!(f, "\"{s}\""),
            ParamValue::Array(items) => {
                f.write_str("[")?;
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{item}")?;
                }
                f.write_str("]")
            }
        }
    }
}

/// Whether a parameter must be given, and what it is when it is not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParamDefault {
    Required,
    Value(ParamValue),
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

    /// Panics (at compile time in a `const`) if `default` does not fit `ty`.
    pub const fn with_default(
        name: &'static str,
        ty: ParamType,
        default: ParamValue,
        doc: &'static str,
    ) -> Self {
        Self {
            default: ParamDefault::Value(default),
            ..Self::required(name, ty, doc)
        }
        .checked()
    }

    pub const fn optional(name: &'static str, ty: ParamType, doc: &'static str) -> Self {
        Self {
            default: ParamDefault::Absent,
            ..Self::required(name, ty, doc)
        }
    }

    /// Declares the valid range of a number parameter, which must hold its
    /// default.
    pub const fn in_range(mut self, min: f64, max: f64) -> Self {
        self.range = Some((min, max));
        self.checked()
    }

    /// Declares the valid values of a string parameter, which must include
    /// its default. No choices (`&[]`) means any string.
    pub const fn one_of(mut self, choices: &'static [&'static str]) -> Self {
        self.choices = choices;
        self.checked()
    }

    /// The same parameter with another default, for a plugin that shares a
    /// group of parameters but not all of its defaults.
    pub const fn with_default_value(mut self, default: ParamValue) -> Self {
        self.default = ParamDefault::Value(default);
        self.checked()
    }

    /// `self`, or a panic naming what is inconsistent: at compile time for
    /// declarations in a `const`.
    pub const fn checked(self) -> Self {
        if self.range.is_some() && !self.ty.is_number() {
            panic!("a range is declared on a parameter that is not a number");
        }
        if !self.choices.is_empty() && !matches!(self.ty, ParamType::String) {
            panic!("choices are declared on a parameter that is not a string");
        }
        if let ParamDefault::Value(value) = self.default {
            if !value.fits(self.ty) {
                panic!("a parameter's default does not fit its type");
            }
            if let Some(range) = self.range {
                if !value.within(range) {
                    panic!("a parameter's default is outside its range");
                }
            }
            if let ParamValue::Str(s) = value {
                if !self.choices.is_empty() && !contains(self.choices, s) {
                    panic!("a parameter's default is not among its choices");
                }
            }
        }
        self
    }

    /// The default as a document node, if it has one.
    pub fn default_node(&self) -> Option<Node> {
        match self.default {
            ParamDefault::Value(value) => Some(value.to_node()),
            ParamDefault::Required | ParamDefault::Absent => None,
        }
    }
}

const fn same(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

const fn contains(names: &[&str], name: &str) -> bool {
    let mut i = 0;
    while i < names.len() {
        if same(names[i], name) {
            return true;
        }
        i += 1;
    }
    false
}

const PLACEHOLDER: ParamSpec = ParamSpec::required("", ParamType::Bool, "");

/// The number of parameters in `parts`, for [`concat()`]'s length.
pub const fn total_len(parts: &[&[ParamSpec]]) -> usize {
    let mut n = 0;
    let mut i = 0;
    while i < parts.len() {
        n += parts[i].len();
        i += 1;
    }
    n
}

/// `parts` one after the other, in a `const`: how a declaration that
/// flattens groups of parameters into its own builds its list.
pub const fn concat<const N: usize>(parts: &[&[ParamSpec]]) -> [ParamSpec; N] {
    let mut out = [PLACEHOLDER; N];
    let mut k = 0;
    let mut i = 0;
    while i < parts.len() {
        let mut j = 0;
        while j < parts[i].len() {
            out[k] = parts[i][j];
            k += 1;
            j += 1;
        }
        i += 1;
    }
    if k != N {
        panic!("concat: the length differs from the parts' total_len");
    }
    out
}

/// `specs` with the default of `name` replaced; panics (at compile time in
/// a `const`) if there is no such parameter or the value does not fit it.
pub const fn override_default<const N: usize>(
    specs: [ParamSpec; N],
    name: &str,
    default: ParamValue,
) -> [ParamSpec; N] {
    let mut out = specs;
    let mut i = 0;
    while i < N {
        if same(out[i].name, name) {
            out[i] = out[i].with_default_value(default);
            return out;
        }
        i += 1;
    }
    panic!("a default is given for a parameter the flattened group does not have");
}

/// Whether `name` is among `specs`, in a `const`.
pub const fn declares(specs: &[ParamSpec], name: &str) -> bool {
    let mut i = 0;
    while i < specs.len() {
        if same(specs[i].name, name) {
            return true;
        }
        i += 1;
    }
    false
}

/// Panics (at compile time in a `const`) if two parameters share a name.
pub const fn check_unique(specs: &[ParamSpec]) {
    let mut i = 0;
    while i < specs.len() {
        let mut j = i + 1;
        while j < specs.len() {
            if same(specs[i].name, specs[j].name) {
                panic!("two parameters share a name");
            }
            j += 1;
        }
        i += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_print_as_a_scene_writes_them() {
        for (value, text) in [
            (ParamValue::Float(1.0), "1.0"),
            (ParamValue::Float(0.1), "0.1"),
            (ParamValue::Int(16), "16"),
            (ParamValue::Bool(false), "false"),
            (ParamValue::Str("power"), "\"power\""),
            (
                ParamValue::Array(&[ParamValue::Int(32), ParamValue::Int(64)]),
                "[32, 64]",
            ),
            (ParamValue::Array(&[]), "[]"),
        ] {
            assert_eq!(value.to_string(), text);
        }
    }

    #[test]
    fn defaults_are_checked_against_the_type() {
        let grey = ParamValue::Float(0.5);
        let xyz = ParamValue::Array(&[
            ParamValue::Float(0.0),
            ParamValue::Int(1),
            ParamValue::Float(0.0),
        ]);
        assert!(grey.fits(ParamType::Rgb) && grey.fits(ParamType::Float));
        assert!(!grey.fits(ParamType::Int) && !grey.fits(ParamType::Vec3));
        assert!(xyz.fits(ParamType::Vec3) && xyz.fits(ParamType::Rgb));
        assert!(!xyz.fits(ParamType::Vec2) && !xyz.fits(ParamType::IntArray));
        let pair = ParamValue::Array(&[ParamValue::Int(640), ParamValue::Int(-1)]);
        assert!(!pair.fits(ParamType::UIntPair) && pair.fits(ParamType::IntArray));
        assert!(ParamValue::Array(&[]).fits(ParamType::StringArray));
    }

    #[test]
    fn concat_and_override_build_one_list() {
        const A: &[ParamSpec] = &[ParamSpec::required("a", ParamType::Rgb, "")];
        const B: &[ParamSpec] = &[
            ParamSpec::with_default("b", ParamType::Float, ParamValue::Float(0.1), ""),
            ParamSpec::optional("c", ParamType::Int, ""),
        ];
        const PARTS: &[&[ParamSpec]] = &[
            A,
            &override_default::<2>(concat(&[B]), "b", ParamValue::Float(0.0)),
        ];
        const ALL: [ParamSpec; total_len(PARTS)] = concat(PARTS);
        let names: Vec<&str> = ALL.iter().map(|s| s.name).collect();
        assert_eq!(names, ["a", "b", "c"]);
        assert_eq!(ALL[1].default, ParamDefault::Value(ParamValue::Float(0.0)));
        assert!(declares(&ALL, "c") && !declares(&ALL, "d"));
        check_unique(&ALL);
    }

    #[test]
    #[should_panic(expected = "outside its range")]
    fn a_default_outside_the_range_is_refused() {
        let _ = ParamSpec::with_default("x", ParamType::Float, ParamValue::Float(2.0), "")
            .in_range(0.0, 1.0);
    }

    #[test]
    #[should_panic(expected = "not among its choices")]
    fn a_default_outside_the_choices_is_refused() {
        let _ = ParamSpec::with_default("x", ParamType::String, ParamValue::Str("max"), "")
            .one_of(&["balance", "power"]);
    }
}
