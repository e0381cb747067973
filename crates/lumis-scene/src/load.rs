//! Loading a scene file: the three stages in order.

use std::path::{Path, PathBuf};
use std::time::Instant;

use lumis_core::doc::Table;
use lumis_core::{
    Denoiser, Error, Integrator, Light, LightSampler, Location, PluginEntity, Registry, Result,
    Sampler, Vec2,
};
use lumis_files::{FileKind, MIB};
use lumis_render::{Aov, PerspectiveCamera};

use crate::assembly::assemble;
use crate::description::SceneDescription;
use crate::document::SceneDocument;
use crate::instantiate::{instantiate, scene_registry};
use crate::render_scene::{RenderScene, SceneBsdf};
use crate::report::LoadReport;

/// Everything `lumis render` needs.
pub struct LoadedScene {
    /// The scene file's stem, e.g. `cornell-box`.
    pub name: String,
    pub scene: RenderScene,
    pub camera: PerspectiveCamera,
    pub sampler: Box<dyn Sampler>,
    pub integrator: Box<dyn Integrator>,
    /// `[denoiser]`, run on the finished film; the raw render is kept too.
    pub denoiser: Option<SceneDenoiser>,
    pub seed: u64,
    /// `film.output`, resolved against the scene file's directory.
    pub output: Option<PathBuf>,
    /// `film.aovs`, and the albedo and normal a denoiser reads: the outputs
    /// written beside the colour.
    pub aovs: Vec<lumis_render::Aov>,
    /// `[film] clamp`: the cap on each sample's largest component.
    pub clamp: Option<f32>,
    /// `[adaptive]`, its `max_spp` the sampler's spp.
    pub adaptive: Option<lumis_render::AdaptiveSampling>,
}

/// A scene's `[denoiser]`: the plugin, and the entity it was made from
/// (its `type` and parameters, overrides applied), which a render records
/// in its images so that a merge of its parts, or `lumis denoise`, makes
/// the same one.
pub struct SceneDenoiser {
    pub denoiser: Box<dyn Denoiser>,
    pub entity: PluginEntity,
}

/// A scene is text a person writes: far below this bound, which refuses
/// a file that is not a scene before it fills memory.
pub const SCENE_FILE: FileKind = FileKind::new("scene", 64 * MIB);

/// Reads and loads a scene file.
pub fn load_file(path: &Path, overrides: &[String], registry: &Registry) -> Result<LoadedScene> {
    SceneDocument::read(path)?.load(overrides, registry)
}

/// Loads a scene from TOML text as if it were the file at `path`
/// ([`SceneDocument::parse`]).
pub fn load_str(
    text: &str,
    path: &Path,
    overrides: &[String],
    registry: &Registry,
) -> Result<LoadedScene> {
    SceneDocument::parse(text, path)?.load(overrides, registry)
}

