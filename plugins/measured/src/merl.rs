//! The MERL BRDF database format (Matusik, Pfister, Brand and McMillan
//! 2003, "A Data-Driven Reflectance Model"), read and written.
//!
//! A file is a header of three little-endian `i32`, the table dimensions
//! `90 x 90 x 180` over `(theta_h, theta_d, phi_d)` of Rusinkiewicz's
//! half/difference parameterization, then `3 x 1458000` little-endian
//! `f64`: the red block, the green block, the blue block, each in the order
//! `phi_d` fastest, then `theta_d`, then `theta_h`. A stored value times
//! its channel's scale (`1/1500`, `1.15/1500`, `1.66/1500`) is the BRDF
//! `f` (without the cosine), in 1/sr. Negative values (the measurement
//! code writes -1) mark samples that were not measured, e.g. below the
//! horizon.
//!
//! The index of a sample, as in the reference reader `BRDFRead.cpp`:
//! `theta_h` with a square-root mapping, `sqrt(theta_h / (pi/2)) * 90`,
//! which puts half the rows within 22.5 degrees of the specular peak;
//! `theta_d / (pi/2) * 90`; `phi_d / pi * 180` after folding `phi_d` into
//! `[0, pi)`: swapping `wi` and `wo` turns `phi_d` into `phi_d + pi`, so a
//! reciprocal BRDF needs only half the circle.
//!
//! The reference reader looks up the sample whose index is the truncated
//! coordinate; this module treats sample `i` as a node at coordinate `i`
//! and interpolates trilinearly between nodes (periodically in `phi_d`),
//! so tables written by [`encode`] from point values at the nodes are
//! reproduced exactly there. Invalid nodes are left out of the
//! interpolation (the weights of the valid ones renormalised).

use std::f32::consts::{FRAC_PI_2, PI};
use std::path::Path;

use lumis_api::{Error, Result, Rgb, Vec3};
use lumis_files::{read_bounded, FileKind};
use lumis_sampling::halfdiff::HalfDiff;

pub const THETA_H_RES: usize = 90;
pub const THETA_D_RES: usize = 90;
pub const PHI_D_RES: usize = 180;
/// Samples per channel.
pub const SAMPLES: usize = THETA_H_RES * THETA_D_RES * PHI_D_RES;
/// The per-channel factors that turn stored values into `f`.
pub const CHANNEL_SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// What the measurement code writes for a sample it does not have.
pub const INVALID_MARKER: f64 = -1.0;
/// Three int32 dimensions.
pub const HEADER_BYTES: usize = 12;
/// The size of every valid file.
pub const FILE_BYTES: usize = HEADER_BYTES + 3 * SAMPLES * 8;

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// The position of sample `(i, j, k)` = `(theta_h, theta_d, phi_d)` in a
/// channel block.
#[inline]
pub fn sample_index(i: usize, j: usize, k: usize) -> usize {
    k + PHI_D_RES * (j + THETA_D_RES * i)
}

/// `(theta_h, theta_d, phi_d)` of node `(i, j, k)`.
#[inline]
pub fn node_angles(i: usize, j: usize, k: usize) -> (f32, f32, f32) {
    let t = i as f32 / THETA_H_RES as f32;
    (
        t * t * FRAC_PI_2,
        j as f32 / THETA_D_RES as f32 * FRAC_PI_2,
        k as f32 / PHI_D_RES as f32 * PI,
    )
}

/// `(wi, wo)` of node `(i, j, k)`, with `phi_h = 0`.
pub fn node_directions(i: usize, j: usize, k: usize) -> (Vec3, Vec3) {
    let (theta_h, theta_d, phi_d) = node_angles(i, j, k);
    HalfDiff {
        theta_h,
        phi_h: 0.0,
        theta_d,
        phi_d,
    }
    .to_directions()
}

/// FNV-1a over the bytes, eight at a time (a content hash for the cache,
/// not a checksum against tampering).
pub fn content_hash(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        h ^= u64::from_le_bytes(c.try_into().expect("8 bytes"));
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    for &b in chunks.remainder() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// A MERL table in memory: `f` per node and channel, negative where the
/// file marks the sample invalid.
#[derive(Clone)]
pub struct MerlTable {
    values: Vec<[f32; 3]>,
    hash: u64,
}

impl std::fmt::Debug for MerlTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MerlTable {{ hash: {:016x} }}", self.hash)
    }
}

