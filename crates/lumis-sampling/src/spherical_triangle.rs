//! Uniform sampling of the solid angle a triangle subtends (Arvo 1995,
//! "Stratified Sampling of Spherical Triangles", SIGGRAPH '95, section 3; in
//! the form of pbrt-v4 `SampleSphericalTriangle`, section 6.5.4).
//!
//! Everything is computed in `f64`. The solid angle comes from Van Oosterom
//! and Strackee's formula rather than the spherical excess `alpha + beta +
//! gamma - pi`, which cancels catastrophically as the triangle shrinks; the
//! inversion still subtracts nearly equal quantities (the arc's cosines near
//! 1), which is why lights fall back to area sampling below
//! [`MIN_SPHERICAL_SAMPLE_AREA`].

use glam::{DVec3, Vec2, Vec3};

/// Below this solid angle (sr) lights sample by area instead: the spherical
/// construction loses precision, and the solid-angle density is then almost
/// proportional to the area density anyway (pbrt-v4 `MinSphericalSampleArea`).
pub const MIN_SPHERICAL_SAMPLE_AREA: f32 = 3e-4;

/// Above this solid angle (sr; a hemisphere is 6.28) spherical triangles
/// become nearly degenerate lunes and the arc construction is ill-conditioned
/// (pbrt-v4 `MaxSphericalSampleArea`).
pub const MAX_SPHERICAL_SAMPLE_AREA: f32 = 6.22;

/// The solid angle (sr) of the spherical triangle with unit vertices `a`,
/// `b`, `c`, by Van Oosterom and Strackee (1983, IEEE Trans. Biomed. Eng.
/// 30(2), eq. 8): `tan(omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a)`.
/// Accurate where the angle sum `alpha + beta + gamma - pi` cancels, and one
/// `atan2` where the angle sum takes three `acos`.
#[inline]
pub(crate) fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let num = a.dot(b.cross(c)).abs();
    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * num.atan2(den)
}

/// The triangle `v` as seen from `p`: unit directions to its vertices and
/// the solid angle they span.
#[derive(Debug, Clone, Copy)]
pub struct SphericalTriangle {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    solid_angle: f64,
    p: Vec3,
    v: [Vec3; 3],
}

impl SphericalTriangle {
    /// `None` when `p` is one of the vertices.
    #[inline]
    pub fn new(v: [Vec3; 3], p: Vec3) -> Option<Self> {
        let pd = p.as_dvec3();
        let a = (v[0].as_dvec3() - pd).try_normalize()?;
        let b = (v[1].as_dvec3() - pd).try_normalize()?;
        let c = (v[2].as_dvec3() - pd).try_normalize()?;
        Some(Self {
            a,
            b,
            c,
            solid_angle: solid_angle(a, b, c),
            p,
            v,
        })
    }

    /// Solid angle (sr); zero when `p` lies in the triangle's plane.
    pub fn solid_angle(&self) -> f64 {
        self.solid_angle
    }

