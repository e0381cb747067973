//! `quad`: a parallelogram emitter, sampled uniformly by area or, for
//! rectangles, uniformly over the spherical rectangle it subtends (Urena et
//! al. 2013).
//!
//! `sampling = "area"` draws a point uniformly by area and converts its
//! density to solid angle, `pdf = d^2 / (|cos theta_l| A)`. `"solid-angle"`
//! is uniform over the spherical rectangle, `pdf = 1 / Omega`, for
//! rectangles subtending at least 3e-4 sr; smaller ones and skewed
//! parallelograms are sampled by area. [Lights and MIS](studies/mis.md)
//! compares the two.

use lumis_api::math::gamma;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Aabb, Error, Light, LightShape, Params, PluginKind, PluginParams, PluginSpec, Result, Vec2,
    Vec3,
};

use lumis_sampling::{SphericalRectangle, MIN_SPHERICAL_SAMPLE_AREA};

use crate::area::{AreaLight, Emission, EmissionParams, PlanarShape, Sampling, SolidAngleSample};
use crate::textured::boxed;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "quad",
    source: lumis_api::source_file!(),
    doc: "emission of a quad shape: uniform area sampling converted to solid angle, or spherical-rectangle sampling (Urena et al. 2013) for rectangles subtending at least 3e-4 sr",
    params: EmissionParams::SPECS,
};

/// A parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`.
#[derive(Debug, Clone)]
pub struct Quad {
    corner: Vec3,
    edge_u: Vec3,
    edge_v: Vec3,
    normal: Vec3,
    area: f32,
}

/// The emission of a quad shape.
pub type QuadLight = AreaLight<Quad>;

impl Quad {
    /// The spherical rectangle and its area (Urena et al. 2013, eq. 1),
    /// when the quad is a rectangle and subtends at least
    /// [`MIN_SPHERICAL_SAMPLE_AREA`]: below that the angle sum cancels and
    /// area sampling is nearly as good. Skewed parallelograms always sample
    /// by area.
    #[inline]
    fn spherical(&self, p: Vec3) -> Option<(SphericalRectangle, f32)> {
        let spherical = SphericalRectangle::new(self.corner, self.edge_u, self.edge_v, p)?;
        let omega = spherical.solid_angle();
        (omega >= f64::from(MIN_SPHERICAL_SAMPLE_AREA)).then_some((spherical, omega as f32))
    }
}

impl Quad {
    /// The coordinates `(s, t)` along the (possibly non-orthogonal) edges
    /// of the offset `d = s edge_u + t edge_v` in the quad's plane.
    #[inline]
    fn coordinates(&self, d: Vec3) -> Vec2 {
        let uu = self.edge_u.length_squared();
        let vv = self.edge_v.length_squared();
        let uv = self.edge_u.dot(self.edge_v);
        let du = d.dot(self.edge_u);
        let dv = d.dot(self.edge_v);
        let det = uu * vv - uv * uv;
        Vec2::new((du * vv - dv * uv) / det, (dv * uu - du * uv) / det)
    }
}

impl QuadLight {
    pub fn new(corner: Vec3, edge_u: Vec3, edge_v: Vec3, emission: Emission) -> Result<Self> {
        let cross = edge_u.cross(edge_v);
        let area = cross.length();
        if !(area > 0.0 && area.is_finite()) {
            return Err(Error::msg(
                "quad light: the edges are parallel or degenerate (zero area)",
            ));
        }
        let shape = Quad {
            corner,
            edge_u,
            edge_v,
            normal: cross / area,
            area,
        };
        Ok(Self {
            shape,
            emission,
            sampling: Sampling::Area,
        })
    }

    /// The light plugin: textured where its radiance is a texture.
    pub fn make(params: &Params, shape: &LightShape) -> Result<Box<dyn Light>> {
        let p = EmissionParams::read(params)?;
        let emission = Emission::from_params(&p, params)?;
        match *shape {
            LightShape::Quad { corner, edge_u, edge_v } => Ok(boxed(
                Self::new(corner, edge_u, edge_v, emission)?.with_sampling(p.sampling),
                p.texture(),
            )),
            _ => Err(Error::msg(format!(
                "{}: the quad light is the emission of a quad shape; use [[shape]] type = \"quad\" with emission = {{ ... }}",
                params.owner()
            ))),
        }
    }
}

impl PlanarShape for Quad {
    fn area(&self) -> f32 {
        self.area
    }

    fn bounds(&self) -> Aabb {
        let (c, u, v) = (self.corner, self.edge_u, self.edge_v);
        Aabb::of_points([c, c + u, c + v, c + u + v])
    }

    fn normal(&self) -> Vec3 {
        self.normal
    }

