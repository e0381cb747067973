//! The grid the sampling precomputations tabulate `f cos theta_i` on.
//!
//! Rows are outgoing elevations: an isotropic BRDF depends on `wo` only
//! through `theta_o` once azimuths are measured from `phi_o`, so `n_o`
//! rows at `theta_o = (k + 1/2) / n_o * pi/2` cover every `wo`. Columns are
//! cells of a radial coordinate `r` and an azimuth `phi` about `wo`, in one
//! of two [`Parameterization`]s, both centred on the specular peak, where
//! a glossy lobe is compact and nearly the same for every `wo`, which is
//! what makes the matrix low-rank:
//!
//! - half-diff: the half vector, `(r, phi) = (1 - cos theta_h, phi_h -
//!   phi_o)` (Lawrence et al. 2004, section 4.1), `d omega_i = 4 <wo, h> dr
//!   dphi`; `r` bins have edges at `theta_h = (a / n_w)^2 pi/2`, the
//!   square-root spacing of the MERL format: a 64-bin grid resolves a lobe
//!   of width 0.01 rad with 4 bins and still covers the horizon.
//! - pdv: the projected deviation vector `(rho, phi)` of
//!   [`lumis_sampling::pdv`], with `r = rho^2`, which is equal-area for the
//!   deviation (`rho d rho dphi = dr dphi / 2`) so that a piecewise-constant
//!   density stays finite at the mirror direction `rho = 0`: `d omega_i =
//!   dr dphi / (2 cos theta_i)`. Edges at `rho = 2 (a / n_w)^2` (the same
//!   square-root spacing; `rho <= 1 + sin theta_o <= 2`).
//!
//! - in-out: the incident direction itself, `(r, phi) = (1 - cos theta_i,
//!   phi_i - phi_o)`, equal-area (`d omega_i = dr dphi`), edges uniform in
//!   `r`. The specular peak is not at a pole here but at `(1 - cos
//!   theta_o, pi)`, so a lobe moves across the grid with `wo`: the
//!   baseline the other two are measured against (Lawrence et al. 2004,
//!   figure 3).
//!
//! `phi` bins are uniform. Each entry is the integral of `f cos theta_i`
//! over the cell, in solid angle of `wi`, by `s x s` midpoints: the mass a
//! sampler should give the cell.

use std::f32::consts::{FRAC_PI_2, PI};

use indicatif::ProgressBar;
use lumis_api::{ParamChoice, Rgb, Vec3};
use lumis_sampling::halfdiff::{
    half_coords_from_wi, half_coords_jacobian, spherical_direction, wi_from_half_coords,
};
use lumis_sampling::pdv::{pdv_from_w, w_from_pdv};
use rayon::prelude::*;

/// The coordinates of `wi` about `wo` that the grid's columns cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum Parameterization {
    /// The half vector (Lawrence et al. 2004).
    HalfDiff,
    /// The projected deviation vector, `rho^2` and its azimuth.
    Pdv,
    /// The incident direction, `1 - cos theta_i` and its azimuth.
    InOut,
}

/// Resolution of the precomputation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    /// Outgoing elevations (rows).
    pub n_o: usize,
    /// Half-angle bins.
    pub n_w: usize,
    /// Azimuth bins over `[0, 2 pi)`.
    pub n_phi: usize,
    /// Midpoints per cell and axis for the cell integrals.
    pub supersamples: usize,
    /// The coordinates of the columns.
    pub parameterization: Parameterization,
}

impl Grid {
    pub fn columns(&self) -> usize {
        self.n_w * self.n_phi
    }

    /// The edges of the radial coordinate: `1 - cos theta_h` at `theta_h =
    /// (a / n_w)^2 pi/2`, `rho^2` at `rho = 2 (a / n_w)^2`, or `1 - cos
    /// theta_i` at `a / n_w`.
    pub fn w_edges(&self) -> Vec<f32> {
        (0..=self.n_w)
            .map(|a| {
                let t = a as f64 / self.n_w as f64;
                match self.parameterization {
                    Parameterization::HalfDiff => {
                        let theta = t * t * std::f64::consts::FRAC_PI_2;
                        // 1 - cos = 2 sin^2(theta / 2), exact near 0.
                        (2.0 * (0.5 * theta).sin().powi(2)) as f32
                    }
                    Parameterization::Pdv => (4.0 * t.powi(4)) as f32,
                    Parameterization::InOut => t as f32,
                }
            })
            .collect()
    }

