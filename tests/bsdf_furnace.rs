//! A white furnace per BSDF: a unit sphere of the material inside uniform
//! emission of radiance 1, seen from 4 radii away.
//!
//! Every pixel looks either at the emission (radiance 1) or at the sphere,
//! whose radiance there is the directional albedo `E(mu)` of the material
//! at `mu = cos theta_o` (the sphere is convex: a reflected ray escapes).
//! For the box filter the image mean is an integral over the film plane,
//! and by the sphere's symmetry an integral over `mu` alone (with `k =
//! (R/D)^2` and `t = tan(fov/2)` for the square image):
//!
//! mean = 1 - (2 pi k / (4 t^2)) int_0^1 (1 - E(mu)) mu / (1 - k (1 - mu^2))^2 dmu
//!
//! (the film point at angle `gamma` from the axis sees the sphere at `sin
//! gamma = sqrt(k (1 - mu^2))`, and `rho drho = k mu / cos^4 gamma dmu`).
//!
//! - Models that conserve energy exactly (diffuse of albedo 1, a perfect
//!   mirror, smooth glass, smooth plastic of base albedo 1 in the linear
//!   mode) must render 1 everywhere.
//! - Single-scattering microfacet models (rough conductor with Fresnel = 1,
//!   Blinn, rough plastic) lose the energy that would scatter more than
//!   once between the facets; the render must match `E(mu)` integrated by
//!   quadrature of the model's `f` over half vectors, an estimate that
//!   shares nothing with `sample_f`, `pdf`, the light or the integrator.
//! - Rough glass must not create energy.
//!
//! The rendered means come from independent seeds, so their spread gives
//! the standard error; the threshold is Student's t, Bonferroni-corrected
//! over the cases. The albedo table of docs/src/studies/bsdfs.md ("White
//! furnace") is printed with `-- --nocapture`.

use std::f64::consts::PI;

use lumis_check::bsdf_suite::{instantiate, variant};
use lumis_check::quadrature::{gauss_legendre, integrate};
use lumis_core::{Bsdf, BsdfContext, Vec3};
use lumis_tests::{mean_and_se, render_toml};
use statrs::distribution::{ContinuousCDF, StudentsT};

const DISTANCE: f64 = 4.0;
const FOV_DEGREES: f64 = 30.0;
const RESOLUTION: usize = 48;
const SPP: u32 = 16;
const SEEDS: u64 = 16;
/// Gauss-Legendre nodes per panel in theta_m (4x as many in phi_m).
const QUADRATURE_NODES: usize = 48;
/// Quadrature error allowed on top of the noise.
const QUADRATURE_TOLERANCE: f64 = 2e-4;

/// What the furnace must show.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    /// Radiance 1 everywhere: the model conserves energy exactly.
    One,
    /// The albedo integrated by quadrature; `width` is the angular scale
    /// of the lobe in half-vector space, where the quadrature concentrates.
    Quadrature { width: f64 },
    /// At most 1: the model may lose energy but must not create it.
    AtMostOne,
}

struct Case {
    bsdf: &'static str,
    params: String,
    expect: Expect,
}

fn case(bsdf: &'static str, params: impl Into<String>, expect: Expect) -> Case {
    Case {
        bsdf,
        params: params.into(),
        expect,
    }
}

fn cases() -> Vec<Case> {
    let mut cases = vec![
        case("diffuse", "reflectance = 1.0", Expect::One),
        // A constant albedo: checks the geometry of the image mean.
        case(
            "diffuse",
            "reflectance = 0.5",
            Expect::Quadrature { width: 1.0 },
        ),
        case("mirror", "", Expect::One),
        case("dielectric", "int_ior = 1.5", Expect::One),
        case("plastic", "diffuse_reflectance = 1.0", Expect::One),
    ];
    for distribution in ["ggx", "beckmann"] {
        for alpha in [0.01, 0.1, 0.3, 0.5, 0.7, 1.0] {
            cases.push(case(
                "conductor",
                format!("distribution = \"{distribution}\"\nroughness = {alpha:?}"),
                Expect::Quadrature { width: alpha },
            ));
        }
    }
    for n in [10.0f64, 100.0, 1000.0] {
        cases.push(case(
            "blinn",
            format!("exponent = {n:?}"),
            Expect::Quadrature {
                width: (2.0 / (n + 2.0)).sqrt(),
            },
        ));
    }
    for alpha in [0.1, 0.5] {
        cases.push(case(
            "plastic",
            format!("diffuse_reflectance = 1.0\nroughness = {alpha:?}"),
            Expect::Quadrature { width: alpha },
        ));
        cases.push(case(
            "dielectric",
            format!("int_ior = 1.5\nroughness = {alpha:?}"),
            Expect::AtMostOne,
        ));
    }
    cases
}

