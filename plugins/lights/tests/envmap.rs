//! The `envmap` light: `sample_li` draws directions with the density
//! `pdf_li` reports (chi-square) on smooth, spiky, sparse, single-texel and
//! large maps; that density is positive wherever the bilinear radiance is;
//! the map is oriented as Mitsuba's `envmap`, its coordinates are those
//! of the double-precision formulas; and bad files are refused
//! with errors naming the key and the file.

use std::path::Path;

use lumis_check::adapters::light_pair;
use lumis_check::{chi_square, corrected_significance, ChiSquareConfig, ChiSquareReport};
use lumis_core::doc;
use lumis_core::glam::Quat;
use lumis_core::{
    Light, LightInput, LightSampleContext, LightShape, Location, PluginEntity, PluginKind,
    Registry, Rgb, Vec2, Vec3,
};
use lumis_image::Image;
use lumis_lights::{EnvMapLight, EnvSampling, Equirect};
use lumis_sampling::Pcg32;

/// A map of `width x height` texels of luminance `f(x, y)` (grey).
fn map(width: usize, height: usize, f: impl Fn(usize, usize) -> f32) -> Equirect {
    let texels = (0..width * height)
        .map(|k| Rgb::splat(f(k % width, k / width)))
        .collect();
    Equirect::new(width, height, texels)
}

fn light(map: Equirect, to_world: Quat) -> EnvMapLight {
    sampled(map, to_world, EnvSampling::Importance)
}

fn sampled(map: Equirect, to_world: Quat, sampling: EnvSampling) -> EnvMapLight {
    let mut light = EnvMapLight::new(map, 1.0, to_world, sampling);
    light.preprocess(Vec3::ZERO, 2.0);
    light
}

/// A sky: a gradient brighter toward the top, and a sun.
fn smooth(width: usize, height: usize) -> Equirect {
    map(width, height, |x, y| {
        let (u, v) = (
            (x as f32 + 0.5) / width as f32,
            (y as f32 + 0.5) / height as f32,
        );
        1.0 + 4.0 * (1.0 - v) + 20.0 * (-40.0 * ((u - 0.3).powi(2) + (v - 0.3).powi(2))).exp()
    })
}

fn bright_texel(width: usize, height: usize) -> Equirect {
    map(width, height, |x, y| {
        if (x, y) == (width / 3, height / 4) {
            1000.0
        } else {
            0.01
        }
    })
}

/// Black but for one row: the rows of zero luminance must not be drawn.
fn lit_row(width: usize, height: usize) -> Equirect {
    map(
        width,
        height,
        |_, y| if y == height / 2 { 3.0 } else { 0.0 },
    )
}

fn run(name: &str, light: &dyn Light, cfg: &ChiSquareConfig) -> ChiSquareReport {
    let (sample, pdf) = light_pair(light, LightSampleContext::at(Vec3::new(0.1, 0.2, 0.3)));
    let report = chi_square(sample, pdf, cfg);
    assert!(
        report.passed,
        "{name}: p = {:.3e}, chi2 = {:.1} ({} dof), pdf integral {:.4}, {:?}",
        report.p_value,
        report.statistic,
        report.degrees_of_freedom,
        report.pdf_integral,
        report.defect
    );
    report
}

fn chi_square_all(cases: Vec<(&str, EnvMapLight)>, samples: usize) {
    let cfg = ChiSquareConfig {
        z_bins: 40,
        phi_bins: 80,
        samples,
        max_refinement: 8,
        integral_tolerance: 5e-3,
        significance: corrected_significance(0.01, cases.len()),
        ..Default::default()
    };
    for (name, light) in &cases {
        run(name, light, &cfg);
    }
}

#[test]
fn sample_li_draws_the_density_of_pdf_li() {
    let tilted = Quat::from_rotation_arc(Vec3::Y, Vec3::new(0.3, 0.5, -0.8).normalize())
        * Quat::from_rotation_y(0.7);
    chi_square_all(
        vec![
            ("smooth", light(smooth(32, 16), Quat::IDENTITY)),
            ("smooth, turned", light(smooth(32, 16), tilted)),
            ("bright texel", light(bright_texel(24, 12), Quat::IDENTITY)),
            ("one lit row", light(lit_row(16, 9), tilted)),
            ("1x1", light(map(1, 1, |_, _| 2.0), Quat::IDENTITY)),
            (
                "smooth, compensated",
                sampled(smooth(32, 16), Quat::IDENTITY, EnvSampling::Compensated),
            ),
        ],
        200_000,
    );
}

