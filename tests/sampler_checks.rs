//! Every built-in sampler passes the checks `lumis check-plugin --sampler`
//! runs (values in [0, 1), determinism, the declared film pattern exactly,
//! uniformity), and samplers with planted defects fail them: a 1.0, an
//! order-dependent stream, a false net declaration, skewed numbers.

use lumis_check::outcome::Outcome;
use lumis_check::sampler_suite::{check_sampler_with, format_sampler_results, SamplerCheckConfig};
use lumis_core::{
    PixelPattern, PluginKind, PluginSpec, Registrar, Registry, Result, Sampler, UVec2, Vec2,
};
use lumis_sampling::{hash_u64, Pcg32};

/// Fewer pixels, seeds and pooled pixels than `check-plugin`'s default.
fn fast() -> SamplerCheckConfig {
    SamplerCheckConfig {
        pixels: vec![UVec2::new(0, 0), UVec2::new(7, 3), UVec2::new(65535, 65535)],
        seeds: vec![0, u64::MAX],
        draws: 4096,
        ..SamplerCheckConfig::default()
    }
}

#[test]
fn every_builtin_sampler_passes_the_check_suite() {
    let registry = lumis_app::builtin_registry().unwrap();
    let names = registry.names(PluginKind::Sampler);
    assert!(names.len() >= 7, "{names:?}");
    let mut failures = Vec::new();
    for name in names {
        let results = check_sampler_with(&registry, name, &[], &fast()).unwrap();
        if !results.iter().all(|r| r.passed()) {
            failures.push(format_sampler_results(&results));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// What a planted sampler gets wrong.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Defect {
    /// Returns exactly 1.0 for one film coordinate.
    One,
    /// Keeps drawing from one stream whatever sample it is asked to start.
    OrderDependent,
    /// Independent numbers, declared a (0, m, 2)-net.
    FalseNet,
    /// Squares every number: skewed towards 0.
    Skewed,
}

/// An independent sampler with `DEFECT`.
#[derive(Clone)]
struct Planted<const DEFECT: u8> {
    rng: Pcg32,
    index: u32,
}

const DEFECTS: [Defect; 4] = [
    Defect::One,
    Defect::OrderDependent,
    Defect::FalseNet,
    Defect::Skewed,
];

impl<const DEFECT: u8> Planted<DEFECT> {
    const DEFECT: Defect = DEFECTS[DEFECT as usize];

    fn next(&mut self) -> f32 {
        let u = self.rng.next_f32();
        if Self::DEFECT == Defect::Skewed {
            u * u
        } else {
            u
        }
    }
}

impl<const DEFECT: u8> Sampler for Planted<DEFECT> {
    fn samples_per_pixel(&self) -> u32 {
        16
    }
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.index = index;
        if Self::DEFECT != Defect::OrderDependent {
            let key = hash_u64(((pixel.x as u64) << 32 | pixel.y as u64) ^ seed);
            self.rng = Pcg32::new(key, index as u64);
        }
    }
    fn get_1d(&mut self) -> f32 {
        self.next()
    }
    fn get_2d(&mut self) -> Vec2 {
        let x = self.next();
        Vec2::new(x, self.next())
    }
    fn get_pixel_2d(&mut self) -> Vec2 {
        let p = self.get_2d();
        if Self::DEFECT == Defect::One && self.index == 3 {
            Vec2::new(1.0, p.y)
        } else {
            p
        }
    }
    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(self.clone())
    }
    fn pixel_pattern(&self) -> PixelPattern {
        if Self::DEFECT == Defect::FalseNet {
            PixelPattern::Net02
        } else {
            PixelPattern::Random
        }
    }
}

fn register<const DEFECT: u8>(registry: &mut Registry, name: &'static str) {
    fn make<const DEFECT: u8>(_: &lumis_core::Params) -> Result<Box<dyn Sampler>> {
        Ok(Box::new(Planted::<DEFECT> {
            rng: Pcg32::new(1, 1),
            index: 0,
        }))
    }
    let spec = PluginSpec {
        kind: PluginKind::Sampler,
        name,
        source: lumis_api::source_file!(),
        doc: "a sampler with a planted defect",
        params: &[],
    };
    registry.add_sampler(spec, make::<DEFECT>).unwrap();
}

#[test]
fn samplers_with_planted_defects_fail() {
    let mut registry = lumis_app::builtin_registry().unwrap();
    register::<0>(&mut registry, "gives-one");
    register::<1>(&mut registry, "order-dependent");
    register::<2>(&mut registry, "false-net");
    register::<3>(&mut registry, "skewed");
    for (name, expected) in [
        ("gives-one", "outside [0, 1): 1.0"),
        ("order-dependent", "not deterministic"),
        ("false-net", "not the declared Net02"),
        ("skewed", "not uniform"),
    ] {
        let results = check_sampler_with(&registry, name, &[], &fast()).unwrap();
        let report = format_sampler_results(&results);
        assert!(results.iter().any(|r| !r.passed()), "{name}: {report}");
        assert!(report.contains(expected), "{name}: {report}");
        assert!(report.contains("FAILED"), "{name}: {report}");
    }
}
