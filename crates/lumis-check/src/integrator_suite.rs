//! The check of an integrator plugin, as `lumis check-plugin` and the test
//! suite run it: over a sweep of the plugin's own parameters, render tiny
//! scenes and test the image means, Sidak-corrected over every test:
//!
//! - white furnace: an albedo-1 diffuse sphere under a constant
//!   environment, where every pixel is exactly the environment's radiance
//!   once paths reach one bounce (the sphere is convex, so the bounce
//!   escapes);
//! - Neumann series: a closed box of emissive walls of albedo a, seen from
//!   inside, where the radiance is exactly `Le (1 + a + ... + a^(D-1))`
//!   for path depth D;
//! - agreement with the built-in `path` at the same depth on a lit box,
//!   pixel block by pixel block (a two-sample test on the per-pixel
//!   differences of independent renders).
//!
//! The exact values need the number of path segments the integrator takes:
//! its `max_depth` parameter, or [`KNOWN_DEPTHS`]. An integrator with
//! neither is "not testable". The suite renders scenes, so it needs the
//! scene loader and Embree: the `integrators` feature of this crate.

use std::collections::HashMap;
use std::fmt::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use crate::corrected_significance;
use crate::outcome::{self, add_faults, summary, unmade, verdict, write_notes, Outcome as _};
use crate::sweep::{declared, parameter_sweep_with, Variant};
use lumis_core::params::{ParamDefault, ParamValue};
use lumis_core::{
    doc::Value, Error, Integrator, Location, PluginEntity, PluginKind, PluginSpec, Registry, Result,
};
use lumis_image::Image;
use lumis_render::{render, RenderSettings};
use statrs::distribution::{ContinuousCDF, Normal};

/// Integrators without a `max_depth` parameter whose depth the kit knows:
/// `direct` adds direct lighting to the emission seen, two segments.
pub const KNOWN_DEPTHS: &[(&str, u32)] = &[("direct", 2)];

/// How thoroughly to check.
#[derive(Debug, Clone, PartialEq)]
pub struct IntegratorCheckConfig {
    /// Film width and height in pixels.
    pub resolution: usize,
    /// Samples per pixel of the furnace renders.
    pub spp: u32,
    /// Samples per pixel of the comparison with `path` (each of the two
    /// renders): a block mean there has the spread of a whole scene.
    pub compare_spp: u32,
    /// Side of the square pixel blocks compared with `path`.
    pub block: usize,
    /// Overall false-alarm rate of the whole sweep.
    pub alpha: f64,
    pub seed: u64,
}

impl Default for IntegratorCheckConfig {
    fn default() -> Self {
        Self {
            resolution: 16,
            spp: 16,
            compare_spp: 64,
            block: 8,
            alpha: 0.01,
            seed: 1,
        }
    }
}

/// The scenes an integrator is checked on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IntegratorTest {
    /// Albedo-1 sphere in a constant environment: exactly the environment.
    Furnace,
    /// Closed emissive box of albedo 0.9: the truncated series.
    NeumannSeries,
    /// A lit box, against the built-in `path` at the same depth.
    AgreesWithPath,
}

impl IntegratorTest {
    const ALL: [Self; 3] = [Self::Furnace, Self::NeumannSeries, Self::AgreesWithPath];

    fn label(self) -> &'static str {
        match self {
            Self::Furnace => "furnace",
            Self::NeumannSeries => "emissive box",
            Self::AgreesWithPath => "same as path",
        }
    }
}

/// The constant environment's radiance in the furnace.
const ENVIRONMENT: [f64; 3] = [0.5, 1.0, 2.0];
/// The emissive box's wall albedo and emitted radiance.
const BOX_ALBEDO: f64 = 0.9;
const BOX_EMISSION: [f64; 3] = [1.0, 0.5, 0.25];

/// The outcome of one (variant, test) case.
#[derive(Debug, Clone)]
pub struct IntegratorCaseResult {
    pub integrator: String,
    pub variant: String,
    pub test: IntegratorTest,
    /// The image mean per channel (of the difference from `path`, for
    /// [`IntegratorTest::AgreesWithPath`]).
    pub mean: [f64; 3],
    /// The exact value per channel (zero difference, for the comparison).
    pub expected: [f64; 3],
    /// The largest |z| over channels (and blocks), and its two-sided
    /// p-value.
    pub z: f64,
    pub p_value: f64,
    /// The (Sidak-corrected) significance the p-value is held to.
    pub significance: f64,
    /// Everything that failed besides the z-test itself.
    pub problems: Vec<String>,
    /// Why the plugin refused this parameter setting (its factory's error).
    pub refused: Option<String>,
    /// Why the kit cannot check this case.
    pub not_testable: Option<String>,
}

