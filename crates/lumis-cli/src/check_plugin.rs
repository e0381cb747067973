//! `lumis check-plugin`: the statistical checks of `lumis-check` run over
//! the plugins a library registers, or over named built-ins
//! ([`lumis_check::plugins`]).

use std::path::PathBuf;

use lumis_app::registry_with_search_path;
use lumis_check::plugins::{check_plugins, CheckSettings, PluginNames};
use lumis_core::{Error, PluginKind, Result};

/// `lumis check-plugin`: returns whether every case passed.
pub(crate) fn check_plugin(
    library: Option<PathBuf>,
    mut names: PluginNames,
    samples: usize,
    bins: usize,
    out: &std::path::Path,
    set: &[String],
) -> Result<bool> {
    let fixed = lumis_app::fixed_parameters(set)?;
    // Before any check runs: a failure picture has somewhere to go.
    std::fs::create_dir_all(out).map_err(|e| {
        Error::msg(format!(
            "--out {}: cannot create the directory for failure pictures: {e}",
            out.display()
        ))
    })?;
    let mut registry = registry_with_search_path()?;
    if let Some(library) = &library {
        // The library's plugins are the ones it added (its path as the
        // registry labels them is the resolved one, not the one given).
        let before: Vec<(PluginKind, &str)> = registry
            .plugins()
            .into_iter()
            .map(|p| (p.spec.kind, p.spec.name))
            .collect();
        lumis_loader::load_library(library, &mut registry)?;
        names.extend_added(&before, &registry);
    }
    if names.is_empty() && names.denoiser.is_empty() {
        return Err(Error::msg(
            "nothing to check: give a plugin library that registers BSDFs, lights, light samplers, samplers or integrators, or --bsdf, --light, --light-sampler, --sampler or --integrator NAME",
        ));
    }
    let settings = CheckSettings {
        samples,
        bins,
        out,
        fixed: &fixed,
    };
    check_plugins(&registry, &names, &settings, &mut |report| {
        print!("{report}")
    })
}
