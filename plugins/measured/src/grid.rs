//! The grid the sampling precomputations tabulate `f cos theta_i` on.
//!
//! Rows are outgoing elevations: an isotropic BRDF depends on `wo` only
//! through `theta_o` once azimuths are measured from `phi_o`, so `n_o`
//! rows at `theta_o = (k + 1/2) / n_o * pi/2` cover every `wo`. Columns are
//! cells of the half-vector coordinates about `wo`, `(w, phi) = (1 - cos
//! theta_h, phi_h - phi_o)` (Lawrence et al. 2004, section 4.1: centred on
//! the specular peak, where a glossy lobe is compact and nearly the same
//! for every `wo`, which is what makes the matrix low-rank). The `w` bins
//! have edges at `theta_h = (a / n_w)^2 pi/2`, the square-root spacing of
//! the MERL format: a 64-bin grid resolves a lobe of width 0.01 rad with
//! 4 bins and still covers the horizon. `phi` bins are uniform.
//!
//! Each entry is the integral of `f cos theta_i` over the cell, in solid
//! angle of `wi` (`d omega_i = 4 <wo, h> dw dphi`), by `s x s` midpoints:
//! the mass a sampler should give the cell.

use std::f32::consts::{FRAC_PI_2, PI};

use indicatif::ProgressBar;
use lumis_core::{Rgb, Vec3};
use lumis_sampling::halfdiff::{half_coords_jacobian, spherical_direction, wi_from_half_coords};
use rayon::prelude::*;

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
}

impl Grid {
    pub fn columns(&self) -> usize {
        self.n_w * self.n_phi
    }

    /// `w = 1 - cos theta_h` at the edges `theta_h = (a / n_w)^2 pi/2`.
    pub fn w_edges(&self) -> Vec<f32> {
        (0..=self.n_w)
            .map(|a| {
                let t = a as f64 / self.n_w as f64;
                let theta = t * t * std::f64::consts::FRAC_PI_2;
                // 1 - cos = 2 sin^2(theta / 2), exact near 0.
                (2.0 * (0.5 * theta).sin().powi(2)) as f32
            })
            .collect()
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
        let wo = spherical_direction(self.theta_o(k), 0.0);
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
                        let Some((wi, wo_h)) = wi_from_half_coords(wo, w, phi) else {
                            continue;
                        };
                        if wi.z <= 0.0 {
                            continue;
                        }
                        let value = f(wo, wi).luminance().max(0.0);
                        sum += (value * wi.z * half_coords_jacobian(wo_h)) as f64;
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
        };
        let f = |_: Vec3, _: Vec3| Rgb::splat(std::f32::consts::FRAC_1_PI);
        for k in 0..grid.n_o {
            let sum: f32 = grid.row(k, &f).iter().sum();
            assert!((sum - 1.0).abs() < 0.02, "row {k}: {sum}");
        }
    }

    #[test]
    fn edges_and_rows_are_consistent() {
        let grid = Grid {
            n_o: 8,
            n_w: 64,
            n_phi: 16,
            supersamples: 1,
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
}
