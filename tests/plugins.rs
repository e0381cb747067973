//! A user's BSDF as a dynamic library: built as a cdylib the way a user
//! builds it, loaded through a scene's `[plugins]` table and through
//! `LUMIS_PLUGIN_PATH`, rendered, and compared with the same BSDF linked in.

use std::path::PathBuf;
use std::process::Command;

use lumis_check::bsdf_suite::{check_bsdf, format_results, BsdfCheckConfig};
use lumis_check::outcome::Outcome;
use lumis_tests::{
    assert_same_mean, bonferroni_z, build_lumis, build_plugin, plugin_quad_scene, render_toml_with,
    scenes_dir,
};

/// `cargo build -p example-bsdf`, returning the path of the cdylib it wrote.
fn build_example_plugin() -> PathBuf {
    build_plugin("example-bsdf", "example_bsdf")
}

fn scene(plugins: &str, seed: u32) -> String {
    format!(
        r#"seed = {seed}
{plugins}
[film]
resolution = [32, 32]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.9]
target = [0.0, 0.0, 2.9]
fov = 39.3077
[sampler]
type = "independent"
spp = 64
[integrator]
type = "path"
max_depth = 5
[[bsdf]]
name = "glossy"
type = "phong"
diffuse = 0.3
specular = 0.6
exponent = 20.0
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.8
[[shape]]
type = "obj"
file = "cornell-box/back.obj"
bsdf = "glossy"
[[shape]]
type = "obj"
file = "cornell-box/floor.obj"
bsdf = "glossy"
[[shape]]
type = "obj"
file = "cornell-box/light.obj"
bsdf = "white"
emission = {{ radiance = [18.387, 13.9873, 6.75357] }}
"#
    )
}

