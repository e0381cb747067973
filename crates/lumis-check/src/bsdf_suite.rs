//! The full check of a BSDF plugin, as `lumis check-plugin` and the test
//! suite run it: over a sweep of the plugin's own parameters (both ends of
//! every declared range, every declared choice, both values of every
//! boolean) and of incident directions down to cos theta = 1e-4, check
//!
//! - chi-square goodness of fit of `sample_f` against `pdf`;
//! - `pdf` integrates to at most 1 (and to the fraction of samples returned);
//! - `sample_f` returns the `f` and `pdf` that `f()` and `pdf()` give, and
//!   `eval()` returns both exactly; the batched and lane methods answer
//!   what the scalar ones do, lane by lane (the lane methods under a mask
//!   too, the masked-out lanes untouched);
//! - energy: the directional albedo is at most 1 (a white furnace per lobe),
//!   measured in importance transport so that the `1/eta^2` radiance
//!   scaling of refraction (a change of units, not of energy) is left out;
//! - reciprocity `f(wo, wi) = f(wi, wo)` for reflection-only models;
//! - no NaN, infinite or negative value anywhere.

use std::fmt::Write;
use std::path::Path;
use std::sync::Arc;

use lumis_core::bsdf::{BsdfEvalLanes, BsdfSampleLanes};
use lumis_core::doc;
use lumis_core::lanes::{LaneMask, Vec2Lanes, Vec3Lanes, LANES};
use lumis_core::texture::Named;
use lumis_core::{
    Bsdf, BsdfContext, BsdfFlags, BsdfSample, BsdfScope, Error, Location, ParamType, PluginEntity,
    PluginKind, Registry, Result, Rgb, TransportMode, Vec2, Vec3,
};
use lumis_sampling::{warp, Pcg32};
use rayon::prelude::*;

use crate::adapters::bsdf_pair;
use crate::chi_square::{ChiSquareConfig, ChiSquareReport};
use crate::corrected_significance;
use crate::lobe_zoom::chi_square_zoomed;
use crate::outcome::{add_faults, summary, unmade, verdict, write_notes, Outcome};
use crate::sweep::declared;
pub use crate::sweep::{parameter_sweep, parameter_sweep_with, variant, Variant, STAND_IN_BSDFS};

/// How thoroughly to check.
#[derive(Debug, Clone, PartialEq)]
pub struct BsdfCheckConfig {
    /// Bins, samples and quadrature of each chi-square test; its
    /// significance is replaced by the Sidak-corrected one for the sweep.
    pub chi_square: ChiSquareConfig,
    /// Overall false-alarm rate of the whole sweep.
    pub alpha: f64,
    /// Incident cos theta values (negative ones probe the back side).
    pub cos_theta_o: Vec<f32>,
    /// Samples for the albedo, consistency and reciprocity checks.
    pub samples: usize,
}

impl Default for BsdfCheckConfig {
    fn default() -> Self {
        Self {
            chi_square: ChiSquareConfig {
                z_bins: 100,
                phi_bins: 100,
                samples: 1_000_000,
                ..Default::default()
            },
            alpha: 0.01,
            cos_theta_o: vec![1e-4, 0.01, 0.1, 0.5, 1.0, -1e-4, -0.5, -1.0],
            samples: 100_000,
        }
    }
}

/// The outcome of one (variant, incident direction) case.
#[derive(Debug, Clone)]
pub struct CaseResult {
    pub bsdf: String,
    pub variant: String,
    pub cos_theta_o: f32,
    pub chi_square: ChiSquareReport,
    /// Magnification of the lobe for the chi-square test (1: none; see
    /// [`crate::lobe_zoom`]).
    pub zoom: f64,
    /// Directional albedo estimate and its standard error.
    pub albedo: f64,
    pub albedo_se: f64,
    /// Why the chi-square test cannot decide, as the kit established it
    /// from the test itself (see [`ChiSquareReport::unresolved`]): set
    /// only for a chi-square that failed with no outright defect. The
    /// other checks still ran, and still fail the case.
    pub not_testable: Option<String>,
    /// Everything that failed besides the chi-square statistic itself.
    pub problems: Vec<String>,
    /// Why the plugin refused this parameter setting (its factory's
    /// error): a combination it declares invalid, such as two albedos
    /// summing past 1, is not tested and not a failure.
    pub refused: Option<String>,
}

impl Outcome for CaseResult {
    fn test_passed(&self) -> bool {
        self.chi_square.passed
    }
    crate::outcome::case_fields!();
}

