//! The `light` integrator (particle tracing) against `path`: the same
//! image in the mean wherever no specular surface is seen directly; its
//! splats the same bits whatever the threads, passes or parts; every
//! built-in light starting paths that carry its power; and the scenes it
//! cannot render refused by name.

use lumis_app::{builtin_registry, render_film, FilmRequest, SampleSlice, Session};
use lumis_core::{
    Light, LightKind, LightSample, LightSampleContext, Params, PluginKind, PluginParams,
    PluginSpec, Registrar, Rgb, Scene, Vec2, Vec3,
};
use lumis_sampling::Pcg32;
use lumis_scene::LoadedScene;
use lumis_tests::{assert_same_mean, bonferroni_z, load_error, render_loaded, scenes_dir};
use std::sync::atomic::AtomicBool;

/// Every kind of light the built-ins have, over a floor and a back wall
/// (diffuse, one of them textured) and a rough conductor: nothing
/// specular is seen directly.
const EVERY_LIGHT: &str = r#"
seed = 1
[film]
resolution = [32, 24]
[camera]
type = "perspective"
origin = [0.0, 1.5, 5.0]
target = [0.0, 0.5, 0.0]
up = [0.0, 1.0, 0.0]
fov = 50.0
[sampler]
type = "independent"
spp = 64
[integrator]
type = "path"
max_depth = 4
[[texture]]
name = "checks"
type = "checkerboard"
color0 = 0.2
color1 = 0.7
uv_scale = [4.0, 4.0]
[[bsdf]]
name = "floor"
type = "diffuse"
reflectance = { texture = "checks" }
[[bsdf]]
name = "wall"
type = "diffuse"
reflectance = [0.6, 0.5, 0.4]
[[bsdf]]
name = "metal"
type = "conductor"
roughness = 0.3
[[bsdf]]
name = "black"
type = "diffuse"
reflectance = 0.0
[[shape]]
type = "quad"
corner = [-3.0, 0.0, 3.0]
edge_u = [6.0, 0.0, 0.0]
edge_v = [0.0, 0.0, -6.0]
bsdf = "floor"
[[shape]]
type = "quad"
corner = [-3.0, 0.0, -3.0]
edge_u = [6.0, 0.0, 0.0]
edge_v = [0.0, 3.0, 0.0]
bsdf = "wall"
[[shape]]
type = "sphere"
center = [0.8, 0.5, 0.5]
radius = 0.5
bsdf = "metal"
[[shape]]
type = "sphere"
center = [-1.2, 1.6, 0.2]
radius = 0.25
bsdf = "black"
emission = { radiance = [4.0, 3.0, 2.0] }
[[shape]]
type = "quad"
corner = [0.5, 2.5, -1.0]
edge_u = [1.0, 0.0, 0.0]
edge_v = [0.0, 0.0, 1.0]
bsdf = "black"
emission = { radiance = 3.0, two_sided = true }
[[light]]
type = "point"
position = [-2.0, 1.0, 1.5]
intensity = [2.0, 2.0, 3.0]
[[light]]
type = "spot"
position = [1.5, 2.5, 2.0]
target = [0.5, 0.0, 0.0]
intensity = 6.0
cutoff = 35.0
falloff_start = 20.0
[[light]]
type = "constant"
radiance = [0.05, 0.07, 0.1]
"#;

