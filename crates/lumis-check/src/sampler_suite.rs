//! The full check of a sampler plugin, as `lumis check-plugin` and the test
//! suite run it: over a sweep of the plugin's own parameters (and of `spp`:
//! 1, a prime, a power of two, besides its default), for pixels from the
//! image corner to 65535 and seeds from 0 to `u64::MAX`, check
//!
//! - every number is finite and in [0, 1), never 1;
//! - the numbers of a (pixel, index, seed) are the same whenever they are
//!   asked for: in reverse index order, from a clone, and through the
//!   batched lanes of a wavefront integrator;
//! - the film positions of each pixel have the structure the sampler
//!   declares ([`PixelPattern`]), exactly: one per grid cell, a (0, m,
//!   2)-net, or a minimum distance;
//! - the film positions and a later 2D dimension, one sample per seed,
//!   over seeds are uniform (Pearson's chi-square, Sidak-corrected for the
//!   cases),
//!   unless the sampler declares its points deterministic
//!   ([`Sampler::randomized`]): that case is "not testable" for
//!   uniformity, and says so.

use std::fmt::Write;

use lumis_core::{
    Location, PixelPattern, PluginEntity, PluginKind, Registry, Result, Sampler, UVec2, Vec2,
};
use lumis_sampling::hash_u64;
use rayon::prelude::*;

use crate::corrected_significance;
use crate::outcome::{add_faults, summary, unmade, verdict, write_notes, Outcome};
use crate::sweep::{declared, parameter_sweep_with, variant, Variant};
use crate::uniformity::uniformity_2d;

/// How thoroughly to check.
#[derive(Debug, Clone, PartialEq)]
pub struct SamplerCheckConfig {
    /// Pixels whose samples are checked one by one.
    pub pixels: Vec<UVec2>,
    pub seeds: Vec<u64>,
    /// `get_1d_2d` requests after the film position, per sample: a path's
    /// vertices.
    pub rounds: usize,
    /// Seeds, one sample each, pooled for the uniformity tests.
    pub draws: usize,
    /// Cells per axis of the uniformity tests.
    pub cells: usize,
    /// Overall false-alarm rate of the whole sweep.
    pub alpha: f64,
}

impl Default for SamplerCheckConfig {
    fn default() -> Self {
        Self {
            pixels: vec![
                UVec2::new(0, 0),
                UVec2::new(1, 0),
                UVec2::new(7, 3),
                UVec2::new(1023, 767),
                UVec2::new(65535, 65535),
            ],
            seeds: vec![0, 1, 0xdead_beef, u64::MAX],
            rounds: 6,
            draws: 8192,
            cells: 8,
            alpha: 0.01,
        }
    }
}

/// Sample counts checked besides a sampler's default: one sample, a prime,
/// a power of two.
pub const SPP_EXTREMES: [u32; 3] = [1, 7, 64];

/// The outcome of one parameter setting.
#[derive(Debug, Clone)]
pub struct SamplerCaseResult {
    pub sampler: String,
    pub variant: String,
    /// What the sampler declared.
    pub pattern: Option<PixelPattern>,
    /// The smaller p-value of the two uniformity tests; NaN where the
    /// sampler declares deterministic points.
    pub p_value: f64,
    /// Why a check could not be run: the sampler declares its points
    /// deterministic, so uniformity is not expected of them.
    pub not_testable: Option<String>,
    /// The (Sidak-corrected) significance the p-value is held to.
    pub significance: f64,
    /// Everything that failed, uniformity included.
    pub problems: Vec<String>,
    /// Why the plugin refused this parameter setting (its factory's error).
    pub refused: Option<String>,
}

impl Outcome for SamplerCaseResult {
    /// The sampler suite's tests report what fails as problems.
    fn test_passed(&self) -> bool {
        true
    }
    crate::outcome::case_fields!();
}

fn owner(name: &str, variant: &Variant) -> String {
    format!("sampler \"{name}\" [{}]", variant.label)
}

