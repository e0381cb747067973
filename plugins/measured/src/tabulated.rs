//! The reference strategy: for each outgoing elevation, the whole 2D
//! table of `f cos theta_i` over the grid's cells as a
//! piecewise-constant distribution (a marginal over `w`, a conditional
//! over `phi` per `w` bin; pbrt-v4 `PiecewiseConstant2D`). It follows the
//! data as closely as the grid allows, at `n_o x n_w x n_phi` entries
//! against the factorization's `L (n_o + n_w + n_phi)`: what the
//! factorization trades in variance for memory.
//!
//! Between rows the density is the mixture of the two rows' (weights
//! linear in `theta_o`), sampled by picking a row. Each row is mixed with
//! the uniform density by [`crate::mixture::DEFENSIVE`], as the factored
//! terms are.

use std::sync::Arc;

use lumis_api::{Vec2, Vec3};
use lumis_sampling::Distribution1D;

use crate::grid::Grid;
use crate::mixture::DEFENSIVE;

#[derive(Debug, Clone)]
struct Row {
    marginal: Distribution1D,
    conditional: Vec<Distribution1D>,
}

#[derive(Debug, Clone)]
pub struct Tabulated {
    grid: Grid,
    rows: Vec<Row>,
}

impl Tabulated {
    /// From the row-normalised matrix of `grid`.
    pub fn new(grid: Grid, y: &[Vec<f32>]) -> Self {
        let w_edges: Arc<[f32]> = grid.w_edges().into();
        let phi_edges: Arc<[f32]> = grid.phi_edges().into();
        // The uniform part sums to DEFENSIVE whatever the radial range.
        let w_span = w_edges[grid.n_w] - w_edges[0];
        let rows = y
            .iter()
            .map(|row| {
                let total: f32 = row.iter().sum();
                // The joint masses of the defensive mixture.
                let joint = |a: usize, b: usize| {
                    let data = if total > 0.0 {
                        row[a * grid.n_phi + b] / total
                    } else {
                        0.0
                    };
                    (1.0 - DEFENSIVE) * data
                        + DEFENSIVE * (w_edges[a + 1] - w_edges[a]) / (w_span * grid.n_phi as f32)
                };
                let marginal: Vec<f32> = (0..grid.n_w)
                    .map(|a| (0..grid.n_phi).map(|b| joint(a, b)).sum())
                    .collect();
                let conditional = (0..grid.n_w)
                    .map(|a| {
                        let masses: Vec<f32> = (0..grid.n_phi).map(|b| joint(a, b)).collect();
                        Distribution1D::new(phi_edges.clone(), &masses)
                    })
                    .collect();
                Row {
                    marginal: Distribution1D::new(w_edges.clone(), &marginal),
                    conditional,
                }
            })
            .collect();
        Self { grid, rows }
    }

    #[inline]
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
        let (k0, k1, t) = self.grid.rows(wo);
        let row = &self.rows[if u1 < t { k1 } else { k0 }];
        let (w, _, a) = row.marginal.sample(u2.x);
        let (phi, _, _) = row.conditional[a].sample(u2.y);
        let (wi, _) = self.grid.direction(wo, w, phi)?;
        Some(wi)
    }

    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some((w, phi, jacobian)) = self.grid.coordinates(wo, wi) else {
            return 0.0;
        };
        let (k0, k1, t) = self.grid.rows(wo);
        let first = &self.rows[k0];
        let (Some(a), Some(b)) = (first.marginal.bin(w), first.conditional[0].bin(phi)) else {
            return 0.0;
        };
        let density = |row: &Row| row.marginal.bin_pdf(a) * row.conditional[a].bin_pdf(b);
        let p = (1.0 - t) * density(first) + t * density(&self.rows[k1]);
        p / jacobian
    }

    /// Bytes held (the shared bin edges once).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self
                .rows
                .iter()
                .map(|r| {
                    r.marginal.memory_bytes()
                        + r.conditional
                            .iter()
                            .map(|c| c.memory_bytes())
                            .sum::<usize>()
                })
                .sum::<usize>()
            + 4 * (self.grid.n_w + self.grid.n_phi + 2)
    }
}
