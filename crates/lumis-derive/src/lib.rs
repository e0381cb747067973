//! Derive macros that declare a lumis plugin's parameters once, as a
//! struct, and generate both the declaration (`PluginSpec::params`: names,
//! types, typed defaults, ranges, choices, docs) and the code that reads
//! it. Use them through `lumis_api`, which re-exports them next to the
//! traits they implement:
//!
//! ```ignore
//! use lumis_api::{ParamChoice, PluginParams, Rgb};
//!
//! #[derive(PluginParams)]
//! pub struct DiffuseParams {
//!     /// albedo R in linear RGB, each channel in [0, 1]
//!     reflectance: Rgb,
//!     /// how directions are drawn
//!     #[param(default = Cosine)]
//!     sampling: DiffuseSampling,
//! }
//!
//! #[derive(Clone, Copy, ParamChoice)]
//! pub enum DiffuseSampling { Cosine, Uniform }
//! ```
//!
//! The generated code names `::lumis_api`, so a crate using the derives
//! depends on lumis-api under that name.

mod attrs;
mod param_choice;
mod plugin_interface;
mod plugin_params;
mod source_file;
mod value;

use proc_macro::TokenStream;
use syn::{parse_macro_input, DeriveInput};

/// Implements `lumis_api::PluginParams` for a struct with named fields:
/// one parameter per field, named after it.
///
/// - The field's `///` comment is the parameter's description (required).
/// - `#[param(default = 0.5)]`: a default, written as in a scene file
///   (`true`, `16`, `0.5`, `"text"`, `[0.0, 1.0, 0.0]`) or, for a choice,
///   as a variant (`Ggx`, or `Distribution::Ggx`).
/// - `#[param(range = (0.0, 1.0))]`: the valid range of a number.
/// - `#[param(rename = "name")]`: a scene key other than the field's name.
/// - `Option<T>`: the parameter may be absent; a field that is neither an
///   `Option` nor has a default is required.
/// - `#[param(flatten)]`: a group of parameters (another struct deriving
///   `PluginParams`) shared by several plugins, in place;
///   `#[param(flatten, default(roughness = 0.0))]` changes some of the
///   group's defaults for this plugin.
///
/// Also generates `<Name>Keys`, the scene keys of the fields
/// (`PluginParams::KEYS`), for errors about values only the plugin can
/// judge. A default of the wrong type or outside the range, a choice
/// default that is no variant, a missing doc comment or two parameters of
/// the same name fail to compile.
#[proc_macro_derive(PluginParams, attributes(param))]
pub fn derive_plugin_params(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    plugin_params::expand(&input)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// Implements `lumis_api::params::ParamChoice` (and `Param`,
/// `FromParam`) for a fieldless enum: a string parameter whose choices are
/// the variants, named in kebab case (`SolidAngle` is `"solid-angle"`) or
/// by `#[choice("Ag")]`.
#[proc_macro_derive(ParamChoice, attributes(choice))]
pub fn derive_param_choice(input: TokenStream) -> TokenStream {
    let input = parse_macro_input!(input as DeriveInput);
    param_choice::expand(&input)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// Declares a plugin interface: the trait, and its wrappers generated from
/// it (`lumis_api::wrap::Wrapped<C, H>` implements it by forwarding every
/// method through a `CallHook`: the panic guard of a loaded plugin, the
/// profiler). A method added to the trait is forwarded by every wrapper
/// without further code.
///
/// - `#[on_fault(expr)]` on a method: its answer when the hook did not let
///   the call complete (the arguments, and the fault as `fault`, are in
///   scope); without it, `Neutral::neutral()` of the return type.
/// - `#[wrappers_answer(expr)]`: wrappers answer without asking the
///   wrapped object (`Scene::as_any`, whose answer would bypass them).
/// - `#[plugin_interface(lane_view = Lane)]`: also implements the trait for
///   one lane of a batch of samplers.
#[proc_macro_attribute]
pub fn plugin_interface(args: TokenStream, item: TokenStream) -> TokenStream {
    let args = parse_macro_input!(args as plugin_interface::Args);
    let item = parse_macro_input!(item as syn::ItemTrait);
    plugin_interface::expand(args, item)
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}

/// `lumis_api::SourceFile` of the file it is written in: its path
/// (`file!()`) and its module documentation (the leading `//!` lines), for
/// `PluginSpec::source`. The plugin reference links to the file and
/// renders the documentation below the plugin's parameters.
#[proc_macro]
pub fn source_file(input: TokenStream) -> TokenStream {
    if !input.is_empty() {
        return syn::Error::new(
            proc_macro2::Span::call_site(),
            "source_file!() takes no arguments",
        )
        .into_compile_error()
        .into();
    }
    source_file::expand()
        .unwrap_or_else(syn::Error::into_compile_error)
        .into()
}
