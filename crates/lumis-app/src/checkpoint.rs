//! A render's exact state on disk, so that a killed render continues where
//! its last checkpoint left it and ends with the image an uninterrupted
//! render makes, bit for bit.
//!
//! The file holds the film's per-pixel sums in double precision (an image
//! of means, rounded to `f32`, could not be continued exactly), the sums
//! behind the outputs the scene asks for (`aovs`, a mask of
//! [`Aov::bit`]s: the squares with `variance`, the first-hit sums with
//! `albedo`, `normal` or `depth`), the sample count, the passes, the seed
//! and the scene hash, in little-endian binary behind a magic number and
//! followed by an FNV-1a checksum of all of it:
//!
//! ```text
//! "LUMISCKP" version:u32 width:u32 height:u32 samples:u32 spp:u32 aovs:u32
//! passes:u64 seed:u64 scene_hash:u64 seconds:f64 sums:[f64; 3 * width * height]
//! squares:[f64; 3 * width * height]? first_hits:[f64; 7 * width * height]?
//! adaptive? splats:[i64; 3 * width * height]? checksum:u64
//! ```
//!
//! With adaptive sampling (bit 31 of `aovs`), `adaptive` is its settings
//! and per-pixel state: `min_spp:u32 max_spp:u32 threshold:f32
//! counts:[u32; width * height] odd_sums:[f64; 3 * width * height]
//! active:[u8; width * height]`. With an integrator that splats (bit 30),
//! `splats` are the film's splat sums.

use std::io::Write;
use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use lumis_files::{read_bounded, FileKind, GIB};
use lumis_render::{AdaptiveSampling, Aov, Film, FirstHitSums};
use lumis_scene::Fnv1a;

