//! The ranking the theory predicts, measured: low-discrepancy sets (Halton,
//! Sobol', Hammersley) below jittered stratification, below independent
//! random points, in L2-star discrepancy at equal N >= 256.

use lumis_analysis::{l2_star_discrepancy, sample_points};
use lumis_core::{Sampler, UVec2};
use lumis_samplers::{
    HaltonSampler, HammersleySampler, IndependentSampler, SobolDimensions, SobolRandomize,
    SobolSampler, StratifiedSampler,
};
use lumis_sampling::DigitScramble;

const SEEDS: u64 = 24;

/// Discrepancy of the film-plane points of one pixel for each seed.
fn discrepancies(sampler: &mut dyn Sampler, n: u32) -> Vec<f64> {
    (0..SEEDS)
        .map(|seed| l2_star_discrepancy(&sample_points(sampler, n, 2, seed, UVec2::new(3, 5))))
        .collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Every seed of the better class beats every seed of the worse one, and
/// the means differ by at least a factor 1.5: with 24 seeds each, complete
/// separation by chance alone has probability 1 / C(48, 24) ~ 3e-14.
fn assert_below(better: &[f64], worse: &[f64], what: &str) {
    let worst_better = better.iter().cloned().fold(0.0, f64::max);
    let best_worse = worse.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(
        worst_better < best_worse && 1.5 * mean(better) < mean(worse),
        "{what}: {:.3e} (max {worst_better:.3e}) vs {:.3e} (min {best_worse:.3e})",
        mean(better),
        mean(worse)
    );
}

#[test]
fn low_discrepancy_below_jittered_below_independent() {
    for n in [256u32, 1024, 4096] {
        let independent = discrepancies(&mut IndependentSampler::new(n), n);
        let jittered = discrepancies(&mut StratifiedSampler::new(n, true), n);
        assert_below(
            &jittered,
            &independent,
            &format!("stratified vs independent, N {n}"),
        );
        let low: [(&str, Box<dyn Sampler>); 3] = [
            (
                "halton",
                Box::new(HaltonSampler::new(n, DigitScramble::Owen)),
            ),
            (
                "sobol",
                SobolSampler::boxed(n, SobolRandomize::Owen, SobolDimensions::Sobol),
            ),
            ("hammersley", Box::new(HammersleySampler::new(n))),
        ];
        for (name, mut sampler) in low {
            let d = discrepancies(sampler.as_mut(), n);
            assert_below(&d, &jittered, &format!("{name} vs stratified, N {n}"));
        }
    }
}
