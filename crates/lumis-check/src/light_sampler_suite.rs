//! The full check of a light-sampler plugin, as `lumis check-plugin` and
//! the test suite run it: over a sweep of the plugin's own parameters, made
//! over [`STAND_IN_LIGHTS`] (lights of different kinds, powers and places,
//! one of them dark), from reference points (behind the one-sided quad, on
//! it, far away, and seeded random ones), check
//!
//! - the pmf over all lights sums to 1, each value finite in [0, 1]; a
//!   sampler that knows some lights cannot reach the point may leave them
//!   out (a sum below 1), and `sample` then returns no light with the
//!   probability left over;
//! - a light of pmf 0 sends no light to the point (else estimates would be
//!   biased);
//! - `sample` draws each light with the frequency `pmf` gives it: Pearson's
//!   chi-square over the lights and "no light" (a draw of a light of pmf 0,
//!   or an index past the last light, fails outright), Sidak-corrected for
//!   the cases;
//! - `sample` returns the pmf that `pmf` gives for the light it draws.

use std::fmt::Write;

use lumis_core::ray::SurfacePoint;
use lumis_core::{
    doc, Light, LightInput, LightSampleContext, LightSampler, LightShape, Location, PluginEntity,
    PluginKind, Registry, Result, Vec2, Vec3,
};
use lumis_sampling::{warp, Pcg32};
use rayon::prelude::*;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::corrected_significance;
use crate::light_suite::{SCENE_CENTER, SCENE_RADIUS};
use crate::outcome::{add_faults, summary, unmade, verdict, write_notes, Outcome};
use crate::sweep::{declared, parameter_sweep_with, Variant};

/// How thoroughly to check.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSamplerCheckConfig {
    /// Reference points per parameter setting: the [`PLACED_POINTS`],
    /// then random ones.
    pub points: usize,
    /// Draws of `sample` per reference point.
    pub samples: usize,
    /// Overall false-alarm rate of the whole sweep.
    pub alpha: f64,
    /// Bins expecting fewer draws than this are pooled (Cochran's rule).
    pub min_expected: f64,
    pub seed: u64,
}

impl Default for LightSamplerCheckConfig {
    fn default() -> Self {
        Self {
            points: 8,
            samples: 50_000,
            alpha: 0.01,
            min_expected: 5.0,
            seed: 1,
        }
    }
}

/// The lights a sampler is checked over: built-in plugin, the shape it is
/// the emission of, parameters. Powers span four decades and one light is
/// dark, so a sampler that ignores power or mishandles a zero shows it.
pub const STAND_IN_LIGHTS: &[(&str, StandInShape, &str)] = &[
    (
        "point",
        StandInShape::None,
        "position = [0.0, 1.0, 0.0]\nintensity = 1.0\n",
    ),
    (
        "point",
        StandInShape::None,
        "position = [3.0, 0.5, -1.0]\nintensity = [20.0, 10.0, 5.0]\n",
    ),
    (
        "point",
        StandInShape::None,
        "position = [-1.0, 2.0, 1.0]\nintensity = 0.0\n",
    ),
    (
        "spot",
        StandInShape::None,
        "position = [-2.0, 2.0, 0.0]\ntarget = [0.0, 0.0, 0.0]\nintensity = 5.0\n",
    ),
    ("quad", StandInShape::Quad, "radiance = 2.0\n"),
    ("sphere", StandInShape::Sphere, "radiance = 0.5\n"),
    ("constant", StandInShape::None, "radiance = 0.002\n"),
];

/// Which shape a stand-in light is the emission of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StandInShape {
    None,
    Quad,
    Sphere,
}

impl StandInShape {
    fn shape(self) -> LightShape {
        match self {
            Self::None => LightShape::None,
            Self::Quad => LightShape::Quad {
                corner: Vec3::new(1.0, 3.0, -1.0),
                edge_u: Vec3::X,
                edge_v: Vec3::Z,
            },
            Self::Sphere => LightShape::Sphere {
                center: Vec3::new(-1.5, 0.5, 1.5),
                radius: 0.3,
                inward: false,
            },
        }
    }
}

