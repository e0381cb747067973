//! Building an Embree scene and tracing single rays through it.

use std::sync::Arc;

use embree4_sys as sys;

use crate::buffer::{PaddedBuffer, SpherePoint, Triangle, Vertex};
use crate::device::{Device, EmbreeError};
use crate::record::{raw_packet, raw_ray, RayHit, RayHit8, Valid8, PACKET};
use crate::tape::Tape;

/// Embree's BVH build quality (`RTC_BUILD_QUALITY_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BuildQuality {
    Low,
    #[default]
    Medium,
    High,
}

impl BuildQuality {
    fn raw(self) -> sys::RTCBuildQuality {
        match self {
            BuildQuality::Low => sys::RTCBuildQuality::LOW,
            BuildQuality::Medium => sys::RTCBuildQuality::MEDIUM,
            BuildQuality::High => sys::RTCBuildQuality::HIGH,
        }
    }
}

/// Scene-wide settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SceneOptions {
    pub quality: BuildQuality,
    /// `RTC_SCENE_FLAG_ROBUST`: watertight traversal at some cost in speed.
    pub robust: bool,
    /// `RTC_SCENE_FLAG_COMPACT`: a smaller BVH at some cost in speed.
    pub compact: bool,
}

/// A ray segment `org + t dir`, `t` in `[tnear, tfar]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    pub org: [f32; 3],
    pub dir: [f32; 3],
    pub tnear: f32,
    pub tfar: f32,
}

/// The closest hit along a ray, as Embree reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// Barycentric coordinates of the hit: weights of vertices 1 and 2.
    pub u: f32,
    pub v: f32,
    /// Unnormalized geometric normal (for triangles `(v1 - v0) x (v2 - v0)`).
    pub ng: [f32; 3],
    /// The geometry within the instanced scene when `inst_id` is set.
    pub geom_id: u32,
    pub prim_id: u32,
    /// The instance hit ([`crate::INVALID_ID`] for geometry of the top scene).
    pub inst_id: u32,
}

/// What the scene keeps alive because Embree reads it in place.
enum SharedStorage {
    Triangles {
        _vertices: Arc<PaddedBuffer<Vertex>>,
        _indices: Arc<PaddedBuffer<Triangle>>,
    },
    Spheres {
        _points: Arc<PaddedBuffer<SpherePoint>>,
    },
    Instance {
        _scene: Arc<Scene>,
    },
}

/// Collects geometries; [`SceneBuilder::commit`] builds the BVH.
pub struct SceneBuilder {
    device: Device,
    raw: sys::RTCScene,
    storage: Vec<SharedStorage>,
    options: SceneOptions,
}

/// A committed scene, ready for queries from any number of threads.
pub struct Scene {
    device: Device,
    raw: sys::RTCScene,
    _storage: Vec<SharedStorage>,
    /// Recorded answers to replay (feature `replay`), else nothing.
    tape: Tape,
}

// SAFETY: a committed Embree scene is immutable and rtcIntersect1/rtcOccluded1
// are thread-safe on it (Embree 4 API docs); the shared buffers it reads are
// owned by `_storage` and never mutated. The other fields (`device`, `tape`)
// are Send and Sync by themselves.
unsafe impl Send for Scene {}
// SAFETY: as above.
unsafe impl Sync for Scene {}

// SAFETY: the builder owns its uncommitted scene exclusively (it is neither
// Clone nor shared), and Embree allows different scenes to be built and
// committed from different threads; moving it to another thread moves that
// exclusive ownership. It is not Sync: `&SceneBuilder` gives no access.
unsafe impl Send for SceneBuilder {}

impl SceneBuilder {
    pub fn new(device: &Device, options: SceneOptions) -> Result<Self, EmbreeError> {
        // SAFETY: the device is alive for the call (and for the scene: it is
        // stored in the builder and then in the Scene).
        let raw = unsafe { sys::rtcNewScene(device.raw()) };
        device.take_error()?;
        let quality = options.quality.raw();
        // SAFETY: `raw` is the scene just created.
        unsafe { sys::rtcSetSceneBuildQuality(raw, quality) };
        device.take_error()?;
        Ok(Self {
            device: device.clone(),
            raw,
            storage: Vec::new(),
            options,
        })
    }

