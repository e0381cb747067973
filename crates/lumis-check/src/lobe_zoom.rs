//! Chi-square tests of lobes far narrower than a bin.
//!
//! A glossy lobe of width 1e-3 rad (roughness 1e-3, Blinn exponent 1e6)
//! falls inside one bin of a 100x100 grid on the sphere, and near the pole
//! the (cos theta, phi) grid is coarsest in angle, so neither the histogram
//! nor the quadrature of the pdf resolve it. The test is done instead on a
//! bijective image of the sphere that magnifies the lobe: rotate its centre
//! to the pole, stretch the polar angle by `k` out to `theta_1` (two lobe
//! widths), let the stretch relax smoothly to a compression `s` by
//! `theta_2` (six widths), and compress the rest of the sphere linearly
//! into what is left (`g(theta) = k theta`, then `g'` falling linearly from
//! `k` to `s`, then `g(theta) = pi - s (pi - theta)`); then rotate the pole
//! to the equator where the grid is finest. Because the far part is only
//! compressed by `s` (about 1/3), a wide lobe beside the narrow one (the
//! diffuse base of a coated material) stays resolved too, and because `g`
//! is C1 the mapped pdf has no jump for the quadrature to chase. The
//! samples are mapped forward; the pdf is evaluated at the preimage of each
//! quadrature node and divided by the Jacobian `d(omega')/d(omega) =
//! g'(theta) sin g(theta) / sin theta`, so the transformed pair is exactly
//! as right or wrong as the original.
//!
//! Centre and width come from a pilot batch drawn with another seed, so
//! the map does not depend on the samples it tests: the centre is where
//! the pdf peaks among the pilot samples, the width the spread of the
//! samples whose pdf is within a factor 100 of that peak. A lobe too wide
//! to need magnifying but lying over a pole is still turned to the
//! equator, unmagnified.

use lumis_core::glam::DVec3;
use lumis_core::{Vec2, Vec3};
use lumis_sampling::Pcg32;

use crate::chi_square::{chi_square, ChiSquareConfig, ChiSquareReport};

/// The magnified lobe spans about this angle (radians) after the map.
const TARGET_WIDTH: f64 = 0.5;
/// The full magnification holds to this many lobe widths from the centre,
/// and the compression is reached at `RELAXED_WIDTHS`.
const MAGNIFIED_WIDTHS: f64 = 2.0;
const RELAXED_WIDTHS: f64 = 6.0;
/// Lobes wider than `TARGET_WIDTH / MIN_ZOOM` are not magnified.
const MIN_ZOOM: f64 = 4.0;
/// Lobes too wide to magnify but narrower than this (radians) that lie
/// over a pole are turned to the equator unmagnified: the grid's polar row
/// (0.2 rad of the 100 bins in `cos theta`) is too coarse for the
/// quadrature of their steps (a tabulated density at normal incidence).
/// Wider lobes span enough rows as they are.
const ROTATED_WIDTH: f64 = 0.5;
/// A centre this close to a pole (cos of 0.01 rad) is taken to be it.
const POLE_SNAP_COS: f64 = 0.99995;
const PILOT_SAMPLES: usize = 20_000;
/// A peak holding less than this share of the pilot samples is not a lobe
/// to magnify (the `1 / <wo, h>` spike of a wide lobe at grazing angles),
/// nor one of fewer samples than `MIN_PEAK_SAMPLES` (too few to measure a
/// width: a hemisphere that receives almost nothing).
const MIN_PEAK_SHARE: f64 = 0.02;
const MIN_PEAK_SAMPLES: usize = 100;

/// The map `d -> d'` for one lobe.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LobeZoom {
    /// Orthonormal frame whose `z` is the lobe centre.
    x: DVec3,
    y: DVec3,
    z: DVec3,
    k: f64,
    theta_1: f64,
    theta_2: f64,
    /// Slope of the compressed part, from `g(pi) = pi`.
    s: f64,
}

impl LobeZoom {
    /// Magnifies the polar angle around `centre` by `k` out to `theta_1`,
    /// relaxing to the compression by `theta_2`. Needs `k (theta_1 +
    /// theta_2) / 2 < pi`.
    pub fn new(centre: Vec3, k: f64, theta_1: f64, theta_2: f64) -> Self {
        use std::f64::consts::PI;
        let z = centre.as_dvec3().normalize();
        let helper = if z.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
        let x = helper.cross(z).normalize();
        let y = z.cross(x);
        // g(theta_2) = k (theta_1 + theta_2) / 2 + s (theta_2 - theta_1) / 2
        // must equal pi - s (pi - theta_2).
        let span = theta_2 - theta_1;
        let s = (PI - 0.5 * k * (theta_1 + theta_2)) / (PI - theta_2 + 0.5 * span);
        debug_assert!(s > 0.0 && span > 0.0, "k {k}, theta {theta_1}..{theta_2}");
        Self {
            x,
            y,
            z,
            k,
            theta_1,
            theta_2,
            s,
        }
    }

