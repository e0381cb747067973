//! A diffuse plane lit by a rectangular area light and by a point light,
//! against the analytic answers.
//!
//! For a Lambertian surface of albedo rho, L = rho / pi * E. A rectangle of
//! radiance Le parallel to the plane gives E = pi Le F, with F the form
//! factor from a differential area to a parallel rectangle (Howell's
//! catalogue, configuration B-3; Cohen and Wallace 1993, appendix):
//! F(X, Y) = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))]
//! for a rectangle with one corner above the point (X = a/c, Y = b/c);
//! F is odd in X and Y, so any rectangle is a signed sum of four corners.

use lumis_tests::{bonferroni_z, mean_and_se, render_toml};

fn corner_factor(x: f64, y: f64) -> f64 {
    let sx = (1.0 + x * x).sqrt();
    let sy = (1.0 + y * y).sqrt();
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Form factor from the origin (normal +y) to the rectangle
/// [x0, x1] x [z0, z1] at height c.
fn form_factor(x0: f64, x1: f64, z0: f64, z1: f64, c: f64) -> f64 {
    let g = |x: f64, z: f64| corner_factor(x / c, z / c);
    g(x1, z1) - g(x0, z1) - g(x1, z0) + g(x0, z0)
}

const RHO: f64 = 0.8;

/// The plane y = 0 seen straight down through a very narrow camera, so
/// every pixel sees (almost exactly) the point at the origin.
fn scene(lights: &str) -> String {
    format!(
        r#"
[film]
resolution = [8, 8]
[camera]
type = "perspective"
origin = [0.0, 0.5, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
fov = 0.05
[sampler]
type = "independent"
spp = 512
[integrator]
type = "path"
max_depth = 2
[[bsdf]]
name = "plane"
type = "diffuse"
reflectance = {RHO}
[[bsdf]]
name = "black"
type = "diffuse"
reflectance = 0.0
[[shape]]
type = "quad"
corner = [-5.0, 0.0, -5.0]
edge_u = [0.0, 0.0, 10.0]
edge_v = [10.0, 0.0, 0.0]
bsdf = "plane"
{lights}
"#
    )
}

fn check(toml: &str, overrides: &[&str], expected: f64, z: f64) {
    let out = render_toml(toml, overrides, 0);
    let values: Vec<f64> = out.image.pixels.iter().map(|p| p[0] as f64).collect();
    let (mean, se) = mean_and_se(&values);
    assert!(
        (mean - expected).abs() <= z * se + 1e-4 * expected,
        "{overrides:?}: {mean} vs analytic {expected} (se {se})"
    );
}

#[test]
fn rectangle_light_matches_form_factor() {
    let (x0, x1, z0, z1, c, le) = (-0.3, 0.5, -0.2, 0.6, 1.0, 3.0);
    // Facing down: edge_u x edge_v = x cross z = -y.
    let light = format!(
        "[[shape]]\ntype = \"quad\"\ncorner = [{x0}, {c}, {z0}]\nedge_u = [{}, 0.0, 0.0]\nedge_v = [0.0, 0.0, {}]\nbsdf = \"black\"\nemission = {{ radiance = {le} }}\n",
        x1 - x0,
        z1 - z0
    );
    let toml = scene(&light);
    let expected = RHO * le * form_factor(x0, x1, z0, z1, c);
    let cases: [&[&str]; 5] = [
        &["integrator.strategy=bsdf"],
        &["integrator.strategy=light"],
        &["integrator.strategy=mis", "integrator.heuristic=balance"],
        &["integrator.strategy=mis", "integrator.heuristic=power"],
        &[
            "integrator.strategy=mis",
            "integrator.heuristic=power",
            "integrator.beta=3.0",
        ],
    ];
    // Each case with the scalar and the wavefront path tracer.
    let z = bonferroni_z(1e-3, 2 * cases.len() + 1);
    for overrides in cases {
        check(&toml, overrides, expected, z);
        let wavefront = [overrides, &["integrator.type=\"wavefront\""]].concat();
        check(&toml, &wavefront, expected, z);
    }
}

#[test]
fn point_light_matches_inverse_square_law() {
    let (px, py, pz, intensity) = (0.2f64, 1.0f64, 0.1f64, 2.0f64);
    let light = format!(
        "[[light]]\ntype = \"point\"\nposition = [{px}, {py}, {pz}]\nintensity = {intensity}\n"
    );
    let d2 = px * px + py * py + pz * pz;
    // L = rho/pi * I cos(theta) / d^2 with cos(theta) = py / d.
    let expected = RHO / std::f64::consts::PI * intensity * (py / d2.sqrt()) / d2;
    for integrator in ["path", "wavefront", "packet"] {
        let integrator = format!("integrator.type=\"{integrator}\"");
        check(
            &scene(&light),
            &["integrator.strategy=mis", &integrator],
            expected,
            5.0,
        );
    }
}
