//! `sphere`: an emissive sphere, sampled by the cone it subtends from
//! outside and by area from inside.
//!
//! With `sampling = "solid-angle"`, a point outside the sphere samples the
//! cone of directions the sphere subtends, uniformly in solid angle, with
//! `1 - cos theta_max` from the half-angle form `sin^2 / (1 + cos)`, exact
//! for a sphere of radius 1e-4 at a distance of 1e4; a point inside (or on)
//! it samples the surface uniformly by area (pbrt-v4 `Sphere::Sample`,
//! section 6.2.4; Shirley, Wang and Zimmerman 1996, "Monte Carlo Techniques
//! for Direct Lighting Calculations", section 3.2). `"area"` samples the
//! surface by area everywhere; from outside, a point on the far side, hidden
//! behind the near one, gives no sample.

use std::f32::consts::PI;

use lumis_api::lanes::{LaneMask, Vec2Lanes, LANES};
use lumis_api::light::{
    sample_li_each, sample_li_lanes_by_batch, EmissionSample, LightSampleLanes,
};

use crate::emission::diffuse_emission;
use lumis_api::math::gamma;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Aabb, Error, Light, LightBounds, LightKind, LightSample, LightSampleContext, LightShape,
    Params, PluginKind, PluginParams, PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::real::{load, F32x8, Real, V3};
use lumis_sampling::simd;
use lumis_sampling::warp;

