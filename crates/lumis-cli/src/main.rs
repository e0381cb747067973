//! `lumis`: a Monte Carlo path tracer about variance reduction.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use lumis_check::bsdf_suite::{
    check_bsdf_with, format_results, write_histogram_png, BsdfCheckConfig,
};
use lumis_cli::{
    analyze_samplers, converge, diff_images, plugin_listing, plugin_markdown, precompute_table,
    registry_with_search_path, render_reference, render_scene_file, tabulate_bsdf, AnalyzeArgs,
    ConvergeArgs, DiffArgs, PrecomputeArgs, ReferenceArgs, RenderArgs, TabulateArgs,
};
use lumis_core::{Error, PluginKind, Registry, Result};

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
    /// Statistically check BSDF plugins: chi-square of sample_f against pdf,
    /// pdf normalisation, sample_f/f/pdf consistency, albedo <= 1,
    /// reciprocity and finiteness, over a sweep of the plugin's parameters
    /// and of incident angles down to cos theta = 1e-4. Exits non-zero on
    /// any failure and writes observed-vs-expected PNGs for failed cases.
    CheckPlugin {
        /// A plugin library: checks every BSDF it registers.
        library: Option<PathBuf>,
        /// Check this BSDF (built-in or from the library); repeatable.
        #[arg(long)]
        bsdf: Vec<String>,
        /// Samples per chi-square test.
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
    /// Render a high-spp reference with the scene's own settings, saved
    /// after every pass with its metadata (PATH.json); rerun to resume.
    Reference(ReferenceArgs),
    /// Error vs samples and vs time against a reference, for variants of a
    /// scene (sampler, strategy, heuristic, BSDF sampling...) over seeds:
    /// CSV, JSON, two log-log plots and a table ranked by efficiency.
    Converge(ConvergeArgs),
    /// Error of an image against a reference: MSE, RMSE, relMSE, mean
    /// absolute and signed relative error, PSNR, per named region, and an
    /// optional false-colour error picture.
    Diff(DiffArgs),
    /// Sample generators: compare where they put their points.
    #[command(subcommand)]
    Samplers(SamplersCommand),
    /// Measured BRDFs: write a BSDF as a MERL table, precompute sampling.
    #[command(subcommand)]
    Brdf(BrdfCommand),
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
}

#[derive(Subcommand)]
enum SamplersCommand {
    /// Point-set pictures, power spectrum (2D and radially averaged),
    /// L2-star discrepancy, raw points, and a convergence study on test
    /// integrands against Simpson's rule, for one sampler or `all`.
    Analyze(AnalyzeArgs),
}

/// What `lumis --version` prints after the name: the versions a plugin
/// library must match to load.
fn version_text() -> String {
    use lumis_core::plugin::{
        CORE_VERSION, INTERFACE_FINGERPRINT, PLUGIN_ABI_VERSION, RUSTC_VERSION,
    };
    format!(
        "{}\nlumis-core {CORE_VERSION}, plugin ABI {PLUGIN_ABI_VERSION}, plugin interface \
         {INTERFACE_FINGERPRINT}\nbuilt by {RUSTC_VERSION}",
        env!("CARGO_PKG_VERSION")
    )
}

