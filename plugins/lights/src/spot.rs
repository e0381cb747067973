//! `spot`: a point light emitting in a cone with a smooth falloff (a delta
//! distribution in position; pbrt-v4 `SpotLight`, section 12.2.1).
//!
//! The intensity is full inside `falloff_start` and falls with a smoothstep
//! in `cos theta` to zero at `cutoff`. Being a delta in position, the light
//! is never hit by a ray, so its samples take MIS weight 1.

use lumis_api::interaction::LightSampleContext;
use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use lumis_api::Frame;
use lumis_api::{
    Aabb, Error, Light, LightBounds, LightKind, LightSample, LightShape, Params, PluginKind,
    PluginParams, PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "spot",
    source: lumis_api::source_file!(),
    doc: "point light emitting into a cone, full intensity inside falloff_start, smoothstep to zero at cutoff; never hit by rays (MIS weight 1)",
    params: SpotLightParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct SpotLightParams {
    /// world-space position
    pub position: Vec3,
    /// a point on the cone's axis
    pub target: Vec3,
    /// radiant intensity I (W/sr) on the axis
    pub intensity: Rgb,
    /// half-angle of the cone in degrees, beyond which nothing is emitted
    #[param(default = 30.0, range = (0.0, 90.0))]
    pub cutoff: f32,
    /// half-angle in degrees up to which the intensity is full; <= cutoff
    #[param(default = 25.0, range = (0.0, 90.0))]
    pub falloff_start: f32,
}

#[derive(Debug, Clone)]
pub struct SpotLight {
    position: Vec3,
    axis: Vec3,
    intensity: Rgb,
    cos_falloff_start: f32,
    cos_falloff_end: f32,
}

impl SpotLight {
    /// Angles are half-angles in degrees.
    pub fn new(
        position: Vec3,
        target: Vec3,
        intensity: Rgb,
        cutoff: f32,
        falloff_start: f32,
    ) -> Result<Self> {
        let axis = (target - position)
            .try_normalize()
            .ok_or_else(|| Error::msg("spot light: target must differ from position"))?;
        if !(0.0..=cutoff).contains(&falloff_start) || !(0.0..=90.0).contains(&cutoff) {
            return Err(Error::msg(format!(
                "spot light: need 0 <= falloff_start ({falloff_start}) <= cutoff ({cutoff}) <= 90"
            )));
        }
        Ok(Self {
            position,
            axis,
            intensity,
            cos_falloff_start: falloff_start.to_radians().cos(),
            cos_falloff_end: cutoff.to_radians().cos(),
        })
    }

    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        if *shape != LightShape::None {
            return Err(Error::msg(format!(
                "{}: a spot light is declared in [[light]], not as a shape's emission",
                params.owner()
            )));
        }
        let p = SpotLightParams::read(params)?;
        let keys = SpotLightParams::KEYS;
        if !(p.intensity.min_component() >= 0.0 && p.intensity.is_finite()) {
            return Err(params.error(keys.intensity, "must be finite and non-negative"));
        }
        if p.falloff_start > p.cutoff {
            return Err(params.error(
                keys.falloff_start,
                format!("must not exceed cutoff ({})", p.cutoff),
            ));
        }
        Self::new(p.position, p.target, p.intensity, p.cutoff, p.falloff_start)
    }

    /// The falloff at `cos_theta` from the axis: 1 inside the inner cone, 0
    /// outside the outer one, and the C1 smoothstep `3t^2 - 2t^3` in cos
    /// theta between (pbrt-v4 `SpotLight::I`).
    #[inline]
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        let (a, b) = (self.cos_falloff_end, self.cos_falloff_start);
        if cos_theta >= b {
            return 1.0;
        }
        if cos_theta <= a {
            return 0.0;
        }
        let t = (cos_theta - a) / (b - a);
        t * t * (3.0 - 2.0 * t)
    }
}

impl Light for SpotLight {
    fn kind(&self) -> LightKind {
        LightKind::DeltaPosition
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        let to_light = self.position - ctx.p();
        let dist2 = to_light.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let wi = to_light / dist2.sqrt();
        let i = self.intensity * self.falloff(self.axis.dot(-wi));
        if i.is_black() {
            return None;
        }
        Some(LightSample {
            l: i / dist2,
            wi,
            pdf: 1.0,
            p: SurfacePoint::isolated(self.position),
        })
    }