/// The size of a real sky map: run with
/// `cargo test -p lumis-lights --test envmap -- --ignored`.
#[test]
#[ignore = "a 8192x4096 map: seconds to build, minutes in a debug build"]
fn sample_li_draws_the_density_of_pdf_li_on_a_large_map() {
    chi_square_all(
        vec![
            (
                "smooth 8192x4096",
                light(smooth(8192, 4096), Quat::IDENTITY),
            ),
            (
                "bright texel 8192x4096",
                light(bright_texel(8192, 4096), Quat::IDENTITY),
            ),
        ],
        1_000_000,
    );
}

/// An unbiased estimator needs a density wherever there is radiance: the
/// bilinear lookup spreads a lit texel half way into its neighbours.
#[test]
fn pdf_is_positive_wherever_radiance_is() {
    let mut rng = Pcg32::new(5, 9);
    let sparse = map(
        16,
        8,
        |x, y| if (x * 7 + y * 3) % 11 == 0 { 1.0 } else { 0.0 },
    );
    let cases = [
        sparse,
        bright_texel(9, 5),
        lit_row(8, 6),
        map(1, 1, |_, _| 1.0),
    ];
    let ctx = LightSampleContext::at(Vec3::ZERO);
    for (k, m) in cases.into_iter().enumerate() {
        let light = light(m, Quat::IDENTITY);
        let mut lit = 0;
        for _ in 0..200_000 {
            let d = lumis_sampling::warp::square_to_uniform_sphere(Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            let l = light.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, d);
            let pdf = light.pdf_li(&ctx, d);
            assert!(pdf.is_finite() && pdf >= 0.0, "case {k}: pdf {pdf} at {d}");
            if l.luminance() > 0.0 {
                lit += 1;
                assert!(pdf > 0.0, "case {k}: radiance {l:?} but pdf 0 at {d}");
            }
        }
        assert!(lit > 0, "case {k} has radiance somewhere");
    }
}

#[test]
fn samples_carry_the_radiance_and_density_of_their_direction() {
    let light = light(bright_texel(24, 12), Quat::from_rotation_x(0.4));
    let ctx = LightSampleContext::at(Vec3::new(0.5, 0.0, 0.0));
    let mut rng = Pcg32::new(1, 2);
    for _ in 0..10_000 {
        let s = light
            .sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32()))
            .expect("a lit map always samples");
        let pdf = light.pdf_li(&ctx, s.wi);
        assert!((s.pdf - pdf).abs() <= 1e-3 * pdf, "{} vs {pdf}", s.pdf);
        let l = light.l(ctx.p(), Vec3::ZERO, Vec2::ZERO, s.wi);
        assert!(
            (s.l.r - l.r).abs() <= 1e-3 * l.r.max(1e-3),
            "{:?} vs {l:?}",
            s.l
        );
        // The shadow ray's end lies beyond the scene's bound.
        assert!(s.p.p.length() > 2.0);
    }
}

#[test]
fn a_black_map_samples_nothing() {
    let light = light(map(8, 4, |_, _| 0.0), Quat::IDENTITY);
    let ctx = LightSampleContext::at(Vec3::ZERO);
    assert!(light.sample_li(&ctx, Vec2::new(0.3, 0.6)).is_none());
    assert_eq!(light.pdf_li(&ctx, Vec3::Y), 0.0);
    assert_eq!(light.power(), Rgb::BLACK);
}

/// As Mitsuba's `envmap`: the top row looks along +y, `u = 1/4` along +x,
/// the image centre along +z, `u = 3/4` along -x.
#[test]
fn the_map_is_oriented_as_mitsubas() {
    // Distinct texels on the horizon row of a 4x3 map, and at the top.
    let m = map(4, 3, |x, y| {
        if y == 1 {
            1.0 + x as f32
        } else {
            10.0 * y as f32
        }
    });
    let light = light(m.clone(), Quat::IDENTITY);
    let l = |d: Vec3| light.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, d).r;
    // Texel centres of the middle row are at u = 1/8, 3/8, 5/8, 7/8;
    // `phi = 2 pi u` and `d = (sin phi, 0, -cos phi)`.
    for x in 0..4 {
        let phi = 2.0 * std::f32::consts::PI * (x as f32 + 0.5) / 4.0;
        let d = Vec3::new(phi.sin(), 0.0, -phi.cos());
        assert!(
            (l(d) - (1.0 + x as f32)).abs() < 1e-4,
            "texel {x}: {}",
            l(d)
        );
    }
    assert!((l(Vec3::Y) - 0.0).abs() < 1e-4);
    assert!((l(-Vec3::Y) - 20.0).abs() < 1e-4);
    // `up` turns the top row toward +z.
    let turned = self::light(m, Quat::from_rotation_arc(Vec3::Y, Vec3::Z));
    assert!((turned.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, -Vec3::Z).r - 20.0).abs() < 1e-4);
}

