//! A render's exact state on disk, so that a killed render continues where
//! its last checkpoint left it and ends with the image an uninterrupted
//! render makes, bit for bit.
//!
//! The file holds the film's per-pixel sums in double precision (an image
//! of means, rounded to `f32`, could not be continued exactly), the sample
//! count, the passes, the seed and the scene hash, in little-endian binary
//! behind a magic number and followed by an FNV-1a checksum of all of it:
//!
//! ```text
//! "LUMISCKP" version:u32 width:u32 height:u32 samples:u32 spp:u32 passes:u64
//! seed:u64 scene_hash:u64 seconds:f64 sums:[f64; 3 * width * height] checksum:u64
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_render::Film;
use lumis_scene::Fnv1a;

const MAGIC: &[u8; 8] = b"LUMISCKP";
const VERSION: u32 = 1;
const HEADER_BYTES: usize = 8 + 5 * 4 + 4 * 8;

/// A render's state between passes.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    pub film: Film,
    /// The samples per pixel the render aims at: samplers that stratify
    /// over the whole count (`stratified`) place sample `i` by it, so it
    /// cannot change on resuming.
    pub spp: u32,
    pub passes: u64,
    pub seed: u64,
    pub scene_hash: u64,
    /// Rendering time so far, over every run.
    pub seconds: f64,
}

/// Where the checkpoint of the render writing `exr` lives: `NAME.checkpoint`
/// beside it.
pub fn checkpoint_path(exr: &Path) -> PathBuf {
    exr.with_extension("checkpoint")
}

impl Checkpoint {
    fn to_bytes(&self) -> Vec<u8> {
        let film = &self.film;
        let mut out = Vec::with_capacity(HEADER_BYTES + film.sums.len() * 24 + 8);
        out.extend_from_slice(MAGIC);
        for v in [
            VERSION,
            film.width as u32,
            film.height as u32,
            film.samples,
            self.spp,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.passes, self.seed, self.scene_hash] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.seconds.to_le_bytes());
        for sum in &film.sums {
            for c in sum {
                out.extend_from_slice(&c.to_le_bytes());
            }
        }
        let mut hash = Fnv1a::default();
        hash.write(&out);
        out.extend_from_slice(&hash.finish().to_le_bytes());
        out
    }

    /// Writes the checkpoint atomically: a kill leaves the previous one.
    pub fn write(&self, path: &Path) -> Result<()> {
        let bytes = self.to_bytes();
        lumis_image::write_atomically(path, |w| w.write_all(&bytes).map_err(|e| e.to_string()))
            .map_err(|e| Error::msg(e.to_string()))
    }

    /// Reads a checkpoint; `None` where there is no file.
    pub fn read(path: &Path) -> Result<Option<Self>> {
        let bytes = match std::fs::read(path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::msg(format!("{}: {e}", path.display()))),
        };
        Self::from_bytes(&bytes)
            .map(Some)
            .map_err(|why| Error::msg(format!("{}: not a lumis checkpoint: {why}", path.display())))
    }

    fn from_bytes(bytes: &[u8]) -> std::result::Result<Self, String> {
        if bytes.len() < HEADER_BYTES + 8 || &bytes[..8] != MAGIC {
            return Err("it does not start with the checkpoint header".into());
        }
        let (body, checksum) = bytes.split_at(bytes.len() - 8);
        let mut hash = Fnv1a::default();
        hash.write(body);
        if hash.finish().to_le_bytes() != checksum {
            return Err("its checksum does not match (the file is damaged)".into());
        }
        let u32_at = |i: usize| u32::from_le_bytes(body[i..i + 4].try_into().unwrap());
        let u64_at = |i: usize| u64::from_le_bytes(body[i..i + 8].try_into().unwrap());
        let version = u32_at(8);
        if version != VERSION {
            return Err(format!(
                "version {version}, this lumis reads version {VERSION}"
            ));
        }
        let (width, height) = (u32_at(12) as usize, u32_at(16) as usize);
        let pixels = width
            .checked_mul(height)
            .filter(|n| n.checked_mul(24) == Some(body.len() - HEADER_BYTES))
            .ok_or_else(|| format!("its size does not fit a {width}x{height} film"))?;
        let sums = body[HEADER_BYTES..]
            .chunks_exact(24)
            .map(|p| {
                std::array::from_fn(|c| f64::from_le_bytes(p[c * 8..c * 8 + 8].try_into().unwrap()))
            })
            .collect::<Vec<[f64; 3]>>();
        debug_assert_eq!(sums.len(), pixels);
        Ok(Self {
            film: Film {
                width,
                height,
                sums,
                samples: u32_at(20),
            },
            spp: u32_at(24),
            passes: u64_at(28),
            seed: u64_at(36),
            scene_hash: u64_at(44),
            seconds: f64::from_bits(u64_at(52)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> Checkpoint {
        Checkpoint {
            film: Film {
                width: 2,
                height: 1,
                sums: vec![[1.0, -0.0, f64::MIN_POSITIVE], [3.5, 1e300, 0.1]],
                samples: 7,
            },
            spp: 16,
            passes: 3,
            seed: u64::MAX,
            scene_hash: 0xdead_beef,
            seconds: 2.5,
        }
    }

    #[test]
    fn round_trips_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.checkpoint");
        assert_eq!(Checkpoint::read(&path).unwrap(), None);
        example().write(&path).unwrap();
        assert_eq!(Checkpoint::read(&path).unwrap(), Some(example()));
    }

    #[test]
    fn damaged_files_are_refused_with_the_reason() {
        let bytes = example().to_bytes();
        let mut flipped = bytes.clone();
        flipped[HEADER_BYTES + 3] ^= 1;
        assert!(Checkpoint::from_bytes(&flipped)
            .unwrap_err()
            .contains("checksum"));
        assert!(Checkpoint::from_bytes(&bytes[..bytes.len() - 9])
            .unwrap_err()
            .contains("checksum"));
        assert!(Checkpoint::from_bytes(b"hello")
            .unwrap_err()
            .contains("header"));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.checkpoint");
        std::fs::write(
            &path,
            b"not a checkpoint at all, but long enough to be read as one",
        )
        .unwrap();
        let err = Checkpoint::read(&path).unwrap_err().to_string();
        assert!(
            err.contains("b.checkpoint") && err.contains("not a lumis checkpoint"),
            "{err}"
        );
    }
}
