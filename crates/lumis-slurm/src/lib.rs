//! `lumis slurm`: one render split over a Slurm job array. Task K renders
//! `--part K/N` of the samples into `part-K.exr`; a merge job, held until
//! every task succeeded (`afterok`), runs `lumis merge` over the parts. A
//! manifest in the run directory records the run, so `lumis slurm status`
//! can report it and resubmit exactly the parts that failed.

mod manifest;
mod scheduler;
mod scripts;
mod status;

use std::path::{Path, PathBuf};

use lumis_core::{Error, Result};

pub use manifest::{Manifest, MergeJob, RenderJob, MANIFEST_NAME};
pub use status::{status as slurm_status, MergeState, PartState, StatusReport};

/// `lumis slurm`: submit a render, or `lumis slurm status DIR`.
#[derive(Debug, Clone, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SlurmArgs {
    #[command(subcommand)]
    pub command: Option<SlurmCommand>,
    #[command(flatten)]
    pub submit: SlurmSubmitArgs,
}

#[derive(Debug, Clone, clap::Subcommand)]
pub enum SlurmCommand {
    /// Report which parts of a run are done, pending, running, failed or
    /// missing, and the merge; with --resubmit, submit a new array for
    /// exactly the failed and missing parts and a merge after it (or only
    /// the merge, when every part is there).
    Status(SlurmStatusArgs),
}

/// What `lumis slurm SCENE` submits.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SlurmSubmitArgs {
    /// The scene file, on a filesystem every node shares.
    #[arg(required = true)]
    pub scene: Option<PathBuf>,
    /// Parts, one array task each.
    #[arg(long, value_name = "N", required = true)]
    pub tasks: Option<u32>,
    /// Samples per pixel of the whole render (overrides sampler.spp).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Random seed (overrides the scene's top-level seed), at most
    /// 2^63 - 1 as a scene's is.
    #[arg(long, value_parser = clap::value_parser!(u64).range(..=i64::MAX as u64))]
    pub seed: Option<u64>,
    /// Override a scene value in every part, as `lumis render --set`.
    #[arg(long = "set", value_name = "KEY.PATH=VALUE")]
    pub set: Vec<String>,
    /// The Slurm partition of both jobs [default: the cluster's default].
    #[arg(long, short)]
    pub partition: Option<String>,
    /// The run directory, shared by every node: scripts, manifest, parts,
    /// logs and the image [default: SCENE-NAME-slurm].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Options given to every `sbatch` of the run, after `--`, e.g.
    /// `-- --time=30 --cpus-per-task=8 --account=vision`.
    #[arg(last = true, value_name = "SBATCH OPTIONS")]
    pub sbatch: Vec<String>,
}

#[derive(Debug, Clone, clap::Args)]
pub struct SlurmStatusArgs {
    /// The run directory `lumis slurm` wrote.
    pub dir: PathBuf,
    /// Submit what the render still needs: the failed and missing parts as
    /// a new array and a merge after them, or only the merge.
    #[arg(long)]
    pub resubmit: bool,
}

/// What `lumis slurm SCENE` submitted.
#[derive(Debug, Clone)]
pub struct Submission {
    pub dir: PathBuf,
    pub render_job: String,
    pub merge_job: String,
    pub manifest: Manifest,
}

impl Submission {
    pub fn summary(&self) -> String {
        format!(
            "submitted {} parts of {} as array job {} and merge job {} (after it)\n\
             the image will be {}; `lumis slurm status {}` follows the run",
            self.manifest.parts,
            self.manifest.scene.display(),
            self.render_job,
            self.merge_job,
            self.dir.join(&self.manifest.image).display(),
            self.dir.display()
        )
    }
}

/// Writes the run directory and submits the array and the merge; `lumis`
/// is the executable every task runs.
pub fn submit_slurm(args: &SlurmSubmitArgs, lumis: &Path) -> Result<Submission> {
    let (Some(scene), Some(parts)) = (&args.scene, args.tasks) else {
        return Err(Error::msg("lumis slurm: expected SCENE and --tasks N"));
    };
    if parts == 0 {
        return Err(Error::msg("--tasks: expected at least one part"));
    }
    // Checked here too, not only by every task after its wait in the queue.
    if let Some(spp) = args.spp.filter(|&spp| spp < parts) {
        return Err(Error::msg(format!(
            "--tasks {parts} parts of a {spp}-spp render would leave some empty; at most {spp} parts"
        )));
    }
    let scene = absolute(scene, "the scene")?;
    let lumis = absolute(lumis, "the lumis executable")?;
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".to_owned());
    let dir = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{stem}-slurm")));
    std::fs::create_dir_all(dir.join(scripts::LOG_DIR))
        .map_err(|e| Error::msg(format!("{}: {e}", dir.display())))?;
    let dir = absolute(&dir, "the run directory")?;
    if dir.join(MANIFEST_NAME).exists() {
        return Err(Error::msg(format!(
            "{} already holds a run ({MANIFEST_NAME}): follow it with `lumis slurm status {}`, \
             or give another --out",
            dir.display(),
            dir.display()
        )));
    }
    let mut manifest = Manifest {
        scene,
        lumis,
        parts,
        spp: args.spp,
        seed: args.seed,
        set: args.set.clone(),
        partition: args.partition.clone(),
        sbatch_options: args.sbatch.clone(),
        image: format!("{stem}.exr"),
        render_jobs: Vec::new(),
        merge_jobs: Vec::new(),
    };
    for (name, text) in [
        (
            scripts::RENDER_SCRIPT,
            scripts::render_script(&manifest, &dir),
        ),
        (
            scripts::MERGE_SCRIPT,
            scripts::merge_script(&manifest, &dir),
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| Error::msg(format!("{}: {e}", path.display())))?;
    }
    manifest.write(&dir)?;

    let options = submission_options(&manifest);
    let render_job = scheduler::sbatch(&dir, &options, scripts::RENDER_SCRIPT)?;
    manifest.render_jobs.push(RenderJob {
        id: render_job.clone(),
        parts: (0..parts).collect(),
    });
    manifest.write(&dir)?;

    let dependency = format!("afterok:{render_job}");
    let mut merge_options = vec![format!("--dependency={dependency}")];
    merge_options.extend(options);
    let merge_job = scheduler::sbatch(&dir, &merge_options, scripts::MERGE_SCRIPT)?;
    manifest.merge_jobs.push(MergeJob {
        id: merge_job.clone(),
        dependency: Some(dependency),
    });
    manifest.write(&dir)?;
    Ok(Submission {
        dir,
        render_job,
        merge_job,
        manifest,
    })
}

/// The `sbatch` options of every submission of a run.
fn submission_options(manifest: &Manifest) -> Vec<String> {
    let mut options: Vec<String> = manifest
        .partition
        .iter()
        .map(|p| format!("--partition={p}"))
        .collect();
    options.extend(manifest.sbatch_options.iter().cloned());
    options
}

/// `path` made absolute and free of `..`: the nodes do not share the
/// submitter's working directory.
fn absolute(path: &Path, what: &str) -> Result<PathBuf> {
    std::fs::canonicalize(path).map_err(|e| Error::msg(format!("{what} {}: {e}", path.display())))
}