/// [`STAND_IN_BSDFS`], made by `registry`.
fn stand_in_bsdfs(registry: &Registry) -> Result<Named<dyn Bsdf>> {
    let mut out = Named::new();
    for &(name, type_name, params) in STAND_IN_BSDFS {
        let table = doc::parse(params, "<stand-in>")?;
        let entity = PluginEntity::new(
            PluginKind::Bsdf,
            format!("stand-in bsdf \"{name}\""),
            type_name,
            table,
            Location::Builtin,
        );
        out.insert(
            name,
            registry.create::<dyn Bsdf>(&entity, BsdfScope::EMPTY)?,
        );
    }
    Ok(out)
}

/// The BSDF plugin `name` with the parameters of `variant` (which may name
/// a [`STAND_IN_BSDFS`] BSDF).
pub fn instantiate(registry: &Registry, name: &str, variant: &Variant) -> Result<Arc<dyn Bsdf>> {
    let owner = owner(name, variant);
    let entity = PluginEntity::new(
        PluginKind::Bsdf,
        owner,
        name,
        variant.table.clone(),
        Location::Builtin,
    );
    let declares_bsdfs = registry
        .find(PluginKind::Bsdf, name)
        .is_some_and(|p| p.spec.params.iter().any(|s| s.ty == ParamType::Bsdf));
    let bsdfs = if declares_bsdfs {
        stand_in_bsdfs(registry)?
    } else {
        Named::new()
    };
    let scope = BsdfScope {
        textures: &lumis_core::texture::NO_TEXTURES,
        bsdfs: &bsdfs,
    };
    registry.create::<dyn Bsdf>(&entity, scope)
}

/// The case of a variant the plugin did not make: refused (its factory
/// returned an error, untested) or failed (its factory panicked).
fn unmade_case(
    name: &str,
    variant: &Variant,
    cos_theta_o: f32,
    unmade: std::result::Result<String, String>,
) -> CaseResult {
    let (problems, refused) = match unmade {
        Ok(refusal) => (Vec::new(), Some(refusal)),
        Err(failure) => (vec![failure], None),
    };
    CaseResult {
        bsdf: name.to_string(),
        variant: variant.label.clone(),
        cos_theta_o,
        chi_square: ChiSquareReport {
            statistic: f64::NAN,
            quadrature_statistic: f64::NAN,
            quadrature_error: f64::NAN,
            degrees_of_freedom: 0,
            p_value: f64::NAN,
            pdf_integral: f64::NAN,
            sampled_fraction: f64::NAN,
            defect: Some("not tested: the plugin was not made".into()),
            passed: false,
            observed: Vec::new(),
            expected: Vec::new(),
        },
        zoom: f64::NAN,
        albedo: f64::NAN,
        albedo_se: f64::NAN,
        not_testable: None,
        problems,
        refused,
    }
}

/// How the plugin made for `variant` is named, in messages and in the
/// registry's record of faults.
fn owner(name: &str, variant: &Variant) -> String {
    format!("bsdf \"{name}\" [{}]", variant.label)
}

fn direction(cos_theta: f32, phi: f32) -> Vec3 {
    let s = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta)
}

