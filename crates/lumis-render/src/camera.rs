//! A pinhole perspective camera.

use lumis_core::glam::Vec3A;
use lumis_core::{Error, Pinhole, PixelFootprint, Ray, Result, UVec2, Vec2, Vec3};

/// A pinhole camera at `origin` looking at `target`. `fov` is the full
/// angle of the image's smaller axis (the vertical one for landscape and
/// square images), like Mitsuba's `fov_axis = "smaller"`.
#[derive(Debug, Clone, PartialEq)]
pub struct PerspectiveCamera {
    origin: Vec3,
    /// The image plane at distance 1 as raster coordinates see it
    /// (pbrt-v4's raster-to-camera transform, folded into three vectors):
    /// the direction through raster point `(x, y)` is
    /// `top_left + x * per_pixel_x + y * per_pixel_y`, two multiply-adds
    /// where the film-to-NDC mapping took a division and five more steps
    /// on the path to each camera ray's query.
    top_left: Vec3A,
    per_pixel_x: Vec3A,
    per_pixel_y: Vec3A,
    resolution: UVec2,
}

impl PerspectiveCamera {
    pub fn new(
        origin: Vec3,
        target: Vec3,
        up: Vec3,
        fov_degrees: f32,
        resolution: UVec2,
    ) -> Result<Self> {
        if !(fov_degrees > 0.0 && fov_degrees < 180.0) {
            return Err(Error::msg(format!(
                "fov must be in (0, 180) degrees, got {fov_degrees}"
            )));
        }
        if resolution.x == 0 || resolution.y == 0 {
            return Err(Error::msg(format!(
                "resolution must be positive, got {resolution}"
            )));
        }
        if !(origin.is_finite() && target.is_finite() && up.is_finite()) {
            return Err(Error::msg(format!(
                "camera origin {origin}, target {target} and up {up} must be finite"
            )));
        }
        let view = target - origin;
        if view == Vec3::ZERO {
            return Err(Error::msg(format!(
                "camera origin and target coincide (both {origin} in f32)"
            )));
        }
        if !view.is_finite() {
            return Err(Error::msg(format!(
                "camera origin {origin} and target {target} are too far apart for f32"
            )));
        }
        // Scaled to its largest component first: the squared length of a
        // distant target (1e30 away) would overflow f32.
        let forward = (view / view.abs().max_element()).normalize();
        let right = forward.cross(up).normalize_or_zero();
        if right == Vec3::ZERO || !right.is_finite() {
            return Err(Error::msg(
                "camera up vector is zero or parallel to the view direction",
            ));
        }
        let up = right.cross(forward);
        let tan_half = (fov_degrees.to_radians() * 0.5).tan();
        let (w, h) = (resolution.x as f32, resolution.y as f32);
        let half_extent = if w >= h {
            Vec2::new(tan_half * w / h, tan_half)
        } else {
            Vec2::new(tan_half, tan_half * h / w)
        };
        Ok(Self {
            origin,
            top_left: (forward - right * half_extent.x + up * half_extent.y).into(),
            per_pixel_x: (right * (2.0 * half_extent.x / w)).into(),
            per_pixel_y: (up * (-2.0 * half_extent.y / h)).into(),
            resolution,
        })
    }

    pub fn resolution(&self) -> UVec2 {
        self.resolution
    }

    /// The camera as paths from the lights see it.
    pub fn pinhole(&self) -> Pinhole {
        Pinhole {
            origin: self.origin,
            forward: self.forward(),
            top_left: self.top_left.into(),
            per_pixel_x: self.per_pixel_x.into(),
            per_pixel_y: self.per_pixel_y.into(),
            resolution: self.resolution,
        }
    }

    /// The unit direction through the centre of the film.
    fn forward(&self) -> Vec3 {
        let centre = self.top_left
            + 0.5 * self.resolution.x as f32 * self.per_pixel_x
            + 0.5 * self.resolution.y as f32 * self.per_pixel_y;
        centre.normalize().into()
    }