fn load(toml: &str, overrides: &[&str]) -> LoadedScene {
    let registry = builtin_registry().unwrap();
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    lumis_scene::load_str(toml, &scenes_dir().join("test.toml"), &overrides, &registry)
        .unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

const LIGHT: &str = "integrator={ type = \"light\", max_depth = 4 }";

/// Paths from the lights estimate what paths from the camera do: the
/// block means of the two images agree, on the Cornell box (an emissive
/// mesh's triangles) and on every kind of light.
#[test]
fn the_mean_is_paths() {
    let cornell = std::fs::read_to_string(scenes_dir().join("cornell-box.toml")).unwrap();
    let cases: [(&str, &[&str], &str); 2] = [
        (
            &cornell,
            &[
                "film.resolution=[32, 32]",
                "sampler.spp=64",
                "integrator.max_depth=4",
            ],
            "the Cornell box",
        ),
        (EVERY_LIGHT, &[], "every light"),
    ];
    let z = bonferroni_z(1e-3, 2 * 3 * 16);
    for (toml, overrides, what) in cases {
        let path = render_loaded(&load(toml, overrides), 2).image;
        let light_overrides = [overrides, &[LIGHT, "sampler.spp=256"]].concat();
        let light = render_loaded(&load(toml, &light_overrides), 2);
        assert_eq!(light.stats.nonfinite, 0, "{what}");
        assert_same_mean(&light.image, &path, 8, z, what);
    }
}

/// The splats' sums are whole numbers: the image is the same bits with
/// one thread or two, in one pass or several, whole or as two parts
/// added.
#[test]
fn splats_are_the_same_whatever_the_threads_passes_or_parts() {
    let registry = builtin_registry().unwrap();
    let stop = AtomicBool::new(false);
    let session = Session::silent(&registry, &stop);
    let loaded = load(EVERY_LIGHT, &[LIGHT, "sampler.spp=4"]);
    let render = |threads, pass_spp, samples| {
        let request = FilmRequest {
            threads,
            pass_spp,
            samples,
            ..Default::default()
        };
        render_film(&loaded, &request, &session).unwrap().film
    };
    let whole = render(2, None, None);
    assert!(whole.splats.is_some());
    let image = whole.image();
    assert_eq!(
        render(1, None, None).image().pixels,
        image.pixels,
        "threads"
    );
    assert_eq!(
        render(2, Some(1), None).image().pixels,
        image.pixels,
        "passes"
    );
    let part = |start, end| {
        let slice = SampleSlice {
            start,
            end,
            total: 4,
        };
        render(2, None, Some(slice))
    };
    let mut merged = part(0, 3);
    merged.append(&part(3, 4)).unwrap();
    assert_eq!(merged.image().pixels, image.pixels, "parts");
}

/// Each built-in light's paths carry its power: the mean of
/// `L |cos| / (pdf_pos pdf_dir)` over its rays is `power()` (area, sphere,
/// point and spot lights, a textured one, and a constant and an image
/// environment, whose power is what enters the scene's bounding sphere).
#[test]
fn every_lights_paths_carry_its_power() {
    let textured = EVERY_LIGHT.replace(
        "emission = { radiance = 3.0, two_sided = true }",
        "emission = { radiance = { texture = \"checks\" }, two_sided = true }",
    );
    let with_map =
        format!("{textured}\n[[light]]\ntype = \"envmap\"\nfilename = \"bench/sky.exr\"\n");
    let loaded = load(&with_map, &[]);
    let lights = loaded.scene.lights();
    assert_eq!(lights.len(), 6);
    let mut rng = Pcg32::new(7, 11);
    let n = 400_000;
    for (index, light) in lights.iter().enumerate() {
        let mut sum = [0.0f64; 3];
        for _ in 0..n {
            let mut u = || rng.next_f32();
            let (u_pos, u_dir) = (Vec2::new(u(), u()), Vec2::new(u(), u()));
            if let Some(emitted) = light.sample_le(u_pos, u_dir) {
                let beta = emitted.beta();
                for (c, v) in sum.iter_mut().zip([beta.r, beta.g, beta.b]) {
                    *c += v as f64 / n as f64;
                }
            }
        }
        let power = light.power();
        for (c, expected) in [power.r, power.g, power.b].into_iter().enumerate() {
            let relative = sum[c] / expected as f64 - 1.0;
            assert!(
                relative.abs() < 0.01,
                "light {index}: power {power}, its paths carry {sum:?}"
            );
        }
    }
}

/// A light that keeps `sample_le`'s default.
struct Dark;

impl Light for Dark {
    fn kind(&self) -> LightKind {
        LightKind::DeltaPosition
    }
    fn sample_li(&self, _: &LightSampleContext, _: Vec2) -> Option<LightSample> {
        None
    }
    fn pdf_li(&self, _: &LightSampleContext, _: Vec3) -> f32 {
        0.0
    }
    fn l(&self, _: Vec3, _: Vec3, _: Vec2, _: Vec3) -> Rgb {
        Rgb::BLACK
    }
    fn power(&self) -> Rgb {
        Rgb::WHITE
    }
}

#[derive(Debug, PluginParams)]
struct DarkParams {}

const DARK: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "dark",
    source: lumis_api::source_file!(),
    doc: "emits power but starts no paths",
    params: DarkParams::SPECS,
};

fn dark(_: &Params, _: &lumis_core::LightShape) -> lumis_core::Result<Box<dyn Light>> {
    Ok(Box::new(Dark))
}

/// What particle tracing cannot render is refused at load, by name:
/// adaptive sampling, and a light that starts no paths.
#[test]
fn what_it_cannot_render_is_refused() {
    let adaptive = format!("{EVERY_LIGHT}\n[adaptive]\nmin_spp = 4\nthreshold = 0.05\n");
    let err = load_error(&adaptive.replace("type = \"path\"", "type = \"light\""));
    assert!(
        err.contains("[adaptive] cannot be used with integrator type 'light'"),
        "{err}"
    );
    let mut registry = builtin_registry().unwrap();
    registry.add_light(DARK, dark).unwrap();
    let toml = format!(
        "{}\n[[light]]\ntype = \"dark\"\n",
        EVERY_LIGHT.replace("type = \"path\"\nmax_depth = 4", "type = \"light\"")
    );
    let err = match lumis_scene::load_str(&toml, &scenes_dir().join("t.toml"), &[], &registry) {
        Ok(_) => panic!("a light without sample_le was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("integrator type 'light' traces paths from the lights, but light ")
            && err.contains("does not implement Light::sample_le"),
        "{err}"
    );
}
