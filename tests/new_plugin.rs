//! `lumis new-plugin`: the crate it writes for each kind builds outside
//! the workspace against this lumis and loads, and the BSDF passes
//! `lumis check-plugin`; in the ignored tier every kind passes its own
//! tests.
//!
//! The generated crates share one target directory under Cargo's scratch
//! directory for tests, so their dependencies compile once, and start from
//! the workspace's `Cargo.lock`, so they resolve the versions lumis is
//! tested with.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use lumis_tests::{assert_same_mean, bonferroni_z, build_lumis, cargo, render_toml_with};

/// Runs `command`, panicking with its output unless it succeeds.
fn succeed(command: &mut Command, what: &str) -> Output {
    let out = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    assert!(
        out.status.success(),
        "{what}: {}\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `lumis new-plugin my-KIND --kind KIND` in `parent`, with the
/// workspace's lock file; returns the crate's directory.
fn new_plugin(lumis: &Path, kind: &str, parent: &Path) -> PathBuf {
    let name = format!("my-{kind}");
    succeed(
        Command::new(lumis)
            .args(["new-plugin", &name, "--kind", kind])
            .current_dir(parent),
        &format!("lumis new-plugin {name}"),
    );
    let dir = parent.join(&name);
    let lock = Path::new(env!("CARGO_MANIFEST_DIR")).join("../Cargo.lock");
    std::fs::copy(lock, dir.join("Cargo.lock")).unwrap();
    dir
}

/// Runs `cargo ARGS` in the generated crate `dir`, in the shared target
/// directory.
fn cargo_in(dir: &Path, args: &[&str]) -> Output {
    let target = Path::new(env!("CARGO_TARGET_TMPDIR")).join("new-plugin");
    succeed(
        Command::new(cargo())
            .args(args)
            .env("CARGO_TARGET_DIR", target)
            // Without debug information: a third of the size and link time.
            .env("CARGO_PROFILE_DEV_DEBUG", "false")
            .env("CARGO_PROFILE_TEST_DEBUG", "false")
            .current_dir(dir),
        &format!("cargo {} in {}", args.join(" "), dir.display()),
    )
}

/// `cargo build` of the generated crate `dir`; returns its library.
fn build(dir: &Path) -> PathBuf {
    let lib = dir.file_name().unwrap().to_str().unwrap().replace('-', "_");
    let suffix = format!(
        "/{}{lib}.{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_EXTENSION
    );
    let out = cargo_in(dir, &["build", "--message-format=json"]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    stdout
        .split('"')
        .find(|s| s.ends_with(&suffix) && Path::new(s).is_file())
        .map(PathBuf::from)
        .unwrap_or_else(|| panic!("cargo reported no {suffix}:\n{stdout}"))
}

/// `lumis ARGS` with no plugin search path; returns its standard output.
fn lumis_run(lumis: &Path, args: &[&str]) -> String {
    let out = succeed(
        Command::new(lumis)
            .args(args)
            .env_remove("LUMIS_PLUGIN_PATH"),
        &format!("lumis {}", args.join(" ")),
    );
    String::from_utf8(out.stdout).unwrap()
}

/// `lumis plugins --load LIB` lists the generated plugin as loaded from it.
fn assert_loads(lumis: &Path, kind: &str, library: &Path) {
    let lib = library.to_str().unwrap();
    let listing = lumis_run(lumis, &["plugins", "--load", lib]);
    let line = format!("type = \"my-{kind}\"  ({lib})");
    assert!(listing.contains(&line), "no '{line}' in:\n{listing}");
}

const KINDS: [&str; 5] = ["bsdf", "light", "sampler", "light-sampler", "integrator"];

#[test]
fn every_new_plugin_builds_and_loads_and_passes_check_plugin() {
    let lumis = build_lumis();
    let parent = tempfile::tempdir().unwrap();
    for kind in KINDS {
        let dir = new_plugin(&lumis, kind, parent.path());
        let library = build(&dir);
        assert_loads(&lumis, kind, &library);
        let out = parent.path().join(format!("check-{kind}"));
        std::fs::create_dir(&out).unwrap();
        let report = lumis_run(
            &lumis,
            &[
                "check-plugin",
                library.to_str().unwrap(),
                "--samples",
                "20000",
                "--out",
                out.to_str().unwrap(),
            ],
        );
        assert!(report.contains(" passed, 0 failed"), "{kind}: {report}");
    }
}

/// A scene lit by the Cornell box's light, with integrator `integrator`.
fn scene(integrator: &str, seed: u32) -> String {
    format!(
        r#"seed = {seed}
[film]
resolution = [24, 24]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.9]
target = [0.0, 0.0, 2.9]
fov = 39.3077
[sampler]
type = "independent"
spp = 1024
[integrator]
type = "{integrator}"
max_depth = 4
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.8
[[shape]]
type = "obj"
file = "cornell-box/back.obj"
bsdf = "white"
[[shape]]
type = "obj"
file = "cornell-box/floor.obj"
bsdf = "white"
[[shape]]
type = "obj"
file = "cornell-box/light.obj"
bsdf = "white"
emission = {{ radiance = [18.387, 13.9873, 6.75357] }}
"#
    )
}

/// The generated integrator (BSDF sampling only) renders, block by block,
/// the mean of the built-in `path` (light and BSDF sampling, MIS).
#[test]
fn a_new_integrator_renders_the_mean_of_path() {
    let lumis = build_lumis();
    let parent = tempfile::tempdir().unwrap();
    let library = build(&new_plugin(&lumis, "integrator", parent.path()));
    let mut registry = lumis_app::builtin_registry().unwrap();
    lumis_loader::load_library(&library, &mut registry).unwrap();
    let generated = render_toml_with(&registry, &scene("my-integrator", 1), &[], 0).image;
    let path = render_toml_with(&registry, &scene("path", 2), &[], 0).image;
    assert!(
        generated.mean()[0] > 0.01,
        "the generated integrator's render is black"
    );
    // One block, the whole image: BSDF sampling finds the small light
    // rarely, and only the mean over every pixel resolves a few percent
    // (a throughput 10% low at each bounce is 5 standard errors off).
    let z = bonferroni_z(1e-3, 3);
    assert_same_mean(&generated, &path, 24, z, "generated integrator vs path");
}

/// Every kind's own `cargo test`: the check kit's tests of the example, in
/// the optimised test profile the generated crate asks for.
#[test]
#[ignore = "compiles the check kit and its dependencies optimised: about 2 minutes"]
fn every_new_plugin_passes_its_own_tests() {
    let lumis = build_lumis();
    let parent = tempfile::tempdir().unwrap();
    for kind in KINDS {
        let dir = new_plugin(&lumis, kind, parent.path());
        cargo_in(&dir, &["test"]);
    }
}
