//! What every area light shares: its emission parameters, and the change of
//! measure from area to solid angle.

use lumis_core::interaction::LightSampleContext;
use lumis_core::ray::SurfacePoint;
use lumis_core::{
    Light, LightKind, LightSample, ParamSpec, ParamType, Params, Result, Rgb, Vec2, Vec3,
};

/// The keys of a shape's `emission = { ... }` table.
pub const EMISSION_PARAMS: &[ParamSpec] = &[
    ParamSpec::required("radiance", ParamType::Rgb, "emitted radiance in linear RGB"),
    ParamSpec::with_default(
        "two_sided",
        ParamType::Bool,
        "false",
        "emit from the back side too",
    ),
];

/// Constant radiance leaving a surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Emission {
    pub radiance: Rgb,
    pub two_sided: bool,
}

impl Emission {
    pub fn from_params(params: &Params) -> Result<Self> {
        let radiance: Rgb = params.get("radiance")?;
        if !(radiance.min_component() >= 0.0 && radiance.is_finite()) {
            return Err(params.error(
                "radiance",
                format!("must be finite and non-negative, got {radiance:?}"),
            ));
        }
        Ok(Self {
            radiance,
            two_sided: params.get("two_sided")?,
        })
    }

    /// Radiance leaving the surface with normal `n` in direction `w`.
    #[inline]
    pub fn radiance_toward(&self, n: Vec3, w: Vec3) -> Rgb {
        if self.two_sided || n.dot(w) > 0.0 {
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
    let dist2 = to_light.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let wi = to_light / dist2.sqrt();
    let l = emission.radiance_toward(point.n, -wi);
    if l.is_black() {
        return None;
    }
    let cos_light = point.n.dot(-wi).abs();
    let pdf = dist2 / (cos_light * area);
    if !pdf.is_finite() || pdf <= 0.0 {
        return None;
    }
    Some(LightSample {
        l,
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

/// A flat shape that an area light can be attached to.
pub trait PlanarShape: Send + Sync {
    fn area(&self) -> f32;

    /// Unit normal on the emitting (front) side.
    fn normal(&self) -> Vec3;

    /// A point distributed uniformly by area, with its error bound.
    fn sample_point(&self, u: Vec2) -> SurfacePoint;

    /// The `t > 0` at which `o + t w` (unit `w`) crosses the shape.
    fn intersect(&self, o: Vec3, w: Vec3) -> Option<f32>;
}

/// Constant emission from a planar shape, sampled uniformly by area
/// (pbrt-v4 `DiffuseAreaLight` without textures).
#[derive(Debug, Clone)]
pub struct AreaLight<S> {
    pub(crate) shape: S,
    pub(crate) emission: Emission,
}

impl<S: PlanarShape> Light for AreaLight<S> {
    fn kind(&self) -> LightKind {
        LightKind::Area
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        area_sample(
            ctx,
            self.shape.sample_point(u),
            self.shape.area(),
            &self.emission,
        )
    }

    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let wi = wi.normalize();
        match self.shape.intersect(ctx.p(), wi) {
            Some(t) => area_pdf(
                t,
                wi,
                self.shape.normal(),
                self.shape.area(),
                &self.emission,
            ),
            None => 0.0,
        }
    }

    fn l(&self, _p: Vec3, n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        self.emission.radiance_toward(n, w)
    }

    fn power(&self) -> Rgb {
        self.emission.power(self.shape.area())
    }
}