/// Albedo, consistency, reciprocity and finiteness for one incident direction.
fn check_values(bsdf: &dyn Bsdf, wo: Vec3, samples: usize, seed: u64) -> (f64, f64, Vec<String>) {
    let ctx = BsdfContext {
        mode: TransportMode::Importance,
        ..Default::default()
    };
    let mut rng = Pcg32::new(seed, 0xa1be);
    let mut problems = Vec::new();
    let mut note = |p: String| {
        if problems.len() < 5 {
            problems.push(p);
        }
    };
    let reciprocal = !bsdf.flags().contains(BsdfFlags::TRANSMISSION);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    let mut lanes = BatchLanes::default();
    for _ in 0..samples {
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        if let Some(s) = bsdf.sample_f(&ctx, wo, u1, u2) {
            let bad = |v: f32| !v.is_finite() || v < 0.0;
            if bad(s.pdf) || bad(s.f.r) || bad(s.f.g) || bad(s.f.b) || !s.wi.is_finite() {
                note(format!(
                    "sample_f returned f = {:?}, pdf = {}, wi = {:?}",
                    s.f, s.pdf, s.wi
                ));
                continue;
            }
            if s.pdf == 0.0 {
                continue;
            }
            let weight = (s.f.max_component() * s.wi.z.abs() / s.pdf) as f64;
            sum += weight;
            sum2 += weight * weight;
            if !s.flags.is_specular() {
                let (pdf, f) = (bsdf.pdf(&ctx, wo, s.wi), bsdf.f(&ctx, wo, s.wi));
                if (pdf - s.pdf).abs() > 1e-3 * s.pdf.max(pdf) {
                    note(format!(
                        "sample_f pdf {} but pdf() = {pdf} at wi = {:?}",
                        s.pdf, s.wi
                    ));
                }
                if (f - s.f)
                    .max_component()
                    .abs()
                    .max((s.f - f).max_component().abs())
                    > 1e-3 * f.max_component().max(s.f.max_component())
                {
                    note(format!(
                        "sample_f f {:?} but f() = {f:?} at wi = {:?}",
                        s.f, s.wi
                    ));
                }
                if reciprocal {
                    let back = bsdf.f(&ctx, s.wi, wo);
                    let scale = f.max_component().max(back.max_component());
                    if (f - back).map(f32::abs).max_component() > 1e-3 * scale {
                        note(format!(
                            "not reciprocal: f(wo, wi) = {f:?}, f(wi, wo) = {back:?}, wi = {:?}",
                            s.wi
                        ));
                    }
                }
            }
        }
        // Evaluation anywhere on the sphere must be finite and non-negative.
        let wi = warp::square_to_uniform_sphere(u2);
        let radiance = BsdfContext::default();
        let (f, pdf) = (bsdf.f(&radiance, wo, wi), bsdf.pdf(&radiance, wo, wi));
        let (eval_f, eval_pdf) = bsdf.eval(&radiance, wo, wi);
        if lanes.wi.len() < BatchLanes::MAX {
            lanes.u.push((u1, u2));
            lanes.wi.push(wi);
        }
        // Compared bit for bit, so that a NaN in both is reported once,
        // as a NaN below, not as a mismatch.
        let bits = |c: Rgb| [c.r, c.g, c.b].map(f32::to_bits);
        if bits(eval_f) != bits(f) || eval_pdf.to_bits() != pdf.to_bits() {
            note(format!(
                "eval() = ({eval_f:?}, {eval_pdf}) but (f(), pdf()) = ({f:?}, {pdf}) at wi = {wi:?}"
            ));
        }
        if !f.is_finite() || f.min_component() < 0.0 || !pdf.is_finite() || pdf < 0.0 {
            note(format!("f() = {f:?}, pdf() = {pdf} at wi = {wi:?}"));
        }
    }
    for problem in check_batches(bsdf, wo, &lanes) {
        note(problem);
    }
    let n = samples as f64;
    let albedo = sum / n;
    let se = ((sum2 / n - albedo * albedo).max(0.0) / n).sqrt();
    if albedo > 1.0 + 4.0 * se + 1e-3 {
        problems.push(format!(
            "directional albedo {albedo:.5} > 1 (standard error {se:.5}): creates energy"
        ));
    }
    (albedo, se, problems)
}

/// The lanes the batched methods are checked on: the value check's
/// random numbers and directions.
#[derive(Default)]
struct BatchLanes {
    u: Vec<(f32, Vec2)>,
    wi: Vec<Vec3>,
}

impl BatchLanes {
    /// Enough lanes for every SIMD width and a partial last chunk.
    const MAX: usize = 1021;
}