    /// Turns `centre` to the equator without magnifying: `k = s = 1` makes
    /// `g` the identity whatever `theta_1 < theta_2`.
    pub fn rotation(centre: Vec3) -> Self {
        Self::new(centre, 1.0, 1.0, 2.0)
    }

    /// The magnification factor at the centre.
    pub fn k(&self) -> f64 {
        self.k
    }

    /// `g(theta)` and the Jacobian `g'(theta) sin g(theta) / sin theta`;
    /// in the compressed part from the distance to the antipode, so that
    /// the ratio of two tiny sines stays exact there.
    fn map_angle(&self, theta: f64, antipode_distance: f64) -> (f64, f64) {
        use std::f64::consts::PI;
        let ratio = |g: f64| {
            if theta == 0.0 {
                self.k
            } else {
                g.sin() / theta.sin()
            }
        };
        if theta <= self.theta_1 {
            let g = self.k * theta;
            (g, self.k * ratio(g))
        } else if theta <= self.theta_2 {
            let x = theta - self.theta_1;
            let span = self.theta_2 - self.theta_1;
            let slope = self.k + (self.s - self.k) * x / span;
            let g = self.k * theta + 0.5 * (self.s - self.k) * x * x / span;
            (g, slope * ratio(g))
        } else {
            let d = self.s * antipode_distance;
            let ratio = if antipode_distance == 0.0 {
                self.s
            } else {
                d.sin() / antipode_distance.sin()
            };
            (PI - d, self.s * ratio)
        }
    }

    fn inverse_angle(&self, g: f64) -> f64 {
        use std::f64::consts::PI;
        let span = self.theta_2 - self.theta_1;
        let g_1 = self.k * self.theta_1;
        let g_2 = PI - self.s * (PI - self.theta_2);
        if g <= g_1 {
            g / self.k
        } else if g <= g_2 {
            // (s - k) / (2 span) x^2 + k x = g - g_1, by the root that
            // cancels nothing.
            let a = 0.5 * (self.s - self.k) / span;
            let c = g - g_1;
            let disc = (self.k * self.k + 4.0 * a * c).max(0.0);
            self.theta_1 + 2.0 * c / (self.k + disc.sqrt())
        } else {
            PI - (PI - g) / self.s
        }
    }

    /// Moves `v` (local frame, pole = centre) to polar angle `theta'`,
    /// keeping its azimuth.
    fn with_polar_angle(v: DVec3, theta: f64) -> DVec3 {
        let sin = (v.x * v.x + v.y * v.y).sqrt();
        let (cos_phi, sin_phi) = if sin > 0.0 {
            (v.x / sin, v.y / sin)
        } else {
            (1.0, 0.0)
        };
        DVec3::new(theta.sin() * cos_phi, theta.sin() * sin_phi, theta.cos())
    }

    /// Polar angle of `v` and its distance from the antipode, both by atan2
    /// (exact near either pole, unlike acos).
    fn polar(v: DVec3) -> (f64, f64) {
        let sin = (v.x * v.x + v.y * v.y).sqrt();
        (sin.atan2(v.z), sin.atan2(-v.z))
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
        let (theta, antipode) = Self::polar(local);
        let (g, _) = self.map_angle(theta, antipode);
        Self::to_grid(Self::with_polar_angle(local, g)).as_vec3()
    }

    /// The preimage of `d'` and the Jacobian `d(omega')/d(omega)` there.
    pub fn inverse(&self, d: Vec3) -> (Vec3, f64) {
        let local = Self::from_grid(d.as_dvec3().normalize());
        let (g, _) = Self::polar(local);
        let theta = self.inverse_angle(g);
        let v = Self::with_polar_angle(local, theta);
        let (_, jacobian) = self.map_angle(theta, std::f64::consts::PI - theta);
        let world = (self.x * v.x + self.y * v.y + self.z * v.z).normalize();
        (world.as_vec3(), jacobian)
    }

