//! The `lumis` command line: the built-in plugin set, the `render` and
//! `samplers analyze` commands, as a library so end-to-end tests and benchmarks drive exactly
//! what users run.

mod assignments;
mod brdf;
mod checkpoint;
mod converge;
mod denoise;
mod denoise_image;
mod diff;
mod integrator_check;
mod interrupt;
mod lecture;
mod listing;
mod memory;
mod merge;
mod metadata;
mod new_plugin;
mod outputs;
mod partial;
mod reference;
mod render;
mod samplers_analyze;
mod slice;
mod slurm;

pub use assignments::{fixed_parameters, parameter_table};
pub use brdf::{
    compress_table, precompute_table, tabulate_bsdf, CompressArgs, PrecomputeArgs, TabulateArgs,
};
pub use checkpoint::{checkpoint_path, Checkpoint};
pub use converge::{
    converge, parse_variants, ConvergeArgs, ConvergeReport, MeasuredImage, Point, Run, Variant,
};
pub use denoise_image::{denoise_image, DenoiseArgs, DenoiseReport};
pub use diff::{diff as diff_images, parse_regions, DiffArgs, Region};
pub use integrator_check::{
    check_integrator_with, format_integrator_results, IntegratorCaseResult, IntegratorCheckConfig,
    IntegratorTest, KNOWN_DEPTHS,
};
pub use interrupt::{stop_on_interrupt, INTERRUPTED_EXIT_CODE};
pub use lecture::{lecture, LectureArgs};
pub use listing::{plugin_listing, plugin_markdown, PLUGIN_MARKDOWN_COMMAND};
pub use merge::{merge, MergeArgs, MergeReport};
pub use metadata::ImageMetadata;
pub use new_plugin::{new_plugin, NewPluginArgs, NewPluginKind};
pub use partial::Partial;
pub use reference::{render_reference, ReferenceArgs};
pub use render::{
    output_paths, render_scene_file, DenoisedReport, RenderArgs, RenderReport,
    DEFAULT_CHECKPOINT_SECONDS,
};
pub use samplers_analyze::{analyze as analyze_samplers, AnalyzeArgs};
pub use slice::SampleSlice;
pub use slurm::{
    slurm_status, submit_slurm, Manifest as SlurmManifest, MergeState, PartState, SlurmArgs,
    SlurmCommand, SlurmStatusArgs, SlurmSubmitArgs, StatusReport, Submission, MANIFEST_NAME,
};

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

/// Warns on stderr where `--threads` asks for more workers than a render
/// runs (`lumis_render::worker_threads`).
pub fn warn_if_threads_capped(requested: usize) {
    let used = lumis_render::worker_threads(requested);
    if requested != 0 && used < requested {
        eprintln!(
            "warning: --threads {requested} capped at {used} ({} per core)",
            lumis_render::MAX_THREADS_PER_CORE
        );
    }
}

/// The built-in plugins plus every library on `LUMIS_PLUGIN_PATH`.
pub fn registry_with_search_path() -> Result<Registry> {
    let mut registry = builtin_registry()?;
    for library in lumis_loader::libraries_on_search_path()? {
        lumis_loader::load_library(&library, &mut registry)?;
    }
    Ok(registry)
}
