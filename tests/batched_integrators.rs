//! The integrators that advance many paths at once (`wavefront`,
//! `packet`) against the scalar `path`: the same estimator, so the same
//! image bit for bit where every query keeps its scalar default, and the
//! same mean where packets and SIMD plugins round differently.

use lumis_render::{render, RenderOutput, RenderSettings};
use lumis_scene::LoadedScene;
use lumis_tests::{assert_same_mean, bonferroni_z, read_scene, render_toml, scenes_dir, Opaque};

/// Loads `scenes/<name>` with `overrides`.
fn load(name: &str, overrides: &[String]) -> LoadedScene {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let path = scenes_dir().join(name);
    lumis_scene::load_file(&path, overrides, &registry)
        .unwrap_or_else(|e| panic!("{overrides:?}: {e}"))
}

/// Renders `loaded` through [`Opaque`]: scalar scene queries, and the
/// integrator's own loop over `dyn Scene`.
fn render_opaque(loaded: &LoadedScene) -> RenderOutput {
    let settings = RenderSettings {
        spp: loaded.sampler.samples_per_pixel(),
        seed: loaded.seed,
        threads: 2,
        progress: false,
        clamp: loaded.clamp,
    };
    render(
        &loaded.camera,
        &Opaque(&loaded.scene),
        loaded.integrator.as_ref(),
        loaded.sampler.as_ref(),
        &settings,
    )
    .expect("render succeeds")
}

/// Each path draws its numbers and does its arithmetic in `path`'s order,
/// so with scalar scene queries the two integrators agree bit for bit, in
/// the image and in every counter: for each strategy, several light and
/// BSDF samples per vertex, the one-sample estimator, specular chains and
/// roulette (glass and plastic), the indirect clamp, waves that do not divide the samples, and
/// packets that refill only below five live lanes.
#[test]
fn same_image_as_path_bit_for_bit() {
    let (cornell, glass) = ("cornell-box.toml", "bench/glass-plastic.toml");
    for (scene, settings) in [
        (cornell, &["integrator.strategy=\"mis\""][..]),
        (cornell, &["integrator.strategy=\"bsdf\""]),
        (
            cornell,
            &["integrator.strategy=\"light\"", "integrator.n_g=3"],
        ),
        (cornell, &["integrator.n_f=3", "integrator.n_g=2"]),
        (cornell, &["integrator.estimator=\"one-sample\""]),
        (cornell, &["integrator.clamp_indirect=0.05"]),
        (glass, &["integrator.rr_depth=1"]),
    ] {
        let mut overrides = vec![
            "film.resolution=[40, 32]".to_string(),
            "sampler.spp=3".to_string(),
        ];
        overrides.extend(settings.iter().map(|s| s.to_string()));
        let path = render_opaque(&load(scene, &overrides));
        assert!(path.image.pixels.iter().any(|p| p[0] > 0.0));
        for batched in [
            &["integrator.type=\"wavefront\"", "integrator.wave_size=100"],
            &["integrator.type=\"packet\"", "integrator.refill_below=5"],
        ] {
            let overrides = [&overrides[..], &batched.map(String::from)].concat();
            let other = render_opaque(&load(scene, &overrides));
            assert_eq!(path.image, other.image, "{batched:?} {settings:?}");
            assert_eq!(path.stats, other.stats, "{batched:?} {settings:?}");
        }
    }
}

/// With Embree packets (`[accel] packets`) and the built-in plugins'
/// batched and lane overrides, the wavefront and packet images have the
/// same mean as `path`'s, block by block, on a diffuse and a glossy scene.
#[test]
fn same_mean_as_path_with_packets_and_simd() {
    let scenes = [
        ("cornell-box.toml", "film.resolution=[64, 64]"),
        ("bench/glossy-beckmann.toml", "film.resolution=[96, 64]"),
    ];
    let block = 16;
    let integrators = ["wavefront", "packet"];
    let z = bonferroni_z(1e-3, integrators.len() * scenes.len() * 4 * 6 * 3);
    for (name, resolution) in scenes {
        let scene = read_scene(name);
        let common = [resolution, "sampler.spp=16"];
        let path = render_toml(&scene, &[&common[..], &["seed=1"]].concat(), 0);
        for integrator in integrators {
            let other = render_toml(
                &scene,
                &[
                    &common[..],
                    &[
                        "seed=2",
                        &format!("integrator.type=\"{integrator}\""),
                        "accel.packets=true",
                    ],
                ]
                .concat(),
                0,
            );
            assert_eq!(other.stats.nonfinite, 0);
            assert_same_mean(&other.image, &path.image, block, z, name);
        }
    }
}

/// On every scene of the bench suite, through lumis's own scene (Embree's
/// packets, the built-in plugins' SIMD overrides), the wavefront and
/// packet images have the same mean as `path`'s, block by block. A scene
/// whose uncommitted asset under `scenes/bench/assets/` is missing (the
/// scanned mesh and the measured table, which the peer bench makes) is
/// skipped, and said so.
#[test]
fn same_mean_as_path_on_every_bench_scene() {
    let mut scenes: Vec<_> = std::fs::read_dir(scenes_dir().join("bench"))
        .expect("scenes/bench exists")
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    scenes.sort();
    assert!(scenes.len() >= 10, "{scenes:?}");
    let integrators = ["wavefront", "packet"];
    let block = 8;
    let z = bonferroni_z(1e-3, scenes.len() * integrators.len() * 4 * 3 * 3);
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let common = ["film.resolution=[32, 24]", "sampler.spp=16"];
    for scene in &scenes {
        let name = scene.file_name().unwrap().to_string_lossy().into_owned();
        let load = |extra: &[&str]| {
            let overrides: Vec<String> =
                common.iter().chain(extra).map(|s| s.to_string()).collect();
            lumis_scene::load_file(scene, &overrides, &registry)
        };
        let path = match load(&["seed=1"]) {
            Ok(loaded) => lumis_tests::render_loaded(&loaded, 2),
            Err(e) if e.to_string().contains("/assets/") => {
                println!("{name} skipped: its asset is not made ({e})");
                continue;
            }
            Err(e) => panic!("{name}: {e}"),
        };
        for integrator in integrators {
            let chosen = format!("integrator.type=\"{integrator}\"");
            let loaded = load(&["seed=2", &chosen]).unwrap_or_else(|e| panic!("{name}: {e}"));
            let other = lumis_tests::render_loaded(&loaded, 2);
            assert_eq!(other.stats.nonfinite, 0, "{name} {integrator}");
            assert_same_mean(
                &other.image,
                &path.image,
                block,
                z,
                &format!("{name} {integrator}"),
            );
        }
    }
}
