//! Every sampler's randomisation keeps each sample uniform on `[0,1)^2`
//! (chi-square on a fine grid over many seeds) and depends on the seed.

use lumis_core::{Sampler, UVec2, Vec2};
use lumis_samplers::{
    HaltonSampler, HammersleySampler, IndependentSampler, PoissonDiskSampler, SobolDimensions,
    SobolRandomize, SobolSampler, StratifiedSampler, ZSobolSampler,
};
use lumis_sampling::{poisson_disk::max_packing_distance, DigitScramble};

const SPP: u32 = 16;

fn samplers() -> Vec<(&'static str, Box<dyn Sampler>)> {
    vec![
        ("independent", Box::new(IndependentSampler::new(SPP))),
        ("stratified", Box::new(StratifiedSampler::new(SPP, true))),
        (
            "halton owen",
            Box::new(HaltonSampler::new(SPP, DigitScramble::Owen)),
        ),
        (
            "halton digits",
            Box::new(HaltonSampler::new(SPP, DigitScramble::RandomDigits)),
        ),
        ("hammersley", Box::new(HammersleySampler::new(SPP))),
        (
            "sobol owen",
            SobolSampler::boxed(SPP, SobolRandomize::Owen, SobolDimensions::Sobol),
        ),
        (
            "sobol xor",
            SobolSampler::boxed(SPP, SobolRandomize::Xor, SobolDimensions::Sobol),
        ),
        (
            "sobol padded",
            SobolSampler::boxed(SPP, SobolRandomize::Owen, SobolDimensions::Padded),
        ),
        ("zsobol", Box::new(ZSobolSampler::new(SPP, true))),
        (
            "poisson-disk",
            Box::new(
                PoissonDiskSampler::new(SPP, 0.7 * max_packing_distance(SPP as usize)).unwrap(),
            ),
        ),
    ]
}

/// Dimension pairs probed: the film plane, the first pair after it and a
/// deep pair (bounce ~10 of a path).
const PAIRS: [usize; 3] = [0, 1, 20];

fn pair(s: &mut dyn Sampler, pixel: UVec2, index: u32, seed: u64, which: usize) -> Vec2 {
    s.start_pixel_sample(pixel, index, seed);
    let mut p = s.get_pixel_2d();
    for _ in 0..which {
        p = s.get_2d();
    }
    p
}

#[test]
fn every_sample_is_uniform_over_seeds() {
    let samplers = samplers();
    let indices = [0u32, 5, SPP - 1];
    let tests = samplers.len() * indices.len() * PAIRS.len();
    let alpha = lumis_check::corrected_significance(0.01, tests);
    let pixel = UVec2::new(13, 21);
    for (name, mut s) in samplers {
        for index in indices {
            for which in PAIRS {
                let points: Vec<[f32; 2]> = (0..40_000u64)
                    .map(|seed| pair(s.as_mut(), pixel, index, seed, which).to_array())
                    .collect();
                let report = lumis_check::uniformity_2d(&points, 20);
                assert!(
                    report.p_value > alpha,
                    "{name}, sample {index}, pair {which}: chi2 {} (dof {}), p {} < {alpha}",
                    report.statistic,
                    report.degrees_of_freedom,
                    report.p_value
                );
            }
        }
    }
}

#[test]
fn seeds_and_pixels_give_different_points() {
    for (name, mut s) in samplers() {
        for which in PAIRS {
            let base = pair(s.as_mut(), UVec2::new(1, 1), 3, 1, which);
            assert_ne!(
                base,
                pair(s.as_mut(), UVec2::new(1, 1), 3, 2, which),
                "{name} seed"
            );
            assert_ne!(
                base,
                pair(s.as_mut(), UVec2::new(2, 1), 3, 1, which),
                "{name} pixel"
            );
        }
    }
}

#[test]
fn samples_are_in_the_unit_square() {
    for (name, mut s) in samplers() {
        for index in 0..SPP {
            for which in 0..8 {
                let p = pair(s.as_mut(), UVec2::new(7, 7), index, 3, which);
                assert!(
                    p.cmpge(Vec2::ZERO).all() && p.cmplt(Vec2::ONE).all(),
                    "{name}: {p}"
                );
            }
        }
    }
}