    /// Sets `RTC_SCENE_FLAG_COMPACT` for the build to come. The scene flags
    /// are applied at [`Self::commit`], so a loader can decide compaction
    /// once it knows how many triangles the scene holds.
    pub fn set_compact(&mut self, compact: bool) {
        self.options.compact = compact;
    }

    fn geometry_quality(&self) -> sys::RTCBuildQuality {
        self.options.quality.raw()
    }

    /// Adds an instance of a committed `scene` (a prototype), placed by the
    /// affine `transform` (3x4, column-major: the three basis columns, then
    /// the translation). The prototype's BVH and buffers are shared by all
    /// its instances; hits inside it report this instance's id as `inst_id`.
    pub fn add_instance(
        &mut self,
        scene: Arc<Scene>,
        transform: &[f32; 12],
    ) -> Result<u32, EmbreeError> {
        if !scene.device.same_as(&self.device) {
            return Err(EmbreeError {
                code: "INVALID_ARGUMENT".into(),
                message: "an instanced scene must come from the same device".into(),
            });
        }
        // SAFETY: the device is alive; the geometry is attached (or released
        // on error) in `attach`.
        let geometry =
            unsafe { sys::rtcNewGeometry(self.device.raw(), sys::RTCGeometryType::INSTANCE) };
        self.device.take_error()?;
        // SAFETY: `scene` is committed and kept alive by `storage` as long as
        // this scene exists; the transform is 12 floats in the format given,
        // copied by Embree during the call.
        unsafe {
            sys::rtcSetGeometryInstancedScene(geometry, scene.raw);
            sys::rtcSetGeometryTransform(
                geometry,
                0,
                sys::RTCFormat::FLOAT3X4_COLUMN_MAJOR,
                transform.as_ptr().cast(),
            );
        }
        let id = self.attach_with(geometry, false)?;
        self.storage.push(SharedStorage::Instance { _scene: scene });
        Ok(id)
    }

    /// Adds a triangle mesh that reads `vertices` and `indices` in place.
    /// Returns the geometry id that hits will report.
    pub fn add_triangle_mesh(
        &mut self,
        vertices: Arc<PaddedBuffer<Vertex>>,
        indices: Arc<PaddedBuffer<Triangle>>,
    ) -> Result<u32, EmbreeError> {
        let count = vertices.len() as u32;
        if let Some(bad) = indices.iter().flatten().find(|&&i| i >= count) {
            return Err(EmbreeError {
                code: "INVALID_ARGUMENT".into(),
                message: format!("triangle index {bad} out of range for {count} vertices"),
            });
        }
        // SAFETY: the device is alive; the geometry is released below after
        // being attached (the scene then holds its own reference).
        let geometry =
            unsafe { sys::rtcNewGeometry(self.device.raw(), sys::RTCGeometryType::TRIANGLE) };
        self.device.take_error()?;
        // SAFETY: both buffers are padded by one element (PaddedBuffer), have
        // the declared strides and counts, and are kept alive by `storage`
        // for as long as the scene exists; nothing mutates them.
        unsafe {
            sys::rtcSetSharedGeometryBuffer(
                geometry,
                sys::RTCBufferType::VERTEX,
                0,
                sys::RTCFormat::FLOAT3,
                vertices.padded_ptr().cast(),
                0,
                std::mem::size_of::<Vertex>(),
                vertices.len(),
            );
            sys::rtcSetSharedGeometryBuffer(
                geometry,
                sys::RTCBufferType::INDEX,
                0,
                sys::RTCFormat::UINT3,
                indices.padded_ptr().cast(),
                0,
                std::mem::size_of::<Triangle>(),
                indices.len(),
            );
        }
        let id = self.attach(geometry)?;
        self.storage.push(SharedStorage::Triangles {
            _vertices: vertices,
            _indices: indices,
        });
        Ok(id)
    }

