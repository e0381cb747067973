//! What an Embree hit becomes: the interaction shading sees, on a mesh,
//! an instance or a sphere, with its point's error bound, frames, uv and
//! texture footprint.

use lumis_core::glam::{Mat3, Vec3A, Vec4};
use lumis_core::math::{gamma, Frame};
use lumis_core::ray::SurfacePoint;
use lumis_core::{LightIndex, LightShape, Ray, SurfaceInteraction, TextureQuery, Vec2, Vec3};
use lumis_embree::{Hit, Triangle, INVALID_ID};

use super::{Geometry, MeshData, Placement, RenderScene};

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

impl RenderScene {
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

impl RenderScene {
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
    pub(super) fn interaction_at(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction<'_> {
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
