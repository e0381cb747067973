//! `sphere`: an emissive sphere. From outside it samples the cone of
//! directions the sphere subtends, uniformly in solid angle; from inside (or
//! on it) it samples the surface uniformly by area (pbrt-v4 `Sphere::Sample`,
//! section 6.2.4; Shirley, Wang and Zimmerman 1996, "Monte Carlo Techniques
//! for Direct Lighting Calculations", section 3.2).

use std::f32::consts::PI;

use lumis_core::math::gamma;
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Error, Frame, Light, LightKind, LightSample, LightSampleContext, LightShape, ParamSpec, Params,
    PluginKind, PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

use crate::area::{sampling_param, Emission, Sampling, RADIANCE, TWO_SIDED};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "sphere",
    doc: "emission of a sphere shape: uniform cone sampling from outside, uniform area sampling from inside or on it",
    params: &[RADIANCE, TWO_SIDED, SAMPLING],
};

const SAMPLING: ParamSpec = sampling_param("\"solid-angle\"");

/// A shading point closer to the centre than `r (1 + ON_SURFACE / 2)` counts
/// as on the sphere and samples by area: the cone there is a hemisphere and
/// the silhouette construction degenerates. Hits on the sphere are
/// reprojected onto it to a few ulps, far inside this band.
const ON_SURFACE: f32 = 1e-4;

/// Constant emission from a sphere.
#[derive(Debug, Clone)]
pub struct SphereLight {
    center: Vec3,
    radius: f32,
    /// Emission leaves through the inner side (`flip_normals`).
    inward: bool,
    emission: Emission,
    sampling: Sampling,
}

