//! The integrator check: every built-in integrator passes it, integrators
//! with planted defects fail it, and `lumis check-plugin --integrator`
//! runs it.

use lumis_check::outcome::Outcome;
use lumis_check::sweep::parameter_sweep;
use std::process::Command;

use lumis_app::builtin_registry;
use lumis_check::integrator_suite::{
    check_integrator_with, format_integrator_results, IntegratorCaseResult, IntegratorCheckConfig,
    IntegratorTest,
};
use lumis_core::{
    Integrator, PluginKind, PluginParams, PluginSpec, Ray, Registrar, Registry, RenderStats, Rgb,
    Sampler, Scene,
};
use lumis_integrators::{EstimatorParams, PathIntegrator, PathParams};

fn check(registry: &Registry, name: &str) -> Vec<IntegratorCaseResult> {
    check_with(registry, name, &IntegratorCheckConfig::default())
}

fn check_with(
    registry: &Registry,
    name: &str,
    cfg: &IntegratorCheckConfig,
) -> Vec<IntegratorCaseResult> {
    check_integrator_with(registry, name, &[], cfg).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// `path` passes the full check in [`check_plugin_checks_a_builtin_integrator`];
/// `direct` (whose exact values are those of depth 2), `wavefront`,
/// `packet` and `light` (the film's splats through the driver) pass it at
/// half the samples, to keep this test short.
#[test]
fn every_builtin_integrator_passes() {
    let registry = builtin_registry().unwrap();
    let cfg = IntegratorCheckConfig {
        spp: 8,
        compare_spp: 32,
        ..IntegratorCheckConfig::default()
    };
    for name in ["direct", "wavefront", "packet", "light"] {
        let results = check_with(&registry, name, &cfg);
        let table = format_integrator_results(&results);
        assert!(results.iter().all(|r| r.passed()), "{table}");
        // Every case was measured: none refused, none left untested.
        assert!(
            results
                .iter()
                .all(|r| r.refused.is_none() && r.not_testable.is_none()),
            "{table}"
        );
    }
}

/// `path`, its radiance scaled by a constant: a defect every test sees.
struct Scaled(PathIntegrator, f32);

impl Integrator for Scaled {
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        self.0.li(ray, scene, sampler, stats) * self.1
    }
}

const SCALED: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "scaled-path",
    source: lumis_api::source_file!(),
    doc: "path, radiance times 0.95 (a planted defect)",
    params: PathParams::SPECS,
};

const SHORT: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "short-path",
    source: lumis_api::source_file!(),
    doc: "path that stops one segment short of its max_depth (a planted defect)",
    params: PathParams::SPECS,
};

const DEPTHLESS: PluginSpec = PluginSpec {
    kind: PluginKind::Integrator,
    name: "depthless",
    source: lumis_api::source_file!(),
    doc: "direct lighting under a name the kit does not know, without max_depth",
    params: EstimatorParams::SPECS,
};

fn registry_with_planted() -> Registry {
    let mut registry = builtin_registry().unwrap();
    registry
        .add_integrator(SCALED, |p| {
            Ok(Box::new(Scaled(PathIntegrator::from_params(p)?, 0.95)))
        })
        .unwrap();
    registry
        .add_integrator(SHORT, |p| {
            let mut read = PathParams::read(p)?;
            read.max_depth = read.max_depth.saturating_sub(1).max(1);
            Ok(Box::new(PathIntegrator::from_read(&read, p)?))
        })
        .unwrap();
    registry
        .add_integrator(DEPTHLESS, |p| {
            Ok(Box::new(lumis_integrators::DirectIntegrator::from_params(
                p,
            )?))
        })
        .unwrap();
    registry
}

fn failed(results: &[IntegratorCaseResult], test: IntegratorTest) -> usize {
    results
        .iter()
        .filter(|r| r.test == test && !r.passed())
        .count()
}

/// 5% too dark: every parameter setting fails, and each test catches it
/// on its own in most of the settings checked with a full case's samples
/// (a value inside a range is checked with a fifth of them, which the
/// comparison with `path` needs more of).
#[test]
fn a_scaled_path_tracer_fails() {
    let registry = registry_with_planted();
    let results = check(&registry, "scaled-path");
    let table = format_integrator_results(&results);
    for variant in results.chunks(3) {
        assert!(variant.iter().any(|r| !r.passed()), "{table}");
    }
    let spec = registry
        .find(PluginKind::Integrator, "scaled-path")
        .unwrap()
        .spec;
    let full: Vec<String> = parameter_sweep(&spec)
        .unwrap()
        .into_iter()
        .filter(|v| v.share() == 1.0)
        .map(|v| v.label)
        .collect();
    let checked_fully: Vec<IntegratorCaseResult> = results
        .iter()
        .filter(|r| full.contains(&r.variant))
        .cloned()
        .collect();
    for test in [
        IntegratorTest::Furnace,
        IntegratorTest::NeumannSeries,
        IntegratorTest::AgreesWithPath,
    ] {
        assert!(
            2 * failed(&checked_fully, test) > full.len(),
            "{test:?}\n{table}"
        );
    }
}

/// One segment short: the sphere furnace cannot tell (the convex sphere
/// needs only one bounce), the emissive box can (at albedo 0.9 the eighth
/// segment carries 8% of the radiance); the comparison with `path` in the
/// lit box is not asked to (the segment carries too little there).
#[test]
fn a_path_tracer_that_drops_its_last_segment_fails() {
    let registry = registry_with_planted();
    let results = check(&registry, "short-path");
    let table = format_integrator_results(&results);
    let variants = results.len() / 3;
    assert_eq!(failed(&results, IntegratorTest::Furnace), 0, "{table}");
    assert_eq!(
        failed(&results, IntegratorTest::NeumannSeries),
        variants,
        "{table}"
    );
}

/// Without a depth the exact values are unknown: every case says so, and
/// none fails or passes in silence.
#[test]
fn an_integrator_without_a_depth_is_not_testable() {
    let registry = registry_with_planted();
    let results = check(&registry, "depthless");
    let table = format_integrator_results(&results);
    assert!(
        results
            .iter()
            .all(|r| r.not_testable.is_some() && r.passed()),
        "{table}"
    );
    assert!(
        table.contains("not testable: \"depthless\" declares no max_depth"),
        "{table}"
    );
    assert!(
        table.contains(&format!(
            "0 passed, 0 failed, {} not testable, 0 refused by the plugin",
            results.len()
        )),
        "{table}"
    );
}

#[test]
fn check_plugin_checks_a_builtin_integrator() {
    let run = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["check-plugin", "--integrator", "path"])
        .output()
        .expect("lumis runs");
    let stdout = String::from_utf8(run.stdout).unwrap();
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        stdout.contains("same as path") && stdout.contains(" 0 failed"),
        "{stdout}"
    );
    let missing = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["check-plugin", "--integrator", "no-such-integrator"])
        .output()
        .expect("lumis runs");
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr)
        .contains("no integrator plugin named \"no-such-integrator\""));
}
