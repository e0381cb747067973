//! Uniform sampling of the solid angle a triangle subtends (Arvo 1995,
//! "Stratified Sampling of Spherical Triangles", SIGGRAPH '95, section 3; in
//! the form of pbrt-v4 `SampleSphericalTriangle`, section 6.5.4).
//!
//! Everything is computed in `f64`: the spherical excess `alpha + beta +
//! gamma - pi` cancels catastrophically as the triangle shrinks, which is why
//! lights fall back to area sampling below [`MIN_SPHERICAL_SAMPLE_AREA`].

use glam::{DVec3, Vec2, Vec3};

/// Below this solid angle (sr) lights sample by area instead: the spherical
/// construction loses precision, and the solid-angle density is then almost
/// proportional to the area density anyway (pbrt-v4 `MinSphericalSampleArea`).
pub const MIN_SPHERICAL_SAMPLE_AREA: f32 = 3e-4;

/// Above this solid angle (sr; a hemisphere is 6.28) spherical triangles
/// become nearly degenerate lunes and the arc construction is ill-conditioned
/// (pbrt-v4 `MaxSphericalSampleArea`).
pub const MAX_SPHERICAL_SAMPLE_AREA: f32 = 6.22;

/// The triangle `v` as seen from `p`: unit directions to its vertices.
#[derive(Debug, Clone, Copy)]
pub struct SphericalTriangle {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    p: DVec3,
    v: [DVec3; 3],
}

impl SphericalTriangle {
    /// `None` when `p` lies in the triangle's plane (zero solid angle).
    pub fn new(v: [Vec3; 3], p: Vec3) -> Option<Self> {
        let p = p.as_dvec3();
        let v = v.map(|q| q.as_dvec3());
        let a = (v[0] - p).try_normalize()?;
        let b = (v[1] - p).try_normalize()?;
        let c = (v[2] - p).try_normalize()?;
        Some(Self { a, b, c, p, v })
    }

    /// Solid angle (sr) by the formula of Van Oosterom and Strackee (1983,
    /// IEEE Trans. Biomed. Eng. 30(2), eq. 8):
    /// `tan(omega / 2) = |a . (b x c)| / (1 + a.b + b.c + c.a)`,
    /// accurate where the angle sum `alpha + beta + gamma - pi` is not.
    pub fn solid_angle(&self) -> f64 {
        let (a, b, c) = (self.a, self.b, self.c);
        let num = a.dot(b.cross(c)).abs();
        let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
        2.0 * num.atan2(den)
    }

    /// Maps `u` to barycentrics `(b0, b1, b2)` of a point whose direction
    /// from `p` is uniform over the spherical triangle.
    ///
    /// Arvo's construction: `u0` picks the sub-triangle `A b c'` of area
    /// `A' = u0 A` (eq. 5: solve `A' = alpha + beta' + gamma' - pi` for the
    /// point `c'` on arc `ac`), then `u1` picks a point on the arc `b c'`
    /// uniformly in `1 - cos` (eq. 7).
    pub fn sample(&self, u: Vec2) -> Option<[f32; 3]> {
        let (a, b, c) = (self.a, self.b, self.c);
        let n_ab = a.cross(b).try_normalize()?;
        let n_bc = b.cross(c).try_normalize()?;
        let n_ca = c.cross(a).try_normalize()?;
        let angle = |x: DVec3, y: DVec3| x.dot(y).clamp(-1.0, 1.0).acos();
        let alpha = angle(n_ab, -n_ca);
        let beta = angle(n_bc, -n_ab);
        let gamma = angle(n_ca, -n_bc);
        let pi = std::f64::consts::PI;
        // A' + pi, interpolated between 0 + pi and A + pi.
        let ap_pi = pi + f64::from(u.x) * (alpha + beta + gamma - pi);
        let (sin_alpha, cos_alpha) = alpha.sin_cos();
        let (sin_ap, cos_ap) = ap_pi.sin_cos();
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
        let e1 = self.v[1] - self.v[0];
        let e2 = self.v[2] - self.v[0];
        let s1 = w.cross(e2);
        let div = s1.dot(e1);
        if div == 0.0 {
            return None;
        }
        let s = self.p - self.v[0];
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