impl SphereLight {
    pub fn new(center: Vec3, radius: f32, inward: bool, emission: Emission) -> Result<Self> {
        if !(radius > 0.0 && radius.is_finite() && center.is_finite()) {
            return Err(Error::msg(format!(
                "sphere light: the radius must be positive and finite, got {radius}"
            )));
        }
        Ok(Self {
            center,
            radius,
            inward,
            emission,
            sampling: Sampling::SolidAngle,
        })
    }

    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        let emission = Emission::from_params(params)?;
        let sampling = Sampling::from_params(params)?;
        match *shape {
            LightShape::Sphere {
                center,
                radius,
                inward,
            } => Ok(Self::new(center, radius, inward, emission)?.with_sampling(sampling)),
            _ => Err(Error::msg(format!(
                "{}: the sphere light is the emission of a sphere shape; use [[shape]] type = \"sphere\" with emission = {{ ... }}",
                params.owner()
            ))),
        }
    }

    /// Whether `p` is inside the sphere or on it (within [`ON_SURFACE`]).
    #[inline]
    fn inside_or_on(&self, p: Vec3) -> bool {
        (p - self.center).length_squared() <= self.radius * self.radius * (1.0 + ON_SURFACE)
    }

    /// Whether `sample_li` from `p` samples the cone (else the area).
    pub fn samples_cone_from(&self, p: Vec3) -> bool {
        self.sampling == Sampling::SolidAngle && !self.inside_or_on(p)
    }

    /// The surface point in direction `n_out` from the centre, with the error
    /// bound of pbrt-v4's reprojection (section 6.8.5).
    #[inline]
    fn surface_point(&self, n_out: Vec3) -> SurfacePoint {
        let local = n_out * self.radius;
        SurfacePoint {
            p: self.center + local,
            p_error: gamma(5) * local.abs() + gamma(1) * self.center.abs(),
            n: if self.inward { -n_out } else { n_out },
        }
    }

    /// `h_max = 1 - cos theta_max` of the cone subtended from distance `d`,
    /// from `sin^2 theta_max = (r/d)^2` by the half-angle form (no
    /// `1 - cos` cancellation for tiny, far spheres).
    #[inline]
    fn cone(&self, d: f32) -> (f32, f32) {
        let sin_max = (self.radius / d).min(1.0);
        (sin_max, warp::one_minus_cos_from_sin2(sin_max * sin_max))
    }

    fn sample_cone(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let to_center = self.center - ctx.p();
        let d = to_center.length();
        let wc = to_center / d;
        let (sin_max, h_max) = self.cone(d);
        let local = warp::square_to_uniform_cone(u, h_max);
        let frame = Frame::from_z(wc);
        let wi = frame.to_world(local).normalize();
        // The point on the sphere seen along wi (pbrt-v4 eq. 6.13 and the
        // law of sines): with s = sin theta / sin theta_max = d sin theta / r
        // the angle at the centre is alpha = asin(s) - theta, so
        // cos alpha = s sin theta + cos theta sqrt(1 - s^2) and
        // sin alpha = s cos theta - sqrt(1 - s^2) sin theta. Building the
        // point from the centre keeps its error at the scale of r, not d.
        let cos_theta = local.z;
        let sin_theta = (local.x * local.x + local.y * local.y).sqrt();
        let s = (sin_theta / sin_max).min(1.0);
        let c = (1.0 - s * s).max(0.0).sqrt();
        let cos_alpha = s * sin_theta + cos_theta * c;
        let sin_alpha = (s * cos_theta - c * sin_theta).max(0.0);
        let azimuth = if sin_theta > 0.0 {
            Vec2::new(local.x, local.y) / sin_theta
        } else {
            Vec2::X
        };
        let n_out = frame
            .to_world(Vec3::new(
                sin_alpha * azimuth.x,
                sin_alpha * azimuth.y,
                -cos_alpha,
            ))
            .normalize();
        let point = self.surface_point(n_out);
        let l = self.emission.radiance_toward(point.n, -wi);
        let pdf = warp::uniform_cone_pdf(h_max);
        if l.is_black() || !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        Some(LightSample {
            l,
            wi,
            pdf,
            p: point,
        })
    }

    /// `d^2 - r^2` for the point `p`, as `(d - r)(d + r)`: the power of
    /// the point, negative inside. Exact enough at the surface, where the
    /// chord formulas below need it.
    #[inline]
    fn power_of(&self, p: Vec3) -> (f32, Vec3, f32) {
        let to_center = self.center - p;
        let d = to_center.length();
        ((d - self.radius) * (d + self.radius), to_center, d)
    }

    fn sample_area(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let n_out = warp::square_to_uniform_sphere(u);
        let point = self.surface_point(n_out);
        let to_light = point.p - ctx.p();
        let dist2 = to_light.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let dist = dist2.sqrt();
        let wi = to_light / dist;
        // The cosine at q, n_out . (q - p) / |q - p|, from quantities that
        // keep their precision: n_out . (q - p) = r - n_out . (p - c), whose
        // terms are exact to the scale of |p - c| (not of |q|, which may be
        // 1e8 times the radius); and, on the sphere's own surface where that
        // cancels for short chords, the law of cosines
        // n_out . (q - p) = (|q - p|^2 - (d^2 - r^2)) / (2 r).
        // Positive: q faces away from p.
        let inside = self.inside_or_on(ctx.p());
        let k = if inside {
            let (c0, _, _) = self.power_of(ctx.p());
            (dist2 - c0) / (2.0 * self.radius)
        } else {
            self.radius - n_out.dot(ctx.p() - self.center)
        };
        // From outside, only the cap facing the point is seen first; the far
        // side is hidden behind it (its direction belongs to the near point).
        if !inside && k >= 0.0 {
            return None;
        }
        let l = self.emission.radiance_toward(point.n, -wi);
        let cos_light = k.abs() / dist;
        let pdf = dist2 / (cos_light * self.area());
        if l.is_black() || !(pdf.is_finite() && pdf > 0.0) {
            return None;
        }
        Some(LightSample {
            l,
            wi,
            pdf,
            p: point,
        })
    }

    fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }
}