/// `sample_f_batch` and `eval_batch` against `sample_f` and `eval`, lane
/// by lane: the same samples and values up to rounding (a relative 1e-4,
/// and `None` or zero exactly where the scalar method gives them).
///
/// The lanes differ as a wave's do, so that an override that reads one
/// lane's arguments for another fails: `wo` cycles through the case's
/// direction, the same turned a quarter about the normal, and its mirror
/// image through the surface (the back side); the transport mode
/// alternates; a BSDF that takes an albedo scale gets one on some lanes.
/// Each method runs on the whole batch (a partial last SIMD chunk for
/// every width up to 16) and on prefixes of 1 and 3 lanes.
fn check_batches(bsdf: &dyn Bsdf, wo: Vec3, lanes: &BatchLanes) -> Vec<String> {
    let n = lanes.wi.len();
    let wos: Vec<Vec3> = (0..n)
        .map(|i| match i % 3 {
            0 => wo,
            1 => Vec3::new(-wo.y, wo.x, wo.z),
            _ => Vec3::new(wo.x, wo.y, -wo.z),
        })
        .collect();
    let ctx: Vec<BsdfContext> = (0..n)
        .map(|i| BsdfContext {
            mode: if i % 2 == 0 {
                TransportMode::Radiance
            } else {
                TransportMode::Importance
            },
            // Each lane at its own uv, so a textured BSDF's lanes differ.
            texture: lumis_core::TextureQuery::at(Vec2::new(
                (i as f32 * 0.37).fract(),
                (i as f32 * 0.61).fract(),
            )),
        })
        .collect();
    let u1: Vec<f32> = lanes.u.iter().map(|u| u.0).collect();
    let u2: Vec<Vec2> = lanes.u.iter().map(|u| u.1).collect();
    let mut problems = Vec::new();
    for len in [n, 1, 3] {
        let len = len.min(n);
        let mut samples = vec![None; len];
        bsdf.sample_f_batch(
            &ctx[..len],
            &wos[..len],
            &u1[..len],
            &u2[..len],
            &mut samples,
        );
        let mut evals = vec![(Rgb::splat(f32::NAN), f32::NAN); len];
        bsdf.eval_batch(&ctx[..len], &wos[..len], &lanes.wi[..len], &mut evals);
        for i in 0..len {
            let scalar = bsdf.sample_f(&ctx[i], wos[i], u1[i], u2[i]);
            if !samples_agree(&scalar, &samples[i]) {
                problems.push(format!(
                    "sample_f_batch lane {i} of {len} gave {:?} but sample_f gave {scalar:?} (wo = {:?}, u1 = {}, u2 = {:?}, {:?})",
                    samples[i], wos[i], u1[i], u2[i], ctx[i].mode
                ));
            }
            let (f, pdf) = bsdf.eval(&ctx[i], wos[i], lanes.wi[i]);
            let (bf, bpdf) = evals[i];
            if !evals_agree((f, pdf), evals[i]) {
                problems.push(format!(
                    "eval_batch lane {i} of {len} gave ({bf:?}, {bpdf}) but eval gave ({f:?}, {pdf}) (wo = {:?}, wi = {:?}, {:?})",
                    wos[i], lanes.wi[i], ctx[i].mode
                ));
            }
            if problems.len() >= 2 {
                return problems;
            }
        }
    }
    problems.extend(check_lanes(bsdf, &ctx, &wos, &u1, &u2, &lanes.wi));
    problems
}

/// Equal up to rounding: a relative 1e-4.
fn close(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a - b).abs() <= 1e-4 * a.abs().max(b.abs())
}

fn close_rgb(a: Rgb, b: Rgb) -> bool {
    close(a.r, b.r) && close(a.g, b.g) && close(a.b, b.b)
}

/// Two answers of `sample_f`'s: the same sample up to rounding, or none.
fn samples_agree(a: &Option<BsdfSample>, b: &Option<BsdfSample>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => {
            close_rgb(a.f, b.f)
                && close(a.pdf, b.pdf)
                && (a.wi - b.wi).abs().max_element() <= 1e-4
                && a.flags == b.flags
                && close(a.eta, b.eta)
        }
        _ => false,
    }
}

fn evals_agree((f, pdf): (Rgb, f32), (g, qdf): (Rgb, f32)) -> bool {
    close_rgb(f, g) && close(pdf, qdf)
}

