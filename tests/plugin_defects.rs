//! Defects of a loaded plugin are caught while rendering, not only by
//! `check-plugin`: a render names the plugin and what it got wrong (NaN,
//! negative values, energy created), `--strict` makes that an error after
//! the image is written, and the check sweep finds a defect confined to a
//! tenth of a parameter's range.

use std::process::Command;

use lumis_check::bsdf_suite::{check_bsdf_with, BsdfCheckConfig};
use lumis_check::outcome::Outcome;
use lumis_core::Registry;
use lumis_tests::{build_lumis, build_plugin, plugin_quad_scene};

fn scene(library: &str, defect: &str, roughness: f32) -> String {
    let bsdf = format!(
        "[[bsdf]]\nname = \"subject\"\ntype = \"defective\"\ndefect = \"{defect}\"\nroughness = {roughness:?}"
    );
    plugin_quad_scene(library, &bsdf, 16, 16)
}

/// `lumis render` of the defective BSDF: (exit code, stderr, whether the
/// image was written).
fn render(defect: &str, roughness: f32, strict: bool) -> (Option<i32>, String, bool) {
    let library = build_plugin("defective-plugin", "defective_plugin");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene(library.to_str().unwrap(), defect, roughness)).unwrap();
    let output = dir.path().join("out.exr");
    let mut command = Command::new(build_lumis());
    command
        .args(["render", "-q", "-o"])
        .arg(&output)
        .arg(&path)
        .env_remove("LUMIS_PLUGIN_PATH");
    if strict {
        command.arg("--strict");
    }
    let out = command.output().expect("lumis runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        output.exists(),
    )
}

#[test]
fn a_render_names_the_plugin_and_its_defect() {
    for (defect, words) in [
        ("nan", "answers with NaN or infinite values"),
        ("negative", "answers with negative values"),
        ("energy", "its reflection samples return 1.05"),
    ] {
        let (code, stderr, written) = render(defect, 0.65, false);
        assert_eq!(code, Some(0), "{defect}: {stderr}");
        assert!(written, "{defect}");
        let warning = stderr
            .lines()
            .find(|l| l.starts_with("warning: ") && l.contains("type = \"defective\""))
            .unwrap_or_else(|| panic!("{defect}: no warning naming the plugin in {stderr}"));
        assert!(warning.contains(words), "{defect}: {warning}");
        assert!(warning.contains("defective_plugin"), "{defect}: {warning}");

        let (code, stderr, written) = render(defect, 0.65, true);
        assert_eq!(code, Some(1), "{defect} --strict: {stderr}");
        assert!(written, "{defect} --strict writes the image first");
        assert!(stderr.contains("--strict: 1 loaded plugin(s)"), "{stderr}");
    }
    // Outside the band the same plugin is sound: no warning, even strict.
    let (code, stderr, _) = render("energy", 0.9, true);
    assert_eq!(code, Some(0), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
}

/// The energy defect lives in a tenth of `roughness`'s range: the sweep
/// meets it there, and only there. (The sweep's earlier two seeded values
/// inside the range, 0.448 and 0.594 for this plugin, missed it.)
#[test]
fn the_sweep_finds_a_defect_in_a_tenth_of_a_range() {
    let mut registry = Registry::new();
    defective_plugin::register(&mut registry).unwrap();
    let mut cfg = BsdfCheckConfig::default();
    cfg.chi_square.samples = 100_000;
    cfg.chi_square.z_bins = 32;
    cfg.chi_square.phi_bins = 32;
    cfg.samples = 20_000;
    let fixed = [("defect".to_string(), "\"energy\"".to_string())];
    let results = check_bsdf_with(&registry, "defective", &fixed, &cfg).unwrap();
    let failed: Vec<&str> = results
        .iter()
        .filter(|r| !r.passed())
        .map(|r| r.variant.as_str())
        .collect();
    let labels: Vec<_> = results
        .iter()
        .map(|r| (r.variant.clone(), r.albedo, r.passed()))
        .collect();
    assert!(!failed.is_empty(), "the defect was not found: {labels:?}");
    for variant in &failed {
        let roughness: f32 = variant
            .strip_prefix("roughness = ")
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("a failure outside the roughness sweep: {variant}"));
        assert!(defective_plugin::BAND.contains(&roughness), "{variant}");
    }
}
