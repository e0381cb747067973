//! `[film] aovs`, `[film] clamp` and `[adaptive]` through
//! `lumis render`: the outputs of an analytic scene, the variance output
//! against the spread of independent renders, what the clamp leaves alone,
//! and where adaptive sampling spends its samples.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use lumis_app::{builtin_registry, RenderArgs, RenderReport, Session};
use lumis_image::Image;
use lumis_render::Aov;

/// A diffuse quad of reflectance (0.2, 0.5, 0.8) in the plane z = 0,
/// facing the camera 3 units away along +z, lit by a sphere light beside
/// the camera; the narrow field of view keeps every camera ray within
/// 0.5 degrees of the axis.
const PLANE: &str = r#"
[film]
resolution = [8, 8]
aovs = ["albedo", "normal", "depth", "variance", "spp"]
[camera]
type = "perspective"
origin = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
fov = 1.0
[sampler]
type = "independent"
spp = 4
[integrator]
type = "path"
max_depth = 3
[[bsdf]]
name = "grey"
type = "diffuse"
reflectance = [0.2, 0.5, 0.8]
[[bsdf]]
name = "black"
type = "diffuse"
reflectance = 0.0
[[shape]]
type = "quad"
corner = [-10.0, -10.0, 0.0]
edge_u = [20.0, 0.0, 0.0]
edge_v = [0.0, 20.0, 0.0]
bsdf = "grey"
[[shape]]
type = "sphere"
center = [2.0, 0.0, 3.0]
radius = 1.0
bsdf = "black"
emission = { radiance = [4.0, 4.0, 4.0] }
"#;

fn render(dir: &Path, name: &str, seed: u64, set: &[&str]) -> RenderReport {
    render_on(dir, name, seed, set, 2)
}

fn render_on(dir: &Path, name: &str, seed: u64, set: &[&str], threads: usize) -> RenderReport {
    let scene = dir.join("plane.toml");
    if !scene.exists() {
        std::fs::write(&scene, PLANE).unwrap();
    }
    let args = RenderArgs {
        scene,
        seed: Some(seed),
        threads,
        output: Some(dir.join(format!("{name}.exr"))),
        set: set.iter().map(|s| s.to_string()).collect(),
        quiet: true,
        no_checkpoint: true,
        ..Default::default()
    };
    let registry = builtin_registry().unwrap();
    lumis_app::render(&args, &Session::silent(&registry, &AtomicBool::new(false))).unwrap()
}

fn aov(report: &RenderReport, aov: Aov) -> &Image {
    &report.aovs.iter().find(|(a, _)| *a == aov).unwrap().1
}

#[test]
fn the_outputs_of_a_plane_are_its_albedo_normal_and_distance() {
    let tmp = tempfile::tempdir().unwrap();
    let report = render(tmp.path(), "plane", 0, &[]);
    for p in &aov(&report, Aov::Albedo).pixels {
        // Cosine-weighted sampling of a Lambertian BSDF: f cos / pdf is
        // the reflectance in every sample.
        for (c, r) in [0.2, 0.5, 0.8].into_iter().enumerate() {
            assert!((p[c] - r).abs() < 1e-5, "albedo {p:?}");
        }
    }
    for p in &aov(&report, Aov::Normal).pixels {
        assert!(p[0].abs() < 1e-6 && p[1].abs() < 1e-6, "normal {p:?}");
        assert!((p[2].abs() - 1.0).abs() < 1e-6, "normal {p:?}");
    }
    // Within 0.5 degrees of the axis: 3 / cos(0.5°) < 3.0002.
    for p in &aov(&report, Aov::Depth).pixels {
        assert!(p[0] >= 3.0 - 1e-4 && p[0] < 3.0002, "depth {p:?}");
    }
    assert!(aov(&report, Aov::Spp).pixels.iter().all(|p| p[0] == 4.0));
    // The EXR holds the same values under the layers' channel names.
    let channels = lumis_image::read_exr_channels(&report.exr).unwrap();
    let mut names: Vec<&str> = channels.iter().map(|(n, _)| n.as_str()).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "B",
            "G",
            "R",
            "albedo.B",
            "albedo.G",
            "albedo.R",
            "depth.Z",
            "normal.X",
            "normal.Y",
            "normal.Z",
            "spp.Y",
            "variance.B",
            "variance.G",
            "variance.R"
        ]
    );
    let depth = &channels.iter().find(|(n, _)| n == "depth.Z").unwrap().1;
    let expected: Vec<f32> = aov(&report, Aov::Depth)
        .pixels
        .iter()
        .map(|p| p[0])
        .collect();
    assert_eq!(depth, &expected);
    // Without `aovs` the EXR is the colour alone, and the same colour.
    let plain = render(tmp.path(), "plain", 0, &["film.aovs=[]"]);
    assert!(plain.aovs.is_empty());
    assert_eq!(lumis_image::read_exr_channels(&plain.exr).unwrap().len(), 3);
    assert_eq!(plain.image, report.image);
}