/// `sample_f_lanes` and `eval_lanes` against `sample_f` and `eval`, a
/// packet of [`LANES`] of the batch's lanes at a time: with every lane
/// active, and with a mask that leaves some out, whose lanes (filled with
/// a marker beforehand) must come back untouched.
fn check_lanes(
    bsdf: &dyn Bsdf,
    ctx: &[BsdfContext],
    wo: &[Vec3],
    u1: &[f32],
    u2: &[Vec2],
    wi: &[Vec3],
) -> Vec<String> {
    let marker = BsdfSample {
        f: Rgb::splat(-1.0),
        wi: Vec3::splat(-1.0),
        pdf: -1.0,
        flags: BsdfFlags::SPECULAR,
        eta: -1.0,
    };
    for start in (0..wo.len().saturating_sub(LANES - 1)).step_by(LANES) {
        let mut packet = (
            [BsdfContext::default(); LANES],
            Vec3Lanes::default(),
            [0.0; LANES],
            Vec2Lanes::default(),
            Vec3Lanes::default(),
        );
        for i in 0..LANES {
            packet.0[i] = ctx[start + i];
            packet.1.set(i, wo[start + i]);
            packet.2[i] = u1[start + i];
            packet.3.set(i, u2[start + i]);
            packet.4.set(i, wi[start + i]);
        }
        for active in [LaneMask::ALL, LaneMask::from_bits(0b0110_1001)] {
            let mut samples = BsdfSampleLanes::default();
            let mut evals = BsdfEvalLanes::default();
            for i in (!active).iter() {
                samples.set(i, Some(marker));
                evals.set(i, (marker.f, marker.pdf));
            }
            bsdf.sample_f_lanes(
                &packet.0,
                &packet.1,
                &packet.2,
                &packet.3,
                active,
                &mut samples,
            );
            bsdf.eval_lanes(&packet.0, &packet.1, &packet.4, active, &mut evals);
            for i in 0..LANES {
                let k = start + i;
                let (want_sample, want_eval) = if active.contains(i) {
                    (
                        bsdf.sample_f(&ctx[k], wo[k], u1[k], u2[k]),
                        bsdf.eval(&ctx[k], wo[k], wi[k]),
                    )
                } else {
                    (Some(marker), (marker.f, marker.pdf))
                };
                if !samples_agree(&want_sample, &samples.get(i)) {
                    return vec![format!(
                        "sample_f_lanes lane {i} of mask {:#010b} gave {:?} but {want_sample:?} was expected (wo = {:?}, u1 = {}, u2 = {:?}, {:?})",
                        active.bits(), samples.get(i), wo[k], u1[k], u2[k], ctx[k].mode
                    )];
                }
                if !(evals.valid.contains(i) && evals_agree(want_eval, evals.get(i))) {
                    return vec![format!(
                        "eval_lanes lane {i} of mask {:#010b} gave {:?} but {want_eval:?} was expected (wo = {:?}, wi = {:?}, {:?})",
                        active.bits(), evals.get(i), wo[k], wi[k], ctx[k].mode
                    )];
                }
            }
        }
    }
    Vec::new()
}

/// Runs every check over the sweep of the plugin's declared parameters
/// (see [`parameter_sweep`]) for the BSDF plugin `name`.
pub fn check_bsdf(
    registry: &Registry,
    name: &str,
    cfg: &BsdfCheckConfig,
) -> Result<Vec<CaseResult>> {
    let spec = declared(registry, PluginKind::Bsdf, name)?;
    check_bsdf_variants(registry, name, &parameter_sweep(&spec)?, cfg)
}

/// [`check_bsdf`] with parameters held fixed (see [`parameter_sweep_with`]).
pub fn check_bsdf_with(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    cfg: &BsdfCheckConfig,
) -> Result<Vec<CaseResult>> {
    let spec = declared(registry, PluginKind::Bsdf, name)?;
    check_bsdf_variants(registry, name, &parameter_sweep_with(&spec, fixed)?, cfg)
}

/// Runs every check for each of `variants` of the BSDF plugin `name` and
/// each incident direction of `cfg`, the cases in parallel; the chi-square
/// significance is corrected for the number of cases.
pub fn check_bsdf_variants(
    registry: &Registry,
    name: &str,
    variants: &[Variant],
    cfg: &BsdfCheckConfig,
) -> Result<Vec<CaseResult>> {
    // A variant the plugin cannot make fails its cases; the others go on.
    let bsdfs: Vec<_> = variants
        .iter()
        .map(|v| instantiate(registry, name, v))
        .collect();
    let mut work = Vec::new();
    for (variant, bsdf) in variants.iter().zip(&bsdfs) {
        for (i, c) in directions_of(variant, &cfg.cos_theta_o) {
            work.push((work.len(), variant, bsdf, i, c));
        }
    }
    let tests: usize = work
        .iter()
        .filter_map(|w| w.2.as_ref().ok())
        .map(|b| hemispheres(b.as_ref()).len())
        .sum();
    let chi_cfg = ChiSquareConfig {
        significance: corrected_significance(cfg.alpha, tests),
        ..cfg.chi_square
    };
    let case_variants: Vec<&Variant> = work.iter().map(|w| w.1).collect();
    let mut results: Vec<CaseResult> = work
        .into_par_iter()
        .map(|(case, variant, bsdf, i, c)| {
            let bsdf = match bsdf {
                Ok(bsdf) => bsdf,
                Err(e) => {
                    return unmade_case(
                        name,
                        variant,
                        c,
                        unmade(registry, &owner(name, variant), e),
                    )
                }
            };
            let wo = direction(c, 0.3 + i as f32);
            // Each case (and hemisphere) draws its own samples, so the
            // tests are independent as the Sidak correction assumes.
            let (report, zoom) = hemispheres(bsdf.as_ref())
                .iter()
                .enumerate()
                .map(|(h, side)| {
                    let (mut sample, pdf) = bsdf_pair(bsdf.as_ref(), wo);
                    let case_cfg = ChiSquareConfig {
                        seed: chi_cfg.seed.wrapping_add(2 * case as u64 + h as u64),
                        ..chi_cfg
                    };
                    chi_square_zoomed(
                        move |u1, u2| sample(u1, u2).filter(|d| side.contains(*d)),
                        move |d| if side.contains(d) { pdf(d) } else { 0.0 },
                        &case_cfg,
                    )
                })
                .min_by(|a, b| a.0.p_value.total_cmp(&b.0.p_value))
                .expect("at least one hemisphere");
            let (albedo, albedo_se, problems) =
                check_values(bsdf.as_ref(), wo, cfg.samples, i as u64);
            let not_testable = if report.passed || report.defect.is_some() {
                None
            } else {
                report.unresolved()
            };
            CaseResult {
                bsdf: name.to_string(),
                variant: variant.label.clone(),
                cos_theta_o: c,
                chi_square: report,
                zoom,
                albedo,
                albedo_se,
                not_testable,
                problems,
                refused: None,
            }
        })
        .collect();
    // A loaded plugin that panicked answered with neutral values (see
    // lumis_api::guard); every case of its variant fails with the panic.
    for (result, variant) in results.iter_mut().zip(case_variants) {
        add_faults(registry, &owner(name, variant), &mut result.problems);
    }
    Ok(results)
}

