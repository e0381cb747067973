//! Piecewise-constant 2D distributions over the unit square (pbrt-v4
//! `PiecewiseConstant2D`): a marginal distribution over rows, and in each
//! row a conditional distribution over its columns.
//!
//! Sampling draws `v` from the marginal, then `u` from the row it fell in;
//! the density w.r.t. area on `[0, 1]^2` is the product of the two, which
//! is `value / average value` inside a cell.

use glam::Vec2;

use crate::distribution::Distribution1D;

/// A piecewise-constant density over `[0, 1]^2` with `width x height`
/// cells of equal size; `u` runs along a row, `v` across rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution2D {
    /// One distribution over `u` per row.
    conditional: Vec<Distribution1D>,
    /// The distribution over rows, by each row's total.
    marginal: Distribution1D,
}

impl Distribution2D {
    /// Bytes the distribution holds: every row's and the marginal.
    pub fn byte_size(&self) -> usize {
        self.conditional
            .iter()
            .map(Distribution1D::byte_size)
            .sum::<usize>()
            + self.marginal.byte_size()
    }

    /// A distribution whose cell `(i, j)` (column `i`, row `j`) has
    /// probability proportional to `values[j * width + i]`. Negative or
    /// non-finite values count as zero. A row of zeros is never sampled;
    /// if every value is zero the distribution is uniform and
    /// [`Self::integral`] is 0.
    ///
    /// Panics if `values` does not hold `width * height > 0` entries (a
    /// programming error, not an input error).
    pub fn new(values: &[f32], width: usize, height: usize) -> Self {
        assert!(
            width > 0 && height > 0 && values.len() == width * height,
            "Distribution2D: {} values for {width} x {height} cells",
            values.len()
        );
        let u_edges: std::sync::Arc<[f32]> = Distribution1D::uniform_edges(0.0, 1.0, width).into();
        let conditional: Vec<Distribution1D> = values
            .chunks_exact(width)
            .map(|row| Distribution1D::new(u_edges.clone(), row))
            .collect();
        let row_mass: Vec<f32> = conditional.iter().map(|c| c.integral() as f32).collect();
        let marginal =
            Distribution1D::new(Distribution1D::uniform_edges(0.0, 1.0, height), &row_mass);
        Self {
            conditional,
            marginal,
        }
    }

    pub fn width(&self) -> usize {
        self.conditional[0].len()
    }

    pub fn height(&self) -> usize {
        self.marginal.len()
    }

    /// The sum of the (clean) values it was built from; 0 for a
    /// distribution of zeros, which falls back to uniform.
    pub fn integral(&self) -> f64 {
        self.marginal.integral()
    }

