//! A BSDF parameter of a BSDF: an adapter (`twosided`) names the
//! `[[bsdf]]` it wraps, declared before it in the scene (Mitsuba 3 nests
//! the inner BSDF; a name keeps tables flat).

use std::fmt;
use std::sync::Arc;

use super::{FromParam, Param, ParamType, Params};
use crate::bsdf::Bsdf;
use crate::doc::Node;
use crate::error::{Error, Result};

/// A BSDF named by a parameter.
#[derive(Clone)]
pub struct NestedBsdf(pub Arc<dyn Bsdf>);

impl fmt::Debug for NestedBsdf {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("NestedBsdf")
    }
}

/// A name alone is no BSDF: only [`Params::value`] can resolve it.
impl FromParam for NestedBsdf {
    fn from_node(_: &Node) -> std::result::Result<Self, String> {
        Err("a BSDF name is resolved against the scene's BSDFs; read it with Params::value".into())
    }
}

impl Param for NestedBsdf {
    const TYPE: ParamType = ParamType::Bsdf;

    fn read_node(params: &Params, name: &str, node: &Node) -> Result<Self> {
        let bsdf_name: String = params.convert(name, node)?;
        let here = |message: String| {
            Error::at(
                &node.location,
                format!("{} key '{name}': {message}", params.owner()),
            )
        };
        let Some(scope) = params.scope else {
            return Err(here(format!(
                "a BSDF (\"{bsdf_name}\") is not accepted here: only BSDFs wrap BSDFs"
            )));
        };
        scope
            .bsdfs
            .get(&bsdf_name)
            .map(|b| NestedBsdf(b.clone()))
            .ok_or_else(|| {
                let names: Vec<&str> = scope.bsdfs.names().collect();
                here(format!(
                    "no [[bsdf]] named \"{bsdf_name}\" is declared before this one{}",
                    if names.is_empty() {
                        String::new()
                    } else {
                        format!("; declared before: {}", names.join(", "))
                    }
                ))
            })
    }
}