/// The incident directions `(index, cos theta_o)` a variant is checked at:
/// all of them; or, for a value inside a range (a stratum of the sweep), a
/// share at full strength: each stratum one front-side direction, and
/// every other stratum one back-side direction too, in turn, so that the
/// ten strata of a range take 15 cases (two full values took 16), every
/// stratum meets the side every BSDF has, and together they meet every
/// direction.
fn directions_of(variant: &Variant, cos_theta_o: &[f32]) -> Vec<(usize, f32)> {
    let all = cos_theta_o.iter().copied().enumerate();
    let Some(k) = variant.stratum else {
        return all.collect();
    };
    let (front, back): (Vec<_>, Vec<_>) = all.partition(|&(_, c)| c > 0.0);
    let mut chosen = Vec::new();
    if !front.is_empty() {
        chosen.push(front[k % front.len()]);
    }
    if (k % 2 == 1 || front.is_empty()) && !back.is_empty() {
        chosen.push(back[(k / 2) % back.len()]);
    }
    chosen
}

/// Where a chi-square test looks for samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Hemisphere {
    All,
    Upper,
    Lower,
}

impl Hemisphere {
    fn contains(self, d: Vec3) -> bool {
        match self {
            Self::All => true,
            Self::Upper => d.z >= 0.0,
            Self::Lower => d.z < 0.0,
        }
    }
}

/// A BSDF that reflects and transmits has two lobes on opposite sides,
/// which no single lobe zoom can magnify together: each hemisphere is then
/// tested on its own (the sampler restricted to it, the pdf zero outside;
/// samples on the other side count as missing mass, so the split between
/// the lobes is tested too). The table shows the worse of the two.
fn hemispheres(bsdf: &dyn Bsdf) -> &'static [Hemisphere] {
    let flags = bsdf.flags();
    if flags.contains(BsdfFlags::TRANSMISSION)
        && flags.contains(BsdfFlags::REFLECTION)
        && flags.is_non_specular()
    {
        &[Hemisphere::Upper, Hemisphere::Lower]
    } else {
        &[Hemisphere::All]
    }
}

