//! The projected deviation vector (PDV) parameterization of a pair of
//! directions of the upper hemisphere.
//!
//! For a fixed direction `v` (the one a BSDF samples from) and a free
//! direction `w`, the deviation vector is the projection of `v + w` (the
//! unnormalised half vector) onto the tangent plane:
//!
//! ```text
//! d = (v_x + w_x, v_y + w_y) = rho (cos(phi_v + phi), sin(phi_v + phi))
//! ```
//!
//! It is zero exactly at the mirror direction `w = (-v_x, -v_y, v_z)`, so a
//! glossy lobe sits around `rho = 0` for every `v`, as it does around the
//! pole of the half vector. The pair is `(v; rho, phi)`: `v` in its
//! spherical coordinates, or `theta_v` alone for an isotropic BRDF, whose
//! value does not change when both directions turn about the normal (which
//! is why `phi` is measured from `phi_v`). `rho` ranges over `[0, 1 + sin
//! theta_v]`, the disk of radius 1 about `v`'s projection.
//!
//! The map is one-to-one on the upper hemisphere of `w` only: `w_z =
//! sqrt(1 - |d - v_t|^2)` takes the positive root. Its Jacobian follows from
//! the projection onto the tangent plane, `dA = w_z d omega_w` (the
//! projected-solid-angle measure), and the polar coordinates of `d`,
//! `dA = rho d rho d phi` (a translation by `v_t` does not change area):
//!
//! ```text
//! d omega_w = rho / w_z  d rho d phi
//! ```
//!
//! zero at `rho = 0` and unbounded at grazing `w`. The formulas are
//! symmetric in `v` and `w` (the sum is), so the roles may be swapped: `d
//! omega_o / (d rho d phi) = rho / cos theta_o` given `wi`.
//!
//! The tests check the Jacobian by differentiating the map numerically,
//! down to `rho -> 0`, up to `rho` at its maximum, and at grazing `v`.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};

/// The free direction `w` for the deviation `(rho, phi)` about `v`, and the
/// Jacobian `d omega_w / (d rho d phi)`; `None` where `d` leaves the disk
/// of radius 1 about `v`'s projection (no direction of the upper
/// hemisphere has that deviation). In f64: [`w_from_pdv`] is the f32 face.
#[inline]
pub fn w_from_pdv_f64(v: DVec3, rho: f64, phi: f64) -> Option<(DVec3, f64)> {
    let phi_v = v.y.atan2(v.x);
    let (s, c) = (phi_v + phi).sin_cos();
    let (x, y) = (rho * c - v.x, rho * s - v.y);
    let z2 = 1.0 - x * x - y * y;
    if z2 <= 0.0 {
        return None;
    }
    let z = z2.sqrt();
    Some((DVec3::new(x, y, z), pdv_jacobian_f64(rho, z)))
}

/// The inverse of [`w_from_pdv_f64`]: `(rho, phi, d omega_w / (d rho d
/// phi))` with `phi` in `[0, 2 pi)`; `None` for `w` below the horizon.
#[inline]
pub fn pdv_from_w_f64(v: DVec3, w: DVec3) -> Option<(f64, f64, f64)> {
    if w.z <= 0.0 {
        return None;
    }
    let (x, y) = (v.x + w.x, v.y + w.y);
    let rho = x.hypot(y);
    let phi_v = v.y.atan2(v.x);
    let phi = (y.atan2(x) - phi_v).rem_euclid(2.0 * PI);
    let phi = if phi >= 2.0 * PI { 0.0 } else { phi };
    Some((rho, phi, pdv_jacobian_f64(rho, w.z)))
}

/// `d omega_w / (d rho d phi) = rho / w_z`.
#[inline]
pub fn pdv_jacobian_f64(rho: f64, w_z: f64) -> f64 {
    rho / w_z
}

/// [`w_from_pdv_f64`] in f32: `w` and `d omega_w / (d rho d phi)`.
#[inline]
pub fn w_from_pdv(v: Vec3, rho: f32, phi: f32) -> Option<(Vec3, f32)> {
    let (w, jacobian) = w_from_pdv_f64(v.as_dvec3(), rho as f64, phi as f64)?;
    Some((w.as_vec3(), jacobian as f32))
}

/// [`pdv_from_w_f64`] in f32: `(rho, phi, d omega_w / (d rho d phi))`.
#[inline]
pub fn pdv_from_w(v: Vec3, w: Vec3) -> Option<(f32, f32, f32)> {
    let (rho, phi, jacobian) = pdv_from_w_f64(v.as_dvec3(), w.as_dvec3())?;
    // phi rounds up to 2 pi in f32 just below it.
    let phi = (phi as f32).min(std::f32::consts::TAU - f32::EPSILON * 8.0);
    Some((rho as f32, phi, jacobian as f32))
}

