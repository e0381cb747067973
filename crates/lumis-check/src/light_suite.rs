//! The full check of a light plugin, as `lumis check-plugin` and the test
//! suite run it: over a sweep of the plugin's own parameters, for each
//! shape the plugin accepts (none, a quad, a triangle, a sphere: area
//! lights are the emission of a shape) and from reference points below,
//! beside, far from, behind and (spheres) on and inside the light, check
//!
//! - chi-square goodness of fit of `sample_li` against `pdf_li` (a
//!   one-sided emitter seen from behind must give pdf 0 and no samples);
//! - `sample_li` returns the pdf `pdf_li` gives for its direction and the
//!   radiance `l()` gives at its point, and `sample_li_batch` and
//!   `sample_li_lanes` (on every lane and under a mask, the masked-out
//!   lanes untouched) return what `sample_li` does;
//! - `power()` is finite and non-negative, and where the light starts
//!   paths from the lights (`sample_le`), the mean power its rays carry,
//!   `L |cos| / (pdf_pos pdf_dir)`, is `power()` within five standard
//!   errors;
//! - no NaN, infinite or negative radiance or pdf anywhere.
//!
//! A delta light (`LightKind::DeltaPosition`) has no density to test: its
//! cases are reported as not testable, after checking what it does
//! promise, that `sample_li` is deterministic and `pdf_li` is zero.

use std::fmt::Write;

use lumis_core::lanes::{LaneMask, Vec2Lanes, LANES};
use lumis_core::light::LightSampleLanes;
use lumis_core::params::ParamDefault;
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Error, Light, LightInput, LightKind, LightSample, LightSampleContext, LightShape, Location,
    ParamType, PluginEntity, PluginKind, Registry, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::{warp, Pcg32};
use rayon::prelude::*;

use crate::adapters::light_pair;
use crate::chi_square::{chi_square, ChiSquareConfig, ChiSquareReport};
use crate::corrected_significance;
use crate::outcome::{add_faults, summary, unmade, verdict, write_notes, Outcome};
use crate::sweep::{declared, parameter_sweep_with, Variant};
use crate::test_map::TestMap;

/// How thoroughly to check.
#[derive(Debug, Clone, PartialEq)]
pub struct LightCheckConfig {
    /// Bins, samples and quadrature of each chi-square test; its
    /// significance is replaced by the Sidak-corrected one for the sweep.
    pub chi_square: ChiSquareConfig,
    /// Overall false-alarm rate of the whole sweep.
    pub alpha: f64,
    /// Samples for the consistency and finiteness checks of each case.
    pub samples: usize,
}

impl Default for LightCheckConfig {
    fn default() -> Self {
        Self {
            chi_square: ChiSquareConfig {
                z_bins: 40,
                phi_bins: 80,
                samples: 50_000,
                // A uniform solid-angle pdf is an indicator of the light's
                // outline, and an area-sampling pdf peaks toward grazing
                // directions: the bins those cross need deeper quadrature,
                // and the integral is only good to a few 1e-3.
                max_refinement: 8,
                integral_tolerance: 5e-3,
                ..Default::default()
            },
            alpha: 0.01,
            samples: 4_000,
        }
    }
}

/// The scene bound handed to `preprocess` (environment lights need one):
/// a sphere holding every light and reference point below.
pub const SCENE_CENTER: Vec3 = Vec3::new(0.0, 0.5, 0.0);
pub const SCENE_RADIUS: f32 = 4.0;

/// Where required position parameters put the light: the first at
/// [`LIGHT_POSITION`], the next at the origin (a spot light's target).
const LIGHT_POSITION: [f32; 3] = [0.0, 1.0, 0.0];
const SECOND_POSITION: [f32; 3] = [0.0, 0.0, 0.0];

