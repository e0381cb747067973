//! Parameterizations of pairs of directions and the Jacobians between them.
//!
//! - in/out: `(wi, wo)`, each a direction of the local frame (`z` = normal),
//!   with `d omega = sin theta d theta d phi` in spherical coordinates.
//! - half/difference (Rusinkiewicz 1998, "A New Change of Variables for
//!   Efficient BRDF Representation"): the half vector `h = (wi + wo) / |wi +
//!   wo|` in spherical coordinates `(theta_h, phi_h)` and the difference
//!   vector `d`, which is `wi` seen from a frame that has `h` as its pole:
//!   `d = R_y(-theta_h) R_z(-phi_h) wi` (Rusinkiewicz section 3.1). An
//!   isotropic BRDF depends on `(theta_h, theta_d, phi_d)` only.
//!   `d omega_i d omega_o = 4 cos theta_d d omega_h d omega_d`.
//! - half vector about a fixed `wo` (Lawrence, Rusinkiewicz and Ramamoorthi
//!   2004, section 4.1): `wi = 2 <wo, h> h - wo` as a function of `h`, in
//!   coordinates `(w, phi) = (1 - cos theta_h, phi_h - phi_o)`, which are
//!   equal-area for `h` (`d omega_h = dw dphi`), so
//!   `d omega_i = 4 <wo, h> dw dphi` (Walter et al. 2007, eq. 14, for the
//!   reflection factor). `1 - cos theta_h` rather than `cos theta_h` keeps
//!   f32 precision at the pole, where glossy lobes put their mass: a lobe
//!   of width 1e-3 rad spans `w` ~ 5e-7, two ulps of `cos` near 1.
//!
//! The tests check each Jacobian by differentiating the maps numerically.

use std::f32::consts::PI;

use glam::Vec3;

/// A direction from spherical coordinates.
#[inline]
pub fn spherical_direction(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, st * sp, ct)
}

/// `(theta, phi)` of a unit vector, `phi` in `(-pi, pi]`. `theta` by
/// `atan2` so that it keeps its precision near the pole, where `acos`
/// loses half the digits.
#[inline]
pub fn spherical_angles(v: Vec3) -> (f32, f32) {
    let r = (v.x * v.x + v.y * v.y).sqrt();
    (r.atan2(v.z), v.y.atan2(v.x))
}

/// `d omega / (d theta d phi) = sin theta`.
#[inline]
pub fn spherical_jacobian(theta: f32) -> f32 {
    theta.sin().abs()
}

/// Rusinkiewicz's coordinates of a pair of directions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfDiff {
    pub theta_h: f32,
    pub phi_h: f32,
    pub theta_d: f32,
    pub phi_d: f32,
}

