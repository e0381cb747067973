//! The first-hit pass: what a camera ray sees first, for the albedo,
//! normal and depth outputs, traced apart from the integrator (as Mitsuba
//! 3's `aov` integrator does) so that no estimator changes for them.

use lumis_core::{BsdfContext, Ray, Scene, Vec2, Vec3};
use lumis_sampling::{hash_with, pixel_key, Pcg32};

/// Perfect mirrors and glass followed before giving up on finding a
/// surface with a non-specular lobe (Open Image Denoise's albedo and
/// normal are those of the first such surface).
pub const MAX_SPECULAR_BOUNCES: u32 = 4;

/// The stream of the first-hit pass's random numbers: its own, so that the
/// integrator's samples are the same with outputs asked for or not.
const FIRST_HIT_STREAM: u64 = 0x6669_7273_7468_6974;

/// What one camera ray found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FirstHit {
    /// One-sample estimate of the hemispherical reflectance `∫ f |cos| dωi`
    /// at `wo` (`f |cos| / pdf` of one BSDF sample: unbiased, its noise
    /// averages out over the pixel's samples); black for a miss.
    pub albedo: Vec3,
    /// World-space shading normal; zero for a miss.
    pub normal: Vec3,
    /// Distance to the first surface along the camera ray; 0 for a miss.
    pub depth: f32,
}

impl FirstHit {
    const MISS: Self = Self {
        albedo: Vec3::ZERO,
        normal: Vec3::ZERO,
        depth: 0.0,
    };
}

/// The random numbers of pixel sample `index` of `pixel`.
pub fn first_hit_rng(pixel: lumis_core::UVec2, index: u32, seed: u64) -> Pcg32 {
    Pcg32::new(
        hash_with(pixel_key(pixel.x, pixel.y, seed), index as u64),
        FIRST_HIT_STREAM,
    )
}

/// Traces `camera_ray` to its first surface, then through perfect specular
/// surfaces (at most [`MAX_SPECULAR_BOUNCES`]) to the first one with a
/// diffuse or glossy lobe.
pub fn first_hit(scene: &dyn Scene, camera_ray: &Ray, rng: &mut Pcg32) -> FirstHit {
    let mut ray = *camera_ray;
    let mut depth = 0.0;
    for bounce in 0..=MAX_SPECULAR_BOUNCES {
        let Some(hit) = scene.intersect(&ray) else {
            return FirstHit {
                depth,
                ..FirstHit::MISS
            };
        };
        if bounce == 0 {
            depth = (hit.p() - ray.o).length();
        }
        let wo = hit.shading.to_local(-ray.d);
        let ctx = BsdfContext {
            texture: hit.texture,
            ..Default::default()
        };
        let u1 = rng.next_f32();
        let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
        let sample = hit.bsdf.sample_f(&ctx, wo, u1, u2);
        if hit.bsdf_flags.is_non_specular() {
            let albedo = sample
                .filter(|s| s.pdf > 0.0)
                .map(|s| {
                    let weight = s.f * (s.wi.z.abs() / s.pdf);
                    Vec3::new(weight.r, weight.g, weight.b)
                })
                .filter(|a| a.is_finite())
                .unwrap_or(Vec3::ZERO);
            return FirstHit {
                albedo,
                normal: hit.shading.normal(),
                depth,
            };
        }
        let Some(sample) = sample else {
            break;
        };
        ray = hit.spawn_ray(hit.shading.to_world(sample.wi));
    }
    FirstHit {
        depth,
        ..FirstHit::MISS
    }
}
