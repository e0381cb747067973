//! Randomisations of base-2 digit sequences that keep (t,m,s)-net structure.
//!
//! A 32-bit fixed-point value `x` stands for the binary fraction
//! `x / 2^32`, its most significant bit being the first digit.

/// Flips every digit of `x` that the seed says to: a random digital shift
/// in base 2 (random-digit scrambling without prefix dependence). Cheap,
/// keeps every elementary interval's count, but each digit flips the same
/// way for all points, so the pattern keeps its lattice look.
#[inline]
pub fn xor_scramble(x: u32, seed: u32) -> u32 {
    x ^ seed
}

/// Laine-Karras style hash: bit `i` of the result is bit `i` of `x` XOR a
/// function of the bits below it (additions carry upwards, multiplications
/// by even constants only mix lower bits into higher ones). Constants from
/// Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4), listing 3.
///
/// This is the nested scramble in the bit-reversed domain (first digit in
/// bit 0): samplers that keep their points reversed call it directly and
/// reverse once, on the way to a float ([`reversed_to_unit_f32`]).
#[inline]
pub fn laine_karras_permutation(mut x: u32, seed: u32) -> u32 {
    x = x.wrapping_add(seed);
    x ^= x.wrapping_mul(0x6c50_b47c);
    x ^= x.wrapping_mul(0xb82f_1e52);
    x ^= x.wrapping_mul(0xc7af_e638);
    x ^= x.wrapping_mul(0x8d22_f6e6);
    x
}

/// Owen's nested uniform scrambling in base 2, hash-based (Burley 2020):
/// digit `k` is flipped by a pseudo-random function of digits `0..k`.
/// Reversing the bits makes the Laine-Karras hash, which mixes low bits into
/// high ones, mix leading digits into trailing ones. Every elementary
/// interval keeps its number of points, and each point becomes uniform on
/// `[0,1)`.
#[inline]
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    laine_karras_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// A 32-bit fixed-point fraction as an `f32` in `[0, 1)`: the top 24 bits,
/// so the value is exact and never rounds up to 1.
#[inline]
pub fn fixed_to_unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// `REVERSED_BYTES[b]` is `b` with its 8 bits reversed.
const REVERSED_BYTES: [u8; 256] = reversed_bytes();

const fn reversed_bytes() -> [u8; 256] {
    let mut table = [0; 256];
    let mut i = 0;
    while i < 256 {
        table[i] = (i as u8).reverse_bits();
        i += 1;
    }
    table
}

/// The top 24 bits of `x.reverse_bits()` (the low 24 bits of `x`, reversed)
/// from three lookups in a 256-byte table. x86 has no bit-reversal
/// instruction: `u32::reverse_bits` is a byte swap and three mask-and-shift
/// rounds (about 15 instructions), and a float needs only 24 of its bits.
#[inline]
pub fn reverse_bits_top24(x: u32) -> u32 {
    let byte = |shift: u32| REVERSED_BYTES[(x >> shift) as u8 as usize] as u32;
    (byte(0) << 16) | (byte(8) << 8) | byte(16)
}

/// `[a.reverse_bits(), b.reverse_bits()]` as one 64-bit reversal, the same
/// instruction sequence as a single 32-bit one: reversing `a << 32 | b`
/// puts `rev(b)` in the high half and `rev(a)` in the low one.
#[inline]
pub fn reverse_bits_pair(a: u32, b: u32) -> [u32; 2] {
    let r = ((a as u64) << 32 | b as u64).reverse_bits();
    [r as u32, (r >> 32) as u32]
}

/// The fixed-point fraction whose bit reversal is `reversed`, as an `f32` in
/// `[0, 1)`: `fixed_to_unit_f32(reversed.reverse_bits())`, exactly.
#[inline]
pub fn reversed_to_unit_f32(reversed: u32) -> f32 {
    reverse_bits_top24(reversed) as f32 * (1.0 / 16_777_216.0)
}

/// [`reversed_to_unit_f32`] of two values, with one 64-bit reversal.
#[inline]
pub fn reversed_pair_to_unit_f32(reversed: [u32; 2]) -> [f32; 2] {
    reverse_bits_pair(reversed[0], reversed[1]).map(fixed_to_unit_f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values that exercise every byte position: all ones in one byte,
    /// alternating patterns, single bits, and a pseudo-random sweep.
    fn probe_values() -> impl Iterator<Item = u32> {
        let patterns = [
            0,
            u32::MAX,
            0xaaaa_aaaa,
            0x5555_5555,
            0x0123_4567,
            0x89ab_cdef,
        ];
        let singles = (0..32).map(|i| 1u32 << i);
        let sweep = (0..1u32 << 16).map(|i| crate::rng::hash_u64(i as u64) as u32);
        patterns.into_iter().chain(singles).chain(sweep)
    }

    #[test]
    fn table_reversal_matches_reverse_bits() {
        for x in probe_values() {
            assert_eq!(reverse_bits_top24(x), x.reverse_bits() >> 8, "{x:#x}");
            assert_eq!(
                reversed_to_unit_f32(x),
                fixed_to_unit_f32(x.reverse_bits()),
                "{x:#x}"
            );
        }
        for b in 0..=255u8 {
            assert_eq!(REVERSED_BYTES[b as usize], b.reverse_bits());
        }
    }

    #[test]
    fn pair_reversal_matches_reverse_bits() {
        for (a, b) in probe_values().zip(probe_values().skip(7)) {
            assert_eq!(
                reverse_bits_pair(a, b),
                [a.reverse_bits(), b.reverse_bits()]
            );
            assert_eq!(
                reversed_pair_to_unit_f32([a, b]),
                [reversed_to_unit_f32(a), reversed_to_unit_f32(b)]
            );
        }
    }

    #[test]
    fn owen_scramble_is_a_nested_permutation() {
        // Two values sharing their first k digits still share their first k
        // digits after scrambling (same prefix -> same flips), and the map
        // restricted to the first 12 digits is a bijection.
        let seed = 0x1234_5678;
        let mut seen = vec![false; 1 << 12];
        for prefix in 0u32..(1 << 12) {
            let x = prefix << 20;
            let y = owen_scramble(x, seed);
            let z = owen_scramble(x | 0xfffff, seed);
            assert_eq!(y >> 20, z >> 20, "prefix {prefix}");
            assert!(!seen[(y >> 20) as usize]);
            seen[(y >> 20) as usize] = true;
        }
    }

    #[test]
    fn owen_scramble_depends_on_the_seed_and_flips_the_first_digit_half_the_time() {
        let flips = (0..4096u32)
            .filter(|&s| owen_scramble(0, crate::rng::hash_u64(s as u64) as u32) >> 31 == 1)
            .count();
        // Binomial(4096, 1/2): sd = 32.
        assert!((flips as i64 - 2048).abs() < 5 * 32, "{flips}");
    }

    #[test]
    fn fixed_point_conversion_stays_below_one() {
        assert_eq!(fixed_to_unit_f32(0), 0.0);
        assert!(fixed_to_unit_f32(u32::MAX) < 1.0);
        assert_eq!(fixed_to_unit_f32(1 << 31), 0.5);
    }
}
