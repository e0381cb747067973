//! The path tracers' clamps (`clamp_direct`, `clamp_indirect`) trade
//! variance for bias, as they are meant to: renders of several seeds,
//! split into squared bias and variance against an unclamped reference.

use lumis_analysis::bias_variance::{bias_variance, Split};
use lumis_tests::{read_scene, render_toml};

/// Renders `scene` at 48x48 (or its own aspect) for seeds 0..8 at 16 spp
/// with `key` set to each of `caps` (`None`: unset), and splits each
/// set's relMSE against a 1024-spp unclamped render of another seed.
/// Returns the splits in the order of `caps`.
fn splits(scene: &str, resolution: &str, key: &str, caps: &[Option<f32>]) -> Vec<Split> {
    let scene = read_scene(scene);
    let render = |cap: Option<f32>, spp: u32, seed: u64| {
        let (spp, seed) = (format!("sampler.spp={spp}"), format!("seed={seed}"));
        let cap = cap.map(|c| format!("integrator.{key}={c}"));
        let mut overrides = vec![resolution, &spp, &seed];
        overrides.extend(cap.as_deref());
        render_toml(&scene, &overrides, 2).image
    };
    let reference = render(None, 1024, 1000);
    caps.iter()
        .map(|&cap| {
            let renders: Vec<_> = (0..8).map(|seed| render(cap, 16, seed)).collect();
            let renders: Vec<_> = renders.iter().collect();
            let split = bias_variance(&renders, &reference).unwrap().rel_mse;
            eprintln!(
                "{key} {cap:?}: bias² {:.3e} +- {:.1e}, variance {:.3e} +- {:.1e}",
                split.bias2, split.bias2_se, split.variance, split.variance_se
            );
            split
        })
        .collect()
}

/// As the cap comes down, bias² grows and the variance falls at every
/// step, and the strongest cap is beyond four standard errors of the
/// unclamped render on both counts (the standard errors are over pixels).
fn assert_trades(splits: &[Split]) {
    for pair in splits.windows(2) {
        assert!(
            pair[1].bias2 > pair[0].bias2,
            "bias² does not grow: {pair:?}"
        );
        assert!(
            pair[1].variance < pair[0].variance,
            "variance does not fall: {pair:?}"
        );
    }
    let (raw, strongest) = (&splits[0], &splits[splits.len() - 1]);
    let apart = |a: f64, b: f64, a_se: f64, b_se: f64| a - b > 4.0 * a_se.hypot(b_se);
    assert!(
        apart(strongest.bias2, raw.bias2, strongest.bias2_se, raw.bias2_se),
        "{splits:?}"
    );
    assert!(
        apart(
            raw.variance,
            strongest.variance,
            raw.variance_se,
            strongest.variance_se
        ),
        "{splits:?}"
    );
}

/// The Cornell box's indirect light.
#[test]
fn indirect_clamp_trades_variance_for_bias() {
    let caps = [None, Some(1.0), Some(0.3), Some(0.1)];
    let splits = splits(
        "cornell-box.toml",
        "film.resolution=[48, 48]",
        "clamp_indirect",
        &caps,
    );
    assert_trades(&splits);
}

/// The glossy plates' highlights: direct lighting only (`max_depth = 2`),
/// where the indirect clamp has nothing to cap.
#[test]
fn direct_clamp_trades_variance_for_bias() {
    let caps = [None, Some(3.0), Some(1.0), Some(0.3)];
    let splits = splits(
        "bench/glossy-beckmann.toml",
        "film.resolution=[72, 48]",
        "clamp_direct",
        &caps,
    );
    assert_trades(&splits);
}
