//! `triangle`: one emissive triangle of a mesh, sampled uniformly by area or
//! uniformly over the spherical triangle it subtends (Arvo 1995).
//!
//! `sampling = "solid-angle"` uses Arvo's spherical triangle sampling
//! between 3e-4 sr and 6.22 sr (pbrt-v4's bounds) and area sampling outside
//! that range: below it the spherical excess cancels in float, and area
//! sampling is almost proportional to solid angle anyway; above it the arcs
//! degenerate.

use lumis_api::math::gamma;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Aabb, Error, Light, LightShape, Params, PluginKind, PluginParams, PluginSpec, Result, Vec2,
    Vec3,
};
use lumis_sampling::{
    warp, SphericalTriangle, MAX_SPHERICAL_SAMPLE_AREA, MIN_SPHERICAL_SAMPLE_AREA,
};

use crate::area::{AreaLight, Emission, EmissionParams, PlanarShape, Sampling, SolidAngleSample};
use crate::textured::boxed;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "triangle",
    source: lumis_api::source_file!(),
    doc: "emission of one mesh triangle: uniform area sampling converted to solid angle, or spherical-triangle sampling (Arvo 1995) where it subtends 3e-4 to 6.22 sr",
    params: EmissionParams::SPECS,
};

/// A triangle; its front faces `(p1 - p0) x (p2 - p0)`.
#[derive(Debug, Clone)]
pub struct Triangle {
    p: [Vec3; 3],
    /// The vertices' texture coordinates.
    uv: [Vec2; 3],
    normal: Vec3,
    area: f32,
}

/// The emission of one mesh triangle.
pub type TriangleLight = AreaLight<Triangle>;

impl TriangleLight {
    pub fn new(p: [Vec3; 3], emission: Emission) -> Result<Self> {
        Self::with_uvs(p, LightShape::BARYCENTRIC_UVS, emission)
    }

    /// A triangle light whose vertices have texture coordinates `uv`.
    pub fn with_uvs(p: [Vec3; 3], uv: [Vec2; 3], emission: Emission) -> Result<Self> {
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let len = cross.length();
        if !(len > 0.0 && len.is_finite()) {
            return Err(Error::msg(
                "triangle light: degenerate triangle (zero area)",
            ));
        }
        let shape = Triangle {
            p,
            uv,
            normal: cross / len,
            area: 0.5 * len,
        };
        Ok(Self {
            shape,
            emission,
            sampling: Sampling::Area,
        })
    }

    /// The light plugin: textured where its radiance is a texture.
    pub fn make(params: &Params, shape: &LightShape) -> Result<Box<dyn Light>> {
        let read = EmissionParams::read(params)?;
        let emission = Emission::from_params(&read, params)?;
        match *shape {
            LightShape::Triangle { p, uv } => Ok(boxed(
                Self::with_uvs(p, uv, emission)?.with_sampling(read.sampling),
                read.texture(),
            )),
            _ => Err(Error::msg(format!(
                "{}: the triangle light is the emission of a mesh shape; give the mesh an emission = {{ ... }}",
                params.owner()
            ))),
        }
    }
}

impl Triangle {
    /// Arvo's spherical triangle and its solid angle, where the triangle
    /// subtends between [`MIN_SPHERICAL_SAMPLE_AREA`] (3e-4 sr: below it
    /// the construction loses precision; a triangle of area `A` at distance
    /// `d` subtends about `A / d^2`, so a unit triangle beyond ~40 units)
    /// and [`MAX_SPHERICAL_SAMPLE_AREA`] (6.22 sr: a shading point almost
    /// in a huge triangle's plane close to it, where the arcs degenerate).
    /// Elsewhere the light samples by area (pbrt-v4 `Triangle::Sample`).
    #[inline]
    fn spherical(&self, p: Vec3) -> Option<(SphericalTriangle, f32)> {
        let spherical = SphericalTriangle::new(self.p, p)?;
        let omega = spherical.solid_angle() as f32;
        (MIN_SPHERICAL_SAMPLE_AREA..=MAX_SPHERICAL_SAMPLE_AREA)
            .contains(&omega)
            .then_some((spherical, omega))
    }

