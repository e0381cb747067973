//! The `oidn` denoiser against images whose truth is known: it must find
//! the library, lower the error of a noisy constant, keep a gradient's mean,
//! and refuse bad input with errors that say what was expected.

use lumis_core::doc;
use lumis_core::entity::TYPE_KEY;
use lumis_core::{DenoiseInput, Denoiser, Location, PluginEntity, PluginKind, Registry};

const WIDTH: usize = 64;
const HEIGHT: usize = 64;

/// A uniform number in [0, 1) for pixel `i`, channel `c` (SplitMix64).
fn uniform(i: usize, c: usize) -> f32 {
    let mut z = (i as u64 * 3 + c as u64).wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

/// `truth` with the noise of a few-sample estimate: each pixel scaled by a
/// factor of mean 1 in [0.2, 1.8], independently per channel.
fn noisy(truth: &[[f32; 3]]) -> Vec<[f32; 3]> {
    truth
        .iter()
        .enumerate()
        .map(|(i, p)| std::array::from_fn(|c| p[c] * (0.2 + 1.6 * uniform(i, c))))
        .collect()
}

fn mse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] as f64 - q[c] as f64).powi(2)))
        .sum();
    sum / (3 * a.len()) as f64
}

fn mean(a: &[[f32; 3]]) -> [f64; 3] {
    std::array::from_fn(|c| a.iter().map(|p| p[c] as f64).sum::<f64>() / a.len() as f64)
}

fn denoiser(table: &str) -> lumis_core::Result<Box<dyn Denoiser>> {
    let mut registry = Registry::new();
    lumis_denoise::register(&mut registry)?;
    let table = doc::parse(table, "scene.toml")?;
    let entity = PluginEntity::from_table(
        PluginKind::Denoiser,
        "denoiser",
        table,
        Location::Builtin,
        TYPE_KEY,
    )?;
    registry.create::<dyn Denoiser>(&entity, ())
}

/// A flat grey albedo and a normal facing the camera.
fn aux() -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    (
        vec![[0.8, 0.8, 0.8]; WIDTH * HEIGHT],
        vec![[0.0, 0.0, 1.0]; WIDTH * HEIGHT],
    )
}

#[test]
fn the_provisioned_library_loads_and_reports_version_2() {
    let (major, minor, patch) = lumis_denoise::oidn_version().unwrap();
    println!("Open Image Denoise {major}.{minor}.{patch}");
    assert_eq!(major, 2, "expected Open Image Denoise 2.x");
}

#[test]
fn denoising_a_noisy_constant_lowers_its_error() {
    let truth = vec![[0.5, 0.3, 0.2]; WIDTH * HEIGHT];
    let color = noisy(&truth);
    let (albedo, normal) = aux();
    for (table, aux) in [
        ("type = \"oidn\"\n", true),
        ("type = \"oidn\"\nprefilter = false\n", true),
        ("type = \"oidn\"\nquality = \"fast\"\n", false),
    ] {
        let input = DenoiseInput {
            width: WIDTH,
            height: HEIGHT,
            color: &color,
            albedo: aux.then_some(&albedo[..]),
            normal: aux.then_some(&normal[..]),
        };
        let denoised = denoiser(table).unwrap().denoise(&input).unwrap();
        let (before, after) = (mse(&color, &truth), mse(&denoised, &truth));
        println!("{table:?}: MSE {before:.5} -> {after:.5}");
        assert!(
            denoised
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0),
            "{table:?}: non-finite or negative output"
        );
        assert!(
            after < before / 10.0,
            "{table:?}: MSE {before} -> {after}, expected at least 10x lower"
        );
    }
}

#[test]
fn denoising_a_noisy_gradient_keeps_its_mean() {
    let truth: Vec<[f32; 3]> = (0..WIDTH * HEIGHT)
        .map(|i| {
            let t = (i % WIDTH) as f32 / (WIDTH - 1) as f32;
            [0.1 + 0.9 * t, 0.5, 1.0 - 0.8 * t]
        })
        .collect();
    let color = noisy(&truth);
    let (albedo, normal) = aux();
    let input = DenoiseInput {
        width: WIDTH,
        height: HEIGHT,
        color: &color,
        albedo: Some(&albedo),
        normal: Some(&normal),
    };
    let denoised = denoiser("type = \"oidn\"\n")
        .unwrap()
        .denoise(&input)
        .unwrap();
    let (want, got) = (mean(&truth), mean(&denoised));
    println!("mean {want:?} -> {got:?}");
    for c in 0..3 {
        assert!(
            (got[c] - want[c]).abs() < 0.03 * want[c],
            "channel {c}: mean {} after denoising, expected {} within 3%",
            got[c],
            want[c]
        );
    }
    assert!(mse(&denoised, &truth) < mse(&color, &truth));
}

#[test]
fn bad_images_are_clear_errors() {
    let oidn = denoiser("type = \"oidn\"\n").unwrap();
    let color = vec![[0.5; 3]; WIDTH * HEIGHT];
    let (albedo, normal) = aux();
    let input = DenoiseInput {
        width: WIDTH,
        height: HEIGHT,
        color: &color,
        albedo: Some(&albedo[1..]),
        normal: Some(&normal),
    };
    let err = oidn.denoise(&input).unwrap_err().to_string();
    assert!(
        err.contains("albedo image has 4095 pixels, expected 4096"),
        "{err}"
    );

    let mut nan = color.clone();
    nan[WIDTH + 2][1] = f32::NAN;
    let input = DenoiseInput {
        color: &nan,
        albedo: None,
        normal: None,
        ..input
    };
    let err = oidn.denoise(&input).unwrap_err().to_string();
    assert!(
        err.contains("color image has a non-finite value") && err.contains("(2, 1)"),
        "{err}"
    );

    let input = DenoiseInput {
        width: 0,
        height: 0,
        color: &[],
        ..input
    };
    let err = oidn.denoise(&input).unwrap_err().to_string();
    assert!(err.contains("at least 1x1"), "{err}");
}

#[test]
fn unknown_types_and_parameters_are_named() {
    let err = denoiser("type = \"oidnn\"\n").err().unwrap().to_string();
    assert!(
        err.contains("unknown denoiser type \"oidnn\"") && err.contains("available: oidn"),
        "{err}"
    );
    let err = denoiser("type = \"oidn\"\nqualty = \"high\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("'qualty'"), "{err}");
    let err = denoiser("type = \"oidn\"\nquality = \"ultra\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("quality") && err.contains("high") && err.contains("fast"),
        "{err}"
    );
}