/// A shape a light can be the emission of, with the reference points that
/// see it from every side that matters.
struct Placement {
    label: &'static str,
    shape: LightShape,
    points: Vec<(&'static str, Vec3)>,
}

/// Every shape is centred near [`LIGHT_POSITION`]; planar ones face -y
/// (their front normal is `edge_u x edge_v`), so "behind" sees their back.
fn placements() -> Vec<Placement> {
    let planar_points = || {
        vec![
            ("below", Vec3::new(0.1, 0.0, 0.1)),
            ("close", Vec3::new(0.2, 0.9, 0.0)),
            // 9.5 degrees above the plane: grazing, yet wide enough (0.03
            // sr) for the quadrature to resolve the outline.
            ("grazing", Vec3::new(1.5, 0.8, 0.3)),
            ("far", Vec3::new(0.0, -2.0, 0.0)),
            ("behind", Vec3::new(0.0, 1.5, 0.0)),
        ]
    };
    vec![
        Placement {
            label: "none",
            shape: LightShape::None,
            points: vec![
                ("below", Vec3::new(0.1, 0.0, 0.1)),
                ("beside", Vec3::new(1.5, 0.8, 0.3)),
                ("far", Vec3::new(0.0, -2.0, 0.0)),
                ("above", Vec3::new(0.0, 1.5, 0.0)),
            ],
        },
        Placement {
            label: "quad",
            shape: LightShape::Quad {
                corner: Vec3::new(-0.3, 1.0, -0.2),
                edge_u: Vec3::X,
                edge_v: Vec3::new(0.0, 0.0, 0.5),
            },
            points: planar_points(),
        },
        Placement {
            label: "triangle",
            shape: LightShape::Triangle {
                p: [
                    Vec3::new(-0.5, 1.0, -0.5),
                    Vec3::new(0.8, 1.0, -0.3),
                    Vec3::new(0.0, 1.0, 0.7),
                ],
                uv: LightShape::BARYCENTRIC_UVS,
            },
            points: planar_points(),
        },
        Placement {
            label: "sphere",
            shape: LightShape::Sphere {
                center: Vec3::new(0.0, 1.0, 0.0),
                radius: 0.3,
                inward: false,
            },
            points: vec![
                ("near", Vec3::new(0.2, 0.5, 0.1)),
                ("far", Vec3::new(0.0, -3.0, 1.0)),
                ("just outside", Vec3::new(0.0, 0.69, 0.0)),
                ("on it", Vec3::new(0.0, 0.7, 0.0)),
                ("inside", Vec3::new(0.1, 1.1, 0.0)),
            ],
        },
    ]
}

/// The outcome of one (variant, shape, reference point) case.
#[derive(Debug, Clone)]
pub struct LightCaseResult {
    pub light: String,
    pub variant: String,
    /// The shape the light is the emission of (`none` for `[[light]]`).
    pub shape: String,
    /// Where the reference point is, e.g. `behind`.
    pub point: String,
    /// `None` when the case was not chi-square tested.
    pub chi_square: Option<ChiSquareReport>,
    /// Why the chi-square test cannot apply or cannot decide, as the kit
    /// established it: a delta light, or a failed test whose quadrature
    /// did not converge (see [`ChiSquareReport::unresolved`]); the other
    /// checks ran, and still fail the case.
    pub not_testable: Option<String>,
    pub power: Rgb,
    /// Everything that failed besides the chi-square statistic itself.
    pub problems: Vec<String>,
    /// Why the plugin refused this parameter setting (its factory's error).
    pub refused: Option<String>,
}

impl Outcome for LightCaseResult {
    fn test_passed(&self) -> bool {
        self.chi_square.as_ref().is_some_and(|c| c.passed)
    }
    crate::outcome::case_fields!();
}

/// How the light made for `variant` on `shape` is named, in messages and
/// in the registry's record of faults.
fn owner(name: &str, variant: &Variant, shape: &str) -> String {
    format!("light \"{name}\" [{}] on shape {shape}", variant.label)
}

/// The light plugin `name` with the parameters of `variant`, as the
/// emission of `shape`, preprocessed with the kit's scene bound.
pub fn instantiate(
    registry: &Registry,
    name: &str,
    variant: &Variant,
    shape: (&str, &LightShape),
) -> Result<Box<dyn Light>> {
    let entity = PluginEntity::new(
        PluginKind::Light,
        owner(name, variant, shape.0),
        name,
        variant.table.clone(),
        Location::Builtin,
    );
    let mut light = registry.create::<dyn Light>(&entity, LightInput::untextured(shape.1))?;
    light.preprocess(SCENE_CENTER, SCENE_RADIUS);
    Ok(light)
}

/// `fixed` with the kit's positions for the required `vec3` parameters
/// that it does not hold (a sweep cannot invent where a light is), and
/// `map` for its required `path` ones (nor the file it reads).
fn with_required(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    map: Option<&TestMap>,
) -> Result<Vec<(String, String)>> {
    let spec = declared(registry, PluginKind::Light, name)?;
    let mut out = fixed.to_vec();
    let mut places = [LIGHT_POSITION, SECOND_POSITION].into_iter();
    for p in spec.params {
        if p.default != ParamDefault::Required || fixed.iter().any(|(k, _)| k == p.name) {
            continue;
        }
        match (p.ty, map) {
            (ParamType::Vec3, _) => {
                let [x, y, z] = places.next().unwrap_or(SECOND_POSITION);
                out.push((p.name.to_string(), format!("[{x:?}, {y:?}, {z:?}]")));
            }
            (ParamType::Path, Some(map)) => {
                out.push((
                    p.name.to_string(),
                    format!("{:?}", map.path().display().to_string()),
                ));
            }
            _ => {}
        }
    }
    Ok(out)
}

/// Whether the light `name` reads a file the scene must name.
fn needs_a_file(registry: &Registry, name: &str, fixed: &[(String, String)]) -> Result<bool> {
    let spec = declared(registry, PluginKind::Light, name)?;
    Ok(spec.params.iter().any(|p| {
        p.ty == ParamType::Path
            && p.default == ParamDefault::Required
            && !fixed.iter().any(|(k, _)| k == p.name)
    }))
}

/// Runs every check over the sweep of the light plugin `name`'s declared
/// parameters, with parameters in `fixed` held at the given values (see
/// [`parameter_sweep_with`]).
pub fn check_light_with(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    cfg: &LightCheckConfig,
) -> Result<Vec<LightCaseResult>> {
    // Kept until the checks end: the lights read it when they are made.
    let map = if needs_a_file(registry, name, fixed)? {
        Some(TestMap::write()?)
    } else {
        None
    };
    let fixed = with_required(registry, name, fixed, map.as_ref())?;
    let spec = declared(registry, PluginKind::Light, name)?;
    let variants = parameter_sweep_with(&spec, &fixed)?;
    check_light_variants(registry, name, &variants, cfg)
}

/// Runs every check for each of `variants` of the light plugin `name`, on
/// each shape whose emission its default setting accepts to be, from each
/// reference point; the cases run in parallel and the chi-square
/// significance is corrected for the number of them.
pub fn check_light_variants(
    registry: &Registry,
    name: &str,
    variants: &[Variant],
    cfg: &LightCheckConfig,
) -> Result<Vec<LightCaseResult>> {
    let base = variants
        .first()
        .ok_or_else(|| Error::msg("no parameter setting to check"))?;
    let mut refusals = Vec::new();
    let placements: Vec<Placement> = placements()
        .into_iter()
        .filter(
            |p| match instantiate(registry, name, base, (p.label, &p.shape)) {
                Ok(_) => true,
                Err(e) => {
                    refusals.push(format!("{}: {e}", p.label));
                    false
                }
            },
        )
        .collect();
    if placements.is_empty() {
        return Err(Error::msg(format!(
            "light \"{name}\" with its default parameters is made on no shape (none, quad, triangle, sphere): {}",
            refusals.join("; ")
        )));
    }
    let mut work = Vec::new();
    for variant in variants {
        for placement in &placements {
            let light = instantiate(registry, name, variant, (placement.label, &placement.shape));
            let light = std::sync::Arc::new(light);
            for &(point, p) in &placement.points {
                work.push((variant, placement.label, light.clone(), point, p));
            }
        }
    }
    let tests = work
        .iter()
        .filter(|w| matches!(w.2.as_ref(), Ok(l) if l.kind() != LightKind::DeltaPosition))
        .count();
    let chi_cfg = ChiSquareConfig {
        significance: corrected_significance(cfg.alpha, tests),
        ..cfg.chi_square
    };
    let mut results: Vec<LightCaseResult> = work
        .par_iter()
        .enumerate()
        .map(|(case, (variant, shape, light, point, p))| {
            let mut result = LightCaseResult {
                light: name.to_string(),
                variant: variant.label.clone(),
                shape: shape.to_string(),
                point: point.to_string(),
                chi_square: None,
                not_testable: None,
                power: Rgb::splat(f32::NAN),
                problems: Vec::new(),
                refused: None,
            };
            let light = match light.as_ref() {
                Ok(light) => light,
                Err(e) => {
                    match unmade(registry, &owner(name, variant, shape), e) {
                        Ok(refusal) => result.refused = Some(refusal),
                        Err(failure) => result.problems.push(failure),
                    }
                    return result;
                }
            };
            let ctx = LightSampleContext::at(*p);
            result.power = light.power();
            if !result.power.is_finite() || result.power.min_component() < 0.0 {
                result
                    .problems
                    .push(format!("power() = {:?}", result.power));
            }
            result.problems.extend(check_emission(
                light.as_ref(),
                variant.samples(cfg.samples),
                case as u64,
            ));
            if light.kind() == LightKind::DeltaPosition {
                result.problems.extend(check_delta(
                    light.as_ref(),
                    &ctx,
                    variant.samples(cfg.samples),
                    case as u64,
                ));
                result.not_testable = Some(
                    "delta light: no density to test (sample_li deterministic, pdf_li = 0 checked)"
                        .into(),
                );
            } else {
                let (sample, pdf) = light_pair(light.as_ref(), ctx);
                let case_cfg = ChiSquareConfig {
                    seed: chi_cfg.seed.wrapping_add(case as u64),
                    samples: variant.samples(chi_cfg.samples),
                    ..chi_cfg
                };
                let report = chi_square(sample, pdf, &case_cfg);
                if !report.passed && report.defect.is_none() {
                    result.not_testable = report.unresolved();
                }
                result.chi_square = Some(report);
                result.problems.extend(check_values(
                    light.as_ref(),
                    &ctx,
                    variant.samples(cfg.samples),
                    case as u64,
                ));
            }
            result
        })
        .collect();
    // A loaded plugin that panicked answered with neutral values (see
    // lumis_api::guard); every case of its setting fails with the panic.
    for result in &mut results {
        let variant = variants
            .iter()
            .find(|v| v.label == result.variant)
            .expect("results come from the variants");
        add_faults(
            registry,
            &owner(name, variant, &result.shape),
            &mut result.problems,
        );
    }
    Ok(results)
}

/// Whether a returned value is usable: finite and non-negative.
fn bad(v: f32) -> bool {
    !v.is_finite() || v < 0.0
}

fn bad_rgb(c: Rgb) -> bool {
    bad(c.r) || bad(c.g) || bad(c.b)
}

/// Within a relative 1e-3 of each other, or bit for bit the same (so that
/// a NaN in both is reported once, as a NaN, not as a mismatch).
fn close(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a - b).abs() <= 1e-3 * a.abs().max(b.abs())
}

