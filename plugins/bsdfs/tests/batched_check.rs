//! Every BSDF of this crate passes the value checks of `lumis check-plugin`
//! over its whole parameter sweep, the batched methods' agreement with the
//! scalar ones among them (`sample_f_batch`/`eval_batch` against
//! `sample_f`/`eval`, lane by lane).
//!
//! The chi-square part runs on few samples here and is not asserted: the
//! batched overrides change no scalar method, and tests/bsdf_checks.rs
//! runs the full suite, chi-square included, over every built-in plugin.

use lumis_check::bsdf_suite::{check_bsdf, format_results, BsdfCheckConfig};
use lumis_check::ChiSquareConfig;
use lumis_core::{PluginKind, Registry};

#[test]
fn every_bsdf_passes_the_value_and_batch_checks() {
    let mut registry = Registry::new();
    lumis_bsdfs::register(&mut registry).unwrap();
    let cfg = BsdfCheckConfig {
        chi_square: ChiSquareConfig {
            z_bins: 10,
            phi_bins: 10,
            samples: 10_000,
            ..Default::default()
        },
        ..Default::default()
    };
    let names = registry.names(PluginKind::Bsdf);
    assert!(names.contains(&"conductor") && names.contains(&"diffuse"));
    let mut failures = Vec::new();
    for name in names {
        let results = check_bsdf(&registry, name, &cfg).unwrap();
        if results.iter().any(|r| !r.problems.is_empty()) {
            failures.push(format_results(&results));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
