//! Checks that `sample_li` draws directions with the density `pdf_li`
//! claims: Pearson's chi-square over the sphere of directions from points
//! in front of the light, and the quadrature of `pdf_li` (which must be 1,
//! the whole emitting side being seen from there).

use lumis_check::adapters::light_pair;
use lumis_check::light_suite::{check_light_with, format_light_results, LightCheckConfig};
use lumis_check::outcome::Outcome;
use lumis_check::{chi_square, corrected_significance, ChiSquareConfig};
use lumis_core::{LightSampleContext, PluginKind, Registry, Rgb, Vec2, Vec3};

use {{lib}}::QuadEmitter;

/// A 1 x 0.5 rectangle at height 1, facing down (`x cross z = -y`).
fn light() -> QuadEmitter {
    QuadEmitter::new(
        Vec3::new(-0.3, 1.0, -0.2),
        Vec3::X,
        Vec3::new(0.0, 0.0, 0.5),
        Rgb::splat(2.0),
    )
    .unwrap()
}

/// Shading points below the light: under it, close, grazing (9.5 degrees
/// above its plane) and far.
const POINTS: [[f32; 3]; 4] = [
    [0.1, 0.0, 0.1],
    [0.2, 0.9, 0.0],
    [1.5, 0.8, 0.3],
    [0.0, -2.0, 0.0],
];

#[test]
fn sample_li_matches_pdf_li() {
    let light = light();
    let cfg = ChiSquareConfig {
        // A small light covers few bins, many of them cut by its outline:
        // fine bins, and more splits of the bins the quadrature of the pdf
        // needs there.
        z_bins: 80,
        phi_bins: 160,
        samples: 400_000,
        max_refinement: 8,
        // Area sampling's density peaks toward grazing directions, where
        // the quadrature is good to a few 1e-3.
        integral_tolerance: 5e-3,
        significance: corrected_significance(0.01, POINTS.len()),
        ..Default::default()
    };
    for p in POINTS {
        let (sample, pdf) = light_pair(&light, LightSampleContext::at(Vec3::from(p)));
        let report = chi_square(sample, pdf, &cfg);
        assert!(
            report.passed,
            "from {p:?}: p = {:.3e}, pdf integral {:.4}, {:?}",
            report.p_value, report.pdf_integral, report.defect
        );
        assert!(
            report.sampled_fraction > 0.99,
            "from {p:?}: only {} of the samples were valid",
            report.sampled_fraction
        );
    }
}

#[test]
fn nothing_is_sampled_from_behind() {
    let light = light();
    let above = LightSampleContext::at(Vec3::new(0.0, 2.0, 0.0));
    let (mut sample, pdf) = light_pair(&light, above);
    assert!(sample(0.5, Vec2::splat(0.5)).is_none());
    assert_eq!(pdf(Vec3::NEG_Y), 0.0);
}

#[test]
fn registers_as_a_light() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    assert!(registry
        .find(PluginKind::Light, {{lib}}::SPEC.name)
        .is_some());
}

/// The checks of `lumis check-plugin`, over the declared parameters, from
/// points all around the light on the quad shape it is the emission of.
#[test]
fn passes_the_light_suite() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    let results = check_light_with(
        &registry,
        {{lib}}::SPEC.name,
        &[],
        &LightCheckConfig::default(),
    )
    .unwrap();
    assert!(
        results.iter().all(|r| r.passed()),
        "{}",
        format_light_results(&results)
    );
}
