//! `lumis.converge` and `lumis.bias_variance`: the studies' measurements
//! from Python, as records.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use lumis_analysis::bias_variance::{BiasVariance, Split};
use lumis_core::Error;
use lumis_image::Image;
use lumis_studies::{converge_variants, read_variants, variant_of, ConvergeArgs, Point, Run};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{lumis_error, Interrupted, OrRaise};
use crate::image::image_from;
use crate::mapping::{assignment, node_of, toml_of};
use crate::plugins;
use crate::stoppable::run_stoppable;

/// What `lumis.converge` measured: each render (`runs`), each variant's
/// summary over its seeds at each spp (`points`, with the error split into
/// bias² and variance), the fitted log-log slopes of relMSE against spp,
/// and the ranked table `lumis converge` prints.
#[pyclass(module = "lumis", frozen)]
pub struct Study {
    #[pyo3(get)]
    runs: Py<PyList>,
    #[pyo3(get)]
    points: Py<PyList>,
    #[pyo3(get)]
    slopes: Py<PyDict>,
    #[pyo3(get)]
    table: String,
    /// Ctrl-C stopped the study: the records are those measured before.
    #[pyo3(get)]
    interrupted: bool,
}

#[pymethods]
impl Study {
    /// `points` (or `runs`) as a pandas DataFrame.
    #[pyo3(signature = (records = "points"))]
    fn to_pandas<'py>(&self, py: Python<'py>, records: &str) -> PyResult<Bound<'py, PyAny>> {
        let rows = match records {
            "points" => &self.points,
            "runs" => &self.runs,
            other => {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "records={other:?}: expected \"points\" or \"runs\""
                )))
            }
        };
        py.import("pandas")?
            .getattr("DataFrame")?
            .call1((rows.clone_ref(py),))
    }

    fn __repr__(&self) -> String {
        self.table.clone()
    }
}

fn run_record<'py>(py: Python<'py>, run: &Run) -> PyResult<Bound<'py, PyDict>> {
    let record = PyDict::new(py);
    record.set_item("variant", &run.variant)?;
    record.set_item("spp", run.spp)?;
    record.set_item("seed", run.seed)?;
    record.set_item("seconds", run.seconds)?;
    record.set_item("samples_per_second", run.samples_per_second)?;
    record.set_item("rays_per_second", run.rays_per_second)?;
    record.set_item("mse", run.mse)?;
    record.set_item("rel_mse", run.rel_mse)?;
    record.set_item("psnr_db", run.psnr_db)?;
    Ok(record)
}

/// A point's record: the columns of `converge.csv`.
fn point_record<'py>(py: Python<'py>, point: &Point) -> PyResult<Bound<'py, PyDict>> {
    let record = PyDict::new(py);
    record.set_item("variant", &point.variant)?;
    record.set_item("spp", point.spp)?;
    record.set_item("seconds", point.seconds)?;
    record.set_item("mse", point.mse)?;
    record.set_item("mse_se", point.mse_se)?;
    record.set_item("rel_mse", point.rel_mse)?;
    record.set_item("rel_mse_se", point.rel_mse_se)?;
    record.set_item("rel_mse_min", point.rel_mse_min)?;
    record.set_item("rel_mse_max", point.rel_mse_max)?;
    record.set_item("psnr_db", point.psnr_db)?;
    record.set_item("efficiency", point.efficiency)?;
    let split = point.split.as_ref();
    record.set_item("bias2", split.map(|s| s.mse.bias2))?;
    record.set_item("variance", split.map(|s| s.mse.variance))?;
    record.set_item("rel_bias2", split.map(|s| s.rel_mse.bias2))?;
    record.set_item("rel_variance", split.map(|s| s.rel_mse.variance))?;
    Ok(record)
}

/// The variants given to `converge`: the path of a variants file, or a
/// list of dicts `{"name": ..., "set": {"key.path": value, ...}, "image":
/// "raw" | "denoised"}`.
fn variants_of(
    py: Python<'_>,
    variants: &Bound<'_, PyAny>,
) -> PyResult<Vec<lumis_studies::Variant>> {
    if let Ok(path) = variants.extract::<PathBuf>() {
        return read_variants(&path).or_raise(py);
    }
    let mut parsed = Vec::new();
    for (i, variant) in variants.try_iter()?.enumerate() {
        let variant = variant?;
        let at = format!("variants[{i}]");
        // `set` is a dict of overrides: each becomes its `--set` text.
        let mut table = match toml_of(&variant, &at)? {
            toml::Value::Table(table) => table,
            _ => {
                return Err(lumis_error(
                    py,
                    &Error::msg(format!("{at}: expected a dict with name, set and image")),
                ))
            }
        };
        if let Ok(set) = variant
            .get_item("set")
            .and_then(|s| Ok(s.cast_into::<PyDict>()?))
        {
            let assignments = set
                .iter()
                .map(|(key, value)| {
                    Ok(toml::Value::String(assignment(
                        &key.extract::<String>()?,
                        &value,
                    )?))
                })
                .collect::<PyResult<Vec<_>>>()?;
            table.insert("set".into(), toml::Value::Array(assignments));
        }
        let node = node_of(&toml::Value::Table(table), at);
        parsed.push(variant_of(&node).or_raise(py)?);
    }
    Ok(parsed)
}

