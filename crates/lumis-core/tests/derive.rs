//! `#[derive(PluginParams)]` and `#[derive(ParamChoice)]` as a plugin
//! uses them: the declaration they write and the reading they generate.

use lumis_core::doc::{self, Table};
use lumis_core::params::{ParamDefault, ParamValue};
use lumis_core::{Location, ParamChoice, ParamType, Params, PluginParams, Result, Rgb, Vec3};

/// A choice: its names are its variants.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
enum Lobe {
    Ggx,
    Beckmann,
    SolidAngle,
    #[choice("Ag")]
    Silver,
}

/// A group several plugins share.
#[derive(Debug, PluginParams)]
struct Roughness {
    /// alpha of the microfacets
    #[param(default = 0.1, range = (0.0, 1.0))]
    roughness: f32,
    /// alpha along the second tangent;
    /// default: roughness
    #[param(range = (0.0, 1.0))]
    roughness_v: Option<f32>,
}

#[derive(Debug, PluginParams)]
struct Material {
    /// albedo in linear RGB
    reflectance: Rgb,
    /// the lobe's shape
    #[param(default = Ggx)]
    lobe: Lobe,
    /// samples per vertex
    #[param(default = 8, range = (1, 64))]
    samples: u32,
    /// the up direction
    #[param(default = [0.0, 1.0, 0.0])]
    up: Vec3,
    /// a key that is not a Rust name
    #[param(rename = "two-sided", default = false)]
    two_sided: bool,
    #[param(flatten, default(roughness = 0.0))]
    microfacet: Roughness,
}

fn table(text: &str) -> Table {
    doc::parse(text, "m.toml").unwrap()
}

fn read(text: &str) -> Result<Material> {
    let t = table(text);
    let params = Params::new("bsdf \"m\"", &t, Location::Builtin, Material::SPECS, &[])?;
    let m = Material::read(&params)?;
    params.finish()?;
    Ok(m)
}

#[test]
fn the_declaration_comes_from_the_fields() {
    let names: Vec<&str> = Material::SPECS.iter().map(|s| s.name).collect();
    assert_eq!(
        names,
        [
            "reflectance",
            "lobe",
            "samples",
            "up",
            "two-sided",
            "roughness",
            "roughness_v"
        ]
    );
    let by_name = |name: &str| *Material::SPECS.iter().find(|s| s.name == name).unwrap();

    let reflectance = by_name("reflectance");
    assert_eq!(reflectance.ty, ParamType::Rgb);
    assert_eq!(reflectance.default, ParamDefault::Required);
    assert_eq!(reflectance.doc, "albedo in linear RGB");

    let lobe = by_name("lobe");
    assert_eq!(lobe.ty, ParamType::String);
    assert_eq!(lobe.default, ParamDefault::Value(ParamValue::Str("ggx")));
    assert_eq!(lobe.choices, ["ggx", "beckmann", "solid-angle", "Ag"]);

    let samples = by_name("samples");
    assert_eq!(
        (samples.ty, samples.default, samples.range),
        (
            ParamType::Int,
            ParamDefault::Value(ParamValue::Int(8)),
            Some((1.0, 64.0))
        )
    );
    assert_eq!(
        by_name("up").default.to_string_for_test(),
        "[0.0, 1.0, 0.0]"
    );

    // The group's default changed for this plugin only.
    assert_eq!(
        by_name("roughness").default,
        ParamDefault::Value(ParamValue::Float(0.0))
    );
    assert_eq!(
        Roughness::SPECS[0].default,
        ParamDefault::Value(ParamValue::Float(0.1))
    );
    let roughness_v = by_name("roughness_v");
    assert_eq!(roughness_v.default, ParamDefault::Absent);
    assert_eq!(
        roughness_v.doc,
        "alpha along the second tangent; default: roughness"
    );

    assert_eq!(Material::KEYS.two_sided, "two-sided");
    assert_eq!(Material::KEYS.microfacet.roughness_v, "roughness_v");
}

/// A default's text, as `lumis plugins` prints it.
trait DefaultText {
    fn to_string_for_test(&self) -> String;
}

impl DefaultText for ParamDefault {
    fn to_string_for_test(&self) -> String {
        match self {
            ParamDefault::Value(v) => v.to_string(),
            other => format!("{other:?}"),
        }
    }
}

#[test]
fn reads_values_defaults_and_absence() {
    let m = read("reflectance = 0.5\nlobe = \"solid-angle\"\nroughness_v = 0.3\n").unwrap();
    assert_eq!(m.reflectance, Rgb::splat(0.5));
    assert_eq!(m.lobe, Lobe::SolidAngle);
    assert_eq!(m.samples, 8);
    assert_eq!(m.up, Vec3::Y);
    assert!(!m.two_sided);
    assert_eq!(m.microfacet.roughness, 0.0);
    assert_eq!(m.microfacet.roughness_v, Some(0.3));

    let m = read("reflectance = [1, 0, 0]\n\"two-sided\" = true\nlobe = \"Ag\"\n").unwrap();
    assert!(m.two_sided);
    assert_eq!(m.lobe, Lobe::Silver);
    assert_eq!(m.microfacet.roughness_v, None);
}

#[test]
fn a_missing_required_parameter_is_an_error() {
    let err = read("samples = 2\n").unwrap_err().to_string();
    assert!(
        err.contains("bsdf \"m\" needs 'reflectance' (rgb: albedo in linear RGB)"),
        "{err}"
    );
}

#[test]
fn out_of_range_values_are_located_errors() {
    let err = read("reflectance = 1\nsamples = 65\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("m.toml:2:11") && err.contains("key 'samples': must be in [1, 64], got 65"),
        "{err}"
    );
    let err = read("reflectance = 1\nroughness_v = 1.5\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("'roughness_v': must be in [0, 1], got 1.5"),
        "{err}"
    );
}

#[test]
fn a_bad_choice_names_the_choices() {
    let err = read("reflectance = 1\nlobe = \"phong\"\n")
        .unwrap_err()
        .to_string();
    assert!(err.starts_with("m.toml:2:8"), "{err}");
    assert!(
        err.contains(
            "key 'lobe': must be one of \"ggx\", \"beckmann\", \"solid-angle\", \"Ag\", got \"phong\""
        ),
        "{err}"
    );
    let err = read("reflectance = 1\nlobe = 2\n").unwrap_err().to_string();
    assert!(err.contains("expected a string, found an integer"), "{err}");
}

#[test]
fn a_wrong_type_and_an_unknown_key_are_errors() {
    let err = read("reflectance = 1\nsamples = 2.5\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("key 'samples': expected an integer"), "{err}");
    let err = read("reflectance = 1\nroughnes = 0.2\n")
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("m.toml:2:1") && err.contains("unknown key 'roughnes'"),
        "{err}"
    );
}

#[test]
fn a_key_marked_unread_is_rejected_when_given() {
    let t = table("reflectance = 1\nroughness_v = 0.2\n");
    let params = Params::new("bsdf \"m\"", &t, Location::Builtin, Material::SPECS, &[]).unwrap();
    let _ = Material::read(&params).unwrap();
    params.unread(Material::KEYS.microfacet.roughness_v);
    let err = params.finish().unwrap_err().to_string();
    assert!(err.contains("key 'roughness_v' is not used"), "{err}");
}

#[test]
fn choices_convert_both_ways() {
    for (&variant, &name) in Lobe::VARIANTS.iter().zip(Lobe::NAMES) {
        assert_eq!(variant.name(), name);
        assert_eq!(Lobe::from_name(name), Some(variant));
    }
    assert_eq!(Lobe::from_name("GGX"), None);
}
