//! Sampling a BRDF from the factors of a tensor, in the manner of Bilgili,
//! Ozturk and Kurt 2011 (section 5). The density a sampler should follow,
//! `g = f cos theta_i J` (luminance; `J = d omega_i / (dr dphi)` of
//! [`crate::grid`]'s coordinates `(r, phi)` of `wi` about `wo`), is fitted
//! at the nodes of a parameterization ([`crate::tensor`]'s, `90 x 90 x
//! 180`) by a non-negative CP model ([`crate::cp`], hierarchical ALS)
//!
//! ```text
//! g(x0, x1, x2) ~ sum_{q < L} a_q(x0) b_q(x1) c_q(x2),   a, b, c >= 0,
//! ```
//!
//! a mixture of `L` separable terms, so each can be drawn on its own: the
//! term from its weight for `wo` (the marginal over terms), then each
//! sampled coordinate from its one-dimensional factor (the conditionals
//! given the term). The rendered tensor (`representation = "tensor"`) is a
//! fit of `ln(1 + f)`, whose exponential is not a mixture, so the sampler
//! is this fit of the same nodes (of the rendered tensor itself when it is
//! what the material renders). Per parameterization:
//!
//! - in-out `(theta_o, theta_i, dphi)`: `wo` fixes `x0`, so a term's
//!   weight is `a(theta_o)` times its mass; `r = 1 - cos theta_i` is drawn
//!   from `b`, `phi` from `c` mirrored about `pi`: the model's exact
//!   conditional given `wo`.
//! - pdv `(theta_o, rho, phi)`: the same, with `r = rho^2` (a sample
//!   beyond the disk `rho <= 1 + sin theta_o` is lost).
//! - half-diff `(theta_h, theta_d, phi_d)`: no coordinate is fixed by
//!   `wo`, so the half vector is drawn from the model's marginal over the
//!   difference angles, `r = 1 - cos theta_h` from `a` (`dr dphi` is the
//!   solid angle of `h`, as a microfacet distribution is sampled) and `phi`
//!   uniformly; a term's weight takes `b` at `theta_d = theta_o`, the
//!   difference angle of the specular pair, as its one dependence on `wo`.
//!   Not proportional to `f cos theta_i`, but unbiased: the density below
//!   is exact.
//!
//! The density is the mixture's ([`crate::mixture`], as for the factored
//! sampler), evaluated the same way, each 1D distribution defensive.

use std::f32::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use lumis_api::{Rgb, Vec2, Vec3};
use rayon::prelude::*;

use crate::cp::{AlsSettings, Cp};
use crate::grid::Parameterization;
use crate::merl::clamped_axis;
use crate::mixture::{defensive, SeparableMixture};
use crate::reflectance::Reflectance;
use crate::tensor::{elevation_index, node_grid, node_pair, node_reflectance, DIMS};

/// Sweeps of hierarchical ALS: its steps are smaller than the
/// unconstrained solve's.
pub const SWEEPS: usize = 200;
/// Stop sooner when a sweep gains less than this fraction of the residual.
const TOLERANCE: f64 = 1e-7;

/// Numbers in the payload of `terms` terms.
pub fn payload_len(terms: usize) -> usize {
    terms * DIMS.iter().sum::<usize>()
}