    /// Maps `u` to barycentrics `(b0, b1, b2)` of a point whose direction
    /// from `p` is uniform over the spherical triangle.
    ///
    /// Arvo's construction: `u0` picks the sub-triangle `A b c'` of area
    /// `A' = u0 A` (eq. 5: solve `A' = alpha + beta' + gamma' - pi` for the
    /// point `c'` on arc `ac`), then `u1` picks a point on the arc `b c'`
    /// uniformly in `1 - cos` (eq. 7). Only the angle `alpha` at `a` enters
    /// eq. 5, through its sine and cosine, which come from the planes'
    /// normals without an `acos`; `A` is [`Self::solid_angle`].
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<[f32; 3]> {
        let (a, b, c) = (self.a, self.b, self.c);
        // alpha: the angle at a between the great circles through b and c.
        let n_ab = a.cross(b).try_normalize()?;
        let n_ac = a.cross(c).try_normalize()?;
        let cos_alpha = n_ab.dot(n_ac);
        let sin_alpha = n_ab.cross(n_ac).length();
        // sin and cos of A' + pi are -sin A' and -cos A'.
        let (sin_a, cos_a) = (f64::from(u.x) * self.solid_angle).sin_cos();
        let (sin_ap, cos_ap) = (-sin_a, -cos_a);
        let sin_phi = sin_ap * cos_alpha - cos_ap * sin_alpha;
        let cos_phi = cos_ap * cos_alpha + sin_ap * sin_alpha;
        let k1 = cos_phi + cos_alpha;
        let k2 = sin_phi - sin_alpha * a.dot(b);
        let cos_bp = ((k2 + (k2 * cos_phi - k1 * sin_phi) * cos_alpha)
            / ((k2 * sin_phi + k1 * cos_phi) * sin_alpha))
            .clamp(-1.0, 1.0);
        let sin_bp = (1.0 - cos_bp * cos_bp).max(0.0).sqrt();
        let cp = cos_bp * a + sin_bp * (c - a * c.dot(a)).try_normalize()?;
        // Uniform in 1 - cos theta along the arc from b to c'.
        let cos_theta = 1.0 - f64::from(u.y) * (1.0 - cp.dot(b));
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let w = cos_theta * b + sin_theta * (cp - b * cp.dot(b)).try_normalize()?;
        // Where the ray p + t w crosses the triangle (Moller-Trumbore).
        let v = self.v.map(Vec3::as_dvec3);
        let e1 = v[1] - v[0];
        let e2 = v[2] - v[0];
        let s1 = w.cross(e2);
        let div = s1.dot(e1);
        if div == 0.0 {
            return None;
        }
        let s = self.p.as_dvec3() - v[0];
        let mut b1 = (s.dot(s1) / div).clamp(0.0, 1.0);
        let mut b2 = (w.dot(s.cross(e1)) / div).clamp(0.0, 1.0);
        let sum = b1 + b2;
        if sum > 1.0 {
            b1 /= sum;
            b2 /= sum;
        }
        Some([(1.0 - b1 - b2) as f32, b1 as f32, b2 as f32])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octant_is_an_eighth_of_the_sphere() {
        let t = SphericalTriangle::new([Vec3::X, Vec3::Y, Vec3::Z], Vec3::ZERO).unwrap();
        let omega = t.solid_angle();
        assert!(
            (omega - std::f64::consts::PI / 2.0).abs() < 1e-12,
            "{omega}"
        );
        let b = t.sample(Vec2::new(0.3, 0.7)).unwrap();
        assert!(b.iter().all(|&x| (0.0..=1.0).contains(&x)));
        assert!((b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    /// Arvo's inversion is only right if the area it is given is the
    /// triangle's: `u0 = 0` must give the arc through `a` (`c' = a`), `u0 = 1`
    /// the arc through `c` (`c' = c`), and `u1 = 0` the vertex `b`.
    #[test]
    fn the_unit_square_corners_map_to_the_vertices() {
        let mut rng = crate::Pcg32::new(3, 5);
        let mut point = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0;
        let mut checked = 0;
        for _ in 0..200 {
            let (v, p) = ([point(), point(), point()], point());
            let Some(t) = SphericalTriangle::new(v, p) else {
                continue;
            };
            if !(0.05..6.0).contains(&t.solid_angle()) {
                continue;
            }
            for (u, want) in [
                ((0.0, 1.0), [1.0, 0.0, 0.0]),
                ((0.37, 0.0), [0.0, 1.0, 0.0]),
                ((1.0, 1.0), [0.0, 0.0, 1.0]),
            ] {
                let b = t.sample(Vec2::from(u)).unwrap();
                let err = b
                    .iter()
                    .zip(want)
                    .map(|(x, y)| (x - y).abs())
                    .fold(0.0, f32::max);
                assert!(
                    err < 1e-3,
                    "{v:?} from {p}: u {u:?} gave {b:?}, want {want:?}"
                );
            }
            checked += 1;
        }
        assert!(checked > 50, "{checked}");
    }

    #[test]
    fn tiny_far_triangle_keeps_a_positive_solid_angle() {
        let v = [
            Vec3::new(0.0, 0.0, 1e4),
            Vec3::new(1e-3, 0.0, 1e4),
            Vec3::new(0.0, 1e-3, 1e4),
        ];
        let omega = SphericalTriangle::new(v, Vec3::ZERO).unwrap().solid_angle();
        let expected = 0.5e-6 / 1e8;
        assert!((omega / expected - 1.0).abs() < 1e-4, "{omega}");
    }
}