impl outcome::Outcome for IntegratorCaseResult {
    fn test_passed(&self) -> bool {
        self.p_value >= self.significance
    }
    outcome::case_fields!();
}

fn owner(name: &str, variant: &Variant) -> String {
    format!("integrator \"{name}\" [{}]", variant.label)
}

/// Runs every check over the sweep of the integrator plugin `name`'s
/// declared parameters, with parameters in `fixed` held at the given
/// values (see [`parameter_sweep_with`]). `registry` must also hold the
/// built-in plugins the scenes use (`path`, `diffuse`, `constant`, ...).
pub fn check_integrator_with(
    registry: &Registry,
    name: &str,
    fixed: &[(String, String)],
    cfg: &IntegratorCheckConfig,
) -> Result<Vec<IntegratorCaseResult>> {
    let spec = declared(registry, PluginKind::Integrator, name)?;
    if cfg.resolution == 0 || cfg.block == 0 || cfg.spp == 0 || cfg.compare_spp == 0 {
        return Err(Error::msg(
            "integrator check: resolution, block, spp and compare_spp must be positive",
        ));
    }
    let variants = parameter_sweep_with(&spec, fixed)?;
    let blocks = cfg.resolution.div_ceil(cfg.block).pow(2);
    // One z-test per channel for each furnace, per channel and block for
    // the comparison.
    let tests = variants.len() * 3 * (2 + blocks);
    let significance = corrected_significance(cfg.alpha, tests);
    let mut results = Vec::new();
    let mut renders = Renders::new(registry);
    for (v, variant) in variants.iter().enumerate() {
        let depth = declared_depth(&spec, variant);
        let entity = PluginEntity::new(
            PluginKind::Integrator,
            owner(name, variant),
            name,
            variant.table.clone(),
            Location::Builtin,
        );
        let made = registry.create::<dyn Integrator>(&entity, ());
        // A value inside a range is rendered with its share of the samples.
        let cfg = &IntegratorCheckConfig {
            spp: variant.samples(cfg.spp as usize) as u32,
            compare_spp: variant.samples(cfg.compare_spp as usize) as u32,
            ..cfg.clone()
        };
        for (t, test) in IntegratorTest::ALL.into_iter().enumerate() {
            let mut result = IntegratorCaseResult {
                integrator: name.to_string(),
                variant: variant.label.clone(),
                test,
                mean: [f64::NAN; 3],
                expected: [f64::NAN; 3],
                z: f64::NAN,
                p_value: f64::NAN,
                significance,
                problems: Vec::new(),
                refused: None,
                not_testable: None,
            };
            let seed = cfg
                .seed
                .wrapping_add((v * IntegratorTest::ALL.len() + t) as u64);
            match &made {
                Ok(integrator) => measure(
                    &mut renders,
                    integrator.as_ref(),
                    test,
                    depth,
                    cfg,
                    seed,
                    &mut result,
                ),
                Err(e) => match unmade(registry, &owner(name, variant), e) {
                    Ok(refusal) => result.refused = Some(refusal),
                    Err(failure) => result.problems.push(failure),
                },
            }
            add_faults(registry, &owner(name, variant), &mut result.problems);
            results.push(result);
        }
    }
    Ok(results)
}

/// Renders one case into `result`, or says why it cannot be tested.
fn measure(
    renders: &mut Renders,
    integrator: &dyn Integrator,
    test: IntegratorTest,
    depth: Option<u32>,
    cfg: &IntegratorCheckConfig,
    seed: u64,
    result: &mut IntegratorCaseResult,
) {
    let Some(depth) = depth else {
        result.not_testable = Some(format!(
            "\"{}\" declares no max_depth parameter, so the exact value is unknown",
            result.integrator
        ));
        return;
    };
    if depth < 2 && test == IntegratorTest::Furnace {
        result.not_testable = Some(
            "short of 2 segments the sphere is black: the image mean has no exact value".into(),
        );
        return;
    }
    let run = catch_unwind(AssertUnwindSafe(|| {
        run_case(renders, integrator, test, depth, cfg, seed)
    }));
    match run {
        Ok(Ok(outcome)) => outcome.fill(result),
        Ok(Err(e)) => result.problems.push(e.to_string()),
        Err(panic) => result
            .problems
            .push(format!("panicked: {}", panic_message(&panic))),
    }
}

