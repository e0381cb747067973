//! `lumis converge` end to end on a tiny scene: every output, and the
//! convergence rate Monte Carlo theory predicts.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use lumis_app::{builtin_registry, render, render_reference, ReferenceArgs, RenderArgs, Session};
use lumis_studies::{converge, ConvergeArgs};

/// A fresh directory for one test's files, removed when the test ends.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("lumis-converge-{name}-"))
        .tempdir()
        .unwrap()
}

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box.toml")
}

/// Renders `scene` with `set` at `spp` from seed 1000 (apart from the
/// variants' seeds) to `out`, the reference the variants are measured
/// against.
fn reference_render(
    registry: &lumis_core::Registry,
    scene: &Path,
    set: &str,
    spp: u32,
    out: &Path,
) {
    render(
        &RenderArgs {
            scene: scene.to_path_buf(),
            spp: Some(spp),
            seed: Some(1000),
            output: Some(out.to_path_buf()),
            set: vec![set.into()],
            quiet: true,
            ..Default::default()
        },
        &Session::silent(registry, &AtomicBool::new(false)),
    )
    .unwrap();
}

const TINY: &str = "film.resolution=[16, 16]";

/// relMSE of independent sampling falls as 1/spp: the fitted log-log slope
/// over 1..64 spp is within 0.1 of -1 (the reference's own error, at 8192
/// spp, is under 1% of the 64-spp error).
#[test]
fn two_variants_produce_every_output_and_the_independent_slope_is_minus_one() {
    let tmp = scratch("slope");
    let dir = tmp.path();
    let registry = builtin_registry().unwrap();
    let reference = dir.join("reference.exr");
    reference_render(&registry, &scene(), TINY, 8192, &reference);
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
        first_seed: 0,
        time_budget: None,
        set: vec![TINY.into()],
        threads: 0,
        out: out.clone(),
    };
    let report = converge(&args, &registry, &AtomicBool::new(false)).unwrap();
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

/// A raw and a denoised variant over two seeds: the split is in every
/// output, and per (variant, spp) bias² + variance is the mean relMSE of
/// its renders (the identity the split rests on).
#[test]
fn a_denoised_variant_is_measured_and_the_error_is_split() {
    let tmp = scratch("split");
    let dir = tmp.path();
    let registry = builtin_registry().unwrap();
    let reference = dir.join("reference.exr");
    reference_render(&registry, &scene(), TINY, 256, &reference);
    let variants = dir.join("variants.toml");
    std::fs::write(
        &variants,
        "[[variant]]\nname = \"raw\"\n\n\
         [[variant]]\nname = \"denoised\"\nset = [\"denoiser.type=oidn\"]\nimage = \"denoised\"\n",
    )
    .unwrap();
    let out = dir.join("out");
    let mut args = ConvergeArgs {
        scene: scene(),
        reference,
        variants,
        spp: vec![1, 4],
        seeds: 3,
        first_seed: 0,
        time_budget: None,
        set: vec![TINY.into()],
        threads: 0,
        out: out.clone(),
    };
    let report = converge(&args, &registry, &AtomicBool::new(false)).unwrap();
    assert_eq!(report.points.len(), 4);
    for point in &report.points {
        let split = point.split.expect("3 seeds split the error");
        let total = split.rel_mse.bias2 + split.rel_mse.variance;
        assert!(
            (total - point.rel_mse).abs() < 1e-4 * point.rel_mse,
            "{} @ {}: {total} vs {}",
            point.variant,
            point.spp,
            point.rel_mse
        );
    }
    let rel = |name: &str| {
        report
            .points
            .iter()
            .find(|p| p.variant == name && p.spp == 1)
            .unwrap()
            .rel_mse
    };
    assert_ne!(
        rel("raw"),
        rel("denoised"),
        "the denoised image was measured"
    );
    let csv = std::fs::read_to_string(out.join("converge.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.ends_with(",bias2,variance,rel_bias2,rel_variance"),
        "{header}"
    );
    assert_eq!(csv.lines().count(), 1 + 2 * 2 * 3);
    assert!(csv.lines().skip(1).all(|l| !l.ends_with(",,,")), "{csv}");
    let json = std::fs::read_to_string(out.join("converge.json")).unwrap();
    assert_eq!(json.matches("\"rel_mse_split\"").count(), 4, "{json}");
    assert!(report.table.contains("bias²") && report.table.contains("denoised"));
    assert!(out.join("renders/1-denoised.denoised.exr").is_file());
    assert!(!report.table.contains("overlap"), "{}", report.table);
    // The reference was rendered from seed 1000: measuring that seed again
    // is warned about.
    args.first_seed = 1000;
    args.spp = vec![1];
    let report = converge(&args, &registry, &AtomicBool::new(false)).unwrap();
    assert!(
        report.table.contains("overlap the seeds measured"),
        "{}",
        report.table
    );
}

#[test]
fn bad_variants_and_mismatched_reference_are_clear_errors() {
    let tmp = scratch("errors");
    let dir = tmp.path();
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
        first_seed: 0,
        time_budget: None,
        set: vec![TINY.into()],
        threads: 0,
        out: dir.join("out"),
    };
    let e = converge(&args, &registry, &AtomicBool::new(false))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("variants.toml:3") && e.contains("key.path=value"),
        "{e}"
    );
    std::fs::write(
        &variants,
        "[[variant]]\nname = \"a\"\nimage = \"blurred\"\n",
    )
    .unwrap();
    let e = converge(&args, &registry, &AtomicBool::new(false))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("image must be \"raw\" or \"denoised\""), "{e}");
    std::fs::write(
        &variants,
        "[[variant]]\nname = \"a\"\nimage = \"denoised\"\n",
    )
    .unwrap();
    let e = converge(&args, &registry, &AtomicBool::new(false))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("needs a [denoiser]"), "{e}");
    std::fs::write(&variants, "[[variant]]\nname = \"a\"\nset = []\n").unwrap();
    let e = converge(&args, &registry, &AtomicBool::new(false))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("differ in size: 16x16 vs 256x256"), "{e}");
    let e = converge(&args, &registry, &AtomicBool::new(true))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("interrupted before the first"), "{e}");
    args.seeds = 0;
    assert!(converge(&args, &registry, &AtomicBool::new(false)).is_err());
}

