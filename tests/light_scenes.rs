//! The Cornell boxes with a sphere light and with a triangle light, and the
//! estimator switches of `path` and `direct`: every estimator of the same
//! image agrees in the mean (BSDF-only, light-only, MIS balance and power;
//! direct lighting and full depth; n_f/n_g multi-sample and one-sample;
//! area and solid-angle light sampling; uniform, power and bvh light
//! selection).

use lumis_image::Image;
use lumis_tests::{assert_same_mean, bonferroni_z, read_scene, render_toml};

const BLOCK: usize = 16;

fn render(scene: &str, overrides: &[&str]) -> Image {
    let mut all = vec!["film.resolution=[64, 64]", "sampler.spp=64"];
    all.extend_from_slice(overrides);
    let out = render_toml(scene, &all, 0);
    assert_eq!(out.stats.nonfinite, 0, "{overrides:?}");
    assert!(out.image.pixels.iter().any(|p| p[0] > 0.0));
    out.image
}

/// `scene` with its `[integrator]` table replaced by `table`.
fn with_integrator(scene: &str, table: &str) -> String {
    let start = scene.find("[integrator]").expect("an [integrator] table");
    let end = scene[start + 1..]
        .find("\n[")
        .map(|i| start + 1 + i)
        .unwrap_or(scene.len());
    format!("{}{}\n{}", &scene[..start], table, &scene[end..])
}

/// Compares each image with the first, Bonferroni-corrected over all blocks.
fn agree(images: &[(String, Image)], tests_in_file: usize, what: &str) {
    let blocks = (64 / BLOCK) * (64 / BLOCK) * 3;
    let z = bonferroni_z(1e-3, tests_in_file * blocks);
    let (base_name, base) = &images[0];
    for (name, image) in &images[1..] {
        let worst = assert_same_mean(
            image,
            base,
            BLOCK,
            z,
            &format!("{what}: {name} vs {base_name}"),
        );
        eprintln!("{what}: {name} vs {base_name}: largest block |z| = {worst:.2}");
    }
}

/// Comparisons made by this file, for the Bonferroni correction.
const COMPARISONS: usize = 3 * 2 * 4 + 2 + 3 + 1 + 1 + 3;

fn strategies_agree(scene_file: &str) {
    let scene = read_scene(scene_file);
    for (depth, what) in [("2", "direct lighting"), ("8", "full depth")] {
        let depth = format!("integrator.max_depth={depth}");
        let mut images = Vec::new();
        for (i, (name, settings)) in [
            (
                "mis-power",
                ["integrator.strategy=mis", "integrator.heuristic=power"],
            ),
            (
                "bsdf",
                ["integrator.strategy=bsdf", "integrator.heuristic=power"],
            ),
            (
                "light",
                ["integrator.strategy=light", "integrator.heuristic=power"],
            ),
            (
                "mis-balance",
                ["integrator.strategy=mis", "integrator.heuristic=balance"],
            ),
            (
                "wavefront mis-power",
                ["integrator.type=\"wavefront\"", "integrator.strategy=mis"],
            ),
        ]
        .into_iter()
        .enumerate()
        {
            let seed = format!("seed={}", 10 + i);
            let mut o: Vec<&str> = settings.to_vec();
            o.push(&depth);
            o.push(&seed);
            images.push((name.to_string(), render(&scene, &o)));
        }
        agree(&images, COMPARISONS, &format!("{scene_file}, {what}"));
    }
}

#[test]
fn cornell_box_strategies_agree() {
    strategies_agree("cornell-box.toml");
}

#[test]
fn sphere_light_strategies_agree() {
    strategies_agree("cornell-box-sphere-light.toml");
}

#[test]
fn triangle_light_strategies_agree() {
    strategies_agree("cornell-box-triangle-light.toml");
}

/// `direct` is `path` stopped after two segments, for every estimator
/// setting: the default, more samples per strategy, and the one-sample
/// model.
#[test]
fn direct_integrator_matches_path_at_depth_two() {
    let scene = read_scene("cornell-box-sphere-light.toml");
    let path = render(&scene, &["integrator.max_depth=2", "seed=1"]);
    let direct = |table: &str, seed: &str| render(&with_integrator(&scene, table), &[seed]);
    let images = vec![
        ("path, max_depth 2".to_string(), path),
        (
            "direct".to_string(),
            direct("[integrator]\ntype = \"direct\"\n", "seed=2"),
        ),
        (
            "direct, n_f = 2, n_g = 3, balance".to_string(),
            direct(
                "[integrator]\ntype = \"direct\"\nn_f = 2\nn_g = 3\nheuristic = \"balance\"\n",
                "seed=3",
            ),
        ),
    ];
    agree(&images, COMPARISONS, "direct vs path");
}