#[test]
fn dynamically_loaded_bsdf_renders_like_the_linked_one() {
    let library = build_example_plugin();
    let builtin = lumis_app::builtin_registry().unwrap();

    // Without the plugin, the type is unknown.
    let err = lumis_scene::load_str(
        &scene("", 1),
        &scenes_dir().join("plugin.toml"),
        &[],
        &builtin,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(err.contains("unknown bsdf type \"phong\""), "{err}");

    let plugins = format!("[plugins]\nload = [\"{}\"]\n", library.display());
    let dynamic = render_toml_with(&builtin, &scene(&plugins, 1), &[], 0).image;
    assert!(dynamic.mean()[0] > 0.01, "the plugin's render is black");

    let mut linked = lumis_app::builtin_registry().unwrap();
    example_bsdf::register(&mut linked).unwrap();
    let reference = render_toml_with(&linked, &scene("", 2), &[], 0).image;
    let z = bonferroni_z(1e-3, 4 * 4 * 3);
    assert_same_mean(&dynamic, &reference, 8, z, "dynamic vs linked phong");

    // The loaded BSDF passes the same statistical checks as the built-in ones.
    let mut loaded = lumis_app::builtin_registry().unwrap();
    lumis_loader::load_library(&library, &mut loaded).unwrap();
    let results = check_bsdf(&loaded, "phong", &BsdfCheckConfig::default()).unwrap();
    assert!(
        results.iter().all(|r| r.passed()),
        "{}",
        format_results(&results)
    );

    // Loading it on top of the linked copy clashes, naming both sources.
    let err = lumis_scene::load_str(
        &scene(&plugins, 1),
        &scenes_dir().join("plugin.toml"),
        &[],
        &linked,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        err.contains("clashes")
            && err.contains("built-in")
            && err.contains(&library.display().to_string()),
        "{err}"
    );
}

#[test]
fn plugin_search_path_is_loaded_at_start_up() {
    let library = build_example_plugin();
    let dir = std::env::temp_dir().join(format!("lumis-plugin-path-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(&library, dir.join(library.file_name().unwrap())).unwrap();
    std::env::set_var(lumis_loader::PLUGIN_PATH_VAR, &dir);
    let registry = lumis_app::registry_with_search_path().unwrap();
    std::env::remove_var(lumis_loader::PLUGIN_PATH_VAR);
    let phong = registry
        .find(lumis_core::PluginKind::Bsdf, "phong")
        .expect("phong registered");
    assert!(
        phong.source.contains("lumis-plugin-path"),
        "{}",
        phong.source
    );
    let listing = lumis_cli::plugin_listing(&registry);
    assert!(
        listing.contains("type = \"phong\"") && listing.contains("exponent"),
        "{listing}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn library_from_another_lumis_core_is_refused_before_registering() {
    let library = build_plugin("foreign-plugin", "foreign_plugin");
    let mut registry = lumis_app::builtin_registry().unwrap();
    // Its register function panics: reaching it would fail differently.
    let err = lumis_loader::load_library(&library, &mut registry)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("built against lumis-api 0.0.0-elsewhere")
            && err.contains(lumis_core::plugin::API_VERSION)
            && err.contains("rebuild"),
        "{err}"
    );
    assert!(registry
        .find(lumis_core::PluginKind::Bsdf, "phong")
        .is_none());
}

#[test]
fn library_with_another_plugin_interface_is_refused_before_registering() {
    let library = build_plugin("altered-interface-plugin", "altered_interface_plugin");
    let mut registry = lumis_app::builtin_registry().unwrap();
    // Its register function panics: reaching it would fail differently.
    let err = lumis_loader::load_library(&library, &mut registry)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("plugin interface differs")
            && err.contains("0123456789abcdef")
            && err.contains(lumis_core::plugin::INTERFACE_FINGERPRINT)
            && err.contains("rebuild"),
        "{err}"
    );
}

/// A copy of the example plugin in a fresh directory.
fn plugin_copy(tag: &str) -> (PathBuf, PathBuf) {
    let library = build_example_plugin();
    let dir = std::env::temp_dir().join(format!("lumis-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let copy = dir.join(library.file_name().unwrap());
    std::fs::copy(&library, &copy).unwrap();
    (dir, copy)
}

/// The same file named twice (once by another path) is loaded once.
#[test]
fn a_library_named_twice_loads_once() {
    let (dir, copy) = plugin_copy("plugin-twice");
    let mut registry = lumis_app::builtin_registry().unwrap();
    lumis_loader::load_library(&copy, &mut registry).unwrap();
    let again = dir.join(".").join(copy.file_name().unwrap());
    lumis_loader::load_library(&again, &mut registry).unwrap();
    let phongs = registry
        .plugins()
        .into_iter()
        .filter(|p| p.spec.name == "phong")
        .count();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(phongs, 1);
}

/// A library cut short is an error naming the file, not a SIGBUS.
#[test]
fn a_truncated_library_is_an_error() {
    let (dir, copy) = plugin_copy("plugin-cut");
    let bytes = std::fs::read(&copy).unwrap();
    std::fs::write(&copy, &bytes[..bytes.len() / 3]).unwrap();
    let err = lumis_loader::load_library(&copy, &mut lumis_core::Registry::new())
        .unwrap_err()
        .to_string();
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        err.contains("cut short") && err.contains("not a loadable shared library"),
        "{err}"
    );
}

/// A panic in a loaded plugin, in `register`, its factory or any method,
/// is an error naming the plugin, its parameters, its library and the
/// method: `lumis` exits 1, never aborts (exit 134), and writes no image.
/// In `check-plugin` the cases of the panicking variants fail with it and
/// the sweep goes on.
#[test]
fn a_panicking_plugin_is_an_error_not_an_abort() {
    let library = build_plugin("panicking-plugin", "panicking_plugin");
    let lumis = build_lumis();
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str], register_panics: bool| {
        let mut command = Command::new(&lumis);
        command.args(args).env_remove("LUMIS_PLUGIN_PATH");
        if register_panics {
            command.env("LUMIS_TEST_PANIC_IN_REGISTER", "1");
        }
        let out = command.output().expect("lumis runs");
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let lib = library.to_str().unwrap();

    let (code, _, stderr) = run(&["plugins", "--load", lib], true);
    assert_eq!(code, Some(1), "{stderr}");
    assert!(
        stderr.contains("panicked in register: the fixture panics in register as asked"),
        "{stderr}"
    );

    // `f` and `pdf` are reached through `eval`, the call that crosses the
    // boundary.
    for (panic_in, method) in [
        ("factory", "its factory"),
        ("f", "Bsdf::eval"),
        ("sample-f", "Bsdf::sample_f"),
        ("pdf", "Bsdf::eval"),
    ] {
        let scene = dir.path().join(format!("{panic_in}.toml"));
        let text = scene_with_plugin(lib, panic_in);
        std::fs::write(&scene, text).unwrap();
        let output = dir.path().join(panic_in);
        let (code, _, stderr) = run(
            &[
                "render",
                scene.to_str().unwrap(),
                "-q",
                "-o",
                output.to_str().unwrap(),
            ],
            false,
        );
        assert_eq!(code, Some(1), "{panic_in}: {stderr}");
        for part in [
            format!("panicked in {method}: the fixture panics in"),
            format!("panic_in = \"{panic_in}\""),
            lib.to_string(),
        ] {
            assert!(
                stderr.contains(&part),
                "{panic_in}: no '{part}' in {stderr}"
            );
        }
        assert!(!output.with_extension("exr").exists(), "{panic_in}");
    }

    // The packet integrator asks the BSDF for its lanes; the trait's
    // default runs inside the library and calls `sample_f` there, so the
    // panic is the lane method's, and the same error.
    let scene = dir.path().join("packet.toml");
    std::fs::write(&scene, scene_with_plugin(lib, "sample-f")).unwrap();
    let output = dir.path().join("packet");
    let (code, _, stderr) = run(
        &[
            "render",
            scene.to_str().unwrap(),
            "--set",
            "integrator.type=\"packet\"",
            "-q",
            "-o",
            output.to_str().unwrap(),
        ],
        false,
    );
    assert_eq!(code, Some(1), "packet: {stderr}");
    assert!(
        stderr.contains("panicked in Bsdf::sample_f_lanes: the fixture panics in"),
        "packet: {stderr}"
    );
    assert!(!output.with_extension("exr").exists(), "packet");

    // `--out` names a directory that does not exist yet: check-plugin
    // makes it before the first case.
    let out_dir = dir.path().join("check").join("pictures");
    let (code, stdout, stderr) = run(
        &[
            "check-plugin",
            lib,
            "--samples",
            "20000",
            "--out",
            out_dir.to_str().unwrap(),
        ],
        false,
    );
    assert_eq!(code, Some(1), "{stdout}{stderr}");
    for method in ["its factory", "Bsdf::f", "Bsdf::sample_f", "Bsdf::pdf"] {
        assert!(
            stdout.contains(&format!("panicked in {method}")),
            "{method}: {stdout}"
        );
    }
    let nowhere_passes = stdout
        .lines()
        .filter(|l| l.contains("panic_in = \"nowhere\"") || l.contains("base"))
        .any(|l| l.trim_end().ends_with("ok"));
    assert!(nowhere_passes, "{stdout}");
    assert!(out_dir.is_dir(), "{stderr}");
}

fn scene_with_plugin(library: &str, panic_in: &str) -> String {
    let bsdf =
        format!("[[bsdf]]\nname = \"subject\"\ntype = \"panicking\"\npanic_in = \"{panic_in}\"");
    plugin_quad_scene(library, &bsdf, 8, 4)
}
