//! Factored importance sampling (Lawrence, Rusinkiewicz and Ramamoorthi
//! 2004, "Efficient BRDF Importance Sampling Using a Factored
//! Representation", SIGGRAPH).
//!
//! The matrix `Y[wo][cell]` of [`crate::grid`] (`f cos theta_i` over the
//! cells `(w, phi)` of each outgoing elevation, in the half-vector or the
//! deviation-vector coordinates, each row scaled to sum 1)
//! is approximated as
//!
//! ```text
//! Y(wo, w, phi) ~ sum_{l < L} F_l(wo) u_l(w) v_l(phi)        (eq. 3 and 4)
//! ```
//!
//! in two steps as in the paper (section 4.2): a non-negative matrix
//! factorization `Y ~ F G` of rank `L` (Lee and Seung 2001, multiplicative
//! updates for the Frobenius norm), then each `G_l`, an `n_w x n_phi`
//! matrix, by its best rank-1 approximation `u_l v_l^T` (the leading
//! singular pair, non-negative by Perron-Frobenius, by power iteration).
//! The first factorization is not unique, so its `G_l` need not be
//! separable and the split loses accuracy; starting from the split, all
//! three factors are then refined together by the multiplicative updates
//! of the non-negative 3-way (PARAFAC) model (Welling and Weber 2001,
//! "Positive tensor factorization"), which minimise `|Y - sum_l F_l u_l
//! v_l|^2` itself.
//! With `u_l` and `v_l` normalised to sum 1, `F_l(wo)` is the mass of term
//! `l`, and sampling (section 5) picks `l` with probability `F_l / sum_j
//! F_j`, draws `w` from `u_l` and `phi` from `v_l` (piecewise constant)
//! and maps `(w, phi)` to `wi` through the grid's parameterization. Its
//! density is evaluated the same way:
//!
//! ```text
//! p(wi) = sum_l F_l / sum_j F_j  u_l(w) v_l(phi) / J,   J = d omega_i / (dw dphi)
//! ```
//!
//! (`J = 4 <wo, h>` for the half vector, `1 / (2 cos theta_i)` for the
//! deviation vector, [`crate::grid`]).
//!
//! with `u_l(w)`, `v_l(phi)` the densities of the 1D distributions. `F`
//! is interpolated linearly in `theta_o` between rows, which keeps the
//! mixture exact. A factorization can leave a term near zero where `f` is
//! not: each 1D distribution is defensive ([`crate::mixture`], which also
//! draws and evaluates the mixture).

use indicatif::ProgressBar;
use lumis_api::Vec3;
use lumis_sampling::Pcg32;

use crate::grid::Grid;
use crate::mixture::{defensive, SeparableMixture};

/// Multiplicative-update iterations of the rank-L factorization.
pub const NMF_ITERATIONS: usize = 400;
/// Power iterations for each rank-1 split and refit iterations of `F`.
const POWER_ITERATIONS: usize = 60;
/// Iterations of the joint refinement of `F`, `u`, `v`.
pub const REFINE_ITERATIONS: usize = 300;
const TINY: f64 = 1e-30;

/// The factors, as stored in the cache: `f` is `n_o x L` (row-major),
/// `u` is `L x n_w`, `v` is `L x n_phi`; `u` and `v` rows sum to 1.
#[derive(Debug, Clone, PartialEq)]
pub struct Factors {
    pub terms: usize,
    pub f: Vec<f32>,
    pub u: Vec<f32>,
    pub v: Vec<f32>,
}

/// `Y ~ F G` with non-negative factors of rank `terms` (Lee and Seung
/// 2001, Theorem 1: the updates never increase `|Y - F G|^2`).
fn nmf(
    y: &[Vec<f32>],
    terms: usize,
    iterations: usize,
    progress: &ProgressBar,
) -> (Vec<f64>, Vec<f64>) {
    let (n, m) = (y.len(), y[0].len());
    let mut rng = Pcg32::new(0x1a77e4ce, 2004);
    let mut f: Vec<f64> = (0..n * terms)
        .map(|_| 0.5 + rng.next_f32() as f64)
        .collect();
    let mut g: Vec<f64> = (0..terms * m)
        .map(|_| (0.5 + rng.next_f32() as f64) / m as f64)
        .collect();
    for _ in 0..iterations {
        // G <- G (F^T Y) / (F^T F G)
        let mut ftf = vec![0.0f64; terms * terms];
        for k in 0..n {
            for a in 0..terms {
                for b in 0..terms {
                    ftf[a * terms + b] += f[k * terms + a] * f[k * terms + b];
                }
            }
        }
        for j in 0..m {
            for l in 0..terms {
                let mut num = 0.0;
                for (k, row) in y.iter().enumerate() {
                    num += f[k * terms + l] * row[j] as f64;
                }
                let den: f64 = (0..terms).map(|q| ftf[l * terms + q] * g[q * m + j]).sum();
                g[l * m + j] *= num / (den + TINY);
            }
        }
        // F <- F (Y G^T) / (F G G^T)
        refit_f(y, &mut f, &g, terms);
        progress.inc(1);
    }
    (f, g)
}

