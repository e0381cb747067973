//! The plugins a session renders with: those that ship with lumis, and the
//! libraries on `LUMIS_PLUGIN_PATH`.

use lumis_core::{Registry, Result};

/// A registry holding every plugin that ships with lumis; the integrators
/// come compiled for lumis's own scene type too (see
/// [`lumis_integrators::Specialized`]).
pub fn builtin_registry() -> Result<Registry> {
    let mut registry = Registry::new();
    lumis_samplers::register(&mut registry)?;
    lumis_textures::register(&mut registry)?;
    lumis_bsdfs::register(&mut registry)?;
    lumis_measured::register(&mut registry)?;
    lumis_lights::register(&mut registry)?;
    lumis_light_samplers::register(&mut registry)?;
    lumis_integrators::register_specialized::<lumis_scene::RenderScene>(&mut registry)?;
    lumis_denoise::register(&mut registry)?;
    Ok(registry)
}

/// The built-in plugins plus every library on `LUMIS_PLUGIN_PATH`.
pub fn registry_with_search_path() -> Result<Registry> {
    let mut registry = builtin_registry()?;
    for library in lumis_loader::libraries_on_search_path()? {
        lumis_loader::load_library(&library, &mut registry)?;
    }
    Ok(registry)
}
