//! Poisson disk patterns on the unit torus by dart throwing.
//!
//! Points are uniform random subject to a minimum distance, which removes
//! the low frequencies of the power spectrum (blue noise) without the
//! aliasing of a regular grid (Cook 1986, "Stochastic Sampling in Computer
//! Graphics"). The torus makes the pattern tileable, so a toroidal shift of
//! it is still a Poisson disk pattern.

use glam::Vec2;

use crate::rng::Pcg32;

/// Distance between neighbours of the densest packing of `count` points on
/// the unit torus, the hexagonal lattice: `sqrt(2 / (sqrt(3) count))`
/// (Lagae and Dutre 2008, "A Comparison of Methods for Generating Poisson
/// Disk Distributions", eq. 2). Dart throwing jams near 0.77 of it.
pub fn max_packing_distance(count: usize) -> f32 {
    (2.0 / (3f32.sqrt() * count as f32)).sqrt()
}

/// Darts thrown per requested point before giving up.
const ATTEMPTS_PER_POINT: usize = 2_000;

/// `count` points at toroidal distance >= `min_distance` from each other,
/// in the order they were accepted, or `None` when the darts run out (the
/// distance is too large for that many points).
///
/// A background grid with cells of side <= `min_distance / sqrt(2)` holds at
/// most one point per cell, so each dart checks a fixed neighbourhood.
pub fn poisson_disk_pattern(count: usize, min_distance: f32, rng: &mut Pcg32) -> Option<Vec<Vec2>> {
    let r = min_distance.max(0.0);
    let r2 = r * r;
    let grid = ((std::f32::consts::SQRT_2 / r).ceil() as usize).clamp(1, 4096);
    let reach = ((r * grid as f32).ceil() as isize).max(1);
    let check_all = 2 * reach as usize + 1 >= grid;
    let mut cells: Vec<u32> = vec![u32::MAX; grid * grid];
    let mut points: Vec<Vec2> = Vec::with_capacity(count);
    let mut attempts = 0usize;
    let max_attempts = ATTEMPTS_PER_POINT * count.max(1);
    while points.len() < count {
        if attempts == max_attempts {
            return None;
        }
        attempts += 1;
        let p = Vec2::new(rng.next_f32(), rng.next_f32());
        let too_close = |q: Vec2| {
            let d = (p - q).abs();
            let d = d.min(Vec2::ONE - d);
            d.length_squared() < r2
        };
        let cx = ((p.x * grid as f32) as usize).min(grid - 1);
        let cy = ((p.y * grid as f32) as usize).min(grid - 1);
        let rejected = if check_all {
            points.iter().any(|&q| too_close(q))
        } else {
            let g = grid as isize;
            (-reach..=reach).any(|dy| {
                (-reach..=reach).any(|dx| {
                    let x = (cx as isize + dx).rem_euclid(g) as usize;
                    let y = (cy as isize + dy).rem_euclid(g) as usize;
                    let i = cells[y * grid + x];
                    i != u32::MAX && too_close(points[i as usize])
                })
            })
        };
        if !rejected {
            if !check_all {
                cells[cy * grid + cx] = points.len() as u32;
            }
            points.push(p);
        }
    }
    Some(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_toroidal_distance(points: &[Vec2]) -> f32 {
        let mut best = f32::INFINITY;
        for (i, &p) in points.iter().enumerate() {
            for &q in &points[i + 1..] {
                let d = (p - q).abs();
                best = best.min(d.min(Vec2::ONE - d).length());
            }
        }
        best
    }

    #[test]
    fn respects_the_minimum_distance() {
        for (count, relative) in [(16usize, 0.7f32), (256, 0.7), (1024, 0.6), (3, 0.5)] {
            let r = relative * max_packing_distance(count);
            let points = poisson_disk_pattern(count, r, &mut Pcg32::new(1, 2)).unwrap();
            assert_eq!(points.len(), count);
            assert!(min_toroidal_distance(&points) >= r, "count {count}");
        }
    }

    #[test]
    fn an_impossible_distance_fails_instead_of_looping() {
        // Twice the densest packing distance cannot hold 64 points.
        let r = 2.0 * max_packing_distance(64);
        assert!(poisson_disk_pattern(64, r, &mut Pcg32::new(3, 4)).is_none());
    }

    #[test]
    fn zero_distance_is_uniform_random() {
        let points = poisson_disk_pattern(10_000, 0.0, &mut Pcg32::new(5, 6)).unwrap();
        let mean = points.iter().copied().sum::<Vec2>() / points.len() as f32;
        // sd of the mean of U(0,1): 1/sqrt(12 n) = 0.0029.
        assert!(
            (mean - Vec2::splat(0.5)).abs().max_element() < 0.015,
            "{mean}"
        );
    }
}