fn close_rgb(a: Rgb, b: Rgb) -> bool {
    close(a.r, b.r) && close(a.g, b.g) && close(a.b, b.b)
}

/// The radiance `l()` gives for a sample's point seen along `wi`: leaving
/// the light's point toward the reference point, or (infinite lights)
/// arriving along `-wi`.
fn radiance_of(light: &dyn Light, ctx: &LightSampleContext, s: &LightSample, wi: Vec3) -> Rgb {
    match light.kind() {
        LightKind::Infinite => light.l(ctx.p(), Vec3::ZERO, Vec2::ZERO, wi),
        _ => light.l(s.p.p, s.p.n, Vec2::ZERO, -wi),
    }
}

/// Finiteness, and `sample_li` against `pdf_li`, `l` and `sample_li_batch`.
fn check_values(
    light: &dyn Light,
    ctx: &LightSampleContext,
    samples: usize,
    seed: u64,
) -> Vec<String> {
    let mut rng = Pcg32::new(seed, 0x119e);
    let mut problems = Vec::new();
    let mut note = |p: String| {
        if problems.len() < 5 {
            problems.push(p);
        }
    };
    let mut lanes = Vec::new();
    for _ in 0..samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        if lanes.len() < BATCH_LANES {
            lanes.push(u);
        }
        if let Some(s) = light.sample_li(ctx, u) {
            if bad(s.pdf) || bad_rgb(s.l) || !s.wi.is_finite() || !s.p.p.is_finite() {
                note(format!(
                    "sample_li returned l = {:?}, pdf = {}, wi = {:?}, p = {:?}",
                    s.l, s.pdf, s.wi, s.p.p
                ));
                continue;
            }
            if s.pdf > 0.0 {
                let pdf = light.pdf_li(ctx, s.wi);
                if !close(pdf, s.pdf) && !within_spread(|w| light.pdf_li(ctx, w), s.wi, s.pdf) {
                    note(format!(
                        "sample_li pdf {} but pdf_li() = {pdf} at wi = {:?}",
                        s.pdf, s.wi
                    ));
                }
                let l = radiance_of(light, ctx, &s, s.wi);
                let channel_within_spread = |c: fn(Rgb) -> f32| {
                    within_spread(|w| c(radiance_of(light, ctx, &s, w)), s.wi, c(s.l))
                };
                if !close_rgb(l, s.l)
                    && ![|l: Rgb| l.r, |l: Rgb| l.g, |l: Rgb| l.b]
                        .into_iter()
                        .all(channel_within_spread)
                {
                    note(format!(
                        "sample_li radiance {:?} but l() = {l:?} at p = {:?}",
                        s.l, s.p.p
                    ));
                }
            }
        }
        // The density anywhere on the sphere must be finite and non-negative.
        let wi = warp::square_to_uniform_sphere(u);
        let pdf = light.pdf_li(ctx, wi);
        if bad(pdf) {
            note(format!("pdf_li() = {pdf} at wi = {wi:?}"));
        }
    }
    for p in check_batch(light, ctx, &lanes) {
        note(p);
    }
    problems
}

