//! Textured parameters read from a parsed scene document: constants,
//! texture references, and the errors of bad references.

use std::sync::Arc;

use glam::Vec2;
use lumis_core::doc;
use lumis_core::error::{Location, Result};
use lumis_core::params::{Param, ParamSpec, ParamType, Params, TexturedFloat, TexturedRgb};
use lumis_core::spectrum::Rgb;
use lumis_core::texture::{Texture, TextureQuery, Textures};

struct Ramp;

impl Texture for Ramp {
    fn eval(&self, q: &TextureQuery) -> Rgb {
        Rgb::new(q.uv.x, q.uv.y, 0.5)
    }
}

const SPEC: &[ParamSpec] = &[
    ParamSpec::required("albedo", ParamType::TexturedRgb, "a colour"),
    ParamSpec::with_default(
        "roughness",
        ParamType::TexturedFloat,
        lumis_core::ParamValue::Float(0.5),
        "a number",
    )
    .in_range(0.0, 1.0),
    ParamSpec::optional("tint", ParamType::Rgb, "an untextured colour"),
];

fn textures() -> Textures {
    let mut t = Textures::new();
    t.insert("ramp", Arc::new(Ramp));
    t
}

fn read<T: Param>(text: &str, name: &str, textures: Option<&Textures>) -> Result<T> {
    let table = doc::parse(text, "s.toml").unwrap();
    let params = Params::new("bsdf \"b\"", &table, Location::Builtin, SPEC, &[]).unwrap();
    let params = match textures {
        Some(t) => params.with_scope(lumis_core::texture::BsdfScope::textures(t)),
        None => params,
    };
    params.value(name)
}

#[test]
fn constants_and_textures_are_read() {
    let t = textures();
    let q = TextureQuery::at(Vec2::new(0.25, 0.75));
    let c: TexturedRgb = read("albedo = [0.1, 0.2, 0.3]\n", "albedo", Some(&t)).unwrap();
    assert_eq!(c.eval(&q), Rgb::new(0.1, 0.2, 0.3));
    assert_eq!(c.constant(), Some(Rgb::new(0.1, 0.2, 0.3)));
    let r: TexturedRgb = read("albedo = { texture = \"ramp\" }\n", "albedo", Some(&t)).unwrap();
    assert_eq!(r.eval(&q), Rgb::new(0.25, 0.75, 0.5));
    assert!(r.constant().is_none());
    let f: TexturedFloat = read(
        "roughness = { texture = \"ramp\" }\n",
        "roughness",
        Some(&t),
    )
    .unwrap();
    assert_eq!(f.eval(&q), 0.5);
    let d: TexturedFloat = read("", "roughness", Some(&t)).unwrap();
    assert_eq!(d.constant(), Some(0.5));
}

#[test]
fn bad_references_name_the_key_and_what_was_expected() {
    let t = textures();
    let err = |text: &str, name: &str, textures: Option<&Textures>| {
        let result = if name == "tint" {
            read::<Rgb>(text, name, textures).map(|_| ())
        } else {
            read::<TexturedRgb>(text, name, textures).map(|_| ())
        };
        result.unwrap_err().to_string()
    };
    let e = err("albedo = { texture = \"wood\" }\n", "albedo", Some(&t));
    assert!(
        e.starts_with("s.toml:1:10")
            && e.contains("bsdf \"b\" key 'albedo': unknown texture \"wood\"; declared: ramp"),
        "{e}"
    );
    let e = err(
        "albedo = { texture = \"wood\" }\n",
        "albedo",
        Some(&Textures::new()),
    );
    assert!(e.contains("the scene declares no [[texture]]"), "{e}");
    let e = err("albedo = { texture = \"ramp\" }\n", "albedo", None);
    assert!(e.contains("is not accepted here"), "{e}");
    let e = err("albedo = { texture = 3 }\n", "albedo", Some(&t));
    assert!(
        e.contains("'texture' must be the name of a [[texture]], found an integer"),
        "{e}"
    );
    let e = err(
        "albedo = { texture = \"ramp\", scale = 2 }\n",
        "albedo",
        Some(&t),
    );
    assert!(
        e.contains("unknown key 'scale'; expected { texture = \"name\" }"),
        "{e}"
    );
    let e = err("tint = { texture = \"ramp\" }\n", "tint", Some(&t));
    assert!(
        e.contains("key 'tint'") && e.contains("this parameter takes no texture"),
        "{e}"
    );
    let e = read::<TexturedFloat>("roughness = 2\n", "roughness", Some(&t))
        .unwrap_err()
        .to_string();
    assert!(e.contains("must be in [0, 1]"), "{e}");
}