    /// `wi` at coordinates `(r, phi)` about `wo` and `d omega_i / (dr
    /// dphi)`; `None` where no `wi` of the upper hemisphere has them.
    #[inline]
    pub fn direction(&self, wo: Vec3, r: f32, phi: f32) -> Option<(Vec3, f32)> {
        let (wi, jacobian) = match self.parameterization {
            Parameterization::HalfDiff => {
                let (wi, wo_h) = wi_from_half_coords(wo, r, phi)?;
                (wi, half_coords_jacobian(wo_h))
            }
            Parameterization::Pdv => {
                let (wi, _) = w_from_pdv(wo, r.max(0.0).sqrt(), phi)?;
                (wi, 0.5 / wi.z)
            }
            Parameterization::InOut => {
                let cos_theta = 1.0 - r;
                let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
                let (s, c) = (wo.y.atan2(wo.x) + phi).sin_cos();
                (Vec3::new(sin_theta * c, sin_theta * s, cos_theta), 1.0)
            }
        };
        (wi.z > 0.0).then_some((wi, jacobian))
    }

    /// The inverse of [`Self::direction`]: `(r, phi, d omega_i / (dr
    /// dphi))`, `phi` in `[0, 2 pi)`; `None` for `wi` the coordinates do
    /// not reach.
    #[inline]
    pub fn coordinates(&self, wo: Vec3, wi: Vec3) -> Option<(f32, f32, f32)> {
        match self.parameterization {
            Parameterization::HalfDiff => {
                let (w, phi, wo_h) = half_coords_from_wi(wo, wi)?;
                Some((w, phi, half_coords_jacobian(wo_h)))
            }
            Parameterization::Pdv => {
                let (rho, phi, _) = pdv_from_w(wo, wi)?;
                Some((rho * rho, phi, 0.5 / wi.z))
            }
            Parameterization::InOut => {
                if wi.z <= 0.0 {
                    return None;
                }
                let phi = (wi.y.atan2(wi.x) - wo.y.atan2(wo.x)).rem_euclid(2.0 * PI);
                // rem_euclid rounds up to 2 pi just below 0.
                let phi = phi.min(2.0 * PI - f32::EPSILON * 8.0);
                Some((1.0 - wi.z, phi, 1.0))
            }
        }
    }

    pub fn phi_edges(&self) -> Vec<f32> {
        lumis_sampling::Distribution1D::uniform_edges(0.0, 2.0 * PI, self.n_phi)
    }

    /// The elevation of row `k`.
    pub fn theta_o(&self, k: usize) -> f32 {
        (k as f32 + 0.5) / self.n_o as f32 * FRAC_PI_2
    }

    /// The two rows around `wo` and the weight of the second (linear in
    /// `theta_o`, clamped beyond the first and last rows).
    #[inline]
    pub fn rows(&self, wo: Vec3) -> (usize, usize, f32) {
        let r = (wo.x * wo.x + wo.y * wo.y).sqrt();
        let theta = r.atan2(wo.z);
        let x = (theta / FRAC_PI_2 * self.n_o as f32 - 0.5).clamp(0.0, (self.n_o - 1) as f32);
        let k0 = (x.floor() as usize).min(self.n_o - 1);
        let k1 = (k0 + 1).min(self.n_o - 1);
        (k0, k1, x - k0 as f32)
    }

    /// Row `k`: the mass of `f cos theta_i` (luminance) in every cell,
    /// `a * n_phi + b` for `w` bin `a` and `phi` bin `b`.
    pub fn row(&self, k: usize, f: &(dyn Fn(Vec3, Vec3) -> Rgb + Sync)) -> Vec<f32> {
        self.row_at(self.theta_o(k), f)
    }

    /// [`Self::row`] for the outgoing elevation `theta_o`.
    pub fn row_at(&self, theta_o: f32, f: &(dyn Fn(Vec3, Vec3) -> Rgb + Sync)) -> Vec<f32> {
        let wo = spherical_direction(theta_o, 0.0);
        let (w_edges, phi_edges) = (self.w_edges(), self.phi_edges());
        let s = self.supersamples;
        let mut out = vec![0.0f32; self.columns()];
        for a in 0..self.n_w {
            let (w0, w1) = (w_edges[a], w_edges[a + 1]);
            for b in 0..self.n_phi {
                let (p0, p1) = (phi_edges[b], phi_edges[b + 1]);
                let mut sum = 0.0f64;
                for sa in 0..s {
                    let w = w0 + (w1 - w0) * ((sa as f32 + 0.5) / s as f32);
                    for sb in 0..s {
                        let phi = p0 + (p1 - p0) * ((sb as f32 + 0.5) / s as f32);
                        let Some((wi, jacobian)) = self.direction(wo, w, phi) else {
                            continue;
                        };
                        let value = f(wo, wi).luminance().max(0.0);
                        sum += (value * wi.z * jacobian) as f64;
                    }
                }
                let area = ((w1 - w0) * (p1 - p0)) as f64 / (s * s) as f64;
                out[a * self.n_phi + b] = (sum * area) as f32;
            }
        }
        out
    }

