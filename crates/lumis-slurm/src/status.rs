//! `lumis slurm status DIR`: what became of every part of a run, from the
//! part files and Slurm's answer, and with `--resubmit` a new array for
//! exactly the parts that failed or went missing plus a merge after it.

use std::fmt;
use std::path::{Path, PathBuf};

use lumis_core::Result;

use super::manifest::{Manifest, MergeJob, RenderJob};
use super::scheduler;
use super::scripts::{array_ranges, MERGE_SCRIPT, RENDER_SCRIPT};

/// Where one part of the render stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PartState {
    /// Its file is in the run directory (written only by a task that
    /// succeeded).
    Done,
    /// Slurm still has its task to run, or is running it: `PENDING`,
    /// `RUNNING`...
    Active { task: String, state: String },
    /// Its task ended without writing the part: `FAILED`, `CANCELLED`,
    /// `TIMEOUT`, `NODE_FAIL`...
    Failed { task: String, state: String },
    /// No file and Slurm does not know its task (never submitted, cancelled
    /// while pending, or forgotten since it ended).
    Missing,
}

/// Where the merge stands.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MergeState {
    /// The image is in the run directory.
    Done,
    /// The latest merge job is waiting or running.
    Active { job: String, state: String },
    /// No merge job is waiting: none was submitted, or it ended without
    /// the image.
    Needed { last: Option<(String, String)> },
}

/// The answer of `lumis slurm status`.
#[derive(Debug, Clone)]
pub struct StatusReport {
    pub dir: PathBuf,
    pub manifest: Manifest,
    /// Part K's state at index K.
    pub parts: Vec<PartState>,
    pub merge: MergeState,
    /// With `--resubmit`: the array job submitted for the failed and
    /// missing parts.
    pub resubmitted: Option<RenderJob>,
    /// With `--resubmit`: the merge job submitted, and the one it replaced.
    pub new_merge: Option<MergeJob>,
    pub cancelled_merge: Option<String>,
}

impl StatusReport {
    /// The parts no task will deliver any more.
    pub fn to_retry(&self) -> Vec<u32> {
        (0..self.manifest.parts)
            .filter(|&k| {
                matches!(
                    self.parts[k as usize],
                    PartState::Failed { .. } | PartState::Missing
                )
            })
            .collect()
    }
}

/// Slurm states in which a job has yet to end.
const ACTIVE_STATES: [&str; 14] = [
    "PENDING",
    "CONFIGURING",
    "RUNNING",
    "COMPLETING",
    "REQUEUED",
    "REQUEUE_FED",
    "REQUEUE_HOLD",
    "RESIZING",
    "SUSPENDED",
    "STOPPED",
    "SIGNALING",
    "STAGE_OUT",
    "RESV_DEL_HOLD",
    "SPECIAL_EXIT",
];

fn is_active(state: &str) -> bool {
    ACTIVE_STATES.contains(&state)
}

/// Reads the run in `dir`, asks Slurm about its jobs and, if `resubmit`,
/// submits what the render still needs.
pub fn status(dir: &Path, resubmit: bool) -> Result<StatusReport> {
    let mut manifest = Manifest::read(dir)?;
    let ids: Vec<String> = manifest
        .render_jobs
        .iter()
        .map(|j| j.id.clone())
        .chain(manifest.merge_jobs.iter().map(|j| j.id.clone()))
        .collect();
    let states = scheduler::job_states(dir, &ids)?;

    let parts: Vec<PartState> = (0..manifest.parts)
        .map(|k| {
            if dir.join(Manifest::part_name(k)).is_file() {
                return PartState::Done;
            }
            let Some(job) = manifest.render_job_of(k) else {
                return PartState::Missing;
            };
            let task = format!("{}_{k}", job.id);
            match states.get(&task) {
                Some(state) if is_active(state) => PartState::Active {
                    task,
                    state: state.clone(),
                },
                Some(state) => PartState::Failed {
                    task,
                    state: state.clone(),
                },
                None => PartState::Missing,
            }
        })
        .collect();

    let last_merge = manifest
        .merge_jobs
        .last()
        .map(|j| (j.id.clone(), states.get(&j.id).cloned().unwrap_or_default()));
    let merge = if dir.join(&manifest.image).is_file() {
        MergeState::Done
    } else {
        match last_merge {
            Some((job, state)) if is_active(&state) => MergeState::Active { job, state },
            last => MergeState::Needed { last },
        }
    };

    let mut report = StatusReport {
        dir: dir.to_path_buf(),
        manifest: manifest.clone(),
        parts,
        merge,
        resubmitted: None,
        new_merge: None,
        cancelled_merge: None,
    };
    if resubmit {
        submit_what_is_needed(dir, &mut manifest, &mut report)?;
        report.manifest = manifest;
    }
    Ok(report)
}

