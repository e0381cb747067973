//! Radical inverses in prime bases (the Halton and Hammersley sequences),
//! plain and randomised digit by digit.

use crate::rng::hash_u64;

/// Largest `f32` below one: where sample values are clamped so that a
/// rounded-up value never reaches 1.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// How the digits of a radical inverse are randomised.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DigitScramble {
    /// The plain sequence: identical in every pixel and every seed.
    None,
    /// One random permutation per digit position, the same for all points
    /// (Faure and Tezuka's random-digit scrambling; pbrt's PermuteDigits).
    RandomDigits,
    /// Owen 1995 nested uniform scrambling: the permutation of digit `k`
    /// depends on digits `0..k`, so every elementary interval is shuffled
    /// independently.
    Owen,
}

/// Digits beyond this weight cannot change an `f32` in `[0, 1)`.
const LAST_DIGIT_WEIGHT: f64 = 1.0 / 16_777_216.0;

/// Van der Corput's radical inverse: the base-`base` digits of `a` mirrored
/// about the radix point, `sum_k d_k base^-(k+1)`.
pub fn radical_inverse(base: u32, mut a: u64) -> f32 {
    let b = base as u64;
    let inv_base = 1.0 / base as f64;
    let (mut reversed, mut weight) = (0.0f64, 1.0f64);
    while a > 0 {
        weight *= inv_base;
        reversed += (a % b) as f64 * weight;
        a /= b;
    }
    (reversed as f32).min(ONE_MINUS_EPSILON)
}

/// The radical inverse with each digit passed through a random permutation
/// chosen by `seed` (and, for Owen scrambling, by the digits before it).
///
/// The permutation of a digit is the affine map `d -> (m d + c) mod base`
/// with `m` in `1..base` and `c` in `0..base` drawn from a hash: for a prime
/// base it is a bijection, uniform in `c`, which is all the equidistribution
/// argument needs (a random linear scrambling in the sense of Matousek 1998,
/// "On the L2-discrepancy for anchored boxes"). In base 2 it is exactly a
/// random flip. Digits are processed until their weight drops below `f32`
/// resolution, because scrambling turns the infinite tail of zero digits
/// into random digits.
pub fn scrambled_radical_inverse(base: u32, mut a: u64, seed: u64, scramble: DigitScramble) -> f32 {
    if scramble == DigitScramble::None {
        return radical_inverse(base, a);
    }
    let inv_base = 1.0 / base as f64;
    let (mut value, mut weight) = (0.0f64, inv_base);
    let mut key = seed;
    while weight >= LAST_DIGIT_WEIGHT {
        let digit = next_digit(&mut a, base);
        // Range reductions by multiply-high (Lemire 2019), not division.
        let h = hash_u64(key);
        let multiplier = 1 + (((h >> 32) * (base as u64 - 1)) >> 32) as u32;
        let shift = (((h & 0xffff_ffff) * base as u64) >> 32) as u32;
        let permuted = if base == 2 {
            digit ^ shift
        } else {
            (multiplier * digit + shift) % base
        };
        value += permuted as f64 * weight;
        key = match scramble {
            DigitScramble::Owen => {
                hash_u64(key ^ (digit as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15))
            }
            _ => key.wrapping_add(0x9e37_79b9_7f4a_7c15),
        };
        weight *= inv_base;
    }
    (value as f32).min(ONE_MINUS_EPSILON)
}

/// Pops the lowest base-`base` digit of `a`; 32-bit division when `a` fits,
/// which is most of the time and several times faster than 64-bit.
#[inline]
fn next_digit(a: &mut u64, base: u32) -> u32 {
    if let Ok(small) = u32::try_from(*a) {
        *a = (small / base) as u64;
        small % base
    } else {
        let digit = (*a % base as u64) as u32;
        *a /= base as u64;
        digit
    }
}

/// The index whose first `digits` base-`base` digits, mirrored, are the
/// digits of `inverse`: the integer `a < base^digits` with
/// `radical_inverse(base, a) * base^digits == inverse` (pbrt-v4,
/// `InverseRadicalInverse`).
pub fn inverse_radical_inverse(mut inverse: u64, base: u32, digits: u32) -> u64 {
    let b = base as u64;
    let mut index = 0;
    for _ in 0..digits {
        index = index * b + inverse % b;
        inverse /= b;
    }
    index
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
        assert_eq!(radical_inverse(2, 1), 0.5);
        assert_eq!(radical_inverse(2, 6), 0.375); // 110 -> 0.011
        assert!((radical_inverse(3, 5) - 7.0 / 9.0).abs() < 1e-7); // 12 -> 0.21
        assert_eq!(radical_inverse(5, 0), 0.0);
    }

    #[test]
    fn inverse_radical_inverse_inverts() {
        for base in [2u32, 3, 5] {
            let digits = 4;
            let n = (base as u64).pow(digits);
            for a in 0..n {
                let inverse = (radical_inverse(base, a) as f64 * n as f64).round() as u64;
                assert_eq!(inverse_radical_inverse(inverse, base, digits), a);
            }
        }
    }

    /// The first base^k points fall one in each interval of width base^-k,
    /// whatever the scrambling.
    #[test]
    fn scrambling_keeps_stratification() {
        for base in [2u32, 3, 5, 7, 13] {
            for scramble in [DigitScramble::RandomDigits, DigitScramble::Owen] {
                for seed in 0..4u64 {
                    let k = if base < 7 { 4 } else { 2 };
                    let n = (base as usize).pow(k);
                    let mut seen = vec![false; n];
                    for a in 0..n as u64 {
                        let x = scrambled_radical_inverse(base, a, hash_u64(seed), scramble);
                        let cell = (x as f64 * n as f64) as usize;
                        assert!(!seen[cell], "base {base} {scramble:?} seed {seed} a {a}");
                        seen[cell] = true;
                    }
                }
            }
        }
    }

    #[test]
    fn scrambled_values_are_uniform_and_seed_dependent() {
        // One point (index 3, base 5) over many seeds: chi-square over 50
        // bins, 49 degrees of freedom, 99.99th percentile 95.
        for scramble in [DigitScramble::RandomDigits, DigitScramble::Owen] {
            let mut counts = [0f64; 50];
            for seed in 0..50_000u64 {
                let x = scrambled_radical_inverse(5, 3, hash_u64(seed), scramble);
                counts[(x * 50.0) as usize] += 1.0;
            }
            let chi2: f64 = counts.iter().map(|c| (c - 1000.0).powi(2) / 1000.0).sum();
            assert!(chi2 < 95.0, "{scramble:?}: {chi2}");
        }
    }
}