/// One multiplicative update of `F` for fixed `G` (`terms x m`).
fn refit_f(y: &[Vec<f32>], f: &mut [f64], g: &[f64], terms: usize) {
    let m = y[0].len();
    let mut ggt = vec![0.0f64; terms * terms];
    for a in 0..terms {
        for b in 0..terms {
            ggt[a * terms + b] = (0..m).map(|j| g[a * m + j] * g[b * m + j]).sum();
        }
    }
    for (k, row) in y.iter().enumerate() {
        let mut num = vec![0.0f64; terms];
        for (l, n) in num.iter_mut().enumerate() {
            *n = row
                .iter()
                .zip(&g[l * m..(l + 1) * m])
                .map(|(&yv, &gv)| yv as f64 * gv)
                .sum();
        }
        let old: Vec<f64> = f[k * terms..(k + 1) * terms].to_vec();
        for l in 0..terms {
            let den: f64 = (0..terms).map(|q| old[q] * ggt[q * terms + l]).sum();
            f[k * terms + l] = old[l] * num[l] / (den + TINY);
        }
    }
}

/// The best rank-1 approximation `s u v^T` of a non-negative `rows x
/// cols` matrix, `u` and `v` summing to 1 (power iteration).
fn rank_one(g: &[f64], rows: usize, cols: usize) -> (Vec<f64>, Vec<f64>, f64) {
    let mut v = vec![1.0f64; cols];
    let mut u = vec![0.0f64; rows];
    for _ in 0..POWER_ITERATIONS {
        let vv: f64 = v.iter().map(|x| x * x).sum::<f64>() + TINY;
        for (a, ua) in u.iter_mut().enumerate() {
            *ua = (0..cols).map(|b| g[a * cols + b] * v[b]).sum::<f64>() / vv;
        }
        let uu: f64 = u.iter().map(|x| x * x).sum::<f64>() + TINY;
        for (b, vb) in v.iter_mut().enumerate() {
            *vb = (0..rows).map(|a| g[a * cols + b] * u[a]).sum::<f64>() / uu;
        }
    }
    let (su, sv) = (u.iter().sum::<f64>(), v.iter().sum::<f64>());
    if su <= 0.0 || sv <= 0.0 {
        return (
            vec![1.0 / rows as f64; rows],
            vec![1.0 / cols as f64; cols],
            0.0,
        );
    }
    u.iter_mut().for_each(|x| *x /= su);
    v.iter_mut().for_each(|x| *x /= sv);
    (u, v, su * sv)
}

/// Factors the row-normalised matrix `y` of `grid` into `terms` separable
/// terms; ticks `progress` once per NMF iteration.
pub fn factorize(y: &[Vec<f32>], grid: &Grid, terms: usize, progress: &ProgressBar) -> Factors {
    let (n, m) = (grid.n_o, grid.columns());
    let (f0, g) = nmf(y, terms, NMF_ITERATIONS, progress);
    let mut f = f0;
    let mut u = Vec::with_capacity(terms * grid.n_w);
    let mut v = Vec::with_capacity(terms * grid.n_phi);
    for l in 0..terms {
        let (ul, vl, s) = rank_one(&g[l * m..(l + 1) * m], grid.n_w, grid.n_phi);
        for k in 0..n {
            f[k * terms + l] *= s;
        }
        u.extend(ul.iter().map(|&x| x as f32));
        v.extend(vl.iter().map(|&x| x as f32));
    }
    let mut u64_: Vec<f64> = u.iter().map(|&x| x as f64).collect();
    let mut v64: Vec<f64> = v.iter().map(|&x| x as f64).collect();
    for _ in 0..REFINE_ITERATIONS {
        refine(y, grid, terms, &mut f, &mut u64_, &mut v64);
        progress.inc(1);
    }
    // Normalise u and v to sum 1, moving their scale into F.
    for l in 0..terms {
        let su: f64 = u64_[l * grid.n_w..(l + 1) * grid.n_w].iter().sum();
        let sv: f64 = v64[l * grid.n_phi..(l + 1) * grid.n_phi].iter().sum();
        if su > 0.0 && sv > 0.0 {
            u64_[l * grid.n_w..(l + 1) * grid.n_w]
                .iter_mut()
                .for_each(|x| *x /= su);
            v64[l * grid.n_phi..(l + 1) * grid.n_phi]
                .iter_mut()
                .for_each(|x| *x /= sv);
            (0..n).for_each(|k| f[k * terms + l] *= su * sv);
        }
    }
    Factors {
        terms,
        f: f.iter().map(|&x| x as f32).collect(),
        u: u64_.iter().map(|&x| x as f32).collect(),
        v: v64.iter().map(|&x| x as f32).collect(),
    }
}

