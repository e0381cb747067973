//! The CP (CANDECOMP/PARAFAC) decomposition of a 3-way array by
//! alternating least squares, with missing entries.
//!
//! A dense array `X[i][j][k]` (`k` fastest) is approximated by `R` rank-1
//! terms,
//!
//! ```text
//! X[i][j][k] ~ sum_{r < R} lambda_r A[i][r] B[j][r] C[k][r]
//! ```
//!
//! with unit-norm columns `A[.][r]`, `B[.][r]`, `C[.][r]`. Alternating
//! least squares (Kolda and Bader 2009, "Tensor Decompositions and
//! Applications", SIAM Review 51(3), section 3.4, figure 3.3) solves for one
//! factor with the other two held: for `A`,
//!
//! ```text
//! A = X_(1) (C kr B) (C^T C * B^T B)^-1
//! ```
//!
//! where `X_(1) (C kr B)` is the matricized-tensor times Khatri-Rao
//! product, `M[i][r] = sum_{j,k} X[i][j][k] B[j][r] C[k][r]`, and `*` is
//! the elementwise product: the normal equations of each row are `R x R`,
//! solved here by Cholesky. Each update cannot increase the residual, so
//! the fit decreases monotonically to a (local) minimum.
//!
//! Entries marked missing (a MERL sample below the horizon, a deviation
//! outside the disk) are imputed by the current model before every sweep,
//! the expectation-maximisation form of ALS with missing values (Tomasi
//! and Bro 2005, "PARAFAC and missing values", Chemometrics and Intelligent
//! Laboratory Systems 75): each sweep then minimises the residual over the
//! known entries, which still decreases monotonically.
//!
//! With [`AlsSettings::nonnegative`], each factor is instead updated by
//! hierarchical ALS (Cichocki and Phan 2009, "Fast local algorithms for
//! large scale nonnegative matrix and tensor factorizations", IEICE
//! Transactions on Fundamentals E92-A(3), algorithm 2): one column at a
//! time, the least-squares update with the others held, projected onto
//! the non-negative orthant,
//!
//! ```text
//! A[.][r] <- max(eps, A[.][r] + (M[.][r] - A G[.][r]) / G[r][r])
//! ```
//!
//! from the same `M` and `G`. Each column update is the exact minimiser
//! of a convex problem, so the residual still cannot increase. A model
//! whose terms are non-negative is a mixture that can be sampled term by
//! term ([`crate::tensor_sampling`]).

use lumis_sampling::Pcg32;
use rayon::prelude::*;

/// When to stop the sweeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlsSettings {
    pub max_sweeps: usize,
    /// Stop when a sweep lowers the squared residual by less than this
    /// fraction of it.
    pub tolerance: f64,
    /// Seed of the initial factors.
    pub seed: u64,
    /// Keep every factor non-negative (hierarchical ALS).
    pub nonnegative: bool,
}

impl Default for AlsSettings {
    fn default() -> Self {
        Self {
            max_sweeps: 60,
            tolerance: 1e-5,
            seed: 2011,
            nonnegative: false,
        }
    }
}

/// A rank-`R` CP model of an `n0 x n1 x n2` array.
#[derive(Debug, Clone, PartialEq)]
pub struct Cp {
    pub rank: usize,
    pub dims: [usize; 3],
    /// `lambda_r`.
    pub weights: Vec<f64>,
    /// `A`, `B`, `C`: `dims[m] x rank`, row-major, unit-norm columns.
    pub factors: [Vec<f64>; 3],
}

/// How a fit went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AlsReport {
    pub sweeps: usize,
    /// `sum (X - model)^2` over the known entries.
    pub residual: f64,
    /// `sum X^2` over the known entries.
    pub norm: f64,
}

impl AlsReport {
    /// `|X - model| / |X|` over the known entries.
    pub fn relative_error(&self) -> f64 {
        (self.residual / self.norm.max(f64::MIN_POSITIVE)).sqrt()
    }
}

impl Cp {
    /// The model at `(i, j, k)`.
    #[inline]
    pub fn value(&self, i: usize, j: usize, k: usize) -> f64 {
        let r = self.rank;
        let [a, b, c] = &self.factors;
        (0..r)
            .map(|t| self.weights[t] * a[i * r + t] * b[j * r + t] * c[k * r + t])
            .sum()
    }

