//! The record of a distributed render, `lumis-slurm.toml` in its directory:
//! what was rendered and which Slurm jobs were asked to do it, so `lumis
//! slurm status` can follow and repair the run later, from any login node.

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};
use serde::{Deserialize, Serialize};

/// The manifest's file name in the run directory.
pub const MANIFEST_NAME: &str = "lumis-slurm.toml";

/// One distributed render.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The scene, absolute: every node reads it from the shared filesystem.
    pub scene: PathBuf,
    /// The lumis executable every task runs, absolute.
    pub lumis: PathBuf,
    /// How many parts the render is split into (`--part K/N`).
    pub parts: u32,
    /// `--spp` of every part; absent means the scene's own.
    pub spp: Option<u32>,
    /// `--seed` of every part; absent means the scene's own.
    pub seed: Option<u64>,
    /// `--set` overrides of every part.
    #[serde(default)]
    pub set: Vec<String>,
    /// The Slurm partition both jobs go to; absent means the default one.
    pub partition: Option<String>,
    /// Further `sbatch` options, given to every submission.
    #[serde(default)]
    pub sbatch_options: Vec<String>,
    /// The merged image, in the run directory.
    pub image: String,
    /// Every array job submitted to render parts, oldest first.
    #[serde(default)]
    pub render_jobs: Vec<RenderJob>,
    /// Every merge job submitted, oldest first.
    #[serde(default)]
    pub merge_jobs: Vec<MergeJob>,
}

/// An array job rendering some parts: task K renders part K.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RenderJob {
    pub id: String,
    pub parts: Vec<u32>,
}

/// A merge job and the dependency it waits for.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct MergeJob {
    pub id: String,
    pub dependency: Option<String>,
}

impl Manifest {
    /// The file part `k` is written to, in the run directory.
    pub fn part_name(k: u32) -> String {
        format!("part-{k}.exr")
    }

    /// The latest array job that was asked to render part `k`.
    pub fn render_job_of(&self, k: u32) -> Option<&RenderJob> {
        self.render_jobs.iter().rev().find(|j| j.parts.contains(&k))
    }

    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST_NAME);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            Error::msg(format!(
                "{}: {e} (expected the directory of a `lumis slurm` run)",
                path.display()
            ))
        })?;
        toml::from_str(&text).map_err(|e| {
            Error::msg(format!(
                "{}: not a lumis slurm manifest: {e}",
                path.display()
            ))
        })
    }

    /// Writes the manifest atomically, so an interrupted update leaves the
    /// previous one.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let text = toml::to_string(self)
            .map_err(|e| Error::msg(format!("cannot write the slurm manifest: {e}")))?;
        let path = dir.join(MANIFEST_NAME);
        lumis_image::write_atomically(&path, |w| {
            std::io::Write::write_all(w, text.as_bytes()).map_err(|e| e.to_string())
        })
        .map_err(|e| Error::msg(format!("{}: {e}", path.display())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_manifest_reads_back_as_written() {
        let manifest = Manifest {
            scene: "/shared/scene.toml".into(),
            lumis: "/shared/bin/lumis".into(),
            parts: 4,
            spp: Some(16),
            seed: None,
            set: vec!["film.width=32".into()],
            partition: Some("batch".into()),
            sbatch_options: vec!["--time=10".into()],
            image: "scene.exr".into(),
            render_jobs: vec![
                RenderJob {
                    id: "12".into(),
                    parts: vec![0, 1, 2, 3],
                },
                RenderJob {
                    id: "14".into(),
                    parts: vec![2],
                },
            ],
            merge_jobs: vec![MergeJob {
                id: "13".into(),
                dependency: Some("afterok:12".into()),
            }],
        };
        let dir = tempfile::tempdir().unwrap();
        manifest.write(dir.path()).unwrap();
        assert_eq!(Manifest::read(dir.path()).unwrap(), manifest);
        assert_eq!(manifest.render_job_of(2).unwrap().id, "14");
        assert_eq!(manifest.render_job_of(3).unwrap().id, "12");
    }

    #[test]
    fn a_directory_without_a_manifest_is_a_clear_error() {
        let dir = tempfile::tempdir().unwrap();
        let error = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(error.contains(MANIFEST_NAME), "{error}");
        assert!(error.contains("lumis slurm"), "{error}");
    }
}
