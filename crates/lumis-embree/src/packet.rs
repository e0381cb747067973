//! Ray packets for `rtcIntersect4/8/16` and `rtcOccluded4/8/16`.
//!
//! The records are the structure-of-arrays forms of those in `record`, with
//! the same room after the 4.2 hit for what a newer runtime writes there
//! (`instID[1..L]` and `instPrimID[0..L]`, each one packet wide). Embree
//! requires each record and its valid mask to be aligned to the packet's
//! size in bytes (16, 32 or 64), which the types here carry.

use std::mem::MaybeUninit;

use embree4_sys as sys;

use crate::ray::{Hit, Ray};
use crate::record::MAX_INSTANCE_LEVELS;
use crate::scene::Scene;

/// Rays per Embree packet query.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PacketWidth {
    Four,
    Eight,
    Sixteen,
}

impl PacketWidth {
    pub const ALL: [Self; 3] = [Self::Four, Self::Eight, Self::Sixteen];

    pub const fn lanes(self) -> usize {
        match self {
            Self::Four => 4,
            Self::Eight => 8,
            Self::Sixteen => 16,
        }
    }
}

/// The widest packet, so that a caller can stage any packet in one
/// fixed-size buffer.
pub const MAX_PACKET: usize = 16;

/// How a batch of rays goes to Embree as packets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Packets {
    pub width: PacketWidth,
    /// Passes `RTC_RAY_QUERY_FLAG_COHERENT`: the rays of a packet travel
    /// together (camera rays through one pixel), so Embree keeps the packet
    /// together in traversal instead of splitting it into single rays as
    /// soon as a few lanes diverge. Measured (the `embree_overhead`
    /// bench): up to 1.8 times the rays per second of single rays for camera
    /// rays, but 1.2 to 3 times slower for bounce and shadow rays.
    pub coherent: bool,
}

/// One width's records and entry points, so that one generic loop in
/// `scene` serves every width.
pub(crate) trait Packet {
    const LANES: usize;
    /// The lanes holding a ray (-1) or not (0).
    type Valid;
    /// An occlusion packet (`RTCRayN`).
    type Rays;
    /// A closest-hit packet (`RTCRayHitN` with room after it).
    type RayHit;

    /// The first `n` lanes valid.
    fn valid(n: usize) -> Self::Valid;
    /// `rays` (at most `LANES`) in the first lanes; the others hold an
    /// empty segment that the valid mask switches off.
    fn rays(rays: &[Ray]) -> Self::Rays;
    /// As [`Packet::rays`], with no hits recorded yet.
    fn ray_hit(rays: &[Ray]) -> Self::RayHit;
    fn intersect(scene: &Scene, valid: &Self::Valid, packet: &mut Self::RayHit, args: &mut Args);
    fn occluded(scene: &Scene, valid: &Self::Valid, packet: &mut Self::Rays, args: &mut Args);
    /// Lane `lane`'s answer, as `Scene::intersect1` gives it.
    fn hit(packet: &Self::RayHit, lane: usize) -> Option<Hit>;
    fn is_occluded(packet: &Self::Rays, lane: usize) -> bool;

    /// Fills the room after the hit with `word`, to see what Embree writes.
    #[cfg(test)]
    fn fill_tail(packet: &mut Self::RayHit, word: u32);
    /// The room after the hit, after [`Packet::fill_tail`].
    #[cfg(test)]
    fn tail(packet: &Self::RayHit) -> &[u32];
}

/// The optional query arguments: null for Embree's defaults (incoherent),
/// or `RTC_RAY_QUERY_FLAG_COHERENT`.
pub(crate) struct Args {
    args: Option<ArgsRecord>,
}

/// `RTCIntersectArguments` followed by `minWidthDistanceFactor`, which a
/// runtime built with `RTC_MIN_WIDTH` reads after the fields `embree4-sys`
/// knows; `RTCOccludedArguments` has the same layout.
#[repr(C)]
struct ArgsRecord {
    args: sys::RTCIntersectArguments,
    min_width_distance_factor: f32,
}

const _: () = {
    use std::mem::{align_of, offset_of, size_of};
    assert!(size_of::<sys::RTCIntersectArguments>() == size_of::<sys::RTCOccludedArguments>());
    assert!(align_of::<sys::RTCIntersectArguments>() == align_of::<sys::RTCOccludedArguments>());
    assert!(
        offset_of!(sys::RTCIntersectArguments, intersect)
            == offset_of!(sys::RTCOccludedArguments, occluded)
    );
};

