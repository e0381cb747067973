//! Every built-in light and light sampler passes the checks `lumis
//! check-plugin` runs on them (crates/lumis-check/src/light_suite.rs,
//! light_sampler_suite.rs), and the checks catch planted defects: a light
//! whose pdf is a few percent off, a light sampler whose pmf disagrees with
//! its draws, one whose pmf sums past 1, one that never picks a lit light.

use lumis_check::light_sampler_suite::{
    check_light_sampler_with, format_light_sampler_results, LightSamplerCheckConfig,
};
use lumis_check::light_suite::{check_light_with, format_light_results, LightCheckConfig};
use lumis_check::outcome::Outcome;
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Light, LightKind, LightSample, LightSampleContext, LightSampler, LightShape, Params,
    PluginKind, PluginSpec, Registrar, Registry, Result, Rgb, SampledLight, Vec2, Vec3,
};
use lumis_sampling::warp;

fn names(registry: &Registry, kind: PluginKind) -> Vec<&'static str> {
    registry
        .plugins()
        .into_iter()
        .filter(|p| p.spec.kind == kind)
        .map(|p| p.spec.name)
        .collect()
}

/// The default tier's configuration: coarser bins and fewer samples than
/// `check-plugin`'s, so every light's sweep takes about a second.
fn fast() -> LightCheckConfig {
    let mut cfg = LightCheckConfig::default();
    cfg.chi_square.z_bins = 20;
    cfg.chi_square.phi_bins = 40;
    cfg.chi_square.samples = 20_000;
    cfg.samples = 1_000;
    cfg
}

#[test]
fn every_builtin_light_passes_the_check_suite() {
    every_builtin_light_passes(&fast());
}

/// What `lumis check-plugin --light NAME` runs.
/// `cargo test -p lumis-tests --test light_checks -- --ignored`
#[test]
#[ignore = "check-plugin's configuration, about 20 s"]
fn every_builtin_light_passes_the_full_check_suite() {
    every_builtin_light_passes(&LightCheckConfig::default());
}

fn every_builtin_light_passes(cfg: &LightCheckConfig) {
    let registry = lumis_app::builtin_registry().unwrap();
    let lights = names(&registry, PluginKind::Light);
    assert!(lights.len() >= 6, "{lights:?}");
    let mut failures = Vec::new();
    for name in lights {
        let results = check_light_with(&registry, name, &[], cfg).unwrap();
        // Every light is tested on some shape from some point; area
        // lights as the emission of their own shape, and a one-sided one
        // is dark from behind: no samples, and a pdf of 0.
        assert!(results.iter().any(|r| r.refused.is_none()), "{name}");
        if ["quad", "triangle", "sphere"].contains(&name) {
            assert!(results
                .iter()
                .all(|r| r.shape == name && r.chi_square.is_some()));
        }
        if let Some(behind) = results
            .iter()
            .find(|r| r.variant == "base" && r.point == "behind")
            .and_then(|r| r.chi_square.as_ref())
        {
            assert_eq!(
                (behind.sampled_fraction, behind.pdf_integral),
                (0.0, 0.0),
                "{name}"
            );
        }
        if !results.iter().all(|r| r.passed()) {
            failures.push(format_light_results(&results));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Delta lights are reported as not testable, never as passed or failed.
#[test]
fn delta_lights_are_not_testable() {
    let registry = lumis_app::builtin_registry().unwrap();
    let cfg = fast();
    for name in ["point", "spot"] {
        let results = check_light_with(&registry, name, &[], &cfg).unwrap();
        assert!(
            results.iter().all(|r| r.refused.is_some()
                || r.not_testable
                    .as_deref()
                    .is_some_and(|w| w.starts_with("delta light"))
                    && r.chi_square.is_none()
                    && r.passed()),
            "{}",
            format_light_results(&results)
        );
        assert!(format_light_results(&results).contains("not testable"));
    }
}

/// An environment of cosine-weighted radiance about +y, sampled by its
/// cosine, whose pdf (both `pdf_li` and the pdf `sample_li` returns, so
/// the two agree) is scaled by `PERCENT` / 100.
struct Cosine<const PERCENT: u32>;

impl<const PERCENT: u32> Cosine<PERCENT> {
    fn pdf(wi: Vec3) -> f32 {
        warp::cosine_hemisphere_pdf(wi.y.max(0.0)) * PERCENT as f32 / 100.0
    }
}

impl<const PERCENT: u32> Light for Cosine<PERCENT> {
    fn kind(&self) -> LightKind {
        LightKind::Infinite
    }
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let local = warp::square_to_cosine_hemisphere(u);
        let wi = Vec3::new(local.x, local.z, local.y);
        Some(LightSample {
            l: self.l(ctx.p(), Vec3::ZERO, Vec2::ZERO, wi),
            wi,
            pdf: Self::pdf(wi),
            p: SurfacePoint::isolated(ctx.p() + 100.0 * wi),
        })
    }
    fn pdf_li(&self, _: &LightSampleContext, wi: Vec3) -> f32 {
        Self::pdf(wi)
    }
    fn l(&self, _: Vec3, _: Vec3, _: Vec2, w: Vec3) -> Rgb {
        Rgb::splat(w.y.max(0.0))
    }
    fn power(&self) -> Rgb {
        Rgb::WHITE
    }
}

fn cosine_spec(name: &'static str) -> PluginSpec {
    PluginSpec {
        kind: PluginKind::Light,
        name,
        source: lumis_api::source_file!(),
        doc: "test light",
        params: &[],
    }
}

fn environment_only(params: &Params, shape: &LightShape) -> Result<()> {
    if *shape == LightShape::None {
        Ok(())
    } else {
        Err(lumis_core::Error::msg(format!(
            "{}: no shape",
            params.owner()
        )))
    }
}

#[test]
fn a_light_whose_pdf_is_three_percent_off_fails() {
    let mut registry = lumis_app::builtin_registry().unwrap();
    registry
        .add_light(cosine_spec("cosine"), |p, shape| {
            environment_only(p, shape)?;
            Ok(Box::new(Cosine::<100>))
        })
        .unwrap();
    registry
        .add_light(cosine_spec("cosine-97"), |p, shape| {
            environment_only(p, shape)?;
            Ok(Box::new(Cosine::<97>))
        })
        .unwrap();
    let cfg = fast();
    let right = check_light_with(&registry, "cosine", &[], &cfg).unwrap();
    assert!(
        right.iter().all(|r| r.passed()),
        "{}",
        format_light_results(&right)
    );
    let wrong = check_light_with(&registry, "cosine-97", &[], &cfg).unwrap();
    // Caught by the chi-square alone: the pdf and the samples agree on
    // every value the consistency checks compare.
    assert!(
        wrong
            .iter()
            .all(|r| r.problems.is_empty() && !r.chi_square.as_ref().unwrap().passed),
        "{}",
        format_light_results(&wrong)
    );
    assert!(format_light_results(&wrong).contains("FAILED"));
}

#[test]
fn every_builtin_light_sampler_passes_the_check_suite() {
    let registry = lumis_app::builtin_registry().unwrap();
    let samplers = names(&registry, PluginKind::LightSampler);
    assert!(samplers.len() >= 2, "{samplers:?}");
    for name in samplers {
        let results =
            check_light_sampler_with(&registry, name, &[], &LightSamplerCheckConfig::default())
                .unwrap();
        assert!(
            results.iter().all(|r| r.refused.is_none() && r.passed()),
            "{}",
            format_light_sampler_results(&results)
        );
    }
}

/// Picks light `i` with frequency proportional to `i + 1`, but reports a
/// uniform pmf (consistently, from `sample` and `pmf`).
struct Lying {
    count: u32,
}

impl LightSampler for Lying {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        let n = self.count as f32;
        let total = n * (n + 1.0) / 2.0;
        let mut acc = 0.0;
        let index = (0..self.count)
            .find(|&i| {
                acc += (i + 1) as f32 / total;
                u < acc
            })
            .unwrap_or(self.count - 1);
        Some(SampledLight {
            index,
            pmf: self.pmf(ctx, index),
        })
    }
    fn pmf(&self, _: &LightSampleContext, _: u32) -> f32 {
        1.0 / self.count as f32
    }
}

/// Reports a pmf of 1/N for every light but the last, which gets
/// 1/N + 0.03: the pmf sums to 1.03.
struct OverOne {
    count: u32,
}

impl LightSampler for OverOne {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        let index = ((u * self.count as f32) as u32).min(self.count - 1);
        Some(SampledLight {
            index,
            pmf: self.pmf(ctx, index),
        })
    }
    fn pmf(&self, _: &LightSampleContext, index: u32) -> f32 {
        1.0 / self.count as f32 + if index + 1 == self.count { 0.03 } else { 0.0 }
    }
}

