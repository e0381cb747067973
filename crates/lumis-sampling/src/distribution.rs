//! Piecewise-constant 1D distributions over bins of arbitrary widths
//! (pbrt-v4 `PiecewiseConstant1D`, generalised to non-uniform edges).
//!
//! Non-uniform edges let a tabulated density put its resolution where the
//! function varies (e.g. the square-root spacing of the half angle of a
//! glossy lobe) while staying constant, and hence bounded, inside each
//! bin. Sampling inverts the CDF with a binary search behind a guide
//! table ([`GuideTable`]), which finds in O(1) on average what the search
//! alone finds; the density is `value / (integral * width)` inside a bin.

use std::sync::Arc;

use crate::guide_table::GuideTable;

/// A piecewise-constant density over `[edges[0], edges[n]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution1D {
    /// Shared between distributions over the same bins (tables of them).
    edges: Arc<[f32]>,
    /// Probability of each bin (sums to 1).
    mass: Vec<f32>,
    /// `cdf[i]` = probability of bins `< i`; `cdf[n] = 1`.
    cdf: Vec<f32>,
    /// Where the inversion of `cdf` starts its search.
    guide: GuideTable,
    /// The sum of the bin masses before normalisation.
    integral: f64,
}

impl Distribution1D {
    /// A distribution whose bin `i` (between `edges[i]` and `edges[i + 1]`)
    /// has probability proportional to `mass[i]` (a mass, not a density: the
    /// integral of the function over the bin). Negative or non-finite
    /// masses are treated as zero. If every mass is zero, the distribution
    /// is uniform over the domain and [`Self::integral`] is 0.
    ///
    /// Panics if `edges` is not increasing or has not `mass.len() + 1`
    /// entries (a programming error, not an input error).
    pub fn new(edges: impl Into<Arc<[f32]>>, mass: &[f32]) -> Self {
        let edges: Arc<[f32]> = edges.into();
        assert!(
            edges.len() == mass.len() + 1 && !mass.is_empty(),
            "Distribution1D: {} edges for {} bins",
            edges.len(),
            mass.len()
        );
        assert!(
            edges.windows(2).all(|w| w[1] > w[0]),
            "Distribution1D: edges must increase"
        );
        let clean: Vec<f64> = mass
            .iter()
            .map(|&m| {
                if m.is_finite() && m > 0.0 {
                    m as f64
                } else {
                    0.0
                }
            })
            .collect();
        let integral: f64 = clean.iter().sum();
        let n = mass.len();
        let probabilities: Vec<f64> = if integral > 0.0 {
            clean.iter().map(|m| m / integral).collect()
        } else {
            let width = (edges[n] - edges[0]) as f64;
            (0..n)
                .map(|i| (edges[i + 1] - edges[i]) as f64 / width)
                .collect()
        };
        let mut cdf = Vec::with_capacity(n + 1);
        let mut running = 0.0f64;
        cdf.push(0.0);
        for p in &probabilities {
            running += p;
            cdf.push(running as f32);
        }
        cdf[n] = 1.0;
        Self {
            edges,
            mass: probabilities.iter().map(|&p| p as f32).collect(),
            guide: GuideTable::new(&cdf),
            cdf,
            integral,
        }
    }

    /// `n` bins of equal width over `[a, b]`.
    pub fn uniform_edges(a: f32, b: f32, n: usize) -> Vec<f32> {
        (0..=n)
            .map(|i| a + (b - a) * (i as f32 / n as f32))
            .collect()
    }

    pub fn len(&self) -> usize {
        self.mass.len()
    }

    /// Bytes the distribution holds: its masses, cdf and guide table, and
    /// its bin edges (which tables of distributions share: counted by each).
    pub fn byte_size(&self) -> usize {
        std::mem::size_of_val(&*self.edges)
            + std::mem::size_of_val(self.mass.as_slice())
            + std::mem::size_of_val(self.cdf.as_slice())
            + self.guide.byte_size()
    }

    pub fn is_empty(&self) -> bool {
        self.mass.is_empty()
    }

    pub fn edges(&self) -> &[f32] {
        &self.edges
    }

    /// The sum of the masses it was built from (0: the uniform fallback).
    pub fn integral(&self) -> f64 {
        self.integral
    }

    /// The probability of bin `i`.
    pub fn bin_probability(&self, i: usize) -> f32 {
        self.mass[i]
    }

    /// The bin holding `x`, or `None` outside the domain.
    #[inline]
    pub fn bin(&self, x: f32) -> Option<usize> {
        let n = self.mass.len();
        let (a, b) = (self.edges[0], self.edges[n]);
        if !(x >= a && x <= b) {
            return None;
        }
        // The bin of equal widths holding x, if its edges hold x: on
        // uniform edges (every 2D distribution's) always but for rounding,
        // sparing the search.
        let guess = (((x - a) / (b - a) * n as f32) as usize).min(n - 1);
        if self.edges[guess] <= x && (x < self.edges[guess + 1] || guess == n - 1) {
            return Some(guess);
        }
        // First edge > x, minus one; x == last edge belongs to the last bin.
        let i = self.edges.partition_point(|&e| e <= x);
        Some(i.saturating_sub(1).min(n - 1))
    }

    /// Density at `x` w.r.t. the measure of the domain.
    #[inline]
    pub fn pdf(&self, x: f32) -> f32 {
        match self.bin(x) {
            Some(i) => self.bin_pdf(i),
            None => 0.0,
        }
    }