impl Args {
    pub fn new(coherent: bool) -> Self {
        // What rtcInitIntersectArguments sets, with the coherence flag.
        let args = coherent.then_some(ArgsRecord {
            args: sys::RTCIntersectArguments {
                flags: sys::RTCRayQueryFlags::COHERENT,
                feature_mask: sys::RTCFeatureFlags::RTC_FEATURE_FLAG_ALL,
                context: std::ptr::null_mut(),
                filter: None,
                intersect: None,
            },
            min_width_distance_factor: 0.0,
        });
        Self { args }
    }

    fn intersect(&mut self) -> *mut sys::RTCIntersectArguments {
        self.args
            .as_mut()
            .map_or(std::ptr::null_mut(), |a| &mut a.args)
    }

    fn occluded(&mut self) -> *mut sys::RTCOccludedArguments {
        // Same layout (asserted above); `filter` and `occluded` are None.
        self.intersect().cast()
    }
}

/// Defines a module with one width's records and its [`Packet`].
macro_rules! packet {
    ($module:ident, $lanes:literal, $align:literal, $ray:ident, $hit:ident, $rayhit:ident,
     $intersect:ident, $occluded:ident) => {
        pub(crate) mod $module {
            use super::*;

            #[repr(C, align($align))]
            pub(crate) struct Valid(pub(crate) [i32; $lanes]);

            /// The 4.2 record followed by room for the rest of the hit.
            #[repr(C, align($align))]
            pub(crate) struct RayHit {
                ray: sys::$ray,
                hit: sys::$hit,
                /// Written by Embree, never read.
                _tail: MaybeUninit<[u32; (2 * MAX_INSTANCE_LEVELS - 1) * $lanes]>,
            }

            // The prefix cast in `intersect`, and the alignment Embree
            // requires (the packet's size in bytes).
            const _: () = {
                use std::mem::{align_of, offset_of};
                assert!(offset_of!(RayHit, ray) == offset_of!(sys::$rayhit, ray));
                assert!(offset_of!(RayHit, hit) == offset_of!(sys::$rayhit, hit));
                assert!(align_of::<RayHit>() == 4 * $lanes);
                assert!(align_of::<sys::$ray>() == 4 * $lanes);
                assert!(align_of::<Valid>() == 4 * $lanes);
            };

            pub(crate) struct Width;

            impl Packet for Width {
                const LANES: usize = $lanes;
                type Valid = Valid;
                type Rays = sys::$ray;
                type RayHit = RayHit;

                #[inline(always)]
                fn valid(n: usize) -> Valid {
                    Valid(std::array::from_fn(|i| if i < n { -1 } else { 0 }))
                }

                #[inline(always)]
                fn rays(rays: &[Ray]) -> sys::$ray {
                    debug_assert!(rays.len() <= $lanes);
                    let mut p = sys::$ray {
                        org_x: [0.0; $lanes],
                        org_y: [0.0; $lanes],
                        org_z: [0.0; $lanes],
                        tnear: [0.0; $lanes],
                        dir_x: [0.0; $lanes],
                        dir_y: [0.0; $lanes],
                        dir_z: [1.0; $lanes],
                        time: [0.0; $lanes],
                        tfar: [0.0; $lanes],
                        mask: [u32::MAX; $lanes],
                        id: [0; $lanes],
                        flags: [0; $lanes],
                    };
                    for (i, r) in rays.iter().enumerate().take($lanes) {
                        p.org_x[i] = r.org[0];
                        p.org_y[i] = r.org[1];
                        p.org_z[i] = r.org[2];
                        p.tnear[i] = r.tnear;
                        p.dir_x[i] = r.dir[0];
                        p.dir_y[i] = r.dir[1];
                        p.dir_z[i] = r.dir[2];
                        p.tfar[i] = r.tfar;
                    }
                    p
                }

                #[inline(always)]
                fn ray_hit(rays: &[Ray]) -> RayHit {
                    const NONE: u32 = sys::RTC_INVALID_GEOMETRY_ID;
                    RayHit {
                        ray: Self::rays(rays),
                        // Embree requires geomID and instID[0] invalid.
                        hit: sys::$hit {
                            Ng_x: [0.0; $lanes],
                            Ng_y: [0.0; $lanes],
                            Ng_z: [0.0; $lanes],
                            u: [0.0; $lanes],
                            v: [0.0; $lanes],
                            primID: [NONE; $lanes],
                            geomID: [NONE; $lanes],
                            instID: [[NONE; $lanes]; 1],
                        },
                        _tail: MaybeUninit::uninit(),
                    }
                }

                #[inline(always)]
                fn intersect(scene: &Scene, valid: &Valid, packet: &mut RayHit, args: &mut Args) {
                    let raw: *mut sys::$rayhit = (packet as *mut RayHit).cast();
                    // SAFETY: the scene is committed and alive for the call;
                    // `valid` and `packet` have the alignment Embree requires
                    // (asserted above); `packet` starts with an RTCRayHitN
                    // (asserted) and has room for every field the runtime
                    // writes after it (module doc); `args` is null or a
                    // full arguments record (`Args`).
                    unsafe { sys::$intersect(valid.0.as_ptr(), scene.raw(), raw, args.intersect()) }
                }

                #[inline(always)]
                fn occluded(scene: &Scene, valid: &Valid, packet: &mut sys::$ray, args: &mut Args) {
                    // SAFETY: as in `intersect`, with an RTCRayN, whose
                    // layout no runtime version changed.
                    unsafe {
                        sys::$occluded(valid.0.as_ptr(), scene.raw(), packet, args.occluded())
                    }
                }

                #[inline(always)]
                fn hit(packet: &RayHit, lane: usize) -> Option<Hit> {
                    let (ray, hit) = (&packet.ray, &packet.hit);
                    (hit.geomID[lane] != sys::RTC_INVALID_GEOMETRY_ID).then(|| Hit {
                        t: ray.tfar[lane],
                        u: hit.u[lane],
                        v: hit.v[lane],
                        ng: [hit.Ng_x[lane], hit.Ng_y[lane], hit.Ng_z[lane]],
                        geom_id: hit.geomID[lane],
                        prim_id: hit.primID[lane],
                        inst_id: hit.instID[0][lane],
                    })
                }

                #[inline(always)]
                fn is_occluded(packet: &sys::$ray, lane: usize) -> bool {
                    // Embree sets tfar to -inf where the ray is occluded.
                    packet.tfar[lane] == f32::NEG_INFINITY
                }

                #[cfg(test)]
                fn fill_tail(packet: &mut RayHit, word: u32) {
                    packet._tail = MaybeUninit::new([word; (2 * MAX_INSTANCE_LEVELS - 1) * $lanes]);
                }

                #[cfg(test)]
                fn tail(packet: &RayHit) -> &[u32] {
                    // SAFETY: only called after `fill_tail` initialised it;
                    // Embree stores only whole `unsigned int`s there.
                    unsafe { packet._tail.assume_init_ref() }
                }
            }
        }
    };
}

