//! `envmap`: radiance arriving from every direction, read from an
//! equirectangular image (pbrt-v4 `ImageInfiniteLight`, Mitsuba 3
//! `envmap`), importance-sampled by luminance.
//!
//! The image (EXR or Radiance `.hdr`) is looked up bilinearly between texel
//! centres. `sampling = "importance"` draws a texel from a piecewise-constant
//! 2D distribution (a marginal over rows, a conditional in each row:
//! [`lumis_sampling::Distribution2D`]) of each texel's average interpolated
//! luminance times `sin theta`, then a point uniformly inside it, and maps
//! that to a direction; the Jacobian of `(u, v) -> direction` is
//! `2 pi^2 sin theta`, so the density in solid angle is
//! `p(u, v) / (2 pi^2 sin theta)` (pbrt-v4, section 12.5.2). Averaging the
//! interpolation (1/8, 3/4, 1/8 of the neighbours along each axis) gives
//! every texel the interpolation reaches a density. `"uniform"` samples the
//! sphere, the baseline the bench compares against. `power()` is pbrt-v4's
//! `Phi`: `pi r^2`, r the scene's bounding radius, times the integral of
//! radiance over the sphere.

mod equirect;

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use crate::emission::infinite_emission;
use lumis_api::glam::Quat;
use lumis_api::interaction::LightSampleContext;
use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use lumis_api::{
    Error, Light, LightKind, LightSample, LightShape, ParamChoice, Params, PluginKind,
    PluginParams, PluginSpec, Result, Rgb, Vec2, Vec3,
};
use lumis_sampling::{warp, Distribution2D};

pub use equirect::Equirect;

pub const SPEC: PluginSpec = PluginSpec {
    kind: PluginKind::Light,
    name: "envmap",
    source: lumis_api::source_file!(),
    doc: "environment radiance from an equirectangular EXR or Radiance .hdr image (Mitsuba's convention: +y up, the image centre along +z), looked up bilinearly and importance-sampled by luminance",
    params: EnvMapParams::SPECS,
};

#[derive(Debug, Clone, PluginParams)]
pub struct EnvMapParams {
    /// the equirectangular image (EXR or Radiance .hdr), relative to the
    /// scene file
    pub filename: PathBuf,
    /// multiplies every texel
    #[param(default = 1.0)]
    pub scale: f32,
    /// the world direction the image's top row looks toward
    #[param(default = [0.0, 1.0, 0.0])]
    pub up: Vec3,
    /// turns the map about `up` by this many degrees (counter-clockwise
    /// seen from above)
    #[param(default = 0.0)]
    pub rotation: f32,
    /// how directions are drawn: "importance" (by luminance),
    /// "compensated" (by luminance above its average, for MIS with BSDF
    /// sampling only) or "uniform" (over the sphere, a baseline)
    #[param(default = Importance)]
    pub sampling: EnvSampling,
}

/// How `sample_li` draws directions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum EnvSampling {
    /// In proportion to the map's luminance.
    Importance,
    /// In proportion to the luminance above the map's average (pbrt-v4's
    /// MIS compensation): directions dimmer than the average have no
    /// density, so only an integrator that combines light and BSDF
    /// samples by MIS (`strategy = "mis"`) stays unbiased.
    Compensated,
    /// Uniformly over the sphere.
    Uniform,
}

/// An environment map light.
#[derive(Debug, Clone)]
pub struct EnvMapLight {
    map: Equirect,
    scale: f32,
    /// From the map's frame to the world.
    to_world: Quat,
    /// Luminance times `sin theta` per texel; `None` for uniform sampling.
    distribution: Option<Distribution2D>,
    scene_center: Vec3,
    scene_radius: f32,
}

impl EnvMapLight {
    /// A light of `map` (radiance per texel, already checked) times
    /// `scale`, turned by `to_world`.
    pub fn new(map: Equirect, scale: f32, to_world: Quat, sampling: EnvSampling) -> Self {
        let weights = match sampling {
            EnvSampling::Importance => Some(map.sampling_weights(false)),
            EnvSampling::Compensated => Some(map.sampling_weights(true)),
            EnvSampling::Uniform => None,
        };
        let distribution =
            weights.map(|weights| Distribution2D::new(&weights, map.width(), map.height()));
        Self {
            map,
            scale,
            to_world,
            distribution,
            scene_center: Vec3::ZERO,
            scene_radius: 1.0,
        }
    }

    pub fn from_params(params: &Params, shape: &LightShape) -> Result<Self> {
        if *shape != LightShape::None {
            return Err(Error::msg(format!(
                "{}: an envmap light is declared in [[light]], not as a shape's emission",
                params.owner()
            )));
        }
        let p = EnvMapParams::read(params)?;
        let keys = EnvMapParams::KEYS;
        let map = read_map(&p.filename)
            .map_err(|e| params.error(keys.filename, format!("{}: {e}", p.filename.display())))?;
        if !(p.scale.is_finite() && p.scale >= 0.0) {
            return Err(params.error(keys.scale, "must be finite and non-negative"));
        }
        if !(p.up.is_finite() && p.up.length() > 0.0) {
            return Err(params.error(keys.up, "must be a non-zero direction"));
        }
        if !p.rotation.is_finite() {
            return Err(params.error(keys.rotation, "must be a finite angle in degrees"));
        }
        Ok(Self::new(map, p.scale, frame(p.up, p.rotation), p.sampling))
    }