/// Fits `terms` non-negative terms to the density a sampler should follow
/// at the nodes of `parameterization`: the luminance of `f cos theta_i`
/// per unit `dr dphi` of the sampled coordinates (`f cos theta_i J`, `J`
/// of [`crate::grid::Grid::coordinates`]), which integrates to the albedo over a row
/// and so stays bounded where `f` itself grows without bound at grazing
/// angles. A node with no pair of directions, or a table's invalid one, is
/// a known zero, not a missing value as for the rendered tensor: no
/// sample should go there. The payload is the three factors, `DIMS[m] x
/// terms` row-major, the weights folded into the first.
pub fn fit(source: &Reflectance, parameterization: Parameterization, terms: usize) -> Vec<f32> {
    let grid = node_grid(parameterization);
    let values: Vec<f64> = node_reflectance(source, parameterization)
        .into_par_iter()
        .enumerate()
        .map(|(n, f)| {
            let [Some(r), Some(g), Some(b)] = f else {
                return 0.0;
            };
            let (i, j, k) = (
                n / (DIMS[1] * DIMS[2]),
                (n / DIMS[2]) % DIMS[1],
                n % DIMS[2],
            );
            let Some((wo, wi)) = node_pair(parameterization, i, j, k) else {
                return 0.0;
            };
            let Some((_, _, jacobian)) = grid.coordinates(wo, wi) else {
                return 0.0;
            };
            (Rgb::new(r, g, b).luminance().max(0.0) * wi.z * jacobian) as f64
        })
        .collect();
    let settings = AlsSettings {
        max_sweeps: SWEEPS,
        tolerance: TOLERANCE,
        nonnegative: true,
        ..AlsSettings::default()
    };
    let (cp, _) = Cp::fit(&values, None, DIMS, terms, settings);
    (0..3).flat_map(|m| cp.folded_factor(m)).collect()
}

/// Which factor depends on `wo`, and where `wo` falls on it.
#[derive(Debug, Clone, Copy)]
struct Condition {
    axis: usize,
    parameterization: Parameterization,
}

impl Condition {
    /// The index coordinate of `wo` on the conditioning axis.
    #[inline]
    fn index(self, wo: Vec3) -> f32 {
        match self.parameterization {
            Parameterization::HalfDiff => {
                // theta_d of the specular pair is theta_o.
                let theta_o = (wo.x * wo.x + wo.y * wo.y).sqrt().atan2(wo.z);
                theta_o / FRAC_PI_2 * DIMS[1] as f32
            }
            Parameterization::Pdv | Parameterization::InOut => elevation_index(wo),
        }
    }
}

/// Draws `wi` from the factors of a non-negative tensor.
#[derive(Debug, Clone)]
pub struct TensorSampler {
    condition: Condition,
    terms: usize,
    /// Per term: the conditioning factor, `DIMS[axis]` values.
    conditioning: Vec<f32>,
    /// Per term: the masses of its two sampled factors (and, in
    /// half-diff, of `phi_d`).
    mass: Vec<f32>,
    mixture: SeparableMixture,
}

/// Edges of `phi` over `[0, 2 pi)`: the tensor's azimuth nodes `c / (n - 1)
/// pi` on `[0, pi]`, mirrored.
fn mirrored_phi_edges() -> Vec<f32> {
    let n = DIMS[2] - 1;
    (0..=2 * n).map(|c| c as f32 / n as f32 * PI).collect()
}

/// The masses of a factor over [`mirrored_phi_edges`]: the mean of the
/// two nodes of each bin, times its width, mirrored.
fn mirrored_phi_masses(c: &[f32]) -> Vec<f32> {
    let width = PI / (DIMS[2] - 1) as f32;
    let half: Vec<f32> = c
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]).max(0.0) * width)
        .collect();
    half.iter().chain(half.iter().rev()).copied().collect()
}

