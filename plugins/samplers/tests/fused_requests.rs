//! `get_1d_2d` is `get_1d` then `get_2d`, bit for bit, for every sampler
//! and every randomisation: the integrators take light and BSDF samples
//! through it, so an override that drifted would change every render.

use lumis_core::doc;
use lumis_core::registry::TableRef;
use lumis_core::{Location, PluginKind, Registry, Sampler, UVec2};

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
                let sampler = registry
                    .create_sampler(&TableRef {
                        owner: "sampler",
                        table: &table,
                        location: &Location::Builtin,
                        type_name: plugin.spec.name,
                        type_location: &Location::Builtin,
                        structural: &[],
                    })
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