    /// Adds spheres (`RTC_GEOMETRY_TYPE_SPHERE_POINT`), one primitive per point.
    pub fn add_spheres(
        &mut self,
        points: Arc<PaddedBuffer<SpherePoint>>,
    ) -> Result<u32, EmbreeError> {
        // SAFETY: as in add_triangle_mesh.
        let geometry =
            unsafe { sys::rtcNewGeometry(self.device.raw(), sys::RTCGeometryType::SPHERE_POINT) };
        self.device.take_error()?;
        // SAFETY: the buffer is padded, holds `len()` FLOAT4 items and lives
        // in `storage` as long as the scene.
        unsafe {
            sys::rtcSetSharedGeometryBuffer(
                geometry,
                sys::RTCBufferType::VERTEX,
                0,
                sys::RTCFormat::FLOAT4,
                points.padded_ptr().cast(),
                0,
                std::mem::size_of::<SpherePoint>(),
                points.len(),
            );
        }
        let id = self.attach(geometry)?;
        self.storage
            .push(SharedStorage::Spheres { _points: points });
        Ok(id)
    }

    /// Commits and attaches a new geometry, then drops our reference to it.
    fn attach(&mut self, geometry: sys::RTCGeometry) -> Result<u32, EmbreeError> {
        self.attach_with(geometry, true)
    }

    /// As [`Self::attach`]; `with_quality` sets the geometry's own build
    /// quality (meaningful for primitives, not for instances).
    fn attach_with(
        &mut self,
        geometry: sys::RTCGeometry,
        with_quality: bool,
    ) -> Result<u32, EmbreeError> {
        // SAFETY: `geometry` is live and its buffers are set; after
        // rtcAttachGeometry the scene holds a reference, so releasing ours is
        // the documented ownership pattern.
        let id = unsafe {
            if with_quality {
                sys::rtcSetGeometryBuildQuality(geometry, self.geometry_quality());
            }
            sys::rtcCommitGeometry(geometry);
            let id = sys::rtcAttachGeometry(self.raw, geometry);
            sys::rtcReleaseGeometry(geometry);
            id
        };
        self.device.take_error()?;
        Ok(id)
    }

    /// Builds the BVH.
    pub fn commit(self) -> Result<Scene, EmbreeError> {
        let mut flags = sys::RTCSceneFlags::NONE;
        if self.options.robust {
            flags |= sys::RTCSceneFlags::ROBUST;
        }
        if self.options.compact {
            flags |= sys::RTCSceneFlags::COMPACT;
        }
        // SAFETY: the scene and every buffer it references are alive; the
        // flags take effect at this commit.
        unsafe {
            sys::rtcSetSceneFlags(self.raw, flags);
            sys::rtcCommitScene(self.raw);
        }
        self.device.take_error()?;
        let this = std::mem::ManuallyDrop::new(self);
        // SAFETY: moving fields out of a ManuallyDrop builder whose Drop
        // (which would release the scene) never runs.
        let (device, storage) =
            unsafe { (std::ptr::read(&this.device), std::ptr::read(&this.storage)) };
        Ok(Scene {
            device,
            raw: this.raw,
            _storage: storage,
            tape: Tape::default(),
        })
    }
}

impl Drop for SceneBuilder {
    fn drop(&mut self) {
        // SAFETY: an uncommitted scene we own; released exactly once.
        unsafe { sys::rtcReleaseScene(self.raw) }
    }
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: we own the only reference; the buffers in `_storage` are
        // dropped after this (fields drop after `drop` returns).
        unsafe { sys::rtcReleaseScene(self.raw) }
    }
}

impl Scene {
    pub(crate) fn raw(&self) -> sys::RTCScene {
        self.raw
    }

    pub fn device(&self) -> &Device {
        &self.device
    }

