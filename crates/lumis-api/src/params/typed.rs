//! Parameters declared once, as a struct: `#[derive(PluginParams)]` writes
//! its declaration ([`PluginParams::SPECS`]) and the code that reads it
//! ([`PluginParams::read`]) from the same fields, and
//! `#[derive(ParamChoice)]` turns a fieldless enum into a string parameter
//! whose choices are its variants. A field read under a name the
//! declaration does not have, or as another type, cannot compile.

use super::{quoted, FromParam, ParamSpec, Params};
use crate::doc::Node;
use crate::error::Result;

/// A plugin's parameters as a struct (derive it: see the plugin guide).
pub trait PluginParams: Sized {
    /// The declaration, for [`PluginSpec::params`](crate::PluginSpec):
    /// one entry per field, flattened groups in place.
    const SPECS: &'static [ParamSpec];
    /// Each field's key as the scene writes it, for messages about a value
    /// that only the plugin can judge ([`Params::error`]).
    type Keys: Copy + 'static;
    const KEYS: Self::Keys;

    /// Reads every field (its value, its default or its absence), checking
    /// types, ranges and choices, with errors located in the scene file.
    fn read(params: &Params) -> Result<Self>;
}

/// A string parameter whose values are the variants of a fieldless enum
/// (derive it: the names are the variants in kebab case, or
/// `#[choice("...")]`).
pub trait ParamChoice: Copy + 'static {
    /// Every variant, in order.
    const VARIANTS: &'static [Self];
    /// Their names, in the same order.
    const NAMES: &'static [&'static str];

    /// The variant's name.
    fn name(self) -> &'static str;

    /// The variant named `name`, if any.
    fn from_name(name: &str) -> Option<Self> {
        Self::VARIANTS
            .iter()
            .zip(Self::NAMES)
            .find_map(|(&variant, &n)| (n == name).then_some(variant))
    }
}

/// Reads a choice: a string among `T::NAMES`, or an error listing them.
pub fn choice_from_node<T: ParamChoice>(node: &Node) -> std::result::Result<T, String> {
    let name = String::from_node(node)?;
    T::from_name(&name)
        .ok_or_else(|| format!("must be one of {}, got \"{name}\"", quoted(T::NAMES)))
}
