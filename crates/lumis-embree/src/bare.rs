//! A bare Embree ray loop: the baseline that lumis's throughput is measured
//! against. Each ray costs exactly one `rtcIntersect1` or `rtcOccluded1`
//! call on the raw scene, nothing else.

use embree4_sys as sys;

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
    let raw = scene.raw();
    let mut hits = 0;
    for r in rays {
        let ray = sys::RTCRay {
            org_x: r.org[0],
            org_y: r.org[1],
            org_z: r.org[2],
            tnear: 0.0,
            dir_x: r.dir[0],
            dir_y: r.dir[1],
            dir_z: r.dir[2],
            time: 0.0,
            tfar: r.tfar,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        };
        if r.shadow {
            let mut ray = ray;
            // SAFETY: committed, live scene; valid RTCRay; default arguments.
            unsafe { sys::rtcOccluded1(raw, &mut ray, std::ptr::null_mut()) };
            hits += u64::from(ray.tfar == f32::NEG_INFINITY);
        } else {
            let mut rayhit = sys::RTCRayHit {
                ray,
                hit: crate::scene::empty_hit(),
            };
            // SAFETY: as above, with a properly aligned RTCRayHit.
            unsafe { sys::rtcIntersect1(raw, &mut rayhit, std::ptr::null_mut()) };
            hits += u64::from(rayhit.hit.geomID != sys::RTC_INVALID_GEOMETRY_ID);
        }
    }
    hits
}
