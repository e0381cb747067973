//! Where paths traced from the lights start ([`Light::sample_le`]): the
//! directions a diffuse surface emits into, and the disk an infinite light
//! shines through (pbrt-v4 `DiffuseAreaLight::SampleLe`,
//! `UniformInfiniteLight::SampleLe`).

use std::f32::consts::PI;

use lumis_api::light::EmissionSample;
use lumis_api::ray::SurfacePoint;
use lumis_api::{Frame, Light, LightSampleContext, Rgb, Vec2, Vec3};
use lumis_sampling::warp;

/// Light leaving `point` of a diffuse emitter of radiance `radiance`: a
/// direction cosine-distributed about the normal, on the front side, or on
/// either side with probability 1/2 each (`u_dir.x` choosing) when
/// `two_sided`; the origin's density is `pdf_pos`.
pub fn diffuse_emission(
    point: SurfacePoint,
    pdf_pos: f32,
    radiance: Rgb,
    two_sided: bool,
    u_dir: Vec2,
) -> Option<EmissionSample> {
    if radiance.is_black() {
        return None;
    }
    let (u, n, side_pmf) = match two_sided {
        false => (u_dir, point.n, 1.0),
        true if u_dir.x < 0.5 => (Vec2::new(2.0 * u_dir.x, u_dir.y), point.n, 0.5),
        true => (Vec2::new(2.0 * u_dir.x - 1.0, u_dir.y), -point.n, 0.5),
    };
    let local = warp::square_to_cosine_hemisphere(u);
    if local.z <= 0.0 {
        return None;
    }
    Some(EmissionSample {
        p: point,
        d: Frame::from_z(n).to_world(local),
        l: radiance,
        pdf_pos,
        pdf_dir: warp::cosine_hemisphere_pdf(local.z) * side_pmf,
    })
}

/// Light of an infinite `light` entering the scene's bounding sphere
/// (`center`, `radius`): a direction from its own `sample_li` (asked from
/// the centre), travelling from a point uniform on the disk of the
/// sphere's radius that faces it, outside the sphere.
pub fn infinite_emission(
    light: &dyn Light,
    center: Vec3,
    radius: f32,
    u_pos: Vec2,
    u_dir: Vec2,
) -> Option<EmissionSample> {
    let from = light.sample_li(&LightSampleContext::at(center), u_dir)?;
    let d = -from.wi;
    let disk = warp::square_to_concentric_disk(u_pos) * radius;
    let frame = Frame::from_z(from.wi);
    let p = center + (frame.to_world(Vec3::new(disk.x, disk.y, 0.0)) + from.wi * radius);
    Some(EmissionSample {
        p: SurfacePoint {
            n: d,
            ..SurfacePoint::isolated(p)
        },
        d,
        l: from.l,
        pdf_pos: 1.0 / (PI * radius * radius),
        pdf_dir: from.pdf,
    })
}