/// How far from a sampled direction [`within_spread`] looks (radians).
const DIRECTION_SPREAD: f32 = 1e-6;

/// Whether `value` differs from `f(wi)` by no more than `f` itself varies
/// over directions within [`DIRECTION_SPREAD`] of `wi` (a few f32 ulps of
/// a direction). A sample's value and the value looked up along its
/// direction agree only as well as f32 resolves that direction: an
/// area-sampling pdf grows as `1 / cos` toward a light's silhouette and
/// jumps to 0 across it, and an environment map's radiance jumps at a
/// sun's edge (a sample reads it at the point it drew, as pbrt-v4 does,
/// `l()` at the direction's point). There a comparison says nothing.
fn within_spread(f: impl Fn(Vec3) -> f32, wi: Vec3, value: f32) -> bool {
    let e1 = wi.any_orthonormal_vector();
    let e2 = wi.cross(e1);
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for t in [e1, -e1, e2, -e2] {
        let v = f((wi + DIRECTION_SPREAD * t).normalize());
        lo = lo.min(v);
        hi = hi.max(v);
    }
    (value - f(wi)).abs() <= hi - lo
}

/// Enough lanes for every SIMD width and a partial last chunk.
const BATCH_LANES: usize = 1021;

/// `sample_li_batch` against `sample_li`, lane by lane, up to rounding (a
/// relative 1e-4, and `None` exactly where the scalar method gives it).
fn check_batch(light: &dyn Light, ctx: &LightSampleContext, u: &[Vec2]) -> Vec<String> {
    let ctxs = vec![*ctx; u.len()];
    let mut out = vec![None; u.len()];
    light.sample_li_batch(&ctxs, u, &mut out);
    let lanes = u.len();
    for (i, (&u, batch)) in u.iter().zip(&out).enumerate() {
        let scalar = light.sample_li(ctx, u);
        if !samples_agree(&scalar, batch) {
            return vec![format!(
                "sample_li_batch lane {i} of {lanes} gave {batch:?} but sample_li gave {scalar:?} (u = {u:?})"
            )];
        }
    }
    check_lanes(light, ctx, u)
}

