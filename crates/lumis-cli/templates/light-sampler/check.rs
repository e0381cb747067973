//! Checks that the probabilities sum to 1, that `sample` picks each light
//! as often as `pmf` says (stratified numbers, so the counts are exact up
//! to one per light) and reports the same probability.

use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Light, LightKind, LightSample, LightSampleContext, LightSampler, PluginKind, Registry, Rgb,
    Vec2, Vec3,
};

use {{lib}}::PowerSampler;

/// A point light of a given intensity: all the sampler sees is its power.
struct Bulb {
    position: Vec3,
    intensity: Rgb,
}

impl Light for Bulb {
    fn kind(&self) -> LightKind {
        LightKind::DeltaPosition
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        let to_light = self.position - ctx.p();
        let d2 = to_light.length_squared();
        Some(LightSample {
            l: self.intensity / d2,
            wi: to_light / d2.sqrt(),
            pdf: 1.0,
            p: SurfacePoint::isolated(self.position),
        })
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }

    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn power(&self) -> Rgb {
        self.intensity * (4.0 * std::f32::consts::PI)
    }
}

fn lights(intensities: &[f32]) -> Vec<Box<dyn Light>> {
    intensities
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            Box::new(Bulb {
                position: Vec3::new(i as f32, 2.0, 0.0),
                intensity: Rgb::splat(v),
            }) as Box<dyn Light>
        })
        .collect()
}

const SCENES: [&[f32]; 4] = [&[1.0], &[1.0, 3.0], &[0.5, 0.0, 2.0, 1.5], &[0.0, 0.0]];

#[test]
fn probabilities_sum_to_one() {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    for intensities in SCENES {
        let sampler = PowerSampler::new(&lights(intensities));
        let sum: f32 = (0..intensities.len() as u32)
            .map(|i| sampler.pmf(&ctx, i))
            .sum();
        assert!((sum - 1.0).abs() < 1e-6, "{intensities:?}: {sum}");
        assert_eq!(sampler.pmf(&ctx, intensities.len() as u32), 0.0);
    }
    assert!(PowerSampler::new(&[]).sample(&ctx, 0.5).is_none());
}

#[test]
fn picks_each_light_as_often_as_its_pmf() {
    let ctx = LightSampleContext::at(Vec3::ZERO);
    let n = 100_000;
    for intensities in SCENES {
        let sampler = PowerSampler::new(&lights(intensities));
        let mut counts = vec![0usize; intensities.len()];
        for k in 0..n {
            let u = (k as f32 + 0.5) / n as f32;
            let chosen = sampler.sample(&ctx, u).unwrap();
            assert_eq!(chosen.pmf, sampler.pmf(&ctx, chosen.index));
            counts[chosen.index as usize] += 1;
        }
        for (i, &count) in counts.iter().enumerate() {
            let expected = f64::from(sampler.pmf(&ctx, i as u32)) * n as f64;
            assert!(
                (count as f64 - expected).abs() <= 2.0,
                "{intensities:?}, light {i}: {count} picks, {expected} expected"
            );
        }
    }
}

#[test]
fn registers_as_a_light_sampler() {
    let mut registry = Registry::new();
    {{lib}}::register(&mut registry).unwrap();
    assert!(registry
        .find(PluginKind::LightSampler, {{lib}}::SPEC.name)
        .is_some());
}