packet!(
    w4,
    4,
    16,
    RTCRay4,
    RTCHit4,
    RTCRayHit4,
    rtcIntersect4,
    rtcOccluded4
);
packet!(
    w8,
    8,
    32,
    RTCRay8,
    RTCHit8,
    RTCRayHit8,
    rtcIntersect8,
    rtcOccluded8
);
packet!(
    w16,
    16,
    64,
    RTCRay16,
    RTCHit16,
    RTCRayHit16,
    rtcIntersect16,
    rtcOccluded16
);

/// The packet queries of a scene.
impl Scene {
    /// [`Scene::intersect1`] for each ray of `rays`, traced as Embree
    /// packets (`rtcIntersect4/8/16`); a last packet that is not full has
    /// its other lanes switched off. `out` has the length of `rays`. The
    /// answers are those of single rays up to rounding. Recorded and
    /// replayed lane by lane, in order, with the single-ray queries (feature
    /// `replay`; see the `tape` module).
    pub fn intersect_packets(&self, packets: Packets, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        self.tape.hits(out, |start, out| {
            let rays = &rays[start..];
            match packets.width {
                PacketWidth::Four => self.trace_packets::<w4::Width>(packets, rays, out),
                PacketWidth::Eight => self.trace_packets::<w8::Width>(packets, rays, out),
                PacketWidth::Sixteen => self.trace_packets::<w16::Width>(packets, rays, out),
            }
        });
    }

    fn trace_packets<P: Packet>(&self, packets: Packets, rays: &[Ray], out: &mut [Option<Hit>]) {
        let mut args = Args::new(packets.coherent);
        for (rays, out) in rays.chunks(P::LANES).zip(out.chunks_mut(P::LANES)) {
            let mut packet = P::ray_hit(rays);
            P::intersect(self, &P::valid(rays.len()), &mut packet, &mut args);
            for (lane, out) in out.iter_mut().enumerate() {
                *out = P::hit(&packet, lane);
            }
        }
    }