/// Two answers of `sample_li`'s: the same sample up to rounding (a
/// relative 1e-4), or none.
fn samples_agree(a: &Option<LightSample>, b: &Option<LightSample>) -> bool {
    let near =
        |a: f32, b: f32| a.to_bits() == b.to_bits() || (a - b).abs() <= 1e-4 * a.abs().max(b.abs());
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            near(a.pdf, b.pdf)
                && near(a.l.r, b.l.r)
                && near(a.l.g, b.l.g)
                && near(a.l.b, b.l.b)
                && (a.wi - b.wi).abs().max_element() <= 1e-4
        }
        _ => false,
    }
}

/// `sample_li_lanes` against `sample_li`, a packet of [`LANES`] numbers
/// at a time: with every lane active, and with a mask that leaves some
/// out, whose lanes (filled with a marker beforehand) must come back
/// untouched.
fn check_lanes(light: &dyn Light, ctx: &LightSampleContext, u: &[Vec2]) -> Vec<String> {
    let marker = LightSample {
        l: Rgb::splat(-1.0),
        wi: Vec3::splat(-1.0),
        pdf: -1.0,
        p: SurfacePoint::isolated(Vec3::splat(-1.0)),
    };
    for numbers in u.chunks_exact(LANES) {
        let mut packet = Vec2Lanes::default();
        for (i, &u) in numbers.iter().enumerate() {
            packet.set(i, u);
        }
        for active in [LaneMask::ALL, LaneMask::from_bits(0b1001_0110)] {
            let mut out = LightSampleLanes::default();
            for i in (!active).iter() {
                out.set(i, Some(marker));
            }
            light.sample_li_lanes(&[*ctx; LANES], &packet, active, &mut out);
            for (i, &u) in numbers.iter().enumerate() {
                let want = if active.contains(i) {
                    light.sample_li(ctx, u)
                } else {
                    Some(marker)
                };
                if !samples_agree(&want, &out.get(i)) {
                    return vec![format!(
                        "sample_li_lanes lane {i} of mask {:#010b} gave {:?} but {want:?} was expected (u = {u:?})",
                        active.bits(),
                        out.get(i)
                    )];
                }
            }
        }
    }
    Vec::new()
}

