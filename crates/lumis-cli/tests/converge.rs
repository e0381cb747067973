//! `lumis converge` end to end on a tiny scene: every output, and the
//! convergence rate Monte Carlo theory predicts.

use std::path::{Path, PathBuf};

use lumis_cli::{builtin_registry, converge, render_scene_file, ConvergeArgs, RenderArgs};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lumis-converge-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml")
}

const TINY: &str = "film.resolution=[16, 16]";

/// relMSE of independent sampling falls as 1/spp: the fitted log-log slope
/// over 1..64 spp is within 0.1 of -1 (the reference's own error, at 8192
/// spp, is under 1% of the 64-spp error).
#[test]
fn two_variants_produce_every_output_and_the_independent_slope_is_minus_one() {
    let dir = scratch("slope");
    let registry = builtin_registry().unwrap();
    let reference = dir.join("reference.exr");
    render_scene_file(
        &RenderArgs {
            scene: scene(),
            spp: Some(8192),
            seed: Some(1000),
            output: Some(reference.clone()),
            set: vec![TINY.into()],
            quiet: true,
            ..Default::default()
        },
        &registry,
    )
    .unwrap();
    let variants = dir.join("variants.toml");
    std::fs::write(
        &variants,
        "[[variant]]\nname = \"independent\"\nset = [\"sampler.type=independent\"]\n\n\
         [[variant]]\nname = \"stratified\"\nset = [\"sampler.type=stratified\"]\n",
    )
    .unwrap();
    let out = dir.join("out");
    let args = ConvergeArgs {
        scene: scene(),
        reference,
        variants,
        spp: vec![1, 2, 4, 8, 16, 32, 64],
        seeds: 16,
        time_budget: None,
        set: vec![TINY.into()],
        threads: 0,
        out: out.clone(),
    };
    let report = converge(&args, &registry).unwrap();
    for file in [
        "converge.csv",
        "converge.json",
        "relmse-vs-spp.png",
        "relmse-vs-seconds.png",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
    assert_eq!(report.runs.len(), 2 * 7 * 16);
    let csv = std::fs::read_to_string(out.join("converge.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 7 * 16);
    let slope = report
        .slopes
        .iter()
        .find(|s| s.0 == "independent")
        .unwrap()
        .1
        .unwrap();
    assert!(
        (slope + 1.0).abs() < 0.1,
        "independent slope {slope}\n{}",
        report.table
    );
    assert!(report.table.contains("stratified"));
}

#[test]
fn bad_variants_and_mismatched_reference_are_clear_errors() {
    let dir = scratch("errors");
    let registry = builtin_registry().unwrap();
    let variants = dir.join("variants.toml");
    std::fs::write(
        &variants,
        "[[variant]]\nname = \"a\"\nset = [\"sampler.type\"]\n",
    )
    .unwrap();
    let reference = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes/reference/cornell-box-mitsuba.exr");
    let mut args = ConvergeArgs {
        scene: scene(),
        reference,
        variants: variants.clone(),
        spp: vec![1],
        seeds: 1,
        time_budget: None,
        set: vec![TINY.into()],
        threads: 0,
        out: dir.join("out"),
    };
    let e = converge(&args, &registry).err().unwrap().to_string();
    assert!(
        e.contains("variants.toml:3") && e.contains("key.path=value"),
        "{e}"
    );
    std::fs::write(&variants, "[[variant]]\nname = \"a\"\nset = []\n").unwrap();
    let e = converge(&args, &registry).err().unwrap().to_string();
    assert!(e.contains("differ in size: 16x16 vs 256x256"), "{e}");
    args.seeds = 0;
    assert!(converge(&args, &registry).is_err());
}
