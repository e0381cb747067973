//! Runs (or loads from the cache) the precomputation a sampling strategy
//! needs, once per table and setting: the grid of `f cos theta_i` in
//! parallel, then the factorization, or the non-negative tensor of the
//! nodes, behind one progress bar.

use std::path::Path;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use lumis_api::{Result, Rgb, Vec3};

use crate::cache::{self, CacheKey};
use crate::factored::{factorize, Factored, Factors, NMF_ITERATIONS, REFINE_ITERATIONS};
use crate::grid::{normalize_rows, Grid};
use crate::reflectance::Reflectance;
use crate::tabulated::Tabulated;
use crate::tensor_sampling::{self, TensorSampler};

/// What the strategy needs precomputed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plan {
    Factored {
        terms: usize,
    },
    Tabulated,
    /// On the tensor's nodes ([`crate::tensor::node_grid`]).
    Tensor {
        terms: usize,
    },
}

impl Plan {
    fn name(self) -> &'static str {
        match self {
            Plan::Factored { .. } => "factored",
            Plan::Tabulated => "tabulated",
            Plan::Tensor { .. } => "tensor-sampling",
        }
    }

    fn terms(self) -> usize {
        match self {
            Plan::Factored { terms } | Plan::Tensor { terms } => terms,
            Plan::Tabulated => 0,
        }
    }

    /// What the cache of this plan on `grid` for a table of content hash
    /// `table_hash` must match.
    pub fn cache_key(self, table_hash: u64, grid: Grid) -> CacheKey {
        CacheKey {
            table_hash,
            strategy: self.name(),
            terms: self.terms(),
            grid,
        }
    }

    /// Numbers in the cache payload.
    fn count(self, grid: &Grid) -> usize {
        match self {
            Plan::Factored { terms } => terms * (grid.n_o + grid.n_w + grid.n_phi),
            Plan::Tabulated => grid.n_o * grid.columns(),
            Plan::Tensor { terms } => tensor_sampling::payload_len(terms),
        }
    }
}

/// A ready sampler.
#[derive(Debug, Clone)]
pub enum Prepared {
    Factored(Factored),
    Tabulated(Tabulated),
    Tensor(TensorSampler),
}

impl Prepared {
    pub fn memory_bytes(&self) -> usize {
        match self {
            Prepared::Factored(f) => f.memory_bytes(),
            Prepared::Tabulated(t) => t.memory_bytes(),
            Prepared::Tensor(t) => t.memory_bytes(),
        }
    }
}

/// How the sampler came to be.
#[derive(Debug, Clone, PartialEq)]
pub struct PrecomputeReport {
    /// Seconds spent computing (0 when loaded from the cache).
    pub seconds: f64,
    pub from_cache: bool,
    pub memory_bytes: usize,
    /// The line printed to stderr.
    pub message: String,
}

fn from_payload(plan: Plan, grid: Grid, data: &[f32]) -> Prepared {
    match plan {
        Plan::Factored { terms } => {
            let (f, rest) = data.split_at(grid.n_o * terms);
            let (u, v) = rest.split_at(terms * grid.n_w);
            Prepared::Factored(Factored::new(
                grid,
                &Factors {
                    terms,
                    f: f.to_vec(),
                    u: u.to_vec(),
                    v: v.to_vec(),
                },
            ))
        }
        Plan::Tabulated => {
            let rows: Vec<Vec<f32>> = data
                .chunks_exact(grid.columns())
                .map(<[f32]>::to_vec)
                .collect();
            Prepared::Tabulated(Tabulated::new(grid, &rows))
        }
        Plan::Tensor { terms } => {
            Prepared::Tensor(TensorSampler::new(grid.parameterization, terms, data))
        }
    }
}

