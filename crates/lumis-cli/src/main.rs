//! `lumis`: a Monte Carlo path tracer about variance reduction.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use lumis_cli::{plugin_listing, registry_with_search_path, render_scene_file, RenderArgs};

#[derive(Parser)]
#[command(
    name = "lumis",
    version,
    about = "A Monte Carlo path tracer that measures what each sampling choice buys"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a TOML scene to PATH.exr (linear float RGB) and PATH.png (sRGB).
    Render {
        /// The scene file.
        scene: PathBuf,
        /// Samples per pixel (overrides sampler.spp).
        #[arg(long)]
        spp: Option<u32>,
        /// Random seed (overrides the scene's top-level seed).
        #[arg(long)]
        seed: Option<u64>,
        /// Worker threads; 0 or absent means one per core.
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Output path: writes PATH.exr and PATH.png [default: the scene's
        /// film.output, else SCENE-NAME.exr in the current directory].
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Override any scene value, e.g. --set integrator.max_depth=3,
        /// --set bsdf.white.reflectance=[0.5,0.5,0.5], --set sampler.type=independent.
        /// Arrays of tables are addressed by name or index (shape.0.file).
        #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
        set: Vec<String>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        /// Print what the loader decided the scene needs.
        #[arg(long, short)]
        verbose: bool,
    },
    /// List every plugin (built-in, and libraries on LUMIS_PLUGIN_PATH or
    /// given with --load) with its parameters: name, type, default, meaning.
    Plugins {
        /// Also load this plugin library (repeatable).
        #[arg(long, value_name = "LIB.so")]
        load: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render {
            scene,
            spp,
            seed,
            threads,
            output,
            set,
            quiet,
            verbose,
        } => registry_with_search_path().and_then(|registry| {
            let args = RenderArgs {
                scene,
                spp,
                seed,
                threads,
                output,
                set,
                progress: !quiet,
                verbose,
            };
            render_scene_file(&args, &registry).map(|report| println!("{}", report.summary()))
        }),
        Command::Plugins { load } => registry_with_search_path().and_then(|mut registry| {
            for library in &load {
                lumis_loader::load_library(library, &mut registry)?;
            }
            print!("{}", plugin_listing(&registry));
            Ok(())
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