fn main() -> ExitCode {
    // Built once per process; clap keeps a `&'static str`.
    let version: &'static str = Box::leak(version_text().into_boxed_str());
    let matches = Cli::command().version(version).get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    let result = match cli.command {
        Command::Render(args) => registry_with_search_path().and_then(|registry| {
            render_scene_file(&args, &registry).map(|report| {
                println!("{}", report.summary());
                for line in report.profile.iter().flat_map(|p| p.lines()) {
                    println!("{line}");
                }
                true
            })
        }),
        Command::Plugins { load, markdown } => {
            registry_with_search_path().and_then(|mut registry| {
                for library in &load {
                    lumis_loader::load_library(library, &mut registry)?;
                }
                if markdown {
                    print!("{}", plugin_markdown(&registry));
                } else {
                    print!("{}", plugin_listing(&registry));
                }
                Ok(true)
            })
        }
        Command::CheckPlugin {
            library,
            bsdf,
            samples,
            bins,
            out,
            set,
        } => check_plugin(library, bsdf, samples, bins, &out, &set),
        Command::Reference(args) => registry_with_search_path().and_then(|registry| {
            let stop = stop_on_ctrl_c()?;
            let (path, meta) = render_reference(&args, &registry, &stop)?;
            println!(
                "{}: {} spp in {:.1} s (metadata in {}.json)",
                path.display(),
                meta.spp,
                meta.seconds,
                path.display()
            );
            Ok(true)
        }),
        Command::Converge(args) => registry_with_search_path()
            .and_then(|registry| converge(&args, &registry, &*stop_on_ctrl_c()?))
            .map(|report| {
                print!("{}", report.table);
                println!("CSV, JSON and plots in {}", args.out.display());
                true
            }),
        Command::Diff(args) => diff_images(&args).map(|report| {
            print!("{report}");
            true
        }),
        Command::Brdf(BrdfCommand::Tabulate(args)) => registry_with_search_path()
            .and_then(|registry| tabulate_bsdf(&args, &registry))
            .map(|line| {
                println!("{line}");
                true
            }),
        Command::Brdf(BrdfCommand::Precompute(args)) => precompute_table(&args).map(|line| {
            println!("{line}");
            true
        }),
        Command::Samplers(SamplersCommand::Analyze(args)) => registry_with_search_path()
            .and_then(|registry| analyze_samplers(&args, &registry))
            .map(|report| {
                print!("{report}");
                println!("pictures and CSV in {}", args.out.display());
                true
            }),
    };
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// A flag Ctrl-C sets: long commands finish the render in flight and keep
/// what they measured instead of dying.
fn stop_on_ctrl_c() -> Result<std::sync::Arc<std::sync::atomic::AtomicBool>> {
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, std::sync::atomic::Ordering::Relaxed))
        .map_err(|e| Error::msg(format!("cannot install the Ctrl-C handler: {e}")))?;
    Ok(stop)
}

/// `lumis check-plugin`: returns whether every case passed.
fn check_plugin(
    library: Option<PathBuf>,
    mut names: Vec<String>,
    samples: usize,
    bins: usize,
    out: &std::path::Path,
    set: &[String],
) -> Result<bool> {
    let fixed = lumis_cli::fixed_parameters(set)?;
    let mut registry = registry_with_search_path()?;
    if let Some(library) = &library {
        // The library's BSDFs are the ones it added (its path as the
        // registry labels them is the resolved one, not the one given).
        let bsdfs = |registry: &Registry| -> Vec<String> {
            registry
                .plugins()
                .into_iter()
                .filter(|p| p.spec.kind == PluginKind::Bsdf)
                .map(|p| p.spec.name.to_string())
                .collect()
        };
        let before = bsdfs(&registry);
        lumis_loader::load_library(library, &mut registry)?;
        names.extend(bsdfs(&registry).into_iter().filter(|n| !before.contains(n)));
    }
    if names.is_empty() {
        return Err(Error::msg(
            "nothing to check: give a plugin library that registers BSDFs, or --bsdf NAME",
        ));
    }
    let mut cfg = BsdfCheckConfig::default();
    cfg.chi_square.samples = samples;
    cfg.chi_square.z_bins = bins;
    cfg.chi_square.phi_bins = bins;
    let mut all_passed = true;
    for name in &names {
        let results = check_bsdf_with(&registry, name, &fixed, &cfg)?;
        print!("{}", format_results(&results));
        for (i, r) in results
            .iter()
            .enumerate()
            .filter(|(_, r)| !r.chi_square.passed && !r.chi_square.observed.is_empty())
        {
            let path = out.join(format!("check-{name}-{i}.png"));
            write_histogram_png(&r.chi_square, &cfg.chi_square, &path)?;
            println!(
                "observed | expected histograms of failed case {i}: {}",
                path.display()
            );
        }
        all_passed &= results.iter().all(|r| r.passed());
    }
    Ok(all_passed)
}
