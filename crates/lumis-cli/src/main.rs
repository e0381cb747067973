//! `lumis`: a Monte Carlo path tracer about variance reduction.

mod check_plugin;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use lumis_app::{
    denoise_image, merge, registry_with_search_path, render, render_reference, DenoiseArgs,
    MergeArgs, Progress, ReferenceArgs, RenderArgs, Session,
};
use lumis_brdf::{
    compress_table, precompute_table, tabulate_bsdf, CompressArgs, PrecomputeArgs, TabulateArgs,
};
use lumis_cli::{
    new_plugin, plugin_listing, plugin_markdown, stop_on_interrupt, NewPluginArgs,
    INTERRUPTED_EXIT_CODE,
};
use lumis_core::{Error, Registry, Result};
use lumis_sampling::simd::{self, Isa};
use lumis_slurm::{slurm_status, submit_slurm, SlurmArgs, SlurmCommand};
use lumis_studies::{
    analyze_samplers, converge, diff_images, lecture, AnalyzeArgs, ConvergeArgs, DiffArgs,
    LectureArgs,
};

use check_plugin::check_plugin;
use lumis_check::plugins::PluginNames;

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
    Render(RenderArgs),
    /// Merge the partial images of a render split into parts (`render
    /// --part K/N` or `--samples A..B`) into the image one render makes,
    /// after checking they are parts of one render (scene, seed, spp) that
    /// cover each sample index once; denoise it as the render would when
    /// its scene has a `[denoiser]`.
    Merge(MergeArgs),
    /// Denoise an image on disk (an EXR, guided by the albedo and normal
    /// layers a render writes) into IMAGE.denoised.exr and .png, with the
    /// denoiser of its scene (`lumis.denoiser` in its header), else oidn,
    /// or --denoiser TYPE.
    Denoise(DenoiseArgs),
    /// List every plugin (built-in, and libraries on LUMIS_PLUGIN_PATH or
    /// given with --load) with its parameters: name, type, default, meaning.
    Plugins {
        /// Also load this plugin library (repeatable).
        #[arg(long, value_name = "LIB.so")]
        load: Vec<PathBuf>,
        /// Print the list as the book's Markdown reference (docs/src/plugins.md).
        #[arg(long)]
        markdown: bool,
    },
    /// Statistically check BSDF, light, light-sampler, sampler and
    /// integrator plugins over a sweep of their parameters: for BSDFs,
    /// chi-square of sample_f against pdf, pdf normalisation,
    /// sample_f/f/pdf consistency, albedo <= 1, reciprocity and finiteness,
    /// at incident angles down to cos theta = 1e-4; for lights, chi-square
    /// of sample_li against pdf_li from points around and inside them,
    /// consistency and finiteness; for light samplers, the pmf against the
    /// draws; for samplers, the range [0, 1), determinism, the declared film
    /// pattern (exactly) and uniformity; for integrators, white furnaces and
    /// agreement with the built-in path tracer. Exits non-zero on any
    /// failure and writes observed-vs-expected PNGs for failed chi-square
    /// cases.
    CheckPlugin {
        /// A plugin library: checks every plugin of these kinds it registers.
        library: Option<PathBuf>,
        /// Check this BSDF (built-in or from the library); repeatable.
        #[arg(long)]
        bsdf: Vec<String>,
        /// Check this light (built-in or from the library); repeatable.
        #[arg(long)]
        light: Vec<String>,
        /// Check this light sampler (built-in or from the library); repeatable.
        #[arg(long)]
        light_sampler: Vec<String>,
        /// Check this sampler (built-in or from the library); repeatable.
        #[arg(long)]
        sampler: Vec<String>,
        /// Check this integrator (built-in or from the library); repeatable.
        #[arg(long)]
        integrator: Vec<String>,
        /// Samples per chi-square test; the albedo, consistency and
        /// reciprocity checks take 100,000, or this many if fewer.
        #[arg(long, default_value_t = 1_000_000)]
        samples: usize,
        /// Bins per axis (cos theta and phi) of the chi-square histogram.
        #[arg(long, default_value_t = 100)]
        bins: usize,
        /// Where failure pictures go.
        #[arg(long, default_value = ".")]
        out: PathBuf,
        /// Hold a parameter at this value in every case instead of sweeping
        /// it, e.g. `--bsdf measured --set file=table.binary` (repeatable).
        #[arg(long = "set", value_name = "key=value")]
        set: Vec<String>,
    },
    /// Write a new plugin crate NAME/ of the given kind: a small working
    /// example, its tests (with lumis-check) and a README, building against
    /// this lumis.
    NewPlugin(NewPluginArgs),
    /// Render a high-spp reference with the scene's own settings, saved
    /// after every pass with its metadata in the EXR header; rerun to
    /// resume. Refuses, without --force, to replace a reference that is
    /// more converged or of another scene.
    Reference(ReferenceArgs),
    /// Error vs samples and vs time against a reference, for variants of a
    /// scene (sampler, strategy, heuristic, BSDF sampling...) over seeds:
    /// CSV, JSON, two log-log plots and a table ranked by efficiency.
    Converge(ConvergeArgs),
    /// Error of an image against a reference: MSE, RMSE, relMSE, mean
    /// absolute and signed relative error, PSNR, per named region, and an
    /// optional false-colour error picture.
    Diff(DiffArgs),
    /// Render SCENE as a Slurm job array of --tasks parts and a merge job
    /// that waits for all of them (`lumis slurm SCENE --tasks N`), or report
    /// and repair a run (`lumis slurm status DIR [--resubmit]`).
    Slurm(SlurmArgs),
    /// Sample generators: compare where they put their points.
    #[command(subcommand)]
    Samplers(SamplersCommand),
    /// Measured BRDFs: write a BSDF as a MERL table, precompute sampling,
    /// compress a table into a tensor.
    #[command(subcommand)]
    Brdf(BrdfCommand),
    /// The Monte Carlo lecture's experiments on test integrands and point
    /// sets: variance of stratified sampling with proportional and Neyman
    /// allocation against the formula, power spectra of 256-point
    /// jittered, Poisson disk and white-noise sets, and the bias, variance
    /// and MSE of two biased estimators against the sample mean: half the
    /// sample maximum (the lecture's example, MSE O(1/N^2)) and the scaled
    /// mean N/(N+1) F_N; tables and PNGs.
    Lecture(LectureArgs),
}