    /// A direction uniform in the cone of the cutoff angle (pbrt-v4
    /// `SpotLight::SampleLe`), its intensity the falloff's.
    fn sample_le(&self, _u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let h_max = 1.0 - self.cos_falloff_end;
        let local = warp::square_to_uniform_cone(u_dir, h_max);
        let l = self.intensity * self.falloff(local.z);
        (!l.is_black()).then(|| EmissionSample {
            p: SurfacePoint::isolated(self.position),
            d: Frame::from_z(self.axis).to_world(local),
            l,
            pdf_pos: 1.0,
            pdf_dir: warp::uniform_cone_pdf(h_max),
        })
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }

    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        Rgb::BLACK
    }

    /// `I 2 pi [(1 - cos_start) + (cos_start - cos_end) / 2]`: the integral
    /// of the falloff over the sphere; the smoothstep in cos theta averages
    /// to 1/2 (pbrt-v4 `SpotLight::Phi`).
    fn power(&self) -> Rgb {
        let (a, b) = (self.cos_falloff_end, self.cos_falloff_start);
        self.intensity * (2.0 * std::f32::consts::PI * ((1.0 - b) + 0.5 * (b - a)))
    }

    /// A point whose "normals" fill the inner cone and emit up to the
    /// falloff's width beyond it; the power is that of the intensity on
    /// the axis in every direction, as pbrt-v4's `SpotLight::Bounds`.
    fn bounds(&self) -> Option<LightBounds> {
        let (a, b) = (self.cos_falloff_end, self.cos_falloff_start);
        let mut cos_theta_e = (a.acos() - b.acos()).cos();
        // Slack for rounding in the importance's cos theta', where the
        // falloff has a width that rounds away.
        if cos_theta_e == 1.0 && a != b {
            cos_theta_e = 0.999;
        }
        Some(LightBounds {
            bounds: Aabb::point(self.position),
            w: self.axis,
            phi: self.intensity.luminance() * 4.0 * std::f32::consts::PI,
            cos_theta_o: b,
            cos_theta_e,
            two_sided: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spot() -> SpotLight {
        SpotLight::new(Vec3::Y, Vec3::ZERO, Rgb::splat(4.0), 30.0, 20.0).unwrap()
    }

    #[test]
    fn full_on_axis_dark_outside_smooth_between() {
        let l = spot();
        let on_axis = l
            .sample_li(&LightSampleContext::at(Vec3::ZERO), Vec2::ZERO)
            .unwrap();
        assert_eq!(on_axis.l, Rgb::splat(4.0));
        // 45 degrees off the axis: outside the 30 degree cutoff.
        assert!(l
            .sample_li(
                &LightSampleContext::at(Vec3::new(1.0, 0.0, 0.0)),
                Vec2::ZERO
            )
            .is_none());
        let mut last = 1.0;
        for deg in 20..=30 {
            let f = l.falloff((deg as f32).to_radians().cos());
            assert!(f <= last && (0.0..=1.0).contains(&f), "{deg}: {f}");
            last = f;
        }
        assert_eq!(l.falloff(30f32.to_radians().cos() - 1e-6), 0.0);
    }

    #[test]
    fn power_is_the_integral_of_the_intensity() {
        // Midpoint rule over cos theta: Phi = 2 pi int I(cos) dcos.
        let l = spot();
        let n = 200_000;
        let sum: f64 = (0..n)
            .map(|i| l.falloff(-1.0 + 2.0 * (i as f32 + 0.5) / n as f32) as f64)
            .sum::<f64>()
            * 2.0
            / n as f64;
        let expected = 4.0 * 2.0 * std::f64::consts::PI * sum;
        assert!(((l.power().r as f64) / expected - 1.0).abs() < 1e-3);
    }

    #[test]
    fn falloff_start_beyond_cutoff_is_refused() {
        assert!(SpotLight::new(Vec3::Y, Vec3::ZERO, Rgb::WHITE, 10.0, 20.0).is_err());
        assert!(SpotLight::new(Vec3::Y, Vec3::Y, Rgb::WHITE, 10.0, 5.0).is_err());
    }
}
