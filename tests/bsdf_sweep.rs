//! The sweep of issue 5 for every built-in BSDF: the full check kit
//! (chi-square of sample_f vs pdf, Sidak-corrected over all cases of a
//! model; pdf integral; sample_f consistent with f and pdf; albedo <= 1 in
//! importance transport; reciprocity for reflection; no NaN, Inf or
//! negative value) at
//!
//! - roughness 1e-4 (delta), 1e-3, 0.01, 0.1, 0.5, 1 for both distributions
//!   and both normal-sampling modes, plus anisotropy 1:10 both ways;
//! - Blinn exponents 0 to 1e6;
//! - relative IOR 1.0001, 1.5 and 4, seen from outside (cos theta_o > 0)
//!   and from inside the medium (cos theta_o < 0, relative IOR inverted);
//! - cos theta_o = 1e-4, 0.01, 0.1, 0.5, 1 and -1e-4, -0.5, -1.
//!
//! Two tiers run the same cases. The default tier's chi-square has 50x50
//! bins and 250,000 samples (as many per bin as the full test, a quarter of
//! the time); the extended tier's, 100x100 bins and a million samples
//! (`cargo test -p lumis-tests --test bsdf_sweep -- --ignored`, about 13
//! minutes on two cores).

use lumis_check::bsdf_suite::{
    check_bsdf_variants, format_results, variant, BsdfCheckConfig, CaseResult, Variant,
};
use lumis_check::outcome::Outcome;

const ROUGHNESS: [f64; 6] = [1e-4, 1e-3, 0.01, 0.1, 0.5, 1.0];

/// How finely a tier tests: the chi-square's bins per axis and samples.
#[derive(Clone, Copy)]
enum Tier {
    Default,
    Extended,
}

impl Tier {
    fn config(self) -> BsdfCheckConfig {
        let mut cfg = BsdfCheckConfig::default();
        if let Tier::Default = self {
            cfg.chi_square.z_bins = 50;
            cfg.chi_square.phi_bins = 50;
            cfg.chi_square.samples = 250_000;
        }
        cfg
    }
}

fn run(name: &str, variants: Vec<Variant>, tier: Tier) {
    run_except(name, variants, &[], tier);
}

/// Roughness 1e-3 seen at cos theta_o = +-1e-4: the reflected lobe is at
/// most 2 <wo, m> alpha ~ 2e-6 rad wide across the plane of incidence,
/// some 30 f32 ulps, and the rounded directions miss the pdf's mass by
/// ~0.05% (0.15% inside glass), which a million samples detect. The sweep
/// tests roughness 1e-3 from cos theta_o = 0.01 and grazing angles from
/// roughness 0.01 by chi-square; these cases by every other check.
fn beyond_f32_at_grazing(r: &CaseResult) -> bool {
    r.variant.contains("alpha 0.001") && r.cos_theta_o.abs() == 1e-4
}

/// [`run`], with the chi-square of the cases `(variant label, cos theta_o)`
/// in `beyond_f32` (and those of [`beyond_f32_at_grazing`]) left out;
/// every other check still applies to them.
fn run_except(name: &str, variants: Vec<Variant>, beyond_f32: &[(&str, f32)], tier: Tier) {
    let registry = lumis_app::builtin_registry().unwrap();
    let results = check_bsdf_variants(&registry, name, &variants, &tier.config()).unwrap();
    let report = format_results(&results);
    println!("{report}");
    let ok = |r: &CaseResult| {
        let exempt = beyond_f32_at_grazing(r)
            || beyond_f32
                .iter()
                .any(|&(label, c)| r.variant == label && r.cos_theta_o == c);
        if exempt {
            r.problems.is_empty()
        } else {
            r.passed()
        }
    };
    assert!(results.iter().all(ok), "{report}");
}

fn v(label: String, toml: String) -> Variant {
    variant(label, &toml).unwrap()
}

fn conductor_variants() -> Vec<Variant> {
    let mut variants = Vec::new();
    for distribution in ["ggx", "beckmann"] {
        for sampling in ["visible", "full"] {
            for r in ROUGHNESS {
                variants.push(v(
                    format!("{distribution} {sampling} alpha {r}"),
                    format!("distribution = \"{distribution}\"\nsampling = \"{sampling}\"\nroughness = {r:?}\n"),
                ));
            }
            for (u, w) in [(0.05, 0.5), (0.5, 0.05)] {
                variants.push(v(
                    format!("{distribution} {sampling} alpha {u}x{w}"),
                    format!("distribution = \"{distribution}\"\nsampling = \"{sampling}\"\nroughness = {u:?}\nroughness_v = {w:?}\nmaterial = \"Au\"\n"),
                ));
            }
        }
    }
    for sampling in ["cosine", "uniform"] {
        variants.push(v(
            format!("ggx {sampling} alpha 0.1"),
            format!("sampling = \"{sampling}\"\nroughness = 0.1\nmaterial = \"Cu\"\n"),
        ));
    }
    variants
}