/// A new array for the parts to retry and a merge after it and after the
/// parts still on their way; or, when no part needs retrying, just a merge
/// if none is waiting. A new merge replaces a waiting one, whose
/// dependency on a failed task could never be met.
fn submit_what_is_needed(
    dir: &Path,
    manifest: &mut Manifest,
    report: &mut StatusReport,
) -> Result<()> {
    if report.merge == MergeState::Done {
        return Ok(());
    }
    let retry = report.to_retry();
    if retry.is_empty() && matches!(report.merge, MergeState::Active { .. }) {
        return Ok(());
    }
    let options = super::submission_options(manifest);
    let mut after: Vec<String> = report
        .parts
        .iter()
        .filter_map(|part| match part {
            PartState::Active { task, .. } => Some(task.clone()),
            _ => None,
        })
        .collect();
    if !retry.is_empty() {
        let mut render_options = vec![format!("--array={}", array_ranges(&retry))];
        render_options.extend(options.iter().cloned());
        let id = scheduler::sbatch(dir, &render_options, RENDER_SCRIPT)?;
        let job = RenderJob { id, parts: retry };
        after.insert(0, job.id.clone());
        manifest.render_jobs.push(job.clone());
        manifest.write(dir)?;
        report.resubmitted = Some(job);
    }
    if let MergeState::Active { job, .. } = &report.merge {
        scheduler::scancel(dir, job)?;
        report.cancelled_merge = Some(job.clone());
    }
    let dependency = (!after.is_empty()).then(|| format!("afterok:{}", after.join(":")));
    let mut merge_options: Vec<String> = dependency
        .iter()
        .map(|d| format!("--dependency={d}"))
        .collect();
    merge_options.extend(options);
    let id = scheduler::sbatch(dir, &merge_options, MERGE_SCRIPT)?;
    let merge = MergeJob { id, dependency };
    manifest.merge_jobs.push(merge.clone());
    manifest.write(dir)?;
    report.new_merge = Some(merge);
    Ok(())
}

impl fmt::Display for StatusReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let m = &self.manifest;
        let spp = m
            .spp
            .map_or_else(|| "the scene's spp".to_owned(), |s| format!("{s} spp"));
        writeln!(
            f,
            "{}: {} parts at {spp} in {}",
            m.scene.display(),
            m.parts,
            self.dir.display()
        )?;
        let with = |keep: &dyn Fn(&PartState) -> bool| -> Vec<u32> {
            (0..m.parts)
                .filter(|&k| keep(&self.parts[k as usize]))
                .collect()
        };
        let done = with(&|p| *p == PartState::Done);
        writeln!(f, "  done:    {}", listed(&done))?;
        for (k, part) in self.parts.iter().enumerate() {
            match part {
                PartState::Active { task, state } => {
                    writeln!(f, "  part {k}:  {state} (task {task})")?
                }
                PartState::Failed { task, state } => {
                    writeln!(f, "  part {k}:  failed, {state} (task {task})")?
                }
                PartState::Missing => writeln!(
                    f,
                    "  part {k}:  missing (no file, and Slurm does not know its task)"
                )?,
                PartState::Done => {}
            }
        }
        match &self.merge {
            MergeState::Done => writeln!(f, "  image:   {}", self.dir.join(&m.image).display())?,
            MergeState::Active { job, state } => writeln!(f, "  merge:   job {job} {state}")?,
            MergeState::Needed {
                last: Some((job, state)),
            } => writeln!(
                f,
                "  merge:   job {job} ended {} without the image",
                if state.is_empty() {
                    "(forgotten by Slurm)"
                } else {
                    state
                }
            )?,
            MergeState::Needed { last: None } => writeln!(f, "  merge:   never submitted")?,
        }
        if let Some(job) = &self.resubmitted {
            writeln!(
                f,
                "resubmitted parts {} as array job {}",
                array_ranges(&job.parts),
                job.id
            )?;
        }
        if let Some(job) = &self.cancelled_merge {
            writeln!(
                f,
                "cancelled merge job {job}, which waited for a failed part"
            )?;
        }
        if let Some(merge) = &self.new_merge {
            match &merge.dependency {
                Some(d) => writeln!(f, "submitted merge job {} ({d})", merge.id)?,
                None => writeln!(f, "submitted merge job {}", merge.id)?,
            }
        } else if self.merge != MergeState::Done
            && (!self.to_retry().is_empty() || matches!(self.merge, MergeState::Needed { .. }))
        {
            writeln!(
                f,
                "`lumis slurm status {} --resubmit` submits what is missing",
                self.dir.display()
            )?;
        }
        Ok(())
    }
}

fn listed(parts: &[u32]) -> String {
    if parts.is_empty() {
        "none".to_owned()
    } else {
        array_ranges(parts)
    }
}
