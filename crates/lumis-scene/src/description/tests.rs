//! The description keeps every plugin as a located entity and fills in
//! defaults as entities, never as TOML text.

use std::sync::Arc;

use lumis_core::{Location, PluginKind};

use super::{SceneDescription, ShapeSource, SurfaceGeometry};

const BASE: &str = r#"[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "independent"
[integrator]
type = "path"
[[bsdf]]
name = "white"
type = "diffuse"
"#;

fn describe(extra: &str) -> SceneDescription {
    let root = lumis_core::doc::parse(&format!("{BASE}{extra}"), "s.toml").unwrap();
    let file = Location::File {
        path: Arc::from("s.toml"),
        line: 1,
        column: 1,
    };
    SceneDescription::from_document(root, &file).unwrap()
}

#[test]
fn plugin_entities_keep_their_locations() {
    let scene = describe("");
    let white = &scene.bsdfs[0];
    assert_eq!(white.name, "white");
    assert_eq!(white.entity.kind, PluginKind::Bsdf);
    assert_eq!(white.entity.owner, "bsdf \"white\"");
    assert_eq!(white.entity.type_location.to_string(), "s.toml:12:8");
    assert_eq!(scene.sampler.type_name, "independent");
    assert_eq!(scene.integrator.location.to_string(), "s.toml:8:1");
}

#[test]
fn the_default_light_sampler_is_a_typed_entity() {
    let absent = describe("").light_sampler;
    assert_eq!(absent.kind, PluginKind::LightSampler);
    assert_eq!(absent.type_name, "uniform");
    assert!(absent.table.entries.is_empty());
    let untyped = describe("[light_sampler]\n").light_sampler;
    assert_eq!(untyped.type_name, "uniform");
    let power = describe("[light_sampler]\ntype = \"power\"\n").light_sampler;
    assert_eq!(power.type_name, "power");
    assert_eq!(power.type_location.to_string(), "s.toml:14:8");
}

#[test]
fn emission_takes_the_light_of_its_geometry_unless_named() {
    let scene = describe(
        r#"[[shape]]
type = "quad"
corner = [0.0, 0.0, 0.0]
edge_u = [1.0, 0.0, 0.0]
edge_v = [0.0, 1.0, 0.0]
bsdf = "white"
emission = { radiance = 1.0 }
[[shape]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
bsdf = "white"
emission = { radiance = 1.0 }
[[shape]]
type = "mesh"
positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
indices = [0, 1, 2]
bsdf = "white"
emission = { type = "my_triangle", radiance = 1.0 }
"#,
    );
    let lights: Vec<(&str, String)> = scene
        .shapes
        .iter()
        .map(|shape| {
            let ShapeSource::Surface(surface) = &shape.source else {
                panic!("{} is a surface", shape.owner)
            };
            let kind = match surface.geometry {
                SurfaceGeometry::Quad { .. } => "quad",
                SurfaceGeometry::Sphere { .. } => "sphere",
                SurfaceGeometry::Mesh(_) => "mesh",
                SurfaceGeometry::Obj(_) => "obj",
            };
            let emission = surface.emission.as_ref().expect("it emits");
            assert_eq!(emission.kind, PluginKind::Light);
            (kind, emission.type_name.clone())
        })
        .collect();
    assert_eq!(
        lights,
        [
            ("quad", "quad".to_string()),
            ("sphere", "sphere".to_string()),
            ("mesh", "my_triangle".to_string())
        ]
    );
    let ShapeSource::Surface(quad) = &scene.shapes[0].source else {
        panic!("a surface")
    };
    let emission = quad.emission.as_ref().unwrap();
    assert_eq!(emission.owner, "[[shape]] #0 (type = \"quad\") emission");
    assert_eq!(emission.location.to_string(), "s.toml:19:12");
    assert_eq!(quad.bsdf.location.to_string(), "s.toml:18:8");
}

fn try_describe(text: &str) -> lumis_core::Result<SceneDescription> {
    let root = lumis_core::doc::parse(text, "s.toml").unwrap();
    let file = Location::File {
        path: Arc::from("s.toml"),
        line: 1,
        column: 1,
    };
    SceneDescription::from_document(root, &file)
}

#[test]
fn film_aovs_are_typed_and_unknown_names_refused() {
    use lumis_render::Aov;
    assert!(describe("").film.aovs.is_empty());
    let film = describe("[film]\naovs = [\"depth\", \"albedo\", \"spp\"]\n").film;
    assert_eq!(film.aovs, [Aov::Depth, Aov::Albedo, Aov::Spp]);
    let err = try_describe(&format!("{BASE}[film]\naovs = [\"albedo\", \"colour\"]\n"))
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("aovs") && err.contains("\"colour\"") && err.contains("\"variance\""),
        "{err}"
    );
    let err = try_describe(&format!("{BASE}[film]\naovs = [\"spp\", \"spp\"]\n"))
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("twice"), "{err}");
}

