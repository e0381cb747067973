//! `lumis.check_plugin`: `lumis check-plugin`'s suite from Python, for a
//! built-in plugin or one written in Python.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

use lumis_api::registrar::PluginKind;
use lumis_api::Error;
use lumis_check::plugins::{check_plugins, CheckSettings, PluginNames};
use lumis_render::RenderPool;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::{raise_plugin_exception, registry, take_exception, thread_host};
use crate::errors::{lumis_error, OrRaise};
use crate::mapping::toml_of;
use crate::stoppable::run_stoppable;

/// Runs `lumis check-plugin`'s suite for the plugin `name` (a BSDF, light,
/// light sampler, sampler or integrator, built-in or registered from
/// Python) and prints its report; returns whether every case passed.
/// `samples` and `bins` size each BSDF chi-square, as `--samples` and
/// `--bins` do; failure pictures go to `out`; each keyword holds a
/// parameter at a value instead of sweeping it (`--set`).
#[pyfunction]
#[pyo3(signature = (name, samples = 1_000_000, bins = 100, out = PathBuf::from("."), **fixed))]
pub fn check_plugin(
    py: Python<'_>,
    name: &str,
    samples: usize,
    bins: usize,
    out: PathBuf,
    fixed: Option<&Bound<'_, PyDict>>,
) -> PyResult<bool> {
    let mut held = Vec::new();
    for (key, value) in fixed.into_iter().flat_map(|f| f.iter()) {
        let key: String = key.extract()?;
        let value = toml_of(&value, &key)?;
        held.push((key, value.to_string()));
    }
    let registry = py.detach(registry).or_raise(py)?;
    let mut names = PluginNames::default();
    let kinds: Vec<PluginKind> = registry
        .plugins()
        .iter()
        .filter(|p| p.spec.name == name)
        .map(|p| p.spec.kind)
        .collect();
    for kind in &kinds {
        let list = match kind {
            PluginKind::Bsdf => &mut names.bsdf,
            PluginKind::Light => &mut names.light,
            PluginKind::LightSampler => &mut names.light_sampler,
            PluginKind::Sampler => &mut names.sampler,
            PluginKind::Integrator => &mut names.integrator,
            _ => continue,
        };
        list.push(name.to_string());
    }
    if names.is_empty() {
        return Err(lumis_error(
            py,
            &Error::msg(format!(
                "check_plugin: no BSDF, light, light sampler, sampler or integrator is named '{name}'"
            )),
        ));
    }
    std::fs::create_dir_all(&out)
        .map_err(|e| Error::msg(format!("out={}: {e}", out.display())))
        .or_raise(py)?;
    let settings = CheckSettings {
        samples,
        bins,
        out: &out,
        fixed: &held,
    };
    let report = Mutex::new(String::new());
    let stop = AtomicBool::new(false);
    take_exception();
    // The suites' parallel loops run on threads that joined the
    // interpreter once.
    let pool = RenderPool::hosted(0, Some(thread_host())).or_raise(py)?;
    let (passed, stopped_by) = run_stoppable(
        py,
        &stop,
        || {
            pool.install(|| {
                check_plugins(&registry, &names, &settings, &mut |text| {
                    report.lock().unwrap().push_str(text)
                })
            })
        },
        |_| Ok(()),
    )?;
    let report = report.into_inner().unwrap_or_default();
    py.import("builtins")?
        .getattr("print")?
        .call1((report.trim_end(),))?;
    if let Some(e) = stopped_by {
        return Err(e);
    }
    let passed = raise_plugin_exception(py, passed)?;
    // A fault is a failed check, reported by the exception it raised.
    if let Err(fault) = registry.faults().check() {
        return Err(take_exception().unwrap_or_else(|| lumis_error(py, &fault)));
    }
    Ok(passed)
}
