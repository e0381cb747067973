//! The statistical checks of `lumis check-plugin`, run on this crate's
//! plugin as part of `cargo test`: chi-square of `sample_f` against `pdf`,
//! pdf normalisation, `sample_f`/`f`/`pdf` consistency, albedo <= 1,
//! reciprocity and finiteness, over a sweep of the declared parameters.

use lumis_check::bsdf_suite::{check_bsdf_with, format_results, BsdfCheckConfig};
use lumis_check::outcome::Outcome;
use lumis_core::Registry;

#[test]
fn passes_the_bsdf_suite() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    let results = check_bsdf_with(
        &registry,
        {{lib}}::SPEC.name,
        &[],
        &BsdfCheckConfig::default(),
    )
    .unwrap();
    assert!(!results.is_empty());
    assert!(
        results.iter().all(|r| r.passed()),
        "{}",
        format_results(&results)
    );
}