#[derive(Subcommand)]
enum BrdfCommand {
    /// Write an isotropic, reciprocal lumis BSDF as a MERL table (90 x 90 x
    /// 180 samples of f over theta_h, theta_d, phi_d), e.g.
    /// `lumis brdf tabulate --bsdf conductor --set roughness=0.2 -o metal.binary`.
    Tabulate(TabulateArgs),
    /// Run the precomputation of a sampling strategy of the `measured` BSDF
    /// for a table (ignoring and replacing its cache); print its time and
    /// memory.
    Precompute(PrecomputeArgs),
    /// Fit a rank-R tensor (CP) approximation of a table over a
    /// parameterization; print its size and error against the table, and
    /// write the factors with `-o`.
    Compress(CompressArgs),
}

#[derive(Subcommand)]
enum SamplersCommand {
    /// Point-set pictures, power spectrum (2D and radially averaged),
    /// L2-star discrepancy, raw points, and a convergence study on test
    /// integrands against Simpson's rule, for one sampler or `all`.
    Analyze(AnalyzeArgs),
}

/// What `lumis --version` prints after the name: the versions a plugin
/// library must match to load, and the instruction sets of the SIMD
/// kernels with the one this CPU runs.
fn version_text() -> String {
    use lumis_core::plugin::{
        API_VERSION, INTERFACE_FINGERPRINT, PLUGIN_ABI_VERSION, RUSTC_VERSION,
    };
    let built: Vec<_> = Isa::BUILT.iter().map(|isa| isa.name()).collect();
    format!(
        "{}\nlumis-api {API_VERSION}, plugin ABI {PLUGIN_ABI_VERSION}, plugin interface \
         {INTERFACE_FINGERPRINT}\nbuilt by {RUSTC_VERSION}\nSIMD kernels for {}; this CPU \
         runs them with {} ({} chooses)",
        env!("CARGO_PKG_VERSION"),
        built.join(", "),
        simd::chosen(),
        simd::ENV,
    )
}

