//! Fits (or loads from the cache) the tensor approximation of a table, once
//! per table, parameterization and rank, as [`crate::precompute`] does for
//! the samplers: `TABLE.tensor-LR-90x90x180s0[-pdv|-in-out].lumis-cache`.

use std::path::Path;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use lumis_api::{Error, ParamChoice, Result};

use crate::cache::{self, CacheKey};
use crate::cp::{AlsReport, AlsSettings};
use crate::grid::{Grid, Parameterization};
use crate::merl::MerlTable;
use crate::tensor::{fit, TensorBrdf, DIMS};

/// The cache key of the tensor of `table` (the grid records the tensor's
/// dimensions and parameterization; `supersamples` is unused).
pub fn cache_key(table: &MerlTable, parameterization: Parameterization, rank: usize) -> CacheKey {
    CacheKey {
        table_hash: table.hash(),
        strategy: "tensor",
        terms: rank,
        grid: Grid {
            n_o: DIMS[0],
            n_w: DIMS[1],
            n_phi: DIMS[2],
            supersamples: 0,
            parameterization,
        },
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

/// Fits `rank` terms per channel to `table`, behind a progress bar.
fn fit_with_progress(
    table: &MerlTable,
    table_path: &Path,
    parameterization: Parameterization,
    rank: usize,
) -> (TensorBrdf, [AlsReport; 3], f64) {
    let progress = ProgressBar::new(3).with_message(format!(
        "rank-{rank} tensor of {} ({})",
        table_path.display(),
        parameterization.name()
    ));
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} channels {elapsed}")
    {
        progress.set_style(style.progress_chars("=> "));
    }
    let start = Instant::now();
    let (tensor, fits) = fit(
        table,
        parameterization,
        rank,
        AlsSettings::default(),
        &|| progress.inc(1),
    );
    progress.finish_and_clear();
    (tensor, fits, start.elapsed().as_secs_f64())
}

/// The tensor of `table`, from the cache next to `table_path` if it holds
/// it, else fitted (and cached when `use_cache`).
pub fn prepare_tensor(
    table: &MerlTable,
    table_path: &Path,
    parameterization: Parameterization,
    rank: usize,
    use_cache: bool,
) -> Result<(TensorBrdf, CompressReport)> {
    let key = cache_key(table, parameterization, rank);
    let path = key.path(table_path);
    let count = TensorBrdf::payload_len(rank);
    let label = format!("rank-{rank} tensor ({})", parameterization.name());
    let mut note = String::new();
    if use_cache {
        match cache::load(&path, &key, count) {
            Ok(data) => {
                let tensor = TensorBrdf::from_payload(parameterization, rank, &data)
                    .ok_or_else(|| Error::msg(format!("{}: bad tensor payload", path.display())))?;
                let message = format!(
                    "{}: {label} loaded from {} ({} KiB)",
                    table_path.display(),
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
            Err(miss) => note = miss.note(&path),
        }
    }
    let (tensor, fits, seconds) = fit_with_progress(table, table_path, parameterization, rank);
    if use_cache {
        match cache::store(&path, &key, &tensor.payload()) {
            Ok(()) => note.push_str(&format!(", cached in {}", path.display())),
            Err(e) => note.push_str(&format!(" (not cached: {e})")),
        }
    }
    let error = fits
        .iter()
        .map(AlsReport::relative_error)
        .fold(0.0, f64::max);
    let message = format!(
        "{}: {label} fitted in {seconds:.2} s ({} sweeps, relative error of ln(1 + f) {error:.2e} at most per channel), {} KiB{note}",
        table_path.display(),
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