    /// Factor `mode` as f32, `dims[mode] x rank` row-major, with the
    /// weights folded into mode 0 (so that the model is the plain sum of
    /// products of the three).
    pub fn folded_factor(&self, mode: usize) -> Vec<f32> {
        let r = self.rank;
        self.factors[mode]
            .chunks_exact(r)
            .flat_map(|row| {
                row.iter()
                    .enumerate()
                    .map(move |(q, &v)| (if mode == 0 { v * self.weights[q] } else { v }) as f32)
            })
            .collect()
    }

    /// Fits `rank` terms to `data` (`dims[0] x dims[1] x dims[2]`, `k`
    /// fastest); `known[n] == false` marks entry `n` missing.
    pub fn fit(
        data: &[f64],
        known: Option<&[bool]>,
        dims: [usize; 3],
        rank: usize,
        settings: AlsSettings,
    ) -> (Self, AlsReport) {
        assert!(rank >= 1, "a CP model has at least one term");
        assert_eq!(data.len(), dims[0] * dims[1] * dims[2]);
        let missing: Vec<usize> = known.map_or_else(Vec::new, |k| {
            assert_eq!(k.len(), data.len());
            (0..k.len()).filter(|&n| !k[n]).collect()
        });
        let mut x = data.to_vec();
        // Missing entries start at the mean of the known ones.
        let known_count = data.len() - missing.len();
        let norm: f64 = {
            let mut is_missing = vec![false; data.len()];
            missing.iter().for_each(|&n| is_missing[n] = true);
            let (sum, sum2) = data
                .iter()
                .zip(&is_missing)
                .filter(|(_, m)| !**m)
                .fold((0.0, 0.0), |(s, s2), (v, _)| (s + v, s2 + v * v));
            let mean = sum / known_count.max(1) as f64;
            missing.iter().for_each(|&n| x[n] = mean);
            sum2
        };
        let mut rng = Pcg32::new(settings.seed, 0xc9);
        let mut random =
            |n: usize| -> Vec<f64> { (0..n * rank).map(|_| 0.1 + rng.next_f32() as f64).collect() };
        let mut model = Cp {
            rank,
            dims,
            weights: vec![1.0; rank],
            factors: [vec![0.0; dims[0] * rank], random(dims[1]), random(dims[2])],
        };
        for m in 1..3 {
            normalize_columns(&mut model.factors[m], rank);
        }
        let mut previous = f64::INFINITY;
        let mut report = AlsReport {
            sweeps: 0,
            residual: previous,
            norm,
        };
        for sweep in 1..=settings.max_sweeps {
            if sweep > 1 {
                for &n in &missing {
                    let (i, j, k) = split(n, dims);
                    x[n] = model.value(i, j, k);
                }
            }
            model.sweep(&x, settings.nonnegative);
            let residual = model.residual(data, &missing);
            report = AlsReport {
                sweeps: sweep,
                residual,
                norm,
            };
            if residual <= 1e-30 * norm || previous - residual <= settings.tolerance * residual {
                break;
            }
            previous = residual;
        }
        (model, report)
    }