use crate::area::{Emission, EmissionParams, Sampling};

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "sphere",
    source: lumis_api::source_file!(),
    doc: "emission of a sphere shape: uniform cone sampling from outside, uniform area sampling from inside or on it",
    params: SphereLightParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct SphereLightParams {
    /// A sphere is sampled by solid angle unless asked otherwise.
    #[param(flatten, default(sampling = Sampling::SolidAngle))]
    pub emission: EmissionParams,
}

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
        let p = SphereLightParams::read(params)?.emission;
        if p.texture().is_some() {
            return Err(params.error(
                EmissionParams::KEYS.radiance,
                "a sphere light's radiance is a colour: textured radiance is for quads and triangles",
            ));
        }
        let emission = Emission::from_params(&p, params)?;
        let sampling = p.sampling;
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
        let (wi, n_out, pdf) = self.sample_cone_lanes(V3::from(ctx.p()), [u.x, u.y]);
        self.cone_sample(wi.into(), n_out.into(), pdf)
    }

    /// `(wi, n_out, pdf)` of the cone sample from `p` (outside the sphere)
    /// for `u`: the direction, the outward normal of the point it sees,
    /// the density; for one point or a point per lane.
    #[inline(always)]
    fn sample_cone_lanes<F: Real>(&self, p: V3<F>, u: [F; 2]) -> (V3<F>, V3<F>, F) {
        let k = F::splat;
        let to_center = V3::splat(self.center) - p;
        let d = to_center.length();
        let wc = to_center / d;
        // `self.cone(d)`.
        let sin_max = (k(self.radius) / d).min(k(1.0));
        let h_max = warp::one_minus_cos_from_sin2(sin_max * sin_max);
        let local = warp::square_to_uniform_cone_lanes(u, h_max);
        let frame = FrameLanes::from_z(wc);
        let wi = frame.to_world(local).normalize();
        // The point on the sphere seen along wi (pbrt-v4 eq. 6.13 and the
        // law of sines): with s = sin theta / sin theta_max = d sin theta / r
        // the angle at the centre is alpha = asin(s) - theta, so
        // cos alpha = s sin theta + cos theta sqrt(1 - s^2) and
        // sin alpha = s cos theta - sqrt(1 - s^2) sin theta. Building the
        // point from the centre keeps its error at the scale of r, not d.
        let cos_theta = local.z;
        let sin_theta = (local.x * local.x + local.y * local.y).sqrt();
        let s = (sin_theta / sin_max).min(k(1.0));
        let c = (k(1.0) - s * s).max(k(0.0)).sqrt();
        let cos_alpha = s * sin_theta + cos_theta * c;
        let sin_alpha = (s * cos_theta - c * sin_theta).max(k(0.0));
        let tilted = sin_theta.gt(k(0.0));
        let azimuth_x = F::select(tilted, local.x / sin_theta, k(1.0));
        let azimuth_y = F::select(tilted, local.y / sin_theta, k(0.0));
        let n_out = frame
            .to_world(V3::new(
                sin_alpha * azimuth_x,
                sin_alpha * azimuth_y,
                -cos_alpha,
            ))
            .normalize();
        let pdf = warp::uniform_cone_pdf(h_max);
        (wi, n_out, pdf)
    }

    /// The light sample along `wi` of the point with outward normal
    /// `n_out`; `None` where nothing is emitted toward the reference point
    /// or the density is not positive and finite.
    #[inline]
    fn cone_sample(&self, wi: Vec3, n_out: Vec3, pdf: f32) -> Option<LightSample> {
        let point = self.surface_point(n_out);
        let l = self.emission.radiance_toward(point.n, -wi);
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

    /// A packet's lanes through the SIMD [`Light::sample_li_batch`].
    fn sample_li_lanes(
        &self,
        ctx: &[LightSampleContext; LANES],
        u: &Vec2Lanes,
        active: LaneMask,
        out: &mut LightSampleLanes,
    ) {
        sample_li_lanes_by_batch(self, ctx, u, active, out)
    }

    /// [`Light::sample_li`] eight lanes at a time for the cone sampling
    /// from outside (`SphereLight::sample_cone_lanes` on SIMD lanes, the
    /// scalar's own formulas), bit for bit its answer; lanes inside or on
    /// the sphere, and area sampling, call `sample_li`.
    fn sample_li_batch(
        &self,
        ctx: &[LightSampleContext],
        u: &[Vec2],
        out: &mut [Option<LightSample>],
    ) {
        if self.sampling != Sampling::SolidAngle {
            return sample_li_each(self, ctx, u, out);
        }
        // Padding lanes look from a point outside.
        let pad = LightSampleContext::at(self.center + Vec3::X * (4.0 * self.radius));
        let width = Lanes::LANES;
        simd::dispatch(|| {
            for ((ctx, u), out) in ctx
                .chunks(width)
                .zip(u.chunks(width))
                .zip(out.chunks_mut(width))
            {
                let mut cone = 0u32;
                for (i, c) in ctx.iter().enumerate() {
                    cone |= (self.samples_cone_from(c.p()) as u32) << i;
                }
                if cone == 0 {
                    sample_li_each(self, ctx, u, out);
                    continue;
                }
                let p = V3::<Lanes>::new(
                    load(ctx, pad, |c| c.p().x),
                    load(ctx, pad, |c| c.p().y),
                    load(ctx, pad, |c| c.p().z),
                );
                let u_lanes = [load(u, Vec2::ZERO, |u| u.x), load(u, Vec2::ZERO, |u| u.y)];
                let (wi, n_out, pdf) = self.sample_cone_lanes(p, u_lanes);
                let pdf = pdf.to_array();
                for (i, out) in out.iter_mut().enumerate() {
                    *out = if cone >> i & 1 != 0 {
                        self.cone_sample(wi.lane(i), n_out.lane(i), pdf[i])
                    } else {
                        self.sample_area(&ctx[i], u[i])
                    };
                }
            }
        })
    }

    /// A point uniform by area, emitting cosine-distributed about its
    /// normal (inward for an inward sphere).
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        diffuse_emission(
            self.surface_point(warp::square_to_uniform_sphere(u_pos)),
            1.0 / self.area(),
            self.emission.radiance,
            self.emission.two_sided,
            u_dir,
        )
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

    /// Normals in every direction, each emitting over its hemisphere.
    fn bounds(&self) -> Option<LightBounds> {
        let r = Vec3::splat(self.radius);
        Some(LightBounds {
            bounds: Aabb::of_points([self.center - r, self.center + r]),
            w: Vec3::Z,
            phi: self.power().luminance(),
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: self.emission.two_sided,
        })
    }
}

/// The SIMD lanes of `sample_li_batch` (eight, as the conductor's).
type Lanes = F32x8;

/// `lumis_api::Frame` restated over lanes (a test holds it to its bits):
/// the orthonormal basis around a unit `z` of Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited".
struct FrameLanes<F> {
    x: V3<F>,
    y: V3<F>,
    z: V3<F>,
}