/// [`STAND_IN_LIGHTS`], made by `registry` and preprocessed with the kit's
/// scene bound.
pub fn stand_in_lights(registry: &Registry) -> Result<Vec<Box<dyn Light>>> {
    STAND_IN_LIGHTS
        .iter()
        .enumerate()
        .map(|(i, &(type_name, shape, params))| {
            let entity = PluginEntity::new(
                PluginKind::Light,
                format!("stand-in light {i}"),
                type_name,
                doc::parse(params, "<stand-in>")?,
                Location::Builtin,
            );
            let mut light =
                registry.create::<dyn Light>(&entity, LightInput::untextured(&shape.shape()))?;
            light.preprocess(SCENE_CENTER, SCENE_RADIUS);
            Ok(light)
        })
        .collect()
}

/// The outcome of one (variant, reference point) case.
#[derive(Debug, Clone)]
pub struct LightSamplerCaseResult {
    pub sampler: String,
    pub variant: String,
    pub point: Vec3,
    /// Sum of the pmf over the lights.
    pub pmf_sum: f64,
    /// Pearson's statistic of the draws against the pmf, and its p-value.
    pub statistic: f64,
    pub p_value: f64,
    /// The (Sidak-corrected) significance the p-value is held to.
    pub significance: f64,
    /// Everything that failed besides the chi-square statistic itself.
    pub problems: Vec<String>,
    /// Why the plugin refused this parameter setting (its factory's error).
    pub refused: Option<String>,
}

impl Outcome for LightSamplerCaseResult {
    fn test_passed(&self) -> bool {
        self.p_value >= self.significance
    }
    fn refused(&self) -> Option<&str> {
        self.refused.as_deref()
    }
    /// Every made case is decided: a light sampler's pmf is always tested.
    fn not_testable(&self) -> Option<&str> {
        None
    }
    fn problems(&self) -> &[String] {
        &self.problems
    }
}

fn owner(name: &str, variant: &Variant) -> String {
    format!("light_sampler \"{name}\" [{}]", variant.label)
}

/// Runs every check over the sweep of the light-sampler plugin `name`'s
/// declared parameters, with parameters in `fixed` held at the given
/// values (see [`parameter_sweep_with`]).
pub fn check_light_sampler_with(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    cfg: &LightSamplerCheckConfig,
) -> Result<Vec<LightSamplerCaseResult>> {
    let spec = declared(registry, PluginKind::LightSampler, name)?;
    let variants = parameter_sweep_with(&spec, fixed)?;
    let lights = stand_in_lights(registry)?;
    let samplers: Vec<_> = variants
        .iter()
        .map(|v| {
            let entity = PluginEntity::new(
                PluginKind::LightSampler,
                owner(name, v),
                name,
                v.table.clone(),
                Location::Builtin,
            );
            registry.create::<dyn LightSampler>(&entity, &lights[..])
        })
        .collect();
    let points = reference_points(cfg);
    let significance = corrected_significance(cfg.alpha, variants.len() * points.len());
    let mut work = Vec::new();
    for (variant, sampler) in variants.iter().zip(&samplers) {
        for (i, &ctx) in points.iter().enumerate() {
            work.push((variant, sampler, i, ctx));
        }
    }
    let results = work
        .into_par_iter()
        .map(|(variant, sampler, i, ctx)| {
            let mut result = LightSamplerCaseResult {
                sampler: name.to_string(),
                variant: variant.label.clone(),
                point: ctx.p(),
                pmf_sum: f64::NAN,
                statistic: f64::NAN,
                p_value: f64::NAN,
                significance,
                problems: Vec::new(),
                refused: None,
            };
            match sampler {
                Ok(sampler) => {
                    let seed = cfg.seed.wrapping_add(i as u64);
                    let cfg = LightSamplerCheckConfig {
                        samples: variant.samples(cfg.samples),
                        ..cfg.clone()
                    };
                    check_case(sampler.as_ref(), &lights, &ctx, &cfg, seed, &mut result);
                }
                Err(e) => match unmade(registry, &owner(name, variant), e) {
                    Ok(refusal) => result.refused = Some(refusal),
                    Err(failure) => result.problems.push(failure),
                },
            }
            add_faults(registry, &owner(name, variant), &mut result.problems);
            result
        })
        .collect();
    Ok(results)
}