    /// The density inside bin `i`.
    #[inline]
    pub fn bin_pdf(&self, i: usize) -> f32 {
        self.mass[i] / (self.edges[i + 1] - self.edges[i])
    }

    /// Draws `x` by inverting the CDF at `u` in `[0, 1)`: returns `x`, its
    /// density and its bin. Bins of zero probability are never returned.
    #[inline]
    pub fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.mass.len();
        // Last i with cdf[i] <= u, among bins of positive mass.
        let mut i = self.guide.find(&self.cdf, u).min(n - 1);
        while self.mass[i] == 0.0 && i > 0 {
            i -= 1;
        }
        while self.mass[i] == 0.0 && i + 1 < n {
            i += 1;
        }
        let t = ((u - self.cdf[i]) / self.mass[i]).clamp(0.0, 1.0);
        let (a, b) = (self.edges[i], self.edges[i + 1]);
        let x = (a + t * (b - a)).clamp(a, b);
        (x, self.bin_pdf(i), i)
    }

    /// Bytes held, not counting the (shareable) edges: for memory reports.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + 4 * (self.mass.len() + self.cdf.len())
            + self.guide.memory_bytes()
    }

    /// The masses it was built from, normalised (bin probabilities).
    pub fn probabilities(&self) -> &[f32] {
        &self.mass
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    #[test]
    fn sampled_histogram_matches_masses_on_uneven_bins() {
        let edges = vec![0.0, 0.01, 0.1, 0.5, 1.0];
        let mass = [1.0, 0.0, 3.0, 4.0];
        let d = Distribution1D::new(edges, &mass);
        let mut counts = [0usize; 4];
        let mut rng = Pcg32::new(3, 5);
        let n = 200_000;
        for _ in 0..n {
            let (x, pdf, i) = d.sample(rng.next_f32());
            assert_eq!(d.bin(x), Some(i), "x {x} in bin {i}");
            assert!(
                (pdf - d.pdf(x)).abs() <= 1e-5 * pdf,
                "{pdf} vs {}",
                d.pdf(x)
            );
            counts[i] += 1;
        }
        assert_eq!(counts[1], 0, "a bin of zero mass is never drawn");
        for (i, &m) in mass.iter().enumerate() {
            let p = m / 8.0;
            let se = (p * (1.0 - p) / n as f32).sqrt();
            let f = counts[i] as f32 / n as f32;
            assert!((f - p).abs() < 5.0 * se + 1e-6, "bin {i}: {f} vs {p}");
        }
    }

    #[test]
    fn density_integrates_to_one() {
        let d = Distribution1D::new(vec![-1.0, 0.0, 0.25, 2.0], &[0.5, 2.0, 0.1]);
        let total: f32 = (0..3)
            .map(|i| d.bin_pdf(i) * (d.edges()[i + 1] - d.edges()[i]))
            .sum();
        assert!((total - 1.0).abs() < 1e-6);
        assert_eq!(d.pdf(2.5), 0.0);
        assert_eq!(d.pdf(-1.5), 0.0);
        assert!((d.integral() - 2.6).abs() < 1e-6);
    }

    #[test]
    fn all_zero_masses_fall_back_to_uniform() {
        let d = Distribution1D::new(Distribution1D::uniform_edges(0.0, 2.0, 4), &[0.0; 4]);
        assert_eq!(d.integral(), 0.0);
        assert!((d.pdf(1.3) - 0.5).abs() < 1e-6);
        let (x, pdf, _) = d.sample(0.625);
        assert!((x - 1.25).abs() < 1e-6 && (pdf - 0.5).abs() < 1e-6);
    }

    #[test]
    fn extreme_uniform_numbers_stay_in_the_domain() {
        let d = Distribution1D::new(vec![0.0, 1.0, 2.0], &[0.0, 1.0]);
        for u in [0.0, 1e-9, 0.5, 1.0 - f32::EPSILON] {
            let (x, pdf, i) = d.sample(u);
            assert_eq!(i, 1);
            assert!((1.0..=2.0).contains(&x) && pdf == 1.0, "u {u}: {x} {pdf}");
        }
    }

    /// `bin` (a guess checked against the edges, then the search) finds
    /// what the search alone finds, on uniform and uneven edges.
    #[test]
    fn bin_is_the_binary_search_on_uniform_and_uneven_edges() {
        let search = |edges: &[f32], x: f32| {
            let n = edges.len() - 1;
            (x >= edges[0] && x <= edges[n]).then(|| {
                edges
                    .partition_point(|&e| e <= x)
                    .saturating_sub(1)
                    .min(n - 1)
            })
        };
        let mut rng = Pcg32::new(8, 1);
        for edges in [
            Distribution1D::uniform_edges(0.0, 1.0, 512),
            Distribution1D::uniform_edges(-3.0, 7.0, 100),
            (0..=64).map(|i| (i as f32 / 64.0).powi(2)).collect(),
        ] {
            let n = edges.len() - 1;
            let d = Distribution1D::new(edges.clone(), &vec![1.0; n]);
            let mut xs: Vec<f32> = edges
                .iter()
                .flat_map(|&e| [e, e.next_down(), e.next_up()])
                .collect();
            xs.extend((0..10_000).map(|_| edges[0] + (edges[n] - edges[0]) * rng.next_f32()));
            xs.push(f32::NAN);
            for x in xs {
                assert_eq!(d.bin(x), search(&edges, x), "x = {x}");
            }
        }
    }
}