    /// The closest hit in `[tnear, tfar]`, if any.
    #[inline]
    pub fn intersect1(&self, ray: &Ray) -> Option<Hit> {
        self.tape.hit(|| self.traverse(ray))
    }

    #[inline(always)]
    fn traverse(&self, ray: &Ray) -> Option<Hit> {
        let mut rayhit = RayHit::new(ray);
        // SAFETY: the scene is committed and alive; `rayhit` is an aligned
        // RTCRayHit with room for every field the runtime writes (see
        // `record`); null arguments select Embree's defaults.
        unsafe { sys::rtcIntersect1(self.raw, rayhit.as_raw(), std::ptr::null_mut()) };
        if !rayhit.found() {
            return None;
        }
        let hit = &rayhit.hit;
        Some(Hit {
            t: rayhit.ray.tfar,
            u: hit.u,
            v: hit.v,
            ng: [hit.Ng_x, hit.Ng_y, hit.Ng_z],
            geom_id: hit.geomID,
            prim_id: hit.primID,
            inst_id: hit.instID[0],
        })
    }

    /// Whether anything blocks the segment `[tnear, tfar]` (a shadow ray).
    #[inline]
    pub fn occluded1(&self, ray: &Ray) -> bool {
        self.tape.occluded(|| self.traverse_occluded(ray))
    }

    #[inline(always)]
    fn traverse_occluded(&self, ray: &Ray) -> bool {
        let mut raw = raw_ray(ray);
        // SAFETY: as in intersect1, with an RTCRay.
        unsafe { sys::rtcOccluded1(self.raw, &mut raw, std::ptr::null_mut()) };
        // Embree sets tfar to -inf when the ray is occluded.
        raw.tfar == f32::NEG_INFINITY
    }

