//! The render-ready scene: Embree geometry plus what shading needs per hit.

use std::sync::Arc;

use lumis_core::glam::{Mat3, Vec3A, Vec4};
use lumis_core::math::{gamma, Frame};
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Bsdf, BsdfFlags, Light, LightIndex, LightSampler, LightShape, PixelFootprint, Ray, Scene,
    SurfaceInteraction, TextureQuery, Vec2, Vec3,
};
use lumis_embree::{Hit, PacketWidth, Packets, PaddedBuffer, Triangle, Vertex, INVALID_ID};

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
    /// `[accel] packets`: every ray of a batch in packets, not only camera
    /// rays ([`Scene::intersect_batch`]).
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

    /// The texture lookup at `uv` on `point`, whose surface has partial
    /// derivatives `dp_duv`, with the camera's footprint.
    #[inline]
    fn texture_query(&self, uv: Vec2, point: &SurfacePoint, dp_duv: (Vec3, Vec3)) -> TextureQuery {
        match &self.footprint {
            Some(footprint) => {
                let (duv_dx, duv_dy) = footprint.uv_footprint(point.p, point.n, dp_duv.0, dp_duv.1);
                TextureQuery::new(uv, duv_dx, duv_dy)
            }
            None => TextureQuery::at(uv),
        }
    }

    /// `shading` turned about its normal to follow the texture tangents
    /// `dp_duv`, in a scene whose BSDFs read them.
    #[inline]
    fn shading_frame(&self, shading: Frame, dp_duv: Option<(Vec3, Vec3)>) -> Frame {
        match dp_duv {
            Some((dpdu, dpdv)) if self.tangent_frames => {
                Frame::from_tangents(shading.normal(), dpdu, dpdv)
            }
            _ => shading,
        }
    }

    /// The interaction at `point` with shading frame `shading` on a surface
    /// of scene BSDF `bsdf`.
    #[inline(always)]
    fn interaction(
        &self,
        point: SurfacePoint,
        shading: Frame,
        texture: TextureQuery,
        bsdf: u32,
        light: Option<LightIndex>,
    ) -> SurfaceInteraction<'_> {
        let bsdf = &self.bsdfs[bsdf as usize];
        SurfaceInteraction {
            point,
            shading,
            texture,
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

    /// A hit inside an instance: shaded in object space, then placed.
    #[inline]
    fn instance_hit<const DIFFERENTIALS: bool>(&self, hit: &Hit) -> SurfaceInteraction<'_> {
        let Geometry::Instance {
            prototype,
            placement,
            lights,
        } = &self.geometries[hit.inst_id as usize]
        else {
            unreachable!("inst_id names an instance geometry")
        };
        let mesh = &self.prototypes[*prototype as usize].meshes[hit.geom_id as usize];
        let (local, local_shading, uv, dp_duv) = mesh_hit(mesh, hit, DIFFERENTIALS);
        let (p, p_error) = placement.point(local.p, local.p_error);
        let n = placement.normal(local.n);
        let ns = placement.normal(local_shading.normal());
        let ns = if ns.dot(n) < 0.0 { -ns } else { ns };
        let light = lights
            .get(hit.geom_id as usize)
            .and_then(|l| l.get(hit.prim_id as usize))
            .and_then(|&i| LightIndex::new(i));
        let point = SurfacePoint { p, p_error, n };
        let shading = Frame::from_z(ns);
        if !DIFFERENTIALS {
            return self.interaction(point, shading, TextureQuery::at(uv), mesh.bsdf, light);
        }
        let dp_duv = dp_duv.map(|(u, v)| (placement.linear * u, placement.linear * v));
        let texture = dp_duv.map_or(TextureQuery::at(uv), |d| self.texture_query(uv, &point, d));
        let shading = self.shading_frame(shading, dp_duv);
        self.interaction(point, shading, texture, mesh.bsdf, light)
    }
}

/// What a hit on a mesh gives shading, in the mesh's own space: the point
/// (recomputed from barycentrics, with its error bound), the shading
/// frame, the uv and, when asked for and the mesh has uvs, `dp/du` and
/// `dp/dv`.
type MeshHit = (SurfacePoint, Frame, Vec2, Option<(Vec3, Vec3)>);

