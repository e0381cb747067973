//! White-furnace tests: scenes whose exact answer is known.
//!
//! 1. A diffuse sphere of albedo 1 under constant environment radiance Le:
//!    every pixel is Le (energy conservation; the sphere is convex, so a
//!    reflected ray always escapes).
//! 2. A closed cube of emissive faces (radiance Le) with albedo a, seen from
//!    inside, Russian roulette off: the radiance is the truncated series
//!    Le (1 + a + ... + a^(D-1)) for max_depth D, which tends to Le / (1 - a).
//!    The same holds inside a sphere light whose normals face inward: the
//!    camera is inside the light, which is sampled from inside it.

use lumis_check::integrator_suite::CUBE_FACES;
use lumis_tests::{bonferroni_z, mean_and_se, render_toml};

/// The integrators that trace paths: the scalar one, the wavefront and the
/// packet one.
const PATH_TRACERS: [&str; 3] = ["path", "wavefront", "packet"];

/// 3 integrators x 3 strategies x 7 scenes x 3 channels, overall
/// false-alarm rate 1e-3.
fn z_limit() -> f64 {
    bonferroni_z(1e-3, 189)
}

fn check_uniform_image(toml: &str, strategy: &str, expected: [f64; 3]) {
    for integrator in PATH_TRACERS {
        let out = render_toml(
            toml,
            &[
                &format!("integrator.strategy={strategy}"),
                &format!("integrator.type=\"{integrator}\""),
            ],
            0,
        );
        assert_eq!(out.stats.nonfinite, 0);
        for (c, &want) in expected.iter().enumerate() {
            let values: Vec<f64> = out.image.pixels.iter().map(|p| p[c] as f64).collect();
            let (mean, se) = mean_and_se(&values);
            let tolerance = z_limit() * se + 1e-5 * want;
            assert!(
                (mean - want).abs() <= tolerance,
                "{integrator}, {strategy}: channel {c}: mean {mean} vs exact {want} (se {se})"
            );
        }
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

/// The bsdf, normals and emission of a closed emitter's surfaces: grey,
/// facing inward, radiance [1, 0.5, 0.25].
const INWARD_EMITTER: &str =
    "bsdf = \"grey\"\nflip_normals = true\nemission = { radiance = [1.0, 0.5, 0.25] }\n";

/// A scene seen from `origin` towards `target` inside a closed emitter of
/// albedo `albedo` (its shapes to follow, each with [`INWARD_EMITTER`]),
/// paths of up to `max_depth` segments, Russian roulette off.
fn inside_closed_emitter(
    origin: [f64; 3],
    target: [f64; 3],
    albedo: f64,
    max_depth: u32,
) -> String {
    format!(
        r#"
[film]
resolution = [16, 16]
[camera]
type = "perspective"
origin = {origin:?}
target = {target:?}
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
    )
}

/// Six outward-facing quads flipped to face the inside of [-s, s]^3,
/// offset by `shift` (to put the box far from the origin).
fn emissive_cube(albedo: f64, max_depth: u32, scale: f64, shift: f64) -> String {
    let at = |x: f64, y: f64, z: f64| [shift + x * scale, shift + y * scale, shift + z * scale];
    let mut toml = inside_closed_emitter(at(0.1, -0.2, 0.05), at(0.3, 0.1, 1.0), albedo, max_depth);
    let point = |a: [i32; 3]| format!("{:?}", a.map(|c| shift + c as f64 * scale));
    let edge = |a: [i32; 3]| format!("{:?}", a.map(|c| c as f64 * scale));
    for (corner, u, w) in CUBE_FACES {
        toml += &format!(
            "[[shape]]\ntype = \"quad\"\ncorner = {}\nedge_u = {}\nedge_v = {}\n{INWARD_EMITTER}",
            point(corner),
            edge(u),
            edge(w)
        );
    }
    toml
}

#[test]
fn closed_emissive_box_reproduces_the_neumann_series() {
    for (albedo, depth) in [(0.5f64, 8u32), (0.9, 60)] {
        let series: f64 = (0..depth).map(|k| albedo.powi(k as i32)).sum();
        let toml = emissive_cube(albedo, depth, 1.0, 0.0);
        for strategy in ["bsdf", "light", "mis"] {
            check_uniform_image(&toml, strategy, [series, 0.5 * series, 0.25 * series]);
        }
    }
}

/// The camera inside a sphere light (normals flipped to face the inside),
/// off its centre: every path bounces inside the emitter, so the image is
/// the closed box's series. From inside, the light is sampled uniformly by
/// area (the cone of a point inside is the whole sphere of directions), and
/// BSDF samples hit it everywhere; every strategy must agree.
#[test]
fn inside_a_sphere_light_the_image_is_the_series() {
    let (albedo, depth) = (0.6f64, 10u32);
    let series: f64 = (0..depth).map(|k| albedo.powi(k as i32)).sum();
    let mut toml = inside_closed_emitter([0.3, -0.2, 0.1], [0.5, 0.1, -1.0], albedo, depth);
    toml += &format!(
        "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n{INWARD_EMITTER}"
    );
    for strategy in ["bsdf", "light", "mis"] {
        check_uniform_image(&toml, strategy, [series, 0.5 * series, 0.25 * series]);
    }
}

/// The same closed box at 1e-4 and 1e5 units, and 100 units wide 1e4 units
/// from the origin:
/// self-intersection (acne) would lose energy and leaks would let paths
/// escape, both of which change the series. Ray origins are offset by
/// rounding-error bounds, not by a fixed epsilon, so every scale works.
#[test]
fn tiny_huge_and_far_scenes_have_no_acne_or_leaks() {
    let (albedo, depth) = (0.8f64, 12u32);
    let series: f64 = (0..depth).map(|k| albedo.powi(k as i32)).sum();
    for (scale, shift) in [(1e-4, 0.0), (1e5, 0.0), (100.0, 1e4)] {
        let toml = emissive_cube(albedo, depth, scale, shift);
        for strategy in ["bsdf", "light", "mis"] {
            check_uniform_image(&toml, strategy, [series, 0.5 * series, 0.25 * series]);
        }
    }
}

/// A smooth glass sphere (IOR 1.5) under constant radiance is invisible,
/// and with Russian roulette from the first bounce every path still
/// returns exactly the environment's radiance: each refraction scales the
/// throughput by `1/eta'^2` and the next one undoes it, so roulette judges
/// the throughput with that factor taken out (pbrt-v4's `etaScale`) and
/// never kills a path inside the glass. Judging the raw throughput would
/// keep the mean but kill 56% of the paths inside and double the survivors
/// (noise of the order of the radiance itself).
#[test]
fn roulette_does_not_kill_paths_inside_glass() {
    let toml = SPHERE_IN_FURNACE
        .replace(
            "type = \"diffuse\"\nreflectance = 1.0",
            "type = \"dielectric\"\nint_ior = 1.5",
        )
        .replace("max_depth = 16", "max_depth = 64\nrr_depth = 1");
    assert!(toml.contains("dielectric") && toml.contains("rr_depth = 1"));
    let expected = [0.5f32, 1.0, 2.0];
    for (strategy, integrator) in ["bsdf", "mis"]
        .into_iter()
        .flat_map(|s| PATH_TRACERS.map(|i| (s, i)))
    {
        let out = render_toml(
            &toml,
            &[
                &format!("integrator.strategy={strategy}"),
                &format!("integrator.type=\"{integrator}\""),
            ],
            0,
        );
        for p in &out.image.pixels {
            for c in 0..3 {
                assert!(
                    (p[c] - expected[c]).abs() <= 1e-4 * expected[c],
                    "{integrator}, {strategy}: pixel {p:?}, expected {expected:?}"
                );
            }
        }
    }
}
