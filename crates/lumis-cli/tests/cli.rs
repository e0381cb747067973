//! The `lumis` binary as a user runs it.

mod common;

use std::path::Path;
use std::process::Command;

use common::*;

/// The start-up report counts what the scene's textures and environment
/// map hold (each plugin's `memory_bytes`), at least the map's texels.
#[test]
fn the_start_up_report_counts_images() {
    let sky = lumis_image::read_exr(Path::new(&scene("bench/sky.exr"))).unwrap();
    let texel_bytes = (sky.width * sky.height * 12) as f64;
    let tmp = scratch("memory-report");
    let out = path_in(tmp.path(), "sky.exr");
    let run = lumis(&[
        "render",
        &scene("bench/envmap-sky.toml"),
        "--spp",
        "1",
        "--set",
        "film.resolution=[8, 8]",
        "-o",
        &out,
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    let megabytes: f64 = stderr
        .split(" MB textures and environment maps")
        .next()
        .and_then(|before| before.rsplit("+ ").next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no texture memory in:\n{stderr}"));
    assert!(
        megabytes * 1e6 >= texel_bytes * 0.99,
        "{megabytes} MB for {texel_bytes} bytes of texels"
    );
    assert!(stderr.contains("memory: "), "{stderr}");
}

/// `--parts` checkpoints and resumes like any render: it takes
/// `--checkpoint` and `--resume` alike.
#[test]
fn parts_take_checkpoint_and_resume_alike() {
    let tmp = scratch("parts-resume");
    let out = path_in(tmp.path(), "plates.exr");
    let mut args = small_render(&out, "4");
    args.extend(["--parts", "2", "--checkpoint", "--resume"]);
    let result = lumis(&args);
    assert!(result.status.success(), "{result:?}");
    assert_eq!(header(&tmp.path().join("plates.exr"), "spp"), "4");
}

/// A number the scene could not take is refused where it is parsed,
/// naming the flag: a seed past 2^63 - 1 (a scene's integers are signed),
/// zero parts.
#[test]
fn flags_out_of_range_are_refused_by_the_parser() {
    for (flag, value) in [("--seed", "9223372036854775808"), ("--parts", "0")] {
        let run = lumis(&["render", &scene("cornell-box.toml"), flag, value, "-q"]);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{flag} {value}: {stderr}");
        assert!(
            stderr.contains(&format!("invalid value '{value}' for '{flag}")),
            "{stderr}"
        );
    }
}

#[test]
fn help_documents_every_flag() {
    let top = String::from_utf8(lumis(&["--help"]).stdout).unwrap();
    assert!(top.contains("render"), "{top}");
    let help = String::from_utf8(lumis(&["render", "--help"]).stdout).unwrap();
    for flag in [
        "--spp",
        "--seed",
        "--threads",
        "--output",
        "--set",
        "--quiet",
        "--verbose",
        "--stats",
        "--checkpoint",
        "--no-checkpoint",
        "--resume",
        "--pass-spp",
        "--force",
        "--max-memory",
    ] {
        assert!(help.contains(flag), "render --help lacks {flag}:\n{help}");
    }
}

#[test]
fn renders_exr_and_png_with_a_summary() {
    let tmp = scratch("render");
    let dir = tmp.path();
    let out = dir.join("box.exr");
    let result = lumis(&[
        "render",
        &scene("cornell-box.toml"),
        "--spp",
        "2",
        "--threads",
        "2",
        "--set",
        "film.resolution=[32, 32]",
        "--output",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    let stdout = String::from_utf8(result.stdout).unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    for part in ["32x32", "2 spp", "Msamples/s", "Mrays/s", "0 NaN/Inf"] {
        assert!(stdout.contains(part), "summary lacks '{part}': {stdout}");
    }
    let image = lumis_image::read_exr(&out).unwrap();
    assert_eq!((image.width, image.height), (32, 32));
    assert!(image.mean()[0] > 0.0);
    assert!(dir.join("box.png").exists());
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        2,
        "no temporary files left"
    );
}

/// `--stats` reports the stages of the render, largest first, with shares
/// that add up to the whole; the image is the one a plain render makes.
#[test]
fn stats_report_where_the_time_went() {
    let tmp = scratch("stats");
    let render = |name: &str, stats: bool| {
        let out = tmp.path().join(name);
        let mut args = vec![
            "render",
            "-q",
            "--spp",
            "64",
            "--threads",
            "2",
            "--set",
            "film.resolution=[128, 128]",
            "-o",
            out.to_str().unwrap(),
        ];
        // Long enough (about a second) for every stage to be sampled.
        let scene = scene("glossy-plates.toml");
        args.insert(1, &scene);
        if stats {
            args.push("--stats");
        }
        let result = lumis(&args);
        assert!(result.status.success(), "{result:?}");
        (
            String::from_utf8(result.stdout).unwrap(),
            // The pixels: the header holds the render time.
            lumis_image::read_exr(&out.with_extension("exr")).unwrap(),
        )
    };
    let (profiled, profiled_image) = render("profiled.exr", true);
    let (plain, plain_image) = render("plain.exr", false);
    assert!(!plain.contains("time by stage"), "{plain}");
    assert_eq!(profiled_image, plain_image, "--stats changed the image");
    let rows: Vec<(&str, f64)> = profiled
        .lines()
        .skip_while(|l| !l.starts_with("time by stage"))
        .skip(1)
        .map(|l| {
            let percent = l.split_whitespace().rev().nth(2).unwrap();
            (l, percent.trim_end_matches('%').parse().unwrap())
        })
        .collect();
    assert!(rows.len() >= 4, "{profiled}");
    let total: f64 = rows.iter().map(|r| r.1).sum();
    assert!(
        (total - 100.0).abs() < 0.5,
        "shares add to {total}:\n{profiled}"
    );
    assert!(rows.windows(2).all(|w| w[0].1 >= w[1].1), "{profiled}");
    for stage in ["traversal", "BSDF", "light sampling", "shadow rays"] {
        assert!(
            rows.iter().any(|r| r.0.contains(stage)),
            "no {stage} row:\n{profiled}"
        );
    }
}

#[test]
fn a_scene_without_lights_renders_with_a_warning() {
    let tmp = scratch("dark");
    let dir = tmp.path();
    let dark = dir.join("dark.toml");
    std::fs::write(
        &dark,
        "[film]\nresolution = [8, 8]\n[camera]\ntype = \"perspective\"\norigin = [0.0, 0.0, 3.0]\n\
         target = [0.0, 0.0, 0.0]\nfov = 40.0\n[sampler]\ntype = \"independent\"\nspp = 1\n\
         [integrator]\ntype = \"path\"\n[[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\n\
         reflectance = 0.5\n[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n\
         bsdf = \"white\"\n",
    )
    .unwrap();
    let out = dir.join("dark.exr");
    let result = lumis(&[
        "render",
        dark.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert!(result.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: the scene has no lights"),
        "{stderr}"
    );
    assert_eq!(lumis_image::read_exr(&out).unwrap().mean(), [0.0; 3]);
    // A lit scene gets no such warning.
    let lit = lumis(&[
        "render",
        &scene("cornell-box.toml"),
        "--spp",
        "1",
        "--set",
        "film.resolution=[8, 8]",
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8(lit.stderr).unwrap();
    assert!(
        lit.status.success() && !stderr.contains("no lights"),
        "{stderr}"
    );
}

#[test]
fn failed_render_leaves_no_image() {
    let tmp = scratch("fail");
    let dir = tmp.path();
    let out = dir.join("missing-dir/box.exr");
    let result = lumis(&[
        "render",
        &scene("cornell-box.toml"),
        "--spp",
        "1",
        "--set",
        "film.resolution=[8, 8]",
        "-o",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(!result.status.success());
    let stderr = String::from_utf8(result.stderr).unwrap();
    assert!(
        stderr.starts_with("error:") && stderr.contains("missing-dir"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), 0);
}

/// `lumis render` of the Cornell box with one `--set`, which must fail:
/// its stderr.
fn render_error(set: &str) -> String {
    let result = lumis(&["render", &scene("cornell-box.toml"), "--set", set, "-q"]);
    assert!(!result.status.success(), "--set {set} rendered");
    String::from_utf8(result.stderr).unwrap()
}

#[test]
fn scene_errors_exit_nonzero_with_the_location() {
    let stderr = render_error("integrator.max_dpeth=3");
    assert!(
        stderr.contains("--set integrator.max_dpeth=3")
            && stderr.contains("unknown key 'max_dpeth'"),
        "{stderr}"
    );
    // A colour is said as a scene writes it, not as Rust prints it.
    let stderr = render_error("bsdf.red.reflectance=[2, 0.5, 0]");
    assert!(
        stderr.contains("got [2, 0.5, 0]") && !stderr.contains("Rgb {"),
        "{stderr}"
    );
    // A film beyond any memory is an error before rendering, not an abort:
    // the memory estimate refuses it, or, where the system does not say
    // what it has, the allocation (whose byte count exceeds what one may
    // ask for, whatever the machine's memory or overcommit policy).
    let stderr = render_error("film.resolution=[4000000000, 4000000000]");
    assert!(
        stderr.starts_with("error: film resolution 4000000000x4000000000")
            && stderr.contains(" GB"),
        "{stderr}"
    );
}

#[test]
fn check_plugin_checks_a_builtin_bsdf_and_reports_a_table() {
    let result = lumis(&[
        "check-plugin",
        "--bsdf",
        "diffuse",
        "--samples",
        "20000",
        "--bins",
        "20",
    ]);
    let stdout = String::from_utf8(result.stdout).unwrap();
    assert!(
        result.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert!(
        stdout.contains("p-value") && stdout.contains("passed, 0 failed"),
        "{stdout}"
    );
    let missing = lumis(&["check-plugin", "--bsdf", "no-such-bsdf"]);
    assert!(!missing.status.success());
    assert!(
        String::from_utf8_lossy(&missing.stderr).contains("no bsdf plugin named \"no-such-bsdf\"")
    );
}

/// Delta lights are not testable, and say so, without failing the run.
#[test]
fn check_plugin_checks_builtin_lights_and_light_samplers() {
    let result = lumis(&[
        "check-plugin",
        "--light",
        "spot",
        "--light-sampler",
        "uniform",
    ]);
    let stdout = String::from_utf8(result.stdout).unwrap();
    assert!(
        result.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert!(
        stdout.contains("not testable: delta light") && !stdout.contains("FAILED"),
        "{stdout}"
    );
    assert!(stdout.contains("8 passed, 0 failed"), "{stdout}");
    let missing = lumis(&["check-plugin", "--light", "no-such-light"]);
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stderr)
        .contains("no light plugin named \"no-such-light\""));
}

/// Every built-in sampler passes, the deterministic settings (strata
/// centres, unscrambled sequences) reported as not testable for uniformity.
#[test]
fn check_plugin_checks_builtin_samplers() {
    let mut args = vec!["check-plugin"];
    for name in [
        "independent",
        "stratified",
        "halton",
        "hammersley",
        "sobol",
        "zsobol",
        "poisson-disk",
    ] {
        args.extend(["--sampler", name]);
    }
    let result = lumis(&args);
    let stdout = String::from_utf8(result.stdout).unwrap();
    assert!(
        result.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert!(
        stdout.contains("not testable: uniformity") && !stdout.contains("FAILED"),
        "{stdout}"
    );
}

#[test]
fn samplers_analyze_writes_pictures_points_and_a_convergence_table() {
    let tmp = scratch("analyze");
    let dir = tmp.path();
    let out = dir.join("out");
    let dump = dir.join("points.csv");
    let run = lumis(&[
        "samplers",
        "analyze",
        "--sampler",
        "sobol",
        "--count",
        "64",
        "--dims",
        "5",
        "--realizations",
        "2",
        "--spectrum-size",
        "16",
        "--max-count",
        "64",
        "--seeds",
        "8",
        "--out",
        out.to_str().unwrap(),
        "--dump",
        dump.to_str().unwrap(),
    ]);
    let stdout = stdout_of_success(&run);
    for file in [
        "sobol-points.png",
        "sobol-points-d2-d3.png",
        "sobol-psd.png",
        "sobol-radial-psd.png",
        "convergence.csv",
        "convergence-gaussian.png",
        "convergence-step-1d.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    // 64 rows of 5 columns, every value in [0, 1).
    let csv = std::fs::read_to_string(&dump).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("d0,d1,d2,d3,d4"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 64);
    assert!(rows
        .iter()
        .all(|r| r.len() == 5 && r.iter().all(|v| (0.0..1.0).contains(v))));
    assert!(stdout.contains("L2-star discrepancy") && stdout.contains("simpson"));
}

#[test]
fn lecture_writes_its_figures_and_tables() {
    let tmp = scratch("lecture");
    let out = tmp.path().join("out");
    let run = lumis(&[
        "lecture",
        "--runs",
        "4",
        "--realizations",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = stdout_of_success(&run);
    for file in [
        "stratified-variance-gaussian.png",
        "stratified-variance-disk.png",
        "spectrum-stratified-points.png",
        "spectrum-poisson-disk-psd.png",
        "spectrum-independent-radial-psd.png",
        "spectrum-radial.png",
        "half-max.png",
        "scaled-mean-gaussian-1d.png",
        "scaled-mean-ratio.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    assert!(
        stdout.contains("Stratified sampling")
            && stdout.contains("Power spectra")
            && stdout.contains("N < 4.09")
            && stdout.contains("from N = 3 on by the formulas"),
        "{stdout}"
    );
    let run = lumis(&["lecture", "--runs", "1", "--out", out.to_str().unwrap()]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("--runs must be at least 2"));
}

#[test]
fn samplers_analyze_rejects_unknown_sampler_and_bad_parameters() {
    let tmp = scratch("analyze-errors");
    let dir = tmp.path();
    let run = lumis(&[
        "samplers",
        "analyze",
        "--sampler",
        "sobl",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("unknown sampler \"sobl\"") && stderr.contains("independent, poisson-disk"),
        "{stderr}"
    );
    let run = lumis(&[
        "samplers",
        "analyze",
        "--sampler",
        "sobol",
        "--set",
        "randomize=fancy",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("randomize") && stderr.contains("owen"),
        "{stderr}"
    );
}

fn write_exr(path: &Path, width: usize, height: usize, values: &[f32]) {
    let mut image = lumis_image::Image::new(width, height);
    for (p, v) in image.pixels.iter_mut().zip(values) {
        *p = [*v; 3];
    }
    lumis_image::write_exr(path, &image).unwrap();
}

#[test]
fn diff_prints_known_numbers_per_region_and_refuses_other_sizes() {
    let tmp = scratch("diff");
    let dir = tmp.path();
    let (a, b, c) = (dir.join("a.exr"), dir.join("b.exr"), dir.join("c.exr"));
    // Reference (1, 0), image (1.5, 0.1): MSE 0.13, relMSE (0.25/1.01 + 1)/2.
    write_exr(&a, 2, 1, &[1.5, 0.1]);
    write_exr(&b, 2, 1, &[1.0, 0.0]);
    write_exr(&c, 1, 2, &[1.0, 0.0]);
    let mask = dir.join("regions.toml");
    std::fs::write(
        &mask,
        "[[region]]\nname = \"left\"\nmin = [0, 0]\nmax = [1, 1]\n",
    )
    .unwrap();
    let picture = dir.join("err.png");
    let run = lumis(&[
        "diff",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--mask",
        mask.to_str().unwrap(),
        "--error-image",
        picture.to_str().unwrap(),
    ]);
    let stdout = stdout_of_success(&run);
    let image_row = stdout.lines().find(|l| l.starts_with("image")).unwrap();
    let numbers: Vec<f64> = image_row
        .split_whitespace()
        .skip(1)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((numbers[0] - 0.13).abs() < 1e-6, "{image_row}");
    assert!(
        (numbers[2] - (0.25 / 1.01 + 1.0) / 2.0).abs() < 1e-4,
        "{image_row}"
    );
    let left_row = stdout.lines().find(|l| l.starts_with("left")).unwrap();
    let left: Vec<f64> = left_row
        .split_whitespace()
        .skip(1)
        .map(|v| v.parse().unwrap())
        .collect();
    assert!((left[0] - 0.25).abs() < 1e-6, "{left_row}");
    assert!(picture.is_file());

    let run = lumis(&["diff", a.to_str().unwrap(), c.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(stderr.contains("differ in size: 2x1 vs 1x2"), "{stderr}");
}

/// A bare plugin library name is the file in the current directory, never
/// one on the system's library search path, and the loader's reason is
/// kept.
#[test]
fn plugin_library_names_resolve_in_the_current_directory() {
    let dir = scratch("bare-plugin");
    let in_dir = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_lumis"))
            .args(args)
            .current_dir(dir.path())
            .env_remove("LUMIS_PLUGIN_PATH")
            .output()
            .expect("lumis runs")
    };
    // libm is on the system's search path, not in this directory.
    let out = in_dir(&["plugins", "--load", "libm.so.6"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("'libm.so.6' does not exist"),
        "{stderr}"
    );
    std::fs::write(dir.path().join("fake.so"), "not a library").unwrap();
    let out = in_dir(&["plugins", "--load", "fake.so"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let local = std::fs::canonicalize(dir.path().join("fake.so")).unwrap();
    assert!(
        !out.status.success()
            && stderr.contains(&local.display().to_string())
            && stderr.contains("no ELF header"),
        "{stderr}"
    );
}

#[test]
fn version_names_the_plugin_interface_and_the_compiler() {
    let out = lumis(&["--version"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}");
    for part in [
        lumis_core::plugin::API_VERSION,
        &format!("plugin ABI {}", lumis_core::plugin::PLUGIN_ABI_VERSION),
        lumis_core::plugin::INTERFACE_FINGERPRINT,
        lumis_core::plugin::RUSTC_VERSION,
    ] {
        assert!(stdout.contains(part), "{part} missing from:\n{stdout}");
    }
}

/// An image against itself (zero error everywhere) still gets its error
/// picture, and the command ends.
#[test]
fn diff_of_an_image_with_itself_draws_its_error_picture() {
    let tmp = scratch("diff-self");
    let (image, picture) = (tmp.path().join("x.exr"), tmp.path().join("e.png"));
    write_exr(&image, 4, 2, &[0.5, 1.0, 0.0, 2.0, 0.25, 0.5, 1.0, 3.0]);
    let x = image.to_str().unwrap();
    let out = lumis(&["diff", x, x, "--error-image", picture.to_str().unwrap()]);
    assert!(
        out.status.success() && picture.exists(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The error picture is an output like a render's: a run holding its lock
/// keeps `diff` from writing it, and an input is never overwritten.
#[test]
fn diff_locks_its_error_picture_and_never_writes_an_input() {
    let tmp = scratch("diff-lock");
    let (image, picture) = (tmp.path().join("x.exr"), tmp.path().join("e.png"));
    write_exr(&image, 4, 2, &[0.5, 1.0, 0.0, 2.0, 0.25, 0.5, 1.0, 3.0]);
    let x = image.to_str().unwrap();
    let lock = lumis_image::OutputLock::acquire(&picture).unwrap();
    let out = lumis(&["diff", x, x, "--error-image", picture.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("another lumis"),
        "{stderr}"
    );
    assert!(!picture.exists());
    drop(lock);
    let out = lumis(&["diff", x, x, "--error-image", x]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("is one of the images compared"),
        "{stderr}"
    );
}

/// `-o NAME.png` writes NAME.exr and NAME.png, `-o DIR/` the scene's name
/// in DIR, and `--threads` past four per core is capped with a warning.
#[test]
fn output_names_and_thread_counts_do_what_users_expect() {
    let tmp = scratch("outputs");
    let dir = tmp.path();
    let render = |output: &Path, threads: &str| {
        lumis(&[
            "render",
            &scene("cornell-box.toml"),
            "--spp",
            "1",
            "--threads",
            threads,
            "--set",
            "film.resolution=[8, 8]",
            "--output",
            output.to_str().unwrap(),
            "--quiet",
        ])
    };
    let out = render(&dir.join("box.png"), "100000");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("--threads 100000 capped at"), "{stderr}");
    assert!(dir.join("box.exr").exists() && dir.join("box.png").exists());
    assert!(!dir.join("box.png.exr").exists());
    let sub = dir.join("renders");
    std::fs::create_dir(&sub).unwrap();
    let out = render(&sub, "1");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let names: Vec<String> = std::fs::read_dir(&sub)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.contains(&"cornell-box.exr".to_string())
            && names.contains(&"cornell-box.png".to_string()),
        "{names:?}"
    );
}
