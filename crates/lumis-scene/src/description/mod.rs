//! The first stage: the TOML document to a typed [`SceneDescription`].
//!
//! Every key is checked here, against what the scene layer reads itself
//! (film, camera, shapes, `[accel]`) or against the plugin kind a table
//! names (its parameters are checked when the plugin is created). Every
//! plugin is described the same way, as a [`PluginEntity`] that keeps the
//! locations of its table, so the later stages can still point at the
//! line that caused an error. Nothing is created and no asset is read
//! here, except the glTF asset a `[camera] type = "gltf"` names.

mod accel;
mod adaptive;
mod camera;
mod clamp;
mod document;
mod film;
mod gltf_shape;
mod named;
mod plugin_libraries;
mod shapes;
mod tables;
mod transform;

use lumis_core::doc::Table;
use lumis_core::entity::TYPE_KEY;
use lumis_core::{Error, Location, Params, PluginEntity, PluginKind, PluginParams, Result};
use lumis_render::PerspectiveCamera;

pub(crate) use accel::AccelOptions;
pub use accel::{Compaction, AUTO_COMPACT_TRIANGLES};
pub(crate) use adaptive::AdaptiveDescription;
pub(crate) use film::FilmDescription;
pub(crate) use named::NamedPlugin;
pub(crate) use plugin_libraries::PluginLibraries;
pub(crate) use shapes::{ShapeEntity, ShapeSource, Surface, SurfaceGeometry};
pub use tables::{scene_tables, SceneTable};

use document::{take_required_table, take_table, take_tables};

const TOP_LEVEL_KEYS: &[&str] = &[
    "film",
    "camera",
    "sampler",
    "integrator",
    "light_sampler",
    "texture",
    "bsdf",
    "shape",
    "light",
    "seed",
    "plugins",
    "accel",
    "denoiser",
    "adaptive",
];

/// A scene as its file describes it, checked and typed.
pub(crate) struct SceneDescription {
    pub seed: u64,
    pub film: FilmDescription,
    pub camera: PerspectiveCamera,
    pub plugin_libraries: PluginLibraries,
    pub accel: AccelOptions,
    pub sampler: PluginEntity,
    /// `[adaptive]`.
    pub adaptive: Option<AdaptiveDescription>,
    pub integrator: PluginEntity,
    /// `[film] clamp`: the cap on each sample's largest component.
    pub clamp: Option<f32>,
    /// What the scene writes in a deprecated way, for the load report.
    pub warnings: Vec<String>,
    /// `[denoiser]`: a post-process on the finished film, if the scene asks
    /// for one.
    pub denoiser: Option<PluginEntity>,
    /// `[light_sampler]`, or the uniform one when the scene has none.
    pub light_sampler: PluginEntity,
    /// `[[texture]]`s, which BSDF parameters name.
    pub textures: Vec<NamedPlugin>,
    pub bsdfs: Vec<NamedPlugin>,
    pub shapes: Vec<ShapeEntity>,
    /// `[[light]]` tables (emitting shapes describe their own lights).
    pub lights: Vec<PluginEntity>,
}

