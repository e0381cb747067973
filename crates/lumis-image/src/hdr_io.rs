//! Radiance `.hdr` (RGBE) files, read through the `radiant` crate.

use std::io::{BufRead, BufReader, Seek, SeekFrom};
use std::path::Path;

use lumis_files::IMAGE_FILE;

use crate::{limits, open_image, Image, ImageError};

/// The first bytes of every Radiance file.
const MAGIC: &[u8] = b"#?";

/// Whether `path` starts as a Radiance file does (`#?RADIANCE`, `#?RGBE`).
/// Only a regular file is opened (a FIFO would block).
pub fn is_hdr(path: &Path) -> bool {
    use std::io::Read;
    let mut start = [0u8; 2];
    lumis_files::open_regular(path, IMAGE_FILE)
        .is_ok_and(|mut f| f.read_exact(&mut start).is_ok() && start == MAGIC)
}

/// Reads a Radiance RGBE file (flat or run-length encoded scanlines),
/// once its resolution line is checked against what lumis decodes
/// ([`crate::limits`]).
pub fn read_hdr(path: &Path) -> Result<Image, ImageError> {
    let unreadable = |message: String| ImageError::Format {
        path: path.to_path_buf(),
        message,
    };
    let io = |source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    };
    let (mut file, _) = open_image(path)?;
    let (width, height) = claimed_size(BufReader::new(&mut file)).map_err(unreadable)?;
    limits::check_claimed_size("Radiance", width, height).map_err(|message| {
        ImageError::Refused {
            path: path.to_path_buf(),
            message,
        }
    })?;
    file.seek(SeekFrom::Start(0)).map_err(io)?;
    let hdr = radiant::load(BufReader::new(file))
        .map_err(|e| unreadable(format!("not a readable Radiance .hdr: {e}")))?;
    Ok(Image {
        width: hdr.width,
        height: hdr.height,
        pixels: hdr.data.iter().map(|p| [p.r, p.g, p.b]).collect(),
    })
}

/// The longest header read before the resolution line: Radiance writers
/// put a few short lines there.
const MAX_HEADER_BYTES: u64 = 64 * 1024;

/// The `(width, height)` a Radiance file's resolution line claims
/// (`-Y 512 +X 1024`, either axis first, either sign), read from `reader`
/// through that line.
fn claimed_size(reader: impl BufRead) -> Result<(u64, u64), String> {
    let mut lines = reader.take(MAX_HEADER_BYTES).split(b'\n');
    // The header's lines end at an empty one; the resolution line follows.
    loop {
        match lines.next() {
            Some(Ok(line)) if line.is_empty() => break,
            Some(Ok(_)) => {}
            Some(Err(e)) => return Err(format!("cannot read its header: {e}")),
            None => return Err("not a readable Radiance .hdr: its header does not end".into()),
        }
    }
    let line = match lines.next() {
        Some(Ok(line)) => String::from_utf8_lossy(&line).into_owned(),
        _ => return Err("not a readable Radiance .hdr: no resolution line".into()),
    };
    let axis = |sign_axis: &str, number: &str| -> Option<(char, u64)> {
        let mut chars = sign_axis.chars();
        let (sign, axis) = (chars.next()?, chars.next()?);
        let single = matches!(sign, '+' | '-') && chars.next().is_none();
        single.then(|| number.parse().ok().map(|n| (axis, n)))?
    };
    let words: Vec<&str> = line.split_whitespace().collect();
    let size = match words.as_slice() {
        [a, m, b, n] => match (axis(a, m), axis(b, n)) {
            (Some(('Y', h)), Some(('X', w))) | (Some(('X', w)), Some(('Y', h))) => Some((w, h)),
            _ => None,
        },
        _ => None,
    };
    size.ok_or_else(|| {
        format!("not a readable Radiance .hdr: its resolution line {line:?} is not \"-Y height +X width\"")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat (not run-length encoded) 2x1 file: mantissas and a shared
    /// exponent per pixel, `value = mantissa / 256 * 2^(e - 128)`.
    fn flat_file(dir: &Path) -> std::path::PathBuf {
        let path = dir.join("flat.hdr");
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n".to_vec();
        bytes.extend([128, 64, 0, 129, 0, 0, 255, 128]);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn reads_flat_scanlines() {
        let dir = tempfile::tempdir().unwrap();
        let path = flat_file(dir.path());
        assert!(is_hdr(&path));
        let image = read_hdr(&path).unwrap();
        assert_eq!((image.width, image.height), (2, 1));
        // radiant decodes `m / 255 * 2^(e - 128)`, within 0.4% of Ward's
        // `(m + 0.5) / 256 * 2^(e - 128)`.
        let [r, g, b] = image.get(0, 0);
        assert!(
            (r - 1.0).abs() < 5e-3 && (g - 0.5).abs() < 5e-3 && b == 0.0,
            "{r} {g} {b}"
        );
        let [r, g, b] = image.get(1, 0);
        assert!(
            r == 0.0 && g == 0.0 && (b - 1.0).abs() < 5e-3,
            "{r} {g} {b}"
        );
    }

    #[test]
    fn other_files_are_refused_with_their_path() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("text.hdr");
        std::fs::write(&path, "#? not really").unwrap();
        let error = read_hdr(&path).unwrap_err().to_string();
        assert!(
            error.contains("text.hdr") && error.contains("Radiance"),
            "{error}"
        );
        assert!(!is_hdr(&dir.path().join("missing.hdr")));
    }

    #[test]
    fn the_resolution_line_is_read_in_either_order() {
        let size = |text: &str| claimed_size(text.as_bytes());
        assert_eq!(size("#?RADIANCE\n\n-Y 3 +X 5\n"), Ok((5, 3)));
        assert_eq!(size("#?RGBE\nEXPOSURE=1\n\n+X 5 -Y 3\n"), Ok((5, 3)));
        assert!(size("#?RADIANCE\n\n-Y 3 +Z 5\n").is_err());
        assert!(size("#?RADIANCE\n-Y 3 +X 5\n").is_err());
    }

    #[test]
    fn a_claim_past_the_limit_is_refused_before_decoding() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bomb.hdr");
        std::fs::write(&path, b"#?RADIANCE\n\n-Y 100000 +X 100000\n\x02\x02").unwrap();
        let error = read_hdr(&path).unwrap_err().to_string();
        assert!(
            error.contains("bomb.hdr") && error.contains("claims 100000 x 100000 pixels"),
            "{error}"
        );
    }
}