    /// One ALS sweep over the three factors.
    fn sweep(&mut self, x: &[f64], nonnegative: bool) {
        let r = self.rank;
        let [n0, n1, n2] = self.dims;
        // T[i][j][r] = sum_k X[i][j][k] C[k][r]: shared by the A and B
        // updates, for which C is the same.
        let c = &self.factors[2];
        let t: Vec<f64> = x
            .par_chunks(n2)
            .flat_map_iter(|fibre| {
                let mut out = vec![0.0; r];
                for (k, &v) in fibre.iter().enumerate() {
                    for (o, &ck) in out.iter_mut().zip(&c[k * r..(k + 1) * r]) {
                        *o += v * ck;
                    }
                }
                out
            })
            .collect();
        // A: M[i][r] = sum_j B[j][r] T[i][j][r].
        let b = &self.factors[1];
        let mut m = vec![0.0; n0 * r];
        for i in 0..n0 {
            for j in 0..n1 {
                let tij = &t[(i * n1 + j) * r..(i * n1 + j + 1) * r];
                for q in 0..r {
                    m[i * r + q] += b[j * r + q] * tij[q];
                }
            }
        }
        self.solve_mode(0, m, nonnegative);
        // B: M[j][r] = sum_i A[i][r] T[i][j][r].
        let a = &self.factors[0];
        let mut m = vec![0.0; n1 * r];
        for i in 0..n0 {
            for j in 0..n1 {
                let tij = &t[(i * n1 + j) * r..(i * n1 + j + 1) * r];
                for q in 0..r {
                    m[j * r + q] += a[i * r + q] * tij[q];
                }
            }
        }
        self.solve_mode(1, m, nonnegative);
        // C: M[k][r] = sum_{i,j} A[i][r] B[j][r] X[i][j][k].
        let (a, b) = (&self.factors[0], &self.factors[1]);
        let m = x
            .par_chunks(n1 * n2)
            .enumerate()
            .fold(
                || vec![0.0; n2 * r],
                |mut acc, (i, slab)| {
                    let mut w = vec![0.0; r];
                    for (j, fibre) in slab.chunks_exact(n2).enumerate() {
                        for q in 0..r {
                            w[q] = a[i * r + q] * b[j * r + q];
                        }
                        for (k, &v) in fibre.iter().enumerate() {
                            for (o, &wq) in acc[k * r..(k + 1) * r].iter_mut().zip(&w) {
                                *o += v * wq;
                            }
                        }
                    }
                    acc
                },
            )
            .reduce(
                || vec![0.0; n2 * r],
                |mut s, o| {
                    s.iter_mut().zip(o).for_each(|(s, o)| *s += o);
                    s
                },
            );
        self.solve_mode(2, m, nonnegative);
    }

    /// Factor `mode` from its MTTKRP `m`: each row solves `G x = m_i` with
    /// `G` the elementwise product of the other two factors' Gram matrices
    /// (their columns are unit-norm, so `G` is well scaled), or, if
    /// `nonnegative`, takes one hierarchical-ALS step from the current
    /// factor; the column norms of the result become the weights.
    fn solve_mode(&mut self, mode: usize, mut m: Vec<f64>, nonnegative: bool) {
        let r = self.rank;
        let mut g = vec![1.0; r * r];
        for other in (0..3).filter(|&o| o != mode) {
            let gram = gram(&self.factors[other], r);
            g.iter_mut().zip(gram).for_each(|(g, h)| *g *= h);
        }
        if nonnegative {
            // Positive, so that a column never dies (Cichocki and Phan's eps).
            const FLOOR: f64 = 1e-16;
            let current = &self.factors[mode];
            for (row, old) in m.chunks_exact_mut(r).zip(current.chunks_exact(r)) {
                let mut x: Vec<f64> = old.iter().zip(&self.weights).map(|(v, w)| v * w).collect();
                for q in 0..r {
                    let gx: f64 = (0..r).map(|p| x[p] * g[p * r + q]).sum();
                    x[q] = (x[q] + (row[q] - gx) / g[q * r + q].max(f64::MIN_POSITIVE)).max(FLOOR);
                }
                row.copy_from_slice(&x);
            }
        } else {
            let l = cholesky(&g, r);
            for row in m.chunks_exact_mut(r) {
                cholesky_solve(&l, r, row);
            }
        }
        self.weights = normalize_columns(&mut m, r);
        self.factors[mode] = m;
    }

    /// `sum (X - model)^2` over the entries not in `missing` (sorted).
    fn residual(&self, data: &[f64], missing: &[usize]) -> f64 {
        let r = self.rank;
        let [_, n1, n2] = self.dims;
        let [a, b, c] = &self.factors;
        data.par_chunks(n1 * n2)
            .enumerate()
            .map(|(i, slab)| {
                let start = i * n1 * n2;
                let lo = missing.partition_point(|&n| n < start);
                let hi = missing.partition_point(|&n| n < start + n1 * n2);
                let mut skip = missing[lo..hi].iter().peekable();
                let mut w = vec![0.0; r];
                let mut sum = 0.0;
                for (j, fibre) in slab.chunks_exact(n2).enumerate() {
                    for q in 0..r {
                        w[q] = self.weights[q] * a[i * r + q] * b[j * r + q];
                    }
                    for (k, &v) in fibre.iter().enumerate() {
                        let n = start + j * n2 + k;
                        if skip.peek() == Some(&&n) {
                            skip.next();
                            continue;
                        }
                        let model: f64 = w
                            .iter()
                            .zip(&c[k * r..(k + 1) * r])
                            .map(|(w, c)| w * c)
                            .sum();
                        sum += (v - model) * (v - model);
                    }
                }
                sum
            })
            .sum()
    }

