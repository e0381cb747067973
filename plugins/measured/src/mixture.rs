//! A mixture of separable densities over the coordinates `(r, phi)` of
//! `wi` about `wo` ([`Grid::direction`]): what the factored sampler
//! (Lawrence et al. 2004) and the tensor sampler both draw from. They
//! differ only in how each term's weight depends on `wo`:
//!
//! ```text
//! p(wi) = sum_q P_q(wo) u_q(r) v_q(phi) / J,   J = d omega_i / (dr dphi).
//! ```
//!
//! Each 1D distribution is mixed with a uniform one of weight
//! [`DEFENSIVE`] ([`defensive`]) so that the density is positive wherever
//! `f` may be (Hesterberg 1995's defensive mixture), at a cost of 1% of the
//! samples.

use std::sync::Arc;

use lumis_api::{Vec2, Vec3};
use lumis_sampling::Distribution1D;

use crate::grid::Grid;

/// Weight of the uniform part of every 1D distribution.
pub const DEFENSIVE: f32 = 0.01;

/// A distribution over `edges` with masses `p` (in any scale) mixed with
/// the uniform one (masses proportional to bin width) by [`DEFENSIVE`].
pub fn defensive(edges: &Arc<[f32]>, p: &[f32]) -> Distribution1D {
    let width = edges[edges.len() - 1] - edges[0];
    let total: f32 = p.iter().sum();
    let mass: Vec<f32> = p
        .iter()
        .enumerate()
        .map(|(i, &x)| {
            let data = if total > 0.0 { x / total } else { 0.0 };
            (1.0 - DEFENSIVE) * data + DEFENSIVE * (edges[i + 1] - edges[i]) / width
        })
        .collect();
    Distribution1D::new(edges.clone(), &mass)
}

/// Terms `u_q(r) v_q(phi)`, all `u` over the same edges, all `v` too.
#[derive(Debug, Clone)]
pub struct SeparableMixture {
    /// Maps `(r, phi)` to `wi`.
    grid: Grid,
    u: Vec<Distribution1D>,
    v: Vec<Distribution1D>,
}

impl SeparableMixture {
    pub fn new(grid: Grid, u: Vec<Distribution1D>, v: Vec<Distribution1D>) -> Self {
        assert!(
            !u.is_empty() && u.len() == v.len(),
            "one u and one v per term"
        );
        Self { grid, u, v }
    }

    pub fn terms(&self) -> usize {
        self.u.len()
    }

    /// Draws `wi` from the term `u1` picks among `weights` (its
    /// probabilities, one per term), or `None` when the coordinates leave
    /// the upper hemisphere.
    #[inline]
    pub fn sample(
        &self,
        wo: Vec3,
        weights: impl Iterator<Item = f32>,
        u1: f32,
        u2: Vec2,
    ) -> Option<Vec3> {
        let mut q = self.terms() - 1;
        let mut acc = 0.0;
        for (j, p) in weights.enumerate() {
            acc += p;
            if u1 < acc {
                q = j;
                break;
            }
        }
        let (r, _, _) = self.u[q].sample(u2.x);
        let (phi, _, _) = self.v[q].sample(u2.y);
        let (wi, _) = self.grid.direction(wo, r, phi)?;
        Some(wi)
    }

    /// The density of [`Self::sample`] w.r.t. solid angle of `wi`, with the
    /// same `weights`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, weights: impl Iterator<Item = f32>) -> f32 {
        let Some((r, phi, jacobian)) = self.grid.coordinates(wo, wi) else {
            return 0.0;
        };
        let (Some(a), Some(b)) = (self.u[0].bin(r), self.v[0].bin(phi)) else {
            return 0.0;
        };
        let mut p = 0.0;
        for (q, weight) in weights.enumerate() {
            p += weight * self.u[q].bin_pdf(a) * self.v[q].bin_pdf(b);
        }
        p / jacobian
    }

    /// Bytes held by the distributions (their shared edges once).
    pub fn memory_bytes(&self) -> usize {
        self.u
            .iter()
            .chain(&self.v)
            .map(|d| d.memory_bytes())
            .sum::<usize>()
            + 4 * (self.u[0].edges().len() + self.v[0].edges().len())
    }
}
