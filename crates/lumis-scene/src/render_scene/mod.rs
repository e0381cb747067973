//! The render-ready scene: Embree geometry plus what shading needs per hit.
//!
//! This file holds the scene's data; `hit` turns an Embree hit into the
//! interaction shading sees, and `queries` answers the plugin interface's
//! queries, ray by ray and as packets.

use std::sync::Arc;

use lumis_core::glam::Mat3;
use lumis_core::math::Frame;
use lumis_core::{Bsdf, BsdfFlags, Light, LightIndex, LightSampler, PixelFootprint, Vec2, Vec3};
use lumis_embree::{PaddedBuffer, Triangle, Vertex};

pub use crate::report::LoadReport;

/// Marks a triangle without an area light in [`MeshData::lights`]: the one
/// index [`LightIndex::new`] maps to `None`, so a hit converts either kind
/// of entry with that one call.
pub(crate) const NO_LIGHT: u32 = u32::MAX;
const _: () = assert!(LightIndex::new(NO_LIGHT).is_none());

/// A triangle mesh as shading sees it; its buffers are the ones Embree reads.
pub(crate) struct MeshData {
    pub vertices: Arc<PaddedBuffer<Vertex>>,
    pub indices: Arc<PaddedBuffer<Triangle>>,
    /// Per-vertex shading normals; `None` means flat shading (and no
    /// interpolation cost).
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates, stored only when the material reads
    /// them; without them a hit's uv is its barycentric coordinates.
    pub uvs: Option<Vec<Vec2>>,
    pub bsdf: u32,
    /// Light index per triangle (`NO_LIGHT` if none); empty when the
    /// mesh does not emit. Always empty in a [`Prototype`], whose lights
    /// differ per instance.
    pub lights: Vec<u32>,
    /// -1 flips the geometric normal (and so the front side).
    pub orientation: f32,
    /// The shading frame of each triangle of a flat-shaded mesh, stored by
    /// [`MeshData::store_flat_frames`] in scenes small enough to keep the
    /// fast BVH; empty otherwise. A hit loads its frame instead of
    /// normalising Embree's normal and building a basis around it: a
    /// square root and two divisions in a row on the path from one query
    /// to the next, 4% of the Cornell box's render time, for 48 bytes per
    /// triangle (docs/src/performance.md, "Levers").
    pub flat_frames: Vec<Frame>,
}

impl MeshData {
    /// Bytes of per-vertex and per-triangle data this mesh holds.
    pub fn byte_size(&self) -> usize {
        self.vertices.byte_size()
            + self.indices.byte_size()
            + self
                .normals
                .as_ref()
                .map_or(0, |n| n.capacity() * std::mem::size_of::<Vec3>())
            + self
                .uvs
                .as_ref()
                .map_or(0, |n| n.capacity() * std::mem::size_of::<Vec2>())
            + self.lights.capacity() * std::mem::size_of::<u32>()
            + self.flat_frames.capacity() * std::mem::size_of::<Frame>()
    }

    /// Stores [`MeshData::flat_frames`] if the mesh is flat-shaded.
    pub fn store_flat_frames(&mut self) {
        if self.normals.is_some() {
            return;
        }
        let vertices: &[Vertex] = &self.vertices;
        self.flat_frames = self
            .indices
            .iter()
            .map(|tri| {
                let [p0, p1, p2] = tri.map(|i| Vec3::from(vertices[i as usize]));
                // The direction of Embree's geometric normal (see `mesh_hit`).
                let n = (p1 - p0).cross(p2 - p0).normalize_or_zero() * self.orientation;
                Frame::from_z(n)
            })
            .collect();
    }
}

/// A mesh built once in its own Embree scene and placed by instances; its
/// meshes are indexed by the geometry id within that scene.
pub(crate) struct Prototype {
    pub meshes: Vec<MeshData>,
}

/// An affine placement of a prototype, with what shading needs to bring
/// object-space hits into world space.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Placement {
    pub linear: Mat3,
    pub translation: Vec3,
    /// Inverse transpose of `linear`, for normals.
    pub normal: Mat3,
}

mod hit;
mod queries;
#[cfg(test)]
mod tests;

/// Per-geometry shading data, indexed by Embree geometry id.
pub(crate) enum Geometry {
    Mesh(MeshData),
    /// An Embree instance of `prototypes[prototype]`.
    Instance {
        prototype: u32,
        placement: Placement,
        /// Per prototype mesh, the light index per triangle of this
        /// instance (world-space triangle lights); empty when none emits.
        lights: Vec<Vec<u32>>,
    },
    Sphere {
        center: Vec3,
        radius: f32,
        bsdf: u32,
        light: Option<u32>,
        orientation: f32,
    },
}

