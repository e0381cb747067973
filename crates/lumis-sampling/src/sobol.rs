//! Sobol' sequence points from the Joe-Kuo generator matrices.

include!(concat!(env!("OUT_DIR"), "/sobol_matrices.rs"));

/// Dimensions with their own generator matrix.
pub const SOBOL_DIMENSIONS: usize = 1024;

/// Points and dimensions of [`SOBOL_PREFIX_REVERSED`]: the first 256 points
/// (every pixel's samples up to 256 spp) in the first 64 dimensions (a
/// camera sample and seven path vertices of a path tracer's requests).
pub const SOBOL_PREFIX_POINTS: usize = 256;
pub const SOBOL_PREFIX_DIMENSIONS: usize = 64;

/// [`sobol_reversed_u32`] of the first points and dimensions, evaluated at
/// compile time (64 KiB). Every pixel draws the same unscrambled points,
/// only their scrambles differ, so a per-pixel sampler reads a coordinate
/// here instead of running the matrix product per request; at 64 spp the
/// rows in use fit in 16 KiB.
pub static SOBOL_PREFIX_REVERSED: [[u32; SOBOL_PREFIX_DIMENSIONS]; SOBOL_PREFIX_POINTS] = {
    let mut table = [[0; SOBOL_PREFIX_DIMENSIONS]; SOBOL_PREFIX_POINTS];
    let mut index = 0;
    while index < SOBOL_PREFIX_POINTS {
        let mut dim = 0;
        while dim < SOBOL_PREFIX_DIMENSIONS {
            let mut bits = index;
            let mut bit = 0;
            let mut x = 0;
            while bits != 0 {
                if bits & 1 != 0 {
                    x ^= SOBOL_MATRICES_REVERSED[dim][bit];
                }
                bits >>= 1;
                bit += 1;
            }
            table[index][dim] = x;
            dim += 1;
        }
        index += 1;
    }
    table
};

/// Coordinate `dim` of Sobol' point `index` as a 32-bit fixed-point
/// fraction: the XOR of the matrix columns selected by the set bits of the
/// index (a matrix-vector product over GF(2)). Dimensions 0 and 1 together
/// are a (0,2)-sequence: every aligned block of 2^m points is a (0,m,2)-net.
#[inline]
pub fn sobol_u32(index: u32, dim: usize) -> u32 {
    sobol_reversed_u32(index, dim).reverse_bits()
}

/// [`sobol_u32`] with its bits reversed (first digit in bit 0), the form
/// [`crate::scramble::laine_karras_permutation`] takes.
#[inline]
pub fn sobol_reversed_u32(mut index: u32, dim: usize) -> u32 {
    let columns = &SOBOL_MATRICES_REVERSED[dim];
    let mut x = 0;
    while index != 0 {
        let bit = index.trailing_zeros();
        x ^= columns[bit as usize];
        index &= index - 1;
    }
    x
}

/// [`sobol_reversed_u32`] of `N` dimensions of the same point in one pass
/// over the index bits: a 2D request, or a 1D and a 2D request drawn
/// together, costs one loop, not one per dimension.
#[inline]
pub fn sobol_reversed_columns<const N: usize>(mut index: u32, dims: [usize; N]) -> [u32; N] {
    let columns = dims.map(|d| &SOBOL_MATRICES_REVERSED[d]);
    let mut x = [0; N];
    while index != 0 {
        let bit = index.trailing_zeros() as usize;
        for (x, column) in x.iter_mut().zip(&columns) {
            *x ^= column[bit];
        }
        index &= index - 1;
    }
    x
}

/// [`sobol_reversed_run`] where [`SOBOL_PREFIX_REVERSED`] holds it (a
/// table read), else `None`.
#[inline(always)]
pub fn sobol_reversed_tabulated<const N: usize>(index: u32, first: usize) -> Option<[u32; N]> {
    let row = SOBOL_PREFIX_REVERSED.get(index as usize)?;
    if first + N > SOBOL_PREFIX_DIMENSIONS {
        return None;
    }
    Some(std::array::from_fn(|k| row[first + k]))
}

