//! Power spectra of 2D point sets: the Fourier view of where samples go
//! (Ulichney 1987; Lagae and Dutre 2008, "A Comparison of Methods for
//! Generating Poisson Disk Distributions", section 2).

use rayon::prelude::*;

/// The periodogram `P(k) = |sum_j exp(-2 pi i k . x_j)|^2 / N` on the
/// integer frequencies `k` in `[-K/2, K/2)^2`, row-major with `k_y` as row,
/// DC at `(K/2, K/2)`. For uniform random points `E[P(k)] = 1` for `k != 0`;
/// blue noise is low near the centre. `exp(-2 pi i (kx x + ky y))` factors
/// into `e_x(kx) e_y(ky)`, so each point costs one table per axis.
pub fn periodogram(points: &[[f64; 2]], size: usize) -> Vec<f64> {
    let half = (size / 2) as f64;
    // e[j][k] = exp(-2 pi i (k - K/2) x_j) per axis, as (re, im).
    let table = |axis: usize| -> Vec<(f64, f64)> {
        points
            .iter()
            .flat_map(|p| {
                (0..size).map(move |k| {
                    let phase = -2.0 * std::f64::consts::PI * (k as f64 - half) * p[axis];
                    (phase.cos(), phase.sin())
                })
            })
            .collect()
    };
    let (ex, ey) = (table(0), table(1));
    let n = points.len().max(1) as f64;
    (0..size)
        .into_par_iter()
        .flat_map_iter(|ky| {
            let mut row = vec![(0.0f64, 0.0f64); size];
            for j in 0..points.len() {
                let (yr, yi) = ey[j * size + ky];
                for (acc, &(xr, xi)) in row.iter_mut().zip(&ex[j * size..(j + 1) * size]) {
                    acc.0 += xr * yr - xi * yi;
                    acc.1 += xr * yi + xi * yr;
                }
            }
            row.into_iter().map(move |(re, im)| (re * re + im * im) / n)
        })
        .collect()
}

/// Radially averaged power spectrum and anisotropy: the mean of `P` over
/// annuli `r <= |k| < r + 1`, and the anisotropy `var / mean^2` over each
/// annulus (Lagae and Dutre 2008; 1, i.e. 0 dB, for white noise, whose
/// periodogram values are exponentially distributed; larger when the
/// spectrum has directional structure). The DC term is left out.
pub fn radial_average(psd: &[f64], size: usize) -> (Vec<f64>, Vec<f64>) {
    let half = size as isize / 2;
    let rings = size / 2;
    let mut sum = vec![0.0; rings];
    let mut sum2 = vec![0.0; rings];
    let mut count = vec![0usize; rings];
    for ky in 0..size {
        for kx in 0..size {
            let (dx, dy) = (kx as isize - half, ky as isize - half);
            let r = ((dx * dx + dy * dy) as f64).sqrt() as usize;
            if (dx, dy) == (0, 0) || r >= rings {
                continue;
            }
            let v = psd[ky * size + kx];
            sum[r] += v;
            sum2[r] += v * v;
            count[r] += 1;
        }
    }
    let mut mean = vec![0.0; rings];
    let mut anisotropy = vec![0.0; rings];
    for r in 0..rings {
        if count[r] > 0 {
            let m = sum[r] / count[r] as f64;
            mean[r] = m;
            let var = sum2[r] / count[r] as f64 - m * m;
            anisotropy[r] = if m > 0.0 { var / (m * m) } else { 0.0 };
        }
    }
    (mean, anisotropy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use lumis_sampling::Pcg32;

    #[test]
    fn uniform_random_points_have_a_flat_unit_spectrum() {
        // Each P(k), k != 0, is ~Exponential(1) for uniform points; the mean
        // over 32x32 - 1 frequencies and 20 realisations has sd ~ 1/143.
        let size = 32;
        let mut rng = Pcg32::new(1, 1);
        let mut total = vec![0.0; size * size];
        let realisations = 20;
        for _ in 0..realisations {
            let points: Vec<[f64; 2]> = (0..256)
                .map(|_| [rng.next_f32() as f64, rng.next_f32() as f64])
                .collect();
            for (t, p) in total.iter_mut().zip(periodogram(&points, size)) {
                *t += p / realisations as f64;
            }
        }
        let dc = size / 2 * size + size / 2;
        assert!((total[dc] - 256.0).abs() < 1e-6, "DC = N");
        let mean: f64 = total
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != dc)
            .map(|(_, v)| v)
            .sum::<f64>()
            / (size * size - 1) as f64;
        assert!((mean - 1.0).abs() < 5.0 / 143.0, "{mean}");
    }

    #[test]
    fn a_regular_grid_only_has_power_at_multiples_of_its_frequency() {
        let g = 8;
        let points: Vec<[f64; 2]> = (0..g * g)
            .map(|i| [(i % g) as f64 / g as f64, (i / g) as f64 / g as f64])
            .collect();
        let size = 32;
        let psd = periodogram(&points, size);
        for ky in 0..size {
            for kx in 0..size {
                let (fx, fy) = (kx as i64 - 16, ky as i64 - 16);
                let on_lattice = fx % g as i64 == 0 && fy % g as i64 == 0;
                let v = psd[ky * size + kx];
                if on_lattice {
                    assert!((v - (g * g) as f64).abs() < 1e-6);
                } else {
                    assert!(v < 1e-9, "{fx},{fy}: {v}");
                }
            }
        }
        let (radial, _) = radial_average(&psd, size);
        assert!(radial[1..8].iter().all(|&v| v < 1e-9));
        assert!(radial[8] > 1.0);
    }
}