#[inline]
fn rotate_z(v: Vec3, angle: f32) -> Vec3 {
    let (s, c) = angle.sin_cos();
    Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

#[inline]
fn rotate_y(v: Vec3, angle: f32) -> Vec3 {
    let (s, c) = angle.sin_cos();
    Vec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

impl HalfDiff {
    /// The coordinates of `(wi, wo)`; `None` if they are opposite (no half
    /// vector). Computed in f64, and `theta_h`, `theta_d` from `wi + wo`
    /// and `|wi - wo|` (`|wi + wo| = 2 cos theta_d`, `|wi - wo| = 2 sin
    /// theta_d`), which do not depend on the order of the pair: a table
    /// lookup is then reciprocal to rounding of `phi_d` alone, even at
    /// grazing angles where the lobe is steep and f32 rotations would
    /// differ by 1e-3.
    #[inline]
    pub fn from_directions(wi: Vec3, wo: Vec3) -> Option<Self> {
        let (a, b) = (wi.as_dvec3(), wo.as_dvec3());
        let sum = a + b;
        let len = sum.length();
        if len <= 0.0 {
            return None;
        }
        let h = sum / len;
        let theta_h = (h.x * h.x + h.y * h.y).sqrt().atan2(h.z);
        let phi_h = h.y.atan2(h.x);
        let theta_d = (a - b).length().atan2(len);
        // d = R_y(-theta_h) R_z(-phi_h) wi.
        let (sp, cp) = phi_h.sin_cos();
        let r = glam::DVec3::new(cp * a.x + sp * a.y, -sp * a.x + cp * a.y, a.z);
        let (st, ct) = theta_h.sin_cos();
        let d = glam::DVec3::new(ct * r.x - st * r.z, r.y, st * r.x + ct * r.z);
        let phi_d = d.y.atan2(d.x);
        Some(Self {
            theta_h: theta_h as f32,
            phi_h: phi_h as f32,
            theta_d: theta_d as f32,
            phi_d: phi_d as f32,
        })
    }

    /// `(wi, wo)` from the coordinates: `wi = R_z(phi_h) R_y(theta_h) d`,
    /// `wo` its mirror image about `h`.
    #[inline]
    pub fn to_directions(&self) -> (Vec3, Vec3) {
        let h = spherical_direction(self.theta_h, self.phi_h);
        let d = spherical_direction(self.theta_d, self.phi_d);
        let wi = rotate_z(rotate_y(d, self.theta_h), self.phi_h);
        let wo = 2.0 * wi.dot(h) * h - wi;
        (wi, wo)
    }
}

/// `d omega_i d omega_o / (d omega_h d omega_d) = 4 cos theta_d`.
#[inline]
pub fn half_diff_jacobian(theta_d: f32) -> f32 {
    4.0 * theta_d.cos().abs()
}

/// The half-vector coordinates about a fixed `wo`: `wi` for the half
/// vector with `1 - cos theta_h = w` and azimuth `phi_o + phi`, with
/// `<wo, h>`; `None` if `h` faces away from `wo` (then `wi` would have
/// `-h`, not `h`, as its half vector and the map would not be one-to-one).
#[inline]
pub fn wi_from_half_coords(wo: Vec3, w: f32, phi: f32) -> Option<(Vec3, f32)> {
    let phi_o = wo.y.atan2(wo.x);
    // sin theta = sqrt(1 - (1 - w)^2) = sqrt(w (2 - w)), exact for small w.
    let s = (w * (2.0 - w)).max(0.0).sqrt();
    let (sp, cp) = (phi_o + phi).sin_cos();
    let h = Vec3::new(s * cp, s * sp, 1.0 - w);
    let wo_h = wo.dot(h);
    if wo_h <= 0.0 {
        return None;
    }
    Some((2.0 * wo_h * h - wo, wo_h))
}

/// The inverse of [`wi_from_half_coords`]: `(w, phi, <wo, h>)` with `phi`
/// in `[0, 2 pi)`; `None` if `wi = -wo`.
#[inline]
pub fn half_coords_from_wi(wo: Vec3, wi: Vec3) -> Option<(f32, f32, f32)> {
    let sum = wi.as_dvec3() + wo.as_dvec3();
    let len = sum.length();
    if len <= 0.0 {
        return None;
    }
    let h = sum / len;
    // 1 - cos theta = sin^2 theta / (1 + cos theta): no cancellation.
    let w = ((h.x * h.x + h.y * h.y) / (1.0 + h.z)) as f32;
    let phi_o = (wo.y as f64).atan2(wo.x as f64);
    let phi = (h.y.atan2(h.x) - phi_o).rem_euclid(2.0 * std::f64::consts::PI) as f32;
    let phi = if phi >= 2.0 * PI { 0.0 } else { phi };
    Some((w, phi, (0.5 * len) as f32))
}

/// `d omega_i / (dw dphi) = 4 <wo, h>` for the half-vector coordinates
/// (equal-area `h`, times the reflection factor).
#[inline]
pub fn half_coords_jacobian(wo_dot_h: f32) -> f32 {
    4.0 * wo_dot_h
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    /// Tangent basis of the unit sphere at `v`.
    fn tangents(v: Vec3) -> (Vec3, Vec3) {
        let a = if v.z.abs() < 0.9 { Vec3::Z } else { Vec3::X };
        let t = a.cross(v).normalize();
        (t, v.cross(t))
    }

    fn det4(m: [[f64; 4]; 4]) -> f64 {
        // Laplace expansion along the first row.
        let minor = |c: usize| {
            let rows: Vec<[f64; 3]> = (1..4)
                .map(|r| {
                    let mut row = [0.0; 3];
                    let mut k = 0;
                    for (j, &v) in m[r].iter().enumerate() {
                        if j != c {
                            row[k] = v;
                            k += 1;
                        }
                    }
                    row
                })
                .collect();
            rows[0][0] * (rows[1][1] * rows[2][2] - rows[1][2] * rows[2][1])
                - rows[0][1] * (rows[1][0] * rows[2][2] - rows[1][2] * rows[2][0])
                + rows[0][2] * (rows[1][0] * rows[2][1] - rows[1][1] * rows[2][0])
        };
        (0..4)
            .map(|c| if c % 2 == 0 { 1.0 } else { -1.0 } * m[0][c] * minor(c))
            .sum()
    }

    #[test]
    fn half_diff_round_trips() {
        let mut rng = Pcg32::new(7, 1);
        for _ in 0..1000 {
            let wi = spherical_direction(rng.next_f32() * 1.5, rng.next_f32() * 2.0 * PI);
            let wo = spherical_direction(rng.next_f32() * 1.5, rng.next_f32() * 2.0 * PI);
            let hd = HalfDiff::from_directions(wi, wo).unwrap();
            let (wi2, wo2) = hd.to_directions();
            assert!((wi - wi2).length() < 1e-4, "{wi} {wi2}");
            assert!((wo - wo2).length() < 1e-4, "{wo} {wo2}");
            // The pair reversed: same theta_h, theta_d; phi_d shifted by pi
            // (the reciprocity that lets isotropic tables fold phi_d).
            let rev = HalfDiff::from_directions(wo, wi).unwrap();
            assert!((rev.theta_h - hd.theta_h).abs() < 1e-4);
            assert!((rev.theta_d - hd.theta_d).abs() < 1e-4);
            let dphi = (rev.phi_d - hd.phi_d).rem_euclid(2.0 * PI);
            assert!(
                (dphi - PI).abs() < 1e-3,
                "phi_d {} vs {}",
                hd.phi_d,
                rev.phi_d
            );
        }
    }

    #[test]
    fn swapping_the_pair_keeps_theta_exactly_even_at_grazing() {
        let wo = Vec3::new(0.3, 0.953_939_2, 1e-4).normalize();
        let wi = Vec3::new(-0.954_660_8, -0.295_604_74, 0.035_222_962).normalize();
        let (a, b) = (
            HalfDiff::from_directions(wi, wo).unwrap(),
            HalfDiff::from_directions(wo, wi).unwrap(),
        );
        assert_eq!((a.theta_h, a.theta_d), (b.theta_h, b.theta_d));
        let dphi = (a.phi_d - b.phi_d).rem_euclid(2.0 * PI);
        assert!((dphi - PI).abs() < 1e-5, "{} {}", a.phi_d, b.phi_d);
    }

    #[test]
    fn spherical_jacobian_by_numerical_differentiation() {
        let e = 1e-2f32;
        for (theta, phi) in [(0.3, 0.1), (1.2, 2.0), (2.5, -1.0)] {
            let dt = (spherical_direction(theta + e, phi) - spherical_direction(theta - e, phi))
                / (2.0 * e);
            let dp = (spherical_direction(theta, phi + e) - spherical_direction(theta, phi - e))
                / (2.0 * e);
            let numeric = dt.cross(dp).length();
            let analytic = spherical_jacobian(theta);
            assert!(
                (numeric - analytic).abs() < 1e-4 * analytic.max(1.0),
                "{numeric} {analytic}"
            );
        }
    }

    #[test]
    fn half_diff_jacobian_by_numerical_differentiation() {
        // The 4D map (theta_h, phi_h, theta_d, phi_d) -> (wi, wo) on S^2 x
        // S^2: its derivative projected on tangent bases of wi and wo is a
        // 4x4 matrix whose determinant is the density ratio
        // d omega_i d omega_o / (dtheta_h dphi_h dtheta_d dphi_d)
        // = 4 cos theta_d sin theta_h sin theta_d.
        let mut rng = Pcg32::new(2, 9);
        let e = 1e-3f64;
        for _ in 0..200 {
            let x = [
                0.05 + rng.next_f32() as f64 * 1.4,
                rng.next_f32() as f64 * 6.0,
                0.05 + rng.next_f32() as f64 * 1.4,
                rng.next_f32() as f64 * 6.0,
            ];
            let map = |x: [f64; 4]| {
                HalfDiff {
                    theta_h: x[0] as f32,
                    phi_h: x[1] as f32,
                    theta_d: x[2] as f32,
                    phi_d: x[3] as f32,
                }
                .to_directions()
            };
            let (wi, wo) = map(x);
            let (ti, si) = tangents(wi);
            let (to, so) = tangents(wo);
            let mut m = [[0.0f64; 4]; 4];
            for k in 0..4 {
                let (mut a, mut b) = (x, x);
                a[k] += e;
                b[k] -= e;
                let ((wia, woa), (wib, wob)) = (map(a), map(b));
                let di = (wia - wib).as_dvec3() / (2.0 * e);
                let d_o = (woa - wob).as_dvec3() / (2.0 * e);
                m[0][k] = di.dot(ti.as_dvec3());
                m[1][k] = di.dot(si.as_dvec3());
                m[2][k] = d_o.dot(to.as_dvec3());
                m[3][k] = d_o.dot(so.as_dvec3());
            }
            let numeric = det4(m).abs();
            let analytic = (half_diff_jacobian(x[2] as f32)
                * spherical_jacobian(x[0] as f32)
                * spherical_jacobian(x[2] as f32)) as f64;
            assert!(
                (numeric - analytic).abs() < 2e-2 * analytic + 1e-4,
                "at {x:?}: numeric {numeric}, analytic {analytic}"
            );
        }
    }

    #[test]
    fn half_coords_jacobian_by_numerical_differentiation() {
        let mut rng = Pcg32::new(4, 4);
        let e = 1e-3f32;
        let mut checked = 0;
        for _ in 0..500 {
            let wo = spherical_direction(rng.next_f32() * 1.55, rng.next_f32() * 2.0 * PI);
            let z = 0.02 + 0.96 * rng.next_f32();
            let phi = rng.next_f32() * 2.0 * PI;
            let at = |z: f32, phi: f32| wi_from_half_coords(wo, z, phi).map(|(w, _)| w);
            let (Some((wi, wo_h)), Some(zp), Some(zm), Some(pp), Some(pm)) = (
                wi_from_half_coords(wo, z, phi),
                at(z + e, phi),
                at(z - e, phi),
                at(z, phi + e),
                at(z, phi - e),
            ) else {
                continue;
            };
            let numeric = ((zp - zm) / (2.0 * e))
                .cross((pp - pm) / (2.0 * e))
                .length();
            let analytic = half_coords_jacobian(wo_h);
            assert!(
                (numeric - analytic).abs() < 1e-2 * analytic + 1e-3,
                "wo {wo}, z {z}, phi {phi}: numeric {numeric}, analytic {analytic}"
            );
            // And the inverse map returns the coordinates.
            let (z2, phi2, wo_h2) = half_coords_from_wi(wo, wi).unwrap();
            assert!((z2 - z).abs() < 1e-4 && (wo_h2 - wo_h).abs() < 1e-4);
            let dphi = (phi2 - phi).rem_euclid(2.0 * PI);
            assert!(dphi.min(2.0 * PI - dphi) < 1e-3, "{phi} {phi2}");
            checked += 1;
        }
        assert!(checked > 300, "only {checked} points checked");
    }

    #[test]
    fn half_coords_keep_precision_at_the_pole() {
        let wo = spherical_direction(0.7, 0.4);
        for w in [1e-9f32, 1e-7, 1e-5] {
            let (wi, _) = wi_from_half_coords(wo, w, 1.0).unwrap();
            let (w2, _, _) = half_coords_from_wi(wo, wi).unwrap();
            assert!((w2 - w).abs() < 0.05 * w, "w {w} came back as {w2}");
        }
    }
}