/// [`sobol_reversed_columns`] of the `N` consecutive dimensions from
/// `first` (wrapping past the last dimension to the first): a table read for
/// the points and dimensions of [`SOBOL_PREFIX_REVERSED`], the matrix
/// product beyond.
#[inline]
pub fn sobol_reversed_run<const N: usize>(index: u32, first: usize) -> [u32; N] {
    if let Some(run) = sobol_reversed_tabulated(index, first) {
        return run;
    }
    sobol_reversed_columns(
        index,
        std::array::from_fn(|k| (first + k) % SOBOL_DIMENSIONS),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scramble::{owen_scramble, xor_scramble};

    #[test]
    fn first_points_match_the_published_sequence() {
        // Joe-Kuo dimension 3 (our index 2) starts 0, 1/2, 3/4, 1/4, 3/8, 7/8.
        let x: Vec<f64> = (0..6)
            .map(|i| sobol_u32(i, 2) as f64 / 4_294_967_296.0)
            .collect();
        assert_eq!(x, [0.0, 0.5, 0.75, 0.25, 0.375, 0.875]);
        // Dimension 1 (polynomial x + 1): 0, 1/2, 3/4, 1/4, 5/8, 1/8.
        let y: Vec<f64> = (0..6)
            .map(|i| sobol_u32(i, 1) as f64 / 4_294_967_296.0)
            .collect();
        assert_eq!(y, [0.0, 0.5, 0.75, 0.25, 0.625, 0.125]);
    }

    /// Every elementary interval of volume 2^-m (2^a by 2^b cells,
    /// a + b = m) holds exactly one of the first 2^m points.
    fn assert_02_net(points: &[(u32, u32)], m: u32, label: &str) {
        for a in 0..=m {
            let b = m - a;
            let mut seen = vec![false; 1 << m];
            for &(x, y) in points {
                let cx = if a == 0 { 0 } else { x >> (32 - a) };
                let cy = if b == 0 { 0 } else { y >> (32 - b) };
                let cell = ((cx << b) | cy) as usize;
                assert!(
                    !seen[cell],
                    "{label}: m {m}, {a}x{b} split, cell {cell} twice"
                );
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn first_two_dimensions_form_02_nets_before_and_after_scrambling() {
        for m in 0..=14u32 {
            let n = 1u32 << m;
            // Aligned blocks, not only the prefix: the second block of 2^m.
            for block in [0u32, 1] {
                let points: Vec<(u32, u32)> = (block * n..(block + 1) * n)
                    .map(|i| (sobol_u32(i, 0), sobol_u32(i, 1)))
                    .collect();
                assert_02_net(&points, m, "plain");
                let owen: Vec<(u32, u32)> = points
                    .iter()
                    .map(|&(x, y)| (owen_scramble(x, 0x9e37_79b9), owen_scramble(y, 0x7f4a_7c15)))
                    .collect();
                assert_02_net(&owen, m, "owen");
                let xor: Vec<(u32, u32)> = points
                    .iter()
                    .map(|&(x, y)| (xor_scramble(x, 0xdead_beef), xor_scramble(y, 0x1234_5678)))
                    .collect();
                assert_02_net(&xor, m, "xor");
            }
        }
    }

    #[test]
    fn every_dimension_is_a_01_sequence() {
        // Each one-dimensional projection: the first 2^m points fill the
        // 2^m intervals of width 2^-m once each.
        let m = 10;
        for dim in [0, 1, 2, 5, 100, 500, SOBOL_DIMENSIONS - 1] {
            let mut seen = vec![false; 1 << m];
            for i in 0..1u32 << m {
                let cell = (sobol_u32(i, dim) >> (32 - m)) as usize;
                assert!(!seen[cell], "dim {dim}");
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn the_prefix_table_and_runs_match_the_matrix_product() {
        for (index, row) in SOBOL_PREFIX_REVERSED.iter().enumerate() {
            for (dim, &x) in row.iter().enumerate() {
                assert_eq!(
                    x,
                    sobol_reversed_u32(index as u32, dim),
                    "index {index} dim {dim}"
                );
            }
        }
        // Inside the table, across its edges (index 256, dimension 64) and
        // wrapping past the last dimension.
        for index in [0u32, 1, 63, 255, 256, 1000, u32::MAX] {
            for first in [
                0,
                2,
                61,
                62,
                63,
                64,
                500,
                SOBOL_DIMENSIONS - 2,
                SOBOL_DIMENSIONS - 1,
            ] {
                let expect = |k: usize| sobol_reversed_u32(index, (first + k) % SOBOL_DIMENSIONS);
                assert_eq!(sobol_reversed_run::<1>(index, first), [expect(0)]);
                assert_eq!(
                    sobol_reversed_run::<2>(index, first),
                    [expect(0), expect(1)]
                );
                assert_eq!(
                    sobol_reversed_run::<3>(index, first),
                    [expect(0), expect(1), expect(2)],
                    "index {index} first {first}"
                );
            }
        }
    }

    #[test]
    fn pairs_and_triples_match_single_dimensions() {
        for index in [0u32, 1, 2, 3, 63, 64, 1000, u32::MAX] {
            for dims in [[0, 1], [2, 3], [7, 1023], [500, 500]] {
                assert_eq!(
                    sobol_reversed_columns(index, dims),
                    dims.map(|d| sobol_reversed_u32(index, d)),
                    "index {index} dims {dims:?}"
                );
            }
            for dims in [[2, 3, 4], [1021, 1022, 1023], [9, 9, 0]] {
                assert_eq!(
                    sobol_reversed_columns(index, dims),
                    dims.map(|d| sobol_reversed_u32(index, d)),
                    "index {index} dims {dims:?}"
                );
            }
        }
    }
}