    /// The scaled radiance arriving along `-w` (world).
    #[inline]
    fn radiance(&self, w: Vec3) -> Rgb {
        let (uv, _) = Equirect::uv_of(self.to_world.inverse() * w);
        self.map.lookup(uv) * self.scale
    }

    /// A point beyond the scene's bounding sphere along `wi`, for the
    /// shadow ray.
    fn far_point(&self, ctx: &LightSampleContext, wi: Vec3) -> SurfacePoint {
        let reach = 2.0 * (self.scene_radius + (ctx.p() - self.scene_center).length());
        SurfacePoint::isolated(ctx.p() + wi * reach)
    }
}

/// The rotation taking the map's frame (`+y` up) to the world: `+y` onto
/// `up` by the shortest arc, after turning by `degrees` about `+y`.
fn frame(up: Vec3, degrees: f32) -> Quat {
    Quat::from_rotation_arc(Vec3::Y, up.normalize()) * Quat::from_rotation_y(degrees.to_radians())
}

/// The texels of an EXR or Radiance `.hdr` file (told apart by their
/// first bytes), checked: a non-empty image of finite, non-negative values.
fn read_map(path: &Path) -> std::result::Result<Equirect, String> {
    let image = if lumis_image::is_hdr(path) {
        lumis_image::read_hdr(path)
    } else {
        lumis_image::read_exr(path)
    }
    .map_err(|e| e.to_string())?;
    if image.width == 0 || image.height == 0 {
        return Err(format!(
            "the image is {}x{}, expected at least one texel",
            image.width, image.height
        ));
    }
    let texels = image
        .pixels
        .iter()
        .enumerate()
        .map(|(k, &[r, g, b])| {
            let t = Rgb::new(r, g, b);
            if t.is_finite() && t.min_component() >= 0.0 {
                Ok(t)
            } else {
                Err(format!(
                    "texel ({}, {}) is {t:?}, expected finite non-negative radiance",
                    k % image.width,
                    k / image.width
                ))
            }
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    Ok(Equirect::new(image.width, image.height, texels))
}

impl Light for EnvMapLight {
    fn kind(&self) -> LightKind {
        LightKind::Infinite
    }

    fn memory_bytes(&self) -> usize {
        self.map.byte_size()
            + self
                .distribution
                .as_ref()
                .map_or(0, Distribution2D::byte_size)
    }

    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        let (wi, pdf, l) = match &self.distribution {
            None => {
                let wi = warp::square_to_uniform_sphere(u);
                (wi, warp::UNIFORM_SPHERE_PDF, self.radiance(wi))
            }
            Some(distribution) => {
                // A black map has nothing to draw.
                if distribution.integral() == 0.0 {
                    return None;
                }
                let (uv, pdf_uv) = distribution.sample(u);
                let (d, sin_theta) = Equirect::direction_of(uv);
                if !(sin_theta > 0.0 && pdf_uv > 0.0) {
                    return None;
                }
                // The radiance at the drawn point itself: the same as
                // looking up `wi`, without mapping it back.
                (
                    (self.to_world * d).normalize(),
                    pdf_uv / (2.0 * PI * PI * sin_theta),
                    self.map.lookup(uv) * self.scale,
                )
            }
        };
        Some(LightSample {
            l,
            wi,
            pdf,
            p: self.far_point(ctx, wi),
        })
    }

    /// From a point on the disk facing the direction drawn, outside the
    /// scene's bounding sphere.
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        infinite_emission(self, self.scene_center, self.scene_radius, u_pos, u_dir)
    }

    fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> f32 {
        let Some(distribution) = &self.distribution else {
            return warp::UNIFORM_SPHERE_PDF;
        };
        if distribution.integral() == 0.0 {
            return 0.0;
        }
        let (uv, sin_theta) = Equirect::uv_of((self.to_world.inverse() * wi).normalize());
        if sin_theta.is_nan() || sin_theta <= 0.0 {
            return 0.0;
        }
        distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }

    fn l(&self, _p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        self.radiance(w)
    }

    /// Flux through the scene's bounding disk: `pi r^2` times the
    /// integral of radiance over the sphere (pbrt-v4
    /// `ImageInfiniteLight::Phi`, on the equirectangular cells).
    fn power(&self) -> Rgb {
        self.map.radiance_integral() * (self.scale * PI * self.scene_radius * self.scene_radius)
    }

    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        self.scene_center = scene_center;
        self.scene_radius = scene_radius.max(f32::MIN_POSITIVE);
    }
}