impl MerlTable {
    /// Reads a table, with an error naming the file and what is wrong.
    pub fn read(path: &Path) -> Result<Self> {
        // One byte over the format's size, so that a slightly longer file
        // gets `from_bytes`'s "trailing data" message.
        let kind = FileKind::new("MERL table", FILE_BYTES as u64 + 1);
        let bytes = read_bounded(path, kind).map_err(Error::msg)?;
        Self::from_bytes(&bytes, &path.display().to_string())
    }

    /// Parses the bytes of a file; `name` is used in error messages.
    pub fn from_bytes(bytes: &[u8], name: &str) -> Result<Self> {
        if bytes.len() < HEADER_BYTES {
            return Err(Error::msg(format!(
                "{name}: {} bytes, too short for the {HEADER_BYTES}-byte MERL header (three int32 dimensions)",
                bytes.len()
            )));
        }
        let dim = |o: usize| i32::from_le_bytes(bytes[o..o + 4].try_into().expect("4 bytes"));
        let dims = (dim(0), dim(4), dim(8));
        if dims != (THETA_H_RES as i32, THETA_D_RES as i32, PHI_D_RES as i32) {
            return Err(Error::msg(format!(
                "{name}: header dimensions {} x {} x {}; the MERL format has {THETA_H_RES} x {THETA_D_RES} x {PHI_D_RES} (theta_h, theta_d, phi_d)",
                dims.0, dims.1, dims.2
            )));
        }
        if bytes.len() != FILE_BYTES {
            return Err(Error::msg(format!(
                "{name}: {} bytes, expected {FILE_BYTES} ({HEADER_BYTES}-byte header + 3 x {SAMPLES} f64): {}",
                bytes.len(),
                if bytes.len() < FILE_BYTES {
                    "truncated data"
                } else {
                    "trailing data after the blue block"
                }
            )));
        }
        let mut values = vec![[0.0f32; 3]; SAMPLES];
        let mut valid = 0usize;
        for (c, scale) in CHANNEL_SCALE.iter().enumerate() {
            let block =
                &bytes[HEADER_BYTES + c * SAMPLES * 8..HEADER_BYTES + (c + 1) * SAMPLES * 8];
            for (n, raw) in block.chunks_exact(8).enumerate() {
                let v = f64::from_le_bytes(raw.try_into().expect("8 bytes"));
                if !v.is_finite() || v < INVALID_MARKER {
                    let (i, j, k) = (
                        n / (PHI_D_RES * THETA_D_RES),
                        (n / PHI_D_RES) % THETA_D_RES,
                        n % PHI_D_RES,
                    );
                    return Err(Error::msg(format!(
                        "{name}: value {v} at byte offset {} ({} channel, theta_h index {i}, theta_d index {j}, phi_d index {k}); stored values must be >= 0, or negative down to {INVALID_MARKER} to mark an invalid sample",
                        HEADER_BYTES + (c * SAMPLES + n) * 8,
                        CHANNELS[c]
                    )));
                }
                if v >= 0.0 {
                    values[n][c] = (v * scale) as f32;
                    valid += 1;
                } else {
                    values[n][c] = -1.0;
                }
            }
        }
        if valid == 0 {
            return Err(Error::msg(format!(
                "{name}: every sample is marked invalid (negative); nothing to render"
            )));
        }
        Ok(Self {
            values,
            hash: content_hash(bytes),
        })
    }

    /// The content hash of the file it was read from.
    pub fn hash(&self) -> u64 {
        self.hash
    }

    /// `f` at node `(i, j, k)`; `None` where the file marks it invalid.
    pub fn node(&self, i: usize, j: usize, k: usize) -> [Option<f32>; 3] {
        self.values[sample_index(i, j, k)].map(|v| (v >= 0.0).then_some(v))
    }

    /// Bytes held in memory.
    pub fn memory_bytes(&self) -> usize {
        self.values.len() * std::mem::size_of::<[f32; 3]>()
    }

