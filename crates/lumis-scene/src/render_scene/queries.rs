//! The scene's answers to the plugin interface's queries: closest hit and
//! occlusion, ray by ray and in batches, camera rays as Embree packets.

use lumis_core::{Light, LightSampler, Ray, Scene, SurfaceInteraction};
use lumis_embree::{PacketWidth, Packets};

use super::RenderScene;

/// Fills the unused lanes of a packet (which Embree skips).
const NO_RAY: lumis_embree::Ray = lumis_embree::Ray {
    org: [0.0; 3],
    dir: [0.0, 0.0, 1.0],
    tnear: 0.0,
    tfar: 0.0,
};

#[inline]
fn to_embree(ray: &Ray) -> lumis_embree::Ray {
    lumis_embree::Ray {
        org: ray.o.into(),
        dir: ray.d.into(),
        tnear: 0.0,
        tfar: ray.t_max,
    }
}

/// Camera rays: packets with Embree's coherence hint.
const CAMERA_PACKETS: Packets = Packets {
    width: PacketWidth::Eight,
    coherent: true,
};

/// Every other ray, with `[accel] packets`: without the hint, which slows
/// incoherent rays down 1.2 to 3 times.
const OTHER_PACKETS: Packets = Packets {
    width: PacketWidth::Eight,
    coherent: false,
};

/// Rays per packet, of either kind.
const LANES: usize = CAMERA_PACKETS.width.lanes();
const _: () = assert!(OTHER_PACKETS.width.lanes() == LANES);

/// The first [`LANES`] rays of `rays`, if they all leave one point: camera
/// rays (a pinhole's), which a wavefront batch holds in runs (a wave's new
/// paths, in pixel order, each pixel's samples together). Only these gained
/// as packets on every bench scene, so only these go as packets by default.
///
/// Measured with the `embree_overhead` bench (the `wavefront` integrator's
/// batches, 16 spp, one thread), in rays per second of packets over those
/// of single rays, bare Embree, by kind of ray:
///
/// | scene                  | camera, 8 / 16 coherent | bounce, 8 | shadow, 8 |
/// |------------------------|-------------------------|-----------|-----------|
/// | Cornell box            | 1.09-1.16 / 1.26-1.58   | 0.83-0.86 | 0.86-0.90 |
/// | dragon scan (871k tri) | 1.37-1.40 / 1.75-1.77   | 0.91-0.94 | 1.14-1.17 |
///
/// Packets of 16 traverse fastest, but slow the rest of a render down (the
/// 512-bit instructions, presumably through the core's clock): whole
/// renders took 5% longer with 16-wide camera packets on the Cornell box and
/// gained nothing on the dragon, where packets of 8 gain 4% (and lose 1% on
/// the Cornell box, within what code placement alone moves there). Shadow
/// rays gained on three more bench scenes (1.05-1.34) but lost on the
/// Cornell box, so they go one by one unless `[accel] packets` asks. A
/// partial packet costs about what a full one does, so the rays after a
/// run's last full packet go one by one.
#[inline]
fn camera_packet(rays: &[Ray]) -> Option<&[Ray]> {
    let packet = rays.get(..LANES)?;
    let origin = packet[0].o;
    packet[1..].iter().all(|r| r.o == origin).then_some(packet)
}

/// `rays` (at most [`LANES`]) as Embree takes them.
#[inline]
fn to_embree_packet(rays: &[Ray]) -> [lumis_embree::Ray; LANES] {
    debug_assert!(rays.len() <= LANES);
    std::array::from_fn(|i| rays.get(i).map_or(NO_RAY, to_embree))
}

impl RenderScene {
    /// Traces `rays` (at most [`LANES`]) as one packet into `out`, shading
    /// the hits as [`Scene::intersect`] does.
    fn intersect_packet<'s>(
        &'s self,
        packets: Packets,
        rays: &[Ray],
        out: &mut [Option<SurfaceInteraction<'s>>],
    ) {
        let n = rays.len();
        let mut hits = [None; LANES];
        self.embree
            .intersect_packets(packets, &to_embree_packet(rays)[..n], &mut hits[..n]);
        for ((ray, hit), out) in rays.iter().zip(&hits).zip(out) {
            *out = hit.as_ref().map(|hit| self.interaction_at(ray, hit));
        }
    }
}

impl Scene for RenderScene {
    #[inline]
    fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction<'_>> {
        debug_assert!(
            (ray.d.length() - 1.0).abs() < 1e-3,
            "intersect expects a unit direction"
        );
        let hit = self.embree.intersect1(&to_embree(ray))?;
        Some(self.interaction_at(ray, &hit))
    }

    #[inline]
    fn occluded(&self, ray: &Ray) -> bool {
        self.embree.occluded1(&to_embree(ray))
    }

    /// Camera rays as coherent packets of 8, every other ray by itself (in
    /// packets of 8 with `[accel] packets`); see `camera_packet` for the
    /// rule and the measurements behind it.
    fn intersect_batch<'s>(&'s self, rays: &[Ray], out: &mut [Option<SurfaceInteraction<'s>>]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        let mut i = 0;
        while i < rays.len() {
            if let Some(packet) = camera_packet(&rays[i..]) {
                self.intersect_packet(CAMERA_PACKETS, packet, &mut out[i..i + LANES]);
                i += LANES;
            } else if self.packets {
                // Up to a packet of the rays before the next camera packet.
                let mut end = i + 1;
                while end < rays.len() && end - i < LANES && camera_packet(&rays[end..]).is_none() {
                    end += 1;
                }
                self.intersect_packet(OTHER_PACKETS, &rays[i..end], &mut out[i..end]);
                i = end;
            } else {
                out[i] = self.intersect(&rays[i]);
                i += 1;
            }
        }
    }

    /// Ray by ray (in packets of 8 with `[accel] packets`): shadow rays
    /// lost as packets on the Cornell box (`camera_packet`).
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        if !self.packets {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.occluded(ray);
            }
            return;
        }
        for (rays, out) in rays.chunks(LANES).zip(out.chunks_mut(LANES)) {
            self.embree
                .occluded_packets(OTHER_PACKETS, &to_embree_packet(rays)[..rays.len()], out);
        }
    }

    fn lights(&self) -> &[Box<dyn Light>] {
        &self.lights
    }

    fn infinite_lights(&self) -> &[u32] {
        &self.infinite_lights
    }

    fn light_sampler(&self) -> &dyn LightSampler {
        self.light_sampler.as_ref()
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_core::Vec3;

    /// Packets go to runs of a full packet of rays from one origin, and
    /// only to those.
    #[test]
    fn camera_packets_are_full_runs_from_one_origin() {
        let ray = |x: f32| Ray {
            o: Vec3::new(x, 0.0, 1.0),
            d: Vec3::NEG_Z,
            t_max: f32::INFINITY,
        };
        let run = vec![ray(0.0); LANES + 3];
        assert_eq!(camera_packet(&run).map(<[Ray]>::len), Some(LANES));
        assert_eq!(camera_packet(&run[3..]).map(<[Ray]>::len), Some(LANES));
        assert!(camera_packet(&run[4..]).is_none());
        let mut broken = run.clone();
        broken[LANES - 1] = ray(1e-6);
        assert!(camera_packet(&broken).is_none());
        assert!(camera_packet(&broken[LANES..]).is_none());
    }
}
