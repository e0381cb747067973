//! `Light::sample_li_batch` against a loop over `Light::sample_li` on the
//! same lanes, for the sphere light seen from outside (its cone sampling,
//! as the glossy bench scenes use it) and from inside (area sampling, which
//! the batch hands to the scalar method). Batches of 4096 lanes, each timed
//! as the best of several repeats; prints ns per lane and the ratio,
//! asserts nothing about time.
//!
//! `cargo bench -p lumis-lights --bench sample_li_batch`

use std::hint::black_box;
use std::time::Instant;

use lumis_core::{Light, LightSample, LightSampleContext, Rgb, Vec2, Vec3};
use lumis_lights::{Emission, SphereLight};

const LANES: usize = 4096;
const REPEATS: usize = 400;

/// Seconds per lane of `run` over the batch: the best of 5 rounds.
fn per_lane(mut run: impl FnMut()) -> f64 {
    (0..5)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..REPEATS {
                run();
            }
            start.elapsed().as_secs_f64() / (REPEATS * LANES) as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let fraction = |i: usize, a: f64| ((i as f64 * a).fract()) as f32;
    let center = Vec3::new(0.0, 3.0, 0.0);
    let light = SphereLight::new(
        center,
        0.5,
        false,
        Emission {
            radiance: Rgb::splat(4.0),
            two_sided: false,
        },
    )
    .unwrap();
    let u: Vec<Vec2> = (0..LANES)
        .map(|i| Vec2::new(fraction(i, 0.324_718), fraction(i, 0.754_878)))
        .collect();
    println!("{LANES} lanes, ns per lane: sample_li loop -> sample_li_batch (speed-up)");
    for (name, distance) in [
        ("outside (cone)", (2.0f32, 20.0f32)),
        ("inside (area)", (0.0, 0.4)),
    ] {
        let ctx: Vec<LightSampleContext> = (0..LANES)
            .map(|i| {
                let d = distance.0 + (distance.1 - distance.0) * fraction(i, 0.618_034);
                let phi = std::f32::consts::TAU * fraction(i, 0.414_214);
                let z = 2.0 * fraction(i, 0.732_051) - 1.0;
                let r = (1.0 - z * z).sqrt();
                LightSampleContext::at(center + d * Vec3::new(r * phi.cos(), r * phi.sin(), z))
            })
            .collect();
        let mut out: Vec<Option<LightSample>> = vec![None; LANES];
        let scalar = per_lane(|| {
            for (i, out) in out.iter_mut().enumerate() {
                *out = light.sample_li(&ctx[i], u[i]);
            }
            black_box(&mut out);
        });
        let batched = per_lane(|| {
            light.sample_li_batch(&ctx, &u, &mut out);
            black_box(&mut out);
        });
        println!(
            "sphere {name:<16} {:6.1} -> {:6.1} ns ({:.2}x)",
            scalar * 1e9,
            batched * 1e9,
            scalar / batched
        );
    }
}
