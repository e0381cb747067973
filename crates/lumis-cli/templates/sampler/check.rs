//! Checks the two promises of a stratified sampler: every stratum of every
//! dimension holds exactly one of a pixel's samples, and each sample is
//! uniformly distributed over `[0, 1)^2` (Pearson's chi-square on a grid,
//! over many pixels); and runs `lumis check-plugin`'s sampler suite.

use lumis_check::corrected_significance;
use lumis_check::outcome::Outcome;
use lumis_check::sampler_suite::{check_sampler_with, format_sampler_results, SamplerCheckConfig};
use lumis_check::uniformity::uniformity_2d;
use lumis_core::{PluginKind, Registry, Sampler, UVec2};

use {{lib}}::JitteredSampler;

const STRATA: [u32; 3] = [1, 3, 8];

#[test]
fn every_stratum_holds_one_sample() {
    for n in STRATA {
        let spp = (n * n) as usize;
        let mut sampler = JitteredSampler::new(n);
        // Per dimension: the pixel's 2D, then a 2D, a 1D and a 2D.
        let mut cells = vec![vec![0u32; spp]; 4];
        for i in 0..n * n {
            sampler.start_pixel_sample(UVec2::new(5, 9), i, 3);
            let points = [sampler.get_pixel_2d(), sampler.get_2d()];
            let x = sampler.get_1d();
            let last = sampler.get_2d();
            for (d, p) in points.iter().chain([&last]).enumerate() {
                let cell = (p.y * n as f32) as usize * n as usize + (p.x * n as f32) as usize;
                cells[[0, 1, 3][d]][cell] += 1;
            }
            cells[2][(x * spp as f32) as usize] += 1;
        }
        for (d, counts) in cells.iter().enumerate() {
            assert!(
                counts.iter().all(|&c| c == 1),
                "strata {n}, dimension {d}: {counts:?}"
            );
        }
    }
}

#[test]
fn each_dimension_is_uniform() {
    let significance = corrected_significance(0.01, 2 * STRATA.len());
    for n in STRATA {
        let mut sampler = JitteredSampler::new(n);
        let (mut pixel, mut pair) = (Vec::new(), Vec::new());
        for p in 0..20_000 / (n * n) + 1 {
            for i in 0..n * n {
                sampler.start_pixel_sample(UVec2::new(p, 7), i, 1);
                let u = sampler.get_pixel_2d();
                let v = sampler.get_2d();
                pixel.push([u.x, u.y]);
                pair.push([v.x, v.y]);
            }
        }
        // 10 x 10 cells, not a multiple of the strata: the test sees the
        // jitter inside strata, not only the strata themselves.
        for (what, points) in [("pixel", &pixel), ("2D", &pair)] {
            let report = uniformity_2d(points, 10);
            assert!(
                report.p_value > significance,
                "strata {n}, {what}: {report:?}"
            );
        }
    }
}

#[test]
fn registers_as_a_sampler() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    assert!(registry
        .find(PluginKind::Sampler, {{lib}}::SPEC.name)
        .is_some());
}

/// The checks of `lumis check-plugin`: numbers in [0, 1), the same numbers
/// however they are asked for, the declared grid exactly, uniformity.
#[test]
fn passes_the_sampler_suite() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    let results = check_sampler_with(
        &registry,
        {{lib}}::SPEC.name,
        &[],
        &SamplerCheckConfig::default(),
    )
    .unwrap();
    assert!(
        results.iter().all(|r| r.passed()),
        "{}",
        format_sampler_results(&results)
    );
}
