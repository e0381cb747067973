//! The camera as a path traced from the lights sees it: where a point
//! lands on the film, and the camera's importance toward it (pbrt-v4
//! `PerspectiveCamera::SampleWi` for a pinhole, section 5.4.1; Veach 1997,
//! section 4.5 for importance).

use glam::{UVec2, Vec2, Vec3};

/// A pinhole camera: its centre of projection and its film as the image
/// plane at distance 1 along the view direction sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pinhole {
    pub origin: Vec3,
    /// The unit viewing direction, through the centre of the film.
    pub forward: Vec3,
    /// The top-left corner of the film on the image plane at distance 1,
    /// as a direction from `origin`.
    pub top_left: Vec3,
    /// One pixel to the right and one pixel down, on that plane.
    pub per_pixel_x: Vec3,
    pub per_pixel_y: Vec3,
    pub resolution: UVec2,
}

/// The camera seen from a point ([`Pinhole::sample_wi`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraSample {
    /// Unit direction from the point toward the camera.
    pub wi: Vec3,
    /// The distance to the camera, for the shadow ray.
    pub dist: f32,
    /// Where the point lands on the film, in pixels from the top-left
    /// corner.
    pub raster: Vec2,
    /// The importance `We` toward the point over the density of `wi`
    /// (`dist^2 / cos theta`, the pinhole's lens being a point), so that
    /// light leaving the point toward the camera with radiance `L` adds
    /// `L |cos theta_p| weight` to the film at `raster`, before the
    /// film's division by the samples per pixel.
    pub weight: f32,
}

impl Pinhole {
    /// The area of the film on the image plane at distance 1.
    pub fn film_area(&self) -> f32 {
        let (w, h) = (self.resolution.x as f32, self.resolution.y as f32);
        self.per_pixel_x.length() * w * self.per_pixel_y.length() * h
    }

    /// The pinhole's importance `We = 1 / (A cos^4 theta)` for a ray
    /// leaving at angle `theta` to the view direction, inside the film's
    /// frustum: normalised so that it integrates to 1 against `cos theta`
    /// over the directions the film sees (pbrt-v4 eq. 5.20).
    pub fn importance(&self, cos_theta: f32) -> f32 {
        let cos2 = cos_theta * cos_theta;
        1.0 / (self.film_area() * cos2 * cos2)
    }

    /// Where the ray from the camera along `dir` (any length) lands on the
    /// film, in pixels; `None` outside the film or behind the camera.
    pub fn raster(&self, dir: Vec3) -> Option<Vec2> {
        let along = dir.dot(self.forward);
        // Also false for NaN.
        if along.is_nan() || along <= 0.0 {
            return None;
        }
        let on_plane = dir / along - self.top_left;
        let raster = Vec2::new(
            on_plane.dot(self.per_pixel_x) / self.per_pixel_x.length_squared(),
            on_plane.dot(self.per_pixel_y) / self.per_pixel_y.length_squared(),
        );
        let size = self.resolution.as_vec2();
        (raster.x >= 0.0 && raster.y >= 0.0 && raster.x < size.x && raster.y < size.y)
            .then_some(raster)
    }

    /// The camera seen from `p`; `None` where `p` is outside the film's
    /// frustum.
    pub fn sample_wi(&self, p: Vec3) -> Option<CameraSample> {
        let to_p = p - self.origin;
        let dist2 = to_p.length_squared();
        let dist = dist2.sqrt();
        let raster = self.raster(to_p)?;
        let cos_theta = to_p.dot(self.forward) / dist;
        // We / pdf = (1 / (A cos^4)) / (dist^2 / cos).
        let weight = self.importance(cos_theta) * cos_theta / dist2;
        (weight.is_finite() && weight > 0.0).then(|| CameraSample {
            wi: -to_p / dist,
            dist,
            raster,
            weight,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4:3 film looking down -z from the origin, 90 degrees across its
    /// smaller side.
    fn pinhole() -> Pinhole {
        let (w, h) = (40, 30);
        let half = Vec2::new(4.0 / 3.0, 1.0);
        Pinhole {
            origin: Vec3::ZERO,
            forward: -Vec3::Z,
            top_left: Vec3::new(-half.x, half.y, -1.0),
            per_pixel_x: Vec3::X * (2.0 * half.x / w as f32),
            per_pixel_y: -Vec3::Y * (2.0 * half.y / h as f32),
            resolution: UVec2::new(w, h),
        }
    }

    #[test]
    fn a_point_lands_where_its_camera_ray_leaves() {
        let camera = pinhole();
        for raster in [
            Vec2::new(0.5, 0.5),
            Vec2::new(39.9, 0.1),
            Vec2::new(20.0, 15.0),
        ] {
            let dir =
                camera.top_left + camera.per_pixel_x * raster.x + camera.per_pixel_y * raster.y;
            let seen = camera.sample_wi(dir * 7.0).unwrap();
            assert!(
                (seen.raster - raster).abs().max_element() < 1e-4,
                "{raster}"
            );
            assert!((seen.dist - 7.0 * dir.length()).abs() < 1e-4);
            assert!((seen.wi + dir.normalize()).length() < 1e-6);
        }
        assert!(camera.sample_wi(Vec3::new(0.0, 0.0, 1.0)).is_none());
        assert!(camera.sample_wi(Vec3::new(10.0, 0.0, -1.0)).is_none());
    }

    /// `We cos theta` integrates to 1 over the directions the film sees:
    /// a midpoint sum over the image plane, where `d omega = dA cos^3`.
    #[test]
    fn importance_integrates_to_one_over_the_film() {
        let camera = pinhole();
        let n = 400;
        let size = camera.resolution.as_vec2();
        let cell = camera.film_area() / (n * n) as f32;
        let mut sum = 0.0f64;
        for i in 0..n * n {
            let raster = Vec2::new(
                ((i % n) as f32 + 0.5) / n as f32 * size.x,
                ((i / n) as f32 + 0.5) / n as f32 * size.y,
            );
            let dir =
                camera.top_left + camera.per_pixel_x * raster.x + camera.per_pixel_y * raster.y;
            let cos = dir.normalize().dot(camera.forward);
            sum += (camera.importance(cos) * cos * cos.powi(3) * cell) as f64;
        }
        assert!((sum - 1.0).abs() < 1e-4, "{sum}");
    }
}