    /// The map suited to what `sample` draws with density `pdf`: `None` if
    /// there is no peak narrow enough to need it.
    pub fn for_sampler(
        sample: &mut dyn FnMut(f32, Vec2) -> Option<Vec3>,
        pdf: &dyn Fn(Vec3) -> f32,
        seed: u64,
    ) -> Option<Self> {
        let mut rng = Pcg32::new(seed ^ 0x9e37_79b9, 0x10be);
        let mut pilot = Vec::with_capacity(PILOT_SAMPLES);
        for _ in 0..PILOT_SAMPLES {
            let u1 = rng.next_f32();
            let u2 = Vec2::new(rng.next_f32(), rng.next_f32());
            if let Some(d) = sample(u1, u2).filter(|d| d.is_finite()) {
                let p = pdf(d) as f64;
                if p.is_finite() && p > 0.0 {
                    pilot.push((d.as_dvec3().normalize(), p));
                }
            }
        }
        let peak = pilot.iter().map(|&(_, p)| p).fold(0.0, f64::max);
        // The core of the peak locates the centre (its mean is inside the
        // lobe even where the horizon cuts it); the samples within a factor
        // 100 of the peak density measure the width.
        let core: DVec3 = pilot
            .iter()
            .filter(|&&(_, p)| p >= 0.5 * peak)
            .map(|&(d, _)| d)
            .sum();
        let centre = core.try_normalize()?;
        let mut angles: Vec<f64> = pilot
            .iter()
            .filter(|&&(_, p)| p >= 1e-2 * peak)
            .map(|&(d, _)| d.dot(centre).clamp(-1.0, 1.0).acos())
            .collect();
        if angles.len() < MIN_PEAK_SAMPLES
            || (angles.len() as f64) < MIN_PEAK_SHARE * pilot.len() as f64
        {
            return None;
        }
        angles.sort_by(f64::total_cmp);
        let width = angles[angles.len() * 9 / 10].max(1e-9);
        let k = (TARGET_WIDTH / width).min(1e6);
        if k >= MIN_ZOOM {
            Some(Self::new(
                centre.as_vec3(),
                k,
                MAGNIFIED_WIDTHS * width,
                RELAXED_WIDTHS * width,
            ))
        } else if width < ROTATED_WIDTH && Self::polar(centre).0.min(Self::polar(-centre).0) < width
        {
            // At normal incidence the centre is the pole itself: taking it
            // exactly keeps the hemisphere's rim on bin edges.
            let centre = if centre.z.abs() > POLE_SNAP_COS {
                DVec3::Z * centre.z.signum()
            } else {
                centre
            };
            Some(Self::rotation(centre.as_vec3()))
        } else {
            None
        }
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
    match LobeZoom::for_sampler(&mut sample, &pdf, cfg.seed) {
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
        let zoom = LobeZoom::new(Vec3::new(0.3, -0.2, 0.9).normalize(), 50.0, 0.02, 0.05);
        for d in [
            Vec3::new(0.31, -0.19, 0.9),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(-0.5, 0.5, 0.1),
        ] {
            let d = d.normalize();
            let (back, _) = zoom.inverse(zoom.forward(d));
            assert!((back - d).length() < 1e-5, "{d:?} -> {back:?}");
        }
        // Jacobian by finite areas around a point in the magnified part
        // and one in the compressed part.
        for d in [
            Vec3::new(0.305, -0.2, 0.9),
            Vec3::new(0.33, -0.2, 0.9),
            Vec3::new(-0.5, 0.4, 0.2),
        ] {
            let d = d.normalize();
            let (_, j) = zoom.inverse(zoom.forward(d));
            let e1 = d.any_orthonormal_vector();
            let e2 = d.cross(e1);
            let h = 1e-4;
            let a = zoom.forward((d + e1 * h).normalize()) - zoom.forward(d);
            let b = zoom.forward((d + e2 * h).normalize()) - zoom.forward(d);
            let area_ratio = a.cross(b).length() as f64 / (h * h) as f64;
            assert!(
                (area_ratio / j - 1.0).abs() < 2e-2,
                "{d:?}: {area_ratio} vs {j}"
            );
        }
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
        // A lobe of 1e-3 rad is resolved: the kit does not excuse it.
        assert_eq!((good.unresolved(), bad.unresolved()), (None, None));
    }

    #[test]
    fn a_narrow_lobe_beside_a_wide_one_is_resolved() {
        // 10% in a cone of half-angle 1e-3 rad, 90% cosine-weighted: the
        // mixture of a coated material. The wide part must stay testable
        // after the map, and a wrong weight of the narrow part be caught.
        let axis = Vec3::new(0.0, 0.6, 0.8);
        let frame = lumis_core::Frame::from_z(axis);
        let h = warp::one_minus_cos_from_sin2(1e-6);
        let unit_axis = axis.as_dvec3().normalize();
        let pdf = move |d: Vec3| {
            let c = d.as_dvec3().normalize().dot(unit_axis);
            let cone = if 1.0 - c <= h as f64 {
                warp::uniform_cone_pdf(h)
            } else {
                0.0
            };
            0.1 * cone + 0.9 * warp::cosine_hemisphere_pdf(d.z.max(0.0))
        };
        let sample = |weight: f32| {
            move |u1: f32, u: Vec2| {
                Some(if u1 < weight {
                    frame.to_world(warp::square_to_uniform_cone(u, h))
                } else {
                    warp::square_to_cosine_hemisphere(u)
                })
            }
        };
        let cfg = ChiSquareConfig {
            samples: 1_000_000,
            ..Default::default()
        };
        let (good, k) = chi_square_zoomed(sample(0.1), pdf, &cfg);
        assert!(
            k > 100.0 && good.passed,
            "zoom {k}: p {} integral {} {:?}",
            good.p_value,
            good.pdf_integral,
            good.defect
        );
        let (bad, _) = chi_square_zoomed(sample(0.105), pdf, &cfg);
        assert!(!bad.passed, "p {}", bad.p_value);
        assert_eq!(bad.unresolved(), None);
    }
}