/// The rays `sample_le` starts carry the light's power on average: the
/// mean of `L |cos| / (pdf_pos pdf_dir)` over `samples` random rays is
/// `power()` within five standard errors, and every ray is finite with
/// positive densities. A light that starts none (the trait's default) has
/// nothing to check.
fn check_emission(light: &dyn Light, samples: usize, seed: u64) -> Vec<String> {
    let mut rng = Pcg32::new(seed, 0xe1e5);
    let (mut sum, mut squares, mut started) = ([0.0f64; 3], [0.0f64; 3], 0);
    for _ in 0..samples {
        let mut u = || rng.next_f32();
        let (u_pos, u_dir) = (Vec2::new(u(), u()), Vec2::new(u(), u()));
        let Some(ray) = light.sample_le(u_pos, u_dir) else {
            continue;
        };
        let beta = ray.beta();
        if bad(ray.pdf_pos) || bad(ray.pdf_dir) || bad_rgb(beta) || !ray.d.is_finite() {
            return vec![format!(
                "sample_le returned a ray with l = {:?}, pdf_pos = {}, pdf_dir = {}, d = {:?} at u = {u_pos:?}, {u_dir:?}",
                ray.l, ray.pdf_pos, ray.pdf_dir, ray.d
            )];
        }
        started += 1;
        for (c, v) in [beta.r, beta.g, beta.b].into_iter().enumerate() {
            sum[c] += v as f64;
            squares[c] += v as f64 * v as f64;
        }
    }
    if started == 0 {
        return Vec::new();
    }
    let n = samples as f64;
    let power = light.power();
    let mut problems = Vec::new();
    for (c, expected) in [power.r, power.g, power.b].into_iter().enumerate() {
        let mean = sum[c] / n;
        let se = ((squares[c] / n - mean * mean).max(0.0) / n).sqrt();
        let expected = expected as f64;
        if (mean - expected).abs() > 5.0 * se + 1e-4 * expected.abs() {
            problems.push(format!(
                "the rays sample_le starts carry {mean:.5} on average in channel {c}, not power() = {expected:.5} ({se:.2e} standard error)"
            ));
        }
    }
    problems
}