/// The [`MeshHit`] of `hit`; `dp_duv` asks for the uv derivatives.
#[inline(always)]
fn mesh_hit(mesh: &MeshData, hit: &Hit, dp_duv: bool) -> MeshHit {
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
    let (uv, derivatives) = mesh_uv(mesh, tri, [b0, b1, b2], [p0, p1, p2], dp_duv);
    // A flat triangle's frame, where the scene stored it.
    if let Some(&frame) = mesh.flat_frames.get(hit.prim_id as usize) {
        return (
            SurfacePoint {
                p,
                p_error,
                n: frame.normal(),
            },
            frame,
            uv,
            derivatives,
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
    (
        SurfacePoint { p, p_error, n },
        Frame::from_z(ns),
        uv,
        derivatives,
    )
}

/// The uv at barycentrics `b` of triangle `tri` (vertices `p`):
/// interpolated texture coordinates, else the barycentrics `(b1, b2)`
/// themselves; with `dp_duv`, also the triangle's `dp/du` and `dp/dv`
/// where its uvs are not degenerate.
#[inline(always)]
fn mesh_uv(
    mesh: &MeshData,
    tri: Triangle,
    [b0, b1, b2]: [f32; 3],
    p: [Vec3A; 3],
    dp_duv: bool,
) -> (Vec2, Option<(Vec3, Vec3)>) {
    let (uv, t) = match &mesh.uvs {
        Some(uvs) => {
            let t = tri.map(|i| uvs[i as usize]);
            (t[0] * b0 + t[1] * b1 + t[2] * b2, t)
        }
        None => (Vec2::new(b1, b2), LightShape::BARYCENTRIC_UVS),
    };
    let derivatives = if dp_duv {
        lumis_core::footprint::triangle_dp_duv(p.map(Vec3::from), t)
    } else {
        None
    };
    (uv, derivatives)
}

impl RenderScene {
    /// The interaction where `ray` found `hit`, in a scene whose hits need
    /// the surface's uv derivatives (for a pixel footprint or tangent
    /// frames) or not. Two copies of the hit code, chosen by one branch per
    /// hit: a scene without filtered textures or tangent frames runs one
    /// that has no such work in it at all (measured: checked per hit, the
    /// footprint cost the Cornell box 3% of its time).
    #[inline(always)]
    fn interaction_at(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction<'_> {
        if self.footprint.is_some() || self.tangent_frames {
            self.interaction_with::<true>(ray, hit)
        } else {
            self.interaction_with::<false>(ray, hit)
        }
    }

    /// [`Self::interaction_at`], with `DIFFERENTIALS` saying whether hits
    /// need `dp/du` and `dp/dv` (for a pixel footprint or tangent frames).
    #[inline(always)]
    fn interaction_with<const DIFFERENTIALS: bool>(
        &self,
        ray: &Ray,
        hit: &Hit,
    ) -> SurfaceInteraction<'_> {
        if hit.inst_id != INVALID_ID {
            return self.instance_hit::<DIFFERENTIALS>(hit);
        }
        match &self.geometries[hit.geom_id as usize] {
            Geometry::Mesh(mesh) => {
                let (point, shading, uv, dp_duv) = mesh_hit(mesh, hit, DIFFERENTIALS);
                let light = mesh
                    .lights
                    .get(hit.prim_id as usize)
                    .and_then(|&i| LightIndex::new(i));
                if !DIFFERENTIALS {
                    return self.interaction(
                        point,
                        shading,
                        TextureQuery::at(uv),
                        mesh.bsdf,
                        light,
                    );
                }
                let texture =
                    dp_duv.map_or(TextureQuery::at(uv), |d| self.texture_query(uv, &point, d));
                let shading = self.shading_frame(shading, dp_duv);
                self.interaction(point, shading, texture, mesh.bsdf, light)
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
                let point = SurfacePoint { p, p_error, n };
                let light = light.and_then(LightIndex::new);
                if !DIFFERENTIALS {
                    let texture = TextureQuery::at(uv);
                    return self.interaction(point, Frame::from_z(n), texture, *bsdf, light);
                }
                let dp_duv = sphere_dp_duv(local, phi);
                let texture = self.texture_query(uv, &point, dp_duv);
                let shading = self.shading_frame(Frame::from_z(n), Some(dp_duv));
                self.interaction(point, shading, texture, *bsdf, light)
            }
        }
    }
}

/// `dp/du` and `dp/dv` of a sphere at `local` (relative to its centre),
/// azimuth `phi`, for `u = phi / 2 pi` and `v = theta / pi` (pbrt-v4
/// `Sphere::InteractionFromIntersection`, with its full ranges of phi and
/// theta).
#[inline]
fn sphere_dp_duv(local: Vec3, phi: f32) -> (Vec3, Vec3) {
    use std::f32::consts::PI;
    let dpdu = 2.0 * PI * Vec3::new(-local.y, local.x, 0.0);
    let (sin_phi, cos_phi) = phi.sin_cos();
    let rho = local.truncate().length();
    let dpdv = PI * Vec3::new(local.z * cos_phi, local.z * sin_phi, -rho);
    (dpdu, dpdv)
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
    use lumis_core::light_sampler::NoLights;
    use lumis_core::{BsdfContext, BsdfSample, Rgb};
    use lumis_embree::{Device, SceneBuilder, SceneOptions, SpherePoint};

    use super::*;

    struct Black;

    impl Bsdf for Black {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::DIFFUSE_REFLECTION
        }
        fn f(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> Rgb {
            Rgb::BLACK
        }
        fn sample_f(&self, _: &BsdfContext, _: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
            None
        }
        fn pdf(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> f32 {
            0.0
        }
    }

    /// A small deterministic generator (SplitMix64).
    struct Rng(u64);

    impl Rng {
        fn next_f32(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
        }

        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next_f32()
        }

        fn direction(&mut self) -> Vec3 {
            let z = self.range(-1.0, 1.0);
            let phi = self.range(0.0, std::f32::consts::TAU);
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        }
    }

    /// A UV sphere mesh with smooth normals and texture coordinates.
    fn uv_sphere(n: u32, bsdf: u32) -> MeshData {
        let (mut vertices, mut normals, mut uvs) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..=n {
            let theta = std::f32::consts::PI * i as f32 / n as f32;
            for j in 0..n {
                let phi = std::f32::consts::TAU * j as f32 / n as f32;
                let p = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                vertices.push(p.to_array());
                normals.push(p);
                uvs.push(Vec2::new(j as f32 / n as f32, i as f32 / n as f32));
            }
        }
        let at = |i: u32, j: u32| i * n + j % n;
        let mut indices = Vec::new();
        for i in 0..n {
            for j in 0..n {
                indices.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                indices.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        MeshData {
            vertices: Arc::new(vertices.into()),
            indices: Arc::new(indices.into()),
            normals: Some(normals),
            uvs: Some(uvs),
            bsdf,
            lights: Vec::new(),
            orientation: 1.0,
            flat_frames: Vec::new(),
        }
    }

    /// A flat-shaded floor whose second triangle emits.
    fn floor(bsdf: u32) -> MeshData {
        let vertices = vec![
            [-5.0, -5.0, -1.5],
            [5.0, -5.0, -1.5],
            [5.0, 5.0, -1.5],
            [-5.0, 5.0, -1.5],
        ];
        let mut mesh = MeshData {
            vertices: Arc::new(vertices.into()),
            indices: Arc::new(vec![[0, 1, 2], [0, 2, 3]].into()),
            normals: None,
            uvs: None,
            bsdf,
            lights: vec![NO_LIGHT, 0],
            orientation: 1.0,
            flat_frames: Vec::new(),
        };
        mesh.store_flat_frames();
        mesh
    }

    fn add(builder: &mut SceneBuilder, mesh: &MeshData) {
        builder
            .add_triangle_mesh(mesh.vertices.clone(), mesh.indices.clone())
            .unwrap();
    }

    /// A mesh with shading normals and uvs, a flat floor, two placed
    /// instances of a prototype and spheres: every kind of hit shading
    /// knows. Geometry ids follow the order of `geometries`.
    fn scene(packets: bool) -> RenderScene {
        let device = Device::new().unwrap();
        let mut proto_builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let proto_mesh = uv_sphere(12, 1);
        add(&mut proto_builder, &proto_mesh);
        let prototype = Arc::new(proto_builder.commit().unwrap());

        let mut builder = SceneBuilder::new(&device, SceneOptions::default()).unwrap();
        let mut geometries = Vec::new();
        let mesh = uv_sphere(24, 0);
        add(&mut builder, &mesh);
        geometries.push(Geometry::Mesh(mesh));
        let floor = floor(1);
        add(&mut builder, &floor);
        geometries.push(Geometry::Mesh(floor));
        for (angle, translation) in [
            (0.3f32, Vec3::new(2.2, 0.5, 0.0)),
            (1.1, Vec3::new(-2.0, 1.5, 0.5)),
        ] {
            let linear =
                Mat3::from_rotation_z(angle) * Mat3::from_diagonal(Vec3::new(0.6, 0.8, 0.7));
            let mut transform = [0.0; 12];
            transform[..9].copy_from_slice(&linear.to_cols_array());
            transform[9..].copy_from_slice(&translation.to_array());
            builder.add_instance(prototype.clone(), &transform).unwrap();
            geometries.push(Geometry::Instance {
                prototype: 0,
                placement: Placement {
                    linear,
                    translation,
                    normal: linear.inverse().transpose(),
                },
                lights: Vec::new(),
            });
        }
        let spheres: Vec<SpherePoint> = vec![[0.5, -2.0, 0.0, 0.7]];
        builder.add_spheres(Arc::new(spheres.into())).unwrap();
        geometries.push(Geometry::Sphere {
            center: Vec3::new(0.5, -2.0, 0.0),
            radius: 0.7,
            bsdf: 1,
            light: Some(1),
            orientation: 1.0,
        });
        RenderScene {
            embree: builder.commit().unwrap(),
            geometries,
            prototypes: vec![Prototype {
                meshes: vec![proto_mesh],
            }],
            bsdfs: vec![
                SceneBsdf::new(Arc::new(Black)),
                SceneBsdf::new(Arc::new(Black)),
            ],
            lights: Vec::new(),
            infinite_lights: Vec::new(),
            light_sampler: Box::new(NoLights),
            counts: SceneCounts::default(),
            report: LoadReport::default(),
            packets,
            footprint: None,
            tangent_frames: false,
        }
    }

    /// A batch as a wavefront integrator makes one: incoherent rays from
    /// anywhere, then runs of camera rays (one origin, nearby directions)
    /// of lengths around the packet width; a third of all rays have a
    /// finite `t_max`, often short of what they would hit.
    fn batch(seed: u64) -> Vec<Ray> {
        let mut rng = Rng(seed);
        let mut rays = Vec::new();
        let limit = |rng: &mut Rng, o: Vec3, d: Vec3| {
            let t_max = if rng.next_f32() < 1.0 / 3.0 {
                rng.range(0.05, 5.0)
            } else {
                f32::INFINITY
            };
            Ray { o, d, t_max }
        };
        for run in [0, 3, 16, 17, 5, 40, 15, 32] {
            for _ in 0..60 {
                let o = Vec3::new(
                    rng.range(-3.0, 3.0),
                    rng.range(-3.0, 3.0),
                    rng.range(-1.0, 3.0),
                );
                let d = rng.direction();
                rays.push(limit(&mut rng, o, d));
            }
            let eye = Vec3::new(0.3, -0.2, 6.0);
            let aim = Vec3::new(rng.range(-0.4, 0.4), rng.range(-0.4, 0.4), -1.0);
            for _ in 0..run {
                let jitter = Vec3::new(rng.range(-0.02, 0.02), rng.range(-0.02, 0.02), 0.0);
                rays.push(limit(&mut rng, eye, (aim + jitter).normalize()));
            }
        }
        rays
    }

    /// Whether two interactions agree up to the rounding of the traversal.
    fn same(a: &SurfaceInteraction, b: &SurfaceInteraction) -> bool {
        let close =
            |x: Vec3, y: Vec3| (x - y).abs().max_element() <= 1e-4 * x.abs().max_element().max(1.0);
        close(a.point.p, b.point.p)
            && close(a.point.n, b.point.n)
            && close(a.shading.z.into(), b.shading.z.into())
            && close(a.shading.x.into(), b.shading.x.into())
            && (a.texture.uv - b.texture.uv).abs().max_element() <= 1e-4
            && std::ptr::addr_eq(a.bsdf, b.bsdf)
            && a.bsdf_flags == b.bsdf_flags
            && a.light == b.light
    }

    /// Both batch queries answer as the single-ray ones, with and without
    /// `[accel] packets`, on whole batches and on lengths that are not
    /// multiples of a packet, from offsets that cut camera runs apart.
    #[test]
    fn batches_answer_as_single_rays() {
        let rays = batch(11);
        for packets in [false, true] {
            let scene = scene(packets);
            let single: Vec<_> = rays.iter().map(|r| scene.intersect(r)).collect();
            let blocked: Vec<bool> = rays.iter().map(|r| scene.occluded(r)).collect();
            for n in [0, 1, 7, 9, 33, rays.len()] {
                for start in [0, 61, 70, 100, 171] {
                    let end = (start + n).min(rays.len());
                    let mut found = vec![None; end - start];
                    scene.intersect_batch(&rays[start..end], &mut found);
                    let mut occluded = vec![false; end - start];
                    scene.occluded_batch(&rays[start..end], &mut occluded);
                    for (k, (found, occluded)) in (start..end).zip(found.iter().zip(&occluded)) {
                        match (&single[k], found) {
                            (None, None) => {}
                            (Some(a), Some(b)) if same(a, b) => {}
                            (a, b) => panic!(
                                "packets {packets}, batch {start}..{end}, ray {k} {:?}: single {:?}, batch {:?}",
                                rays[k],
                                a.as_ref().map(|h| (h.point, h.texture.uv, h.light)),
                                b.as_ref().map(|h| (h.point, h.texture.uv, h.light)),
                            ),
                        }
                        assert_eq!(*occluded, blocked[k], "packets {packets}, ray {k}");
                    }
                }
            }
            // The rays reach every geometry (and the emitting triangle),
            // and finite segments stop short of some hits.
            let hits: Vec<&SurfaceInteraction> = single.iter().flatten().collect();
            assert!(
                hits.len() > 200 && hits.len() < rays.len(),
                "{}",
                hits.len()
            );
            assert!(hits.iter().any(|h| h.light == LightIndex::new(0)));
            assert!(
                hits.iter().any(|h| h.light == LightIndex::new(1)),
                "a sphere hit"
            );
            assert!(
                hits.iter().any(|h| h.point.p.x > 1.5 && h.point.p.z > -1.0),
                "an instance hit"
            );
            let cut = rays
                .iter()
                .zip(&single)
                .filter(|(r, hit)| {
                    hit.is_none()
                        && scene
                            .intersect(&Ray {
                                t_max: f32::INFINITY,
                                ..**r
                            })
                            .is_some()
                })
                .count();
            assert!(cut > 20, "{cut}");
        }
    }

    /// The comparison tells a wrong answer from rounding.
    #[test]
    fn interaction_comparison_rejects_wrong_answers() {
        let scene = scene(false);
        let ray = Ray {
            o: Vec3::new(0.1, 0.2, 5.0),
            d: Vec3::NEG_Z,
            t_max: f32::INFINITY,
        };
        let hit = scene.intersect(&ray).unwrap();
        assert!(same(&hit, &hit));
        let mut moved = hit;
        moved.point.p.z += 1e-3;
        assert!(!same(&hit, &moved));
        let mut other = hit;
        other.bsdf = scene.bsdfs[1].bsdf.as_ref();
        assert!(!same(&hit, &other));
        let mut lit = hit;
        lit.light = LightIndex::new(3);
        assert!(!same(&hit, &lit));
    }

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
