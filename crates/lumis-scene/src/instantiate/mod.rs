//! The second stage: plugins from their entities.
//!
//! Every plugin, of every kind, is made by [`Registry::create`] from a
//! [`PluginEntity`]: the ones the description names here, area lights and
//! the BSDFs of imported materials during the assembly, the light sampler
//! once the lights exist. Only the plugins a scene names are created.

mod bsdf_table;

use lumis_core::texture::Named;
use lumis_core::{
    Bsdf, BsdfScope, Denoiser, Error, Integrator, Light, LightInput, LightShape, PluginEntity,
    Registry, Result, Sampler, Texture, Textures,
};

pub(crate) use bsdf_table::BsdfTable;

use crate::description::{NamedPlugin, PluginLibraries};

/// The plugins a scene names outside its shapes.
pub(crate) struct Plugins {
    pub sampler: Box<dyn Sampler>,
    pub integrator: Box<dyn Integrator>,
    pub denoiser: Option<Box<dyn Denoiser>>,
    pub bsdfs: BsdfTable,
    /// `[[light]]`s, in file order.
    pub lights: Vec<Box<dyn Light>>,
    /// The `[[texture]]`s by name, which shapes' emission may name too.
    pub textures: Textures,
}

/// Creates the `[[texture]]`s, `[[bsdf]]`s (whose parameters may name the
/// textures), `[[light]]`s, sampler, integrator and denoiser.
pub(crate) fn instantiate(
    registry: &Registry,
    textures: &[NamedPlugin],
    bsdfs: &[NamedPlugin],
    lights: &[PluginEntity],
    sampler: &PluginEntity,
    integrator: &PluginEntity,
    denoiser: Option<&PluginEntity>,
) -> Result<Plugins> {
    let mut by_name = Textures::new();
    for texture in textures {
        let made = registry.create::<dyn Texture>(&texture.entity, ())?;
        if !by_name.insert(texture.name.clone(), made) {
            return Err(Error::at(
                &texture.entity.location,
                format!("a [[texture]] named \"{}\" already exists", texture.name),
            ));
        }
    }
    // Each BSDF may name the textures and the BSDFs declared before it.
    let mut before = Named::<dyn Bsdf>::new();
    let mut named = Vec::with_capacity(bsdfs.len());
    for b in bsdfs {
        let scope = BsdfScope {
            textures: &by_name,
            bsdfs: &before,
        };
        let made = registry.create::<dyn Bsdf>(&b.entity, scope)?;
        before.insert(b.name.clone(), made.clone());
        named.push((b.name.clone(), made));
    }
    let lights = lights
        .iter()
        .map(|l| {
            let input = LightInput {
                shape: &LightShape::None,
                textures: &by_name,
            };
            registry.create::<dyn Light>(l, input)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Plugins {
        sampler: registry.create::<dyn Sampler>(sampler, ())?,
        integrator: registry.create::<dyn Integrator>(integrator, ())?,
        denoiser: denoiser
            .map(|d| registry.create::<dyn Denoiser>(d, ()))
            .transpose()?,
        bsdfs: BsdfTable::named(named),
        lights,
        textures: by_name,
    })
}

/// A copy of `registry` extended with the scene's plugin libraries, or
/// `None` when it loads none: the caller's registry stays as it was, and
/// nothing but what this scene names is registered.
pub(crate) fn scene_registry(
    libraries: &PluginLibraries,
    registry: &Registry,
) -> Result<Option<Registry>> {
    if libraries.location.is_none() {
        return Ok(None);
    }
    let mut extended = registry.clone();
    for library in &libraries.paths {
        lumis_loader::load_library(library, &mut extended)
            .map_err(|e| libraries.error(e.message))?;
    }
    Ok(Some(extended))
}
