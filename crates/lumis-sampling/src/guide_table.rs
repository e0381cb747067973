//! A guide table in front of the binary search that inverts a CDF: the
//! cutpoint method of Chen and Asau, "On generating random variates from
//! an empirical distribution" (AIIE Transactions 6, 1974), in Devroye's
//! "Non-Uniform Random Variate Generation" (1986), section III.2.4.
//!
//! `[0, 1)` is cut into as many equal intervals as the CDF has bins; the
//! table keeps, for each interval, the last CDF entry below it. A search
//! for `u` then starts at its interval's entry and ends at the next
//! interval's, a range that holds on average one entry (the intervals
//! are equally likely), where a binary search over the whole CDF takes
//! `log2 n` dependent loads. The answer is the binary search's, bit for
//! bit: the sampling warp, and so the stratification of low-discrepancy
//! samples, is unchanged.

/// Cutpoints over a non-decreasing CDF `cdf[0] = 0, ..., cdf[n] = 1`.
#[derive(Debug, Clone, PartialEq)]
pub struct GuideTable {
    /// `start[k]`: the last `i` with `interval(cdf[i]) < k`, or 0; `k` in
    /// `0..=n`, so that `start[k + 1]` bounds the search from above.
    start: Vec<u32>,
}

impl GuideTable {
    /// Bytes the table holds.
    pub fn byte_size(&self) -> usize {
        std::mem::size_of_val(self.start.as_slice())
    }

    /// The table of `cdf`, which must be non-decreasing (as a running
    /// sum is) with at least two entries.
    pub fn new(cdf: &[f32]) -> Self {
        let intervals = cdf.len() - 1;
        let mut start = Vec::with_capacity(intervals + 1);
        // How many entries lie in intervals before k.
        let mut below = 0;
        for k in 0..=intervals {
            while below < cdf.len() && interval(cdf[below], intervals) < k {
                below += 1;
            }
            start.push(below.saturating_sub(1) as u32);
        }
        Self { start }
    }

    /// The last `i` with `cdf[i] <= u`, or 0 if there is none (`u < 0`,
    /// NaN): `cdf.partition_point(|&c| c <= u).saturating_sub(1)`, for the
    /// `cdf` the table was built on.
    ///
    /// The interval map is monotone, so an entry in an earlier interval
    /// than `u`'s is below `u` and one in a later interval is above it: the
    /// answer lies in `start[k]..=start[k + 1]` for `u`'s interval `k`.
    #[inline]
    pub fn find(&self, cdf: &[f32], u: f32) -> usize {
        let k = interval(u, self.start.len() - 1);
        let (lo, hi) = (self.start[k] as usize, self.start[k + 1] as usize);
        lo + cdf[lo + 1..=hi].partition_point(|&c| c <= u)
    }

    /// Bytes held: for memory reports.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>() + 4 * self.start.len()
    }
}

/// Which of `n` equal intervals of `[0, 1)` holds `x`: monotone in `x`,
/// with everything below 0 (and NaN) in the first and everything from 1
/// on in the last.
#[inline]
fn interval(x: f32, n: usize) -> usize {
    ((x * n as f32) as usize).min(n - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Pcg32;

    /// The binary search the table stands in front of.
    fn search(cdf: &[f32], u: f32) -> usize {
        cdf.partition_point(|&c| c <= u).saturating_sub(1)
    }

    /// A CDF of `masses` as `Distribution1D` builds it (running sum in
    /// f64, the last entry 1).
    fn cdf_of(masses: &[f64]) -> Vec<f32> {
        let total: f64 = masses.iter().sum();
        let mut running = 0.0;
        let mut cdf = vec![0.0];
        for m in masses {
            running += m / total;
            cdf.push(running as f32);
        }
        *cdf.last_mut().unwrap() = 1.0;
        cdf
    }

    #[test]
    fn finds_what_the_binary_search_finds_bit_for_bit() {
        let mut rng = Pcg32::new(5, 9);
        let peaked: Vec<f64> = (0..512)
            .map(|i| if (200..203).contains(&i) { 1e6 } else { 1e-3 })
            .collect();
        let with_zeros: Vec<f64> = (0..97).map(|i| (i % 3 == 0) as u8 as f64).collect();
        let rough: Vec<f64> = (0..300).map(|_| (rng.next_f32() as f64).powi(8)).collect();
        let cases = [
            vec![1.0],
            vec![0.0, 0.0, 5.0, 0.0],
            vec![1.0; 1000],
            peaked,
            with_zeros,
            rough,
        ];
        for masses in &cases {
            let cdf = cdf_of(masses);
            let table = GuideTable::new(&cdf);
            // Every CDF entry and its neighbours, the interval ends, the
            // extremes and random numbers.
            let mut us: Vec<f32> = cdf
                .iter()
                .flat_map(|&c| {
                    [
                        c,
                        f32::from_bits(c.to_bits().max(1) - 1),
                        f32::from_bits(c.to_bits() + 1),
                    ]
                })
                .collect();
            let n = cdf.len() - 1;
            us.extend((0..=n).map(|k| k as f32 / n as f32));
            us.extend([
                0.0,
                -0.0,
                -1.0,
                1.0 - f32::EPSILON / 2.0,
                1.0,
                2.0,
                f32::NAN,
            ]);
            us.extend((0..20_000).map(|_| rng.next_f32()));
            for u in us {
                assert_eq!(
                    table.find(&cdf, u),
                    search(&cdf, u),
                    "{} bins, u = {u}",
                    masses.len()
                );
            }
        }
    }
}
