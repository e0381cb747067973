//! Chi-square tests of lobes far narrower than a bin.
//!
//! A glossy lobe of width 1e-3 rad (roughness 1e-3, Blinn exponent 1e6)
//! falls inside one bin of a 100x100 grid on the sphere, and near the pole
//! the (cos theta, phi) grid is coarsest in angle, so neither the histogram
//! nor the quadrature of the pdf resolve it. The test is done instead on a
//! bijective image of the sphere that magnifies the lobe: rotate its centre
//! to the pole, scale the stereographic radius `r = tan(theta/2)` by `k`
//! (a conformal map, so the lobe keeps its shape), and rotate the pole to
//! the equator where the grid is finest. The samples are mapped forward;
//! the pdf is evaluated at the preimage of each quadrature node and
//! divided by the Jacobian `d(omega')/d(omega) = (k (1 + r^2) / (1 +
//! k^2 r^2))^2`, so the transformed pair is exactly as right or wrong as
//! the original.
//!
//! Centre and width come from a pilot batch drawn with another seed, so
//! the map does not depend on the samples it tests.

use lumis_core::glam::DVec3;
use lumis_core::{Vec2, Vec3};
use lumis_sampling::Pcg32;

use crate::chi_square::{chi_square, ChiSquareConfig, ChiSquareReport};

/// The magnified lobe spans about this angle (radians) after the map.
const TARGET_WIDTH: f64 = 0.5;
/// Lobes wider than `TARGET_WIDTH / MIN_ZOOM` are tested as they are.
const MIN_ZOOM: f64 = 4.0;

/// The map `d -> d'` for one lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeZoom {
    /// Orthonormal frame whose `z` is the lobe centre.
    x: DVec3,
    y: DVec3,
    z: DVec3,
    k: f64,
}

impl LobeZoom {
    pub fn new(centre: Vec3, k: f64) -> Self {
        let z = centre.as_dvec3().normalize();
        let helper = if z.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let x = helper.cross(z).normalize();
        let y = z.cross(x);
        Self { x, y, z, k }
    }

    /// The magnification factor.
    pub fn k(&self) -> f64 {
        self.k
    }

    /// Scales the stereographic radius of `v` (local frame, pole = centre)
    /// by `s`; returns the new local vector and `r`, `r'`.
    fn scale(v: DVec3, s: f64) -> (DVec3, f64, f64) {
        let sin = (v.x * v.x + v.y * v.y).sqrt();
        if sin == 0.0 {
            // The pole stays put (r = 0), and so does the antipode (r = inf).
            let r = if v.z > 0.0 { 0.0 } else { f64::INFINITY };
            return (v, r, r);
        }
        // r = tan(theta/2) = sin / (1 + cos), stable except at the antipode.
        let r = sin / (1.0 + v.z);
        let r2 = s * r;
        let (z, sin2) = if r2.is_finite() {
            let d = 1.0 + r2 * r2;
            ((1.0 - r2 * r2) / d, 2.0 * r2 / d)
        } else {
            (-1.0, 0.0)
        };
        (DVec3::new(v.x / sin * sin2, v.y / sin * sin2, z), r, r2)
    }

    /// Local frame (pole = centre) -> the grid's frame (pole on the equator).
    fn to_grid(v: DVec3) -> DVec3 {
        DVec3::new(v.z, v.x, v.y)
    }

    fn from_grid(v: DVec3) -> DVec3 {
        DVec3::new(v.y, v.z, v.x)
    }

    pub fn forward(&self, d: Vec3) -> Vec3 {
        let d = d.as_dvec3().normalize();
        let local = DVec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z));
        let (zoomed, _, _) = Self::scale(local, self.k);
        Self::to_grid(zoomed).normalize().as_vec3()
    }

    /// The preimage of `d'` and the Jacobian `d(omega')/d(omega)` there.
    pub fn inverse(&self, d: Vec3) -> (Vec3, f64) {
        let local = Self::from_grid(d.as_dvec3());
        let (v, r2, r) = Self::scale(local, 1.0 / self.k);
        let world = (self.x * v.x + self.y * v.y + self.z * v.z).normalize();
        let jacobian = if r2.is_finite() {
            (self.k * (1.0 + r * r) / (1.0 + r2 * r2)).powi(2)
        } else {
            // At the antipode the factor tends to 1/k^2.
            1.0 / (self.k * self.k)
        };
        (world.as_vec3(), jacobian)
    }

    /// The map suited to what `sample` draws: `None` if the lobe is wide
    /// enough for the plain test (or there is no single lobe).
    pub fn for_sampler(
        sample: &mut dyn FnMut(f32, Vec2) -> Option<Vec3>,
        seed: u64,
    ) -> Option<Self> {
        let mut rng = Pcg32::new(seed ^ 0x9e37_79b9, 0x10be);
        let mut pilot = Vec::with_capacity(20_000);
        for _ in 0..20_000 {
            let u1 = rng.next_f32();
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(d) = sample(u1, u2).filter(|d| d.is_finite()) {
                pilot.push(d.as_dvec3());
            }
        }
        if pilot.len() < 1000 {
            return None;
        }
        let mean: DVec3 = pilot.iter().sum::<DVec3>() / pilot.len() as f64;
        // A diffuse or two-lobed distribution has a short mean vector.
        if mean.length() < 0.5 {
            return None;
        }
        let centre = mean.normalize();
        let mut angles: Vec<f64> = pilot
            .iter()
            .map(|d| d.normalize().dot(centre).clamp(-1.0, 1.0).acos())
            .collect();
        angles.sort_by(f64::total_cmp);
        let width = angles[angles.len() * 9 / 10];
        let k = TARGET_WIDTH / width.max(1e-9);
        (k >= MIN_ZOOM).then(|| Self::new(centre.as_vec3(), k.min(1e6)))
    }
}