/// Measures variants of a scene against a reference, as `lumis converge`
/// does, and returns the study as records (`Study`); it writes
/// `converge.csv`, `converge.json`, the plots and each variant's last
/// render under `out` too.
///
/// `variants` is a variants file's path or a list of dicts (`name`, `set`
/// as a dict of overrides, `image`); `spp` the samples per pixel measured;
/// `seeds` the renders per (variant, spp) from `first_seed`;
/// `time_budget` (seconds) makes it an equal-time study; `overrides` apply
/// to every variant. Ctrl-C stops after the render in flight and raises
/// `lumis.Interrupted`, whose `study` holds what was measured.
#[pyfunction]
#[pyo3(signature = (
    scene, reference, variants, spp = vec![1, 2, 4, 8, 16, 32, 64], seeds = 4, first_seed = 0,
    time_budget = None, overrides = None, threads = 0, out = PathBuf::from("converge")
))]
#[allow(clippy::too_many_arguments)]
pub fn converge(
    py: Python<'_>,
    scene: PathBuf,
    reference: PathBuf,
    variants: &Bound<'_, PyAny>,
    spp: Vec<u32>,
    seeds: u64,
    first_seed: u64,
    time_budget: Option<f64>,
    overrides: Option<&Bound<'_, PyDict>>,
    threads: usize,
    out: PathBuf,
) -> PyResult<Study> {
    if time_budget.is_some_and(|t| !(t > 0.0 && t.is_finite())) {
        return Err(lumis_error(
            py,
            &Error::msg("time_budget: expected a positive number of seconds"),
        ));
    }
    let variants = variants_of(py, variants)?;
    let mut set = Vec::new();
    for (key, value) in overrides.into_iter().flat_map(|o| o.iter()) {
        set.push(assignment(&key.extract::<String>()?, &value)?);
    }
    let args = ConvergeArgs {
        scene,
        reference,
        variants: PathBuf::new(),
        spp,
        seeds,
        first_seed,
        time_budget,
        set,
        threads,
        out,
    };
    let registry = py.detach(plugins::registry).or_raise(py)?;
    let stop = AtomicBool::new(false);
    plugins::take_exception();
    let (report, stopped_by) = run_stoppable(
        py,
        &stop,
        || converge_variants(&args, &variants, &registry, &stop),
        |_| Ok(()),
    )?;
    let report = plugins::raise_plugin_exception(py, report)?;
    let runs = report
        .runs
        .iter()
        .map(|r| run_record(py, r))
        .collect::<PyResult<Vec<_>>>()?;
    let points = report
        .points
        .iter()
        .map(|p| point_record(py, p))
        .collect::<PyResult<Vec<_>>>()?;
    let slopes = PyDict::new(py);
    for (variant, slope) in &report.slopes {
        slopes.set_item(variant, slope)?;
    }
    let study = Study {
        runs: PyList::new(py, runs)?.unbind(),
        points: PyList::new(py, points)?.unbind(),
        slopes: slopes.unbind(),
        table: report.table,
        interrupted: report.interrupted,
    };
    match stopped_by {
        None => Ok(study),
        Some(e) if e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) => {
            let error = Interrupted::new_err(
                "interrupted: the exception's `study` holds what was measured",
            );
            error.value(py).setattr("study", Py::new(py, study)?)?;
            error.value(py).setattr("render", py.None())?;
            Err(error)
        }
        Some(e) => Err(e),
    }
}

fn split_record<'py>(py: Python<'py>, split: &Split) -> PyResult<Bound<'py, PyDict>> {
    let record = PyDict::new(py);
    record.set_item("total", split.total)?;
    record.set_item("bias2", split.bias2)?;
    record.set_item("bias2_se", split.bias2_se)?;
    record.set_item("variance", split.variance)?;
    record.set_item("variance_se", split.variance_se)?;
    Ok(record)
}

/// The error of renders that differ only in their seed, split into squared
/// bias and variance against `reference` (the split `lumis converge`
/// reports; `lumis_analysis::bias_variance` has the derivation):
/// `{"mse": {...}, "rel_mse": {...}, "renders": n}`, each part with
/// `total`, `bias2`, `bias2_se`, `variance` and `variance_se`. Each image
/// is a Render, an EXR's path or an array of shape (height, width, 3).
#[pyfunction]
pub fn bias_variance<'py>(
    py: Python<'py>,
    renders: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    let images = renders
        .try_iter()?
        .map(|r| image_from(&r?))
        .collect::<PyResult<Vec<Image>>>()?;
    let reference = image_from(reference)?;
    let split: BiasVariance = lumis_analysis::bias_variance::bias_variance(
        &images.iter().collect::<Vec<_>>(),
        &reference,
    )
    .map_err(Error::msg)
    .or_raise(py)?;
    let record = PyDict::new(py);
    record.set_item("mse", split_record(py, &split.mse)?)?;
    record.set_item("rel_mse", split_record(py, &split.rel_mse)?)?;
    record.set_item("renders", split.renders)?;
    Ok(record)
}