    /// Every row, in parallel, ticking `progress` once per row.
    pub fn rows_of(
        &self,
        f: &(dyn Fn(Vec3, Vec3) -> Rgb + Sync),
        progress: &ProgressBar,
    ) -> Vec<Vec<f32>> {
        (0..self.n_o)
            .into_par_iter()
            .map(|k| {
                let row = self.row(k, f);
                progress.inc(1);
                row
            })
            .collect()
    }
}

/// Scales each row to sum 1 (rows of zero stay zero): the samplers need
/// each row's shape, not its albedo, and the factorization should fit
/// grazing rows as well as bright ones.
pub fn normalize_rows(rows: &mut [Vec<f32>]) {
    for row in rows {
        let sum: f64 = row.iter().map(|&v| v as f64).sum();
        if sum > 0.0 {
            row.iter_mut().for_each(|v| *v = (*v as f64 / sum) as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_of_a_lambertian_hold_its_albedo() {
        // f = 1/pi: each row integrates f cos over the hemisphere = 1, up
        // to the cells that straddle the horizon.
        let grid = Grid {
            n_o: 4,
            n_w: 32,
            n_phi: 32,
            supersamples: 4,
            parameterization: Parameterization::HalfDiff,
        };
        let f = |_: Vec3, _: Vec3| Rgb::splat(std::f32::consts::FRAC_1_PI);
        for parameterization in [
            Parameterization::HalfDiff,
            Parameterization::Pdv,
            Parameterization::InOut,
        ] {
            let grid = Grid {
                parameterization,
                ..grid
            };
            for k in 0..grid.n_o {
                let sum: f32 = grid.row(k, &f).iter().sum();
                assert!(
                    (sum - 1.0).abs() < 0.02,
                    "{parameterization:?} row {k}: {sum}"
                );
            }
        }
    }

    #[test]
    fn edges_and_rows_are_consistent() {
        let grid = Grid {
            n_o: 8,
            n_w: 64,
            n_phi: 16,
            supersamples: 1,
            parameterization: Parameterization::HalfDiff,
        };
        let e = grid.w_edges();
        assert_eq!(e[0], 0.0);
        assert!((e[64] - 1.0).abs() < 1e-6);
        assert!(
            e[1] > 0.0 && e[1] < 1e-6,
            "first bin at theta_h 3.8e-4: {}",
            e[1]
        );
        assert_eq!(grid.rows(Vec3::Z), (0, 1, 0.0));
        let (k0, k1, t) = grid.rows(spherical_direction(grid.theta_o(3) + 1e-3, 1.0));
        assert!(k0 == 3 && k1 == 4 && t > 0.0 && t < 0.1);
        assert_eq!(
            grid.rows(Vec3::new(1.0, 0.0, 1e-4).normalize()),
            (7, 7, 0.0)
        );
    }

    #[test]
    fn coordinates_invert_direction_in_every_parameterization() {
        let mut rng = lumis_sampling::Pcg32::new(3, 11);
        for parameterization in [
            Parameterization::HalfDiff,
            Parameterization::Pdv,
            Parameterization::InOut,
        ] {
            let grid = Grid {
                n_o: 8,
                n_w: 64,
                n_phi: 16,
                supersamples: 1,
                parameterization,
            };
            let edges = grid.w_edges();
            let mut checked = 0;
            for _ in 0..1000 {
                let wo = spherical_direction(rng.next_f32() * 1.57, rng.next_f32() * 2.0 * PI);
                let r = rng.next_f32() * edges[grid.n_w];
                let phi = rng.next_f32() * 2.0 * PI;
                let Some((wi, jacobian)) = grid.direction(wo, r, phi) else {
                    continue;
                };
                let (r2, phi2, jacobian2) = grid.coordinates(wo, wi).unwrap();
                assert!(
                    (r2 - r).abs() < 1e-4 * r.max(1.0),
                    "{parameterization:?}: r {r} {r2}"
                );
                let dphi = (phi2 - phi).rem_euclid(2.0 * PI);
                assert!(
                    dphi.min(2.0 * PI - dphi) < 1e-3,
                    "{parameterization:?}: phi {phi} {phi2}"
                );
                assert!((jacobian2 - jacobian).abs() <= 1e-3 * jacobian);
                checked += 1;
            }
            assert!(checked > 200, "{parameterization:?}: {checked} points");
        }
    }
}