/// `uv_of` (two single-precision `atan2`s) and `direction_of` (sines in
/// turns) against the double-precision formulas: over a grid of `uv`
/// that takes in the poles (`v = 0, 1`), the seam (`u = 0, 1`) and the
/// texel edges of common map sizes, directions within 3e-7 and
/// coordinates within 1e-6 (`u` modulo 1, and any `u` at the poles);
/// `sin theta` within 3e-7.
#[test]
fn map_coordinates_match_double_precision_at_the_poles_and_the_seam() {
    let pi = std::f64::consts::PI;
    let n = 2048;
    let mut values: Vec<f32> = (0..=n).map(|k| k as f32 / n as f32).collect();
    values.extend([1e-7, 1e-5, 0.5 - 1e-7, 0.5 + 1e-7, 1.0 - 1e-7, 1.0 - 1e-5]);
    for &v in &values {
        for &u in values.iter().step_by(7).chain(&values[n..]) {
            let (theta, phi) = (pi * v as f64, 2.0 * pi * u as f64);
            let exact = [
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            ];
            let (d, sin_theta) = Equirect::direction_of(Vec2::new(u, v));
            for (got, exact) in d.to_array().iter().zip(exact) {
                assert!(
                    (*got as f64 - exact).abs() < 3e-7,
                    "direction_of({u}, {v}) = {d}, exact {exact:?}"
                );
            }
            assert!((sin_theta as f64 - theta.sin()).abs() < 3e-7);
            // Back from the exact direction rounded to f32.
            let exact = Vec3::new(exact[0] as f32, exact[1] as f32, exact[2] as f32);
            let (uv, sin_theta) = Equirect::uv_of(exact);
            assert!(
                (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
                "{uv}"
            );
            assert!(
                (uv.y - v).abs() < 1e-6,
                "uv_of({exact}) = {uv}, exact v {v}"
            );
            assert!((sin_theta as f64 - theta.sin()).abs() < 3e-7);
            let du = (uv.x - u).abs();
            let at_pole = theta.sin() < 1e-6;
            assert!(
                at_pole || du.min(1.0 - du) < 1e-6,
                "uv_of({exact}) = {uv}, exact u {u}"
            );
        }
    }
}

/// pbrt-v4's `Phi`: `pi r^2` times the integral of radiance over the
/// sphere, `4 pi L` for a constant map (what `constant` reports).
#[test]
fn power_of_a_constant_map_is_that_of_a_constant_light() {
    let light = light(map(16, 8, |_, _| 3.0), Quat::IDENTITY);
    let pi = std::f32::consts::PI;
    let expected = 4.0 * pi * pi * 2.0 * 2.0 * 3.0;
    assert!(
        (light.power().g - expected).abs() < 1e-3 * expected,
        "{:?}",
        light.power()
    );
}

fn registry() -> Registry {
    let mut registry = Registry::new();
    lumis_lights::register(&mut registry).unwrap();
    registry
}

/// The light a scene at `scene` declares with `table` (TOML).
fn from_scene(scene: &Path, table: &str) -> lumis_core::Result<Box<dyn Light>> {
    let table = doc::parse(table, &scene.to_string_lossy())?;
    let entity = PluginEntity::new(
        PluginKind::Light,
        "light \"sky\"",
        "envmap",
        table,
        Location::Builtin,
    );
    registry().create::<dyn Light>(&entity, LightInput::untextured(&LightShape::None))
}

fn write(path: &Path, width: usize, height: usize, texel: [f32; 3]) {
    let mut image = Image::new(width, height);
    for p in &mut image.pixels {
        *p = [0.5, 1.0, 2.0];
    }
    image.set(width - 1, height - 1, texel);
    lumis_image::write_exr(path, &image).unwrap();
}

#[test]
fn files_are_read_relative_to_the_scene_and_bad_ones_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    write(&dir.path().join("sky.exr"), 4, 2, [1.0; 3]);
    let light = from_scene(&scene, "filename = \"sky.exr\"\nscale = 2.0").unwrap();
    let l = light.l(
        Vec3::ZERO,
        Vec3::ZERO,
        Vec2::ZERO,
        Vec3::new(0.0, 0.7, -0.7).normalize(),
    );
    assert!((l.b - 4.0).abs() < 1e-5, "{l:?}");

    // A Radiance file: one flat scanline of two texels, 1.0 and 0.5 grey.
    let mut hdr = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
    hdr.extend([128, 128, 128, 129, 128, 128, 128, 128]);
    std::fs::write(dir.path().join("sky.hdr"), hdr).unwrap();
    let light = from_scene(&scene, "filename = \"sky.hdr\"").unwrap();
    let l = |d: Vec3| light.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, d).g;
    // Texel centres at u = 1/4 (+x) and 3/4 (-x).
    assert!((l(Vec3::X) - 1.0).abs() < 5e-3 && (l(-Vec3::X) - 0.5).abs() < 5e-3);
    std::fs::write(dir.path().join("broken.hdr"), "#?RADIANCE\n").unwrap();

    write(&dir.path().join("negative.exr"), 3, 2, [1.0, -1.0, 0.0]);
    write(&dir.path().join("nan.exr"), 3, 2, [f32::NAN, 0.0, 0.0]);
    std::fs::write(dir.path().join("text.exr"), "not an image").unwrap();
    for (file, expected) in [
        ("missing.exr", "missing.exr"),
        ("negative.exr", "texel (2, 1)"),
        ("nan.exr", "texel (2, 1)"),
        ("text.exr", "not a readable"),
        ("broken.hdr", "not a readable Radiance"),
    ] {
        let error = from_scene(&scene, &format!("filename = \"{file}\""))
            .err()
            .unwrap_or_else(|| panic!("{file} was accepted"))
            .to_string();
        assert!(
            error.contains("filename") && error.contains(file) && error.contains(expected),
            "{file}: {error}"
        );
    }
    for (table, key) in [
        ("filename = \"sky.exr\"\nscale = -1.0", "scale"),
        ("filename = \"sky.exr\"\nup = [0.0, 0.0, 0.0]", "up"),
        ("filename = \"sky.exr\"\nsampling = \"cosine\"", "sampling"),
    ] {
        let error = from_scene(&scene, table).err().expect(key).to_string();
        assert!(error.contains(key), "{key}: {error}");
    }
}

