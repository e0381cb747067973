//! The first primes, computed at compile time: the bases of the Halton
//! sequence, one per dimension.

/// How many primes (and so Halton dimensions) the table holds, as in pbrt.
pub const PRIME_TABLE_SIZE: usize = 1000;

pub static PRIMES: [u32; PRIME_TABLE_SIZE] = first_primes();

const fn first_primes<const N: usize>() -> [u32; N] {
    let mut primes = [0u32; N];
    let mut count = 0;
    let mut candidate = 2u32;
    while count < N {
        let mut is_prime = true;
        let mut k = 0;
        while k < count && primes[k] * primes[k] <= candidate {
            if candidate.is_multiple_of(primes[k]) {
                is_prime = false;
                break;
            }
            k += 1;
        }
        if is_prime {
            primes[count] = candidate;
            count += 1;
        }
        candidate += 1;
    }
    primes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_primes() {
        assert_eq!(&PRIMES[..10], &[2, 3, 5, 7, 11, 13, 17, 19, 23, 29]);
        // The 1000th prime.
        assert_eq!(PRIMES[999], 7919);
    }
}
