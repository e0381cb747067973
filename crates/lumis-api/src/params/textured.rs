//! Parameters that a texture may give: `reflectance = 0.5` or
//! `reflectance = { texture = "wood" }` (pbrt-v4's and Mitsuba 3's textured
//! material parameters). A BSDF declares such a field once, as
//! [`TexturedRgb`] or [`TexturedFloat`], and evaluates it at each hit.

use std::fmt;
use std::sync::Arc;

use super::{FromParam, Param, ParamType, Params};
use crate::doc::{Node, Table, Value};
use crate::error::{Error, Result};
use crate::spectrum::Rgb;
use crate::texture::{Texture, TextureQuery};

/// A constant, or a texture of the scene.
#[derive(Clone)]
pub enum Textured<T> {
    Constant(T),
    Texture(Arc<dyn Texture>),
}

/// A colour parameter a texture may give.
pub type TexturedRgb = Textured<Rgb>;
/// A number parameter a texture may give (its channels' mean,
/// [`Texture::eval_float`]).
pub type TexturedFloat = Textured<f32>;

impl<T: fmt::Debug> fmt::Debug for Textured<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Textured::Constant(v) => write!(f, "Constant({v:?})"),
            Textured::Texture(_) => f.write_str("Texture"),
        }
    }
}

impl<T: Copy> Textured<T> {
    /// The value if it is a constant.
    pub fn constant(&self) -> Option<T> {
        match self {
            Textured::Constant(v) => Some(*v),
            Textured::Texture(_) => None,
        }
    }
}

impl From<Rgb> for TexturedRgb {
    fn from(v: Rgb) -> Self {
        Textured::Constant(v)
    }
}

impl From<f32> for TexturedFloat {
    fn from(v: f32) -> Self {
        Textured::Constant(v)
    }
}

impl TexturedRgb {
    /// The colour at `query`.
    #[inline]
    pub fn eval(&self, query: &TextureQuery) -> Rgb {
        match self {
            Textured::Constant(v) => *v,
            Textured::Texture(t) => t.eval(query),
        }
    }
}

impl TexturedFloat {
    /// The number at `query`.
    #[inline]
    pub fn eval(&self, query: &TextureQuery) -> f32 {
        match self {
            Textured::Constant(v) => *v,
            Textured::Texture(t) => t.eval_float(query),
        }
    }
}

/// The constant form; a `{ texture = ".." }` table needs the scene's
/// textures, which only [`Params::value`] has.
impl<T: FromParam> FromParam for Textured<T> {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::Table(_) => Err(
                "a texture reference is resolved against the scene's textures; read it with Params::value".into(),
            ),
            _ => T::from_node(node).map(Textured::Constant),
        }
    }
}

macro_rules! textured_param {
    ($($ty:ty => $param:ident),*) => {$(
        impl Param for Textured<$ty> {
            const TYPE: ParamType = ParamType::$param;

            fn check_range(&self, range: (f64, f64)) -> std::result::Result<(), String> {
                match self {
                    Textured::Constant(v) => v.check_range(range),
                    // A texture's values are not known before the render.
                    Textured::Texture(_) => Ok(()),
                }
            }

            fn read_node(params: &Params, name: &str, node: &Node) -> Result<Self> {
                match &node.value {
                    Value::Table(table) => params.texture(name, table, &node.location).map(Textured::Texture),
                    _ => params.convert(name, node),
                }
            }
        }
    )*};
}

textured_param!(Rgb => TexturedRgb, f32 => TexturedFloat);

impl Params<'_> {
    /// The texture a `{ texture = "name" }` table refers to, or an error
    /// naming the key and what was expected.
    fn texture(
        &self,
        name: &str,
        table: &Table,
        location: &crate::Location,
    ) -> Result<Arc<dyn Texture>> {
        let here = |message: String| {
            Error::at(
                location,
                format!("{} key '{name}': {message}", self.owner()),
            )
        };
        if let Some(extra) = table.entries.iter().find(|e| e.key != "texture") {
            return Err(Error::at(
                &extra.key_location,
                format!(
                    "{} key '{name}': unknown key '{}'; expected {{ texture = \"name\" }}",
                    self.owner(),
                    extra.key
                ),
            ));
        }
        let texture_name = match table.get("texture") {
            Some(Node {
                value: Value::String(s),
                ..
            }) => s,
            Some(node) => {
                return Err(Error::at(
                    &node.location,
                    format!(
                        "{} key '{name}': 'texture' must be the name of a [[texture]], found {}",
                        self.owner(),
                        node.value.type_name()
                    ),
                ))
            }
            None => {
                return Err(here(
                    "expected { texture = \"name\" }, found an empty table".into(),
                ))
            }
        };
        let Some(textures) = self.scope.map(|s| s.textures) else {
            return Err(here(format!(
                "a texture (\"{texture_name}\") is not accepted here: only the BSDFs of a scene take textures"
            )));
        };
        textures.get(texture_name).cloned().ok_or_else(|| {
            let names: Vec<&str> = textures.names().collect();
            here(format!(
                "unknown texture \"{texture_name}\"; {}",
                if names.is_empty() {
                    "the scene declares no [[texture]]".to_string()
                } else {
                    format!("declared: {}", names.join(", "))
                }
            ))
        })
    }
}
