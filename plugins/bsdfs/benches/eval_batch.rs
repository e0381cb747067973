//! The batched BSDF methods against loops over the scalar ones on the same
//! lanes: `Bsdf::eval_batch` against `Bsdf::eval` (light samples) and
//! `Bsdf::sample_f_batch` against `Bsdf::sample_f`, for the rough
//! conductor with each distribution at the roughnesses of the glossy bench
//! scenes, with the perfect and a metal's Fresnel term, and for the
//! diffuse BSDF, which keeps the default loop: its `eval` is a few
//! cycles, bound by the stores, and a SIMD override measured no faster.
//! Batches of 4096 lanes (a wave's worth, in cache), each
//! timed as the best of several repeats; prints ns per lane and the ratio,
//! asserts nothing about time.
//!
//! `cargo bench -p lumis-bsdfs --bench eval_batch [-- name-filter]`

use std::hint::black_box;
use std::time::Instant;

use lumis_bsdfs::microfacet::{Distribution, Microfacet};
use lumis_bsdfs::{
    fresnel, Conductor, ConductorFresnel, Diffuse, DiffuseSampling, MicrofacetLobeSampling,
};
use lumis_core::{Bsdf, BsdfContext, BsdfSample, Rgb, Vec2, Vec3};

const LANES: usize = 4096;
const REPEATS: usize = 400;

/// A direction in the upper hemisphere from two numbers in [0, 1).
fn direction(u: f32, v: f32) -> Vec3 {
    let z = 0.02 + 0.98 * u;
    let r = (1.0 - z * z).sqrt();
    let phi = std::f32::consts::TAU * v;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Seconds per lane of `run` over the batch: the best of 5 rounds of
/// `REPEATS` runs.
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

struct Lanes {
    ctx: Vec<BsdfContext>,
    wo: Vec<Vec3>,
    wi: Vec<Vec3>,
    u1: Vec<f32>,
    u2: Vec<Vec2>,
}

fn lanes() -> Lanes {
    let fraction = |i: usize, a: f64| ((i as f64 * a).fract()) as f32;
    let wo: Vec<Vec3> = (0..LANES)
        .map(|i| direction(fraction(i, 0.618_034), fraction(i, 0.414_214)))
        .collect();
    // Light directions near the mirror direction, as light samples of a
    // glossy plate are, and some far from it.
    let wi = wo
        .iter()
        .enumerate()
        .map(|(i, w)| {
            let jitter = 0.2 * (fraction(i, 0.732_051) - 0.5);
            Vec3::new(-w.x + jitter, -w.y, w.z).normalize()
        })
        .collect();
    Lanes {
        ctx: vec![BsdfContext::default(); LANES],
        wo,
        wi,
        u1: (0..LANES).map(|i| fraction(i, 0.236_068)).collect(),
        u2: (0..LANES)
            .map(|i| Vec2::new(fraction(i, 0.324_718), fraction(i, 0.754_878)))
            .collect(),
    }
}

/// The scalar loops call the concrete type's methods, which inline, as
/// the default batched methods do: the ratio is what the SIMD override
/// adds to batching itself.
fn compare<B: Bsdf>(name: &str, bsdf: &B, l: &Lanes) {
    // An argument (other than cargo's `--bench`) selects the cases whose
    // name contains it.
    if let Some(filter) = std::env::args().skip(1).find(|a| !a.starts_with("--")) {
        if !name.contains(&filter) {
            return;
        }
    }
    let mut evals = vec![(Rgb::BLACK, 0.0); LANES];
    let mut samples: Vec<Option<BsdfSample>> = vec![None; LANES];
    let eval_loop = per_lane(|| {
        for (i, out) in evals.iter_mut().enumerate() {
            *out = bsdf.eval(&l.ctx[i], l.wo[i], l.wi[i]);
        }
        black_box(&mut evals);
    });
    let eval_batch = per_lane(|| {
        bsdf.eval_batch(&l.ctx, &l.wo, &l.wi, &mut evals);
        black_box(&mut evals);
    });
    let sample_loop = per_lane(|| {
        for (i, out) in samples.iter_mut().enumerate() {
            *out = bsdf.sample_f(&l.ctx[i], l.wo[i], l.u1[i], l.u2[i]);
        }
        black_box(&mut samples);
    });
    let sample_batch = per_lane(|| {
        bsdf.sample_f_batch(&l.ctx, &l.wo, &l.u1, &l.u2, &mut samples);
        black_box(&mut samples);
    });
    let ns = 1e9;
    println!(
        "{name:<34} eval {:6.1} -> {:6.1} ns ({:.2}x)   sample_f {:6.1} -> {:6.1} ns ({:.2}x)",
        eval_loop * ns,
        eval_batch * ns,
        eval_loop / eval_batch,
        sample_loop * ns,
        sample_batch * ns,
        sample_loop / sample_batch,
    );
}

fn main() {
    let l = lanes();
    println!(
        "{LANES} lanes, ns per lane: scalar loop -> batched (speed-up), best of 5 x {REPEATS}"
    );
    let gold = fresnel::metal("Au").expect("gold");
    for (name, distribution) in [
        ("beckmann", Distribution::Beckmann),
        ("ggx", Distribution::Ggx),
    ] {
        for alpha in [0.005, 0.05, 0.3] {
            for (metal, fresnel) in [
                ("perfect", ConductorFresnel::Perfect),
                (
                    "Au",
                    ConductorFresnel::Complex {
                        eta: gold.eta.into(),
                        k: gold.k.into(),
                    },
                ),
            ] {
                let bsdf = Conductor::new(
                    Microfacet::new(distribution, alpha, alpha),
                    fresnel,
                    MicrofacetLobeSampling::Visible.into(),
                );
                compare(&format!("conductor {name} {alpha} {metal}"), &bsdf, &l);
            }
        }
    }
    for (name, sampling) in [
        ("cosine", DiffuseSampling::Cosine),
        ("uniform", DiffuseSampling::Uniform),
    ] {
        let bsdf = Diffuse::new(Rgb::splat(0.5), false, sampling);
        // No override: the default loop, for comparison.
        compare(&format!("diffuse {name} (default)"), &bsdf, &l);
    }
}
