//! The `lumis` command line: the built-in plugin set and the `render`
//! command, as a library so end-to-end tests and benchmarks drive exactly
//! what users run.

mod render;

pub use render::{output_paths, render_scene_file, RenderArgs, RenderReport};

use lumis_core::{Registry, Result};

/// A registry holding every plugin that ships with lumis.
pub fn builtin_registry() -> Result<Registry> {
    let mut registry = Registry::new();
    lumis_samplers::register(&mut registry)?;
    lumis_bsdfs::register(&mut registry)?;
    lumis_lights::register(&mut registry)?;
    lumis_light_samplers::register(&mut registry)?;
    lumis_integrators::register(&mut registry)?;
    Ok(registry)
}