    /// `f(wi, wo)` by trilinear interpolation in the index coordinates.
    /// Both directions must be in the upper hemisphere (the caller's
    /// business: the table has nothing below it).
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3) -> Rgb {
        let Some(hd) = HalfDiff::from_directions(wi, wo) else {
            return Rgb::BLACK;
        };
        let th = (hd.theta_h.max(0.0) / FRAC_PI_2).sqrt() * THETA_H_RES as f32;
        let td = hd.theta_d.max(0.0) / FRAC_PI_2 * THETA_D_RES as f32;
        let pd = hd.phi_d.rem_euclid(PI) / PI * PHI_D_RES as f32;
        let (i0, i1, ti) = clamped_axis(th, THETA_H_RES);
        let (j0, j1, tj) = clamped_axis(td, THETA_D_RES);
        let k0f = pd.floor();
        let tk = pd - k0f;
        let k0 = (k0f as usize) % PHI_D_RES;
        let k1 = (k0 + 1) % PHI_D_RES;
        let mut sum = [0.0f32; 3];
        let mut weight = [0.0f32; 3];
        for (i, wi_) in [(i0, 1.0 - ti), (i1, ti)] {
            for (j, wj) in [(j0, 1.0 - tj), (j1, tj)] {
                for (k, wk) in [(k0, 1.0 - tk), (k1, tk)] {
                    let w = wi_ * wj * wk;
                    let v = self.values[sample_index(i, j, k)];
                    for c in 0..3 {
                        if v[c] >= 0.0 {
                            sum[c] += w * v[c];
                            weight[c] += w;
                        }
                    }
                }
            }
        }
        let channel = |c: usize| {
            if weight[c] > 0.0 {
                sum[c] / weight[c]
            } else {
                0.0
            }
        };
        Rgb::new(channel(0), channel(1), channel(2))
    }
}

/// The two nodes around coordinate `x` on an axis of `n` nodes and the
/// weight of the second; clamped at both ends (there is no node at `n`).
#[inline]
pub(crate) fn clamped_axis(x: f32, n: usize) -> (usize, usize, f32) {
    let x = x.clamp(0.0, (n - 1) as f32);
    let i0 = (x.floor() as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, x - i0 as f32)
}

