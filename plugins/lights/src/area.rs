//! What every area light shares: its emission parameters, and the change of
//! measure from area to solid angle.

use lumis_api::interaction::LightSampleContext;
use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use std::sync::Arc;

use crate::emission::diffuse_emission;

use lumis_api::params::Textured;
use lumis_api::{
    Aabb, Light, LightBounds, LightKind, LightSample, ParamChoice, Params, PluginParams, Result,
    Rgb, Texture, TexturedRgb, Vec2, Vec3,
};

/// The keys of every `emission = { ... }` table.
#[derive(Debug, Clone, PluginParams)]
pub struct EmissionParams {
    /// emitted radiance in linear RGB, or a texture of it over the
    /// surface's uv (quads and triangles)
    pub radiance: TexturedRgb,
    /// emit from the back side too
    #[param(default = false)]
    pub two_sided: bool,
    /// "solid-angle": uniform over the solid angle the shape subtends (area
    /// sampling where that is unstable), "area": uniform over the surface,
    /// converted to solid angle
    // Quads and triangles default to "area" so that scenes written before
    // the switch existed render bit-identically; spheres default to
    // "solid-angle".
    #[param(default = Area)]
    pub sampling: Sampling,
}

/// How an area light chooses points for next-event estimation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Sampling {
    /// Uniform over the solid angle subtended from the shading point:
    /// density `1 / Omega`, no `1/d^2` or `1/cos` spikes.
    SolidAngle,
    /// Uniform by area; the density in solid angle is `d^2 / (|cos| A)`,
    /// which peaks at grazing angles and near the light.
    Area,
}

/// Constant radiance leaving a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emission {
    pub radiance: Rgb,
    pub two_sided: bool,
}

impl Emission {
    /// The emission `p` describes, its radiance checked; a textured
    /// radiance is white here, and [`EmissionParams::texture`] scales it.
    pub fn from_params(p: &EmissionParams, params: &Params) -> Result<Self> {
        let radiance = p.radiance.constant().unwrap_or(Rgb::WHITE);
        if !(radiance.min_component() >= 0.0 && radiance.is_finite()) {
            return Err(params.error(
                EmissionParams::KEYS.radiance,
                format!("must be finite and non-negative, got {radiance}"),
            ));
        }
        Ok(Self {
            radiance,
            two_sided: p.two_sided,
        })
    }

    /// Whether a direction `w` with `n.dot(w) = n_dot_w` leaves from an
    /// emitting side (`w` need not be unit length: only its side counts).
    #[inline]
    pub fn emits_toward(&self, n_dot_w: f32) -> bool {
        self.two_sided || n_dot_w > 0.0
    }

    /// Radiance leaving the surface with normal `n` in direction `w`.
    #[inline]
    pub fn radiance_toward(&self, n: Vec3, w: Vec3) -> Rgb {
        if self.emits_toward(n.dot(w)) {
            self.radiance
        } else {
            Rgb::BLACK
        }
    }

    /// Power of a surface of area `area`: pi L A per emitting side.
    pub fn power(&self, area: f32) -> Rgb {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        self.radiance * (std::f32::consts::PI * area * sides)
    }
}

impl EmissionParams {
    /// The texture of a textured radiance.
    pub fn texture(&self) -> Option<Arc<dyn Texture>> {
        match &self.radiance {
            Textured::Constant(_) => None,
            Textured::Texture(t) => Some(t.clone()),
        }
    }
}