/// The multi-sample counts and the one-sample estimator of the path tracer
/// are unbiased at full depth, and the counters say which strategy
/// contributed.
#[test]
fn sample_counts_and_one_sample_mis_agree() {
    let scene = read_scene("cornell-box-triangle-light.toml");
    let base = render(&scene, &["seed=21"]);
    let images = vec![
        ("default (n_f = n_g = 1)".to_string(), base),
        (
            "n_f = 1, n_g = 4".to_string(),
            render(&scene, &["integrator.n_g=4", "seed=22"]),
        ),
        (
            "n_f = 3, n_g = 1".to_string(),
            render(&scene, &["integrator.n_f=3", "seed=23"]),
        ),
        (
            "one-sample, balance, n_f : n_g = 1 : 2".to_string(),
            render(
                &scene,
                &[
                    "integrator.estimator=one-sample",
                    "integrator.heuristic=balance",
                    "integrator.n_g=2",
                    "seed=24",
                ],
            ),
        ),
    ];
    agree(&images, COMPARISONS, "sample counts");

    // Counting: light-only finds no emission by BSDF sampling after the
    // camera ray, BSDF-only takes no shadow rays, n_g = 4 takes four times
    // the shadow rays of n_g = 1 (up to rays saved by black BSDF values).
    let stats = |o: &[&str]| {
        let mut all = vec![
            "film.resolution=[32, 32]",
            "sampler.spp=4",
            "integrator.max_depth=2",
        ];
        all.extend_from_slice(o);
        render_toml(&scene, &all, 0).stats
    };
    let light = stats(&["integrator.strategy=light"]);
    let bsdf = stats(&["integrator.strategy=bsdf"]);
    let mis = stats(&[]);
    let mis4 = stats(&["integrator.n_g=4"]);
    assert_eq!(light.bsdf_light_hits, 0);
    assert!(light.light_samples > 0 && light.shadow_rays > 0);
    assert_eq!((bsdf.shadow_rays, bsdf.light_samples), (0, 0));
    assert!(bsdf.bsdf_light_hits > 0);
    assert!(mis.bsdf_light_hits > 0 && mis.light_samples > 0);
    let ratio = mis4.shadow_rays as f64 / mis.shadow_rays as f64;
    assert!((3.9..4.1).contains(&ratio), "{mis4:?} vs {mis:?}");
    assert_eq!(
        mis4.rays, mis.rays,
        "extra light samples trace no extra rays"
    );
}

/// Solid-angle and area sampling of the same lights render the same image;
/// so do uniform, power and bvh light selection.
#[test]
fn light_sampling_modes_agree() {
    let tri = read_scene("cornell-box-triangle-light.toml");
    let sphere = read_scene("cornell-box-sphere-light.toml");
    let area_tri = tri.replace("sampling = \"solid-angle\"", "sampling = \"area\"");
    let area_sphere = sphere.replace("sampling = \"solid-angle\"", "sampling = \"area\"");
    assert_ne!(area_tri, tri);
    assert_ne!(area_sphere, sphere);
    agree(
        &[
            ("triangle, solid angle".into(), render(&tri, &["seed=31"])),
            ("triangle, area".into(), render(&area_tri, &["seed=32"])),
        ],
        COMPARISONS,
        "triangle sampling",
    );
    agree(
        &[
            ("sphere, cone".into(), render(&sphere, &["seed=33"])),
            ("sphere, area".into(), render(&area_sphere, &["seed=34"])),
        ],
        COMPARISONS,
        "sphere sampling",
    );
    // Two lights of very different power: the sphere's and a dim point
    // light; power-proportional selection against uniform.
    let two = format!(
        "{sphere}\n[[light]]\ntype = \"point\"\nposition = [0.5, 0.5, 0.5]\nintensity = [0.05, 0.05, 0.05]\n"
    );
    agree(
        &[
            (
                "uniform".into(),
                render(&two, &["light_sampler.type=uniform", "seed=35"]),
            ),
            (
                "power".into(),
                render(&two, &["light_sampler.type=power", "seed=36"]),
            ),
            (
                "bvh".into(),
                render(&two, &["light_sampler.type=bvh", "seed=37"]),
            ),
        ],
        COMPARISONS,
        "light selection",
    );
}

/// A smooth plastic plane with a black base fills the view under constant
/// light: every pixel is the coat's Fresnel reflection of the light, found
/// only by BSDF samples of the specular lobe. With extra BSDF samples (n_f
/// = 3) the image must agree in the mean: the specular lobe's emission is
/// counted once, by the sample that continues the path, not again by each
/// extra sample, in `path` and in `direct`.
#[test]
fn extra_bsdf_samples_count_a_specular_lobe_once() {
    let scene = |integrator: &str| {
        format!(
            r#"
[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = [0.0, 0.0, 0.0]
target = [0.0, 0.0, -1.0]
fov = 40.0
[sampler]
type = "independent"
spp = 16
[integrator]
{integrator}
[[bsdf]]
name = "coat"
type = "plastic"
diffuse_reflectance = 0.0
[[shape]]
type = "quad"
corner = [-10.0, -10.0, -2.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
bsdf = "coat"
[[light]]
type = "constant"
radiance = [1.0, 1.0, 1.0]
"#
        )
    };
    for integrator in ["type = \"path\"\nmax_depth = 2", "type = \"direct\""] {
        let scene = scene(integrator);
        let images = vec![
            ("n_f = 1".to_string(), render(&scene, &["seed=41"])),
            (
                "n_f = 3".to_string(),
                render(&scene, &["integrator.n_f=3", "seed=42"]),
            ),
        ];
        agree(
            &images,
            COMPARISONS,
            &format!("{integrator}, smooth plastic"),
        );
    }
}