/// The bytes of a MERL file holding `f` (per node, per channel; `None`
/// for an invalid sample, written as the -1 marker), stored divided by the
/// channel scales.
pub fn encode(values: &[Option<[f64; 3]>]) -> Vec<u8> {
    assert_eq!(values.len(), SAMPLES, "a MERL table has {SAMPLES} samples");
    let mut out = Vec::with_capacity(FILE_BYTES);
    for d in [THETA_H_RES, THETA_D_RES, PHI_D_RES] {
        out.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for (c, scale) in CHANNEL_SCALE.iter().enumerate() {
        for v in values {
            let raw = v.map_or(INVALID_MARKER, |f| f[c] / scale);
            out.extend_from_slice(&raw.to_le_bytes());
        }
    }
    out
}

/// Writes `bytes` to a temporary file beside `path`, then renames it over
/// `path`: a reader never sees half a file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let file_name = path
        .file_name()
        .ok_or_else(|| Error::msg(format!("{}: not a file path", path.display())))?;
    let mut tmp_name = file_name.to_os_string();
    tmp_name.push(format!(".tmp-{}", std::process::id()));
    let tmp = path.with_file_name(tmp_name);
    std::fs::write(&tmp, bytes)
        .map_err(|e| Error::msg(format!("cannot write {}: {e}", tmp.display())))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::msg(format!(
            "cannot rename {} to {}: {e}",
            tmp.display(),
            path.display()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth, isotropic, reciprocal test function of the node angles.
    fn analytic(theta_h: f32, theta_d: f32, phi_d: f32) -> [f64; 3] {
        let base = 0.2 + (-(theta_h * theta_h) / 0.05).exp() as f64;
        let shape = 1.0 + 0.3 * (theta_d as f64).cos() + 0.1 * (2.0 * phi_d as f64).cos();
        [base * shape, 0.5 * base * shape, 0.25 * base]
    }

    fn table_bytes() -> Vec<u8> {
        let mut values = vec![None; SAMPLES];
        for i in 0..THETA_H_RES {
            for j in 0..THETA_D_RES {
                for k in 0..PHI_D_RES {
                    let (th, td, pd) = node_angles(i, j, k);
                    values[sample_index(i, j, k)] = (j < 85).then(|| analytic(th, td, pd));
                }
            }
        }
        encode(&values)
    }

    #[test]
    fn round_trip_reproduces_nodes_and_interpolates_between_them() {
        let bytes = table_bytes();
        assert_eq!(bytes.len(), FILE_BYTES);
        let t = MerlTable::from_bytes(&bytes, "t.binary").unwrap();
        // At a node, exactly the written value (to f32 precision).
        for (i, j, k) in [(10, 20, 30), (0, 0, 0), (45, 60, 179)] {
            let (wi, wo) = node_directions(i, j, k);
            let (th, td, pd) = node_angles(i, j, k);
            let want = analytic(th, td, pd);
            let got = t.eval(wi, wo);
            for (g, w) in [got.r, got.g, got.b].iter().zip(want) {
                assert!(
                    (*g as f64 - w).abs() < 2e-3 * w,
                    "node {i},{j},{k}: {got:?} vs {want:?}"
                );
            }
        }
        // Between nodes, close to the smooth function; and reciprocal.
        let hd = HalfDiff {
            theta_h: 0.3,
            phi_h: 1.0,
            theta_d: 0.4,
            phi_d: 2.0,
        };
        let (wi, wo) = hd.to_directions();
        let want = analytic(0.3, 0.4, 2.0);
        let got = t.eval(wi, wo);
        assert!(
            (got.r as f64 - want[0]).abs() < 0.02 * want[0],
            "{got:?} {want:?}"
        );
        let back = t.eval(wo, wi);
        assert!((back.r - got.r).abs() < 1e-4 * got.r, "{back:?} {got:?}");
    }

    #[test]
    fn invalid_nodes_are_left_out_of_the_interpolation() {
        let t = MerlTable::from_bytes(&table_bytes(), "t.binary").unwrap();
        assert_eq!(t.node(3, 88, 4), [None, None, None]);
        // theta_d between nodes 84 (valid) and 85 (invalid): the valid value.
        let (th, td, pd) = node_angles(5, 84, 7);
        let hd = HalfDiff {
            theta_h: th,
            phi_h: 0.0,
            theta_d: td + 0.5 * FRAC_PI_2 / 90.0,
            phi_d: pd,
        };
        let (wi, wo) = hd.to_directions();
        let want = analytic(th, td, pd);
        let got = t.eval(wi, wo);
        assert!(
            (got.b as f64 - want[2]).abs() < 1e-3 * want[2],
            "{got:?} {want:?}"
        );
    }

    #[test]
    fn bad_files_get_errors_naming_file_and_problem() {
        let good = table_bytes();
        let err = |bytes: &[u8]| {
            MerlTable::from_bytes(bytes, "bad.binary")
                .unwrap_err()
                .to_string()
        };
        let e = err(&good[..8]);
        assert!(e.starts_with("bad.binary:") && e.contains("header"), "{e}");
        let mut dims = good.clone();
        dims[8..12].copy_from_slice(&360i32.to_le_bytes());
        let e = err(&dims);
        assert!(
            e.contains("90 x 90 x 360") && e.contains("90 x 90 x 180"),
            "{e}"
        );
        let e = err(&good[..FILE_BYTES - 8]);
        assert!(
            e.contains("truncated") && e.contains(&FILE_BYTES.to_string()),
            "{e}"
        );
        let mut long = good.clone();
        long.push(0);
        assert!(err(&long).contains("trailing"));
        let mut negative = good.clone();
        let offset = HEADER_BYTES + (SAMPLES + sample_index(2, 3, 4)) * 8;
        negative[offset..offset + 8].copy_from_slice(&(-2.5f64).to_le_bytes());
        let e = err(&negative);
        assert!(
            e.contains("-2.5")
                && e.contains(&format!("byte offset {offset}"))
                && e.contains("green")
                && e.contains("theta_h index 2, theta_d index 3, phi_d index 4"),
            "{e}"
        );
        let mut nan = good.clone();
        nan[HEADER_BYTES..HEADER_BYTES + 8].copy_from_slice(&f64::NAN.to_le_bytes());
        assert!(err(&nan).contains("NaN"));
        let none = encode(&vec![None; SAMPLES]);
        assert!(err(&none).contains("invalid"));
        let missing = MerlTable::read(Path::new("/nonexistent/x.binary"))
            .unwrap_err()
            .to_string();
        assert!(missing.contains("/nonexistent/x.binary"), "{missing}");
    }

    #[test]
    fn atomic_write_leaves_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("lumis-merl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.binary");
        write_atomic(&path, b"abc").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"abc");
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