/// A readable table of results, one line per case, failures explained.
pub fn format_results(results: &[CaseResult]) -> String {
    let mut out = String::new();
    // The case number is the one failure pictures carry
    // (`check-NAME-CASE.png`).
    let _ = writeln!(
        out,
        "{:>4} {:<11} {:<44} {:>8} {:>7} {:>10} {:>9} {:>9} {:>8}  result",
        "case", "bsdf", "parameters", "cos_o", "zoom", "p-value", "pdf int", "sampled", "albedo"
    );
    for (case, r) in results.iter().enumerate() {
        let c = &r.chi_square;
        let _ = writeln!(
            out,
            "{case:>4} {:<11} {:<44} {:>8} {:>7.0} {:>10.3e} {:>9.5} {:>9.5} {:>8.4}  {}",
            r.bsdf,
            r.variant,
            r.cos_theta_o,
            r.zoom,
            c.p_value,
            c.pdf_integral,
            c.sampled_fraction,
            r.albedo,
            verdict(r)
        );
        let statistic = match &c.defect {
            Some(d) => Some(format!("chi-square: {d}")),
            None => (!c.passed && r.not_testable.is_none()).then(|| {
                format!(
                    "chi-square: statistic {:.1} with {} degrees of freedom",
                    c.statistic, c.degrees_of_freedom
                )
            }),
        };
        write_notes(&mut out, r, statistic);
    }
    let _ = writeln!(out, "{}", summary(results));
    out
}

