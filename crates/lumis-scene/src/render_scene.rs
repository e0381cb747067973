//! The render-ready scene: Embree geometry plus what shading needs per hit.

use std::sync::Arc;

use lumis_core::glam::{Mat3, Vec3A, Vec4};
use lumis_core::math::{gamma, Frame};
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Bsdf, BsdfFlags, Light, LightIndex, LightSampler, Ray, Scene, SurfaceInteraction, Vec2, Vec3,
};
use lumis_embree::{Hit, PaddedBuffer, Triangle, Vertex, INVALID_ID, PACKET};

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

impl Placement {
    /// pbrt-v4 `Transform::operator()(Point3fi)`: the transformed point
    /// and a bound on its rounding error, given the error of `p`.
    #[inline]
    fn point(&self, p: Vec3, error: Vec3) -> (Vec3, Vec3) {
        let abs = Mat3::from_cols(
            self.linear.x_axis.abs(),
            self.linear.y_axis.abs(),
            self.linear.z_axis.abs(),
        );
        let q = self.linear * p + self.translation;
        let e =
            (gamma(3) + 1.0) * (abs * error) + gamma(3) * (abs * p.abs() + self.translation.abs());
        (q, e)
    }

    #[inline]
    fn normal(&self, n: Vec3) -> Vec3 {
        (self.normal * n).normalize()
    }
}

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
    /// `[accel] packets`: batched queries as Embree packets.
    pub(crate) packets: bool,
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
        use lumis_render::profile::{ProfiledBsdf, ProfiledLight, ProfiledLightSampler};
        for b in &mut self.bsdfs {
            b.bsdf = Arc::new(ProfiledBsdf(Arc::clone(&b.bsdf)));
        }
        self.lights = std::mem::take(&mut self.lights)
            .into_iter()
            .map(|light| Box::new(ProfiledLight(light)) as Box<dyn Light>)
            .collect();
        self.light_sampler = Box::new(ProfiledLightSampler(self.light_sampler));
        self
    }

    /// Bounding sphere of the geometry: `(center, radius)`.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        bounding_sphere(&self.embree)
    }

    /// The interaction at `point` with shading frame `shading` on a surface
    /// of scene BSDF `bsdf`.
    #[inline(always)]
    fn interaction(
        &self,
        point: SurfacePoint,
        shading: Frame,
        uv: Vec2,
        wo: Vec3,
        bsdf: u32,
        light: Option<LightIndex>,
    ) -> SurfaceInteraction<'_> {
        let bsdf = &self.bsdfs[bsdf as usize];
        SurfaceInteraction {
            point,
            shading,
            uv,
            wo,
            bsdf: bsdf.bsdf.as_ref(),
            bsdf_flags: bsdf.flags,
            light,
        }
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

impl RenderScene {
    /// A hit inside an instance: shaded in object space, then placed.
    #[inline]
    fn instance_hit(&self, hit: &Hit, wo: Vec3) -> SurfaceInteraction<'_> {
        let Geometry::Instance {
            prototype,
            placement,
            lights,
        } = &self.geometries[hit.inst_id as usize]
        else {
            unreachable!("inst_id names an instance geometry")
        };
        let mesh = &self.prototypes[*prototype as usize].meshes[hit.geom_id as usize];
        let (local, local_shading, uv) = mesh_hit(mesh, hit);
        let (p, p_error) = placement.point(local.p, local.p_error);
        let n = placement.normal(local.n);
        let ns = placement.normal(local_shading.normal());
        let ns = if ns.dot(n) < 0.0 { -ns } else { ns };
        let light = lights
            .get(hit.geom_id as usize)
            .and_then(|l| l.get(hit.prim_id as usize))
            .and_then(|&i| LightIndex::new(i));
        self.interaction(
            SurfacePoint { p, p_error, n },
            Frame::from_z(ns),
            uv,
            wo,
            mesh.bsdf,
            light,
        )
    }
}

