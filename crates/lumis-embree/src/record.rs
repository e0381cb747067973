//! The ray and ray-hit records handed to `rtcIntersect1` / `rtcOccluded1`.
//!
//! `embree4-sys` is generated from the Embree 4.2 headers, but the runtime
//! lumis links may be newer. Embree 4.3 added instance arrays, and a runtime
//! built with them (the default, and the 4.4 wheel `build.rs` fetches) lays
//! `RTCHit` out as
//!
//! ```c
//! float Ng_x, Ng_y, Ng_z, u, v;
//! unsigned int primID, geomID;
//! unsigned int instID[RTC_MAX_INSTANCE_LEVEL_COUNT];
//! unsigned int instPrimID[RTC_MAX_INSTANCE_LEVEL_COUNT];  // new in 4.3
//! ```
//!
//! and writes `instPrimID` on every hit through an instance. Passed the 4.2
//! `RTCRayHit` (80 bytes), that store lands past its end, on the caller's
//! stack. [`RayHit`] is the 4.2 record followed by room for both arrays at
//! any instance depth up to [`MAX_INSTANCE_LEVELS`]; the fields lumis reads
//! sit at the same offsets in every layout.

use std::mem::MaybeUninit;

use embree4_sys as sys;

use crate::ray::Ray;

/// The deepest instance stack (`RTC_MAX_INSTANCE_LEVEL_COUNT`) of a runtime
/// whose hits fit in a [`RayHit`]. Embree's default is 1; lumis instances
/// one level deep.
pub(crate) const MAX_INSTANCE_LEVELS: usize = 8;

/// Words Embree may write after the 4.2 `RTCHit`, whose `instID` holds one
/// word: `instID[1..L]` and `instPrimID[0..L]`, `2 L - 1` words, rounded up
/// to the record's 16-byte alignment.
const TAIL_WORDS: usize = (2 * MAX_INSTANCE_LEVELS - 1).next_multiple_of(4);

/// An `RTCRayHit` with room for whatever a newer runtime writes after it.
#[repr(C, align(16))]
pub(crate) struct RayHit {
    pub ray: sys::RTCRay,
    pub hit: sys::RTCHit,
    /// Written by Embree, never read; left uninitialised so a query costs
    /// no extra stores.
    _tail: MaybeUninit<[u32; TAIL_WORDS]>,
}

// `RTCRayHit` must be a prefix of `RayHit` for the pointer cast in `as_raw`.
const _: () = {
    assert!(std::mem::offset_of!(RayHit, ray) == std::mem::offset_of!(sys::RTCRayHit, ray));
    assert!(std::mem::offset_of!(RayHit, hit) == std::mem::offset_of!(sys::RTCRayHit, hit));
    assert!(std::mem::size_of::<RayHit>() >= std::mem::size_of::<sys::RTCRayHit>());
    assert!(std::mem::align_of::<RayHit>() >= std::mem::align_of::<sys::RTCRayHit>());
};

impl RayHit {
    /// A closest-hit query for `ray`, with no hit recorded yet.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        Self {
            ray: raw_ray(ray),
            hit: empty_hit(),
            _tail: MaybeUninit::uninit(),
        }
    }

    /// The record as Embree's API takes it; Embree may write up to the end
    /// of `self`.
    #[inline]
    pub fn as_raw(&mut self) -> *mut sys::RTCRayHit {
        // Sound to hand out: `RTCRayHit` is a prefix of `RayHit` (asserted
        // above), and the pointer is only ever dereferenced by Embree.
        (self as *mut Self).cast()
    }

    /// Whether the query found a hit.
    #[inline]
    pub fn found(&self) -> bool {
        self.hit.geomID != sys::RTC_INVALID_GEOMETRY_ID
    }
}

