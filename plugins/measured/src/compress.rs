//! Fits (or loads from the cache) the tensor approximation of a table, once
//! per table, parameterization and rank, as [`crate::precompute`] does for
//! the samplers: `TABLE.tensor-LR-90x90x180s0[-pdv|-in-out].lumis-cache`.
//! An analytic source has no file to cache next to: its tensor is fitted
//! every time.

use std::path::Path;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use lumis_api::{Error, ParamChoice, Result};

use crate::cache::{self, CacheKey};
use crate::cp::{AlsReport, AlsSettings};
use crate::grid::Parameterization;
use crate::precompute::source_name;
use crate::reflectance::Reflectance;
use crate::tensor::{fit, node_grid, TensorBrdf};

/// The cache key of the tensor of the table with content hash
/// `table_hash` (the grid records the tensor's dimensions and
/// parameterization; `supersamples` is unused).
pub fn cache_key(table_hash: u64, parameterization: Parameterization, rank: usize) -> CacheKey {
    CacheKey {
        table_hash,
        strategy: "tensor",
        terms: rank,
        grid: node_grid(parameterization),
    }
}

/// How the tensor came to be.
#[derive(Debug, Clone)]
pub struct CompressReport {
    /// Seconds spent fitting (0 when loaded from the cache).
    pub seconds: f64,
    /// The fits of the three channels (`None` when loaded).
    pub fits: Option<[AlsReport; 3]>,
    /// The line printed to stderr.
    pub message: String,
}

/// Fits `rank` terms per channel to `source` (named `name`), behind a
/// progress bar.
fn fit_with_progress(
    source: &Reflectance,
    name: &str,
    parameterization: Parameterization,
    rank: usize,
) -> (TensorBrdf, [AlsReport; 3], f64) {
    let progress = ProgressBar::new(3).with_message(format!(
        "rank-{rank} tensor of {name} ({})",
        parameterization.name()
    ));
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} channels {elapsed}")
    {
        progress.set_style(style.progress_chars("=> "));
    }
    let start = Instant::now();
    let (tensor, fits) = fit(
        source,
        parameterization,
        rank,
        AlsSettings::default(),
        &|| progress.inc(1),
    );
    progress.finish_and_clear();
    (tensor, fits, start.elapsed().as_secs_f64())
}

/// The tensor of `source` (a table, or an analytic BSDF), from the cache
/// next to `table_path` if it holds it, else fitted (and cached when
/// `use_cache` and there is a table file).
pub fn prepare_tensor(
    source: &Reflectance,
    table_path: Option<&Path>,
    parameterization: Parameterization,
    rank: usize,
    use_cache: bool,
) -> Result<(TensorBrdf, CompressReport)> {
    let name = source_name(table_path);
    let label = format!("rank-{rank} tensor ({})", parameterization.name());
    let cache = cache::slot(use_cache, table_path, source.cache_hash(), |hash| {
        cache_key(hash, parameterization, rank)
    });
    let mut note = String::new();
    if let Some((path, key)) = &cache {
        match cache::load(path, key, TensorBrdf::payload_len(rank)) {
            Ok(data) => {
                let tensor = TensorBrdf::from_payload(parameterization, rank, &data)
                    .ok_or_else(|| Error::msg(format!("{}: bad tensor payload", path.display())))?;
                let message = format!(
                    "{name}: {label} loaded from {} ({} KiB)",
                    path.display(),
                    tensor.memory_bytes() / 1024
                );
                return Ok((
                    tensor,
                    CompressReport {
                        seconds: 0.0,
                        fits: None,
                        message,
                    },
                ));
            }
            Err(miss) => note = miss.note(path),
        }
    }
    let (tensor, fits, seconds) = fit_with_progress(source, &name, parameterization, rank);
    if let Some((path, key)) = &cache {
        match cache::store(path, key, &tensor.payload()) {
            Ok(()) => note.push_str(&format!(", cached in {}", path.display())),
            Err(e) => note.push_str(&format!(" (not cached: {e})")),
        }
    }
    let error = fits
        .iter()
        .map(AlsReport::relative_error)
        .fold(0.0, f64::max);
    let message = format!(
        "{name}: {label} fitted in {seconds:.2} s ({} sweeps, relative error of ln(1 + f) {error:.2e} at most per channel), {} KiB{note}",
        fits.iter().map(|f| f.sweeps).max().unwrap_or(0),
        tensor.memory_bytes() / 1024
    );
    Ok((
        tensor,
        CompressReport {
            seconds,
            fits: Some(fits),
            message,
        },
    ))
}