/// A delta light: `sample_li` returns the same sample whatever `u` (bit
/// for bit), finite and non-negative, and `pdf_li` is zero everywhere.
fn check_delta(
    light: &dyn Light,
    ctx: &LightSampleContext,
    samples: usize,
    seed: u64,
) -> Vec<String> {
    let mut rng = Pcg32::new(seed, 0xde17a);
    let mut problems = Vec::new();
    let key = |s: &Option<LightSample>| {
        s.map(|s| {
            let SurfacePoint { p, .. } = s.p;
            [
                s.l.r, s.l.g, s.l.b, s.pdf, s.wi.x, s.wi.y, s.wi.z, p.x, p.y, p.z,
            ]
            .map(f32::to_bits)
        })
    };
    let first = light.sample_li(ctx, Vec2::new(0.5, 0.5));
    if let Some(s) = first {
        if bad(s.pdf) || bad_rgb(s.l) || !s.wi.is_finite() {
            problems.push(format!(
                "sample_li returned l = {:?}, pdf = {}, wi = {:?}",
                s.l, s.pdf, s.wi
            ));
        }
        let pdf = light.pdf_li(ctx, s.wi);
        if pdf != 0.0 {
            problems.push(format!(
                "a delta light's pdf_li() = {pdf} (not 0) at its own wi"
            ));
        }
    }
    for _ in 0..samples {
        let u = Vec2::new(rng.next_f32(), rng.next_f32());
        let s = light.sample_li(ctx, u);
        if key(&s) != key(&first) {
            problems.push(format!(
                "a delta light's sample_li depends on u: {s:?} at u = {u:?}, {first:?} at u = (0.5, 0.5)"
            ));
            break;
        }
        let wi = warp::square_to_uniform_sphere(u);
        let pdf = light.pdf_li(ctx, wi);
        if pdf != 0.0 {
            problems.push(format!(
                "a delta light's pdf_li() = {pdf} (not 0) at wi = {wi:?}"
            ));
            break;
        }
    }
    problems
}

