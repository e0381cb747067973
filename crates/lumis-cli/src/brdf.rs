//! `lumis brdf`: measured-BRDF tools. `tabulate` writes any lumis BSDF as
//! a MERL table (a measured material with a known ground truth);
//! `precompute` runs a sampling precomputation of a table, reports its
//! time and memory and refreshes its cache.

use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use lumis_core::ParamChoice;
use lumis_core::{Bsdf, Error, Location, PluginEntity, PluginKind, Registry, Result};
use lumis_measured::grid::{Grid, Parameterization};
use lumis_measured::merl::{write_atomic, MerlTable, THETA_H_RES};
use lumis_measured::precompute::{prepare, Plan};
use lumis_measured::tabulate::tabulate;

use crate::assignments::parameter_table;

#[derive(clap::Args, Debug, Clone)]
pub struct TabulateArgs {
    /// The BSDF plugin to tabulate (built-in or loaded), e.g. conductor.
    #[arg(long)]
    pub bsdf: String,
    /// Its parameters, e.g. `--set roughness=0.2 --set material=Au`.
    #[arg(long = "set", value_name = "key=value")]
    pub set: Vec<String>,
    /// The MERL file to write (written to a temporary file, then renamed).
    #[arg(short, long, value_name = "OUT.binary")]
    pub output: PathBuf,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(clap::Args, Debug, Clone)]
pub struct PrecomputeArgs {
    /// The MERL table.
    pub table: PathBuf,
    /// factored or tabulated.
    #[arg(long, default_value = "factored")]
    pub sampling: String,
    /// Terms of the factorization (factored).
    #[arg(long, default_value_t = 2)]
    pub terms: usize,
    /// Outgoing elevations, half-angle bins, azimuth bins.
    #[arg(long, value_delimiter = ',', default_value = "32,64,64")]
    pub grid: Vec<usize>,
    /// The coordinates of the grid: half-diff or pdv.
    #[arg(long, default_value = "half-diff")]
    pub parameterization: String,
}

/// `lumis brdf tabulate`: returns the summary line.
pub fn tabulate_bsdf(args: &TabulateArgs, registry: &Registry) -> Result<String> {
    let table = parameter_table(&args.set)?;
    let owner = format!("bsdf \"{}\"", args.bsdf);
    let entity = PluginEntity::new(
        PluginKind::Bsdf,
        owner,
        &args.bsdf,
        table,
        Location::Builtin,
    );
    let bsdf = registry.create::<dyn Bsdf>(&entity, lumis_core::texture::BsdfScope::EMPTY)?;
    let progress = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(THETA_H_RES as u64)
    };
    if let Ok(style) = ProgressStyle::with_template(
        "tabulating {msg} [{bar:30}] {pos}/{len} theta_h rows {elapsed}",
    ) {
        progress.set_style(style.progress_chars("=> "));
    }
    progress.set_message(args.bsdf.clone());
    let start = Instant::now();
    let label = if args.set.is_empty() {
        args.bsdf.clone()
    } else {
        format!("{} ({})", args.bsdf, args.set.join(", "))
    };
    let bytes = tabulate(bsdf.as_ref(), &label, &progress)?;
    progress.finish_and_clear();
    write_atomic(&args.output, &bytes)?;
    // Read back what was written: the file is checked like any other.
    let check = MerlTable::read(&args.output)?;
    Ok(format!(
        "{label} -> {} ({} bytes, content hash {:016x}) in {:.2} s",
        args.output.display(),
        bytes.len(),
        check.hash(),
        start.elapsed().as_secs_f64()
    ))
}

/// `lumis brdf precompute`: returns the report line.
pub fn precompute_table(args: &PrecomputeArgs) -> Result<String> {
    let plan = match args.sampling.as_str() {
        "factored" if (1..=16).contains(&args.terms) => Plan::Factored { terms: args.terms },
        "factored" => return Err(Error::msg(format!("--terms must be in [1, 16], got {}", args.terms))),
        "tabulated" => Plan::Tabulated,
        other => {
            return Err(Error::msg(format!(
                "--sampling must be factored or tabulated (cosine needs no precomputation), got \"{other}\""
            )))
        }
    };
    let parameterization = parameterization(&args.parameterization)?;
    let grid = match args.grid.as_slice() {
        &[n_o, n_w, n_phi] if [n_o, n_w, n_phi].iter().all(|n| (2..=1024).contains(n)) => Grid {
            n_o,
            n_w,
            n_phi,
            supersamples: 4,
            parameterization,
        },
        g => {
            return Err(Error::msg(format!(
                "--grid expects three integers in [2, 1024], got {g:?}"
            )))
        }
    };
    let table = MerlTable::read(&args.table)?;
    // Remove the cache first so that the time is the computation's.
    let cache = lumis_measured::cache::CacheKey {
        table_hash: table.hash(),
        strategy: match plan {
            Plan::Factored { .. } => "factored",
            Plan::Tabulated => "tabulated",
        },
        terms: match plan {
            Plan::Factored { terms } => terms,
            Plan::Tabulated => 0,
        },
        grid,
    }
    .path(&args.table);
    let _ = std::fs::remove_file(&cache);
    let (_, report) = prepare(&table, &args.table, plan, grid, true)?;
    Ok(report.message)
}

/// `--parameterization`: one of the grid's coordinates by name.
fn parameterization(name: &str) -> Result<Parameterization> {
    Parameterization::from_name(name).ok_or_else(|| {
        Error::msg(format!(
            "--parameterization must be one of {}, got \"{name}\"",
            Parameterization::NAMES.join(", ")
        ))
    })
}