/// One round of multiplicative updates of the non-negative PARAFAC model
/// `Y[k][a][b] ~ sum_l F[k][l] U[l][a] V[l][b]` (Welling and Weber 2001):
/// each factor is multiplied by (data projected on the other two) / (model
/// projected on the other two), whose Gram matrices are Hadamard products.
fn refine(y: &[Vec<f32>], grid: &Grid, terms: usize, f: &mut [f64], u: &mut [f64], v: &mut [f64]) {
    let (n, nw, np) = (grid.n_o, grid.n_w, grid.n_phi);
    let gram = |x: &[f64], len: usize| {
        let mut g = vec![0.0f64; terms * terms];
        for a in 0..terms {
            for b in 0..terms {
                g[a * terms + b] = (0..len).map(|i| x[a * len + i] * x[b * len + i]).sum();
            }
        }
        g
    };
    let f_t: Vec<f64> = (0..terms * n).map(|i| f[(i % n) * terms + i / n]).collect();
    let (gf, gv) = (gram(&f_t, n), gram(v, np));
    // U: numerator[l][a] = sum_{k,b} Y F[k][l] V[l][b].
    let mut num = vec![0.0f64; terms * nw];
    for (k, row) in y.iter().enumerate() {
        for a in 0..nw {
            let cells = &row[a * np..(a + 1) * np];
            for l in 0..terms {
                let yv: f64 = cells
                    .iter()
                    .zip(&v[l * np..(l + 1) * np])
                    .map(|(&c, &vb)| c as f64 * vb)
                    .sum();
                num[l * nw + a] += f[k * terms + l] * yv;
            }
        }
    }
    let old = u.to_vec();
    for l in 0..terms {
        for a in 0..nw {
            let den: f64 = (0..terms)
                .map(|q| old[q * nw + a] * gf[q * terms + l] * gv[q * terms + l])
                .sum();
            u[l * nw + a] = old[l * nw + a] * num[l * nw + a] / (den + TINY);
        }
    }
    let gu_new = gram(u, nw);
    // V: numerator[l][b] = sum_{k,a} Y F[k][l] U[l][a].
    let mut num = vec![0.0f64; terms * np];
    for (k, row) in y.iter().enumerate() {
        for a in 0..nw {
            let cells = &row[a * np..(a + 1) * np];
            for l in 0..terms {
                let s = f[k * terms + l] * u[l * nw + a];
                if s == 0.0 {
                    continue;
                }
                for (b, &c) in cells.iter().enumerate() {
                    num[l * np + b] += s * c as f64;
                }
            }
        }
    }
    let old = v.to_vec();
    for l in 0..terms {
        for b in 0..np {
            let den: f64 = (0..terms)
                .map(|q| old[q * np + b] * gf[q * terms + l] * gu_new[q * terms + l])
                .sum();
            v[l * np + b] = old[l * np + b] * num[l * np + b] / (den + TINY);
        }
    }
    let gv_new = gram(v, np);
    // F: numerator[k][l] = sum_{a,b} Y U[l][a] V[l][b].
    for (k, row) in y.iter().enumerate() {
        let mut num = vec![0.0f64; terms];
        for a in 0..nw {
            let cells = &row[a * np..(a + 1) * np];
            for (l, nl) in num.iter_mut().enumerate() {
                let yv: f64 = cells
                    .iter()
                    .zip(&v[l * np..(l + 1) * np])
                    .map(|(&c, &vb)| c as f64 * vb)
                    .sum();
                *nl += u[l * nw + a] * yv;
            }
        }
        let old: Vec<f64> = f[k * terms..(k + 1) * terms].to_vec();
        for l in 0..terms {
            let den: f64 = (0..terms)
                .map(|q| old[q] * gu_new[q * terms + l] * gv_new[q * terms + l])
                .sum();
            f[k * terms + l] = old[l] * num[l] / (den + TINY);
        }
    }
}

/// The sampler built from [`Factors`].
#[derive(Debug, Clone)]
pub struct Factored {
    grid: Grid,
    terms: usize,
    /// Selection probabilities per row, `n_o x L`, rows summing to 1.
    weights: Vec<f32>,
    mixture: SeparableMixture,
}