fn main() -> ExitCode {
    // Built once per process; clap keeps a `&'static str`.
    let version: &'static str = Box::leak(version_text().into_boxed_str());
    let matches = Cli::command().version(version).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    if let Err(why) = simd::choose_from_env() {
        eprintln!("error: {why}");
        return ExitCode::FAILURE;
    }
    let result = match cli.command {
        Command::Render(args) => interruptible(|stop| {
            let registry = registry_with_search_path()?;
            let report = render(&args, &on_stderr(&registry, stop))?;
            println!("{}", report.summary());
            for line in report.profile.iter().flat_map(|p| p.lines()) {
                println!("{line}");
            }
            for warning in report.defect_warnings() {
                eprintln!("{warning}");
            }
            report.strict_check(&args)?;
            Ok(Outcome::Done)
        }),
        Command::Merge(args) => plain(|| {
            let registry = registry_with_search_path()?;
            merge(&args, &registry).map(|report| {
                let denoised = match &report.denoised {
                    Some(exr) => format!(", denoised -> {}", exr.display()),
                    None => String::new(),
                };
                println!(
                    "{} spp from {} parts -> {} and {}{denoised}",
                    report.metadata.spp,
                    args.parts.len(),
                    report.exr.display(),
                    report.png.display()
                );
                Outcome::Done
            })
        }),
        Command::Denoise(args) => plain(|| {
            let registry = registry_with_search_path()?;
            denoise_image(&args, &registry).map(|report| {
                println!("{}", report.summary(&args.image));
                Outcome::Done
            })
        }),
        Command::Reference(args) => interruptible(|stop| {
            let registry = registry_with_search_path()?;
            let (path, meta) = render_reference(&args, &on_stderr(&registry, stop))?;
            println!(
                "{}: {} spp in {:.1} s ({} passes; metadata in its header)",
                path.display(),
                meta.spp,
                meta.seconds,
                meta.passes
            );
            Ok(Outcome::Done)
        }),
        Command::Plugins { load, markdown } => plain(|| {
            registry_with_search_path().and_then(|mut registry| {
                for library in &load {
                    lumis_loader::load_library(library, &mut registry)?;
                }
                if markdown {
                    print!("{}", plugin_markdown(&registry));
                } else {
                    print!("{}", plugin_listing(&registry));
                }
                Ok(Outcome::Done)
            })
        }),
        Command::CheckPlugin {
            library,
            bsdf,
            light,
            light_sampler,
            sampler,
            integrator,
            samples,
            bins,
            out,
            set,
        } => plain(|| {
            let names = PluginNames {
                bsdf,
                light,
                light_sampler,
                sampler,
                integrator,
                denoiser: Vec::new(),
            };
            check_plugin(library, names, samples, bins, &out, &set).map(Outcome::passed)
        }),
        Command::NewPlugin(args) => plain(|| {
            new_plugin(&args, std::path::Path::new(".")).map(|dir| {
                println!(
                    "wrote {}: cd there, then `cargo build --release` and `cargo test` (see its README.md)",
                    dir.display()
                );
                Outcome::Done
            })
        }),
        Command::Converge(args) => plain(|| {
            registry_with_search_path()
                .and_then(|registry| converge(&args, &registry, &*stop_on_interrupt()?))
                .map(|report| {
                    print!("{}", report.table);
                    println!("CSV, JSON and plots in {}", args.out.display());
                    Outcome::Done
                })
        }),
        Command::Diff(args) => plain(|| {
            diff_images(&args).map(|report| {
                print!("{report}");
                Outcome::Done
            })
        }),
        Command::Brdf(BrdfCommand::Tabulate(args)) => plain(|| {
            registry_with_search_path()
                .and_then(|registry| tabulate_bsdf(&args, &registry))
                .map(|line| {
                    println!("{line}");
                    Outcome::Done
                })
        }),
        Command::Brdf(BrdfCommand::Precompute(args)) => plain(|| {
            precompute_table(&args).map(|line| {
                println!("{line}");
                Outcome::Done
            })
        }),
        Command::Brdf(BrdfCommand::Compress(args)) => plain(|| {
            compress_table(&args).map(|report| {
                println!("{report}");
                Outcome::Done
            })
        }),
        Command::Lecture(args) => plain(|| {
            registry_with_search_path()
                .and_then(|registry| lecture(&args, &registry))
                .map(|report| {
                    print!("{report}");
                    println!("figures in {}", args.out.display());
                    Outcome::Done
                })
        }),
        Command::Slurm(args) => plain(|| {
            match &args.command {
                Some(SlurmCommand::Status(status)) => {
                    print!("{}", slurm_status(&status.dir, status.resubmit)?)
                }
                None => {
                    let lumis = std::env::current_exe()
                        .map_err(|e| Error::msg(format!("the lumis executable: {e}")))?;
                    println!("{}", submit_slurm(&args.submit, &lumis)?.summary());
                }
            }
            Ok(Outcome::Done)
        }),
        Command::Samplers(SamplersCommand::Analyze(args)) => plain(|| {
            registry_with_search_path()
                .and_then(|registry| analyze_samplers(&args, &registry))
                .map(|report| {
                    print!("{report}");
                    println!("pictures and CSV in {}", args.out.display());
                    Outcome::Done
                })
        }),
    };
    match result {
        Ok(Outcome::Done) => ExitCode::SUCCESS,
        Ok(Outcome::Failed) => ExitCode::FAILURE,
        Ok(Outcome::Interrupted) => ExitCode::from(INTERRUPTED_EXIT_CODE),
        Err(Interruptible::Interrupted(e)) => {
            eprintln!("error: {e}");
            ExitCode::from(INTERRUPTED_EXIT_CODE)
        }
        Err(Interruptible::Failed(e)) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// A render session that prints its notes and its progress on stderr.
fn on_stderr<'a>(registry: &'a Registry, stop: &'a std::sync::atomic::AtomicBool) -> Session<'a> {
    Session {
        registry,
        stop,
        notes: &|line| eprintln!("{line}"),
        progress: Progress::Stderr,
        thread_host: None,
    }
}

/// How a command ended, for its exit status.
enum Outcome {
    Done,
    /// Ran, and found a failure it reported (`check-plugin`).
    Failed,
    /// Stopped by Ctrl-C, SIGTERM or SIGHUP after saving its work.
    Interrupted,
}

impl Outcome {
    fn passed(all_passed: bool) -> Self {
        if all_passed {
            Self::Done
        } else {
            Self::Failed
        }
    }
}

/// A command's error, and whether a signal had asked it to stop (then it
/// exits 130 like any interrupted program, not 1).
enum Interruptible {
    Failed(Error),
    Interrupted(Error),
}

/// Runs a command that a signal kills at once.
fn plain(command: impl FnOnce() -> Result<Outcome>) -> std::result::Result<Outcome, Interruptible> {
    command().map_err(Interruptible::Failed)
}

/// Runs a command that stops on Ctrl-C: interrupted, it ends as
/// [`Outcome::Interrupted`] whether it saved its work or failed.
fn interruptible(
    command: impl FnOnce(&std::sync::atomic::AtomicBool) -> Result<Outcome>,
) -> std::result::Result<Outcome, Interruptible> {
    let stop = stop_on_interrupt().map_err(Interruptible::Failed)?;
    let result = command(&stop);
    let stopped = stop.load(std::sync::atomic::Ordering::SeqCst);
    match result {
        Ok(_) if stopped => Ok(Outcome::Interrupted),
        Ok(outcome) => Ok(outcome),
        Err(e) if stopped => Err(Interruptible::Interrupted(e)),
        Err(e) => Err(Interruptible::Failed(e)),
    }
}
