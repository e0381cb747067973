//! A bare Embree ray loop: the baseline that lumis's throughput is measured
//! against. Each ray costs exactly one `rtcIntersect1` or `rtcOccluded1`
//! call on the raw scene, nothing else; or, for packets, one lane of an
//! `rtcIntersect4/8/16` or `rtcOccluded4/8/16` call.

use embree4_sys as sys;

use crate::packet::{Packets, MAX_PACKET};
use crate::ray::Ray;
use crate::record::{raw_ray, RayHit};
use crate::scene::Scene;

/// A recorded query: a closest-hit ray or a shadow ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BareRay {
    pub org: [f32; 3],
    pub dir: [f32; 3],
    pub tfar: f32,
    pub shadow: bool,
}

/// Traces every ray through `embree4-sys` directly; returns how many hit
/// (or were occluded), so the work cannot be optimised away.
pub fn trace(scene: &Scene, rays: &[BareRay]) -> u64 {
    trace_impl(scene, rays, false)
}

/// As [`trace`], but each ray's origin is made to depend (through an
/// opaque zero mask) on the previous ray's result, as in a path tracer
/// where the next ray starts where the last one hit. The rays are the same;
/// only the CPU's freedom to overlap consecutive queries is taken away.
pub fn trace_dependent(scene: &Scene, rays: &[BareRay]) -> u64 {
    trace_impl(scene, rays, true)
}

fn trace_impl(scene: &Scene, rays: &[BareRay], dependent: bool) -> u64 {
    let raw = scene.raw();
    let mask = std::hint::black_box(0u32);
    let mut previous = 0u32;
    let mut hits = 0;
    for r in rays {
        let mut org = r.org;
        if dependent {
            org[0] = f32::from_bits(org[0].to_bits() ^ (previous & mask));
        }
        let ray = Ray {
            org,
            dir: r.dir,
            tnear: 0.0,
            tfar: r.tfar,
        };
        if r.shadow {
            let mut ray = raw_ray(&ray);
            // SAFETY: committed, live scene; valid RTCRay; default arguments.
            unsafe { sys::rtcOccluded1(raw, &mut ray, std::ptr::null_mut()) };
            hits += u64::from(ray.tfar == f32::NEG_INFINITY);
            previous = ray.tfar.to_bits();
        } else {
            let mut rayhit = RayHit::new(&ray);
            // SAFETY: as above, with an aligned RTCRayHit that has room for
            // every field the runtime writes (see `record`).
            unsafe { sys::rtcIntersect1(raw, rayhit.as_raw(), std::ptr::null_mut()) };
            hits += u64::from(rayhit.found());
            previous = rayhit.ray.tfar.to_bits();
        }
    }
    hits
}

/// As [`trace`], with each run of consecutive rays of one kind traced as
/// packets ([`Scene::intersect_packets`], [`Scene::occluded_packets`]); a
/// packet never spans two runs, so a run whose length is not a multiple of
/// the width ends in a partial packet.
pub fn trace_packets(scene: &Scene, packets: Packets, rays: &[BareRay]) -> u64 {
    let mut hits = 0;
    for run in rays.chunk_by(|a, b| a.shadow == b.shadow) {
        // Staged MAX_PACKET rays at a time on the stack: whole packets of
        // every width.
        for chunk in run.chunks(MAX_PACKET) {
            let n = chunk.len();
            let mut queries = [Ray {
                org: [0.0; 3],
                dir: [0.0; 3],
                tnear: 0.0,
                tfar: 0.0,
            }; MAX_PACKET];
            for (q, r) in queries.iter_mut().zip(chunk) {
                *q = Ray {
                    org: r.org,
                    dir: r.dir,
                    tnear: 0.0,
                    tfar: r.tfar,
                };
            }
            if chunk[0].shadow {
                let mut out = [false; MAX_PACKET];
                scene.occluded_packets(packets, &queries[..n], &mut out[..n]);
                hits += out.iter().filter(|&&o| o).count() as u64;
            } else {
                let mut out = [None; MAX_PACKET];
                scene.intersect_packets(packets, &queries[..n], &mut out[..n]);
                hits += out.iter().filter(|o| o.is_some()).count() as u64;
            }
        }
    }
    hits
}