impl TensorSampler {
    /// From a payload of [`fit`] (of [`payload_len`] numbers).
    pub fn new(parameterization: Parameterization, terms: usize, payload: &[f32]) -> Self {
        assert_eq!(payload.len(), payload_len(terms), "tensor sampler payload");
        let (a, rest) = payload.split_at(DIMS[0] * terms);
        let (b, c) = rest.split_at(DIMS[1] * terms);
        let factors = [a, b, c];
        let grid = node_grid(parameterization);
        // Node `i` of term `q` of factor `m`, clamped to the axis as the
        // model's lookup is.
        let node =
            |m: usize, i: usize, q: usize| factors[m][i.min(DIMS[m] - 1) * terms + q].max(0.0);
        let (condition_axis, r_edges, phi_edges): (usize, Vec<f32>, Vec<f32>) =
            match parameterization {
                Parameterization::HalfDiff => (1, grid.w_edges(), vec![0.0, 2.0 * PI]),
                Parameterization::Pdv => (
                    0,
                    (0..DIMS[1])
                        .map(|b| 4.0 * (b as f32 / (DIMS[1] - 1) as f32).powi(4))
                        .collect(),
                    mirrored_phi_edges(),
                ),
                Parameterization::InOut => (
                    0,
                    (0..=DIMS[1])
                        .map(|b| 1.0 - (b as f32 / DIMS[1] as f32 * FRAC_PI_2).cos())
                        .collect(),
                    mirrored_phi_edges(),
                ),
            };
        let (r_edges, phi_edges): (Arc<[f32]>, Arc<[f32]>) = (r_edges.into(), phi_edges.into());
        let (mut conditioning, mut mass, mut u, mut v) = (vec![], vec![], vec![], vec![]);
        // The sampled radial factor: a (theta_h) in half-diff, b else.
        let radial = if parameterization == Parameterization::HalfDiff {
            0
        } else {
            1
        };
        for q in 0..terms {
            let r_masses: Vec<f32> = r_edges
                .windows(2)
                .enumerate()
                .map(|(i, e)| {
                    let width = e[1] - e[0];
                    match parameterization {
                        // Nodes at the edges: the mean of the two.
                        Parameterization::HalfDiff | Parameterization::Pdv => {
                            0.5 * (node(radial, i, q) + node(radial, i + 1, q)) * width
                        }
                        // A node at the bin's centre.
                        Parameterization::InOut => node(radial, i, q) * width,
                    }
                })
                .collect();
            let azimuth: Vec<f32> = (0..DIMS[2]).map(|k| node(2, k, q)).collect();
            let (phi_masses, other) = match parameterization {
                // phi_d is not sampled: its mass weighs the term.
                Parameterization::HalfDiff => (vec![1.0], azimuth.iter().sum::<f32>()),
                Parameterization::Pdv | Parameterization::InOut => {
                    (mirrored_phi_masses(&azimuth), 1.0)
                }
            };
            let total = |m: &[f32]| m.iter().map(|&x| x as f64).sum::<f64>() as f32;
            mass.push(total(&r_masses) * total(&phi_masses) * other);
            conditioning.extend((0..DIMS[condition_axis]).map(|i| node(condition_axis, i, q)));
            u.push(defensive(&r_edges, &r_masses));
            v.push(defensive(&phi_edges, &phi_masses));
        }
        Self {
            condition: Condition {
                axis: condition_axis,
                parameterization,
            },
            terms,
            conditioning,
            mass,
            mixture: SeparableMixture::new(grid, u, v),
        }
    }

    /// The terms' probabilities for `wo` (uniform if every weight is 0).
    #[inline]
    fn weights(&self, wo: Vec3) -> impl Iterator<Item = f32> + '_ {
        let n = DIMS[self.condition.axis];
        let (i0, i1, t) = clamped_axis(self.condition.index(wo), n);
        let weight = move |q: usize| {
            let g = &self.conditioning[q * n..(q + 1) * n];
            ((1.0 - t) * g[i0] + t * g[i1]) * self.mass[q]
        };
        let total: f32 = (0..self.terms).map(weight).sum();
        (0..self.terms).map(move |q| {
            if total > 0.0 {
                weight(q) / total
            } else {
                1.0 / self.terms as f32
            }
        })
    }

    /// Draws `wi`, or `None` when the coordinates leave the upper
    /// hemisphere (or, in pdv, the disk).
    #[inline]
    pub fn sample(&self, wo: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
        self.mixture.sample(wo, self.weights(wo), u1, u2)
    }

    /// The density of [`Self::sample`] w.r.t. solid angle of `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.mixture.pdf(wo, wi, self.weights(wo))
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + 4 * (self.conditioning.len() + self.mass.len())
            + self.mixture.memory_bytes()
    }
}
