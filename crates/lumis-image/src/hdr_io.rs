//! Radiance `.hdr` (RGBE) files, read through the `radiant` crate.

use std::path::Path;

use crate::{Image, ImageError};

/// The first bytes of every Radiance file.
const MAGIC: &[u8] = b"#?";

/// Whether `path` starts as a Radiance file does (`#?RADIANCE`, `#?RGBE`).
pub fn is_hdr(path: &Path) -> bool {
    use std::io::Read;
    let mut start = [0u8; 2];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut start))
        .is_ok_and(|()| start == MAGIC)
}

/// Reads a Radiance RGBE file (flat or run-length encoded scanlines).
pub fn read_hdr(path: &Path) -> Result<Image, ImageError> {
    let file = std::fs::File::open(path).map_err(|source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let hdr = radiant::load(std::io::BufReader::new(file)).map_err(|e| ImageError::Format {
        path: path.to_path_buf(),
        message: format!("not a readable Radiance .hdr: {e}"),
    })?;
    Ok(Image {
        width: hdr.width,
        height: hdr.height,
        pixels: hdr.data.iter().map(|p| [p.r, p.g, p.b]).collect(),
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
}
