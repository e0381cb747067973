//! `lumis check-plugin`'s checks as a library: each plugin named is run
//! through its kind's suite, the report handed to the caller's `say` (the
//! command line prints it; Python collects it), and a picture written for
//! each failed chi-square.

use std::path::Path;

use lumis_core::{PluginKind, Registry, Result};

use crate::bsdf_suite::{check_bsdf_with, format_results, write_histogram_png, BsdfCheckConfig};
use crate::integrator_suite::{
    check_integrator_with, format_integrator_results, IntegratorCheckConfig,
};
use crate::light_sampler_suite::{
    check_light_sampler_with, format_light_sampler_results, LightSamplerCheckConfig,
};
use crate::light_suite::{check_light_with, format_light_results, LightCheckConfig};
use crate::outcome::Outcome as _;
use crate::sampler_suite::{check_sampler_with, format_sampler_results, SamplerCheckConfig};

/// How `lumis check-plugin` runs: samples and bins of each BSDF
/// chi-square (the value checks take at most as many samples as it),
/// where failure pictures go, and the parameters held fixed instead of
/// swept (`("file", "\"table.binary\"")`, TOML values).
pub struct CheckSettings<'a> {
    pub samples: usize,
    pub bins: usize,
    pub out: &'a Path,
    pub fixed: &'a [(String, String)],
}

/// The plugins `lumis check-plugin` checks, by kind.
#[derive(Default)]
pub struct PluginNames {
    pub bsdf: Vec<String>,
    pub light: Vec<String>,
    pub light_sampler: Vec<String>,
    pub sampler: Vec<String>,
    pub integrator: Vec<String>,
    /// A library's denoisers: named, not checked (see [`check_plugins`]).
    pub denoiser: Vec<String>,
}

impl PluginNames {
    pub fn is_empty(&self) -> bool {
        self.bsdf.is_empty()
            && self.light.is_empty()
            && self.light_sampler.is_empty()
            && self.sampler.is_empty()
            && self.integrator.is_empty()
    }

    /// Adds the plugins of the checked kinds that `registry` has and
    /// `before` did not (a library's, as it registered them).
    pub fn extend_added(&mut self, before: &[(PluginKind, &str)], registry: &Registry) {
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

/// Checks every plugin of `names` (a denoiser is named, not checked: it
/// is a biased post-process, with no distribution or expectation for the
/// suites to hold it to); returns whether every case passed.
pub fn check_plugins(
    registry: &Registry,
    names: &PluginNames,
    settings: &CheckSettings,
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    for name in &names.denoiser {
        say(&format!("denoiser \"{name}\": not checked (a denoiser is a biased post-process; check-plugin tests estimators)\n"));
    }
    let (fixed, out) = (settings.fixed, settings.out);
    let mut all_passed = true;
    for name in &names.bsdf {
        all_passed &= check_bsdf_plugin(registry, name, settings, say)?;
    }
    for name in &names.light {
        all_passed &= check_light_plugin(registry, name, fixed, out, say)?;
    }
    for name in &names.light_sampler {
        all_passed &= check_light_sampler_plugin(registry, name, fixed, say)?;
    }
    for name in &names.sampler {
        all_passed &= check_sampler_plugin(registry, name, fixed, say)?;
    }
    for name in &names.integrator {
        all_passed &= check_integrator_plugin(registry, name, fixed, say)?;
    }
    Ok(all_passed)
}

/// Checks the BSDF `name`, writing a picture of each failed chi-square.
fn check_bsdf_plugin(
    registry: &Registry,
    name: &str,
    settings: &CheckSettings,
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    let mut cfg = BsdfCheckConfig::default();
    cfg.chi_square.samples = settings.samples;
    // A quick check (few chi-square samples) is quick throughout.
    cfg.samples = cfg.samples.min(settings.samples);
    cfg.chi_square.z_bins = settings.bins;
    cfg.chi_square.phi_bins = settings.bins;
    let results = check_bsdf_with(registry, name, settings.fixed, &cfg)?;
    say(&format_results(&results));
    for (i, r) in results
        .iter()
        .enumerate()
        .filter(|(_, r)| !r.passed() && !r.chi_square.passed && !r.chi_square.observed.is_empty())
    {
        let path = settings.out.join(format!("check-{name}-{i}.png"));
        write_histogram_png(&r.chi_square, &cfg.chi_square, &path)?;
        say(&format!(
            "observed | expected histograms of failed case {i}: {}\n",
            path.display()
        ));
    }
    Ok(results.iter().all(|r| r.passed()))
}

/// Checks the light `name`, writing a picture of each failed chi-square.
fn check_light_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    out: &Path,
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    let cfg = LightCheckConfig::default();
    let results = check_light_with(registry, name, fixed, &cfg)?;
    say(&format_light_results(&results));
    for (i, r) in results.iter().enumerate().filter(|(_, r)| !r.passed()) {
        let Some(report) = r.chi_square.as_ref().filter(|c| !c.passed) else {
            continue;
        };
        let path = out.join(format!("check-{name}-{i}.png"));
        write_histogram_png(report, &cfg.chi_square, &path)?;
        say(&format!(
            "observed | expected histograms of failed case {i}: {}\n",
            path.display()
        ));
    }
    Ok(results.iter().all(|r| r.passed()))
}

fn check_light_sampler_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    let cfg = LightSamplerCheckConfig::default();
    let results = check_light_sampler_with(registry, name, fixed, &cfg)?;
    say(&format_light_sampler_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}

fn check_sampler_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    let results = check_sampler_with(registry, name, fixed, &SamplerCheckConfig::default())?;
    say(&format_sampler_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}

/// Checks the integrator `name` on the kit's tiny scenes.
fn check_integrator_plugin(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    say: &mut dyn FnMut(&str),
) -> Result<bool> {
    let cfg = IntegratorCheckConfig::default();
    let results = check_integrator_with(registry, name, fixed, &cfg)?;
    say(&format_integrator_results(&results));
    Ok(results.iter().all(|r| r.passed()))
}