/// The path segments `variant` asks for: its `max_depth` (set, or the
/// declared default), else the kit's [`KNOWN_DEPTHS`].
fn declared_depth(spec: &PluginSpec, variant: &Variant) -> Option<u32> {
    let Some(param) = spec.params.iter().find(|p| p.name == "max_depth") else {
        return KNOWN_DEPTHS
            .iter()
            .find(|(n, _)| *n == spec.name)
            .map(|&(_, d)| d);
    };
    match variant.table.get("max_depth").map(|n| &n.value) {
        Some(&Value::Int(d)) => u32::try_from(d).ok(),
        Some(_) => None,
        None => match param.default {
            ParamDefault::Value(ParamValue::Int(d)) => u32::try_from(d).ok(),
            _ => None,
        },
    }
}

fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into())
}

/// A case's measurement: mean, exact value, worst |z|.
struct Outcome {
    mean: [f64; 3],
    expected: [f64; 3],
    z: f64,
    nonfinite: u64,
}

impl Outcome {
    fn fill(self, result: &mut IntegratorCaseResult) {
        result.mean = self.mean;
        result.expected = self.expected;
        result.z = self.z;
        result.p_value = two_sided_p(self.z);
        if self.nonfinite > 0 {
            result
                .problems
                .push(format!("{} non-finite radiance estimates", self.nonfinite));
        }
    }
}

/// Two-sided normal p-value of `z`; NaN (nothing measured) is 0.
fn two_sided_p(z: f64) -> f64 {
    if z.is_nan() {
        return 0.0;
    }
    let normal = Normal::standard();
    2.0 * (1.0 - normal.cdf(z.abs()))
}

fn run_case(
    renders: &mut Renders,
    integrator: &dyn Integrator,
    test: IntegratorTest,
    depth: u32,
    cfg: &IntegratorCheckConfig,
    seed: u64,
) -> Result<Outcome> {
    let registry = renders.registry;
    match test {
        IntegratorTest::Furnace => {
            let (image, nonfinite) = render_with(registry, &furnace_scene(cfg), integrator, seed)?;
            Ok(against_exact(&image, ENVIRONMENT, nonfinite))
        }
        IntegratorTest::NeumannSeries => {
            let (image, nonfinite) = render_with(registry, &emissive_box(cfg), integrator, seed)?;
            let series: f64 = (0..depth).map(|k| BOX_ALBEDO.powi(k as i32)).sum();
            Ok(against_exact(
                &image,
                BOX_EMISSION.map(|le| le * series),
                nonfinite,
            ))
        }
        IntegratorTest::AgreesWithPath => {
            let scene = lit_box(cfg, depth);
            let (image, nonfinite) = render_with(registry, &scene, integrator, seed)?;
            let reference = renders.path_reference(cfg, depth)?;
            Ok(against_reference(&image, reference, cfg.block, nonfinite))
        }
    }
}

/// What the cases render with: the registry, and the built-in `path`'s
/// images of the lit box, made once per depth and sample count and shared
/// by every setting compared with them (their noise then correlates the
/// tests, which leaves the Sidak correction conservative).
struct Renders<'r> {
    registry: &'r Registry,
    path_references: HashMap<(u32, u32), Image>,
}

impl<'r> Renders<'r> {
    fn new(registry: &'r Registry) -> Self {
        Self {
            registry,
            path_references: HashMap::new(),
        }
    }

    /// `path`'s image of the lit box at `depth`, at `cfg.compare_spp`.
    fn path_reference(&mut self, cfg: &IntegratorCheckConfig, depth: u32) -> Result<&Image> {
        let key = (depth, cfg.compare_spp);
        if !self.path_references.contains_key(&key) {
            let loaded = load(self.registry, &lit_box(cfg, depth))?;
            let reference = render(
                &loaded.camera,
                &loaded.scene,
                loaded.integrator.as_ref(),
                loaded.sampler.as_ref(),
                &settings(&loaded, cfg.seed ^ 0x9e37_79b9_7f4a_7c15),
            )?;
            self.path_references.insert(key, reference.image);
        }
        Ok(&self.path_references[&key])
    }
}

fn settings(loaded: &lumis_scene::LoadedScene, seed: u64) -> RenderSettings {
    RenderSettings {
        spp: loaded.sampler.samples_per_pixel(),
        seed,
        threads: 0,
        progress: false,
        clamp: loaded.clamp,
    }
}