    /// Numbers stored: the weights and the three factors.
    pub fn floats(&self) -> usize {
        self.rank * (1 + self.dims.iter().sum::<usize>())
    }
}

/// `(i, j, k)` of flat index `n`.
#[inline]
fn split(n: usize, dims: [usize; 3]) -> (usize, usize, usize) {
    (
        n / (dims[1] * dims[2]),
        (n / dims[2]) % dims[1],
        n % dims[2],
    )
}

/// `F^T F` of an `n x r` row-major matrix.
fn gram(f: &[f64], r: usize) -> Vec<f64> {
    let mut g = vec![0.0; r * r];
    for row in f.chunks_exact(r) {
        for p in 0..r {
            for q in 0..r {
                g[p * r + q] += row[p] * row[q];
            }
        }
    }
    g
}

/// Scales each column of an `n x r` matrix to unit norm and returns the
/// norms (a zero column stays zero, with norm 0).
fn normalize_columns(f: &mut [f64], r: usize) -> Vec<f64> {
    let mut norms = vec![0.0; r];
    for row in f.chunks_exact(r) {
        norms.iter_mut().zip(row).for_each(|(n, v)| *n += v * v);
    }
    norms.iter_mut().for_each(|n| *n = n.sqrt());
    for row in f.chunks_exact_mut(r) {
        for (v, n) in row.iter_mut().zip(&norms) {
            if *n > 0.0 {
                *v /= n;
            }
        }
    }
    norms
}

/// The lower Cholesky factor of a symmetric `r x r` matrix `g`, with a
/// ridge of `1e-12` of its mean diagonal (Tikhonov) so that a rank-
/// deficient `G` (two equal columns) still factors; a pivot that still
/// vanishes is replaced by the ridge.
fn cholesky(g: &[f64], r: usize) -> Vec<f64> {
    let ridge = 1e-12 * (0..r).map(|p| g[p * r + p]).sum::<f64>() / r as f64 + f64::MIN_POSITIVE;
    let mut l = vec![0.0; r * r];
    for p in 0..r {
        for q in 0..=p {
            let mut s = g[p * r + q] - (0..q).map(|t| l[p * r + t] * l[q * r + t]).sum::<f64>();
            if p == q {
                s += ridge;
                l[p * r + p] = if s > ridge { s.sqrt() } else { ridge.sqrt() };
            } else {
                l[p * r + q] = s / l[q * r + q];
            }
        }
    }
    l
}