impl SceneDescription {
    /// Describes the scene `root` (the whole document, overrides applied);
    /// `file` locates what the document lacks; relative paths resolve as
    /// [`Location::resolve`] says.
    pub fn from_document(mut root: Table, file: &Location) -> Result<Self> {
        check_top_level_keys(&root)?;
        let seed = seed_of(&root, file)?;
        let plugin_libraries =
            plugin_libraries::plugin_libraries(take_table(&mut root, "plugins")?)?;
        let film = film::film(take_table(&mut root, "film")?, file)?;
        let camera = camera::camera(
            take_required_table(&mut root, "camera", file)?,
            film.resolution,
        )?;
        let textures = named::named_plugins(
            PluginKind::Texture,
            "BSDF parameters",
            take_tables(&mut root, "texture")?,
        )?;
        let bsdfs =
            named::named_plugins(PluginKind::Bsdf, "shapes", take_tables(&mut root, "bsdf")?)?;
        let accel = accel::accel_options(take_table(&mut root, "accel")?)?;
        let shapes = take_tables(&mut root, "shape")?
            .into_iter()
            .enumerate()
            .map(|(i, table)| shapes::shape(i, table))
            .collect::<Result<Vec<_>>>()?;
        let lights = take_tables(&mut root, "light")?
            .into_iter()
            .enumerate()
            .map(|(i, (table, location))| {
                let owner = format!("[[light]] #{i}");
                PluginEntity::from_table(PluginKind::Light, owner, table, location, TYPE_KEY)
            })
            .collect::<Result<Vec<_>>>()?;
        let light_sampler = match take_table(&mut root, "light_sampler")? {
            Some((table, location)) => PluginEntity::from_table_or(
                PluginKind::LightSampler,
                "light_sampler",
                table,
                location,
                DEFAULT_LIGHT_SAMPLER,
            )?,
            None => default_light_sampler(),
        };
        let (mut sampler_table, sampler_location) =
            take_required_table(&mut root, PluginKind::Sampler.table_name(), file)?;
        let mut warnings = Vec::new();
        let adaptive = adaptive::take_adaptive(
            take_table(&mut root, adaptive::ADAPTIVE_KEY)?,
            &mut sampler_table,
            &mut warnings,
        )?;
        let sampler = PluginEntity::from_table(
            PluginKind::Sampler,
            PluginKind::Sampler.table_name(),
            sampler_table,
            sampler_location,
            TYPE_KEY,
        )?;
        let (mut integrator_table, integrator_location) =
            take_required_table(&mut root, PluginKind::Integrator.table_name(), file)?;
        let clamp = clamp::take_deprecated_clamp(&mut integrator_table, film.clamp, &mut warnings)?;
        let integrator = PluginEntity::from_table(
            PluginKind::Integrator,
            PluginKind::Integrator.table_name(),
            integrator_table,
            integrator_location,
            TYPE_KEY,
        )?;
        let denoiser = take_table(&mut root, "denoiser")?
            .map(|(table, location)| {
                PluginEntity::from_table(
                    PluginKind::Denoiser,
                    "denoiser",
                    table,
                    location,
                    TYPE_KEY,
                )
            })
            .transpose()?;
        Ok(Self {
            seed,
            film,
            camera,
            plugin_libraries,
            accel,
            sampler,
            adaptive,
            integrator,
            clamp,
            warnings,
            denoiser,
            light_sampler,
            textures,
            bsdfs,
            shapes,
            lights,
        })
    }
}

/// The light sampler of a scene without `[light_sampler]`, or whose table
/// names no type.
const DEFAULT_LIGHT_SAMPLER: &str = "uniform";

fn default_light_sampler() -> PluginEntity {
    PluginEntity::new(
        PluginKind::LightSampler,
        "light_sampler",
        DEFAULT_LIGHT_SAMPLER,
        Table::default(),
        Location::Builtin,
    )
}

fn check_top_level_keys(root: &Table) -> Result<()> {
    match root
        .entries
        .iter()
        .find(|e| !TOP_LEVEL_KEYS.contains(&e.key.as_str()))
    {
        Some(entry) => Err(Error::at(
            &entry.key_location,
            format!(
                "unknown top-level key '{}'; accepted: {}",
                entry.key,
                TOP_LEVEL_KEYS.join(", ")
            ),
        )),
        None => Ok(()),
    }
}

/// The top level's own key (the others name tables).
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct TopLevelParams {
    /// the render's random seed, a non-negative integer (--seed overrides
    /// it)
    #[param(default = 0)]
    seed: i64,
}

/// `seed`, read through the declaration of the top-level keys (the
/// tables beside it are read by their own).
fn seed_of(root: &Table, file: &Location) -> Result<u64> {
    let mut top = Table::default();
    top.entries.extend(
        root.entries
            .iter()
            .filter(|e| e.key == TopLevelParams::KEYS.seed)
            .cloned(),
    );
    let params = Params::new(
        "the top level",
        &top,
        file.clone(),
        TopLevelParams::SPECS,
        &[],
    )?;
    let seed = TopLevelParams::read(&params)?.seed;
    if seed < 0 {
        return Err(params.error(
            TopLevelParams::KEYS.seed,
            format!("expected a non-negative integer, got {seed}"),
        ));
    }
    params.finish()?;
    Ok(seed as u64)
}

#[cfg(test)]
mod tests;
