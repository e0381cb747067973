//! How a document node becomes a typed value ([`FromParam`]), and which
//! [`ParamType`] each Rust type declares ([`Param`]).

use std::path::PathBuf;
use std::sync::Arc;

use glam::{UVec2, Vec2, Vec3};

use super::ParamType;
use crate::doc::{Node, Table, Value};
use crate::error::Location;
use crate::image::DecodedImage;
use crate::spectrum::Rgb;

/// A value that can be read from a document node.
pub trait FromParam: Sized {
    /// Converts, or says what was expected.
    fn from_node(node: &Node) -> std::result::Result<Self, String>;
}

/// Said of `{ texture = ".." }` given to a parameter declared without
/// textures.
const NO_TEXTURE: &str = "this parameter takes no texture";

/// A finite number: TOML's `nan` and `inf` are valid floats, but no scene
/// value means them, and a NaN would pass every range check (all its
/// comparisons are false) and poison the render.
fn number(node: &Node) -> std::result::Result<f64, String> {
    let v = match node.value {
        Value::Float(f) => f,
        Value::Int(i) => i as f64,
        Value::Table(ref t) if t.get("texture").is_some() => return Err(NO_TEXTURE.into()),
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
            Value::Table(t) if t.get("texture").is_some() => {
                Err(format!("expected [r, g, b] or one number; {NO_TEXTURE}"))
            }
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

impl FromParam for usize {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        u32::from_node(node).map(|v| v as usize)
    }
}

/// A file path, resolved as [`crate::Location::resolve`] says.
impl FromParam for PathBuf {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        let text = String::from_node(node)?;
        if text.is_empty() {
            return Err("expected a file path, found an empty string".into());
        }
        Ok(node.location.resolve(text))
    }
}

/// A table given as a parameter, with where it was written: for a value
/// with keys of its own that its reader checks (a pixel filter, a
/// placement).
#[derive(Debug, Clone, PartialEq)]
pub struct LocatedTable {
    pub table: Table,
    pub location: Location,
}

impl FromParam for LocatedTable {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::Table(table) => Ok(Self {
                table: table.clone(),
                location: node.location.clone(),
            }),
            other => Err(format!("expected a table, found {}", other.type_name())),
        }
    }
}

/// Texels a host decoded (an asset's embedded image): shared, not copied.
impl FromParam for Arc<DecodedImage> {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::Image(image) => Ok(Arc::clone(image)),
            other => Err(format!(
                "expected decoded texels, which only lumis itself passes, found {}",
                other.type_name()
            )),
        }
    }
}

/// A type a declared parameter can have: the [`ParamType`] its declaration
/// shows, and the checks every value of it gets.
pub trait Param: FromParam {
    const TYPE: ParamType;
    /// The valid strings, for a choice ([`ParamChoice`](super::ParamChoice)).
    const CHOICES: &'static [&'static str] = &[];

    /// Whether the value lies in `[min, max]`, or says it does not; only
    /// numbers declare ranges (`ParamSpec::in_range` refuses others).
    fn check_range(&self, (min, max): (f64, f64)) -> std::result::Result<(), String> {
        Err(format!(
            "a range [{min}, {max}] is declared on a parameter of type {}",
            Self::TYPE.name()
        ))
    }

    /// Converts the node given for `name`; a type whose value may refer to
    /// other plugins (a texture) resolves it through `params`.
    fn read_node(params: &super::Params, name: &str, node: &Node) -> crate::Result<Self> {
        params.convert(name, node)
    }
}

/// Compares a number with its declared range in the number's own
/// precision (`$wide`): a range written `(0.02, 1.0)` holds the f32 `0.02`,
/// which widened to f64 is not the f64 `0.02`. Integers compare in f64,
/// exactly for every value a scene can write.
macro_rules! number_param {
    ($($ty:ty => $param:ident as $wide:ty),*) => {$(
        impl Param for $ty {
            const TYPE: ParamType = ParamType::$param;

            fn check_range(&self, (min, max): (f64, f64)) -> std::result::Result<(), String> {
                let v = *self as $wide;
                if v >= min as $wide && v <= max as $wide {
                    Ok(())
                } else {
                    Err(format!("must be in [{min}, {max}], got {self}"))
                }
            }
        }
    )*};
}

number_param!(
    f32 => Float as f32,
    f64 => Float as f64,
    i64 => Int as f64,
    u32 => Int as f64,
    usize => Int as f64
);

macro_rules! plain_param {
    ($($ty:ty => $param:ident),*) => {$(
        impl Param for $ty {
            const TYPE: ParamType = ParamType::$param;
        }
    )*};
}

plain_param!(
    bool => Bool,
    String => String,
    PathBuf => Path,
    Rgb => Rgb,
    Vec2 => Vec2,
    Vec3 => Vec3,
    UVec2 => UIntPair,
    Vec<f32> => FloatArray,
    Vec<i64> => IntArray,
    Vec<String> => StringArray,
    Vec<PathBuf> => StringArray,
    Vec<Vec3> => Vec3Array,
    Arc<DecodedImage> => Image,
    LocatedTable => Table
);
