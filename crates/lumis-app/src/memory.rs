//! What a render holds in memory, estimated before it starts and checked
//! against what the machine has: a film that does not fit is refused with
//! what to change, instead of swapping until the machine stalls (where a
//! signal then takes minutes to act) or being killed.

use lumis_core::{Error, Result, UVec2};
use lumis_render::Film;
use lumis_scene::LoadedScene;

/// Bytes per pixel of the images a save writes beside the film's sums:
/// the float colour and the PNG's bytes.
const SAVED_IMAGE_BYTES_PER_PIXEL: u64 = 3 * 4 + 3;

/// A render's memory, in bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MemoryEstimate {
    pub resolution: UVec2,
    /// Loaded already: geometry, BVHs and textures.
    pub scene: u64,
    /// The film's sums (and adaptive sampling's state).
    pub film: u64,
    /// What a save holds besides, for a moment: the checkpoint's copy of
    /// the sums and the images written (colour, outputs, PNG).
    pub saving: u64,
}

impl MemoryEstimate {
    /// What rendering `loaded` holds.
    pub fn of(loaded: &LoadedScene) -> Self {
        let (resolution, aovs) = (loaded.camera.resolution(), &loaded.aovs);
        let report = loaded.scene.load_report();
        let film = Film::memory_bytes(
            resolution,
            aovs,
            loaded.adaptive.is_some(),
            loaded.integrator.splats(),
        );
        let pixels = u64::from(resolution.x) * u64::from(resolution.y);
        let output_channels: u64 = aovs.iter().map(|a| a.channels().len() as u64).sum();
        let images = pixels.saturating_mul(SAVED_IMAGE_BYTES_PER_PIXEL + 4 * output_channels);
        Self {
            resolution,
            scene: (report.geometry_bytes + report.bvh_bytes + report.texture_bytes) as u64,
            film,
            saving: film.saturating_add(images),
        }
    }

    /// The most the render holds at once.
    pub fn peak(&self) -> u64 {
        self.scene
            .saturating_add(self.film)
            .saturating_add(self.saving)
    }

    /// The start-up line: the estimate, and what it is checked against.
    pub fn line(&self, budget: &MemoryBudget) -> String {
        format!(
            "memory: {} at most ({}); {}",
            gb(self.peak()),
            self.parts(),
            budget.describe()
        )
    }

    fn parts(&self) -> String {
        format!(
            "scene {}, film {}, saving {}",
            gb(self.scene),
            gb(self.film),
            gb(self.saving)
        )
    }

    /// Refuses a render whose film and saves do not fit in `budget`.
    pub fn check(&self, budget: &MemoryBudget) -> Result<()> {
        let (needed, what, limit) = match *budget {
            // The scene is loaded already: what the machine still has must
            // hold the film.
            MemoryBudget::Available(available) => (
                self.film.saturating_add(self.saving),
                format!(
                    "its film and saves need {}",
                    gb(self.film.saturating_add(self.saving))
                ),
                available,
            ),
            MemoryBudget::Max(max) => (
                self.peak(),
                format!("the render needs {}", gb(self.peak())),
                max,
            ),
            MemoryBudget::Unknown => return Ok(()),
        };
        if needed <= limit {
            return Ok(());
        }
        Err(Error::msg(format!(
            "film resolution {}x{}: {what} ({}), more than {}: lower [film] resolution, drop \
             [film] aovs or [adaptive], or give --max-memory a larger budget if the \
             machine has it",
            self.resolution.x,
            self.resolution.y,
            self.parts(),
            budget.describe()
        )))
    }
}

/// What a render may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MemoryBudget {
    /// `--max-memory`: the whole render, scene included.
    Max(u64),
    /// What the system says is available now, for the film.
    Available(u64),
    /// Neither is known.
    Unknown,
}

impl MemoryBudget {
    /// `--max-memory` if given, else the system's available memory.
    pub fn of(max_memory: Option<u64>) -> Self {
        match (max_memory, available_memory()) {
            (Some(max), _) => Self::Max(max),
            (None, Some(available)) => Self::Available(available),
            (None, None) => Self::Unknown,
        }
    }

    fn describe(&self) -> String {
        match *self {
            Self::Max(max) => format!("--max-memory {}", gb(max)),
            Self::Available(available) => format!("{} available", gb(available)),
            Self::Unknown => "available memory unknown".into(),
        }
    }
}

/// `bytes` in GB, or in MB below one GB.
fn gb(bytes: u64) -> String {
    if bytes >= 1_000_000_000 {
        format!("{:.2} GB", bytes as f64 * 1e-9)
    } else {
        format!("{:.1} MB", bytes as f64 * 1e-6)
    }
}

/// The memory the system can give without swapping (`MemAvailable` of
/// `/proc/meminfo`), where it says.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    mem_available(&text)
}

fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Reads a size for `--max-memory`: bytes, or a number with `K`, `M`, `G`
/// or `T` (powers of 1024, an optional `B` or `iB` after), as `ulimit` and
/// Slurm's `--mem` take.
pub fn parse_bytes(text: &str) -> std::result::Result<u64, String> {
    let text = text.trim();
    let split = text
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let scale: u64 = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 1,
        "K" | "KB" | "KIB" => 1 << 10,
        "M" | "MB" | "MIB" => 1 << 20,
        "G" | "GB" | "GIB" => 1 << 30,
        "T" | "TB" | "TIB" => 1 << 40,
        _ => return Err(format!("expected a size such as 8G or 512M, got {text:?}")),
    };
    let value: f64 = number
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a positive size such as 8G or 512M, got {text:?}"))?;
    Ok((value * scale as f64) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_read_as_ulimit_and_slurm_write_them() {
        assert_eq!(parse_bytes("512"), Ok(512));
        assert_eq!(parse_bytes("8G"), Ok(8 << 30));
        assert_eq!(parse_bytes("1.5 GiB"), Ok(3 << 29));
        assert_eq!(parse_bytes("512m"), Ok(512 << 20));
        for bad in ["", "G", "-1G", "0", "8 parsecs", "nan"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn available_memory_is_read_from_meminfo() {
        let meminfo = "MemTotal:       16000000 kB\nMemAvailable:    8000000 kB\n";
        assert_eq!(mem_available(meminfo), Some(8_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 1 kB\n"), None);
    }

    #[test]
    fn a_film_past_the_budget_is_refused_with_what_to_change() {
        let estimate = MemoryEstimate {
            resolution: UVec2::new(30000, 30000),
            scene: 1 << 30,
            film: 20 << 30,
            saving: 30 << 30,
        };
        assert!(estimate.check(&MemoryBudget::Unknown).is_ok());
        assert!(estimate.check(&MemoryBudget::Available(51 << 30)).is_ok());
        let err = estimate
            .check(&MemoryBudget::Available(24 << 30))
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("film resolution 30000x30000: its film and saves need 53.69 GB")
                && err.contains("more than 25.77 GB available"),
            "{err}"
        );
        assert!(err.contains("lower [film] resolution"), "{err}");
        assert!(estimate.check(&MemoryBudget::Max(51 << 30)).is_ok());
        let err = estimate
            .check(&MemoryBudget::Max(50 << 30))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("the render needs 54.76 GB")
                && err.contains("more than --max-memory 53.69 GB"),
            "{err}"
        );
    }
}
