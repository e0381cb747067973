//! Turns the Joe-Kuo direction numbers (`data/new-joe-kuo-6.1024.txt`) into
//! the 32-bit generator matrices of the first 1024 Sobol' dimensions, so the
//! sampler reads a static table instead of parsing at start-up.

use std::fmt::Write as _;
use std::path::Path;

const BITS: usize = 32;

fn main() {
    let manifest = std::env::var("CARGO_MANIFEST_DIR").unwrap();
    let data = Path::new(&manifest).join("data/new-joe-kuo-6.1024.txt");
    println!("cargo:rerun-if-changed={}", data.display());
    let text = std::fs::read_to_string(&data).expect("reading the Joe-Kuo table");

    // Dimension 0 is the van der Corput sequence: the identity matrix
    // (column k sets output bit 31 - k).
    let mut matrices: Vec<[u32; BITS]> = vec![std::array::from_fn(|k| 1u32 << (31 - k))];
    for (line_number, line) in text.lines().enumerate().skip(1) {
        let fields: Vec<u32> = line
            .split_whitespace()
            .map(|f| f.parse().expect("a number in the Joe-Kuo table"))
            .collect();
        let (s, a) = (fields[1] as usize, fields[2]);
        let m = &fields[3..];
        assert_eq!(
            m.len(),
            s,
            "line {}: expected {s} direction numbers",
            line_number + 1
        );
        matrices.push(direction_vectors(s, a, m));
    }

    // Stored bit-reversed (first digit in the lowest bit): Owen scrambling
    // works on reversed values, so this saves one reversal per sample.
    let mut out = String::from("/// Generator matrices of Sobol' dimensions 0..1024, one `u32` column per\n/// index bit (bit k of the index selects column k), each column bit-reversed.\npub static SOBOL_MATRICES_REVERSED: [[u32; 32]; ");
    writeln!(out, "{}] = [", matrices.len()).unwrap();
    for m in &matrices {
        out.push_str("    [");
        for v in m {
            write!(out, "{:#010x}, ", v.reverse_bits()).unwrap();
        }
        out.push_str("],\n");
    }
    out.push_str("];\n");
    let dest = Path::new(&std::env::var("OUT_DIR").unwrap()).join("sobol_matrices.rs");
    std::fs::write(dest, out).unwrap();
}

/// Joe and Kuo 2008, "Constructing Sobol sequences with better
/// two-dimensional projections", section 2: V_k = m_k 2^(32-k) for k <= s,
/// then the recurrence of the primitive polynomial of degree s with inner
/// coefficients a.
fn direction_vectors(s: usize, a: u32, m: &[u32]) -> [u32; BITS] {
    let mut v = [0u32; BITS + 1]; // 1-based like the paper
    for k in 1..=BITS {
        v[k] = if k <= s {
            m[k - 1] << (BITS - k)
        } else {
            let mut x = v[k - s] ^ (v[k - s] >> s);
            for j in 1..s {
                if (a >> (s - 1 - j)) & 1 == 1 {
                    x ^= v[k - j];
                }
            }
            x
        };
    }
    std::array::from_fn(|k| v[k + 1])
}
