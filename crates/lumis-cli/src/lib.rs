//! The `lumis` command line's own pieces: the plugin listing and reference
//! page, `new-plugin`, and what an interrupt does. The render session is
//! the `lumis-app` library; the studies, the Slurm driver and the BRDF
//! tools are `lumis-studies`, `lumis-slurm` and `lumis-brdf`. This crate is
//! a library too, so that end-to-end tests drive exactly what users run.

mod interrupt;
mod listing;
mod new_plugin;
mod plugin_notes;

pub use interrupt::{stop_on_interrupt, INTERRUPTED_EXIT_CODE};
pub use listing::{plugin_listing, plugin_markdown, PLUGIN_MARKDOWN_COMMAND};
pub use new_plugin::{new_plugin, NewPluginArgs, NewPluginKind};