/// Loads a document whose overrides are applied; `origin` locates its
/// root, and `name` names the scene.
///
/// The document is described (every key checked, nothing created), its
/// plugins are created through the registry (extended with the libraries
/// the scene loads), and its shapes are assembled into Embree with their
/// area lights; the light sampler comes last, over every light.
///
/// An integrator that traces paths from the lights
/// ([`lumis_core::Integrator::splats`]) is refused with adaptive sampling,
/// and with a light that starts no paths.
pub(crate) fn load_document(
    root: Table,
    origin: &Location,
    name: &str,
    registry: &Registry,
) -> Result<LoadedScene> {
    let parse_start = Instant::now();
    let description = SceneDescription::from_document(root, origin)?;
    let parse = parse_start.elapsed();
    let extended = scene_registry(&description.plugin_libraries, registry)?;
    let registry = extended.as_ref().unwrap_or(registry);
    let plugins = instantiate(
        registry,
        &description.textures,
        &description.bsdfs,
        &description.lights,
        &description.sampler,
        &description.integrator,
        description.denoiser.as_ref(),
    )?;
    // What the scene's own textures and lights hold (images, environment
    // maps); a glTF asset's textures are added as it is imported.
    let report = LoadReport {
        parse,
        texture_bytes: plugins
            .textures
            .values()
            .map(|t| t.memory_bytes())
            .sum::<usize>()
            + plugins
                .lights
                .iter()
                .map(|l| l.memory_bytes())
                .sum::<usize>(),
        warnings: description.warnings,
        ..LoadReport::default()
    };

    let assembled = assemble(
        registry,
        &plugins.textures,
        description.shapes,
        plugins.bsdfs,
        plugins.lights,
        &description.accel,
        report,
    )?;
    let light_sampler =
        registry.create::<dyn LightSampler>(&description.light_sampler, &assembled.lights)?;
    if plugins.integrator.splats() {
        let integrator = &description.integrator;
        if let Some(adaptive) = &description.adaptive {
            return Err(Error::at(
                &adaptive.location,
                format!(
                    "[adaptive] cannot be used with integrator type '{}': its paths from the \
                     lights add light to pixels that may have stopped sampling",
                    integrator.type_name
                ),
            ));
        }
        if let Some(index) = assembled
            .lights
            .iter()
            .position(|l| !starts_light_paths(l.as_ref()))
        {
            return Err(Error::at(
                &integrator.type_location,
                format!(
                    "integrator type '{}' traces paths from the lights, but light {index} \
                     (of power {}) starts none: its plugin does not implement \
                     Light::sample_le",
                    integrator.type_name,
                    assembled.lights[index].power()
                ),
            ));
        }
    }

    let textured = assembled.footprint || plugins.textures.values().any(|t| t.uses_footprint());
    let scene = RenderScene {
        embree: assembled.embree,
        geometries: assembled.geometries,
        prototypes: assembled.prototypes,
        bsdfs: assembled.bsdfs.into_iter().map(SceneBsdf::new).collect(),
        lights: assembled.lights,
        infinite_lights: assembled.infinite_lights,
        light_sampler,
        counts: assembled.counts,
        report: assembled.report,
        packets: description.accel.packets,
        // Only filtered textures read the pixel footprint; a scene without
        // them does no footprint work at its hits.
        footprint: textured.then(|| {
            description
                .camera
                .pixel_footprint(plugins.sampler.samples_per_pixel())
        }),
        tangent_frames: assembled.tangent_frames,
    };
    let adaptive = description
        .adaptive
        .map(|a| {
            let spp = plugins.sampler.samples_per_pixel();
            lumis_render::AdaptiveSampling::new(a.min_spp, a.max_spp.unwrap_or(spp), a.threshold)
                .map_err(|e| Error::at(&a.location, format!("[adaptive] {}", e.message)))
        })
        .transpose()?;
    // A denoiser is guided by the first hit's albedo and normal (Open Image
    // Denoise's auxiliary images): the film makes them whether or not the
    // scene lists them, and the EXR keeps them.
    let mut aovs = description.film.aovs;
    if plugins.denoiser.is_some() {
        for guide in [Aov::Albedo, Aov::Normal] {
            if !aovs.contains(&guide) {
                aovs.push(guide);
            }
        }
    }
    Ok(LoadedScene {
        name: name.to_string(),
        scene,
        camera: description.camera,
        sampler: plugins.sampler,
        integrator: plugins.integrator,
        denoiser: plugins
            .denoiser
            .zip(description.denoiser)
            .map(|(denoiser, entity)| SceneDenoiser { denoiser, entity }),
        seed: description.seed,
        output: description.film.output,
        aovs,
        clamp: description.clamp,
        adaptive,
    })
}

/// Whether `light` starts paths from the lights: one that keeps
/// [`Light::sample_le`]'s default answers `None` everywhere, one that emits
/// answers somewhere on a 4 x 4 grid of its numbers.
fn starts_light_paths(light: &dyn Light) -> bool {
    light.power().is_black()
        || (0..16).any(|i| {
            let u = Vec2::new((i % 4) as f32 + 0.5, (i / 4) as f32 + 0.5) / 4.0;
            light.sample_le(u, Vec2::new(u.y, u.x)).is_some()
        })
}