/// Turns a point sampled uniformly by area into a light sample, with the
/// density converted to solid angle: `pdf_w = d^2 / (|cos theta_l| A)`
/// (pbrt-v4, eq. 4.9 / section 6.1.3).
#[inline]
pub fn area_sample(
    ctx: &LightSampleContext,
    point: SurfacePoint,
    area: f32,
    emission: &Emission,
) -> Option<LightSample> {
    let to_light = point.p - ctx.p();
    // The side the point is seen from needs no normalisation, so it is
    // tested first: points behind a one-sided emitter (a sixth of the
    // Cornell box's light samples, from its ceiling) cost nothing more.
    let n_dot = point.n.dot(to_light);
    if !emission.emits_toward(-n_dot) || emission.radiance.is_black() {
        return None;
    }
    // pdf = d^2 / (|cos| A) with |cos| = |n . v| / d is d^3 / (|n . v| A):
    // the square root and the two reciprocals run side by side instead of
    // in one chain (square root, then a division, then another).
    let dist2 = to_light.length_squared();
    let dist = dist2.sqrt();
    let inv_dist2 = 1.0 / dist2;
    let inv_projected = 1.0 / (n_dot.abs() * area);
    let wi = to_light * (dist * inv_dist2);
    let pdf = dist2 * dist * inv_projected;
    // Also false for NaN (a zero distance) and infinity (grazing).
    if !(pdf > 0.0 && pdf < f32::INFINITY) {
        return None;
    }
    Some(LightSample {
        l: emission.radiance,
        wi,
        pdf,
        p: point,
    })
}

/// The solid-angle density of uniform area sampling for a ray from `ctx`
/// along `wi` that hits the surface at distance `t` where the normal is `n`;
/// zero where that side does not emit (`sample_li` never returns it).
#[inline]
pub fn area_pdf(t: f32, wi: Vec3, n: Vec3, area: f32, emission: &Emission) -> f32 {
    let cos_light = n.dot(-wi);
    if !emission.two_sided && cos_light <= 0.0 {
        return 0.0;
    }
    let pdf = t * t / (cos_light.abs() * area);
    if pdf.is_finite() {
        pdf
    } else {
        0.0
    }
}

/// Turns a point sampled uniformly over the solid angle `omega` subtended
/// from `ctx` into a light sample of density `1 / omega`.
#[inline]
pub fn solid_angle_sample(
    ctx: &LightSampleContext,
    point: SurfacePoint,
    omega: f32,
    emission: &Emission,
) -> Option<LightSample> {
    let wi = (point.p - ctx.p()).try_normalize()?;
    let l = emission.radiance_toward(point.n, -wi);
    let pdf = 1.0 / omega;
    if l.is_black() || !pdf.is_finite() || pdf <= 0.0 {
        return None;
    }
    Some(LightSample {
        l,
        wi,
        pdf,
        p: point,
    })
}

/// A flat shape that an area light can be attached to.
pub trait PlanarShape: Send + Sync {
    fn area(&self) -> f32;

    /// The box holding the shape.
    fn bounds(&self) -> Aabb;

    /// Unit normal on the emitting (front) side.
    fn normal(&self) -> Vec3;

    /// A point distributed uniformly by area, with its error bound.
    fn sample_point(&self, u: Vec2) -> SurfacePoint;

    /// The `t > 0` at which `o + t w` (unit `w`) crosses the shape.
    fn intersect(&self, o: Vec3, w: Vec3) -> Option<f32>;

    /// The texture coordinates of the point `p` on the shape: those a hit
    /// there gets.
    fn uv_at(&self, p: Vec3) -> Vec2;

    /// The solid angle (sr) the shape subtends from `p`, when it samples
    /// that solid angle uniformly from there; `None` where it falls back to
    /// area sampling. Depends on `p` only, so `sample_li` and `pdf_li` make
    /// the same choice.
    fn solid_angle(&self, _p: Vec3) -> Option<f32> {
        None
    }

    /// A point whose direction from `p` is uniform in the solid angle the
    /// shape subtends from there, with that solid angle;
    /// `SolidAngleSample::ByArea` exactly where [`PlanarShape::solid_angle`]
    /// is `None`. One call, so that the spherical geometry is set up once
    /// per sample.
    fn sample_solid_angle(&self, _p: Vec3, _u: Vec2) -> SolidAngleSample {
        SolidAngleSample::ByArea
    }
}

/// What [`PlanarShape::sample_solid_angle`] gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolidAngleSample {
    /// The shape samples by area from this point.
    ByArea,
    /// A point uniform over the solid angle `omega` (sr), or `None` where
    /// the construction degenerates (no sample: falling back to area
    /// sampling would disagree with `pdf_li`).
    Uniform {
        point: Option<SurfacePoint>,
        omega: f32,
    },
}

