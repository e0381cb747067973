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

/// `REVERSED_BYTE_FRACTIONS[k][b]` is the fraction that byte `k` of a
/// bit-reversed value contributes: `b` reversed, times `2^-8(k+1)`.
const REVERSED_BYTE_FRACTIONS: [[f32; 256]; 3] = reversed_byte_fractions();

const fn reversed_byte_fractions() -> [[f32; 256]; 3] {
    let mut table = [[0.0; 256]; 3];
    let mut k = 0;
    while k < 3 {
        let scale = 1.0 / (1u32 << (8 * (k + 1))) as f32;
        let mut b = 0;
        while b < 256 {
            table[k][b] = REVERSED_BYTES[b] as f32 * scale;
            b += 1;
        }
        k += 1;
    }
    table
}

/// The fixed-point fraction whose bit reversal is `reversed`, as an `f32` in
/// `[0, 1)`: `fixed_to_unit_f32(reversed.reverse_bits())`, exactly. Each of
/// the low three bytes looks up its share of the fraction; the shares are
/// multiples of `2^-24` below 1, so their sum is exact in 24 mantissa bits.
/// Three lookups and two additions replace the bit reversal, the integer
/// conversion and the scaling.
#[inline]
pub fn reversed_to_unit_f32(reversed: u32) -> f32 {
    let share = |k: usize| REVERSED_BYTE_FRACTIONS[k][(reversed >> (8 * k)) as u8 as usize];
    share(0) + share(1) + share(2)
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
    fn byte_fractions_match_reverse_bits_exactly() {
        for b in 0..=255u8 {
            assert_eq!(REVERSED_BYTES[b as usize], b.reverse_bits());
        }
        // Every pattern of the 24 bits that reach the float, then values
        // whose ignored top byte is set.
        for x in (0..1u32 << 24).chain(probe_values()) {
            let expected = fixed_to_unit_f32(x.reverse_bits());
            assert_eq!(
                reversed_to_unit_f32(x).to_bits(),
                expected.to_bits(),
                "{x:#x}"
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
