//! Adaptive sampling: each pixel stops once the noise estimated from two
//! independent halves of its samples falls under a threshold (Cycles'
//! adaptive sampling, after Dammertz et al. 2010, "A hierarchical
//! automatic stopping condition for Monte Carlo global illumination").
//!
//! The decisions are made between runs of samples, at fixed sample counts
//! (`min_spp`, `2 min_spp`, ...), from the film's sums alone: the image
//! depends neither on the threads nor on how the render was split into
//! passes, and a resumed render makes the same decisions.

use lumis_core::{Error, Result};

/// A scene's `[adaptive]` table: `min_spp`, `max_spp`, `threshold`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveSampling {
    /// Samples every pixel takes before any may stop; also the interval
    /// between the later decisions.
    pub min_spp: u32,
    /// Samples no pixel goes beyond: the render's spp.
    pub max_spp: u32,
    /// The relative error under which a pixel stops.
    pub threshold: f32,
}

impl AdaptiveSampling {
    /// The settings, or an error naming the rule they break.
    pub fn new(min_spp: u32, max_spp: u32, threshold: f32) -> Result<Self> {
        if min_spp < 2 {
            return Err(Error::msg(format!(
                "adaptive min_spp = {min_spp}: expected at least 2 (the error compares two halves of a pixel's samples)"
            )));
        }
        if max_spp < min_spp {
            return Err(Error::msg(format!(
                "adaptive max_spp = {max_spp}: expected at least min_spp = {min_spp}"
            )));
        }
        if !(threshold > 0.0 && threshold.is_finite()) {
            return Err(Error::msg(format!(
                "adaptive threshold = {threshold}: expected a positive, finite number"
            )));
        }
        Ok(Self {
            min_spp,
            max_spp,
            threshold,
        })
    }

    /// The first sample count after `samples` at which pixels are checked.
    pub fn next_check(&self, samples: u32) -> u32 {
        (samples / self.min_spp + 1).saturating_mul(self.min_spp)
    }

    /// Whether pixels are checked once they have taken `samples`.
    pub fn is_check(&self, samples: u32) -> bool {
        samples >= self.min_spp && samples.is_multiple_of(self.min_spp)
    }
}

/// A pixel's estimated relative error after `n` samples whose sum is
/// `sum` and whose odd-index samples sum to `odd` (Cycles,
/// `film_adaptive_sampling_convergence_check`): with `I` the mean of all
/// samples and `A` that of the odd half,
/// `error = Σ_c |I_c − A_c| / (10⁻⁴ + sqrt(Σ_c I_c))`. The square root
/// weighs the error as the eye sees it, relatively more in the dark; the
/// small constant keeps a black pixel's error finite.
pub fn pixel_error(sum: [f64; 3], odd: [f64; 3], n: u32) -> f64 {
    let halves = (n / 2).max(1) as f64;
    let all = sum.map(|s| s / n.max(1) as f64);
    let half = odd.map(|s| s / halves);
    let difference: f64 = (0..3).map(|c| (all[c] - half[c]).abs()).sum();
    let intensity: f64 = all.iter().sum::<f64>().max(0.0);
    difference / (1e-4 + intensity.sqrt())
}

/// The pixels that keep sampling after a check: an active pixel stays
/// active while any active pixel of its 3x3 neighbourhood has not
/// converged (Cycles dilates the unconverged pixels by one in x and y, so
/// that a noisy region's edge is not left to a lucky estimate).
pub fn still_active(
    width: usize,
    height: usize,
    active: &[bool],
    converged: impl Fn(usize) -> bool,
) -> Vec<bool> {
    let unconverged: Vec<bool> = (0..active.len())
        .map(|i| active[i] && !converged(i))
        .collect();
    (0..active.len())
        .map(|i| {
            let (x, y) = (i % width, i / width);
            active[i]
                && (y.saturating_sub(1)..(y + 2).min(height)).any(|ny| {
                    (x.saturating_sub(1)..(x + 2).min(width)).any(|nx| unconverged[ny * width + nx])
                })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_are_checked() {
        assert!(AdaptiveSampling::new(1, 8, 0.1).is_err());
        assert!(AdaptiveSampling::new(16, 8, 0.1).is_err());
        assert!(AdaptiveSampling::new(4, 8, 0.0).is_err());
        assert!(AdaptiveSampling::new(4, 8, f32::NAN).is_err());
        let a = AdaptiveSampling::new(4, 8, 0.1).unwrap();
        assert_eq!(
            (a.next_check(0), a.next_check(4), a.next_check(5)),
            (4, 8, 8)
        );
        assert!(a.is_check(8) && !a.is_check(2) && !a.is_check(6));
    }

    #[test]
    fn equal_halves_have_no_error_and_unequal_ones_some() {
        assert_eq!(pixel_error([4.0; 3], [2.0; 3], 4), 0.0);
        assert!(pixel_error([4.0; 3], [4.0; 3], 4) > 0.5);
        assert!(pixel_error([0.0; 3], [0.0; 3], 4) == 0.0);
    }

    #[test]
    fn unconverged_pixels_keep_their_neighbours_active() {
        // 4x3, everything converged but pixel (0, 0); pixel (3, 2) inactive.
        let mut active = vec![true; 12];
        active[11] = false;
        let next = still_active(4, 3, &active, |i| i != 0);
        let expected: Vec<bool> = (0..12)
            .map(|i| matches!((i % 4, i / 4), (0 | 1, 0 | 1)))
            .collect();
        assert_eq!(next, expected);
    }
}