/// A reference rendered in two runs (interrupted at 64 spp, then resumed to
/// 128) is bit-identical to one rendered in a single run: passes keep their
/// seeds. A changed scene is refused, and with `--force` starts over
/// instead of mixing images.
#[test]
fn reference_resumes_to_the_same_image_and_restarts_when_the_scene_changes() {
    let tmp = scratch("reference");
    let dir = tmp.path();
    let registry = builtin_registry().unwrap();
    let stop = AtomicBool::new(false);
    let args = |spp: u32, output: &str, extra: &[&str]| ReferenceArgs {
        scene: scene(),
        spp,
        pass_spp: 32,
        output: Some(dir.join(output)),
        set: [TINY]
            .iter()
            .chain(extra.iter().filter(|s| **s != "--force"))
            .map(|s| s.to_string())
            .collect(),
        threads: 0,
        force: extra.contains(&"--force"),
    };
    let (path, meta) = render_reference(
        &args(64, "resumed.exr", &[]),
        &Session::silent(&registry, &stop),
    )
    .unwrap();
    assert_eq!((meta.spp, meta.passes), (64, 2));
    let (_, meta) = render_reference(
        &args(128, "resumed.exr", &[]),
        &Session::silent(&registry, &stop),
    )
    .unwrap();
    assert_eq!((meta.spp, meta.passes), (128, 4));
    let (whole, _) = render_reference(
        &args(128, "whole.exr", &[]),
        &Session::silent(&registry, &stop),
    )
    .unwrap();
    let read = |p: &Path| lumis_image::read_exr(p).unwrap();
    assert_eq!(read(&path), read(&whole));
    let changed = ["integrator.max_depth=2"];
    let refused = render_reference(
        &args(128, "resumed.exr", &changed),
        &Session::silent(&registry, &stop),
    )
    .err()
    .unwrap()
    .to_string();
    assert!(refused.contains("different scene"), "{refused}");
    let forced = ["integrator.max_depth=2", "--force"];
    let (_, meta) = render_reference(
        &args(128, "resumed.exr", &forced),
        &Session::silent(&registry, &stop),
    )
    .unwrap();
    assert_eq!((meta.spp, meta.passes), (128, 4), "restarted from zero");
    assert_ne!(read(&path), read(&whole));
}

/// The committed bias-study variants (raw, adaptive, denoised, denoised +
/// adaptive, clamped) run on their bench scenes, shrunk to 8x8, and each
/// gets its error split.
#[test]
fn the_bias_study_variants_run_on_their_scenes() {
    let tmp = scratch("bias-study");
    let dir = tmp.path();
    let registry = builtin_registry().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let small = "film.resolution=[8, 8]";
    for name in ["cornell-box", "glossy-beckmann", "textured-gltf"] {
        let scene = root.join(format!("scenes/bench/{name}.toml"));
        let reference = dir.join(format!("{name}-reference.exr"));
        reference_render(&registry, &scene, small, 64, &reference);
        let args = ConvergeArgs {
            scene,
            reference,
            variants: root.join(format!("scenes/variants/bias/{name}.toml")),
            spp: vec![16],
            seeds: 2,
            first_seed: 0,
            time_budget: None,
            set: vec![small.into()],
            threads: 0,
            out: dir.join(name),
        };
        let report = converge(&args, &registry, &AtomicBool::new(false))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let names: Vec<&str> = report.points.iter().map(|p| p.variant.as_str()).collect();
        assert_eq!(
            names,
            [
                "raw",
                "adaptive",
                "denoised",
                "denoised+adaptive",
                "clamped"
            ],
            "{name}"
        );
        assert!(report.points.iter().all(|p| p.split.is_some()), "{name}");
    }
}