    /// [`Scene::intersect1`] for each ray, traced in packets of eight
    /// (`rtcIntersect8`). `out` has the length of `rays`.
    pub fn intersect_packets(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        // The tape records and replays one query at a time.
        if self.tape.active() {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.intersect1(ray);
            }
            return;
        }
        for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let valid = Valid8::first(rays.len());
            let mut packet = RayHit8::new(rays);
            // SAFETY: the scene is committed and alive; `valid` and `packet`
            // are 32-byte aligned, `packet` has room for every field the
            // runtime writes (see `record`), and lanes past `rays` are
            // switched off by `valid`; null arguments select the defaults.
            unsafe {
                sys::rtcIntersect8(
                    valid.0.as_ptr(),
                    self.raw,
                    packet.as_raw(),
                    std::ptr::null_mut(),
                )
            };
            let (ray, hit) = (&packet.ray, &packet.hit);
            for (i, out) in out.iter_mut().enumerate() {
                *out = (hit.geomID[i] != sys::RTC_INVALID_GEOMETRY_ID).then(|| Hit {
                    t: ray.tfar[i],
                    u: hit.u[i],
                    v: hit.v[i],
                    ng: [hit.Ng_x[i], hit.Ng_y[i], hit.Ng_z[i]],
                    geom_id: hit.geomID[i],
                    prim_id: hit.primID[i],
                    inst_id: hit.instID[0][i],
                });
            }
        }
    }

    /// [`Scene::occluded1`] for each ray, traced in packets of eight
    /// (`rtcOccluded8`). `out` has the length of `rays`.
    pub fn occluded_packets(&self, rays: &[Ray], out: &mut [bool]) {
        assert_eq!(rays.len(), out.len(), "one answer per ray");
        if self.tape.active() {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.occluded1(ray);
            }
            return;
        }
        for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let valid = Valid8::first(rays.len());
            let mut packet = raw_packet(rays);
            // SAFETY: as in `intersect_packets`, with an RTCRay8 (whose
            // layout no runtime version changed).
            unsafe {
                sys::rtcOccluded8(
                    valid.0.as_ptr(),
                    self.raw,
                    &mut packet,
                    std::ptr::null_mut(),
                )
            };
            for (i, out) in out.iter_mut().enumerate() {
                // Embree sets tfar to -inf where the ray is occluded.
                *out = packet.tfar[i] == f32::NEG_INFINITY;
            }
        }
    }

    /// Records the answers of the queries that follow (feature `replay`;
    /// see the `tape` module), forgetting earlier ones.
    #[cfg(feature = "replay")]
    pub fn record_queries(&mut self) {
        self.tape.record();
    }

    /// Answers the queries that follow from the recording, in its order,
    /// from its start; returns how many closest-hit and shadow answers it
    /// holds.
    #[cfg(feature = "replay")]
    pub fn replay_queries(&mut self) -> (usize, usize) {
        self.tape.replay()
    }

    /// Traverses every query again.
    #[cfg(feature = "replay")]
    pub fn stop_replay(&mut self) {
        self.tape.stop();
    }

    /// How many closest-hit and shadow answers the replay has handed out.
    #[cfg(feature = "replay")]
    pub fn replayed_queries(&self) -> (usize, usize) {
        self.tape.played()
    }

    /// Scene bounds as `(lower, upper)`.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut b = sys::RTCBounds {
            lower_x: 0.0,
            lower_y: 0.0,
            lower_z: 0.0,
            align0: 0.0,
            upper_x: 0.0,
            upper_y: 0.0,
            upper_z: 0.0,
            align1: 0.0,
        };
        // SAFETY: committed scene; `b` is a valid, aligned RTCBounds.
        unsafe { sys::rtcGetSceneBounds(self.raw, &mut b) };
        (
            [b.lower_x, b.lower_y, b.lower_z],
            [b.upper_x, b.upper_y, b.upper_z],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_quad(device: &Device) -> Scene {
        let mut builder = SceneBuilder::new(device, SceneOptions::default()).unwrap();
        let vertices = vec![
            [-1.0, -1.0, 0.0],
            [1.0, -1.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
        ];
        let indices = vec![[0, 1, 2], [0, 2, 3]];
        builder
            .add_triangle_mesh(Arc::new(vertices.into()), Arc::new(indices.into()))
            .unwrap();
        builder.commit().unwrap()
    }

    fn ray(org: [f32; 3], dir: [f32; 3], tfar: f32) -> Ray {
        Ray {
            org,
            dir,
            tnear: 0.0,
            tfar,
        }
    }

    #[test]
    fn hits_quad_and_reports_barycentrics() {
        let device = Device::new().unwrap();
        assert!(device.version() >= 40000, "Embree 4 expected");
        let scene = unit_quad(&device);
        let hit = scene
            .intersect1(&ray([0.5, -0.5, 2.0], [0.0, 0.0, -1.0], f32::INFINITY))
            .unwrap();
        assert!((hit.t - 2.0).abs() < 1e-6);
        assert_eq!(hit.geom_id, 0);
        assert_eq!(hit.prim_id, 0);
        assert_eq!(hit.inst_id, crate::INVALID_ID);
        // p = (1-u-v) v0 + u v1 + v v2 = (0.5, -0.5): u = 0.5, v = 0.25.
        assert!(
            (hit.u - 0.5).abs() < 1e-6 && (hit.v - 0.25).abs() < 1e-6,
            "{hit:?}"
        );
        assert!(hit.ng[2] > 0.0);
        assert!(scene
            .intersect1(&ray([2.0, 0.0, 2.0], [0.0, 0.0, -1.0], f32::INFINITY))
            .is_none());
    }

    /// Replay answers each query with the recorded answer of the query in
    /// the same place, whatever its ray, counts what it handed out, and
    /// traverses again past the recording's end or once stopped.
    #[cfg(feature = "replay")]
    #[test]
    fn replay_answers_queries_in_recorded_order() {
        let device = Device::new().unwrap();
        let mut scene = unit_quad(&device);
        let down = [0.0, 0.0, -1.0];
        let hit_ray = ray([0.5, -0.5, 2.0], down, f32::INFINITY);
        let miss_ray = ray([2.0, 0.0, 2.0], down, f32::INFINITY);
        let blocked = ray([0.0, 0.0, 1.0], down, 2.0);
        let short = ray([0.0, 0.0, 1.0], down, 0.5);

        scene.record_queries();
        let hit = scene.intersect1(&hit_ray);
        assert!(hit.is_some());
        assert!(scene.intersect1(&miss_ray).is_none());
        assert!(scene.occluded1(&blocked));
        assert_eq!(scene.replay_queries(), (2, 1));

        // The rays swapped: the answers come in the recorded order.
        assert_eq!(scene.intersect1(&miss_ray), hit);
        assert!(scene.occluded1(&short));
        assert_eq!(scene.intersect1(&hit_ray), None);
        assert_eq!(scene.replayed_queries(), (2, 1));
        // Past the recording: traversal again.
        assert!(!scene.occluded1(&short));
        assert_eq!(scene.intersect1(&hit_ray), hit);
        assert_eq!(scene.replayed_queries(), (2, 1));

        // Replaying again starts over; stopping traverses.
        assert_eq!(scene.replay_queries(), (2, 1));
        assert_eq!(scene.intersect1(&miss_ray), hit);
        scene.stop_replay();
        assert!(scene.intersect1(&miss_ray).is_none());
        assert!(!scene.occluded1(&short));
    }

    #[test]
    fn occlusion_respects_segment_length() {
        let device = Device::new().unwrap();
        let scene = unit_quad(&device);
        assert!(scene.occluded1(&ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 2.0)));
        assert!(!scene.occluded1(&ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.5)));
    }

    #[test]
    fn spheres_are_hit_from_outside_and_inside() {
        let device = Device::new().unwrap();
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        builder
            .add_spheres(Arc::new(vec![[0.0, 0.0, 0.0, 1.0]].into()))
            .unwrap();
        let scene = builder.commit().unwrap();
        let outside = scene
            .intersect1(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0], f32::INFINITY))
            .unwrap();
        assert!((outside.t - 4.0).abs() < 1e-5);
        let inside = scene
            .intersect1(&ray([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], f32::INFINITY))
            .unwrap();
        assert!((inside.t - 1.0).abs() < 1e-5);
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let device = Device::new().unwrap();
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let err = builder
            .add_triangle_mesh(
                Arc::new(vec![[0.0; 3]; 3].into()),
                Arc::new(vec![[0, 1, 3]].into()),
            )
            .unwrap_err();
        assert!(err.message.contains("out of range"), "{err}");
    }

    /// Packets of eight find what single rays find, for closest hits and
    /// occlusion, on meshes, spheres and instances, with limited and
    /// unlimited segments and with a last packet that is not full.
    #[test]
    fn packets_answer_as_single_rays() {
        let device = Device::new().unwrap();
        let prototype = Arc::new(unit_quad(&device));
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let mut moved = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        moved[9] = 1.5;
        builder.add_instance(prototype, &moved).unwrap();
        builder
            .add_triangle_mesh(
                Arc::new(vec![[-2.0, -2.0, -1.0], [2.0, -2.0, -1.0], [0.0, 2.0, -1.0]].into()),
                Arc::new(vec![[0, 1, 2]].into()),
            )
            .unwrap();
        builder
            .add_spheres(Arc::new(vec![[-1.0, 0.5, 0.5, 0.6]].into()))
            .unwrap();
        let scene = builder.commit().unwrap();
        // A fixed low-discrepancy spray of rays from around the scene.
        let fraction = |i: u32, a: f32| (i as f32 * a).fract();
        let rays: Vec<Ray> = (0..2000u32)
            .map(|i| {
                let org = [
                    4.0 * fraction(i, 0.618_034) - 2.0,
                    4.0 * fraction(i, 0.414_214) - 2.0,
                    3.0,
                ];
                let dir = [
                    0.8 * fraction(i, 0.732_051) - 0.4,
                    0.8 * fraction(i, 0.236_068) - 0.4,
                    -1.0,
                ];
                let tfar = if i % 3 == 0 { 3.5 } else { f32::INFINITY };
                ray(org, dir, tfar)
            })
            .collect();
        let (mut hits, mut blocked) = (0, 0);
        let mut kinds = std::collections::BTreeSet::new();
        for n in [0, 1, 7, 9, 33, rays.len()] {
            let rays = &rays[..n];
            let mut packed = vec![None; n];
            scene.intersect_packets(rays, &mut packed);
            let mut occluded = vec![false; n];
            scene.occluded_packets(rays, &mut occluded);
            for (i, r) in rays.iter().enumerate() {
                let single = scene.intersect1(r);
                match (single, packed[i]) {
                    (None, None) => {}
                    (Some(a), Some(b)) => {
                        assert_eq!(
                            (a.geom_id, a.prim_id, a.inst_id),
                            (b.geom_id, b.prim_id, b.inst_id),
                            "ray {i}"
                        );
                        for (x, y) in [(a.t, b.t), (a.u, b.u), (a.v, b.v)] {
                            assert!((x - y).abs() <= 1e-5 * x.abs().max(1.0), "ray {i}");
                        }
                        hits += 1;
                        kinds.insert((a.inst_id, a.geom_id));
                    }
                    (a, b) => panic!("ray {i}: single {a:?}, packet {b:?}"),
                }
                assert_eq!(scene.occluded1(r), occluded[i], "ray {i}");
                blocked += usize::from(occluded[i]);
            }
        }
        // The spray finds the instance, the mesh and the sphere, and misses
        // too; a segment is blocked exactly where it has a hit.
        assert_eq!(kinds.len(), 3, "{kinds:?}");
        assert!(hits > 500 && hits < 2000, "{hits}");
        assert_eq!(blocked, hits);
    }

    #[test]
    fn instances_share_one_prototype_and_report_their_id() {
        let device = Device::new().unwrap();
        let prototype = Arc::new(unit_quad(&device));
        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let identity = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
        let mut moved = identity;
        moved[9] = 10.0; // translate by +10 in x
        let a = builder.add_instance(prototype.clone(), &identity).unwrap();
        let b = builder.add_instance(prototype, &moved).unwrap();
        let scene = builder.commit().unwrap();
        let down = [0.0, 0.0, -1.0];
        let hit_a = scene
            .intersect1(&ray([0.5, -0.5, 2.0], down, f32::INFINITY))
            .unwrap();
        let hit_b = scene
            .intersect1(&ray([10.5, -0.5, 2.0], down, f32::INFINITY))
            .unwrap();
        assert_eq!((hit_a.inst_id, hit_b.inst_id), (a, b));
        assert_eq!((hit_a.geom_id, hit_b.geom_id), (0, 0));
        // Same object-space point, so the same primitive and barycentrics.
        assert_eq!(
            (hit_a.prim_id, hit_a.u, hit_a.v),
            (hit_b.prim_id, hit_b.u, hit_b.v)
        );
        assert!(scene
            .intersect1(&ray([5.0, 0.0, 2.0], down, f32::INFINITY))
            .is_none());
        assert!(scene.occluded1(&ray([10.0, 0.0, 1.0], down, 2.0)));
    }

    #[test]
    fn memory_monitor_counts_the_bvh() {
        let device = Device::new().unwrap();
        let before = device.memory_in_use();
        let scene = unit_quad(&device);
        assert!(device.memory_in_use() > before);
        drop(scene);
    }

    #[test]
    fn embree_errors_become_rust_errors() {
        let device = Device::new().unwrap();
        let builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        // REFIT is a geometry-only build quality: Embree reports
        // an error through the device callback.
        // SAFETY: a live, uncommitted scene.
        unsafe { sys::rtcSetSceneBuildQuality(builder.raw, sys::RTCBuildQuality::REFIT) };
        let err = device.take_error().unwrap_err();
        assert!(err.message.contains("build quality"), "{err}");
        assert!(device.take_error().is_ok(), "an error is reported once");
    }
}
