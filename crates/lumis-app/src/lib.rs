//! The render session: what `lumis render`, `merge` and `denoise` do, as
//! a library that prints nothing, so that the command line, the Python
//! module and the tests drive the same code.
//!
//! A render ([`render`]) loads a scene with its overrides, renders it in
//! passes into a film, saves checkpoints and resumes from them, renders a
//! part of the samples or sums the parts itself, denoises, and writes the
//! EXR and PNG with their metadata; [`merge`] adds the parts of a render
//! and [`denoise_image`] denoises an image on disk; [`render_reference`]
//! renders a converged reference pass by pass. What a render has to
//! say while it runs (its start-up report, a resume, a warning) and how far
//! it is go to the caller through a [`Session`], which also carries the
//! flag that stops it.
//!
//! The settings of each job ([`RenderArgs`], [`MergeArgs`],
//! [`DenoiseArgs`]) are declared once, with their documentation: the
//! command line parses its flags into them (they derive `clap::Args`),
//! and a library caller fills them in.

mod assignments;
mod checkpoint;
mod denoise;
mod denoise_image;
mod film_render;
mod memory;
mod merge;
mod metadata;
mod outputs;
mod partial;
mod passes;
mod reference;
mod registry;
mod render;
mod render_args;
mod render_report;
mod session;
mod slice;

pub use assignments::{fixed_parameters, parameter_table, parameter_text};
pub use checkpoint::{checkpoint_path, Checkpoint};
pub use denoise::denoised_paths;
pub use denoise_image::{denoise_image, DenoiseArgs, DenoiseReport};
pub use film_render::{render_film, FilmRender, FilmRequest};
pub use memory::parse_bytes;
pub use merge::{merge, MergeArgs, MergeReport};
pub use metadata::ImageMetadata;
pub use outputs::same_file;
pub use partial::Partial;
pub use reference::{render_reference, ReferenceArgs};
pub use registry::{builtin_registry, registry_with_search_path};
pub use render::{output_paths, render, threads_capped};
pub use render_args::{RenderArgs, DEFAULT_CHECKPOINT_SECONDS};
pub use render_report::{DenoisedReport, RenderReport};
pub use session::{Progress, Session};
pub use slice::SampleSlice;
