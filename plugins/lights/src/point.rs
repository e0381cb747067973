//! `point`: an isotropic point light (a delta distribution in position).

use lumis_api::interaction::LightSampleContext;
use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Error, Light, LightBounds, LightKind, LightSample, LightShape, Params, PluginKind,
    PluginParams, PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "point",
    source: lumis_api::source_file!(),
    doc: "isotropic point light: never hit by rays, sampled with probability 1 (MIS weight 1)",
    params: PointLightParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct PointLightParams {
    /// world-space position
    pub position: Vec3,
    /// radiant intensity I (W/sr); irradiance is I cos / d^2
    pub intensity: Rgb,
}

#[derive(Debug, Clone)]
pub struct PointLight {
    position: Vec3,
    intensity: Rgb,
}

impl PointLight {
    pub fn new(position: Vec3, intensity: Rgb) -> Self {
        Self {
            position,
            intensity,
        }
    }

    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        if *shape != LightShape::None {
            return Err(Error::msg(format!(
                "{}: a point light is declared in [[light]], not as a shape's emission",
                params.owner()
            )));
        }
        let p = PointLightParams::read(params)?;
        if !(p.intensity.min_component() >= 0.0 && p.intensity.is_finite()) {
            return Err(params.error(
                PointLightParams::KEYS.intensity,
                "must be finite and non-negative",
            ));
        }
        Ok(Self::new(p.position, p.intensity))
    }
}

impl Light for PointLight {
    fn kind(&self) -> LightKind {
        LightKind::DeltaPosition
    }

    fn sample_li(&self, ctx: &LightSampleContext, _u: Vec2) -> Option<LightSample> {
        let to_light = self.position - ctx.p();
        let dist2 = to_light.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        Some(LightSample {
            l: self.intensity / dist2,
            wi: to_light / dist2.sqrt(),
            pdf: 1.0,
            p: SurfacePoint::isolated(self.position),
        })
    }

    /// A direction uniform over the sphere.
    fn sample_le(&self, _u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        Some(EmissionSample {
            p: SurfacePoint::isolated(self.position),
            d: warp::square_to_uniform_sphere(u_dir),
            l: self.intensity,
            pdf_pos: 1.0,
            pdf_dir: warp::UNIFORM_SPHERE_PDF,
        })
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        0.0
    }

    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        Rgb::BLACK
    }

    fn power(&self) -> Rgb {
        self.intensity * (4.0 * std::f32::consts::PI)
    }

    fn bounds(&self) -> Option<LightBounds> {
        Some(LightBounds::isotropic_point(
            self.position,
            self.power().luminance(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_square_falloff() {
        let l = PointLight::new(Vec3::new(0.0, 2.0, 0.0), Rgb::splat(8.0));
        let s = l
            .sample_li(&LightSampleContext::at(Vec3::ZERO), Vec2::ZERO)
            .unwrap();
        assert_eq!(s.l, Rgb::splat(2.0));
        assert_eq!(s.wi, Vec3::Y);
        assert_eq!(l.kind(), LightKind::DeltaPosition);
    }
}
