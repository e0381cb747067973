//! What BSDF importance sampling buys, measured: the glossy plates of
//! `scenes/glossy-plates.toml` (GGX conductors of roughness 0.005 to 0.15
//! under Veach's four lights), direct lighting with BSDF sampling only, so
//! that the BSDF's sampler alone decides the error, at equal spp with the
//! conductor's `sampling` set to uniform hemisphere, cosine-weighted
//! hemisphere, the full normal distribution and the visible normals.
//!
//! The error of one image is measured against a converged render (MIS of
//! light and BSDF sampling at 64x the spp): the RMSE over a plate is the
//! square root of the squared error averaged over its pixels and over
//! independent runs, with the standard error from the spread of the runs.
//! (The variance across runs would not do: a baseline that finds a
//! highlight once in a million samples shows almost no variance in a few
//! runs, but its image misses the highlight, which the reference shows.)
//! The model's own sampling must win by a wide margin on the sharp plates.
//! The table of docs/src/studies/bsdfs.md ("What BSDF sampling buys") is
//! printed with `-- --nocapture`.

use lumis_image::Image;
use lumis_tests::{mean_and_se, read_scene, render_toml, shape_mask};

const WIDTH: usize = 192;
const HEIGHT: usize = 128;
const RUNS: u64 = 32;
const SPP: u32 = 4;
const ROUGHNESS: [f32; 4] = [0.005, 0.02, 0.05, 0.15];
const SAMPLINGS: [&str; 4] = ["uniform", "cosine", "full", "visible"];

fn render(overrides: &[String]) -> Image {
    let mut all = vec![
        format!("film.resolution=[{WIDTH}, {HEIGHT}]"),
        "integrator.strategy=bsdf".to_string(),
        "integrator.max_depth=2".to_string(),
    ];
    all.extend_from_slice(overrides);
    let refs: Vec<&str> = all.iter().map(String::as_str).collect();
    let out = render_toml(&read_scene("glossy-plates.toml"), &refs, 0);
    assert_eq!(out.stats.nonfinite, 0, "{overrides:?}");
    out.image
}

/// `RUNS` independent `SPP` images with every plate sampled by `sampling`.
fn runs(s: usize, sampling: &str) -> Vec<Image> {
    (0..RUNS)
        .map(|run| {
            let mut o: Vec<String> = (1..=4)
                .map(|p| format!("bsdf.plate-{p}.sampling={sampling}"))
                .collect();
            o.push(format!("sampler.spp={SPP}"));
            o.push(format!("seed={}", 1000 * s as u64 + run));
            render(&o)
        })
        .collect()
}

/// Squared error against `reference` over the pixels of `mask`, channels
/// averaged.
fn squared_error(image: &Image, reference: &Image, mask: &[bool]) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for ((p, r), _) in image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .zip(mask)
        .filter(|(_, &m)| m)
    {
        sum += (0..3)
            .map(|c| (p[c] as f64 - r[c] as f64).powi(2))
            .sum::<f64>()
            / 3.0;
        count += 1;
    }
    assert!(count > 200, "region too small: {count} pixels");
    sum / count as f64
}

#[test]
fn model_sampling_wins_on_sharp_lobes() {
    let reference = render(&[
        "integrator.strategy=mis".to_string(),
        format!("sampler.spp={}", 64 * SPP),
        "seed=99999".to_string(),
    ]);
    let runs: Vec<Vec<Image>> = SAMPLINGS
        .iter()
        .enumerate()
        .map(|(s, name)| runs(s, name))
        .collect();
    let masks: Vec<Vec<bool>> = (0..4).map(|i| shape_mask(render, i)).collect();
    println!(
        "RMSE of one {SPP}-spp image against a {}-spp MIS render, BSDF sampling only, direct lighting, {WIDTH}x{HEIGHT}, {RUNS} runs per strategy",
        64 * SPP
    );
    println!("| plate (GGX roughness) | uniform | cosine | full D cos | visible normals | cosine / visible |");
    println!("| --- | --- | --- | --- | --- | --- |");
    let mut rows = Vec::new();
    for (i, mask) in masks.iter().enumerate() {
        // RMSE = sqrt(MSE); its standard error by the delta method.
        let r: Vec<(f64, f64)> = runs
            .iter()
            .map(|e| {
                let errors: Vec<f64> = e
                    .iter()
                    .map(|im| squared_error(im, &reference, mask))
                    .collect();
                let (mse, se) = mean_and_se(&errors);
                let rmse = mse.sqrt();
                (rmse, se / (2.0 * rmse))
            })
            .collect();
        let cells: Vec<String> = r
            .iter()
            .map(|(v, se)| format!("{v:.4} ± {se:.4}"))
            .collect();
        println!(
            "| {} ({}) | {} | {:.1} |",
            i + 1,
            ROUGHNESS[i],
            cells.join(" | "),
            r[1].0 / r[3].0
        );
        rows.push(r);
    }
    // On the three sharpest plates the model's sampling is at least 5x
    // better than either hemisphere baseline, by more than two standard
    // errors of the margin, so noise cannot make this pass.
    for (i, r) in rows.iter().enumerate().take(3) {
        for baseline in [r[0], r[1]] {
            for model in [r[2], r[3]] {
                let margin = baseline.0 - 5.0 * model.0;
                let se = (baseline.1.powi(2) + 25.0 * model.1.powi(2)).sqrt();
                assert!(
                    margin > 2.0 * se,
                    "plate {}: model RMSE {:.4} +- {:.4} is not 5x below {:.4} +- {:.4}",
                    i + 1,
                    model.0,
                    model.1,
                    baseline.0,
                    baseline.1
                );
            }
        }
    }
}