#[test]
fn film_clamp_is_read_by_the_scene_not_the_plugin() {
    assert_eq!(describe("").clamp, None);
    let with = |clamp: &str| try_describe(&format!("{BASE}[film]\nclamp = {clamp}\n"));
    let scene = with("10").unwrap();
    assert_eq!(scene.clamp, Some(10.0));
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(with("0.5").unwrap().clamp, Some(0.5));
    for bad in ["0", "-1.0", "\"high\"", "1e300"] {
        let err = with(bad).err().unwrap().to_string();
        assert!(err.contains("clamp"), "{bad}: {err}");
    }
}

/// lumis 0.1.0's `[integrator] clamp` still reads, taken out of the
/// plugin's table, with a warning; given with `[film] clamp` it is an
/// error.
#[test]
fn integrator_clamp_reads_with_a_deprecation_warning() {
    let in_integrator = |clamp: &str| {
        BASE.replace(
            "type = \"path\"\n",
            &format!("type = \"path\"\nclamp = {clamp}\n"),
        )
    };
    let scene = try_describe(&in_integrator("10")).unwrap();
    assert_eq!(scene.clamp, Some(10.0));
    assert!(scene.integrator.table.get("clamp").is_none());
    assert!(
        scene.warnings.len() == 1
            && scene.warnings[0].contains("deprecated")
            && scene.warnings[0].contains("[film] clamp"),
        "{:?}",
        scene.warnings
    );
    for bad in ["0", "\"high\""] {
        let err = try_describe(&in_integrator(bad)).err().unwrap().to_string();
        assert!(err.contains("[integrator] clamp"), "{bad}: {err}");
    }
    let both = try_describe(&format!("{}[film]\nclamp = 5\n", in_integrator("10")));
    let err = both.err().unwrap().to_string();
    assert!(err.contains("both given"), "{err}");
}

#[test]
fn adaptive_is_read_by_the_scene_and_sets_the_spp() {
    // A top-level key, written before the first table.
    let with = |adaptive: &str, spp: &str| {
        let base = BASE.replace(
            "type = \"independent\"\n",
            &format!("type = \"independent\"\n{spp}"),
        );
        try_describe(&format!("adaptive = {adaptive}\n{base}"))
    };
    let scene = with("{ min_spp = 4, max_spp = 64, threshold = 0.01 }", "").unwrap();
    let adaptive = scene.adaptive.unwrap();
    assert_eq!((adaptive.min_spp, adaptive.max_spp), (4, Some(64)));
    assert_eq!(adaptive.threshold, 0.01);
    assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
    assert_eq!(
        scene.sampler.table.get("spp").map(|n| n.value.clone()),
        Some(lumis_core::doc::Value::Int(64))
    );
    let same = with(
        "{ min_spp = 4, max_spp = 64, threshold = 0.01 }",
        "spp = 64\n",
    );
    assert!(same.is_ok());
    for (adaptive, spp, expected) in [
        (
            "{ min_spp = 4, max_spp = 64, threshold = 0.01 }",
            "spp = 32\n",
            "disagree",
        ),
        (
            "{ min_spp = 4, threshold = 0.01, spread = 2 }",
            "",
            "spread",
        ),
        ("{ max_spp = 4, threshold = 0.01 }", "", "min_spp"),
        ("4", "", "table"),
    ] {
        let err = with(adaptive, spp).err().unwrap().to_string();
        assert!(err.contains(expected), "{adaptive}: {err}");
    }
}

/// lumis 0.1.0's `[sampler] adaptive = { ... }` still reads, taken out of
/// the plugin's table, with a warning; given with `[adaptive]` it is an
/// error.
#[test]
fn sampler_adaptive_reads_with_a_deprecation_warning() {
    let in_sampler = BASE.replace(
        "type = \"independent\"\n",
        "type = \"independent\"\nadaptive = { min_spp = 4, max_spp = 64, threshold = 0.01 }\n",
    );
    let scene = try_describe(&in_sampler).unwrap();
    let adaptive = scene.adaptive.unwrap();
    assert_eq!((adaptive.min_spp, adaptive.max_spp), (4, Some(64)));
    assert!(scene.sampler.table.get("adaptive").is_none());
    assert!(
        scene.warnings.len() == 1
            && scene.warnings[0].contains("deprecated")
            && scene.warnings[0].contains("[adaptive]"),
        "{:?}",
        scene.warnings
    );
    let both = try_describe(&format!(
        "{in_sampler}[adaptive]\nmin_spp = 4\nthreshold = 0.1\n"
    ));
    let err = both.err().unwrap().to_string();
    assert!(err.contains("both given"), "{err}");
}
