//! Helpers shared by the end-to-end tests: render a scene given as TOML
//! text, and compare images with statistics rather than fixed tolerances.

pub mod gltf_writer;

use std::path::Path;

use lumis_core::Registry;
use lumis_image::Image;
use lumis_render::{render, RenderOutput, RenderSettings};

/// Loads `toml` (relative paths resolve against `scenes/`) with overrides
/// and renders it with the scene's own spp and seed.
pub fn render_toml(toml: &str, overrides: &[&str], threads: usize) -> RenderOutput {
    let registry = lumis_cli::builtin_registry().expect("built-in plugins register");
    render_toml_with(&registry, toml, overrides, threads)
}

/// [`render_toml`] with a given plugin registry.
pub fn render_toml_with(
    registry: &Registry,
    toml: &str,
    overrides: &[&str],
    threads: usize,
) -> RenderOutput {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let loaded = lumis_scene::load_str(
        toml,
        "test.toml",
        "test",
        &scenes_dir(),
        &overrides,
        registry,
    )
    .unwrap_or_else(|e| panic!("scene failed to load: {e}"));
    let settings = RenderSettings {
        spp: loaded.sampler.samples_per_pixel(),
        seed: loaded.seed,
        threads,
        progress: false,
    };
    render(
        &loaded.camera,
        &loaded.scene,
        loaded.integrator.as_ref(),
        loaded.sampler.as_ref(),
        &settings,
    )
    .expect("render succeeds")
}

/// The repository's `scenes/` directory.
pub fn scenes_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("scenes")
}

pub fn read_scene(name: &str) -> String {
    std::fs::read_to_string(scenes_dir().join(name)).expect("scene file exists")
}

/// Mean and standard error of the mean of `values`.
pub fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Compares two images of the same scene block by block: for each block and
/// channel, the mean of the per-pixel differences must be within `z`
/// standard errors of zero (pixels are independent estimates, so the
/// spread of the differences measures the noise of both images). Returns
/// the largest |z| seen; panics with the block if one exceeds `z`.
pub fn assert_same_mean(a: &Image, b: &Image, block: usize, z: f64, what: &str) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "{what}: sizes differ"
    );
    let mut worst = 0.0f64;
    for by in (0..a.height).step_by(block) {
        for bx in (0..a.width).step_by(block) {
            for c in 0..3 {
                let mut diffs = Vec::new();
                for y in by..(by + block).min(a.height) {
                    for x in bx..(bx + block).min(a.width) {
                        diffs.push(a.get(x, y)[c] as f64 - b.get(x, y)[c] as f64);
                    }
                }
                let (mean, se) = mean_and_se(&diffs);
                // Blocks where both images are exactly equal everywhere (e.g.
                // black) have se = 0 and mean = 0: nothing to test.
                if se == 0.0 {
                    assert_eq!(
                        mean, 0.0,
                        "{what}: block ({bx}, {by}) channel {c} differs by a constant"
                    );
                    continue;
                }
                let score = mean / se;
                worst = worst.max(score.abs());
                assert!(
                    score.abs() < z,
                    "{what}: block ({bx}, {by}) channel {c}: mean difference {mean:.5} is {score:.2} standard errors ({se:.5})"
                );
            }
        }
    }
    worst
}

/// A two-sided normal quantile for significance `alpha` shared among
/// `tests` comparisons (Bonferroni), by bisection on the normal tail.
pub fn bonferroni_z(alpha: f64, tests: usize) -> f64 {
    let target = alpha / tests as f64;
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if two_sided_tail(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// P(|Z| > z) for a standard normal Z, via erfc (Numerical Recipes' erfcc,
/// fractional error < 1.2e-7).
fn two_sided_tail(z: f64) -> f64 {
    let x = z / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.5 * x);
    t * (-x * x - 1.26551223
        + t * (1.00002368
            + t * (0.37409196
                + t * (0.09678418
                    + t * (-0.18628806
                        + t * (0.27886807
                            + t * (-1.13520398
                                + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
        .exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bonferroni_quantiles() {
        assert!((bonferroni_z(0.05, 1) - 1.96).abs() < 1e-3);
        assert!((bonferroni_z(0.01, 1) - 2.5758).abs() < 1e-3);
        assert!(bonferroni_z(0.01, 100) > 3.8);
    }
}