/// The ray as Embree takes it: `time` 0, every mask bit set, no flags.
///
/// Embree loads `org` and `dir` as 16-byte vectors (`tnear` and `time` in
/// their fourth lanes). Written field by field, each would reach it as
/// three narrower stores that the CPU cannot forward into one wide load,
/// so every query would start by waiting for its ray to reach the cache;
/// written as whole vectors, the loads take the stores' values directly.
/// Measured with the `embree_overhead` bench: the bare loop 1.86-1.92 s ->
/// 1.53-1.58 s, lumis 3.99-4.35 s -> 3.74-3.92 s (docs/src/performance.md,
/// "Levers", and docs/performance-log.md).
#[inline]
pub(crate) fn raw_ray(ray: &Ray) -> sys::RTCRay {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128, _mm_setr_ps};
        const _: () = assert!(std::mem::size_of::<sys::RTCRay>() == 48);
        // SAFETY: SSE is part of the x86_64 baseline. RTCRay is twelve
        // 4-byte fields, org_x org_y org_z tnear | dir_x dir_y dir_z time |
        // tfar mask id flags, 48 bytes (asserted), so three __m128 hold
        // exactly its bytes, and every bit pattern is a valid f32 or u32.
        unsafe {
            let org = _mm_setr_ps(ray.org[0], ray.org[1], ray.org[2], ray.tnear);
            let dir = _mm_setr_ps(ray.dir[0], ray.dir[1], ray.dir[2], 0.0);
            let rest = _mm_setr_ps(ray.tfar, f32::from_bits(u32::MAX), 0.0, 0.0);
            std::mem::transmute::<[__m128; 3], sys::RTCRay>([org, dir, rest])
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    sys::RTCRay {
        org_x: ray.org[0],
        org_y: ray.org[1],
        org_z: ray.org[2],
        tnear: ray.tnear,
        dir_x: ray.dir[0],
        dir_y: ray.dir[1],
        dir_z: ray.dir[2],
        time: 0.0,
        tfar: ray.tfar,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// No hit yet: Embree requires `geomID` and `instID[0]` to be
/// `RTC_INVALID_GEOMETRY_ID` before a closest-hit query.
#[inline]
fn empty_hit() -> sys::RTCHit {
    sys::RTCHit {
        Ng_x: 0.0,
        Ng_y: 0.0,
        Ng_z: 0.0,
        u: 0.0,
        v: 0.0,
        primID: sys::RTC_INVALID_GEOMETRY_ID,
        geomID: sys::RTC_INVALID_GEOMETRY_ID,
        instID: [sys::RTC_INVALID_GEOMETRY_ID; 1],
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::{Device, SceneBuilder, SceneOptions};

    const SENTINEL: u32 = 0xdead_beef;

    /// A record followed by sentinel words: anything Embree writes past the
    /// record shows up in `beyond`.
    #[repr(C, align(16))]
    struct Probe {
        rayhit: RayHit,
        beyond: [u32; 16],
    }

    #[test]
    fn the_vector_written_ray_has_every_field_in_place() {
        let ray = Ray {
            org: [1.5, -2.0, 3.25],
            dir: [0.0, -0.6, 0.8],
            tnear: 1e-3,
            tfar: f32::INFINITY,
        };
        let raw = raw_ray(&ray);
        assert_eq!([raw.org_x, raw.org_y, raw.org_z], ray.org);
        assert_eq!([raw.dir_x, raw.dir_y, raw.dir_z], ray.dir);
        assert_eq!((raw.tnear, raw.tfar, raw.time), (1e-3, f32::INFINITY, 0.0));
        assert_eq!((raw.mask, raw.id, raw.flags), (u32::MAX, 0, 0));
    }

    #[test]
    fn a_hit_through_an_instance_stays_inside_the_record() {
        let device = Device::new().unwrap();
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        builder
            .add_triangle_mesh(
                Arc::new(vec![[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]].into()),
                Arc::new(vec![[0, 1, 2]].into()),
            )
            .unwrap();
        let prototype = Arc::new(builder.commit().unwrap());
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let instance = builder.add_instance(prototype, &identity).unwrap();
        let scene = builder.commit().unwrap();

        let ray = Ray {
            org: [0.0, 0.0, 1.0],
            dir: [0.0, 0.0, -1.0],
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let mut probe = Probe {
            rayhit: RayHit::new(&ray),
            beyond: [SENTINEL; 16],
        };
        probe.rayhit._tail = MaybeUninit::new([SENTINEL; TAIL_WORDS]);
        // SAFETY: committed, live scene; `probe.rayhit` is a record with
        // room for everything the runtime writes, which is what this test
        // checks through the sentinels after it.
        unsafe { sys::rtcIntersect1(scene.raw(), probe.rayhit.as_raw(), std::ptr::null_mut()) };
        assert!(probe.rayhit.found());
        assert_eq!(probe.rayhit.hit.instID[0], instance);
        assert!((probe.rayhit.ray.tfar - 1.0).abs() < 1e-6);
        assert_eq!(
            probe.beyond,
            [SENTINEL; 16],
            "Embree {} wrote past the ray-hit record",
            device.version()
        );
        // SAFETY: initialised with sentinels above; Embree stores only
        // whole `unsigned int`s there.
        let tail = unsafe { probe.rayhit._tail.assume_init() };
        // A runtime with instance arrays (4.3 on, a build option) stores
        // instPrimID[0], 0 for a plain instance, right after instID[0]: the
        // store the 4.2 record had no room for. One without leaves it.
        assert!(
            tail[0] == SENTINEL || tail[0] == 0,
            "unexpected word after instID[0]: {:#x}",
            tail[0]
        );
    }
}
