//! Random permutations that need no table: element `i` of a permutation of
//! `0..n` chosen by a seed.

/// Kensler 2013, "Correlated Multi-Jittered Sampling" (Pixar technical memo
/// 13-01), listing 3: a hash that is a bijection on the next power of two,
/// applied repeatedly until it lands in `0..n` (cycle walking keeps it a
/// bijection on `0..n`).
pub fn permutation_element(mut i: u32, n: u32, seed: u32) -> u32 {
    debug_assert!(i < n);
    let mut w = n.wrapping_sub(1);
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    let p = seed;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            break;
        }
    }
    ((i as u64 + p as u64) % n as u64) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_a_bijection_for_many_sizes_and_seeds() {
        for n in [1u32, 2, 3, 5, 16, 17, 100, 1000] {
            for seed in [0u32, 1, 0xdead_beef, 12345] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permutation_element(i, n, seed) as usize;
                    assert!(!seen[j], "n {n} seed {seed}");
                    seen[j] = true;
                }
            }
        }
    }

    #[test]
    fn first_element_is_uniform_over_seeds() {
        // Chi-square of where element 0 goes, n = 8, 8000 seeds: 7 degrees
        // of freedom, 99.99th percentile 29.9.
        let n = 8;
        let mut counts = [0f64; 8];
        for s in 0..8000u64 {
            counts[permutation_element(0, n, crate::rng::hash_u64(s) as u32) as usize] += 1.0;
        }
        let chi2: f64 = counts.iter().map(|c| (c - 1000.0).powi(2) / 1000.0).sum();
        assert!(chi2 < 29.9, "{chi2} {counts:?}");
    }
}