    /// [`Scene::occluded1`] for each ray of `rays`, as
    /// [`Scene::intersect_packets`] (`rtcOccluded4/8/16`).
    pub fn occluded_packets(&self, packets: Packets, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        self.tape.occlusions(out, |start, out| {
            let rays = &rays[start..];
            match packets.width {
                PacketWidth::Four => self.trace_occluded::<w4::Width>(packets, rays, out),
                PacketWidth::Eight => self.trace_occluded::<w8::Width>(packets, rays, out),
                PacketWidth::Sixteen => self.trace_occluded::<w16::Width>(packets, rays, out),
            }
        });
    }

    fn trace_occluded<P: Packet>(&self, packets: Packets, rays: &[Ray], out: &mut [bool]) {
        let mut args = Args::new(packets.coherent);
        for (rays, out) in rays.chunks(P::LANES).zip(out.chunks_mut(P::LANES)) {
            let mut packet = P::rays(rays);
            P::occluded(self, &P::valid(rays.len()), &mut packet, &mut args);
            for (lane, out) in out.iter_mut().enumerate() {
                *out = P::is_occluded(&packet, lane);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::{Device, SceneBuilder, SceneOptions};

    const SENTINEL: u32 = 0xdead_beef;

    /// A packet record followed by sentinel words: anything Embree writes
    /// past the record shows up in `beyond`.
    #[repr(C)]
    struct Probe<R> {
        rayhit: R,
        beyond: [u32; 64],
    }

    /// One lane hits through an instance, another misses, the rest are
    /// switched off; nothing lands past the record, and the lanes read back
    /// as single rays would.
    fn instance_hit_stays_inside<P: Packet>() {
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

        let down = |x: f32| Ray {
            org: [x, 0.0, 1.0],
            dir: [0.0, 0.0, -1.0],
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        let rays = [down(0.0), down(5.0), down(0.1)];
        let mut probe = Probe {
            rayhit: P::ray_hit(&rays),
            beyond: [SENTINEL; 64],
        };
        P::fill_tail(&mut probe.rayhit, SENTINEL);
        P::intersect(
            &scene,
            &P::valid(rays.len()),
            &mut probe.rayhit,
            &mut Args::new(false),
        );
        assert_eq!(
            probe.beyond,
            [SENTINEL; 64],
            "Embree {} wrote past the {}-ray record",
            device.version(),
            P::LANES
        );
        for (lane, ray) in rays.iter().enumerate() {
            assert_eq!(
                P::hit(&probe.rayhit, lane),
                scene.intersect1(ray),
                "lane {lane}"
            );
        }
        let hit = P::hit(&probe.rayhit, 0).unwrap();
        assert_eq!(hit.inst_id, instance);
        // Switched-off lanes keep their empty answer.
        for lane in rays.len()..P::LANES {
            assert_eq!(P::hit(&probe.rayhit, lane), None);
        }
        // As for single rays: a runtime with instance arrays stores
        // instPrimID[0][lane] (0) right after instID[0]; one without does
        // not; nothing else is expected there.
        let tail = P::tail(&probe.rayhit);
        for (lane, &word) in tail[..P::LANES].iter().enumerate() {
            assert!(
                word == SENTINEL || word == 0,
                "unexpected word after instID[0][{lane}]: {word:#x}"
            );
        }
    }

    #[test]
    fn packet_hits_through_an_instance_stay_inside_the_record() {
        instance_hit_stays_inside::<w4::Width>();
        instance_hit_stays_inside::<w8::Width>();
        instance_hit_stays_inside::<w16::Width>();
    }

    #[test]
    fn lanes_hold_the_rays_and_the_rest_is_switched_off() {
        let rays: Vec<Ray> = (0..3)
            .map(|i| Ray {
                org: [i as f32, 1.0, 2.0],
                dir: [0.0, 0.6, 0.8],
                tnear: 0.5,
                tfar: 10.0 + i as f32,
            })
            .collect();
        let p = <w8::Width as Packet>::rays(&rays);
        assert_eq!(p.org_x[..4], [0.0, 1.0, 2.0, 0.0]);
        assert_eq!(p.tfar[..4], [10.0, 11.0, 12.0, 0.0]);
        assert_eq!((p.dir_y[2], p.dir_z[2], p.tnear[2]), (0.6, 0.8, 0.5));
        assert_eq!((p.mask[7], p.time[7], p.flags[7]), (u32::MAX, 0.0, 0));
        let valid = <w8::Width as Packet>::valid(3);
        assert_eq!(valid.0, [-1, -1, -1, 0, 0, 0, 0, 0]);
        assert_eq!(PacketWidth::ALL.map(PacketWidth::lanes), [4, 8, MAX_PACKET]);
    }
}