impl Factored {
    pub fn new(grid: Grid, factors: &Factors) -> Self {
        let terms = factors.terms;
        let w_edges: std::sync::Arc<[f32]> = grid.w_edges().into();
        let phi_edges: std::sync::Arc<[f32]> = grid.phi_edges().into();
        let u = (0..terms)
            .map(|l| defensive(&w_edges, &factors.u[l * grid.n_w..(l + 1) * grid.n_w]))
            .collect();
        let v = (0..terms)
            .map(|l| defensive(&phi_edges, &factors.v[l * grid.n_phi..(l + 1) * grid.n_phi]))
            .collect();
        let mut weights = Vec::with_capacity(grid.n_o * terms);
        for k in 0..grid.n_o {
            let row = &factors.f[k * terms..(k + 1) * terms];
            let sum: f32 = row.iter().map(|x| x.max(0.0)).sum();
            weights.extend(row.iter().map(|&x| {
                if sum > 0.0 {
                    x.max(0.0) / sum
                } else {
                    1.0 / terms as f32
                }
            }));
        }
        Self {
            grid,
            terms,
            weights,
            mixture: SeparableMixture::new(grid, u, v),
        }
    }

    /// The terms' probabilities for `wo`, interpolated between rows.
    #[inline]
    fn weights(&self, wo: Vec3) -> impl Iterator<Item = f32> + '_ {
        let (k0, k1, t) = self.grid.rows(wo);
        let row = |k: usize| &self.weights[k * self.terms..(k + 1) * self.terms];
        row(k0)
            .iter()
            .zip(row(k1))
            .map(move |(&w0, &w1)| (1.0 - t) * w0 + t * w1)
    }

    /// Draws `wi` (or `None` when the coordinates send it below the
    /// horizon or faces away from `wo`).
    #[inline]
    pub fn sample(&self, wo: Vec3, u1: f32, u2: lumis_api::Vec2) -> Option<Vec3> {
        self.mixture.sample(wo, self.weights(wo), u1, u2)
    }

    /// The density of [`Self::sample`] w.r.t. solid angle of `wi`.
    #[inline]
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        self.mixture.pdf(wo, wi, self.weights(wo))
    }

    /// Bytes held.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + 4 * self.weights.len() + self.mixture.memory_bytes()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_separable_matrix_is_recovered_exactly_at_its_rank() {
        let grid = Grid {
            n_o: 6,
            n_w: 8,
            n_phi: 5,
            supersamples: 1,
            parameterization: crate::grid::Parameterization::HalfDiff,
        };
        // Y = sum of two separable terms with row weights that vary.
        let u = [
            [1.0, 2.0, 3.0, 4.0, 3.0, 2.0, 1.0, 0.5],
            [4.0, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 4.0],
        ];
        let v = [[1.0, 1.0, 2.0, 1.0, 1.0], [0.2, 3.0, 0.2, 3.0, 0.2]];
        let y: Vec<Vec<f32>> = (0..grid.n_o)
            .map(|k| {
                let c = [1.0 + k as f32, 6.0 - k as f32];
                let mut row = vec![0.0; grid.columns()];
                for a in 0..grid.n_w {
                    for b in 0..grid.n_phi {
                        row[a * grid.n_phi + b] =
                            c[0] * u[0][a] * v[0][b] + c[1] * u[1][a] * v[1][b];
                    }
                }
                row
            })
            .collect();
        let mut y = y;
        crate::grid::normalize_rows(&mut y);
        let f2 = factorize(&y, &grid, 2, &ProgressBar::hidden());
        let f1 = factorize(&y, &grid, 1, &ProgressBar::hidden());
        let err = |f: &Factors| -> f64 {
            let mut e = 0.0;
            for (k, row) in y.iter().enumerate() {
                for a in 0..grid.n_w {
                    for b in 0..grid.n_phi {
                        let approx: f32 = (0..f.terms)
                            .map(|l| {
                                f.f[k * f.terms + l]
                                    * f.u[l * grid.n_w + a]
                                    * f.v[l * grid.n_phi + b]
                            })
                            .sum();
                        e += ((approx - row[a * grid.n_phi + b]) as f64).powi(2);
                    }
                }
            }
            e.sqrt() / (y.len() as f64).sqrt()
        };
        let (e1, e2) = (err(&f1), err(&f2));
        assert!(
            e2 < 1e-3 * e1.max(1e-3) || e2 < 1e-5,
            "rank 2 error {e2}, rank 1 error {e1}"
        );
        assert!(e1 > 1e-3, "rank 1 cannot fit two terms: {e1}");
    }
}
