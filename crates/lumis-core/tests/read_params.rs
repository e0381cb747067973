//! Parameters read from a parsed scene document: values, defaults, types,
//! ranges and where each error points.

use lumis_core::doc::{self, Table};
use lumis_core::error::Location;
use lumis_core::params::{ParamSpec, ParamType, ParamValue, Params};
use lumis_core::spectrum::Rgb;

const SPEC: &[ParamSpec] = &[
    ParamSpec::required("reflectance", ParamType::Rgb, "albedo"),
    ParamSpec::with_default(
        "max_depth",
        ParamType::Int,
        ParamValue::Int(8),
        "path segments",
    ),
    ParamSpec::with_default(
        "heuristic",
        ParamType::String,
        ParamValue::Str("power"),
        "MIS heuristic",
    )
    .one_of(&["balance", "power"]),
    ParamSpec::optional("beta", ParamType::Float, "power heuristic exponent"),
];

fn params(text: &str) -> Table {
    doc::parse(text, "t.toml").unwrap()
}

#[test]
fn reads_values_and_defaults() {
    let t = params("type = \"x\"\nreflectance = 0.5\n");
    let p = Params::new("bsdf \"w\"", &t, Location::Builtin, SPEC, &["type"]).unwrap();
    assert_eq!(p.get::<Rgb>("reflectance").unwrap(), Rgb::splat(0.5));
    assert_eq!(p.get::<i64>("max_depth").unwrap(), 8);
    assert_eq!(p.get::<String>("heuristic").unwrap(), "power");
    assert_eq!(p.get_opt::<f32>("beta").unwrap(), None);
    p.finish().unwrap();
}

#[test]
fn unknown_key_names_key_owner_and_accepted_keys() {
    let t = params("reflectance = 0.5\nreflectence = 0.5\n");
    let err = Params::new("bsdf \"w\"", &t, Location::Builtin, SPEC, &["type"])
        .err()
        .unwrap();
    let text = err.to_string();
    assert!(text.starts_with("t.toml:2:1"), "{text}");
    assert!(
        text.contains("'reflectence'") && text.contains("bsdf \"w\""),
        "{text}"
    );
    assert!(
        text.contains("reflectance, max_depth, heuristic, beta"),
        "{text}"
    );
}

#[test]
fn wrong_type_is_located_at_the_value() {
    let t = params("reflectance = \"red\"\n");
    let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
    let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
    assert!(
        err.starts_with("t.toml:1:15") && err.contains("expected [r, g, b]"),
        "{err}"
    );
}

#[test]
fn nan_infinity_and_f32_overflow_are_refused() {
    for (text, says) in [
        ("reflectance = nan\n", "expected a finite number, found NaN"),
        (
            "reflectance = [0.5, nan, 0.5]\n",
            "element 1: expected a finite number",
        ),
        ("reflectance = [0.5, 0.5, -inf]\n", "found -inf"),
        (
            "reflectance = 1e300\n",
            "beyond the range of a 32-bit float",
        ),
    ] {
        let t = params(text);
        let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
        let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
        assert!(
            err.starts_with("t.toml:1:15") && err.contains(says),
            "{text}: {err}"
        );
    }
    let t = params("reflectance = 0.5\nbeta = inf\n");
    let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
    let err = p.get::<f32>("beta").unwrap_err().to_string();
    assert!(err.contains("'beta'") && err.contains("found inf"), "{err}");
}

#[test]
fn missing_required_key_is_an_error() {
    let t = params("max_depth = 3\n");
    let p = Params::new("bsdf", &t, Location::Builtin, SPEC, &[]).unwrap();
    let err = p.get::<Rgb>("reflectance").unwrap_err().to_string();
    assert!(err.contains("needs 'reflectance'"), "{err}");
}

#[test]
fn unused_key_is_an_error() {
    let t = params("reflectance = 1\nbeta = 2\n");
    let p = Params::new("integrator", &t, Location::Builtin, SPEC, &[]).unwrap();
    p.get::<Rgb>("reflectance").unwrap();
    let err = p.finish().unwrap_err().to_string();
    assert!(err.contains("'beta' is not used"), "{err}");
}

#[test]
fn paths_are_relative_to_the_scene_file() {
    const FILE: &[ParamSpec] = &[ParamSpec::required("file", ParamType::String, "a file")];
    let t = doc::parse("file = \"tables/a.binary\"\n", "/scenes/s.toml").unwrap();
    let p = Params::new("bsdf", &t, Location::Builtin, FILE, &[]).unwrap();
    assert_eq!(
        p.get::<std::path::PathBuf>("file").unwrap(),
        std::path::Path::new("/scenes/tables/a.binary")
    );
    let t = doc::parse("file = \"/abs/a.binary\"\n", "/scenes/s.toml").unwrap();
    let p = Params::new("bsdf", &t, Location::Builtin, FILE, &[]).unwrap();
    assert_eq!(
        p.get::<std::path::PathBuf>("file").unwrap(),
        std::path::Path::new("/abs/a.binary")
    );
}

/// A declared end that is not exact in f32 is accepted as the f32 a
/// scene writes for it; the next f32 beyond either end is not.
#[test]
fn a_range_holds_its_own_ends() {
    const RANGED: &[ParamSpec] =
        &[ParamSpec::required("roughness", ParamType::Float, "r").in_range(0.02, 1.0)];
    let read = |v: f32| {
        let t = params(&format!("roughness = {v:?}\n"));
        let p = Params::new("x", &t, Location::Builtin, RANGED, &[]).unwrap();
        (
            p.value::<f32>("roughness").is_ok(),
            p.get_in_range("roughness").is_ok(),
        )
    };
    assert_eq!(read(0.02), (true, true));
    assert_eq!(read(1.0), (true, true));
    let below = f32::from_bits(0.02f32.to_bits() - 1);
    let above = f32::from_bits(1.0f32.to_bits() + 1);
    assert_eq!(read(below), (false, false));
    assert_eq!(read(above), (false, false));
}

#[test]
fn range_and_choice_checks() {
    let t = params("reflectance = -1\nheuristic = \"max\"\n");
    let p = Params::new("x", &t, Location::Builtin, SPEC, &[]).unwrap();
    assert!(p
        .get_positive("reflectance")
        .unwrap_err()
        .to_string()
        .contains("positive"));
    let err = p.get_choice("heuristic").unwrap_err().to_string();
    assert!(err.contains("\"balance\", \"power\""), "{err}");
}