/// A readable table of results, one line per case, failures explained.
pub fn format_light_results(results: &[LightCaseResult]) -> String {
    let mut out = String::new();
    // The case number is the one failure pictures carry
    // (`check-NAME-CASE.png`).
    let _ = writeln!(
        out,
        "{:>4} {:<10} {:<36} {:<8} {:<12} {:>10} {:>9} {:>9} {:>10}  result",
        "case", "light", "parameters", "shape", "from", "p-value", "pdf int", "sampled", "power"
    );
    for (case, r) in results.iter().enumerate() {
        let (p, integral, sampled) = r
            .chi_square
            .as_ref()
            .map_or((f64::NAN, f64::NAN, f64::NAN), |c| {
                (c.p_value, c.pdf_integral, c.sampled_fraction)
            });
        let verdict = verdict(r);
        let _ = writeln!(
            out,
            "{case:>4} {:<10} {:<36} {:<8} {:<12} {p:>10.3e} {integral:>9.5} {sampled:>9.5} {:>10.4e}  {verdict}",
            r.light,
            r.variant,
            r.shape,
            r.point,
            r.power.luminance(),
        );
        let statistic = r.chi_square.as_ref().and_then(|c| match &c.defect {
            Some(d) => Some(format!("chi-square: {d}")),
            None => (!c.passed).then(|| {
                format!(
                    "chi-square: statistic {:.1} with {} degrees of freedom",
                    c.statistic, c.degrees_of_freedom
                )
            }),
        });
        write_notes(&mut out, r, statistic);
    }
    let _ = writeln!(out, "{}", summary(results));
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::EmissionSample;

    /// An infinite light of radiance 1 above the horizon and 0 below,
    /// sampled uniformly over the sphere; its samples report
    /// `sample_scale` times the radiance `l()` gives.
    struct HalfSky {
        sample_scale: f32,
    }

    impl Light for HalfSky {
        fn kind(&self) -> LightKind {
            LightKind::Infinite
        }

        fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
            let wi = warp::square_to_uniform_sphere(u);
            Some(LightSample {
                l: self.l(ctx.p(), Vec3::ZERO, Vec2::ZERO, wi) * self.sample_scale,
                wi,
                pdf: warp::UNIFORM_SPHERE_PDF,
                p: SurfacePoint::isolated(ctx.p() + wi),
            })
        }

        fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
            warp::UNIFORM_SPHERE_PDF
        }

        fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
            if w.y > 0.0 {
                Rgb::WHITE
            } else {
                Rgb::BLACK
            }
        }

        fn power(&self) -> Rgb {
            Rgb::WHITE
        }
    }

    /// A point of intensity `(1, 2, 1)` in the upper hemisphere and half
    /// that below, which starts rays uniform over the sphere and reports
    /// their density times `pdf_scale`.
    struct Glow {
        pdf_scale: f32,
    }

    impl Light for Glow {
        fn kind(&self) -> LightKind {
            LightKind::DeltaPosition
        }

        fn sample_li(&self, _: &LightSampleContext, _: Vec2) -> Option<LightSample> {
            None
        }

        fn sample_le(&self, _: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
            let d = warp::square_to_uniform_sphere(u_dir);
            let l = Rgb::new(1.0, 2.0, 1.0) * if d.z > 0.0 { 1.0 } else { 0.5 };
            Some(EmissionSample {
                p: SurfacePoint::isolated(Vec3::ZERO),
                d,
                l,
                pdf_pos: 1.0,
                pdf_dir: warp::UNIFORM_SPHERE_PDF * self.pdf_scale,
            })
        }

        fn pdf_li(&self, _: &LightSampleContext, _: Vec3) -> f32 {
            0.0
        }

        fn l(&self, _: Vec3, _: Vec3, _: Vec2, _: Vec3) -> Rgb {
            Rgb::BLACK
        }

        fn power(&self) -> Rgb {
            Rgb::new(1.0, 2.0, 1.0) * (3.0 * std::f32::consts::PI)
        }
    }

    /// Rays that carry the light's power pass; rays whose density is 2%
    /// off fail, naming the channel.
    #[test]
    fn rays_that_miss_the_power_fail() {
        let honest = check_emission(&Glow { pdf_scale: 1.0 }, 20_000, 1);
        assert!(honest.is_empty(), "{honest:?}");
        let off = check_emission(&Glow { pdf_scale: 1.02 }, 20_000, 1);
        assert!(
            off.iter().any(|p| p.contains("sample_le starts carry")),
            "{off:?}"
        );
        let none = check_emission(&HalfSky { sample_scale: 1.0 }, 100, 1);
        assert!(none.is_empty(), "a light that starts no rays: {none:?}");
    }

    /// The spread that forgives a sample at a radiance edge does not
    /// forgive a sample whose radiance is off by 1% everywhere.
    #[test]
    fn a_sample_radiance_other_than_l_fails() {
        let ctx = LightSampleContext::at(Vec3::ZERO);
        let honest = check_values(&HalfSky { sample_scale: 1.0 }, &ctx, 2000, 1);
        assert!(honest.is_empty(), "{honest:?}");
        let off = check_values(&HalfSky { sample_scale: 1.01 }, &ctx, 2000, 1);
        assert!(
            off.iter().any(|p| p.contains("sample_li radiance")),
            "{off:?}"
        );
    }
}