fn load(registry: &Registry, toml: &str) -> Result<lumis_scene::LoadedScene> {
    lumis_scene::load_str(toml, Path::new("check.toml"), &[], registry)
}

/// Renders the scene `toml` with `integrator` in place of its own.
fn render_with(
    registry: &Registry,
    toml: &str,
    integrator: &dyn Integrator,
    seed: u64,
) -> Result<(Image, u64)> {
    let loaded = load(registry, toml)?;
    let out = render(
        &loaded.camera,
        &loaded.scene,
        integrator,
        loaded.sampler.as_ref(),
        &settings(&loaded, seed),
    )?;
    Ok((out.image, out.stats.nonfinite))
}

/// Mean and its standard error from the spread of `values`.
fn mean_and_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
    (mean, (var / n).sqrt())
}

/// The z-score of a mean against its expectation; a noise-free mean is
/// held to float rounding.
fn z_score(mean: f64, expected: f64, se: f64) -> f64 {
    let off = mean - expected;
    if off.abs() <= 1e-5 * expected.abs().max(1e-3) {
        0.0
    } else if se == 0.0 {
        f64::INFINITY
    } else {
        off / se
    }
}

/// Every pixel has the same exact value: the pixels are independent
/// estimates of it, so their spread gives the mean's standard error.
fn against_exact(image: &Image, expected: [f64; 3], nonfinite: u64) -> Outcome {
    let mut mean = [0.0; 3];
    let mut z = 0.0f64;
    for c in 0..3 {
        let values: Vec<f64> = image.pixels.iter().map(|p| f64::from(p[c])).collect();
        let (m, se) = mean_and_se(&values);
        mean[c] = m;
        z = worst(z, z_score(m, expected[c], se));
    }
    Outcome {
        mean,
        expected,
        z,
        nonfinite,
    }
}

/// The larger |z|, NaN winning (a NaN mean is a failure).
fn worst(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b.abs())
    }
}

/// Per block and channel, the mean of the per-pixel differences of two
/// independent renders is zero if they agree in expectation; the spread of
/// the differences measures the noise of both.
fn against_reference(image: &Image, reference: &Image, block: usize, nonfinite: u64) -> Outcome {
    let mut z = 0.0f64;
    let mut mean = [0.0; 3];
    for by in (0..image.height).step_by(block) {
        for bx in (0..image.width).step_by(block) {
            for c in 0..3 {
                let mut diffs = Vec::new();
                for y in by..(by + block).min(image.height) {
                    for x in bx..(bx + block).min(image.width) {
                        diffs.push(
                            f64::from(image.get(x, y)[c]) - f64::from(reference.get(x, y)[c]),
                        );
                    }
                }
                let (m, se) = mean_and_se(&diffs);
                z = worst(z, z_score(m, 0.0, se));
            }
        }
    }
    for (c, m) in mean.iter_mut().enumerate() {
        let n = image.pixels.len() as f64;
        *m = image
            .pixels
            .iter()
            .zip(&reference.pixels)
            .map(|(a, b)| f64::from(a[c]) - f64::from(b[c]))
            .sum::<f64>()
            / n;
    }
    Outcome {
        mean,
        expected: [0.0; 3],
        z,
        nonfinite,
    }
}

/// Film, independent sampler and the `path` integrator the scene loader
/// needs (the integrator under test replaces it).
fn header(cfg: &IntegratorCheckConfig, spp: u32, camera: &str, max_depth: u32) -> String {
    format!(
        "[film]\nresolution = [{r}, {r}]\n[camera]\ntype = \"perspective\"\n{camera}\n\
         [sampler]\ntype = \"independent\"\nspp = {spp}\n\
         [integrator]\ntype = \"path\"\nmax_depth = {max_depth}\n",
        r = cfg.resolution,
    )
}

fn furnace_scene(cfg: &IntegratorCheckConfig) -> String {
    let [r, g, b] = ENVIRONMENT;
    header(
        cfg,
        cfg.spp,
        "origin = [0.0, 0.0, 4.0]\ntarget = [0.0, 0.0, 0.0]\nfov = 40.0",
        8,
    ) + &format!(
        "[[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 1.0\n\
         [[shape]]\ntype = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\nbsdf = \"white\"\n\
         [[light]]\ntype = \"constant\"\nradiance = [{r:?}, {g:?}, {b:?}]\n"
    )
}