    /// The point with barycentrics `b`, with its error bound.
    fn point_at(&self, b: [f32; 3]) -> SurfacePoint {
        let (q0, q1, q2) = (self.p[0] * b[0], self.p[1] * b[1], self.p[2] * b[2]);
        SurfacePoint {
            p: q0 + q1 + q2,
            // pbrt-v4 Triangle::Sample: gamma(6) (|b0 p0| + |b1 p1| + |b2 p2|).
            p_error: gamma(6) * (q0.abs() + q1.abs() + q2.abs()),
            n: self.normal,
        }
    }
}

impl PlanarShape for Triangle {
    fn area(&self) -> f32 {
        self.area
    }

    fn bounds(&self) -> Aabb {
        Aabb::of_points(self.p)
    }

    fn normal(&self) -> Vec3 {
        self.normal
    }

    fn sample_point(&self, u: Vec2) -> SurfacePoint {
        let b = warp::square_to_uniform_triangle(u);
        self.point_at([b.x, b.y, 1.0 - b.x - b.y])
    }

    /// By the barycentrics of `p` projected onto the triangle's plane.
    fn uv_at(&self, q: Vec3) -> Vec2 {
        let [p0, p1, p2] = self.p;
        let (e1, e2, d) = (p1 - p0, p2 - p0, q - p0);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d1, d2) = (d.dot(e1), d.dot(e2));
        let det = d11 * d22 - d12 * d12;
        let b1 = (d22 * d1 - d12 * d2) / det;
        let b2 = (d11 * d2 - d12 * d1) / det;
        let [t0, t1, t2] = self.uv;
        t0 * (1.0 - b1 - b2) + t1 * b1 + t2 * b2
    }

    fn solid_angle(&self, p: Vec3) -> Option<f32> {
        self.spherical(p).map(|(_, omega)| omega)
    }

    fn sample_solid_angle(&self, p: Vec3, u: Vec2) -> SolidAngleSample {
        SolidAngleSample::from_spherical(self.spherical(p), |triangle| {
            triangle.sample(u).map(|b| self.point_at(b))
        })
    }

    /// Moller-Trumbore ray/triangle test (1997, JGT 2(1)).
    fn intersect(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let e1 = self.p[1] - self.p[0];
        let e2 = self.p[2] - self.p[0];
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let tv = o - self.p[0];
        let b1 = tv.dot(pv) * inv;
        if !(0.0..=1.0).contains(&b1) {
            return None;
        }
        let qv = tv.cross(e1);
        let b2 = d.dot(qv) * inv;
        if b2 < 0.0 || b1 + b2 > 1.0 {
            return None;
        }
        let t = e2.dot(qv) * inv;
        (t > 0.0).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_api::{Light, LightSampleContext, Rgb};
    use lumis_sampling::Pcg32;

    #[test]
    fn sample_pdf_matches_pdf_li_and_points_lie_on_triangle() {
        let emission = Emission {
            radiance: Rgb::WHITE,
            two_sided: true,
        };
        let tri = [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let l = TriangleLight::new(tri, emission).unwrap();
        let ctx = LightSampleContext::at(Vec3::new(0.3, -0.5, 0.2));
        let mut rng = Pcg32::new(9, 9);
        for _ in 0..1000 {
            let s = l
                .sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            assert!((s.p.p.y - 1.0).abs() < 1e-6 && s.p.p.x + s.p.p.z <= 1.0 + 1e-5);
            let pdf = l.pdf_li(&ctx, s.wi);
            assert!((s.pdf - pdf).abs() < 1e-3 * pdf, "{} vs {pdf}", s.pdf);
        }
        assert_eq!(l.pdf_li(&ctx, -Vec3::Y), 0.0);
    }
}
