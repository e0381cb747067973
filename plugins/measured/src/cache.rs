//! The cache of a sampling precomputation, stored next to its table.
//!
//! `TABLE.STRATEGY-LL-NOxNWxNPHIsS[-pdv|-in-out].lumis-cache`: a header (magic,
//! format version, the content hash of the table file, strategy, terms,
//! grid and its parameterization) and
//! the precomputed numbers as little-endian f32, then an FNV-1a hash of
//! the payload. A header that does not match (the table changed, another
//! grid) or a damaged payload makes the caller recompute and replace it;
//! writes go to a temporary file renamed into place.

use std::path::{Path, PathBuf};

use lumis_api::Result;

use crate::grid::{Grid, Parameterization};
use crate::merl::{content_hash, write_atomic};

const MAGIC: &[u8; 8] = b"LUMISMSC";
/// Bump when the precomputation changes meaning.
const VERSION: u32 = 1;
const HEADER_BYTES: usize = 8 + 4 + 8 + 4 * 7 + 8;

/// Where a source's precomputation is cached and the key its file must
/// match: beside its table file, when the caller caches and the source has
/// a table to hash (`table_hash`); an analytic source has none.
pub fn slot(
    use_cache: bool,
    table_path: Option<&Path>,
    table_hash: Option<u64>,
    key: impl FnOnce(u64) -> CacheKey,
) -> Option<(PathBuf, CacheKey)> {
    match (use_cache, table_path, table_hash) {
        (true, Some(table_path), Some(hash)) => {
            let key = key(hash);
            Some((key.path(table_path), key))
        }
        _ => None,
    }
}

/// What a cache file holds and must match.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CacheKey {
    pub table_hash: u64,
    /// `"factored"`, `"tabulated"`, `"tensor"` (the rendered tensor) or
    /// `"tensor-sampling"`.
    pub strategy: &'static str,
    pub terms: usize,
    pub grid: Grid,
}

impl CacheKey {
    fn strategy_code(&self) -> u32 {
        match self.strategy {
            "factored" => 1,
            "tabulated" => 2,
            "tensor" => 3,
            "tensor-sampling" => 4,
            other => unreachable!("no precomputation is named {other:?}"),
        }
    }

    /// The cache file for `table`.
    pub fn path(&self, table: &Path) -> PathBuf {
        let g = self.grid;
        let mut name = table
            .file_name()
            .map(|n| n.to_os_string())
            .unwrap_or_default();
        let coordinates = match g.parameterization {
            Parameterization::HalfDiff => "",
            Parameterization::Pdv => "-pdv",
            Parameterization::InOut => "-in-out",
        };
        name.push(format!(
            ".{}-L{}-{}x{}x{}s{}{coordinates}.lumis-cache",
            self.strategy, self.terms, g.n_o, g.n_w, g.n_phi, g.supersamples
        ));
        table.with_file_name(name)
    }

    fn header(&self, count: usize) -> Vec<u8> {
        let mut h = Vec::with_capacity(HEADER_BYTES);
        h.extend_from_slice(MAGIC);
        h.extend_from_slice(&VERSION.to_le_bytes());
        h.extend_from_slice(&self.table_hash.to_le_bytes());
        let g = self.grid;
        for v in [
            self.strategy_code(),
            self.terms as u32,
            g.n_o as u32,
            g.n_w as u32,
            g.n_phi as u32,
            g.supersamples as u32,
            match g.parameterization {
                Parameterization::HalfDiff => 0,
                Parameterization::Pdv => 1,
                Parameterization::InOut => 2,
            },
        ] {
            h.extend_from_slice(&v.to_le_bytes());
        }
        h.extend_from_slice(&(count as u64).to_le_bytes());
        h
    }
}

/// Why a cache file cannot be used (the caller recomputes).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Miss {
    Absent,
    /// Made for another table version or setting: expected after an edit.
    Stale,
    /// Unreadable or damaged.
    Damaged(String),
}

impl Miss {
    /// What a report says of the cache at `path` it recomputed.
    pub fn note(&self, path: &Path) -> String {
        match self {
            Miss::Absent => String::new(),
            Miss::Stale => " (the cache was for another version of the table; replaced)".into(),
            Miss::Damaged(why) => format!(
                " (the cache {} was damaged: {why}; replaced)",
                path.display()
            ),
        }
    }
}

/// The `count` numbers cached at `path` for `key`.
pub fn load(path: &Path, key: &CacheKey, count: usize) -> std::result::Result<Vec<f32>, Miss> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(Miss::Absent),
        Err(e) => return Err(Miss::Damaged(e.to_string())),
    };
    let header = key.header(count);
    if bytes.len() < HEADER_BYTES || &bytes[..8] != MAGIC {
        return Err(Miss::Damaged("not a lumis cache file".into()));
    }
    if bytes[..HEADER_BYTES] != header[..] {
        return Err(Miss::Stale);
    }
    let expected = HEADER_BYTES + 4 * count + 8;
    if bytes.len() != expected {
        return Err(Miss::Damaged(format!(
            "{} bytes, expected {expected}",
            bytes.len()
        )));
    }
    let payload = &bytes[HEADER_BYTES..HEADER_BYTES + 4 * count];
    let stored = u64::from_le_bytes(bytes[expected - 8..].try_into().expect("8 bytes"));
    if stored != content_hash(payload) {
        return Err(Miss::Damaged("payload hash mismatch".into()));
    }
    Ok(payload
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect())
}

/// Writes `data` for `key` to `path` atomically.
pub fn store(path: &Path, key: &CacheKey, data: &[f32]) -> Result<()> {
    let mut bytes = key.header(data.len());
    let start = bytes.len();
    for v in data {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let hash = content_hash(&bytes[start..]);
    bytes.extend_from_slice(&hash.to_le_bytes());
    write_atomic(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_invalidation() {
        let dir = std::env::temp_dir().join(format!("lumis-cache-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let table = dir.join("t.binary");
        let key = CacheKey {
            table_hash: 42,
            strategy: "factored",
            terms: 2,
            grid: Grid {
                n_o: 2,
                n_w: 3,
                n_phi: 4,
                supersamples: 1,
                parameterization: Parameterization::HalfDiff,
            },
        };
        let path = key.path(&table);
        assert_eq!(
            path.file_name().unwrap(),
            "t.binary.factored-L2-2x3x4s1.lumis-cache"
        );
        assert_eq!(load(&path, &key, 3), Err(Miss::Absent));
        store(&path, &key, &[1.0, 2.5, -3.0]).unwrap();
        assert_eq!(load(&path, &key, 3).unwrap(), vec![1.0, 2.5, -3.0]);
        let changed = CacheKey {
            table_hash: 43,
            ..key
        };
        assert_eq!(load(&path, &changed, 3), Err(Miss::Stale));
        let pdv = CacheKey {
            grid: Grid {
                parameterization: Parameterization::Pdv,
                ..key.grid
            },
            ..key
        };
        assert_eq!(
            pdv.path(&table).file_name().unwrap(),
            "t.binary.factored-L2-2x3x4s1-pdv.lumis-cache"
        );
        assert_eq!(load(&path, &pdv, 3), Err(Miss::Stale));
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[HEADER_BYTES] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(load(&path, &key, 3), Err(Miss::Damaged(_))));
        std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        assert!(matches!(load(&path, &key, 3), Err(Miss::Damaged(_))));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