/// Runs every check over the sweep of the sampler plugin `name`'s declared
/// parameters, with parameters in `fixed` held at the given values (see
/// [`parameter_sweep_with`]).
pub fn check_sampler_with(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    cfg: &SamplerCheckConfig,
) -> Result<Vec<SamplerCaseResult>> {
    let spec = declared(registry, PluginKind::Sampler, name)?;
    let mut variants = parameter_sweep_with(&spec, fixed)?;
    let sweeps_spp =
        spec.params.iter().any(|p| p.name == "spp") && !fixed.iter().any(|(k, _)| k == "spp");
    if sweeps_spp {
        let base = variants[0].table.clone();
        for spp in SPP_EXTREMES {
            let mut v = variant(format!("spp = {spp}"), &format!("spp = {spp}\n"))?;
            for entry in base.entries.iter().filter(|e| e.key != "spp") {
                v.table.entries.push(entry.clone());
            }
            variants.push(v);
        }
    }
    let significance = corrected_significance(cfg.alpha, 2 * variants.len());
    let results = variants
        .par_iter()
        .map(|variant| {
            let mut result = SamplerCaseResult {
                sampler: name.to_string(),
                variant: variant.label.clone(),
                pattern: None,
                p_value: f64::NAN,
                not_testable: None,
                significance,
                problems: Vec::new(),
                refused: None,
            };
            let entity = PluginEntity::new(
                PluginKind::Sampler,
                owner(name, variant),
                name,
                variant.table.clone(),
                Location::Builtin,
            );
            match registry.create::<dyn Sampler>(&entity, ()) {
                Ok(mut sampler) => check_case(sampler.as_mut(), cfg, &mut result),
                Err(e) => match unmade(registry, &entity.owner, &e) {
                    Ok(refusal) => result.refused = Some(refusal),
                    Err(failure) => result.problems.push(failure),
                },
            }
            add_faults(registry, &entity.owner, &mut result.problems);
            result
        })
        .collect();
    Ok(results)
}

/// The numbers of one pixel sample: the film position, `rounds`
/// `get_1d_2d` requests, then a `get_1d` and a `get_2d`.
fn draw(s: &mut dyn Sampler, pixel: UVec2, index: u32, seed: u64, rounds: usize) -> Vec<f32> {
    s.start_pixel_sample(pixel, index, seed);
    let film = s.get_pixel_2d();
    let mut out = vec![film.x, film.y];
    for _ in 0..rounds {
        let (a, b) = s.get_1d_2d();
        out.extend([a, b.x, b.y]);
    }
    out.push(s.get_1d());
    let last = s.get_2d();
    out.extend([last.x, last.y]);
    out
}