/// The largest `rho` about `v`: `1 + sin theta_v`.
#[inline]
pub fn pdv_max_rho(v: Vec3) -> f32 {
    1.0 + (v.x * v.x + v.y * v.y).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::halfdiff::spherical_direction;
    use crate::rng::Pcg32;

    fn dir64(theta: f64, phi: f64) -> DVec3 {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        DVec3::new(st * cp, st * sp, ct)
    }

    /// `|dw/drho x dw/dphi|` by central differences with steps small
    /// against `rho` and against `w_z^2` (the curvature of `w_z` near the
    /// rim goes as `1 / w_z^3`) but not lost to rounding.
    fn numeric_jacobian(v: DVec3, rho: f64, phi: f64) -> Option<f64> {
        let at = |r: f64, p: f64| w_from_pdv_f64(v, r, p).map(|(w, _)| w);
        let w_z = at(rho, phi)?.z;
        // Each step moves w by about 1e-4 w_z^2 at most.
        let e_rho = 1e-4 * rho.min(w_z * w_z).min(1.0);
        let e_phi = 1e-4 * (w_z * w_z / rho).min(1.0);
        let (rp, rm, pp, pm) = (
            at(rho + e_rho, phi)?,
            at(rho - e_rho, phi)?,
            at(rho, phi + e_phi)?,
            at(rho, phi - e_phi)?,
        );
        Some(
            ((rp - rm) / (2.0 * e_rho))
                .cross((pp - pm) / (2.0 * e_phi))
                .length(),
        )
    }

    #[test]
    fn jacobian_by_numerical_differentiation_down_to_the_extremes() {
        let mut rng = Pcg32::new(17, 3);
        let mut checked = 0;
        // Interior points, then grazing v, rho -> 0 and rho -> its maximum
        // (where w grazes).
        let mut cases: Vec<(f64, f64, f64, f64)> = (0..400)
            .map(|_| {
                let theta_v = rng.next_f32() as f64 * 1.57;
                let max = 1.0 + theta_v.sin();
                (
                    theta_v,
                    rng.next_f32() as f64 * 2.0 * PI,
                    (0.01 + 0.98 * rng.next_f32() as f64) * max,
                    rng.next_f32() as f64 * 2.0 * PI,
                )
            })
            .collect();
        for theta_v in [0.0, 0.7, 1.5, std::f64::consts::FRAC_PI_2 - 1e-4] {
            let max = 1.0 + f64::sin(theta_v);
            for rho in [1e-6, 1e-3, max * (1.0 - 1e-3), max * (1.0 - 1e-6)] {
                // phi = 0 points away from v's projection, where rho
                // reaches its maximum.
                cases.push((theta_v, 0.4, rho, 0.0));
            }
        }
        for (theta_v, phi_v, rho, phi) in cases {
            let v = dir64(theta_v, phi_v);
            let Some((w, analytic)) = w_from_pdv_f64(v, rho, phi) else {
                continue;
            };
            let Some(numeric) = numeric_jacobian(v, rho, phi) else {
                continue;
            };
            assert!(
                (numeric - analytic).abs() <= 1e-5 * analytic + 1e-12,
                "theta_v {theta_v}, rho {rho}, phi {phi}, w_z {}: numeric {numeric}, analytic {analytic}",
                w.z
            );
            let (rho2, phi2, jacobian2) = pdv_from_w_f64(v, w).unwrap();
            assert!((rho2 - rho).abs() < 1e-12 * rho.max(1.0), "{rho} {rho2}");
            let dphi = (phi2 - phi).rem_euclid(2.0 * PI);
            assert!(
                rho < 1e-5 || dphi.min(2.0 * PI - dphi) < 1e-9 / rho,
                "{phi} {phi2}"
            );
            assert!((jacobian2 - analytic).abs() <= 1e-9 * analytic + 1e-15);
            checked += 1;
        }
        assert!(checked > 200, "only {checked} points checked");
    }

    #[test]
    fn the_jacobian_integrates_to_the_hemisphere() {
        // int int rho / w_z d rho d phi over the disk = 2 pi for any v. The
        // midpoint rule along each ray phi after the substitution rho =
        // r(phi) (1 - t^2), with r(phi) where the ray leaves the disk,
        // which makes the 1 / sqrt singularity at the rim bounded.
        for theta_v in [0.0f64, 0.6, 1.2, 1.56] {
            let v = dir64(theta_v, 1.0);
            let n = 400;
            let mut sum = 0.0;
            for j in 0..n {
                let phi = (j as f64 + 0.5) / n as f64 * 2.0 * PI;
                // |rho u - v_t| = 1 with u the ray's direction.
                let (s, c) = (1.0f64 + phi).sin_cos();
                let b = c * v.x + s * v.y;
                let r = b + (b * b - v.x * v.x - v.y * v.y + 1.0).sqrt();
                for i in 0..n {
                    let t = (i as f64 + 0.5) / n as f64;
                    let (_, jacobian) = w_from_pdv_f64(v, r * (1.0 - t * t), phi).unwrap();
                    sum += jacobian * 2.0 * r * t;
                }
            }
            sum *= 2.0 * PI / (n * n) as f64;
            assert!(
                (sum - 2.0 * PI).abs() < 1e-3,
                "theta_v {theta_v}: {sum} != 2 pi"
            );
        }
    }

    #[test]
    fn f32_faces_round_trip_and_the_mirror_is_the_origin() {
        let mut rng = Pcg32::new(5, 8);
        for _ in 0..1000 {
            let v = spherical_direction(
                rng.next_f32() * 1.57,
                rng.next_f32() * std::f32::consts::TAU,
            );
            let w = spherical_direction(
                rng.next_f32() * 1.55,
                rng.next_f32() * std::f32::consts::TAU,
            );
            let (rho, phi, jac) = pdv_from_w(v, w).unwrap();
            assert!((0.0..std::f32::consts::TAU).contains(&phi));
            assert!(rho <= pdv_max_rho(v) + 1e-6);
            let (w2, jac2) = w_from_pdv(v, rho, phi).unwrap();
            assert!((w - w2).length() < 1e-4, "{w} {w2}");
            assert!((jac - jac2).abs() <= 1e-3 * jac, "{jac} {jac2}");
        }
        let v = spherical_direction(0.8, 2.0);
        let mirror = Vec3::new(-v.x, -v.y, v.z);
        let (rho, _, jac) = pdv_from_w(v, mirror).unwrap();
        assert!(rho < 1e-7 && jac < 1e-6, "{rho} {jac}");
        assert!(pdv_from_w(v, Vec3::new(0.0, 0.6, -0.8)).is_none());
        assert!(w_from_pdv(Vec3::Z, 1.01, 0.0).is_none());
    }
}
