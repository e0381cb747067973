//! `lumis check-plugin`: the statistical checks of `lumis-check` run over
//! the plugins a library registers, or over named built-ins.

use std::path::PathBuf;

use lumis_app::registry_with_search_path;
use lumis_check::bsdf_suite::{
    check_bsdf_with, format_results, write_histogram_png, BsdfCheckConfig,
};
use lumis_check::integrator_suite::{
    check_integrator_with, format_integrator_results, IntegratorCheckConfig,
};
use lumis_check::light_sampler_suite::{
    check_light_sampler_with, format_light_sampler_results, LightSamplerCheckConfig,
};
use lumis_check::light_suite::{check_light_with, format_light_results, LightCheckConfig};
use lumis_check::outcome::Outcome as _;
use lumis_check::sampler_suite::{check_sampler_with, format_sampler_results, SamplerCheckConfig};
use lumis_core::{Error, PluginKind, Registry, Result};

/// The plugins `lumis check-plugin` checks, by kind.
#[derive(Default)]
pub(crate) struct PluginNames {
    pub(crate) bsdf: Vec<String>,
    pub(crate) light: Vec<String>,
    pub(crate) light_sampler: Vec<String>,
    pub(crate) sampler: Vec<String>,
    pub(crate) integrator: Vec<String>,
    /// A library's denoisers: named, not checked (see [`check_plugin`]).
    pub(crate) denoiser: Vec<String>,
}

impl PluginNames {
    fn is_empty(&self) -> bool {
        self.bsdf.is_empty()
            && self.light.is_empty()
            && self.light_sampler.is_empty()
            && self.sampler.is_empty()
            && self.integrator.is_empty()
    }

    /// Adds the plugins of the checked kinds that `registry` has and
    /// `before` did not (a library's, as it registered them).
    fn extend_added(&mut self, before: &[(PluginKind, &str)], registry: &Registry) {
        for p in registry.plugins() {
            if before.contains(&(p.spec.kind, p.spec.name)) {
                continue;
            }
            let name = p.spec.name.to_string();
            match p.spec.kind {
                PluginKind::Bsdf => self.bsdf.push(name),
                PluginKind::Light => self.light.push(name),
                PluginKind::LightSampler => self.light_sampler.push(name),
                PluginKind::Sampler => self.sampler.push(name),
                PluginKind::Integrator => self.integrator.push(name),
                PluginKind::Denoiser => self.denoiser.push(name),
                _ => {}
            }
        }
    }
}

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
    // A denoiser's output is biased by design: there is no distribution or
    // expectation for the statistical tests to hold it to.
    for name in &names.denoiser {
        println!("denoiser \"{name}\": not checked (a denoiser is a biased post-process; check-plugin tests estimators)");
    }
    if names.is_empty() && !names.denoiser.is_empty() {
        return Ok(true);
    }
    if names.is_empty() {
        return Err(Error::msg(
            "nothing to check: give a plugin library that registers BSDFs, lights, light samplers, samplers or integrators, or --bsdf, --light, --light-sampler, --sampler or --integrator NAME",
        ));
    }
    let mut all_passed = true;
    for name in &names.bsdf {
        all_passed &= check_bsdf_plugin(&registry, name, &fixed, samples, bins, out)?;
    }
    for name in &names.light {
        all_passed &= check_light_plugin(&registry, name, &fixed, out)?;
    }
    for name in &names.light_sampler {
        all_passed &= check_light_sampler_plugin(&registry, name, &fixed)?;
    }
    for name in &names.sampler {
        all_passed &= check_sampler_plugin(&registry, name, &fixed)?;
    }
    for name in &names.integrator {
        all_passed &= check_integrator_plugin(&registry, name, &fixed)?;
    }
    Ok(all_passed)
}

/// Checks the BSDF `name`, writing a picture of each failed chi-square.
fn check_bsdf_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    samples: usize,
    bins: usize,
    out: &std::path::Path,
) -> Result<bool> {
    let mut cfg = BsdfCheckConfig::default();
    cfg.chi_square.samples = samples;
    cfg.chi_square.z_bins = bins;
    cfg.chi_square.phi_bins = bins;
    let results = check_bsdf_with(registry, name, fixed, &cfg)?;
    print!("{}", format_results(&results));
    for (i, r) in results
        .iter()
        .enumerate()
        .filter(|(_, r)| !r.passed() && !r.chi_square.passed && !r.chi_square.observed.is_empty())
    {
        let path = out.join(format!("check-{name}-{i}.png"));
        write_histogram_png(&r.chi_square, &cfg.chi_square, &path)?;
        println!(
            "observed | expected histograms of failed case {i}: {}",
            path.display()
        );
    }
    Ok(results.iter().all(|r| r.passed()))
}

/// Checks the light `name`, writing a picture of each failed chi-square.
fn check_light_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    out: &std::path::Path,
) -> Result<bool> {
    let cfg = LightCheckConfig::default();
    let results = check_light_with(registry, name, fixed, &cfg)?;
    print!("{}", format_light_results(&results));
    for (i, r) in results.iter().enumerate().filter(|(_, r)| !r.passed()) {
        let Some(report) = r.chi_square.as_ref().filter(|c| !c.passed) else {
            continue;
        };
        let path = out.join(format!("check-{name}-{i}.png"));
        write_histogram_png(report, &cfg.chi_square, &path)?;
        println!(
            "observed | expected histograms of failed case {i}: {}",
            path.display()
        );
    }
    Ok(results.iter().all(|r| r.passed()))
}

fn check_light_sampler_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
) -> Result<bool> {
    let cfg = LightSamplerCheckConfig::default();
    let results = check_light_sampler_with(registry, name, fixed, &cfg)?;
    print!("{}", format_light_sampler_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}

fn check_sampler_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
) -> Result<bool> {
    let results = check_sampler_with(registry, name, fixed, &SamplerCheckConfig::default())?;
    print!("{}", format_sampler_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}

/// Checks the integrator `name` on the kit's tiny scenes.
fn check_integrator_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
) -> Result<bool> {
    let cfg = IntegratorCheckConfig::default();
    let results = check_integrator_with(registry, name, fixed, &cfg)?;
    print!("{}", format_integrator_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}