/// Solves `L L^T x = b` in place.
fn cholesky_solve(l: &[f64], r: usize, b: &mut [f64]) {
    for p in 0..r {
        let s: f64 = (0..p).map(|t| l[p * r + t] * b[t]).sum();
        b[p] = (b[p] - s) / l[p * r + p];
    }
    for p in (0..r).rev() {
        let s: f64 = (p + 1..r).map(|t| l[t * r + p] * b[t]).sum();
        b[p] = (b[p] - s) / l[p * r + p];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An exactly rank-`rank` array from random factors.
    fn synthetic(dims: [usize; 3], rank: usize, seed: u64) -> Vec<f64> {
        synthetic_from(dims, rank, seed, -0.3)
    }

    /// Factors uniform in `[offset, offset + 1)`.
    fn synthetic_from(dims: [usize; 3], rank: usize, seed: u64, offset: f64) -> Vec<f64> {
        let mut rng = Pcg32::new(seed, 5);
        let mut factor = |n: usize| -> Vec<f64> {
            (0..n * rank)
                .map(|_| rng.next_f32() as f64 + offset)
                .collect()
        };
        let (a, b, c) = (factor(dims[0]), factor(dims[1]), factor(dims[2]));
        let mut x = vec![0.0; dims.iter().product()];
        for i in 0..dims[0] {
            for j in 0..dims[1] {
                for k in 0..dims[2] {
                    x[(i * dims[1] + j) * dims[2] + k] = (0..rank)
                        .map(|r| a[i * rank + r] * b[j * rank + r] * c[k * rank + r])
                        .sum();
                }
            }
        }
        x
    }

    fn exact() -> AlsSettings {
        AlsSettings {
            max_sweeps: 3000,
            tolerance: 1e-13,
            seed: 7,
            nonnegative: false,
        }
    }

    fn all_nonnegative(model: &Cp) -> bool {
        model.weights.iter().all(|&w| w >= 0.0) && model.factors.iter().flatten().all(|&v| v >= 0.0)
    }

    #[test]
    fn nonnegative_fit_recovers_a_nonnegative_rank_3_array() {
        let dims = [20, 15, 12];
        let x = synthetic_from(dims, 3, 4, 0.0);
        let settings = AlsSettings {
            nonnegative: true,
            ..exact()
        };
        let (model, report) = Cp::fit(&x, None, dims, 3, settings);
        assert!(report.relative_error() < 1e-4, "{report:?}");
        assert!(all_nonnegative(&model));
    }

    #[test]
    fn nonnegative_fit_stays_nonnegative_where_the_best_fit_is_not() {
        // Factors of both signs: the unconstrained fit is exact, the
        // constrained one is not, but every factor stays >= 0 and its error
        // cannot be below the unconstrained one's.
        let dims = [12, 10, 9];
        let x = synthetic(dims, 2, 5);
        let (free_model, free) = Cp::fit(&x, None, dims, 2, exact());
        assert!(!all_nonnegative(&free_model));
        let settings = AlsSettings {
            nonnegative: true,
            max_sweeps: 400,
            ..exact()
        };
        let (model, report) = Cp::fit(&x, None, dims, 2, settings);
        assert!(all_nonnegative(&model));
        assert!(report.relative_error() >= free.relative_error());
        assert!(report.relative_error() < 1.0, "{report:?}");
    }

    #[test]
    fn recovers_an_exactly_rank_3_array() {
        let dims = [20, 15, 12];
        let x = synthetic(dims, 3, 1);
        let (model, report) = Cp::fit(&x, None, dims, 3, exact());
        assert!(
            report.relative_error() < 1e-6,
            "{report:?} after {} sweeps",
            report.sweeps
        );
        // The reported residual is the model's.
        let direct: f64 = (0..x.len())
            .map(|n| {
                let (i, j, k) = split(n, dims);
                (x[n] - model.value(i, j, k)).powi(2)
            })
            .sum();
        assert!((direct - report.residual).abs() <= 1e-9 * report.norm);
        // One term fewer cannot fit it.
        let (_, low) = Cp::fit(&x, None, dims, 2, exact());
        assert!(low.relative_error() > 1e-3, "{low:?}");
    }

    #[test]
    fn recovers_a_rank_2_array_with_a_fifth_of_it_missing() {
        let dims = [16, 14, 18];
        let x = synthetic(dims, 2, 2);
        let mut rng = Pcg32::new(3, 3);
        let known: Vec<bool> = (0..x.len()).map(|_| rng.next_f32() > 0.2).collect();
        let mut hidden = x.clone();
        for (v, k) in hidden.iter_mut().zip(&known) {
            if !k {
                *v = 1e3;
            }
        }
        let (model, report) = Cp::fit(&hidden, Some(&known), dims, 2, exact());
        assert!(report.relative_error() < 1e-6, "{report:?}");
        // The missing entries are predicted, not just ignored.
        let worst = (0..x.len())
            .filter(|&n| !known[n])
            .map(|n| {
                let (i, j, k) = split(n, dims);
                (x[n] - model.value(i, j, k)).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 1e-4, "worst missing entry off by {worst}");
    }

    #[test]
    fn cholesky_solves_a_symmetric_system() {
        let g = [4.0, 2.0, 0.6, 2.0, 5.0, 1.0, 0.6, 1.0, 3.0];
        let want = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|p| (0..3).map(|q| g[p * 3 + q] * want[q]).sum())
            .collect();
        cholesky_solve(&cholesky(&g, 3), 3, &mut b);
        for (x, w) in b.iter().zip(want) {
            assert!((x - w).abs() < 1e-9, "{b:?}");
        }
    }
}