/// What [`RenderScene`] was built from, for `lumis render -v`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SceneCounts {
    pub meshes: usize,
    pub triangles: usize,
    pub spheres: usize,
    pub area_lights: usize,
    pub delta_lights: usize,
    pub infinite_lights: usize,
    pub shading_normals: bool,
    /// Embree instances (glTF meshes referenced by several nodes).
    pub instances: usize,
    /// Meshes built once and instanced.
    pub prototypes: usize,
    /// Triangles stored (each instanced mesh once); `triangles` counts
    /// every instance.
    pub unique_triangles: usize,
}

/// A BSDF of the scene with its flags, read once at load so that a hit
/// hands them to the integrator without a virtual call per vertex.
pub(crate) struct SceneBsdf {
    pub(crate) bsdf: Arc<dyn Bsdf>,
    pub(crate) flags: BsdfFlags,
}

impl SceneBsdf {
    pub(crate) fn new(bsdf: Arc<dyn Bsdf>) -> Self {
        let flags = bsdf.flags();
        Self { bsdf, flags }
    }
}

pub struct RenderScene {
    pub(crate) embree: lumis_embree::Scene,
    pub(crate) geometries: Vec<Geometry>,
    pub(crate) prototypes: Vec<Prototype>,
    pub(crate) bsdfs: Vec<SceneBsdf>,
    pub(crate) lights: Vec<Box<dyn Light>>,
    pub(crate) infinite_lights: Vec<u32>,
    pub(crate) light_sampler: Box<dyn LightSampler>,
    pub(crate) counts: SceneCounts,
    pub(crate) report: LoadReport,
    /// `[accel] packets`: every ray of a batch in packets, not only camera
    /// rays ([`lumis_core::Scene::intersect_batch`]).
    pub(crate) packets: bool,
    /// The camera's pixel footprint, which gives hits on surfaces with
    /// texture coordinates the uv footprint their textures filter over.
    pub(crate) footprint: Option<PixelFootprint>,
    /// Whether hits build their shading frames from `dp/du` and `dp/dv`
    /// ([`Frame::from_tangents`]), which a BSDF of the scene reads
    /// ([`lumis_core::Bsdf::uses_tangent_frame`]).
    pub(crate) tangent_frames: bool,
}

impl RenderScene {
    pub fn counts(&self) -> &SceneCounts {
        &self.counts
    }

    /// Load times and memory, for the start-up report.
    pub fn load_report(&self) -> &LoadReport {
        &self.report
    }

    /// The Embree scene, for benchmarks that trace the same rays bare.
    pub fn embree(&self) -> &lumis_embree::Scene {
        &self.embree
    }

    /// Sets what `[accel] packets` sets (for benchmarks that compare).
    pub fn set_packets(&mut self, packets: bool) {
        self.packets = packets;
    }

    /// The Embree scene, to record and replay its answers (feature
    /// `replay`).
    #[cfg(feature = "replay")]
    pub fn embree_mut(&mut self) -> &mut lumis_embree::Scene {
        &mut self.embree
    }

    /// The scene with the profiling wrappers of `lumis_render::profile`
    /// around every BSDF, light and the light sampler, so that a profiled
    /// render attributes their time (`lumis render --stats`). Their values
    /// are unchanged; only their calls cost a little more.
    pub fn into_profiled(mut self) -> Self {
        use lumis_render::profile::{profiled_bsdf, profiled_light, profiled_light_sampler};
        for b in &mut self.bsdfs {
            b.bsdf = Arc::new(profiled_bsdf(Arc::clone(&b.bsdf)));
        }
        self.lights = std::mem::take(&mut self.lights)
            .into_iter()
            .map(|light| Box::new(profiled_light(light)) as Box<dyn Light>)
            .collect();
        self.light_sampler = Box::new(profiled_light_sampler(self.light_sampler));
        self
    }

    /// Bounding sphere of the geometry: `(center, radius)`.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        bounding_sphere(&self.embree)
    }
}

pub(crate) fn bounding_sphere(scene: &lumis_embree::Scene) -> (Vec3, f32) {
    let (lo, hi) = scene.bounds();
    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
    if !(lo.is_finite() && hi.is_finite()) || lo.cmpgt(hi).any() {
        return (Vec3::ZERO, 0.0);
    }
    let center = 0.5 * (lo + hi);
    (center, (hi - center).length())
}