/// Uniform over every light but the last finite one (the stand-in sphere,
/// lit from everywhere outside it), which it never picks: consistent, but
/// biased.
struct SkipsALitLight {
    count: u32,
}

impl SkipsALitLight {
    const SKIPPED: u32 = 5;
}

impl LightSampler for SkipsALitLight {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        let k = ((u * (self.count - 1) as f32) as u32).min(self.count - 2);
        let index = if k >= Self::SKIPPED { k + 1 } else { k };
        Some(SampledLight {
            index,
            pmf: self.pmf(ctx, index),
        })
    }
    fn pmf(&self, _: &LightSampleContext, index: u32) -> f32 {
        if index == Self::SKIPPED || index >= self.count {
            0.0
        } else {
            1.0 / (self.count - 1) as f32
        }
    }
}

fn sampler_spec(name: &'static str) -> PluginSpec {
    PluginSpec {
        kind: PluginKind::LightSampler,
        name,
        source: lumis_api::source_file!(),
        doc: "test light sampler",
        params: &[],
    }
}

#[test]
fn a_light_sampler_whose_pmf_disagrees_with_its_draws_fails() {
    let mut registry = lumis_app::builtin_registry().unwrap();
    registry
        .add_light_sampler(sampler_spec("lying"), |_, lights| {
            Ok(Box::new(Lying {
                count: lights.len() as u32,
            }))
        })
        .unwrap();
    registry
        .add_light_sampler(sampler_spec("over-one"), |_, lights| {
            Ok(Box::new(OverOne {
                count: lights.len() as u32,
            }))
        })
        .unwrap();
    let cfg = LightSamplerCheckConfig::default();
    let lying = check_light_sampler_with(&registry, "lying", &[], &cfg).unwrap();
    assert!(
        lying.iter().all(|r| r.problems.is_empty() && !r.passed()),
        "{}",
        format_light_sampler_results(&lying)
    );
    registry
        .add_light_sampler(sampler_spec("skips-a-lit-light"), |_, lights| {
            Ok(Box::new(SkipsALitLight {
                count: lights.len() as u32,
            }))
        })
        .unwrap();
    let skips = check_light_sampler_with(&registry, "skips-a-lit-light", &[], &cfg).unwrap();
    assert!(
        skips
            .iter()
            .all(|r| r.problems.iter().any(|p| p.contains("light 5 has pmf 0"))),
        "{}",
        format_light_sampler_results(&skips)
    );
    let over = check_light_sampler_with(&registry, "over-one", &[], &cfg).unwrap();
    assert!(
        over.iter()
            .all(|r| r.problems.iter().any(|p| p.contains("sums to"))),
        "{}",
        format_light_sampler_results(&over)
    );
}