/// The variance output of each render estimates the variance of its
/// pixel means; so does the spread of the means over independent renders.
/// Both are unbiased, so their per-pixel difference has mean zero: a
/// t-test over the pixels (independent samplers) at significance 1e-4.
#[test]
fn the_variance_output_matches_the_spread_of_independent_renders() {
    let tmp = tempfile::tempdir().unwrap();
    let renders: Vec<RenderReport> = (0..16)
        .map(|seed| render(tmp.path(), &format!("r{seed}"), seed + 1, &[]))
        .collect();
    let k = renders.len() as f64;
    let pixels = renders[0].image.pixels.len();
    let mut differences = Vec::new();
    for i in 0..pixels {
        for c in 0..3 {
            let means: Vec<f64> = renders
                .iter()
                .map(|r| r.image.pixels[i][c] as f64)
                .collect();
            let mean = means.iter().sum::<f64>() / k;
            let spread = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (k - 1.0);
            let predicted = renders
                .iter()
                .map(|r| aov(r, Aov::Variance).pixels[i][c] as f64)
                .sum::<f64>()
                / k;
            // Relative to the prediction, so that channels of different
            // brightness weigh alike.
            differences.push((spread - predicted) / predicted);
        }
    }
    let n = differences.len() as f64;
    let mean = differences.iter().sum::<f64>() / n;
    let sd = (differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let t = mean / (sd / n.sqrt());
    // Two-sided Student t quantile at 1e-4 with 191 degrees of freedom.
    assert!(t.abs() < 3.98, "t = {t} (mean relative difference {mean})");
}

#[test]
fn clamp_caps_each_sample_and_leaves_a_scene_below_it_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let plain = render(tmp.path(), "plain", 3, &["film.aovs=[]"]);
    let high = render(tmp.path(), "high", 3, &["film.aovs=[]", "film.clamp=1e30"]);
    assert_eq!(
        high.image, plain.image,
        "a cap above every sample changed the image"
    );
    let cap = 0.05;
    assert!(
        plain.image.pixels.iter().flatten().any(|&v| v > cap),
        "the scene never exceeds the cap: the test could not fail"
    );
    let clamped = render(
        tmp.path(),
        "clamped",
        3,
        &["film.aovs=[]", &format!("film.clamp={cap}")],
    );
    // A mean of samples that are each at most the cap.
    for p in &clamped.image.pixels {
        assert!(p.iter().all(|&v| v <= cap * (1.0 + 1e-6)), "{p:?}");
    }
}

/// The plane seen from further away: its edge crosses the image, so the
/// left columns see nothing (no noise at all) and the rest the lit plane.
const ADAPTIVE: [&str; 5] = [
    "camera.fov=40.0",
    "shape.0.corner=[0.0, -10.0, 0.0]",
    "film.resolution=[16, 8]",
    "sampler.spp=64",
    "adaptive={ min_spp = 8, threshold = 0.02 }",
];

#[test]
fn adaptive_sampling_stops_where_there_is_no_noise_and_is_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let report = render_on(tmp.path(), "one", 5, &ADAPTIVE, 1);
    let spp = aov(&report, Aov::Spp);
    let (mut empty, mut lit) = (Vec::new(), Vec::new());
    for (i, p) in spp.pixels.iter().enumerate() {
        // Pixel centres left of x = -0.15 (a margin for the boundary's
        // 3x3 neighbourhood) see no surface.
        match (i % 16, report.image.pixels[i]) {
            (x, _) if x < 5 => empty.push(p[0]),
            (x, colour) if x > 9 && colour[1] > 0.0 => lit.push(p[0]),
            _ => {}
        }
    }
    assert!(empty.iter().all(|&n| n == 8.0), "{empty:?}");
    let mean_lit = lit.iter().sum::<f32>() / lit.len() as f32;
    assert!(mean_lit > 16.0, "the lit plane took {lit:?}");
    assert!(spp.pixels.iter().all(|p| p[0] <= 64.0));
    // Decided between runs of samples: the same with two threads.
    let two = render_on(tmp.path(), "two", 5, &ADAPTIVE, 2);
    assert_eq!(two.image, report.image);
    assert_eq!(two.aovs, report.aovs);
}

/// Each pixel's mean over its own sample count agrees with a plain render
/// of 64 spp: a z-test of the image means, their variances from the
/// variance outputs, at significance 1e-4. (Stopping on the samples seen
/// biases the estimate slightly in theory; at this threshold it is far
/// below the noise.)
#[test]
fn adaptive_sampling_agrees_with_a_plain_render() {
    let tmp = tempfile::tempdir().unwrap();
    let adaptive = render(tmp.path(), "adaptive", 7, &ADAPTIVE);
    let plain = render(tmp.path(), "plain", 8, &ADAPTIVE[..4]);
    let n = adaptive.image.pixels.len() as f64;
    for c in 0..3 {
        let mean = |r: &RenderReport| r.image.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        let variance = |r: &RenderReport| {
            aov(r, Aov::Variance)
                .pixels
                .iter()
                .map(|p| p[c] as f64)
                .sum::<f64>()
                / (n * n)
        };
        let z = (mean(&adaptive) - mean(&plain)) / (variance(&adaptive) + variance(&plain)).sqrt();
        assert!(z.abs() < 3.89, "channel {c}: z = {z}");
    }
}