/// Reference points where samplers that weigh lights by place are apt to
/// go wrong, as (point, surface normal): behind the one-sided stand-in
/// quad, on it, and far from every light.
pub const PLACED_POINTS: [(Vec3, Vec3); 3] = [
    (Vec3::new(1.5, 3.5, -0.5), Vec3::Y),
    (Vec3::new(1.5, 3.0, -0.5), Vec3::NEG_Y),
    (Vec3::new(40.0, 30.0, -50.0), Vec3::ZERO),
];

/// The [`PLACED_POINTS`], then seeded points in a box around the stand-in
/// lights, half of them on a surface (a random normal), half in free space
/// (a zero normal).
fn reference_points(cfg: &LightSamplerCheckConfig) -> Vec<LightSampleContext> {
    let mut rng = Pcg32::new(cfg.seed, 0x9017);
    let placed = PLACED_POINTS.iter().map(|&(p, n)| LightSampleContext {
        point: SurfacePoint {
            p,
            p_error: Vec3::ZERO,
            n,
        },
        ns: n,
    });
    let random = (PLACED_POINTS.len()..cfg.points).map(|i| {
        let mut coordinate = || 6.0 * rng.next_f32() - 3.0;
        let p = Vec3::new(coordinate(), coordinate(), coordinate());
        let n = if i % 2 == 0 {
            warp::square_to_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()))
        } else {
            Vec3::ZERO
        };
        LightSampleContext {
            point: SurfacePoint {
                p,
                p_error: Vec3::ZERO,
                n,
            },
            ns: n,
        }
    });
    placed.chain(random).take(cfg.points).collect()
}

/// Light samples drawn from each light of pmf 0, to see that it is dark.
const DARK_PROBES: u32 = 16;

/// The pmf, the draws against it, and the pmf `sample` returns.
fn check_case(
    sampler: &dyn LightSampler,
    stand_ins: &[Box<dyn Light>],
    ctx: &LightSampleContext,
    cfg: &LightSamplerCheckConfig,
    seed: u64,
    result: &mut LightSamplerCaseResult,
) {
    let note = |problems: &mut Vec<String>, p: String| {
        if problems.len() < 5 {
            problems.push(p);
        }
    };
    let lights = stand_ins.len();
    let pmf: Vec<f32> = (0..lights as u32).map(|i| sampler.pmf(ctx, i)).collect();
    for (i, &p) in pmf.iter().enumerate() {
        if !(p.is_finite() && (0.0..=1.0).contains(&p)) {
            note(&mut result.problems, format!("pmf of light {i} = {p}"));
        }
    }
    result.pmf_sum = pmf.iter().map(|&p| f64::from(p)).sum();
    // False for a NaN sum too.
    let at_most_one = result.pmf_sum <= 1.0 + 1e-4;
    if !at_most_one {
        note(
            &mut result.problems,
            format!(
                "the pmf sums to {} over the {lights} lights, more than 1",
                result.pmf_sum
            ),
        );
    }
    for (i, light) in stand_ins.iter().enumerate() {
        if pmf[i] != 0.0 {
            continue;
        }
        let lit = (0..DARK_PROBES * DARK_PROBES).find_map(|k| {
            let u = Vec2::new(
                ((k % DARK_PROBES) as f32 + 0.5) / DARK_PROBES as f32,
                ((k / DARK_PROBES) as f32 + 0.5) / DARK_PROBES as f32,
            );
            light.sample_li(ctx, u).filter(|s| !s.l.is_black())
        });
        if let Some(s) = lit {
            note(
                &mut result.problems,
                format!(
                    "light {i} has pmf 0 but sends radiance {:?} along {} (it could never be sampled)",
                    s.l, s.wi
                ),
            );
        }
    }
    let mut rng = Pcg32::new(seed, 0x5a3b);
    let mut observed = vec![0u64; lights + 1];
    for _ in 0..cfg.samples {
        let u = rng.next_f32();
        let Some(s) = sampler.sample(ctx, u) else {
            observed[lights] += 1;
            continue;
        };
        let Some(&claimed) = pmf.get(s.index as usize) else {
            note(
                &mut result.problems,
                format!("sample drew light {} of {lights} at u = {u}", s.index),
            );
            continue;
        };
        observed[s.index as usize] += 1;
        let close = s.pmf.to_bits() == claimed.to_bits()
            || (s.pmf - claimed).abs() <= 1e-5 * s.pmf.abs().max(claimed.abs());
        if !close {
            note(
                &mut result.problems,
                format!(
                    "sample returned pmf {} for light {} but pmf() = {claimed} (u = {u})",
                    s.pmf, s.index
                ),
            );
        }
    }
    let n = cfg.samples as f64;
    let mut expected: Vec<f64> = pmf.iter().map(|&p| f64::from(p.max(0.0)) * n).collect();
    // Draws that return no light are the mass the pmf leaves over.
    expected.push((1.0 - result.pmf_sum).max(0.0) * n);
    let (statistic, p_value, defect) = pearson(&observed, &expected, cfg.min_expected);
    if let Some(d) = defect {
        note(&mut result.problems, d);
    }
    result.statistic = statistic;
    result.p_value = p_value;
}

