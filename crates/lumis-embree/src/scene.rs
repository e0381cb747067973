//! Building an Embree scene and tracing rays through it, one at a time or
//! as packets.

use std::sync::Arc;

use embree4_sys as sys;

use crate::buffer::{PaddedBuffer, SpherePoint, Triangle, Vertex};
use crate::device::{Device, EmbreeError};
use crate::ray::{Hit, Ray};
use crate::record::{raw_ray, RayHit};
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
    pub(crate) tape: Tape,
}

// SAFETY: a committed Embree scene is immutable and its queries
// (rtcIntersect1/4/8/16, rtcOccluded1/4/8/16) are thread-safe on it (Embree
// 4 API docs); the shared buffers it reads are owned by `_storage` and
// never mutated. The other fields (`device`, `tape`)
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
mod tests;