impl Light for SphereLight {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        if self.samples_cone_from(ctx.p()) {
            self.sample_cone(ctx, u)
        } else {
            self.sample_area(ctx, u)
        }
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let Some(wi) = wi.try_normalize() else {
            return 0.0;
        };
        let p = ctx.p();
        let (_, to_center, d) = self.power_of(p);
        let inside = self.inside_or_on(p);
        if !inside && self.sampling == Sampling::SolidAngle {
            // Uniform over the cone: is wi inside it? 1 - cos of the angle to
            // the axis is |wi - wc|^2 / 2, exact for tiny angles.
            let (_, h_max) = self.cone(d);
            let h = 0.5 * (wi - to_center / d).length_squared();
            // From outside only the outer side is seen.
            let seen_side_emits = self.emission.two_sided || !self.inward;
            // The slack admits directions sample_li produced at the rim,
            // whose h was rounded on the way through the frame.
            if h > h_max * (1.0 + 1e-3) || !seen_side_emits {
                return 0.0;
            }
            let pdf = warp::uniform_cone_pdf(h_max);
            return if pdf.is_finite() { pdf } else { 0.0 };
        }
        // Area sampling: where does the ray p + t wi cross the sphere?
        // t^2 - 2 b t + c0 = 0 with b = wi . (c - p), c0 = d^2 - r^2. From
        // outside the discriminant comes from the perpendicular distance
        // (pbrt-v4 section 6.8.4), which keeps it accurate at the
        // silhouette; from inside (or on the sphere) b^2 - c0 has no
        // cancellation since c0 <= 0 (up to rounding).
        let (c0, _, _) = self.power_of(p);
        let b = wi.dot(to_center);
        let disc = if inside {
            b * b - c0
        } else {
            let perp = (to_center - wi * b).length();
            (self.radius - perp) * (self.radius + perp)
        };
        if disc < 0.0 {
            return 0.0;
        }
        let q = disc.sqrt();
        // Each root in the form without cancellation (the product of the
        // roots is c0): far root from inside, near root from outside.
        let t = if inside {
            if b >= 0.0 {
                b + q
            } else {
                c0 / (b - q)
            }
        } else if b > 0.0 {
            c0 / (b + q)
        } else {
            return 0.0;
        };
        if t.is_nan() || t <= 0.0 {
            return 0.0;
        }
        // From inside the ray leaves through the inner side, from outside it
        // meets the outer side; |cos| at the hit is q / r either way.
        let seen_side_emits = self.emission.two_sided || (inside == self.inward);
        if !seen_side_emits {
            return 0.0;
        }
        let cos_light = q / self.radius;
        let pdf = t * t / (cos_light * self.area());
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }

    fn l(&self, _p: Vec3, n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        self.emission.radiance_toward(n, w)
    }

    fn power(&self) -> Rgb {
        self.emission.power(self.area())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    #[test]
    fn sample_pdf_matches_pdf_li_in_every_mode() {
        let emission = Emission {
            radiance: Rgb::WHITE,
            two_sided: false,
        };
        let c = Vec3::new(0.0, 1.0, 0.0);
        for (sampling, inward, p) in [
            (Sampling::Area, false, Vec3::new(0.2, 0.5, 0.1)),
            (Sampling::SolidAngle, false, Vec3::new(0.2, 0.5, 0.1)),
            (Sampling::SolidAngle, true, Vec3::new(0.1, 1.1, 0.0)),
        ] {
            let l = SphereLight::new(c, 0.3, inward, emission)
                .unwrap()
                .with_sampling(sampling);
            let ctx = LightSampleContext::at(p);
            let mut rng = Pcg32::new(3, 4);
            let mut valid = 0;
            for _ in 0..1000 {
                let Some(s) = l.sample_li(&ctx, Vec2::new(rng.next_f32(), rng.next_f32())) else {
                    continue;
                };
                valid += 1;
                // Area sampling at the silhouette: pdf ~ 1/cos, whose value
                // is only as good as the grazing cosine (skip cos < ~1e-2).
                if s.pdf > 10.0 {
                    continue;
                }
                let pdf = l.pdf_li(&ctx, s.wi);
                assert!(
                    (s.pdf - pdf).abs() < 1e-3 * pdf,
                    "{sampling:?} {inward}: {} vs {pdf}",
                    s.pdf
                );
                assert!(((s.p.p - c).length() - 0.3).abs() < 1e-5);
            }
            assert!(valid > 100, "{sampling:?}: {valid}");
        }
    }
}