/// The hit point (recomputed from barycentrics, with its error bound), the
/// shading frame on a mesh, in the mesh's own space, and the uv.
#[inline(always)]
fn mesh_hit(mesh: &MeshData, hit: &Hit) -> (SurfacePoint, Frame, Vec2) {
    let tri = mesh.indices[hit.prim_id as usize];
    // Each vertex in one 16-byte load, and the arithmetic below on SIMD
    // lanes: with 12-byte `Vec3`s it takes three times the instructions.
    let [p0, p1, p2] =
        tri.map(|i| Vec3A::from_vec4(Vec4::from_array(mesh.vertices.load4(i as usize))));
    let (b1, b2) = (hit.u, hit.v);
    let b0 = 1.0 - b1 - b2;
    // Recompute the hit from barycentrics and bound its error
    // (pbrt-v4 Triangle::InteractionFromIntersection, eq. 6.37):
    // the ray origin offset then needs no scene-scale epsilon.
    let (q0, q1, q2) = (p0 * b0, p1 * b1, p2 * b2);
    let p = Vec3::from(q0 + q1 + q2);
    let p_error = Vec3::from(gamma(7) * (q0.abs() + q1.abs() + q2.abs()));
    // A flat triangle's frame, where the scene stored it.
    if let Some(&frame) = mesh.flat_frames.get(hit.prim_id as usize) {
        return (
            SurfacePoint {
                p,
                p_error,
                n: frame.normal(),
            },
            frame,
            mesh_uv(mesh, tri, b0, b1, b2),
        );
    }
    // Embree's geometric normal is (p1 - p0) x (p2 - p0), unnormalised, in
    // the mesh's own space (counter-clockwise = front, as here); reusing it
    // saves recomputing the cross product.
    let n = Vec3::from(hit.ng).normalize() * mesh.orientation;
    let ns = match &mesh.normals {
        Some(ns) => {
            let [n0, n1, n2] = tri.map(|i| ns[i as usize]);
            let s = (n0 * b0 + n1 * b1 + n2 * b2).normalize_or_zero();
            // Keep the shading normal on the geometric side.
            if s == Vec3::ZERO {
                n
            } else if s.dot(n) < 0.0 {
                -s
            } else {
                s
            }
        }
        None => n,
    };
    let uv = mesh_uv(mesh, tri, b0, b1, b2);
    (SurfacePoint { p, p_error, n }, Frame::from_z(ns), uv)
}

/// The uv at barycentrics `(b0, b1, b2)` of triangle `tri`: interpolated
/// texture coordinates, else the barycentrics themselves.
#[inline(always)]
fn mesh_uv(mesh: &MeshData, tri: Triangle, b0: f32, b1: f32, b2: f32) -> Vec2 {
    match &mesh.uvs {
        Some(uvs) => {
            let [t0, t1, t2] = tri.map(|i| uvs[i as usize]);
            t0 * b0 + t1 * b1 + t2 * b2
        }
        None => Vec2::new(b1, b2),
    }
}

impl RenderScene {
    /// The interaction where `ray` found `hit`.
    #[inline(always)]
    fn interaction_at(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction<'_> {
        let wo = -ray.d;
        if hit.inst_id != INVALID_ID {
            return self.instance_hit(hit, wo);
        }
        match &self.geometries[hit.geom_id as usize] {
            Geometry::Mesh(mesh) => {
                let (point, shading, uv) = mesh_hit(mesh, hit);
                let light = mesh
                    .lights
                    .get(hit.prim_id as usize)
                    .and_then(|&i| LightIndex::new(i));
                self.interaction(point, shading, uv, wo, mesh.bsdf, light)
            }
            Geometry::Instance { .. } => unreachable!("instances report an inst_id"),
            Geometry::Sphere {
                center,
                radius,
                bsdf,
                light,
                orientation,
            } => {
                // Reproject onto the surface (pbrt-v4 Sphere, section 6.8.5):
                // the error is then gamma(5) |p| in the sphere's frame.
                let local = ray.at(hit.t) - *center;
                let local = local * (*radius / local.length());
                let p = *center + local;
                let p_error = gamma(5) * local.abs() + gamma(1) * center.abs();
                let outward = local / *radius;
                let n = outward * *orientation;
                let phi = outward.y.atan2(outward.x);
                let uv = Vec2::new(
                    (phi * 0.5 * std::f32::consts::FRAC_1_PI).rem_euclid(1.0),
                    outward.z.clamp(-1.0, 1.0).acos() * std::f32::consts::FRAC_1_PI,
                );
                self.interaction(
                    SurfacePoint { p, p_error, n },
                    Frame::from_z(n),
                    uv,
                    wo,
                    *bsdf,
                    light.and_then(LightIndex::new),
                )
            }
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

    /// Ray by ray, or with `[accel] packets` as Embree packets of eight.
    fn intersect_batch<'s>(&'s self, rays: &[Ray], out: &mut [Option<SurfaceInteraction<'s>>]) {
        if !self.packets {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.intersect(ray);
            }
            return;
        }
        for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let queries: [lumis_embree::Ray; PACKET] =
                std::array::from_fn(|i| rays.get(i).map_or(NO_RAY, to_embree));
            let mut hits = [None; PACKET];
            self.embree
                .intersect_packets(&queries[..rays.len()], &mut hits[..rays.len()]);
            for ((ray, hit), out) in rays.iter().zip(&hits).zip(out) {
                *out = hit.as_ref().map(|hit| self.interaction_at(ray, hit));
            }
        }
    }

    /// As [`Scene::intersect_batch`].
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        if !self.packets {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.occluded(ray);
            }
            return;
        }
        for (rays, out) in rays.chunks(PACKET).zip(out.chunks_mut(PACKET)) {
            let queries: [lumis_embree::Ray; PACKET] =
                std::array::from_fn(|i| rays.get(i).map_or(NO_RAY, to_embree));
            self.embree.occluded_packets(&queries[..rays.len()], out);
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
