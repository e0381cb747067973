//! The `lumis` command line's own commands: the studies (`converge`,
//! `lecture`, `samplers analyze`), the BRDF tools, the Slurm driver,
//! `diff`, the plugin listing and `new-plugin`. The
//! render session they build on (render, merge, denoise, references) is
//! the `lumis-app` library; this crate is a library too, so that end-to-end
//! tests and benchmarks drive exactly what users run.

mod brdf;
mod converge;
mod diff;
mod interrupt;
mod lecture;
mod listing;
mod new_plugin;
mod plugin_notes;
mod samplers_analyze;
mod slurm;

pub use brdf::{
    compress_table, precompute_table, tabulate_bsdf, CompressArgs, PrecomputeArgs, TabulateArgs,
};
pub use converge::{
    converge, parse_variants, ConvergeArgs, ConvergeReport, MeasuredImage, Point, Run, Variant,
};
pub use diff::{diff as diff_images, parse_regions, DiffArgs, Region};
pub use interrupt::{stop_on_interrupt, INTERRUPTED_EXIT_CODE};
pub use lecture::{lecture, LectureArgs};
pub use listing::{plugin_listing, plugin_markdown, PLUGIN_MARKDOWN_COMMAND};
pub use new_plugin::{new_plugin, NewPluginArgs, NewPluginKind};
pub use samplers_analyze::{analyze as analyze_samplers, AnalyzeArgs};
pub use slurm::{
    slurm_status, submit_slurm, Manifest as SlurmManifest, MergeState, PartState, SlurmArgs,
    SlurmCommand, SlurmStatusArgs, SlurmSubmitArgs, StatusReport, Submission, MANIFEST_NAME,
};