    fn sample_point(&self, u: Vec2) -> SurfacePoint {
        let su = self.edge_u * u.x;
        let sv = self.edge_v * u.y;
        SurfacePoint {
            p: self.corner + su + sv,
            p_error: gamma(6) * (self.corner.abs() + su.abs() + sv.abs()),
            n: self.normal,
        }
    }

    /// `(s, t)` of `p = corner + s edge_u + t edge_v`, as the quad shape's
    /// hits get them.
    fn uv_at(&self, p: Vec3) -> Vec2 {
        self.coordinates(p - self.corner)
    }

    fn intersect(&self, o: Vec3, w: Vec3) -> Option<f32> {
        let denom = self.normal.dot(w);
        if denom == 0.0 {
            return None;
        }
        let t = self.normal.dot(self.corner - o) / denom;
        if t.is_nan() || t <= 0.0 {
            return None;
        }
        let st = self.coordinates(o + w * t - self.corner);
        ((0.0..=1.0).contains(&st.x) && (0.0..=1.0).contains(&st.y)).then_some(t)
    }

    fn solid_angle(&self, p: Vec3) -> Option<f32> {
        self.spherical(p).map(|(_, omega)| omega)
    }

    fn sample_solid_angle(&self, p: Vec3, u: Vec2) -> SolidAngleSample {
        SolidAngleSample::from_spherical(self.spherical(p), |rectangle| {
            Some(self.sample_point(rectangle.sample(u)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_api::{Light, LightSampleContext, Rgb};
    use lumis_sampling::Pcg32;

    fn light() -> QuadLight {
        let emission = Emission {
            radiance: Rgb::splat(2.0),
            two_sided: false,
        };
        // Facing down at height 1: x cross z = -y.
        QuadLight::new(Vec3::new(-0.5, 1.0, -0.5), Vec3::X, Vec3::Z, emission).unwrap()
    }

    #[test]
    fn sample_pdf_matches_pdf_li() {
        let l = light();
        let ctx = LightSampleContext::at(Vec3::new(0.2, 0.0, 0.1));
        let mut rng = Pcg32::new(1, 2);
        for _ in 0..1000 {
            let s = l
                .sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            let pdf = l.pdf_li(&ctx, s.wi);
            assert!((s.pdf - pdf).abs() < 1e-3 * pdf, "{} vs {pdf}", s.pdf);
        }
    }

    #[test]
    fn solid_angle_estimate_matches_irradiance() {
        // E = integral L cos dw over the quad; estimate with light samples
        // and compare with a fine midpoint sum over the quad's area.
        let l = light();
        let p = Vec3::new(0.2, 0.0, 0.1);
        let ctx = LightSampleContext::at(p);
        let mut rng = Pcg32::new(5, 6);
        let n = 200_000;
        let mut est = 0.0f64;
        for _ in 0..n {
            let s = l
                .sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            est += (s.l.r * s.wi.y / s.pdf) as f64;
        }
        est /= n as f64;
        let m = 400;
        let mut exact = 0.0f64;
        for i in 0..m {
            for j in 0..m {
                let q = Vec3::new(
                    -0.5 + (j as f32 + 0.5) / m as f32,
                    1.0,
                    -0.5 + (i as f32 + 0.5) / m as f32,
                );
                let d = q - p;
                let r2 = d.length_squared() as f64;
                let cos_p = (d.y as f64) / r2.sqrt();
                exact += 2.0 * cos_p * cos_p / r2 / (m * m) as f64;
            }
        }
        assert!((est - exact).abs() < 3e-3 * exact, "{est} vs {exact}");
    }

    #[test]
    fn far_and_tiny_stays_consistent() {
        // 1e4 units below a unit quad: the solid angle is ~1e-8 sr, far too
        // small for a chi-square histogram; sample_li and pdf_li must still
        // agree and stay finite.
        let l = light();
        let ctx = LightSampleContext::at(Vec3::new(0.1, -1e4, 0.2));
        let mut rng = Pcg32::new(7, 8);
        for _ in 0..1000 {
            let s = l
                .sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32()))
                .unwrap();
            let pdf = l.pdf_li(&ctx, s.wi);
            assert!(s.pdf.is_finite() && s.pdf > 1e7, "{}", s.pdf);
            assert!((s.pdf - pdf).abs() < 1e-2 * pdf, "{} vs {pdf}", s.pdf);
        }
    }

    #[test]
    fn back_side_does_not_emit() {
        let l = light();
        let ctx = LightSampleContext::at(Vec3::new(0.0, 2.0, 0.0));
        assert!(l.sample_li(&ctx, Vec2::splat(0.5)).is_none());
        assert_eq!(l.pdf_li(&ctx, -Vec3::Y), 0.0);
        assert!(l.l(Vec3::ZERO, -Vec3::Y, Vec2::ZERO, Vec3::Y).is_black());
    }
}
