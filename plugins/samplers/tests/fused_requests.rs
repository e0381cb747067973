//! `get_1d_2d` is `get_1d` then `get_2d`, bit for bit, for every sampler
//! and every randomisation: the integrators take light and BSDF samples
//! through it, so an override that drifted would change every render. The
//! same holds for its batched form over a sampler's lanes.

use lumis_core::doc;
use lumis_core::{Location, PluginEntity, PluginKind, Registry, Sampler, UVec2};

const SPP: u32 = 512;

/// Every sampler plugin, with every value of its `randomize` and
/// `dimensions` choices (their effect on the hot path differs).
fn variants(registry: &Registry) -> Vec<(String, Box<dyn Sampler>)> {
    let mut out = Vec::new();
    for plugin in registry.plugins() {
        if plugin.spec.kind != PluginKind::Sampler {
            continue;
        }
        let choices = |key: &str| -> Vec<Option<String>> {
            plugin
                .spec
                .params
                .iter()
                .find(|p| p.name == key)
                .map(|p| p.choices.iter().map(|c| Some(c.to_string())).collect())
                .unwrap_or_else(|| vec![None])
        };
        for randomize in choices("randomize") {
            for dimensions in choices("dimensions") {
                let mut text = format!("spp = {SPP}\n");
                for (key, value) in [("randomize", &randomize), ("dimensions", &dimensions)] {
                    if let Some(v) = value {
                        text += &format!("{key} = \"{v}\"\n");
                    }
                }
                let table = doc::parse(&text, "test.toml").unwrap();
                let entity = PluginEntity::new(
                    PluginKind::Sampler,
                    "sampler",
                    plugin.spec.name,
                    table,
                    Location::Builtin,
                );
                let sampler = registry
                    .create::<dyn Sampler>(&entity, ())
                    .unwrap_or_else(|e| panic!("{}: {e}", plugin.spec.name));
                out.push((format!("{} {text:?}", plugin.spec.name), sampler));
            }
        }
    }
    out
}

#[test]
fn fused_1d_2d_requests_match_separate_ones() {
    let mut registry = Registry::new();
    lumis_samplers::register(&mut registry).unwrap();
    let all = variants(&registry);
    assert!(all.len() >= 10, "{} sampler variants", all.len());
    for (name, mut fused) in all {
        let mut separate = fused.clone_sampler();
        // Two samples of each pixel, so that the second finds the first's
        // cached seeds; an index past the Sobol' sampler's table of the
        // first 256 points.
        for (pixel, index) in [
            (UVec2::new(3, 7), 0),
            (UVec2::new(3, 7), 1),
            (UVec2::new(200, 1), 5),
            (UVec2::new(200, 1), 14),
            (UVec2::new(9, 9), 15),
            (UVec2::new(9, 9), 300),
        ] {
            fused.start_pixel_sample(pixel, index, 42);
            separate.start_pixel_sample(pixel, index, 42);
            assert_eq!(fused.get_pixel_2d(), separate.get_pixel_2d(), "{name}");
            // Dozens of requests: past the dimensions samplers tabulate.
            for request in 0..40 {
                let (u, v) = fused.get_1d_2d();
                let (a, b) = (separate.get_1d(), separate.get_2d());
                assert_eq!(
                    (u.to_bits(), v.x.to_bits(), v.y.to_bits()),
                    (a.to_bits(), b.x.to_bits(), b.y.to_bits()),
                    "{name}, pixel {pixel}, sample {index}, request {request}"
                );
                // Interleave plain requests, as an integrator does.
                assert_eq!(
                    fused.get_1d().to_bits(),
                    separate.get_1d().to_bits(),
                    "{name}"
                );
            }
        }
    }
}

/// Each lane of `Sampler::lanes`, asked through `get_1d_2d_batch` over
/// changing subsets of lanes and through single requests in between, draws
/// exactly what a lone clone started on the same pixel sample draws.
#[test]
fn batched_requests_match_lone_samplers() {
    let mut registry = Registry::new();
    lumis_samplers::register(&mut registry).unwrap();
    const N: usize = 6;
    for (name, sampler) in variants(&registry) {
        let mut lanes = sampler.lanes(N);
        assert_eq!(lanes.len(), N, "{name}");
        let mut lone: Vec<Box<dyn Sampler>> = (0..N).map(|_| sampler.clone_sampler()).collect();
        for (i, lone) in lone.iter_mut().enumerate() {
            let (pixel, index) = (UVec2::new(i as u32 % 3, 40 + i as u32), 7 * i as u32);
            lanes.with_lane(i, |lane| lane.start_pixel_sample(pixel, index, 42));
            lone.start_pixel_sample(pixel, index, 42);
            let film = lanes.with_lane(i, |lane| lane.get_pixel_2d());
            assert_eq!(film, lone.get_pixel_2d(), "{name}");
        }
        let subsets: [&[usize]; 3] = [&[0, 1, 2, 3, 4, 5], &[1, 4], &[5, 0, 3]];
        for request in 0..30 {
            let subset = subsets[request % subsets.len()];
            let mut batched = vec![(f32::NAN, lumis_core::Vec2::NAN); subset.len()];
            lanes.get_1d_2d_batch(subset, &mut batched);
            for (&i, &(u, v)) in subset.iter().zip(&batched) {
                let (a, b) = lone[i].get_1d_2d();
                assert_eq!(
                    (u.to_bits(), v.x.to_bits(), v.y.to_bits()),
                    (a.to_bits(), b.x.to_bits(), b.y.to_bits()),
                    "{name}: lane {i}, request {request}"
                );
            }
            // A single request of one lane between batches, as `plan` and
            // Russian roulette make.
            let i = request % N;
            assert_eq!(
                lanes.with_lane(i, |lane| lane.get_1d()).to_bits(),
                lone[i].get_1d().to_bits(),
                "{name}: lane {i}"
            );
        }
    }
}
