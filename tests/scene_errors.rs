//! Bad scenes get clear errors that name the file, line and key.

use lumis_tests::{load_error, scenes_dir};

const BASE: &str = r#"[film]
resolution = [8, 8]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "independent"
spp = 1
[integrator]
type = "path"
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 0.5
"#;

fn with(extra: &str) -> String {
    format!("{BASE}{extra}")
}

fn assert_contains(err: &str, parts: &[&str]) {
    for part in parts {
        assert!(
            err.contains(part),
            "error does not mention '{part}':\n{err}"
        );
    }
}

#[test]
fn base_scene_loads() {
    let registry = lumis_app::builtin_registry().unwrap();
    let toml = with(
        "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nbsdf = \"white\"\n",
    );
    lumis_scene::load_str(&toml, &scenes_dir().join("ok.toml"), &[], &registry).unwrap();
}

#[test]
fn missing_scene_file() {
    let registry = lumis_app::builtin_registry().unwrap();
    let err = lumis_scene::load_file(std::path::Path::new("no/such/scene.toml"), &[], &registry)
        .err()
        .unwrap()
        .to_string();
    assert_contains(&err, &["cannot read scene", "no/such/scene.toml"]);
}

#[test]
fn bad_toml() {
    let err = load_error("[film]\nresolution = [8, 8\n");
    assert_contains(&err, &["bad.toml:", "invalid TOML"]);
}

#[test]
fn unknown_plugin_type_lists_the_available_ones() {
    let err = load_error(&BASE.replace("type = \"diffuse\"", "type = \"difuse\""));
    assert_contains(
        &err,
        &[
            "bad.toml:15:8",
            "unknown bsdf type \"difuse\"",
            "available: blinn, conductor, dielectric, diffuse, measured, mirror, normalmap, plastic, twosided",
        ],
    );
}

#[test]
fn unknown_key_names_the_plugin_and_the_accepted_keys() {
    let err = load_error(&BASE.replace("reflectance = 0.5", "reflectence = 0.5"));
    assert_contains(
        &err,
        &[
            "bad.toml:16:1",
            "unknown key 'reflectence'",
            "bsdf \"white\"",
            "reflectance, two_sided, sampling",
        ],
    );
    let err = load_error(&with("[integrator2]\n"));
    assert_contains(&err, &["unknown top-level key 'integrator2'"]);
}

#[test]
fn wrong_type() {
    let err = load_error(&BASE.replace("spp = 1", "spp = \"many\""));
    assert_contains(
        &err,
        &[
            "bad.toml:10:7",
            "'spp'",
            "expected an integer, found a string",
        ],
    );
    let err = load_error(&BASE.replace("resolution = [8, 8]", "resolution = 8"));
    assert_contains(
        &err,
        &["bad.toml:2:14", "'resolution'", "expected an array of 2"],
    );
}

#[test]
fn out_of_range_values() {
    let err = load_error(&with(
        "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = -1.0\nbsdf = \"white\"\n",
    ));
    assert_contains(&err, &["bad.toml:20:10", "'radius'", "positive"]);
    let err = load_error(&BASE.replace("fov = 40.0", "fov = 180.0"));
    assert_contains(&err, &["bad.toml:7:7", "'fov'", "(0, 180)"]);
    let err = load_error(&BASE.replace("fov = 40.0", "fov = -3"));
    assert_contains(&err, &["'fov'", "(0, 180)"]);
    let err = load_error(&BASE.replace("reflectance = 0.5", "reflectance = 1.5"));
    assert_contains(&err, &["bad.toml:16:15", "[0, 1]"]);
}

#[test]
fn non_finite_numbers() {
    let err = load_error(&BASE.replace("reflectance = 0.5", "reflectance = nan"));
    assert_contains(&err, &["bad.toml:16:15", "'reflectance'", "finite"]);
    let err = load_error(&BASE.replace("fov = 40.0", "fov = inf"));
    assert_contains(&err, &["bad.toml:7:7", "'fov'", "finite"]);
    let err = load_error(&with(
        "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1e39, 0.0]]\nindices = [0, 1, 2]\nbsdf = \"white\"\n",
    ));
    assert_contains(
        &err,
        &["bad.toml:19:13", "'positions'", "element 2", "32-bit float"],
    );
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("nan.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n").unwrap();
    let err = load_error(&with(&format!(
        "[[shape]]\ntype = \"obj\"\nfile = {:?}\nbsdf = \"white\"\n",
        obj.display().to_string()
    )));
    assert_contains(
        &err,
        &["bad.toml:19:8", "nan.obj", "vertex position", "not finite"],
    );
}

#[test]
fn mesh_index_out_of_range() {
    let err = load_error(&with(
        "[[shape]]\ntype = \"mesh\"\npositions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\nindices = [0, 1, 3]\nbsdf = \"white\"\n",
    ));
    assert_contains(
        &err,
        &["bad.toml:20:11", "index 3", "out of range for 3 positions"],
    );
}

#[test]
fn missing_obj_file_and_unknown_bsdf_name() {
    let err = load_error(&with(
        "[[shape]]\ntype = \"obj\"\nfile = \"nope.obj\"\nbsdf = \"white\"\n",
    ));
    assert_contains(
        &err,
        &[
            "bad.toml:19:8",
            "cannot read OBJ mesh",
            "nope.obj",
            "No such file",
        ],
    );
    let err = load_error(&with(
        "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nbsdf = \"whte\"\n",
    ));
    assert_contains(
        &err,
        &[
            "bad.toml:21:8",
            "no [[bsdf]] named \"whte\"",
            "defined: white",
        ],
    );
}

#[test]
fn setting_that_does_not_apply_is_rejected() {
    let err = load_error(&BASE.replace(
        "type = \"path\"",
        "type = \"path\"\nheuristic = \"balance\"\nbeta = 3.0",
    ));
    assert_contains(
        &err,
        &[
            "bad.toml:14:8",
            "'beta': only applies to heuristic = \"power\"",
        ],
    );
}

#[test]
fn missing_required_tables_and_keys() {
    let err = load_error(&BASE.replace("[sampler]\ntype = \"independent\"\nspp = 1\n", ""));
    assert_contains(&err, &["needs a [sampler] table"]);
    let err = load_error(&BASE.replace("fov = 40.0\n", ""));
    assert_contains(&err, &["needs 'fov'"]);
}

#[test]
fn unknown_denoiser_types_and_parameters_are_named() {
    let err = load_error(&with("[denoiser]\ntype = \"oidnn\"\n"));
    assert_contains(
        &err,
        &[
            "bad.toml:18:8",
            "unknown denoiser type \"oidnn\"",
            "available: oidn",
        ],
    );
    let err = load_error(&with("[denoiser]\ntype = \"oidn\"\nqualty = \"fast\"\n"));
    assert_contains(&err, &["bad.toml:19:1", "'qualty'", "quality"]);
    let err = load_error(&with("[denoiser]\ntype = \"oidn\"\nquality = \"best\"\n"));
    assert_contains(
        &err,
        &[
            "bad.toml:19:11",
            "'quality'",
            "\"high\", \"balanced\", \"fast\"",
            "\"best\"",
        ],
    );
}
