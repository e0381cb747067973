//! `lumis brdf`: measured-BRDF tools. `tabulate` writes any lumis BSDF as
//! a MERL table (a measured material with a known ground truth);
//! `precompute` runs a sampling precomputation of a table, reports its
//! time and memory and refreshes its cache; `compress` fits (or loads from
//! the `measured` plugin's cache) a tensor approximation of a table and
//! reports its size and error.

use std::path::PathBuf;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use lumis_core::ParamChoice;
use lumis_core::{Bsdf, Error, Location, PluginEntity, PluginKind, Registry, Result};
use lumis_measured::cache;
use lumis_measured::compress::{cache_key, prepare_tensor};
use lumis_measured::grid::{Grid, Parameterization};
use lumis_measured::merl::{write_atomic, MerlTable, SAMPLES, THETA_H_RES};
use lumis_measured::precompute::{prepare, Plan};
use lumis_measured::reflectance::Reflectance;
use lumis_measured::tabulate::tabulate;
use lumis_measured::tensor::{compression_error, node_grid, DIMS};

use lumis_app::parameter_table;

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
    /// factored, tabulated or tensor.
    #[arg(long, default_value = "factored")]
    pub sampling: String,
    /// Terms of the factorization (factored, tensor).
    #[arg(long, default_value_t = 2)]
    pub terms: usize,
    /// Outgoing elevations, half-angle bins, azimuth bins (factored,
    /// tabulated; the tensor has its nodes).
    #[arg(long, value_delimiter = ',', default_value = "32,64,64")]
    pub grid: Vec<usize>,
    /// The coordinates of the grid: half-diff, pdv or in-out.
    #[arg(long, default_value = "half-diff")]
    pub parameterization: String,
}

#[derive(clap::Args, Debug, Clone)]
pub struct CompressArgs {
    /// The MERL table.
    pub table: PathBuf,
    /// The coordinates of the tensor's axes: half-diff, pdv or in-out.
    #[arg(long, default_value = "half-diff")]
    pub parameterization: String,
    /// R, the rank-1 terms per colour channel.
    #[arg(long, default_value_t = 8)]
    pub rank: usize,
    /// Write the factors here (the cache file format of the `measured`
    /// plugin: a header, then per channel the three axes' n x R matrices
    /// as little-endian f32, then a hash).
    #[arg(short, long, value_name = "OUT")]
    pub output: Option<PathBuf>,
}

/// The largest rank `compress` and the plugin accept.
pub const MAX_RANK: usize = 32;

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
        "factored" | "tensor" if !(1..=16).contains(&args.terms) => {
            return Err(Error::msg(format!("--terms must be in [1, 16], got {}", args.terms)))
        }
        "factored" => Plan::Factored { terms: args.terms },
        "tensor" => Plan::Tensor { terms: args.terms },
        "tabulated" => Plan::Tabulated,
        other => {
            return Err(Error::msg(format!(
                "--sampling must be factored, tabulated or tensor (cosine needs no precomputation), got \"{other}\""
            )))
        }
    };
    let parameterization = parameterization(&args.parameterization)?;
    let grid = match args.grid.as_slice() {
        _ if matches!(plan, Plan::Tensor { .. }) => node_grid(parameterization),
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
    let table_hash = table.hash();
    let reflectance = Reflectance::Table(std::sync::Arc::new(table));
    // Remove the cache first so that the time is the computation's.
    let cache = plan.cache_key(table_hash, grid).path(&args.table);
    let _ = std::fs::remove_file(&cache);
    let (_, report) = prepare(&reflectance, Some(&args.table), plan, grid, true)?;
    Ok(report.message)
}

/// `lumis brdf compress`: returns the report (size, error, fit).
pub fn compress_table(args: &CompressArgs) -> Result<String> {
    let parameterization = parameterization(&args.parameterization)?;
    if !(1..=MAX_RANK).contains(&args.rank) {
        return Err(Error::msg(format!(
            "--rank must be in [1, {MAX_RANK}], got {}",
            args.rank
        )));
    }
    let table = std::sync::Arc::new(MerlTable::read(&args.table)?);
    // Through the plugin's cache: a render with the same settings then
    // loads these factors instead of fitting them again.
    let source = Reflectance::Table(table.clone());
    let (tensor, report) = prepare_tensor(
        &source,
        Some(&args.table),
        parameterization,
        args.rank,
        true,
    )?;
    let error = compression_error(&table, &|wi, wo| tensor.eval(wi, wo));
    let (table_floats, tensor_floats) = (3 * SAMPLES, tensor.payload().len());
    let mut out = format!(
        "{}: rank-{} CP tensor over {} ({} x {} x {} nodes per channel) of ln(1 + f)\n{}\n",
        args.table.display(),
        args.rank,
        parameterization.name(),
        DIMS[0],
        DIMS[1],
        DIMS[2],
        report.message
    );
    out += &format!(
        "size: table {table_floats} floats ({:.1} MB as f32), tensor {tensor_floats} floats ({:.1} KB as f32), {:.0}x smaller\n",
        (4 * table_floats) as f64 / 1e6,
        (4 * tensor_floats) as f64 / 1e3,
        table_floats as f64 / tensor_floats as f64
    );
    out += &format!(
        "error at the {} valid nodes of the table: relative RMSE of f {:.4}, PSNR of ln(1 + f) {:.2} dB",
        error.nodes, error.relative_rmse, error.log_psnr_db
    );
    if let Some(output) = &args.output {
        cache::store(
            output,
            &cache_key(table.hash(), parameterization, args.rank),
            &tensor.payload(),
        )?;
        out += &format!("\nfactors written to {}", output.display());
    }
    Ok(out)
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
