//! The shapes the lecture states for sample patterns, asserted: the
//! spectra of jittered and Poisson disk sets, and the convergence rates of
//! random, stratified and quasi-random points on smooth and discontinuous
//! integrands.

use lumis_analysis::convergence::{loglog_slope, powers_of_two, sampler_rmse};
use lumis_analysis::integrands::{self, Integrand};
use lumis_analysis::spectrum::radial_average;
use lumis_core::Registry;

use super::{make_sampler, Spectrum};

fn registry() -> Registry {
    lumis_app::builtin_registry().unwrap()
}

/// The radially averaged periodogram of 256-point sets (64 scrambles),
/// indexed by the ring `|k|`.
fn radial_spectrum(registry: &Registry, sampler: &str) -> Vec<f64> {
    let spectrum = Spectrum {
        count: 256,
        seed: 0,
        realizations: 64,
        size: 64,
    };
    let mut sampler = make_sampler(registry, sampler, &[], spectrum.count).unwrap();
    let psd = spectrum.average_psd(sampler.as_mut(), || {});
    radial_average(&psd, spectrum.size).0
}

fn mean(rings: &[f64], lo: usize, hi: usize) -> f64 {
    rings[lo..=hi].iter().sum::<f64>() / (hi - lo + 1) as f64
}

/// White noise is flat at the points' count normalised to 1; the jittered
/// and Poisson disk sets have a hole at low frequencies (little power
/// below the strata's or the disks' spacing, Dippe and Wold 1985) and are
/// white again far above it; the Poisson disk set has its ring, a peak
/// above white near the frequency of the disk spacing (Ulichney 1987).
#[test]
fn spectra_have_the_shapes_the_lecture_names() {
    let registry = registry();
    let white = radial_spectrum(&registry, "independent");
    let jittered = radial_spectrum(&registry, "stratified");
    let poisson = radial_spectrum(&registry, "poisson-disk");
    for (k, power) in white.iter().enumerate().skip(1) {
        assert!(
            (0.6..1.5).contains(power),
            "white noise at |k| = {k}: {power}"
        );
    }
    assert!((mean(&white, 1, 31) - 1.0).abs() < 0.05, "{white:?}");
    // Measured: 0.106 and 0.090 at |k| = 1..4, 0.994 and 0.838 at
    // 24..31 (the Poisson disk's ripples still decaying), a ring peak of
    // 1.52, white noise at 1.003.
    for (name, rings) in [("jittered", &jittered), ("Poisson disk", &poisson)] {
        assert!(
            mean(rings, 1, 4) < 0.25,
            "{name}: no low-frequency hole: {rings:?}"
        );
    }
    assert!(
        (mean(&jittered, 24, 31) - 1.0).abs() < 0.1,
        "not white far out: {jittered:?}"
    );
    assert!((0.6..1.2).contains(&mean(&poisson, 24, 31)), "{poisson:?}");
    let peak = poisson[8..24].iter().cloned().fold(0.0, f64::max);
    assert!(
        peak > 1.25,
        "Poisson disk: no ring above white: {poisson:?}"
    );
}

/// RMSE against N = 4 .. 4096 over 32 scrambles, fitted log-log slope of
/// the sampler `name` on `integrand`.
fn slope(registry: &Registry, name: &str, integrand: &Integrand) -> f64 {
    let counts = powers_of_two(4, 4096);
    let make = |n: u32| make_sampler(registry, name, &[], n).unwrap();
    let rmse = sampler_rmse(&make, std::slice::from_ref(integrand), &counts, 32, || {});
    let xs: Vec<f64> = counts.iter().map(|&c| f64::from(c)).collect();
    loglog_slope(&xs, &rmse[0]).unwrap()
}

fn integrand(name: &str) -> Integrand {
    integrands::integrand(name).unwrap()
}

/// The rates the lecture gives: Monte Carlo `N^-1/2` whatever the
/// integrand; jittered sampling `N^-1/2 - 1/d` on smooth integrands
/// (`-1` in 2D, `-1.5` in 1D) and `N^-3/4` on a 2D discontinuity (the
/// strata the edge crosses); Owen-scrambled Sobol' points close to
/// `N^-3/2` on smooth integrands (Owen 1997) and `N^-3/4` on the disk.
/// Measured (fixed seeds): -0.54, -0.53, -0.49; -0.97, -0.75, -1.47;
/// -1.36, -0.73, -1.53.
#[test]
fn convergence_rates_are_the_lecture_s() {
    let registry = registry();
    let (gaussian, disk, gaussian_1d) = (
        integrand("gaussian"),
        integrand("disk"),
        integrand("gaussian-1d"),
    );
    let cases: [(&str, &Integrand, f64, f64); 9] = [
        ("independent", &gaussian, -0.5, 0.1),
        ("independent", &disk, -0.5, 0.1),
        ("independent", &gaussian_1d, -0.5, 0.1),
        ("stratified", &gaussian, -1.0, 0.12),
        ("stratified", &disk, -0.75, 0.12),
        ("stratified", &gaussian_1d, -1.5, 0.12),
        ("sobol", &gaussian, -1.4, 0.2),
        ("sobol", &disk, -0.75, 0.12),
        ("sobol", &gaussian_1d, -1.5, 0.12),
    ];
    for (sampler, g, expected, tolerance) in cases {
        let measured = slope(&registry, sampler, g);
        assert!(
            (measured - expected).abs() < tolerance,
            "{sampler} on {}: slope {measured:.3}, expected {expected} ± {tolerance}",
            g.name
        );
    }
}