    /// The pixel spacing textures filter over, at `spp` samples per pixel
    /// ([`PixelFootprint`]).
    pub fn pixel_footprint(&self, spp: u32) -> PixelFootprint {
        PixelFootprint {
            origin: self.origin,
            forward: self.forward(),
            per_pixel_x: self.per_pixel_x.into(),
            per_pixel_y: self.per_pixel_y.into(),
            scale: PixelFootprint::spp_scale(spp),
        }
    }

    /// The ray through film position `pixel + offset` (offset in `[0,1)^2`;
    /// pixel (0, 0) is the top-left corner).
    #[inline]
    pub fn generate_ray(&self, pixel: UVec2, offset: Vec2) -> Ray {
        let raster = pixel.as_vec2() + offset;
        let d = self.top_left + self.per_pixel_x * raster.x + self.per_pixel_y * raster.y;
        Ray::new(self.origin, d.normalize().into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> PerspectiveCamera {
        PerspectiveCamera::new(
            Vec3::new(0.0, 0.0, 3.9),
            Vec3::new(0.0, 0.0, 2.9),
            Vec3::Y,
            90.0,
            UVec2::new(4, 2),
        )
        .unwrap()
    }

    #[test]
    fn centre_looks_at_target_and_axes_are_oriented() {
        let c = camera();
        let centre = c.generate_ray(UVec2::new(2, 1), Vec2::ZERO);
        assert!((centre.d - Vec3::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // Top-left corner of a 2:1 image with a 90 degree vertical fov.
        let corner = c.generate_ray(UVec2::ZERO, Vec2::ZERO);
        let expected = Vec3::new(-2.0, 1.0, -1.0).normalize();
        assert!((corner.d - expected).length() < 1e-6, "{:?}", corner.d);
    }

    /// The footprint's image plane is the one rays go through: a point one
    /// unit ahead on the view axis moves by one pixel's width.
    #[test]
    fn the_footprint_steps_one_pixel() {
        let c = camera();
        let f = c.pixel_footprint(1);
        assert!((f.forward - Vec3::NEG_Z).length() < 1e-6);
        let a = c.generate_ray(UVec2::new(2, 1), Vec2::ZERO).d;
        let b = c.generate_ray(UVec2::new(3, 1), Vec2::ZERO).d;
        let (dx, _) = f.dp_dxy(c.origin + a, Vec3::Z);
        assert!((dx - (b / b.z.abs() - a)).length() < 1e-6, "{dx}");
    }

    #[test]
    fn invalid_settings_are_errors() {
        let bad = |fov, up| PerspectiveCamera::new(Vec3::ZERO, Vec3::Z, up, fov, UVec2::new(2, 2));
        assert!(bad(0.0, Vec3::Y).is_err());
        assert!(bad(180.0, Vec3::Y).is_err());
        assert!(bad(45.0, Vec3::Z).is_err());
        assert!(
            PerspectiveCamera::new(Vec3::ZERO, Vec3::ZERO, Vec3::Y, 45.0, UVec2::new(2, 2))
                .is_err()
        );
    }

    /// A distant camera is a camera; only a difference that f32 cannot
    /// hold, or none at all, is an error, and the message says which.
    #[test]
    fn camera_checks_account_for_precision() {
        let at = |origin: Vec3, target: Vec3| {
            PerspectiveCamera::new(origin, target, Vec3::Y, 45.0, UVec2::new(2, 2))
        };
        let far = at(Vec3::new(0.0, 0.0, 1e30), Vec3::ZERO).unwrap();
        let d = far.generate_ray(UVec2::new(1, 1), Vec2::ZERO).d;
        assert!((d - Vec3::NEG_Z).length() < 1e-6, "{d}");
        let huge = at(Vec3::new(0.0, 0.0, 3e38), Vec3::new(0.0, 0.0, -3e38));
        assert!(huge.err().unwrap().message.contains("too far apart"));
        let same = at(Vec3::splat(1e8), Vec3::splat(1e8) + Vec3::X);
        assert!(same.err().unwrap().message.contains("coincide"));
        let nan = at(Vec3::NAN, Vec3::ZERO);
        assert!(nan.err().unwrap().message.contains("finite"));
    }
}