/// `integral of L cos / pi` over the hemisphere about +z of `light`'s map,
/// by the midpoint rule on 16 x 16 points per texel.
fn reflected_by_quadrature(light: &EnvMapLight, width: usize, height: usize) -> f64 {
    let (nu, nv) = (16 * width, 16 * height);
    let mut sum = 0.0;
    for j in 0..nv {
        for i in 0..nu {
            let uv = Vec2::new((i as f32 + 0.5) / nu as f32, (j as f32 + 0.5) / nv as f32);
            let (d, sin_theta) = Equirect::direction_of(uv);
            let l = light.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, d).g as f64;
            // d omega = 2 pi^2 sin theta du dv.
            sum += l * (d.z.max(0.0) as f64) * sin_theta as f64;
        }
    }
    sum * 2.0 * std::f64::consts::PI * std::f64::consts::PI
        / (nu * nv) as f64
        / std::f64::consts::PI
}

/// The radiance a white diffuse surface facing +z reflects, estimated
/// with one light sample and one cosine-weighted BSDF sample combined by
/// the balance heuristic (or, `mis` false, by light samples alone): mean
/// and standard error over `n` estimates.
fn reflected_by_sampling(light: &EnvMapLight, n: usize, mis: bool) -> (f64, f64) {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    let cosine_pdf = |d: Vec3| d.z.max(0.0) / std::f32::consts::PI;
    let mut rng = Pcg32::new(17, 4);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let mut f = 0.0f64;
        if let Some(s) = light.sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32())) {
            let p_bsdf = if mis { cosine_pdf(s.wi) } else { 0.0 };
            let weight = s.pdf / (s.pdf + p_bsdf);
            f += (s.l.g * cosine_pdf(s.wi) / s.pdf * weight) as f64;
        }
        if mis {
            let h = lumis_sampling::warp::square_to_cosine_hemisphere(Vec2::new(
                rng.next_f32(),
                rng.next_f32(),
            ));
            let p_bsdf = cosine_pdf(h);
            if p_bsdf > 0.0 {
                let l = light.l(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, h).g;
                let weight = p_bsdf / (p_bsdf + light.pdf_li(&ctx, h));
                f += (l * weight) as f64;
            }
        }
        sum += f;
        sum2 += f * f;
    }
    let mean = sum / n as f64;
    (mean, ((sum2 / n as f64 - mean * mean) / n as f64).sqrt())
}

/// Compensated sampling leaves the directions dimmer than the map's
/// average to BSDF sampling: with MIS the estimate is unbiased, with
/// light samples alone it misses their share.
#[test]
fn compensated_sampling_is_unbiased_under_mis_only() {
    let light = sampled(smooth(32, 16), Quat::IDENTITY, EnvSampling::Compensated);
    let expected = reflected_by_quadrature(&light, 32, 16);
    let (mis, se) = reflected_by_sampling(&light, 200_000, true);
    assert!(
        (mis - expected).abs() < 4.0 * se,
        "MIS {mis} +- {se} vs {expected}"
    );
    let (alone, se) = reflected_by_sampling(&light, 200_000, false);
    assert!(
        expected - alone > 10.0 * se,
        "light alone {alone} +- {se} vs {expected}"
    );
    let plain = sampled(smooth(32, 16), Quat::IDENTITY, EnvSampling::Importance);
    let (alone, se) = reflected_by_sampling(&plain, 200_000, false);
    assert!(
        (alone - expected).abs() < 4.0 * se,
        "importance {alone} +- {se} vs {expected}"
    );
}
