//! Pearson's chi-square test of points against the uniform distribution on
//! a grid of equal cells: the check that a randomisation (scrambling,
//! shuffling, jitter) leaves each sample uniformly distributed.

use statrs::distribution::{ChiSquared, ContinuousCDF};

#[derive(Debug, Clone, Copy)]
pub struct UniformityReport {
    pub statistic: f64,
    pub degrees_of_freedom: usize,
    /// Probability of a statistic at least this large if the points are
    /// uniform.
    pub p_value: f64,
}

/// Bins 2D points of `[0,1)^2` into `cells x cells` equal cells and tests
/// the counts against their uniform expectation.
pub fn uniformity_2d(points: &[[f32; 2]], cells: usize) -> UniformityReport {
    let mut counts = vec![0f64; cells * cells];
    for p in points {
        let x = ((p[0] * cells as f32) as usize).min(cells - 1);
        let y = ((p[1] * cells as f32) as usize).min(cells - 1);
        counts[y * cells + x] += 1.0;
    }
    let expected = points.len() as f64 / counts.len() as f64;
    let statistic: f64 = counts
        .iter()
        .map(|c| (c - expected) * (c - expected) / expected)
        .sum();
    let dof = counts.len() - 1;
    let p_value = ChiSquared::new(dof as f64)
        .map(|d| d.sf(statistic))
        .unwrap_or(0.0);
    UniformityReport {
        statistic,
        degrees_of_freedom: dof,
        p_value,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    #[test]
    fn accepts_uniform_and_rejects_skewed_points() {
        let mut rng = Pcg32::new(1, 2);
        let uniform: Vec<[f32; 2]> = (0..100_000)
            .map(|_| [rng.next_f32(), rng.next_f32()])
            .collect();
        assert!(uniformity_2d(&uniform, 16).p_value > 1e-4);
        let skewed: Vec<[f32; 2]> = uniform.iter().map(|p| [p[0] * p[0], p[1]]).collect();
        assert!(uniformity_2d(&skewed, 16).p_value < 1e-12);
    }
}