const MAGIC: &[u8; 8] = b"LUMISCKP";
const VERSION: u32 = 2;
const HEADER_BYTES: usize = 8 + 6 * 4 + 4 * 8;
/// `f64`s per pixel of the first-hit sums: albedo, normal, depth.
const FIRST_HIT_VALUES: usize = 7;
/// The bit of the `aovs` mask saying the film samples adaptively.
const ADAPTIVE_BIT: u32 = 1 << 31;
/// The bit of the `aovs` mask saying the film holds splats.
const SPLATS_BIT: u32 = 1 << 30;
/// Bytes per pixel of the splat sums.
const SPLAT_PIXEL_BYTES: usize = 24;
/// Bytes per pixel of the adaptive state: count, odd sums, active flag.
const ADAPTIVE_PIXEL_BYTES: usize = 4 + 24 + 1;
/// A checkpoint: a film's sums, far below this for any film lumis
/// renders (a 16k x 16k film with every output is 40 GiB).
const CHECKPOINT_FILE: FileKind = FileKind::new("checkpoint", 64 * GIB);

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
            film.aovs.iter().map(|a| a.bit()).sum::<u32>()
                | if film.adaptive.is_some() {
                    ADAPTIVE_BIT
                } else {
                    0
                }
                | if film.splats.is_some() { SPLATS_BIT } else { 0 },
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.passes, self.seed, self.scene_hash] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.seconds.to_le_bytes());
        let buffers = film.sums.iter().chain(film.squares.iter().flatten());
        for value in buffers.flatten() {
            out.extend_from_slice(&value.to_le_bytes());
        }
        for hit in film.first_hits.iter().flatten() {
            let values = hit.albedo.iter().chain(&hit.normal).chain([&hit.depth]);
            for value in values {
                out.extend_from_slice(&value.to_le_bytes());
            }
        }
        if let Some(adaptive) = &film.adaptive {
            let settings = adaptive.settings;
            for v in [
                settings.min_spp,
                settings.max_spp,
                settings.threshold.to_bits(),
            ] {
                out.extend_from_slice(&v.to_le_bytes());
            }
            for count in &adaptive.counts {
                out.extend_from_slice(&count.to_le_bytes());
            }
            for value in adaptive.odd_sums.iter().flatten() {
                out.extend_from_slice(&value.to_le_bytes());
            }
            out.extend(adaptive.active.iter().map(|&a| a as u8));
        }
        for value in film.splats.iter().flatten().flatten() {
            out.extend_from_slice(&value.to_le_bytes());
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

    /// Reads a checkpoint; `None` where there is no file. Only a regular
    /// file is read (a FIFO would block, `/dev/zero` never end).
    pub fn read(path: &Path) -> Result<Option<Self>> {
        if std::fs::symlink_metadata(path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound)
        {
            return Ok(None);
        }
        let bytes = read_bounded(path, CHECKPOINT_FILE).map_err(Error::msg)?;
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
        let adaptive = u32_at(28) & ADAPTIVE_BIT != 0;
        let splats = u32_at(28) & SPLATS_BIT != 0;
        let mask = u32_at(28) & !(ADAPTIVE_BIT | SPLATS_BIT);
        let aovs: Vec<Aov> = Aov::ALL
            .into_iter()
            .filter(|a| mask & a.bit() != 0)
            .collect();
        if aovs.iter().map(|a| a.bit()).sum::<u32>() != mask {
            return Err(format!("its output mask {mask:#x} names unknown outputs"));
        }
        // The size is checked before any buffer is made for it.
        let values_per_pixel = 3
            + 3 * aovs.contains(&Aov::Variance) as usize
            + FIRST_HIT_VALUES * aovs.iter().any(|a| a.needs_first_hit()) as usize;
        let pixels = width * height;
        let sums_bytes = pixels
            .checked_mul(8 * values_per_pixel)
            .filter(|&n| n <= body.len() - HEADER_BYTES)
            .ok_or_else(|| format!("its size does not fit a {width}x{height} film"))?;
        let rest = &body[HEADER_BYTES + sums_bytes..];
        let expected_rest = if adaptive {
            12 + pixels * ADAPTIVE_PIXEL_BYTES
        } else {
            0
        } + if splats {
            pixels * SPLAT_PIXEL_BYTES
        } else {
            0
        };
        if rest.len() != expected_rest {
            return Err(format!("its size does not fit a {width}x{height} film"));
        }
        let mut film =
            Film::try_with_aovs(lumis_core::UVec2::new(width as u32, height as u32), &aovs)
                .map_err(|e| e.to_string())?;
        let (rest, splat_bytes) =
            rest.split_at(rest.len() - splats as usize * pixels * SPLAT_PIXEL_BYTES);
        if splats {
            let sums = film.splat_sums().map_err(|e| e.to_string())?;
            for (pixel, bytes) in sums
                .iter_mut()
                .zip(splat_bytes.chunks_exact(SPLAT_PIXEL_BYTES))
            {
                *pixel = std::array::from_fn(|c| {
                    i64::from_le_bytes(bytes[c * 8..c * 8 + 8].try_into().unwrap())
                });
            }
        }
        if adaptive {
            let u32_of = |i: usize| u32::from_le_bytes(rest[i..i + 4].try_into().unwrap());
            let settings = AdaptiveSampling::new(u32_of(0), u32_of(4), f32::from_bits(u32_of(8)))
                .map_err(|e| format!("its adaptive sampling: {e}"))?;
            film = film.with_adaptive(settings).map_err(|e| e.to_string())?;
            let state = film.adaptive.as_mut().unwrap();
            let (counts, rest) = rest[12..].split_at(pixels * 4);
            let (odd_sums, active) = rest.split_at(pixels * 24);
            for (count, bytes) in state.counts.iter_mut().zip(counts.chunks_exact(4)) {
                *count = u32::from_le_bytes(bytes.try_into().unwrap());
            }
            for (odd, bytes) in state.odd_sums.iter_mut().zip(odd_sums.chunks_exact(24)) {
                *odd = std::array::from_fn(|c| {
                    f64::from_le_bytes(bytes[c * 8..c * 8 + 8].try_into().unwrap())
                });
            }
            for (flag, &byte) in state.active.iter_mut().zip(active) {
                *flag = byte != 0;
            }
        }
        let mut values = body[HEADER_BYTES..HEADER_BYTES + sums_bytes]
            .chunks_exact(8)
            .map(|v| f64::from_le_bytes(v.try_into().unwrap()));
        let mut next = || values.next().unwrap();
        for buffer in std::iter::once(&mut film.sums).chain(film.squares.as_mut()) {
            for pixel in buffer {
                *pixel = std::array::from_fn(|_| next());
            }
        }
        for hit in film.first_hits.iter_mut().flatten() {
            *hit = FirstHitSums {
                albedo: std::array::from_fn(|_| next()),
                normal: std::array::from_fn(|_| next()),
                depth: next(),
            };
        }
        film.samples = u32_at(20);
        Ok(Self {
            film,
            spp: u32_at(24),
            passes: u64_at(32),
            seed: u64_at(40),
            scene_hash: u64_at(48),
            seconds: f64::from_bits(u64_at(56)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn example() -> Checkpoint {
        let mut film = Film::try_new(lumis_core::UVec2::new(2, 1)).unwrap();
        film.sums = vec![[1.0, -0.0, f64::MIN_POSITIVE], [3.5, 1e300, 0.1]];
        film.samples = 7;
        Checkpoint {
            film,
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
    fn the_outputs_sums_round_trip_exactly() {
        let mut saved = example();
        let aovs = [Aov::Spp, Aov::Variance, Aov::Normal];
        let mut film = Film::try_with_aovs(lumis_core::UVec2::new(2, 1), &aovs).unwrap();
        film.sums = saved.film.sums.clone();
        film.squares = Some(vec![[2.0, 0.5, 1e-300], [7.0, 8.0, 9.0]]);
        film.first_hits = Some(vec![
            FirstHitSums {
                albedo: [0.1, 0.2, 0.3],
                normal: [-1.0, 0.0, 1.0],
                depth: 12.5,
            },
            FirstHitSums::default(),
        ]);
        film.samples = 7;
        let mut film = film
            .with_adaptive(AdaptiveSampling::new(2, 16, 0.05).unwrap())
            .unwrap();
        let adaptive = film.adaptive.as_mut().unwrap();
        adaptive.counts = vec![7, 4];
        adaptive.odd_sums = vec![[0.5, 0.25, -0.0], [1e-9, 2.0, 3.0]];
        adaptive.active = vec![true, false];
        saved.film = film;
        let back = Checkpoint::from_bytes(&saved.to_bytes()).unwrap();
        assert_eq!(back, saved);
        assert_eq!(back.film.aovs, [Aov::Normal, Aov::Variance, Aov::Spp]);
    }

    #[test]
    fn the_splats_round_trip_exactly() {
        let mut saved = example();
        saved
            .film
            .splat_sums()
            .unwrap()
            .copy_from_slice(&[[1, -2, i64::MAX], [0, i64::MIN, 7]]);
        let back = Checkpoint::from_bytes(&saved.to_bytes()).unwrap();
        assert_eq!(back, saved);
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