    /// Draws a point of `[0, 1]^2` from `u` in `[0, 1)^2`: the point and
    /// its density. Cells of zero value are never returned (unless all
    /// are zero).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, row) = self.marginal.sample(u.y);
        let (x, pdf_u, _) = self.conditional[row].sample(u.x);
        (Vec2::new(x, v), pdf_v * pdf_u)
    }

    /// The density at `p` w.r.t. area on `[0, 1]^2`; 0 outside.
    #[inline]
    pub fn pdf(&self, p: Vec2) -> f32 {
        match self.marginal.bin(p.y) {
            Some(row) => self.marginal.bin_pdf(row) * self.conditional[row].pdf(p.x),
            None => 0.0,
        }
    }

    /// Bytes held: for memory reports.
    pub fn memory_bytes(&self) -> usize {
        self.marginal.memory_bytes()
            + self
                .conditional
                .iter()
                .map(Distribution1D::memory_bytes)
                .sum::<usize>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;
    use crate::special::erf_inv;

    /// The upper `significance` quantile of a chi-square law with `dof`
    /// degrees of freedom (Wilson and Hilferty 1931, good to a few percent
    /// for `dof` >= 10, enough to set a threshold).
    fn chi_square_threshold(dof: f64, significance: f64) -> f64 {
        let z = std::f64::consts::SQRT_2 * erf_inv((1.0 - 2.0 * significance) as f32) as f64;
        let a = 2.0 / (9.0 * dof);
        dof * (1.0 - a + z * a.sqrt()).powi(3)
    }

    /// Pearson's statistic of `n` samples of `d` binned on its own cells
    /// (cells of zero expectation must stay empty), and its degrees of
    /// freedom.
    fn pearson(d: &Distribution2D, n: usize, seed: u64) -> (f64, f64) {
        let (w, h) = (d.width(), d.height());
        let mut counts = vec![0usize; w * h];
        let mut rng = Pcg32::new(seed, 7);
        for _ in 0..n {
            let (p, pdf) = d.sample(Vec2::new(rng.next_f32(), rng.next_f32()));
            assert!(
                (pdf - d.pdf(p)).abs() <= 1e-4 * pdf,
                "{pdf} vs {}",
                d.pdf(p)
            );
            let i = ((p.x * w as f32) as usize).min(w - 1);
            let j = ((p.y * h as f32) as usize).min(h - 1);
            counts[j * w + i] += 1;
        }
        let (mut stat, mut cells) = (0.0, 0.0);
        for j in 0..h {
            for i in 0..w {
                let centre = Vec2::new((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                let expected = d.pdf(centre) as f64 / (w * h) as f64 * n as f64;
                let observed = counts[j * w + i] as f64;
                if expected == 0.0 {
                    assert_eq!(observed, 0.0, "cell ({i}, {j}) has zero value");
                } else {
                    stat += (observed - expected).powi(2) / expected;
                    cells += 1.0;
                }
            }
        }
        (stat, cells - 1.0)
    }

    #[test]
    fn histogram_passes_chi_square_on_rough_and_sparse_images() {
        let (w, h) = (12, 7);
        let mut rng = Pcg32::new(11, 3);
        let rough: Vec<f32> = (0..w * h).map(|_| rng.next_f32().powi(3)).collect();
        // A black row, black columns and one bright cell.
        let sparse: Vec<f32> = (0..w * h)
            .map(|k| match (k % w, k / w) {
                (_, 2) => 0.0,
                (3, 5) => 40.0,
                (i, _) if i % 4 == 0 => 0.0,
                _ => 1.0,
            })
            .collect();
        let cases = [rough, sparse];
        // Sidak: an overall false-alarm rate of 1e-3 over the cases.
        let significance = 1.0 - (1.0 - 1e-3f64).powf(1.0 / cases.len() as f64);
        for (k, values) in cases.iter().enumerate() {
            let d = Distribution2D::new(values, w, h);
            let (stat, dof) = pearson(&d, 200_000, k as u64);
            let threshold = chi_square_threshold(dof, significance);
            assert!(stat < threshold, "case {k}: chi2 {stat} >= {threshold}");
        }
    }

    #[test]
    fn density_integrates_to_one_and_is_proportional_to_the_values() {
        let (w, h) = (5, 3);
        let values: Vec<f32> = (0..w * h).map(|k| (k % 4) as f32).collect();
        let d = Distribution2D::new(&values, w, h);
        let total: f32 = values.iter().sum();
        let mut integral = 0.0;
        for j in 0..h {
            for i in 0..w {
                let p = Vec2::new((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
                let pdf = d.pdf(p);
                let expected = values[j * w + i] / total * (w * h) as f32;
                assert!(
                    (pdf - expected).abs() < 1e-5,
                    "({i}, {j}): {pdf} vs {expected}"
                );
                integral += pdf / (w * h) as f32;
            }
        }
        assert!((integral - 1.0).abs() < 1e-5, "{integral}");
        assert_eq!(d.pdf(Vec2::new(0.5, 1.5)), 0.0);
        assert!((d.integral() - total as f64).abs() < 1e-4);
    }

    #[test]
    fn zero_rows_are_never_sampled_and_zeros_fall_back_to_uniform() {
        let d = Distribution2D::new(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0], 3, 2);
        for u in [0.0, 0.3, 0.999_999] {
            let (p, pdf) = d.sample(Vec2::new(u, u));
            assert!(p.y >= 0.5 && p.x <= 1.0 / 3.0, "{p}");
            assert!((pdf - 6.0).abs() < 1e-5, "{pdf}");
        }
        let black = Distribution2D::new(&[0.0; 6], 3, 2);
        assert_eq!(black.integral(), 0.0);
        let (p, pdf) = black.sample(Vec2::new(0.25, 0.75));
        assert!(p.is_finite() && (pdf - 1.0).abs() < 1e-6);
    }

    #[test]
    fn a_single_cell_is_uniform() {
        let d = Distribution2D::new(&[3.0], 1, 1);
        let (p, pdf) = d.sample(Vec2::new(0.2, 0.7));
        assert!((p - Vec2::new(0.2, 0.7)).length() < 1e-6 && (pdf - 1.0).abs() < 1e-6);
    }
}
