//! `constant`: uniform radiance arriving from every direction (the white
//! furnace's light).

use crate::emission::infinite_emission;
use lumis_api::interaction::LightSampleContext;
use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Error, Light, LightKind, LightSample, LightShape, Params, PluginKind, PluginParams, PluginSpec,
    Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::warp;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "constant",
    source: lumis_api::source_file!(),
    doc: "constant environment radiance from all directions, sampled uniformly over the sphere",
    params: ConstantLightParams::SPECS,
};

#[derive(Debug, Clone, Copy, PluginParams)]
pub struct ConstantLightParams {
    /// radiance arriving from every direction
    pub radiance: Rgb,
}

#[derive(Debug, Clone)]
pub struct ConstantLight {
    radiance: Rgb,
    scene_center: Vec3,
    scene_radius: f32,
}

impl ConstantLight {
    pub fn new(radiance: Rgb) -> Self {
        Self {
            radiance,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
        }
    }

    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        if *shape != LightShape::None {
            return Err(Error::msg(format!(
                "{}: a constant light is declared in [[light]], not as a shape's emission",
                params.owner()
            )));
        }
        let radiance = ConstantLightParams::read(params)?.radiance;
        if !(radiance.min_component() >= 0.0 && radiance.is_finite()) {
            return Err(params.error(
                ConstantLightParams::KEYS.radiance,
                "must be finite and non-negative",
            ));
        }
        Ok(Self::new(radiance))
    }
}

impl Light for ConstantLight {
    fn kind(&self) -> LightKind {
        LightKind::Infinite
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let wi = warp::square_to_uniform_sphere(u);
        // A point beyond the scene's bounding sphere, for the shadow ray.
        let far =
            ctx.p() + wi * (2.0 * (self.scene_radius + (ctx.p() - self.scene_center).length()));
        Some(LightSample {
            l: self.radiance,
            wi,
            pdf: warp::UNIFORM_SPHERE_PDF,
            p: SurfacePoint::isolated(far),
        })
    }

    /// From a point on the disk facing the direction drawn, outside the
    /// scene's bounding sphere.
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        infinite_emission(self, self.scene_center, self.scene_radius, u_pos, u_dir)
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> f32 {
        warp::UNIFORM_SPHERE_PDF
    }

    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        self.radiance
    }

    /// Flux through the scene's bounding disk from all directions:
    /// `4 pi^2 r^2 L` (pbrt-v4 `UniformInfiniteLight::Phi`).
    fn power(&self) -> Rgb {
        let pi = std::f32::consts::PI;
        self.radiance * (4.0 * pi * pi * self.scene_radius * self.scene_radius)
    }

    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        self.scene_center = scene_center;
        self.scene_radius = scene_radius.max(f32::MIN_POSITIVE);
    }
}
