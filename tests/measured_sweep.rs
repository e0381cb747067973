//! The check kit on every sampling strategy of the `measured` BSDF, for
//! MERL tables of three lumis BSDFs of increasing glossiness written by
//! `lumis brdf tabulate` (plastic GGX 0.3, conductor GGX 0.2 and 0.05):
//! chi-square of sample_f against pdf (100 x 100 bins, 1e6 samples,
//! Sidak-corrected over all cases), pdf integral <= 1, sample_f consistent
//! with f and pdf, albedo <= 1, reciprocity, finiteness, at cos theta_o =
//! 1e-4, 0.01, 0.1, 0.5, 1 and -1e-4, -0.5, -1 (one-sided: no samples from
//! behind). The same kit on the projected-deviation-vector (`pdv`)
//! parameterization of the factored and tabulated strategies: the
//! conductor-0.2 table in the default tier, every table and term count in
//! an ignored sweep. And the kit on an analytic source (`bsdf`, the check
//! kit's stand-in gold conductor) in every parameterization, its samplers
//! (the tensor sampler's non-negative factors among them) and a tensor
//! fitted to the BSDF itself.

use lumis_check::bsdf_suite::{variant, Variant};
use lumis_tests::{assert_measured_variants_pass, tabulated, MEASURED_MATERIALS as MATERIALS};

#[test]
fn every_strategy_passes_the_check_kit_down_to_grazing() {
    let dir = std::env::temp_dir().join(format!("lumis-measured-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut variants: Vec<Variant> = Vec::new();
    for (name, bsdf, set) in MATERIALS {
        let file = tabulated(&dir, name, bsdf, set);
        let file = file.display();
        let mut add = |label: String, extra: &str| {
            variants.push(variant(label, &format!("file = \"{file}\"\n{extra}")).unwrap());
        };
        add(format!("{name} cosine"), "sampling = \"cosine\"\n");
        for terms in [1, 2, 4] {
            add(
                format!("{name} factored L={terms}"),
                &format!("sampling = \"factored\"\nterms = {terms}\n"),
            );
        }
        add(format!("{name} tabulated"), "sampling = \"tabulated\"\n");
    }
    assert_measured_variants_pass(&variants, &dir);
}

/// With `bsdf` in place of a table, the samplers and the tensor are
/// fitted to the analytic BSDF at their own cells and nodes, in every
/// parameterization; they pass the same kit (the stand-in "gold" is GGX
/// 0.2 gold).
#[test]
fn an_analytic_source_passes_the_check_kit_in_every_parameterization() {
    let dir = std::env::temp_dir().join(format!("lumis-measured-analytic-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut variants: Vec<Variant> = Vec::new();
    for parameterization in ["half-diff", "pdv", "in-out"] {
        for sampling in ["factored", "tabulated", "tensor"] {
            let toml = format!(
                "bsdf = \"gold\"\nparameterization = \"{parameterization}\"\nsampling = \"{sampling}\"\n"
            );
            let label = format!("gold {parameterization} {sampling}");
            variants.push(variant(label, &toml).unwrap());
        }
    }
    let tensor =
        "bsdf = \"gold\"\nparameterization = \"pdv\"\nrepresentation = \"tensor\"\nrank = 2\n";
    variants.push(variant("gold pdv tensor R=2", tensor).unwrap());
    let sampled = format!("{tensor}sampling = \"tensor\"\nterms = 4\n");
    variants.push(variant("gold pdv tensor R=2, tensor sampling L=4", &sampled).unwrap());
    assert_measured_variants_pass(&variants, &dir);
}

/// The check kit on the `pdv` parameterization of `materials`, for the
/// factored strategy with each of `terms` and the tabulated one.
fn check_pdv(tag: &str, materials: &[(&str, &str, &[&str])], terms: &[i64]) {
    let dir = std::env::temp_dir().join(format!("lumis-measured-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut variants: Vec<Variant> = Vec::new();
    for &(name, bsdf, set) in materials {
        let file = tabulated(&dir, name, bsdf, set);
        let file = file.display();
        let mut add = |label: String, extra: &str| {
            let toml = format!("file = \"{file}\"\nparameterization = \"pdv\"\n{extra}");
            variants.push(variant(label, &toml).unwrap());
        };
        for &l in terms {
            add(
                format!("{name} pdv factored L={l}"),
                &format!("sampling = \"factored\"\nterms = {l}\n"),
            );
        }
        add(
            format!("{name} pdv tabulated"),
            "sampling = \"tabulated\"\n",
        );
    }
    assert_measured_variants_pass(&variants, &dir);
}

#[test]
fn pdv_sampling_of_a_conductor_passes_the_check_kit_down_to_grazing() {
    check_pdv("pdv", &MATERIALS[1..2], &[2]);
}

#[test]
#[ignore = "every table and term count: about 4 minutes"]
fn pdv_sampling_of_every_table_passes_the_check_kit_down_to_grazing() {
    check_pdv("pdv-sweep", &MATERIALS, &[1, 2, 4]);
}