/// The faces of [-1, 1]^3 as quads: corner, two edges, outward normal
/// `u x v` (a closed scene flips them to face inward). The furnace tests
/// build their emitting box from the same list.
pub const CUBE_FACES: [([i32; 3], [i32; 3], [i32; 3]); 6] = [
    ([1, -1, -1], [0, 2, 0], [0, 0, 2]),
    ([-1, -1, -1], [0, 0, 2], [0, 2, 0]),
    ([-1, 1, -1], [0, 0, 2], [2, 0, 0]),
    ([-1, -1, -1], [2, 0, 0], [0, 0, 2]),
    ([-1, -1, 1], [2, 0, 0], [0, 2, 0]),
    ([-1, -1, -1], [0, 2, 0], [2, 0, 0]),
];

fn quad(corner: [i32; 3], u: [i32; 3], v: [i32; 3], bsdf: &str, extra: &str) -> String {
    let f = |a: [i32; 3]| format!("{:?}", a.map(f64::from));
    format!(
        "[[shape]]\ntype = \"quad\"\ncorner = {}\nedge_u = {}\nedge_v = {}\nbsdf = \"{bsdf}\"\nflip_normals = true\n{extra}",
        f(corner),
        f(u),
        f(v)
    )
}

const INSIDE_CAMERA: &str = "origin = [0.1, -0.2, 0.05]\ntarget = [0.3, 0.1, 1.0]\nfov = 100.0";

fn emissive_box(cfg: &IntegratorCheckConfig) -> String {
    let [r, g, b] = BOX_EMISSION;
    let mut toml = header(cfg, cfg.spp, INSIDE_CAMERA, 8)
        + &format!("[[bsdf]]\nname = \"grey\"\ntype = \"diffuse\"\nreflectance = {BOX_ALBEDO:?}\n");
    for (corner, u, v) in CUBE_FACES {
        let emission = format!("emission = {{ radiance = [{r:?}, {g:?}, {b:?}] }}\n");
        toml += &quad(corner, u, v, "grey", &emission);
    }
    toml
}

/// A closed box with a red and a green wall, an emissive ceiling panel and
/// a sphere: shadows, colour bleeding and several bounces.
fn lit_box(cfg: &IntegratorCheckConfig, max_depth: u32) -> String {
    let mut toml = header(
        cfg,
        cfg.compare_spp,
        "origin = [0.0, 0.0, 0.9]\ntarget = [0.0, 0.0, -1.0]\nfov = 90.0",
        max_depth,
    ) + "[[bsdf]]\nname = \"white\"\ntype = \"diffuse\"\nreflectance = 0.7\n\
         [[bsdf]]\nname = \"red\"\ntype = \"diffuse\"\nreflectance = [0.6, 0.05, 0.05]\n\
         [[bsdf]]\nname = \"green\"\ntype = \"diffuse\"\nreflectance = [0.1, 0.5, 0.1]\n";
    for (i, (corner, u, v)) in CUBE_FACES.into_iter().enumerate() {
        let bsdf = match i {
            0 => "green",
            1 => "red",
            _ => "white",
        };
        toml += &quad(corner, u, v, bsdf, "");
    }
    toml + "[[shape]]\ntype = \"quad\"\ncorner = [-0.8, 0.99, -0.8]\nedge_u = [1.6, 0.0, 0.0]\n\
            edge_v = [0.0, 0.0, 1.6]\nbsdf = \"white\"\nemission = { radiance = 2.0 }\n\
            [[shape]]\ntype = \"sphere\"\ncenter = [0.3, -0.6, -0.3]\nradius = 0.4\nbsdf = \"white\"\n"
}

/// A readable table of results, one line per case, failures explained.
pub fn format_integrator_results(results: &[IntegratorCaseResult]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:>4} {:<10} {:<28} {:<13} {:>30} {:>30} {:>10}  result",
        "case", "integrator", "parameters", "test", "mean", "exact", "p-value"
    );
    let rgb = |v: [f64; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
    for (case, r) in results.iter().enumerate() {
        let _ = writeln!(
            out,
            "{case:>4} {:<10} {:<28} {:<13} {:>30} {:>30} {:>10.3e}  {}",
            r.integrator,
            r.variant,
            r.test.label(),
            rgb(r.mean),
            rgb(r.expected),
            r.p_value,
            verdict(r)
        );
        let statistic = (r.problems.is_empty() && !r.passed()).then(|| {
            format!(
                "z-test: |z| = {:.2}, p-value below {:.3e}",
                r.z, r.significance
            )
        });
        write_notes(&mut out, r, statistic);
    }
    let _ = writeln!(out, "{}", summary(results));
    out
}
