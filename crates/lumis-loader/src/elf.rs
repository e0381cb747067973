//! A shared library's file checked before `dlopen` maps it: a file cut
//! short maps pages past its end, and touching them kills the process with
//! SIGBUS instead of giving an error. ELF (System V gABI, "ELF Header" and
//! "Program Header"), 64-bit little-endian, the format of the Linux targets
//! lumis builds for; other systems' loaders are left to report.

use std::io::Read;

const HEADER: usize = 64;
const PT_LOAD: u32 = 1;

/// Why the ELF file of `len` bytes whose start is `bytes` cannot be a
/// loadable library, or `None` where its header, program headers, loaded
/// segments and section headers all lie within the file.
fn problem(bytes: &[u8], len: u64) -> Option<String> {
    if bytes.len() < HEADER || bytes[..4] != *b"\x7fELF" {
        return Some("it is not an ELF shared library (no ELF header)".into());
    }
    if bytes[4] != 2 || bytes[5] != 1 {
        return Some("it is not a 64-bit little-endian ELF library".into());
    }
    let u16_at = |at: usize| u16::from_le_bytes([bytes[at], bytes[at + 1]]) as u64;
    let u64_at = |b: &[u8], at: usize| u64::from_le_bytes(b[at..at + 8].try_into().unwrap());
    let (ph_offset, sh_offset) = (u64_at(bytes, 0x20), u64_at(bytes, 0x28));
    let (ph_size, ph_count) = (u16_at(0x36), u16_at(0x38));
    let (sh_size, sh_count) = (u16_at(0x3a), u16_at(0x3c));
    let table_end = |offset: u64, size: u64, count: u64| offset.checked_add(size * count);
    match table_end(sh_offset, sh_size, sh_count) {
        Some(end) if end <= len => {}
        _ => {
            return Some(format!(
                "it is cut short: its section headers end past its {len} bytes"
            ))
        }
    }
    let ph_end = match table_end(ph_offset, ph_size, ph_count) {
        Some(end) if end <= len && ph_size >= 56 && end <= bytes.len() as u64 => end,
        _ => return Some(format!("its program headers do not fit in its {len} bytes")),
    };
    for at in (ph_offset..ph_end).step_by(ph_size as usize) {
        let header = &bytes[at as usize..(at + ph_size) as usize];
        let kind = u32::from_le_bytes(header[..4].try_into().unwrap());
        let (offset, size) = (u64_at(header, 8), u64_at(header, 32));
        if kind == PT_LOAD && offset.checked_add(size).is_none_or(|end| end > len) {
            return Some(format!(
                "it is cut short: a loaded segment ends past its {len} bytes"
            ));
        }
    }
    None
}

/// Checks the library file at `path` (see the module documentation);
/// the error says what is wrong with it.
pub fn check(path: &std::path::Path) -> Result<(), String> {
    let file = std::fs::File::open(path).map_err(|e| format!("it cannot be read: {e}"))?;
    let meta = file
        .metadata()
        .map_err(|e| format!("it cannot be read: {e}"))?;
    if !meta.is_file() {
        return Err("it is not a regular file".into());
    }
    // The program headers sit near the start; 64 KiB holds them in any
    // library a linker writes.
    let mut start = Vec::new();
    file.take(64 * 1024)
        .read_to_end(&mut start)
        .map_err(|e| format!("it cannot be read: {e}"))?;
    match problem(&start, meta.len()) {
        Some(problem) => Err(problem),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The smallest header `problem` reads: one program header (a loaded
    /// segment of `segment_end` bytes) after the ELF header, no sections.
    fn library(segment_end: u64) -> Vec<u8> {
        let mut b = vec![0u8; HEADER + 56];
        b[..4].copy_from_slice(b"\x7fELF");
        b[4] = 2;
        b[5] = 1;
        b[0x20..0x28].copy_from_slice(&(HEADER as u64).to_le_bytes());
        b[0x36..0x38].copy_from_slice(&56u16.to_le_bytes());
        b[0x38..0x3a].copy_from_slice(&1u16.to_le_bytes());
        b[HEADER..HEADER + 4].copy_from_slice(&PT_LOAD.to_le_bytes());
        b[HEADER + 32..HEADER + 40].copy_from_slice(&segment_end.to_le_bytes());
        b
    }

    #[test]
    fn whole_files_pass_and_cut_ones_do_not() {
        let b = library(4096);
        assert_eq!(problem(&b, 4096), None);
        assert!(problem(&b, 4095).unwrap().contains("cut short"));
        assert!(problem(&b[..40], 40).unwrap().contains("no ELF header"));
        assert!(problem(b"not an ELF file", 15)
            .unwrap()
            .contains("no ELF header"));
        let mut wrapping = library(u64::MAX);
        assert!(problem(&wrapping, 4096).unwrap().contains("cut short"));
        wrapping[4] = 1;
        assert!(problem(&wrapping, 4096).unwrap().contains("64-bit"));
    }

    /// A real library passes; the same bytes cut in half fail.
    #[test]
    fn a_system_library_passes_whole_and_fails_truncated() {
        let Some(libm) = [
            "/lib/x86_64-linux-gnu/libm.so.6",
            "/usr/lib/x86_64-linux-gnu/libm.so.6",
            "/lib64/libm.so.6",
        ]
        .into_iter()
        .map(std::path::Path::new)
        .find(|p| p.exists()) else {
            eprintln!("no libm at the usual paths; the synthetic headers above cover the checks");
            return;
        };
        assert_eq!(check(libm), Ok(()));
        let bytes = std::fs::read(libm).unwrap();
        let cut = std::env::temp_dir().join(format!("lumis-cut-{}.so", std::process::id()));
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let result = check(&cut);
        std::fs::remove_file(&cut).unwrap();
        assert!(result.unwrap_err().contains("cut short"));
    }
}