/// Computes the payload of `plan` for `reflectance` (no cache).
pub fn compute(
    reflectance: &Reflectance,
    plan: Plan,
    grid: Grid,
    progress: &ProgressBar,
) -> Vec<f32> {
    let rows = || {
        let f = |wo: Vec3, wi: Vec3| -> Rgb { reflectance.eval(wi, wo) };
        let mut rows = grid.rows_of(&f, progress);
        normalize_rows(&mut rows);
        rows
    };
    match plan {
        Plan::Factored { terms } => {
            let factors = factorize(&rows(), &grid, terms, progress);
            [factors.f, factors.u, factors.v].concat()
        }
        Plan::Tabulated => rows().concat(),
        Plan::Tensor { terms } => {
            let payload = tensor_sampling::fit(reflectance, grid.parameterization, terms);
            progress.inc(1);
            payload
        }
    }
}

/// The sampler for `plan`, from the cache next to `table_path` if it holds
/// this source's, else computed (and cached when `use_cache`). Without a
/// table file (an analytic source) it is computed every time.
pub fn prepare(
    reflectance: &Reflectance,
    table_path: Option<&Path>,
    plan: Plan,
    grid: Grid,
    use_cache: bool,
) -> Result<(Prepared, PrecomputeReport)> {
    let name = source_name(table_path);
    let label = match plan {
        Plan::Factored { terms } => format!("factored L = {terms}"),
        Plan::Tabulated => "tabulated".to_string(),
        Plan::Tensor { terms } => format!("tensor L = {terms}"),
    };
    let cache = cache::slot(use_cache, table_path, reflectance.cache_hash(), |hash| {
        plan.cache_key(hash, grid)
    });
    let mut note = String::new();
    if let Some((path, key)) = &cache {
        match cache::load(path, key, plan.count(&grid)) {
            Ok(data) => {
                let prepared = from_payload(plan, grid, &data);
                let memory_bytes = prepared.memory_bytes();
                let message = format!(
                    "{name}: {label} sampling loaded from {} ({} KiB)",
                    path.display(),
                    memory_bytes / 1024
                );
                return Ok((
                    prepared,
                    PrecomputeReport {
                        seconds: 0.0,
                        from_cache: true,
                        memory_bytes,
                        message,
                    },
                ));
            }
            Err(miss) => note = miss.note(path),
        }
    }
    let total = match plan {
        Plan::Factored { .. } => (grid.n_o + NMF_ITERATIONS + REFINE_ITERATIONS) as u64,
        Plan::Tabulated => grid.n_o as u64,
        Plan::Tensor { .. } => 1,
    };
    let progress = ProgressBar::new(total).with_message(format!("{label} sampling of {name}"));
    if let Ok(style) = ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {elapsed}") {
        progress.set_style(style.progress_chars("=> "));
    }
    let start = Instant::now();
    let data = compute(reflectance, plan, grid, &progress);
    let seconds = start.elapsed().as_secs_f64();
    progress.finish_and_clear();
    if let Some((path, key)) = &cache {
        if let Err(e) = cache::store(path, key, &data) {
            note.push_str(&format!(" (not cached: {e})"));
        } else {
            note.push_str(&format!(", cached in {}", path.display()));
        }
    }
    let prepared = from_payload(plan, grid, &data);
    let memory_bytes = prepared.memory_bytes();
    let (on, cells) = match plan {
        Plan::Tensor { .. } => ("fitted at the", "nodes"),
        Plan::Factored { .. } | Plan::Tabulated => ("on a", "grid precomputed"),
    };
    let message = format!(
        "{name}: {label} sampling {on} {} x {} x {} {cells} in {seconds:.2} s, {} KiB{note}",
        grid.n_o,
        grid.n_w,
        grid.n_phi,
        memory_bytes / 1024
    );
    Ok((
        prepared,
        PrecomputeReport {
            seconds,
            from_cache: false,
            memory_bytes,
            message,
        },
    ))
}

/// What the messages call a source: its table file, or the analytic BSDF.
pub fn source_name(table_path: Option<&Path>) -> String {
    table_path.map_or("the analytic BSDF".to_string(), |p| p.display().to_string())
}