impl SolidAngleSample {
    /// The sample of a shape seen from a point as `spherical` (its
    /// spherical polygon and solid angle, or `None` where it samples by
    /// area), drawn by `sample`.
    #[inline]
    pub fn from_spherical<T>(
        spherical: Option<(T, f32)>,
        sample: impl FnOnce(T) -> Option<SurfacePoint>,
    ) -> Self {
        match spherical {
            Some((polygon, omega)) => SolidAngleSample::Uniform {
                point: sample(polygon),
                omega,
            },
            None => SolidAngleSample::ByArea,
        }
    }
}

/// Constant emission from a planar shape, sampled uniformly by area or by
/// solid angle (pbrt-v4 `DiffuseAreaLight` without textures).
#[derive(Debug, Clone)]
pub struct AreaLight<S> {
    pub(crate) shape: S,
    pub(crate) emission: Emission,
    pub(crate) sampling: Sampling,
}

impl<S: PlanarShape> AreaLight<S> {
    /// The same light with another sampling strategy.
    pub fn with_sampling(mut self, sampling: Sampling) -> Self {
        self.sampling = sampling;
        self
    }

    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// The solid angle used from `p`, or `None` for area sampling.
    #[inline]
    fn spherical(&self, p: Vec3) -> Option<f32> {
        match self.sampling {
            Sampling::SolidAngle => self.shape.solid_angle(p),
            Sampling::Area => None,
        }
    }

    #[inline(always)]
    fn sample_area(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        area_sample(
            ctx,
            self.shape.sample_point(u),
            self.shape.area(),
            &self.emission,
        )
    }

    /// Solid-angle sampling where the shape supports it from `ctx`, else
    /// area sampling. Out of line: its spherical geometry would otherwise
    /// give area sampling, the default, its large stack frame.
    #[inline(never)]
    fn sample_solid_angle(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        match self.shape.sample_solid_angle(ctx.p(), u) {
            SolidAngleSample::Uniform { point, omega } => {
                solid_angle_sample(ctx, point?, omega, &self.emission)
            }
            SolidAngleSample::ByArea => self.sample_area(ctx, u),
        }
    }

    /// Whether `sample_li` from `p` samples the solid angle (else area).
    pub fn samples_solid_angle_from(&self, p: Vec3) -> bool {
        self.spherical(p).is_some()
    }
}

impl<S: PlanarShape> Light for AreaLight<S> {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        match self.sampling {
            Sampling::Area => self.sample_area(ctx, u),
            Sampling::SolidAngle => self.sample_solid_angle(ctx, u),
        }
    }

    /// A point uniform by area, emitting cosine-distributed about its
    /// normal.
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        diffuse_emission(
            self.shape.sample_point(u_pos),
            1.0 / self.shape.area(),
            self.emission.radiance,
            self.emission.two_sided,
            u_dir,
        )
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let wi = wi.normalize();
        let Some(t) = self.shape.intersect(ctx.p(), wi) else {
            return 0.0;
        };
        let normal = self.shape.normal();
        match self.spherical(ctx.p()) {
            Some(omega) => {
                if !self.emission.two_sided && normal.dot(-wi) <= 0.0 {
                    return 0.0;
                }
                let pdf = 1.0 / omega;
                if pdf.is_finite() {
                    pdf
                } else {
                    0.0
                }
            }
            None => area_pdf(t, wi, normal, self.shape.area(), &self.emission),
        }
    }

    fn l(&self, _p: Vec3, n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        self.emission.radiance_toward(n, w)
    }

    fn power(&self) -> Rgb {
        self.emission.power(self.shape.area())
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(planar_bounds(&self.shape, self.power(), &self.emission))
    }
}

/// The bounds of a flat Lambertian emitter of total power `power`.
pub fn planar_bounds<S: PlanarShape>(shape: &S, power: Rgb, emission: &Emission) -> LightBounds {
    LightBounds::planar(
        shape.bounds(),
        shape.normal(),
        power.luminance(),
        emission.two_sided,
    )
}