fn scene(case: &Case) -> String {
    format!(
        r#"
[film]
resolution = [{RESOLUTION}, {RESOLUTION}]
[camera]
type = "perspective"
origin = [0.0, 0.0, {DISTANCE:?}]
target = [0.0, 0.0, 0.0]
fov = {FOV_DEGREES:?}
[sampler]
type = "independent"
spp = {SPP}
[integrator]
type = "path"
max_depth = 16
rr_depth = 16
[[bsdf]]
name = "material"
type = "{}"
{}
[[shape]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
bsdf = "material"
[[light]]
type = "constant"
radiance = 1.0
"#,
        case.bsdf, case.params
    )
}

/// `E(mu) = int f(wo, wi) cos theta_i dwi` by tensor Gauss-Legendre
/// quadrature over `(theta_i, phi_i)` of the upper hemisphere, in panels
/// graded geometrically away from the lobe around the mirror direction
/// (`theta_r = theta_o`, `phi = pi`). A half vector tilted by `delta` moves
/// `wi` by `2 delta` in elevation but only `2 mu delta` sideways, so the
/// lobe is `12 width` tall and `12 mu width / sin theta_r` wide in `phi`:
/// it is resolved however narrow, and no panel straddles the horizon.
fn albedo(bsdf: &dyn Bsdf, mu: f64, width: f64, nodes: usize) -> f64 {
    let ctx = BsdfContext::default();
    let wo = Vec3::new((1.0 - mu * mu).sqrt() as f32, 0.0, mu as f32);
    let theta_r = mu.acos();
    let spread = 6.0 * width;
    let theta_edges = graded_edges(theta_r, 2.0 * spread, 0.0, 0.5 * PI);
    let phi_half = 2.0 * mu * spread / theta_r.sin().max(1e-12);
    let phi_edges = graded_edges(PI, phi_half, 0.0, 2.0 * PI);
    let rule = gauss_legendre(nodes);
    let mut total = 0.0;
    for t in theta_edges.windows(2) {
        for p in phi_edges.windows(2) {
            let (tm, th) = (0.5 * (t[0] + t[1]), 0.5 * (t[1] - t[0]));
            let (pm, ph) = (0.5 * (p[0] + p[1]), 0.5 * (p[1] - p[0]));
            for &(x, wx) in &rule {
                let theta = tm + th * x;
                for &(y, wy) in &rule {
                    let phi = pm + ph * y;
                    let wi = Vec3::new(
                        (theta.sin() * phi.cos()) as f32,
                        (theta.sin() * phi.sin()) as f32,
                        theta.cos() as f32,
                    );
                    let f = bsdf.f(&ctx, wo, wi).g as f64;
                    total += wx * wy * th * ph * f * theta.cos() * theta.sin();
                }
            }
        }
    }
    total
}

/// Panel edges on `[lo, hi]`: `centre +- half 4^j` for `j = 0, 1, ...`,
/// so that panels grow geometrically away from a feature of size `half`.
fn graded_edges(centre: f64, half: f64, lo: f64, hi: f64) -> Vec<f64> {
    let mut edges = vec![lo, hi];
    let mut d = half.max(1e-9);
    while d < hi - lo {
        edges.extend(
            [centre - d, centre + d]
                .into_iter()
                .filter(|&e| e > lo && e < hi),
        );
        d *= 4.0;
    }
    edges.sort_by(f64::total_cmp);
    edges.dedup();
    edges
}

/// `k = (R/D)^2` and `t = tan(fov/2)` of the module docs.
fn geometry() -> (f64, f64) {
    (
        1.0 / (DISTANCE * DISTANCE),
        (0.5 * FOV_DEGREES).to_radians().tan(),
    )
}

/// The image mean for the sphere's albedo `e(mu)` (module docs).
fn image_mean(e: impl Fn(f64) -> f64) -> f64 {
    let (k, t) = geometry();
    let lost = integrate(
        |mu| (1.0 - e(mu)) * mu / (1.0 - k * (1.0 - mu * mu)).powi(2),
        0.0,
        1.0,
        32,
    );
    1.0 - 2.0 * PI * k / (4.0 * t * t) * lost
}

/// The fraction of the film the sphere covers: its disk `pi tan^2
/// gamma_max = pi k / (1 - k)` over the film's `4 t^2`.
fn disk_fraction() -> f64 {
    let (k, t) = geometry();
    PI * k / (1.0 - k) / (4.0 * t * t)
}

/// The mean radiance of the sphere's disk for an image mean `m`.
fn sphere_radiance(m: f64) -> f64 {
    1.0 - (1.0 - m) / disk_fraction()
}

/// Image means of `SEEDS` independent renders; each case has seeds of its
/// own (`first_seed..`), so that the cases' errors are independent too.
fn rendered_means(case: &Case, first_seed: u64) -> Vec<f64> {
    let toml = scene(case);
    (first_seed..first_seed + SEEDS)
        .map(|seed| {
            let out = render_toml(&toml, &[&format!("seed={seed}")], 0);
            assert_eq!(out.stats.nonfinite, 0, "{} {}", case.bsdf, case.params);
            let sum: f64 = out
                .image
                .pixels
                .iter()
                .map(|p| p.iter().map(|&c| c as f64).sum::<f64>() / 3.0)
                .sum();
            sum / out.image.pixels.len() as f64
        })
        .collect()
}

#[test]
fn every_bsdf_in_the_white_furnace() {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let cases = cases();
    // Two-sided, family-wise false alarm rate 1e-3 over all cases.
    let tail = 1e-3 / (2.0 * cases.len() as f64);
    let t_limit = StudentsT::new(0.0, 1.0, (SEEDS - 1) as f64)
        .unwrap()
        .inverse_cdf(1.0 - tail);
    println!(
        "sphere radiance in a white furnace ({RESOLUTION}x{RESOLUTION}, {SPP} spp x {SEEDS} seeds)"
    );
    println!("| bsdf | parameters | rendered | expected | (rendered - expected) / se |");
    println!("| --- | --- | --- | --- | --- |");
    let mut failures = Vec::new();
    for (i, case) in cases.iter().enumerate() {
        let (mean, se) = mean_and_se(&rendered_means(case, i as u64 * SEEDS));
        let expected = match case.expect {
            Expect::One | Expect::AtMostOne => 1.0,
            Expect::Quadrature { width } => {
                let v = variant(case.bsdf, &case.params).unwrap();
                let bsdf = instantiate(&registry, case.bsdf, &v).unwrap();
                image_mean(|mu| albedo(bsdf.as_ref(), mu, width, QUADRATURE_NODES))
            }
        };
        let z = (mean - expected) / se.max(1e-12);
        let label = case.params.replace('\n', ", ");
        let expected_text = match case.expect {
            Expect::AtMostOne => "<= 1".to_string(),
            _ => format!("{:.4}", sphere_radiance(expected)),
        };
        println!(
            "| {} | {} | {:.4} ± {:.4} | {} | {:+.2} |",
            case.bsdf,
            label,
            sphere_radiance(mean),
            se / disk_fraction(),
            expected_text,
            z
        );
        let tolerance = t_limit * se + QUADRATURE_TOLERANCE;
        let ok = match case.expect {
            Expect::AtMostOne => mean <= expected + tolerance,
            _ => (mean - expected).abs() <= tolerance,
        };
        if !ok {
            failures.push(format!(
                "{} [{label}]: image mean {mean:.5} +- {se:.5}, expected {expected_text} ({:.5})",
                case.bsdf, expected
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The quadrature that the furnace trusts is exact where the answer is
/// known (a white diffuse BSDF has `E = 1` at every angle) and converged
/// where it is not (doubling the nodes changes nothing that matters).
#[test]
fn the_albedo_quadrature_is_converged() {
    let registry = lumis_app::builtin_registry().expect("built-in plugins register");
    let bsdf = |name: &str, params: &str| {
        instantiate(&registry, name, &variant(name, params).unwrap()).unwrap()
    };
    let white = bsdf("diffuse", "reflectance = 1.0");
    let glossy = bsdf("conductor", "roughness = 0.01");
    let rough = bsdf("conductor", "distribution = \"beckmann\"\nroughness = 0.7");
    for mu in [1e-3, 0.05, 0.3, 0.7, 1.0] {
        let e = albedo(white.as_ref(), mu, 1.0, QUADRATURE_NODES);
        assert!((e - 1.0).abs() < 1e-5, "diffuse at mu {mu}: {e}");
        for (bsdf, width) in [(&glossy, 0.01), (&rough, 0.7)] {
            let coarse = albedo(bsdf.as_ref(), mu, width, QUADRATURE_NODES);
            let fine = albedo(bsdf.as_ref(), mu, width, 2 * QUADRATURE_NODES);
            // At grazing the horizon cuts a narrow lobe sharply, which
            // costs the rule digits; those angles weigh ~mu in the image.
            let tolerance = if mu < 0.01 { 1e-4 } else { 1e-5 };
            assert!(
                (coarse - fine).abs() < tolerance,
                "mu {mu}: {coarse} vs {fine}"
            );
        }
    }
    // A constant albedo c darkens exactly the sphere's share of the film.
    let m = image_mean(|_| 0.25);
    assert!((m - (1.0 - 0.75 * disk_fraction())).abs() < 1e-12, "{m}");
}
