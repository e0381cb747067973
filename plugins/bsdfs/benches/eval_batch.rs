//! `Bsdf::eval_batch` against a loop over `Bsdf::eval` on the same lanes,
//! for the rough conductor with each distribution and roughness of the
//! glossy bench scenes: the speed-up of its SIMD override. Prints the best
//! of five timings of each and their ratio; asserts nothing about time.
//!
//! `cargo bench -p lumis-bsdfs --bench eval_batch`

use std::hint::black_box;
use std::time::Instant;

use lumis_bsdfs::microfacet::{Distribution, Microfacet};
use lumis_bsdfs::{Conductor, ConductorFresnel, LobeSampling};
use lumis_core::{Bsdf, BsdfContext, Rgb, Vec3};

/// A direction in the upper hemisphere from two numbers in [0, 1).
fn direction(u: f32, v: f32) -> Vec3 {
    let z = 0.02 + 0.98 * u;
    let r = (1.0 - z * z).sqrt();
    let phi = std::f32::consts::TAU * v;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn best_of<T>(repeats: usize, mut run: impl FnMut() -> T) -> f64 {
    (0..repeats)
        .map(|_| {
            let start = Instant::now();
            black_box(run());
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    const LANES: usize = 1 << 20;
    let fraction = |i: usize, a: f64| ((i as f64 * a).fract()) as f32;
    let wo: Vec<Vec3> = (0..LANES)
        .map(|i| direction(fraction(i, 0.618_034), fraction(i, 0.414_214)))
        .collect();
    // Light directions near the mirror direction, as light samples of a
    // glossy plate are, and some far from it.
    let wi: Vec<Vec3> = wo
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let jitter = 0.2 * (fraction(i, 0.732_051) - 0.5);
            Vec3::new(-w.x + jitter, -w.y, w.z).normalize()
        })
        .collect();
    let ctx = vec![BsdfContext::default(); LANES];
    let mut out = vec![(Rgb::BLACK, 0.0); LANES];
    println!("{LANES} lanes, best of 5");
    for (name, distribution) in [
        ("beckmann", Distribution::Beckmann),
        ("ggx", Distribution::Ggx),
    ] {
        for alpha in [0.005, 0.05, 0.3] {
            let bsdf = Conductor::new(
                Microfacet::new(distribution, alpha, alpha),
                ConductorFresnel::Perfect,
                LobeSampling::parse("visible"),
            );
            let scalar = best_of(5, || {
                for i in 0..LANES {
                    out[i] = bsdf.eval(&ctx[i], wo[i], wi[i]);
                }
                out[LANES / 2]
            });
            let batched = best_of(5, || {
                bsdf.eval_batch(&ctx, &wo, &wi, &mut out);
                out[LANES / 2]
            });
            println!(
                "conductor {name} alpha {alpha}: eval loop {:.1} ns/lane, eval_batch {:.1} ns/lane, speed-up {:.2}x",
                scalar / LANES as f64 * 1e9,
                batched / LANES as f64 * 1e9,
                scalar / batched
            );
        }
    }
}
