//! Uniform sampling of the solid angle a rectangle subtends (Urena, Fajardo
//! and King 2013, "An Area-Preserving Parametrization for Spherical
//! Rectangles", EGSR; section 3 for the setup, section 4, eqs. 5-9 for the
//! inversion). Computed in `f64` for the same reason as
//! [`crate::spherical_triangle`]: eq. 1's solid angle is a difference of
//! angles near `2 pi` (here it comes from two triangles' Van Oosterom and
//! Strackee formulas instead), and the inversion subtracts nearly equal
//! quantities for small rectangles.

use glam::{DVec3, Vec2, Vec3};

use crate::spherical_triangle;

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
    cos_k: f64,
    sin_k: f64,
    solid_angle: f64,
    exl: f64,
    eyl: f64,
}

impl SphericalRectangle {
    /// `None` when `o` lies in the rectangle's plane or the edges are not
    /// orthogonal (callers then sample by area).
    #[inline]
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
        // Normals of planes through o and an edge (section 3); eq. 5 needs
        // three of the four.
        let n0 = DVec3::new(0.0, z0, -y0).try_normalize()?;
        let n2 = DVec3::new(0.0, -z0, y1).try_normalize()?;
        let n3 = DVec3::new(z0, 0.0, -x0).try_normalize()?;
        // Eq. 1's solid angle, the sum of the interior angles minus 2 pi,
        // cancels for small rectangles and takes four `acos`: the two
        // triangles' solid angles (Van Oosterom and Strackee) are exact and
        // take two `atan2`.
        let toward = |x: f64, y: f64| DVec3::new(x, y, z0).normalize();
        let (c0, c2) = (toward(x0, y0), toward(x1, y1));
        let solid_angle = spherical_triangle::solid_angle(c0, toward(x1, y0), c2)
            + spherical_triangle::solid_angle(c0, c2, toward(x0, y1));
        // Eq. 5's k = 2 pi - g2 - g3 as its cosine and sine, from those of
        // the interior angles (between planes with normals n and m,
        // cos g = -n.m and sin g = |n x m|), without an `acos`.
        let (cos_g2, sin_g2) = (-n2.dot(n3), n2.cross(n3).length());
        let (cos_g3, sin_g3) = (-n3.dot(n0), n3.cross(n0).length());
        let cos_k = cos_g2 * cos_g3 - sin_g2 * sin_g3;
        let sin_k = -(sin_g2 * cos_g3 + cos_g2 * sin_g3);
        Some(Self {
            x0,
            y0,
            z0,
            x1,
            y1,
            b0: n0.z,
            b1: n2.z,
            cos_k,
            sin_k,
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
    #[inline]
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (u, v) = (f64::from(u.x), f64::from(u.y));
        // Eq. 5-6: the sub-area u S fixes the x coordinate, through the
        // cosine and sine of au = u S + k.
        let (sin_us, cos_us) = (u * self.solid_angle).sin_cos();
        let cos_au = cos_us * self.cos_k - sin_us * self.sin_k;
        let sin_au = sin_us * self.cos_k + cos_us * self.sin_k;
        let fu = (cos_au * self.b0 - self.b1) / sin_au;
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

    /// The inversion is only right if the solid angle and `k` it is given
    /// are the rectangle's: `u0 = 0` and `u0 = 1` must give its two edges
    /// along `ey`, `u1 = 0` and `u1 = 1` the two along `ex`.
    #[test]
    fn the_unit_square_edges_map_to_the_rectangle_edges() {
        let mut rng = crate::Pcg32::new(7, 1);
        let mut next = || rng.next_f32() * 4.0 - 2.0;
        let mut checked = 0;
        for _ in 0..200 {
            let corner = Vec3::new(next(), next(), next());
            let ex = Vec3::new(next(), next(), 0.0);
            let ey = Vec3::new(-ex.y, ex.x, 0.0) * next();
            let o = Vec3::new(next(), next(), next());
            let Some(r) = SphericalRectangle::new(corner, ex, ey, o) else {
                continue;
            };
            if r.solid_angle() < 0.05 {
                continue;
            }
            for (u, s, t) in [
                ((0.0, 0.4), Some(0.0), None),
                ((1.0, 0.4), Some(1.0), None),
                ((0.3, 0.0), None, Some(0.0)),
                ((0.3, 1.0), None, Some(1.0)),
            ] {
                let st = r.sample(Vec2::from(u));
                for (got, want) in [(st.x, s), (st.y, t)] {
                    if let Some(want) = want {
                        assert!((got - want).abs() < 1e-3, "u {u:?} gave {st}");
                    }
                }
            }
            checked += 1;
        }
        assert!(checked > 50, "{checked}");
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
