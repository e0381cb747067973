//! Uniform sampling of the solid angle a rectangle subtends (Urena, Fajardo
//! and King 2013, "An Area-Preserving Parametrization for Spherical
//! Rectangles", EGSR; section 3 for the setup, section 4, eqs. 5-9 for the
//! inversion). Computed in `f64` for the same reason as
//! [`crate::spherical_triangle`]: the solid angle is a difference of angles
//! near `2 pi`.

use glam::{DVec3, Vec2, Vec3};

/// A rectangle `corner + s ex + t ey` (`ex` orthogonal to `ey`) seen from `o`,
/// in the local frame of the paper: `x` along `ex`, `y` along `ey`, `z`
/// pointing away from `o`'s side so that `z0 <= 0`.
#[derive(Debug, Clone, Copy)]
pub struct SphericalRectangle {
    x0: f64,
    y0: f64,
    z0: f64,
    x1: f64,
    y1: f64,
    b0: f64,
    b1: f64,
    k: f64,
    solid_angle: f64,
    exl: f64,
    eyl: f64,
}

impl SphericalRectangle {
    /// `None` when `o` lies in the rectangle's plane or the edges are not
    /// orthogonal (callers then sample by area).
    pub fn new(corner: Vec3, ex: Vec3, ey: Vec3, o: Vec3) -> Option<Self> {
        let (corner, ex, ey, o) = (
            corner.as_dvec3(),
            ex.as_dvec3(),
            ey.as_dvec3(),
            o.as_dvec3(),
        );
        let exl = ex.length();
        let eyl = ey.length();
        let x = ex / exl;
        let y = ey / eyl;
        if x.dot(y).abs() > 1e-5 {
            return None;
        }
        let z = x.cross(y);
        let d = corner - o;
        let x0 = d.dot(x);
        let y0 = d.dot(y);
        let z0 = -d.dot(z).abs();
        if z0 == 0.0 {
            return None;
        }
        let (x1, y1) = (x0 + exl, y0 + eyl);
        // Normals of the four planes through o and an edge (section 3).
        let n0 = DVec3::new(0.0, z0, -y0).try_normalize()?;
        let n1 = DVec3::new(-z0, 0.0, x1).try_normalize()?;
        let n2 = DVec3::new(0.0, -z0, y1).try_normalize()?;
        let n3 = DVec3::new(z0, 0.0, -x0).try_normalize()?;
        let angle = |a: DVec3, b: DVec3| (-a.dot(b)).clamp(-1.0, 1.0).acos();
        let g0 = angle(n0, n1);
        let g1 = angle(n1, n2);
        let g2 = angle(n2, n3);
        let g3 = angle(n3, n0);
        let k = 2.0 * std::f64::consts::PI - g2 - g3;
        // Solid angle: the sum of the interior angles minus 2 pi (eq. 1).
        let solid_angle = g0 + g1 - k;
        Some(Self {
            x0,
            y0,
            z0,
            x1,
            y1,
            b0: n0.z,
            b1: n2.z,
            k,
            solid_angle,
            exl,
            eyl,
        })
    }

    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// Maps `u` to rectangle coordinates `(s, t)` in `[0, 1]^2` (fractions of
    /// `ex` and `ey`) of a point uniform in solid angle.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (u, v) = (f64::from(u.x), f64::from(u.y));
        // Eq. 5-6: the sub-area u S fixes the x coordinate.
        let au = u * self.solid_angle + self.k;
        let fu = (au.cos() * self.b0 - self.b1) / au.sin();
        let cu = (1.0 / (fu * fu + self.b0 * self.b0).sqrt()).copysign(fu);
        let cu = cu.clamp(-1.0, 1.0);
        let xu = (-(cu * self.z0) / (1.0 - cu * cu).max(0.0).sqrt()).clamp(self.x0, self.x1);
        // Eq. 8-9: uniform in the projected height h along that column.
        let d = (xu * xu + self.z0 * self.z0).sqrt();
        let h0 = self.y0 / (d * d + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (d * d + self.y1 * self.y1).sqrt();
        let hv = h0 + v * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * d / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        Vec2::new(
            ((xu - self.x0) / self.exl).clamp(0.0, 1.0) as f32,
            ((yv - self.y0) / self.eyl).clamp(0.0, 1.0) as f32,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_square_from_its_centre_axis() {
        // A 2x2 square at distance 1: solid angle 4 asin(1/3) = 2 pi / 3.
        let r = SphericalRectangle::new(
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::ZERO,
        )
        .unwrap();
        let expected = 2.0 * std::f64::consts::PI / 3.0;
        assert!((r.solid_angle() - expected).abs() < 1e-12);
        let st = r.sample(Vec2::new(0.5, 0.5));
        assert!((st - Vec2::splat(0.5)).length() < 1e-6, "{st}");
    }

    #[test]
    fn parallelograms_and_coplanar_points_are_refused() {
        let skew = SphericalRectangle::new(Vec3::Z, Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::ZERO);
        assert!(skew.is_none());
        assert!(
            SphericalRectangle::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(5.0, 1.0, 0.0))
                .is_none()
        );
    }
}