/// Writes observed (left) and expected (right) histograms side by side as a
/// PNG: rows are cos theta from -1 (top) to 1, columns phi.
pub fn write_histogram_png(
    report: &ChiSquareReport,
    cfg: &ChiSquareConfig,
    path: &Path,
) -> Result<()> {
    let (w, h) = (cfg.phi_bins, cfg.z_bins);
    let gap = 2;
    let mut image = lumis_image::Image::new(2 * w + gap, h);
    let max = report
        .observed
        .iter()
        .chain(&report.expected)
        .fold(0.0f64, |m, &v| m.max(v))
        .max(1.0);
    for z in 0..h {
        for phi in 0..w {
            let i = z * w + phi;
            // Square root so that low-count bins stay visible beside a peak.
            let o = (report.observed[i] / max).sqrt() as f32;
            let e = (report.expected[i] / max).sqrt() as f32;
            image.set(phi, z, [o, o, o]);
            image.set(w + gap + phi, z, [e, e, e]);
        }
        for x in w..w + gap {
            image.set(x, z, [1.0, 0.0, 0.0]);
        }
    }
    lumis_image::write_png(path, &image).map_err(|e| Error::msg(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::{BsdfSample, Registrar};

    /// A Lambertian BSDF whose batched methods can be made wrong.
    #[derive(Default)]
    struct Lambert {
        wrong_eval_batch: bool,
        wrong_sample_batch: bool,
        /// `eval_batch` reads the first lane's `wo` for every lane.
        first_wo: bool,
        /// `sample_f_lanes` answers every lane, not only the active ones.
        every_lane: bool,
        /// `f` is NaN below the horizon.
        nan_below: bool,
        /// `pdf` claims samples bunched toward the normal as `cos^1.05`
        /// (normalised), which `sample_f` does not draw.
        wrong_pdf: bool,
    }

    impl Bsdf for Lambert {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::DIFFUSE_REFLECTION
        }
        fn f(&self, _: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
            if wo.z > 0.0 && wi.z > 0.0 {
                Rgb::splat(std::f32::consts::FRAC_1_PI)
            } else if self.nan_below && wi.z < 0.0 {
                Rgb::splat(f32::NAN)
            } else {
                Rgb::BLACK
            }
        }
        fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, _: f32, u: Vec2) -> Option<BsdfSample> {
            let wi = warp::square_to_cosine_hemisphere(u);
            BsdfSample::reflection(
                wi,
                BsdfFlags::DIFFUSE_REFLECTION,
                |wi| self.pdf(ctx, wo, wi),
                |wi| self.f(ctx, wo, wi),
            )
        }
        fn pdf(&self, _: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
            if wo.z > 0.0 && wi.z > 0.0 && self.wrong_pdf {
                // cos^n / (2 pi / (n + 1)), n = 1.05.
                wi.z.powf(1.05) * 2.05 / (2.0 * std::f32::consts::PI)
            } else if wo.z > 0.0 && wi.z > 0.0 {
                wi.z * std::f32::consts::FRAC_1_PI
            } else {
                0.0
            }
        }
        fn sample_f_batch(
            &self,
            ctx: &[BsdfContext],
            wo: &[Vec3],
            u1: &[f32],
            u2: &[Vec2],
            out: &mut [Option<BsdfSample>],
        ) {
            for (i, out) in out.iter_mut().enumerate() {
                // The wrong override drops the last lane of each eight.
                *out = if self.wrong_sample_batch && i % 8 == 7 {
                    None
                } else {
                    self.sample_f(&ctx[i], wo[i], u1[i], u2[i])
                };
            }
        }
        fn eval_batch(
            &self,
            ctx: &[BsdfContext],
            wo: &[Vec3],
            wi: &[Vec3],
            out: &mut [(Rgb, f32)],
        ) {
            for (i, out) in out.iter_mut().enumerate() {
                let wo = if self.first_wo { wo[0] } else { wo[i] };
                let (f, pdf) = self.eval(&ctx[i], wo, wi[i]);
                // The wrong override forgets the cosine in the pdf.
                *out = if self.wrong_eval_batch && pdf > 0.0 {
                    (f, std::f32::consts::FRAC_1_PI)
                } else {
                    (f, pdf)
                };
            }
        }
        fn sample_f_lanes(
            &self,
            ctx: &[BsdfContext; LANES],
            wo: &Vec3Lanes,
            u1: &[f32; LANES],
            u2: &Vec2Lanes,
            active: LaneMask,
            out: &mut BsdfSampleLanes,
        ) {
            let lanes = if self.every_lane {
                LaneMask::ALL
            } else {
                active
            };
            for i in lanes.iter() {
                out.set(i, self.sample_f(&ctx[i], wo.get(i), u1[i], u2.get(i)));
            }
        }
    }

    #[test]
    fn wrong_batched_overrides_are_reported() {
        let wo = direction(0.6, 0.3);
        let check = |bsdf: Lambert| check_values(&bsdf, wo, 4000, 7).2;
        let right = check(Lambert::default());
        assert!(right.is_empty(), "{right:?}");
        let eval = check(Lambert {
            wrong_eval_batch: true,
            ..Default::default()
        });
        assert!(
            eval.iter().any(|p| p.starts_with("eval_batch lane")),
            "{eval:?}"
        );
        let sample = check(Lambert {
            wrong_sample_batch: true,
            ..Default::default()
        });
        assert!(
            sample
                .iter()
                .any(|p| p.starts_with("sample_f_batch lane 7")),
            "{sample:?}"
        );
        // The lanes' own `wo` matters: lane 2 looks from behind.
        let first = check(Lambert {
            first_wo: true,
            ..Default::default()
        });
        assert!(
            first.iter().any(|p| p.starts_with("eval_batch lane 2 ")),
            "{first:?}"
        );
        // A lane method writes the lanes it is asked for, and no other.
        let every = check(Lambert {
            every_lane: true,
            ..Default::default()
        });
        assert!(
            every
                .iter()
                .any(|p| p.starts_with("sample_f_lanes lane 1 of mask 0b01101001")),
            "{every:?}"
        );
    }

    /// A pdf a few percent off at a resolvable setting fails the suite,
    /// and the kit does not excuse it as not testable.
    #[test]
    fn a_wrong_pdf_fails_and_is_not_excused() {
        let mut registry = Registry::new();
        let spec = lumis_core::PluginSpec {
            kind: PluginKind::Bsdf,
            name: "wrong-lambert",
            source: lumis_api::source_file!(),
            doc: "",
            params: &[],
        };
        registry
            .add_bsdf(spec, |_| {
                Ok(Arc::new(Lambert {
                    wrong_pdf: true,
                    ..Default::default()
                }))
            })
            .unwrap();
        let cfg = BsdfCheckConfig {
            chi_square: ChiSquareConfig {
                z_bins: 20,
                phi_bins: 40,
                samples: 200_000,
                ..Default::default()
            },
            cos_theta_o: vec![0.5, 1.0],
            samples: 1000,
            ..Default::default()
        };
        let variants = [variant("base", "").unwrap()];
        let results = check_bsdf_variants(&registry, "wrong-lambert", &variants, &cfg).unwrap();
        let table = format_results(&results);
        assert!(
            results
                .iter()
                .all(|r| !r.passed() && r.not_testable.is_none() && !r.chi_square.passed),
            "{table}"
        );
        assert!(
            table.contains("FAILED") && !table.contains("not testable:"),
            "{table}"
        );
    }

    /// A NaN is reported as a NaN, not as `eval` disagreeing with `f`.
    #[test]
    fn a_nan_is_reported_as_a_nan() {
        let wo = direction(0.6, 0.3);
        let problems = check_values(
            &Lambert {
                nan_below: true,
                ..Default::default()
            },
            wo,
            400,
            7,
        )
        .2;
        assert!(
            problems
                .iter()
                .any(|p| p.starts_with("f() = Rgb") && p.contains("NaN")),
            "{problems:?}"
        );
        assert!(
            !problems.iter().any(|p| p.starts_with("eval()")),
            "{problems:?}"
        );
    }
}
