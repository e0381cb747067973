// The plugin interface's fingerprint: a hash of what a plugin and its
// host must agree on, so that a plugin built against a lumis-core whose
// traits or types changed shape is refused at load instead of crashing.
// Shared by `build.rs`, which computes it, and a unit test.

/// `source` without its comments, and each run of whitespace as one
/// space: documentation and formatting edits leave the fingerprint alone.
/// (A `//` inside a string literal cuts the line short the same way on
/// both sides, which is all a fingerprint needs.)
pub fn normalize(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    for line in source.lines() {
        let code = line.find("//").map_or(line, |i| &line[..i]);
        for word in code.split_whitespace() {
            if !out.is_empty() {
                out.push(' ');
            }
            out.push_str(word);
        }
    }
    out
}

/// FNV-1a (64 bit) over each source's path and normalized text, in the
/// order given, then the requirements of the crates whose types cross the
/// plugin boundary.
pub fn fingerprint(sources: &[(String, String)], boundary_crates: &[String]) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |bytes: &[u8]| {
        for &b in bytes {
            hash = (hash ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
        }
        // A separator, so that ("ab", "c") and ("a", "bc") differ.
        hash = (hash ^ 0xff).wrapping_mul(0x0000_0100_0000_01b3);
    };
    for (path, text) in sources {
        eat(path.as_bytes());
        eat(normalize(text).as_bytes());
    }
    for requirement in boundary_crates {
        eat(requirement.as_bytes());
    }
    hash
}