/// Pearson's chi-square of `observed` against `expected` counts, bins
/// expecting fewer than `min_expected` pooled; a count where nothing is
/// expected is a defect.
fn pearson(observed: &[u64], expected: &[f64], min_expected: f64) -> (f64, f64, Option<String>) {
    let mut defect = None;
    let (mut statistic, mut dof) = (0.0, 0usize);
    let (mut pool_obs, mut pool_exp) = (0.0, 0.0);
    for (i, (&o, &e)) in observed.iter().zip(expected).enumerate() {
        let o = o as f64;
        if e <= 0.0 && o > 0.0 {
            let what = if i + 1 == observed.len() {
                "no light".to_string()
            } else {
                format!("light {i}")
            };
            defect.get_or_insert(format!("{o} draws of {what}, whose probability is 0"));
        }
        if e < min_expected {
            pool_obs += o;
            pool_exp += e;
        } else {
            statistic += (o - e).powi(2) / e;
            dof += 1;
        }
    }
    if pool_exp >= min_expected {
        statistic += (pool_obs - pool_exp).powi(2) / pool_exp;
        dof += 1;
    } else if pool_obs > pool_exp + 5.0 * pool_exp.max(1.0).sqrt() + 5.0 {
        defect.get_or_insert(format!(
            "{pool_obs} draws where only {pool_exp:.2} are expected"
        ));
    }
    let dof = dof.saturating_sub(1).max(1);
    let p_value = 1.0
        - ChiSquared::new(dof as f64)
            .map(|c| c.cdf(statistic))
            .unwrap_or(0.0);
    (
        statistic,
        if defect.is_some() { 0.0 } else { p_value },
        defect,
    )
}

/// A readable table of results, one line per case, failures explained.
pub fn format_light_sampler_results(results: &[LightSamplerCaseResult]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:>4} {:<10} {:<36} {:<26} {:>10} {:>10}  result",
        "case", "sampler", "parameters", "from", "pmf sum", "p-value"
    );
    for (case, r) in results.iter().enumerate() {
        let from = format!("({:.2}, {:.2}, {:.2})", r.point.x, r.point.y, r.point.z);
        let _ = writeln!(
            out,
            "{case:>4} {:<10} {:<36} {from:<26} {:>10.6} {:>10.3e}  {}",
            r.sampler,
            r.variant,
            r.pmf_sum,
            r.p_value,
            verdict(r)
        );
        let statistic = (r.problems.is_empty() && r.p_value < r.significance).then(|| {
            format!(
                "chi-square: statistic {:.1}, p-value below {:.3e}",
                r.statistic, r.significance
            )
        });
        write_notes(&mut out, r, statistic);
    }
    let _ = writeln!(out, "{}", summary(results));
    out
}
