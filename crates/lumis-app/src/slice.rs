//! The sample indices one part of a render split over processes renders:
//! `--samples A..B`, or `--part K/N`, the `K`-th of `N` contiguous slices.

use std::fmt;

/// Sample indices `start..end` (half-open) of a render of `total` samples
/// per pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SampleSlice {
    pub start: u32,
    pub end: u32,
    pub total: u32,
}

impl fmt::Display for SampleSlice {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "samples {}..{} of {}", self.start, self.end, self.total)
    }
}

impl SampleSlice {
    /// `A..B` of a render of `total` spp: `0 <= A < B <= total`.
    pub fn parse_range(text: &str, total: u32) -> Result<Self, String> {
        let expected = || format!("'{text}': expected A..B, sample indices with A < B <= {total}");
        let (a, b) = text.split_once("..").ok_or_else(expected)?;
        let (start, end) = match (a.trim().parse::<u32>(), b.trim().parse::<u32>()) {
            (Ok(start), Ok(end)) => (start, end),
            _ => return Err(expected()),
        };
        if start >= end || end > total {
            return Err(expected());
        }
        Ok(Self { start, end, total })
    }

    /// Part `K/N` of a render of `total` spp, 0-based ([`Self::part`]).
    pub fn parse_part(text: &str, total: u32) -> Result<Self, String> {
        let expected = || format!("'{text}': expected K/N, a part K of N parts with 0 <= K < N");
        let (k, n) = text.split_once('/').ok_or_else(expected)?;
        let (k, n) = match (k.trim().parse::<u64>(), n.trim().parse::<u64>()) {
            (Ok(k), Ok(n)) if k < n => (k, n),
            _ => return Err(expected()),
        };
        Self::part(k as u32, n, total).map_err(|why| format!("'{text}': {why}"))
    }

    /// Part `k` of `n` (`k < n`) of a render of `total` spp: the slice
    /// `[k total / n, (k + 1) total / n)` (integer division), so the `n`
    /// parts cover `0..total` once, their sizes differing by at most one.
    pub fn part(k: u32, n: u64, total: u32) -> Result<Self, String> {
        if n > total as u64 {
            return Err(format!(
                "{n} parts of a {total}-spp render would leave some empty; at most {total} parts"
            ));
        }
        let bound = |k: u64| (k * total as u64 / n) as u32;
        Ok(Self {
            start: bound(k as u64),
            end: bound(k as u64 + 1),
            total,
        })
    }

    /// Samples per pixel of the slice.
    pub fn spp(&self) -> u32 {
        self.end - self.start
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_the_render_once() {
        for total in [1, 7, 64, 1000] {
            for n in 1..=total.min(9) {
                let mut next = 0;
                for k in 0..n {
                    let part = SampleSlice::parse_part(&format!("{k}/{n}"), total).unwrap();
                    assert_eq!(part.start, next);
                    assert!(part.spp() == total / n || part.spp() == total / n + 1);
                    next = part.end;
                }
                assert_eq!(next, total);
            }
        }
    }

    #[test]
    fn bad_slices_are_refused_with_what_was_expected() {
        for (text, total) in [("3/3", 8), ("1", 8), ("a/2", 8), ("0/0", 8), ("5/9", 8)] {
            let err = SampleSlice::parse_part(text, total).unwrap_err();
            assert!(err.contains(text), "{err}");
        }
        for text in ["4..4", "5..3", "0..9", "1-3", "..3"] {
            let err = SampleSlice::parse_range(text, 8).unwrap_err();
            assert!(err.contains("expected A..B"), "{err}");
        }
        assert_eq!(
            SampleSlice::parse_range("2..8", 8),
            Ok(SampleSlice {
                start: 2,
                end: 8,
                total: 8
            })
        );
    }
}
