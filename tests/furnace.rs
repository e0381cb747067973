//! White-furnace tests: scenes whose exact answer is known.
//!
//! 1. A diffuse sphere of albedo 1 under constant environment radiance Le:
//!    every pixel is Le (energy conservation; the sphere is convex, so a
//!    reflected ray always escapes).
//! 2. A closed cube of emissive faces (radiance Le) with albedo a, seen from
//!    inside, Russian roulette off: the radiance is the truncated series
//!    Le (1 + a + ... + a^(D-1)) for max_depth D, which tends to Le / (1 - a).

use lumis_tests::{bonferroni_z, mean_and_se, render_toml};

/// 3 strategies x 3 scenes x 3 channels, overall false-alarm rate 1e-3.
fn z_limit() -> f64 {
    bonferroni_z(1e-3, 27)
}

fn check_uniform_image(toml: &str, strategy: &str, expected: [f64; 3]) {
    let out = render_toml(toml, &[&format!("integrator.strategy={strategy}")], 0);
    assert_eq!(out.stats.nonfinite, 0);
    for (c, &want) in expected.iter().enumerate() {
        let values: Vec<f64> = out.image.pixels.iter().map(|p| p[c] as f64).collect();
        let (mean, se) = mean_and_se(&values);
        let tolerance = z_limit() * se + 1e-5 * want;
        assert!(
            (mean - want).abs() <= tolerance,
            "{strategy}: channel {c}: mean {mean} vs exact {want} (se {se})"
        );
    }
}

const SPHERE_IN_FURNACE: &str = r#"
[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
fov = 40.0
[sampler]
type = "independent"
spp = 64
[integrator]
type = "path"
max_depth = 16
[[bsdf]]
name = "white"
type = "diffuse"
reflectance = 1.0
[[shape]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
bsdf = "white"
[[light]]
type = "constant"
radiance = [0.5, 1.0, 2.0]
"#;

#[test]
fn albedo_one_sphere_in_constant_light_is_invisible() {
    for strategy in ["bsdf", "light", "mis"] {
        check_uniform_image(SPHERE_IN_FURNACE, strategy, [0.5, 1.0, 2.0]);
    }
}

/// Six outward-facing quads flipped to face the inside of [-1, 1]^3.
fn emissive_cube(albedo: f64, max_depth: u32) -> String {
    let faces = [
        ([1, -1, -1], [0, 2, 0], [0, 0, 2]),
        ([-1, -1, -1], [0, 0, 2], [0, 2, 0]),
        ([-1, 1, -1], [0, 0, 2], [2, 0, 0]),
        ([-1, -1, -1], [2, 0, 0], [0, 0, 2]),
        ([-1, -1, 1], [2, 0, 0], [0, 2, 0]),
        ([-1, -1, -1], [0, 2, 0], [2, 0, 0]),
    ];
    let mut toml = format!(
        r#"
[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = [0.1, -0.2, 0.05]
target = [0.3, 0.1, 1.0]
fov = 100.0
[sampler]
type = "independent"
spp = 64
[integrator]
type = "path"
max_depth = {max_depth}
rr_depth = 100000
[[bsdf]]
name = "grey"
type = "diffuse"
reflectance = {albedo}
"#
    );
    let v = |a: [i32; 3]| format!("[{}.0, {}.0, {}.0]", a[0], a[1], a[2]);
    for (corner, u, w) in faces {
        toml += &format!(
            "[[shape]]\ntype = \"quad\"\ncorner = {}\nedge_u = {}\nedge_v = {}\nbsdf = \"grey\"\nflip_normals = true\nemission = {{ radiance = [1.0, 0.5, 0.25] }}\n",
            v(corner),
            v(u),
            v(w)
        );
    }
    toml
}

#[test]
fn closed_emissive_box_reproduces_the_neumann_series() {
    for (albedo, depth) in [(0.5f64, 8u32), (0.9, 60)] {
        let series: f64 = (0..depth).map(|k| albedo.powi(k as i32)).sum();
        let toml = emissive_cube(albedo, depth);
        for strategy in ["bsdf", "light", "mis"] {
            check_uniform_image(&toml, strategy, [series, 0.5 * series, 0.25 * series]);
        }
    }
}