/// [`chi_square`] of `(sample, pdf)`, on the magnified image of the lobe
/// when it is narrow (see the module docs); the report says which in
/// `zoom` (1 = no magnification).
pub fn chi_square_zoomed(
    mut sample: impl FnMut(f32, Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    cfg: &ChiSquareConfig,
) -> (ChiSquareReport, f64) {
    match LobeZoom::for_sampler(&mut sample, cfg.seed) {
        None => (chi_square(sample, pdf, cfg), 1.0),
        Some(zoom) => {
            let report = chi_square(
                |u1, u2| sample(u1, u2).map(|d| zoom.forward(d)),
                |d| {
                    let (pre, jacobian) = zoom.inverse(d);
                    (pdf(pre) as f64 / jacobian) as f32
                },
                cfg,
            );
            (report, zoom.k())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::warp;

    #[test]
    fn forward_and_inverse_are_inverse_with_the_right_jacobian() {
        let zoom = LobeZoom::new(Vec3::new(0.3, -0.2, 0.9).normalize(), 50.0);
        for d in [
            Vec3::new(0.31, -0.19, 0.9),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(-0.5, 0.5, 0.1),
        ] {
            let d = d.normalize();
            let (back, _) = zoom.inverse(zoom.forward(d));
            assert!((back - d).length() < 1e-5, "{d:?} -> {back:?}");
        }
        // Jacobian by finite areas: a tiny cap around a point.
        let d = Vec3::new(0.305, -0.2, 0.9).normalize();
        let (_, j) = zoom.inverse(zoom.forward(d));
        let e1 = d.any_orthonormal_vector();
        let e2 = d.cross(e1);
        let h = 1e-4;
        let a = zoom.forward((d + e1 * h).normalize()) - zoom.forward(d);
        let b = zoom.forward((d + e2 * h).normalize()) - zoom.forward(d);
        let area_ratio = a.cross(b).length() as f64 / (h * h) as f64;
        assert!((area_ratio / j - 1.0).abs() < 2e-2, "{area_ratio} vs {j}");
    }

    #[test]
    fn a_narrow_correct_lobe_passes_and_a_slightly_wrong_one_fails() {
        // A cone of half-angle 1e-3 rad around a tilted axis, uniform
        // within: its pdf is 1 / (2 pi (1 - cos)).
        let axis = Vec3::new(0.6, 0.0, 0.8);
        let frame = lumis_core::Frame::from_z(axis);
        let h = warp::one_minus_cos_from_sin2(1e-6);
        let cfg = ChiSquareConfig {
            z_bins: 100,
            phi_bins: 100,
            samples: 1_000_000,
            ..Default::default()
        };
        // In f64: 1 - cos of a 1e-3 rad cone is 5e-7, a few f32 ulps of 1
        // (and the f32 axis is itself 1e-7 away from unit length).
        let unit_axis = axis.as_dvec3().normalize();
        let pdf = move |d: Vec3| {
            let c = d.as_dvec3().normalize().dot(unit_axis);
            if 1.0 - c <= h as f64 {
                warp::uniform_cone_pdf(h)
            } else {
                0.0
            }
        };
        let (good, k) = chi_square_zoomed(
            |_, u| Some(frame.to_world(warp::square_to_uniform_cone(u, h))),
            pdf,
            &cfg,
        );
        assert!(
            k > 100.0 && good.passed,
            "zoom {k}: p {} integral {} {:?}",
            good.p_value,
            good.pdf_integral,
            good.defect
        );
        // Samples bunched towards the axis (u^1.1): must be caught.
        let (bad, _) = chi_square_zoomed(
            |_, u| {
                Some(frame.to_world(warp::square_to_uniform_cone(
                    Vec2::new(u.x.powf(1.1), u.y),
                    h,
                )))
            },
            pdf,
            &cfg,
        );
        assert!(!bad.passed, "p {}", bad.p_value);
    }
}