impl<F: Real> FrameLanes<F> {
    #[inline(always)]
    fn from_z(n: V3<F>) -> Self {
        let one = F::splat(1.0);
        let sign = one.copysign(n.z);
        let a = -one / (sign + n.z);
        let b = n.x * n.y * a;
        let x = V3::new(one + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = V3::new(b, sign + n.y * n.y * a, -n.y);
        Self { x, y, z: n }
    }

    #[inline(always)]
    fn to_world(&self, v: V3<F>) -> V3<F> {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_api::Frame;
    use lumis_sampling::Pcg32;

    /// The lane restatement of the frame gives its bits.
    #[test]
    fn restated_frame_is_the_original_bit_for_bit() {
        let mut rng = Pcg32::new(17, 3);
        for _ in 0..100_000 {
            let u = Vec2::new(rng.next_f32(), rng.next_f32());
            let n = warp::square_to_uniform_sphere(u);
            let (frame, lanes) = (Frame::from_z(n), FrameLanes::from_z(V3::from(n)));
            let v = Vec3::new(rng.next_f32() - 0.5, rng.next_f32(), -rng.next_f32());
            assert_eq!(
                Vec3::from(lanes.to_world(V3::from(v))),
                frame.to_world(v),
                "n {n:?}"
            );
        }
    }

    /// `sample_li_batch` gives `sample_li`'s answer bit for bit, `None`
    /// exactly where it is `None`: from points just outside the area
    /// sampling band to 1e4 radii away, inside and on the sphere, for
    /// lights that emit outward, inward (nothing seen from outside) and
    /// both ways, with random numbers including 0 and the largest below 1,
    /// in batches that do and do not fill the last chunk.
    #[test]
    fn sample_li_batch_is_sample_li_bit_for_bit() {
        let center = Vec3::new(0.5, -1.0, 2.0);
        let radius = 0.3;
        let mut rng = Pcg32::new(8, 1);
        let mut ctx = Vec::new();
        let mut u = Vec::new();
        for (k, distance) in [1.0002f32, 1.01, 2.0, 10.0, 1e4, 0.5, 1.0, 0.0]
            .into_iter()
            .cycle()
            .take(96)
            .enumerate()
        {
            let dir = warp::square_to_uniform_sphere(Vec2::new(rng.next_f32(), rng.next_f32()));
            ctx.push(LightSampleContext::at(center + dir * (radius * distance)));
            u.push(match k % 11 {
                0 => Vec2::ZERO,
                1 => Vec2::splat(1.0 - f32::EPSILON / 2.0),
                _ => Vec2::new(rng.next_f32(), rng.next_f32()),
            });
        }
        let n = ctx.len();
        let bits = |s: Option<LightSample>| {
            s.map(|s| {
                [
                    s.l.r,
                    s.l.g,
                    s.l.b,
                    s.wi.x,
                    s.wi.y,
                    s.wi.z,
                    s.pdf,
                    s.p.p.x,
                    s.p.p.y,
                    s.p.p.z,
                    s.p.p_error.x,
                    s.p.p_error.y,
                    s.p.p_error.z,
                    s.p.n.x,
                    s.p.n.y,
                    s.p.n.z,
                ]
                .map(f32::to_bits)
            })
        };
        for (inward, two_sided) in [(false, false), (true, false), (false, true)] {
            for sampling in [Sampling::SolidAngle, Sampling::Area] {
                let emission = Emission {
                    radiance: Rgb::new(1.0, 2.0, 3.0),
                    two_sided,
                };
                let light = SphereLight::new(center, radius, inward, emission)
                    .unwrap()
                    .with_sampling(sampling);
                let mut some = 0;
                for len in [0, 1, 7, 9, 33, n] {
                    let mut out = vec![None; len];
                    light.sample_li_batch(&ctx[..len], &u[..len], &mut out);
                    for i in 0..len {
                        let scalar = light.sample_li(&ctx[i], u[i]);
                        some += scalar.is_some() as usize;
                        assert_eq!(
                            bits(out[i]),
                            bits(scalar),
                            "{sampling:?} inward {inward} two-sided {two_sided}: lane {i} of {len}, p {:?}, u {:?}",
                            ctx[i].p(),
                            u[i]
                        );
                    }
                }
                assert!(
                    some > 0,
                    "{sampling:?} {inward} {two_sided}: nothing compared"
                );
            }
        }
    }

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