/// Bit-for-bit equality, so that a NaN equals itself.
fn same(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

fn check_case(s: &mut dyn Sampler, cfg: &SamplerCheckConfig, result: &mut SamplerCaseResult) {
    let spp = s.samples_per_pixel();
    let pattern = s.pixel_pattern();
    result.pattern = Some(pattern);
    if spp == 0 {
        result.problems.push("samples_per_pixel() is 0".into());
        return;
    }
    let problems = &mut result.problems;
    let mut report = |problem: String| {
        // One message per kind of problem keeps a broken sampler's report
        // readable.
        let kind = problem.split(':').next().unwrap_or_default().to_string();
        if !problems.iter().any(|p| p.starts_with(&kind)) {
            problems.push(problem);
        }
    };
    for &pixel in &cfg.pixels {
        for &seed in &cfg.seeds {
            let at = format!("pixel {pixel}, seed {seed}");
            let forward: Vec<Vec<f32>> = (0..spp)
                .map(|i| draw(s, pixel, i, seed, cfg.rounds))
                .collect();
            for (i, values) in forward.iter().enumerate() {
                if let Some(v) = values.iter().find(|v| !(0.0..1.0).contains(*v)) {
                    report(format!("outside [0, 1): {v:?} at {at}, index {i}"));
                }
            }
            for i in (0..spp).rev() {
                if !same(&draw(s, pixel, i, seed, cfg.rounds), &forward[i as usize]) {
                    report(format!(
                        "not deterministic: index {i} at {at} differs when drawn again in reverse order"
                    ));
                }
            }
            let mut clone = s.clone_sampler();
            let last = spp - 1;
            if !same(
                &draw(clone.as_mut(), pixel, last, seed, cfg.rounds),
                &forward[last as usize],
            ) {
                report(format!("clone_sampler differs: index {last} at {at}"));
            }
            check_lanes(s, pixel, seed, cfg.rounds, &forward, &mut report);
            let film: Vec<Vec2> = forward.iter().map(|v| Vec2::new(v[0], v[1])).collect();
            if let Some(why) = violates(pattern, &film) {
                report(format!("not the declared {pattern:?}: {why} at {at}"));
            }
        }
    }
    if s.randomized() {
        let [film, later] = uniformity_p_values(s, spp, cfg);
        result.p_value = film.min(later);
        if result.p_value < result.significance {
            let which = if film < later {
                "the film positions"
            } else {
                "the third request's 2D numbers"
            };
            result.problems.push(format!(
                "not uniform: {which} over {} seeds, p-value {:.3e} below {:.3e}",
                cfg.draws, result.p_value, result.significance,
            ));
        }
    } else {
        result.not_testable = Some(
            "uniformity: the sampler declares its points deterministic (randomized() is false)"
                .into(),
        );
    }
}

/// The lanes of a batch, each at its own sample index, against the scalar
/// requests.
fn check_lanes(
    s: &dyn Sampler,
    pixel: UVec2,
    seed: u64,
    rounds: usize,
    forward: &[Vec<f32>],
    report: &mut impl FnMut(String),
) {
    let n = forward.len();
    let mut lanes = s.lanes(n);
    let order: Vec<usize> = (0..n).collect();
    for (i, _) in forward.iter().enumerate() {
        lanes.with_lane(i, |lane| {
            lane.start_pixel_sample(pixel, i as u32, seed);
            lane.get_pixel_2d();
        });
    }
    let mut out = vec![(0.0, Vec2::ZERO); n];
    for round in 0..rounds {
        lanes.get_1d_2d_batch(&order, &mut out);
        for (i, &(a, b)) in out.iter().enumerate() {
            let want = &forward[i][2 + 3 * round..5 + 3 * round];
            if !same(&[a, b.x, b.y], want) {
                report(format!(
                    "lanes differ from scalar requests: index {i}, request {round} at pixel {pixel}, seed {seed}"
                ));
                return;
            }
        }
    }
}

/// Why the film positions `p` of one pixel lack `pattern`, if they do.
fn violates(pattern: PixelPattern, p: &[Vec2]) -> Option<String> {
    let cell = |v: f32, n: u32| ((v * n as f32) as u32).min(n - 1);
    match pattern {
        PixelPattern::Random => None,
        PixelPattern::Grid { nx, ny } => {
            if nx * ny != p.len() as u32 {
                return Some(format!("{nx} x {ny} cells for {} samples", p.len()));
            }
            let mut seen = vec![false; p.len()];
            for q in p {
                let c = (cell(q.y, ny) * nx + cell(q.x, nx)) as usize;
                if std::mem::replace(&mut seen[c], true) {
                    return Some(format!("two positions in the cell of {q}"));
                }
            }
            None
        }
        PixelPattern::Net02 => {
            if !p.len().is_power_of_two() {
                return Some(format!("{} samples, not a power of two", p.len()));
            }
            let m = p.len().trailing_zeros();
            (0..=m).find_map(|a| {
                let (nx, ny) = (1u32 << a, 1u32 << (m - a));
                let mut seen = vec![false; p.len()];
                p.iter().find_map(|q| {
                    let c = (cell(q.y, ny) * nx + cell(q.x, nx)) as usize;
                    std::mem::replace(&mut seen[c], true)
                        .then(|| format!("two positions in one {nx} x {ny} interval, at {q}"))
                })
            })
        }
        PixelPattern::MinDistance(d) => {
            // On the torus, as the patterns are made; 1e-5 of slack for the
            // rounding of their shift.
            let torus = |a: f32| a.abs().min(1.0 - a.abs());
            p.iter().enumerate().find_map(|(i, a)| {
                p[i + 1..].iter().find_map(|b| {
                    let gap = Vec2::new(torus(a.x - b.x), torus(a.y - b.y)).length();
                    (gap < d - 1e-5).then(|| format!("{a} and {b} only {gap} apart"))
                })
            })
        }
    }
}

/// The p-values of the uniformity of the film positions, and of the 2D
/// part of the third `get_1d_2d` request, over `cfg.draws` seeds.
///
/// One sample per seed: a randomised sampler makes every number uniform
/// over its randomisation, and different seeds are independent. Samples of
/// one seed are not (a scrambled net's points avoid each other, some
/// higher-dimensional projections of a (t, m, s)-net clump, and a global
/// sequence ties neighbouring pixels together), and Pearson's test needs
/// independent, multinomial counts.
fn uniformity_p_values(s: &mut dyn Sampler, spp: u32, cfg: &SamplerCheckConfig) -> [f64; 2] {
    let (mut film, mut later) = (Vec::new(), Vec::new());
    for k in 0..cfg.draws {
        let seed = hash_u64(k as u64 ^ 0x05ee_d0f5_eed5);
        let v = draw(s, UVec2::new(5, 3), k as u32 % spp, seed, 3);
        film.push([v[0], v[1]]);
        later.push([v[9], v[10]]);
    }
    [
        uniformity_2d(&film, cfg.cells).p_value,
        uniformity_2d(&later, cfg.cells).p_value,
    ]
}

/// The table `lumis check-plugin` prints: a row per case, numbered.
pub fn format_sampler_results(results: &[SamplerCaseResult]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:>4} {:<14} {:<36} {:<28} {:>10}  result",
        "case", "sampler", "parameters", "declared pattern", "p-value"
    );
    for (case, r) in results.iter().enumerate() {
        let pattern = r.pattern.map_or("-".to_string(), |p| format!("{p:?}"));
        let _ = writeln!(
            out,
            "{case:>4} {:<14} {:<36} {pattern:<28} {:>10.3e}  {}",
            r.sampler,
            r.variant,
            r.p_value,
            verdict(r)
        );
        write_notes(&mut out, r, None);
    }
    let _ = writeln!(out, "{}", summary(results));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: u32) -> Vec<Vec2> {
        (0..n * n)
            .map(|i| Vec2::new((i % n) as f32 + 0.5, (i / n) as f32 + 0.5) / n as f32)
            .collect()
    }

    #[test]
    fn patterns_are_checked_exactly() {
        let g = grid(4);
        assert_eq!(violates(PixelPattern::Grid { nx: 4, ny: 4 }, &g), None);
        // A 4 x 4 grid of centres is not a net: the 16 x 1 columns hold
        // four positions each.
        assert!(violates(PixelPattern::Net02, &g).is_some());
        let mut twice = g.clone();
        twice[1] = twice[0];
        assert!(violates(PixelPattern::Grid { nx: 4, ny: 4 }, &twice).is_some());
        assert_eq!(violates(PixelPattern::MinDistance(0.2), &g), None);
        assert!(violates(PixelPattern::MinDistance(0.3), &g).is_some());
        // Across the torus's seam: 0.05 and 0.95 are 0.1 apart.
        let seam = [Vec2::new(0.05, 0.5), Vec2::new(0.95, 0.5)];
        assert!(violates(PixelPattern::MinDistance(0.2), &seam).is_some());
        // The (0, 2, 2)-net of four points.
        let net = [
            Vec2::new(0.1, 0.6),
            Vec2::new(0.3, 0.1),
            Vec2::new(0.6, 0.8),
            Vec2::new(0.8, 0.3),
        ];
        assert_eq!(violates(PixelPattern::Net02, &net), None);
    }
}