#[test]
fn conductor_sweep() {
    run("conductor", conductor_variants(), Tier::Default);
}

#[test]
#[ignore = "the extended tier: 100x100 bins and 1e6 samples per chi-square"]
fn conductor_sweep_extended() {
    run("conductor", conductor_variants(), Tier::Extended);
}

fn mirror_variants() -> Vec<Variant> {
    ["none", "Ag", "Al", "Au", "Cr", "Cu", "Fe", "Pt"]
        .iter()
        .map(|m| v(format!("material {m}"), format!("material = \"{m}\"\n")))
        .collect()
}

#[test]
fn mirror_sweep() {
    run("mirror", mirror_variants(), Tier::Default);
}

#[test]
#[ignore = "the extended tier: 100x100 bins and 1e6 samples per chi-square"]
fn mirror_sweep_extended() {
    run("mirror", mirror_variants(), Tier::Extended);
}

fn blinn_variants() -> Vec<Variant> {
    let mut variants: Vec<Variant> = [0.0, 1.0, 10.0, 100.0, 1e4, 1e6]
        .iter()
        .map(|n| v(format!("exponent {n}"), format!("exponent = {n:?}\n")))
        .collect();
    for sampling in ["cosine", "uniform"] {
        variants.push(v(
            format!("exponent 10 {sampling}"),
            format!("exponent = 10.0\nsampling = \"{sampling}\"\n"),
        ));
    }
    variants
}

/// n = 1e6 seen at cos theta_o = 1e-4: the lobe is 2e-7 rad wide across
/// the plane of incidence (a half vector tilted by delta moves wi sideways
/// by 2 cos theta_o delta), three f32 ulps of a unit vector, so the density
/// of the rounded directions is not the pdf and no chi-square on f32
/// directions can pass (docs/src/studies/bsdfs.md, "The sweep every BSDF
/// passes"). Finiteness, sample_f/f/pdf consistency and energy are still
/// checked.
const BLINN_BEYOND_F32: &[(&str, f32)] = &[("exponent 1000000", 1e-4)];

#[test]
fn blinn_sweep() {
    run_except("blinn", blinn_variants(), BLINN_BEYOND_F32, Tier::Default);
}

#[test]
#[ignore = "the extended tier: 100x100 bins and 1e6 samples per chi-square"]
fn blinn_sweep_extended() {
    run_except("blinn", blinn_variants(), BLINN_BEYOND_F32, Tier::Extended);
}

fn dielectric_variants() -> Vec<Variant> {
    let mut variants = Vec::new();
    for eta in [1.0001, 1.5, 4.0] {
        for distribution in ["ggx", "beckmann"] {
            for r in ROUGHNESS {
                variants.push(v(
                    format!("eta {eta} {distribution} alpha {r}"),
                    format!(
                        "int_ior = {eta:?}\ndistribution = \"{distribution}\"\nroughness = {r:?}\n"
                    ),
                ));
            }
        }
        variants.push(v(
            format!("eta {eta} ggx full alpha 0.3"),
            format!("int_ior = {eta:?}\nsampling = \"full\"\nroughness = 0.3\n"),
        ));
        variants.push(v(
            format!("eta {eta} ggx alpha 0.05x0.5"),
            format!("int_ior = {eta:?}\nroughness = 0.05\nroughness_v = 0.5\n"),
        ));
    }
    variants
}

#[test]
fn dielectric_sweep() {
    run("dielectric", dielectric_variants(), Tier::Default);
}

#[test]
#[ignore = "the extended tier: 100x100 bins and 1e6 samples per chi-square"]
fn dielectric_sweep_extended() {
    run("dielectric", dielectric_variants(), Tier::Extended);
}

fn plastic_variants() -> Vec<Variant> {
    let mut variants = Vec::new();
    for distribution in ["ggx", "beckmann"] {
        for r in [0.0, 1e-3, 0.01, 0.1, 0.5, 1.0] {
            variants.push(v(
                format!("{distribution} alpha {r}"),
                format!("distribution = \"{distribution}\"\nroughness = {r:?}\ndiffuse_reflectance = [0.9, 0.5, 0.1]\n"),
            ));
        }
    }
    for (eta, nonlinear) in [(1.0001, false), (4.0, true), (1.49, true)] {
        variants.push(v(
            format!("eta {eta} nonlinear {nonlinear} alpha 0.1"),
            format!("int_ior = {eta:?}\nnonlinear = {nonlinear}\nroughness = 0.1\ndiffuse_reflectance = 1.0\n"),
        ));
    }
    variants
}

#[test]
fn plastic_sweep() {
    run("plastic", plastic_variants(), Tier::Default);
}

#[test]
#[ignore = "the extended tier: 100x100 bins and 1e6 samples per chi-square"]
fn plastic_sweep_extended() {
    run("plastic", plastic_variants(), Tier::Extended);
}
