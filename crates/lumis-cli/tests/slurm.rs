//! `lumis slurm` against a real single-node Slurm cluster, started in a
//! scratch directory by `scripts/slurm/local-cluster.sh`: a render split
//! over a job array equals, bit for bit, one process rendering with passes
//! at the parts' boundaries; a part whose task is cancelled keeps the merge
//! from running (`afterok`), `lumis merge` refuses the gap by name, and
//! `lumis slurm status --resubmit` renders exactly that part again. The
//! merge job denoises the image as one process does.
//!
//! Where Slurm cannot run (slurm-wlm or munge not installed, a daemon that
//! does not start), the test says why on stderr and returns (`cargo test
//! -p lumis-cli --test slurm -- --nocapture` shows it). `.ci/run` installs
//! the packages.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use common::*;
use lumis_slurm::Manifest;

const PARTS: u32 = 4;
const SPP: &str = "16";
const RESOLUTION: &str = "film.resolution=[32, 32]";
/// The merge job denoises the merged image as `lumis render` would.
const DENOISER: &str = "denoiser.type=\"oidn\"";
/// How long a job may take on a loaded machine before the test gives up
/// and shows the cluster's logs.
const PATIENCE: Duration = Duration::from_secs(300);

/// The running cluster; stopped when dropped, test failing or not.
struct Cluster {
    dir: tempfile::TempDir,
    conf: PathBuf,
}

impl Cluster {
    /// Starts the cluster, or `None` with the reason it cannot run here.
    fn start() -> Result<Self, String> {
        stop_orphaned_clusters();
        let dir = scratch(CLUSTER_DIR);
        std::fs::write(dir.path().join(OWNER_FILE), std::process::id().to_string()).unwrap();
        let output = Command::new("bash")
            .arg(script())
            .args(["start".as_ref(), dir.path().as_os_str()])
            .env("LOCAL_CLUSTER_INSTALL", "0")
            .output()
            .map_err(|e| format!("bash could not run {}: {e}", script().display()))?;
        let cluster = Self {
            conf: dir.path().join("etc/slurm.conf"),
            dir,
        };
        match output.status.code() {
            Some(0) => Ok(cluster),
            // The script's "Slurm cannot run here".
            Some(2) => Err(String::from_utf8_lossy(&output.stderr).into_owned()),
            _ => panic!("local-cluster.sh start failed: {output:?}"),
        }
    }

    /// A Slurm (or lumis) command talking to this cluster.
    fn command(&self, program: &str) -> Command {
        let mut command = Command::new(program);
        command.env("SLURM_CONF", &self.conf);
        command
    }

    fn run(&self, program: &str, args: &[&str]) -> Output {
        let output = self.command(program).args(args).output().unwrap();
        assert!(output.status.success(), "{program} {args:?}: {output:?}");
        output
    }

    fn lumis(&self, args: &[&str]) -> Output {
        self.command(env!("CARGO_BIN_EXE_lumis"))
            .args(args)
            .output()
            .unwrap()
    }

    /// The cluster's logs and queue, for a failure message.
    fn diagnostics(&self, run: &Path) -> String {
        let mut text = String::from_utf8_lossy(
            &self
                .command("squeue")
                .args(["--array", "--states=all"])
                .output()
                .unwrap()
                .stdout,
        )
        .into_owned();
        let logs = [self.dir.path().join("log"), run.join("logs")];
        for dir in logs {
            for name in files_in(&dir) {
                let log = std::fs::read_to_string(dir.join(&name)).unwrap_or_default();
                let tail: Vec<&str> = log.lines().rev().take(10).collect();
                text += &format!(
                    "--- {name}:\n{}\n",
                    tail.into_iter().rev().collect::<Vec<_>>().join("\n")
                );
            }
        }
        text
    }

    /// Waits until `done` holds, or fails with the cluster's state.
    fn wait(&self, run: &Path, what: &str, done: impl Fn() -> bool) {
        let start = Instant::now();
        while !done() {
            assert!(
                start.elapsed() < PATIENCE,
                "{what}: not after {PATIENCE:?}\n{}",
                self.diagnostics(run)
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(script())
            .args(["stop".as_ref(), self.dir.path().as_os_str()])
            .status();
    }
}

/// The cluster's scratch directory name, and the file in it that holds the
/// process id of the test that started it.
const CLUSTER_DIR: &str = "slurm-cluster";
const OWNER_FILE: &str = "owner.pid";

/// Stops the clusters of earlier test runs that were killed before their
/// `Drop` could (their owner is gone), and removes their directories: a
/// killed test would otherwise leave munged, slurmctld and slurmd running.
/// A cluster whose test still runs (another clone's, say) is left alone.
fn stop_orphaned_clusters() {
    let prefix = format!("lumis-cli-{CLUSTER_DIR}-");
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else {
        return;
    };
    for dir in entries.flatten().map(|e| e.path()) {
        let ours = dir
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with(&prefix));
        let owner = std::fs::read_to_string(dir.join(OWNER_FILE)).unwrap_or_default();
        if ours && !owner.trim().is_empty() && !running(owner.trim()) {
            eprintln!(
                "stopping the cluster a killed test left in {}",
                dir.display()
            );
            let _ = Command::new("bash")
                .arg(script())
                .args(["stop".as_ref(), dir.as_os_str()])
                .status();
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
}

/// Whether process `pid` runs: it exists and is not a zombie (a killed
/// process whose parent has not reaped it yet).
fn running(pid: &str) -> bool {
    std::fs::read_to_string(Path::new("/proc").join(pid).join("stat"))
        .ok()
        .and_then(|stat| Some(stat.get(stat.rfind(')')? + 2..)?.starts_with('Z')))
        .is_some_and(|zombie| !zombie)
}

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/slurm/local-cluster.sh")
}

/// `lumis slurm` of the small Cornell box into `run`; its manifest.
fn submit(cluster: &Cluster, run: &Path) -> Manifest {
    let scene = scene("bench/cornell-box.toml");
    let out = run.display().to_string();
    let tasks = PARTS.to_string();
    let args = [
        "slurm", &scene, "--tasks", &tasks, "--spp", SPP, "--set", RESOLUTION, "--set", DENOISER,
        "--out", &out,
    ];
    let output = cluster.lumis(&args);
    assert!(output.status.success(), "{output:?}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let manifest = manifest(run);
    assert!(
        stdout.contains(&format!("array job {}", manifest.render_jobs[0].id)),
        "{stdout}"
    );
    manifest
}

fn manifest(run: &Path) -> Manifest {
    let text = std::fs::read_to_string(run.join(lumis_slurm::MANIFEST_NAME)).unwrap();
    toml::from_str(&text).unwrap()
}

/// One process with the parts' slice boundaries (`--parts`).
fn single_process_render(dir: &Path) -> PathBuf {
    let out = path_in(dir, "single.exr");
    let parts = PARTS.to_string();
    let scene = scene("bench/cornell-box.toml");
    let args = [
        "render", &scene, "--spp", SPP, "--parts", &parts, "--set", RESOLUTION, "--set", DENOISER,
        "-q", "-o", &out,
    ];
    let output = lumis(&args);
    assert!(output.status.success(), "{output:?}");
    PathBuf::from(out)
}

/// Without Slurm, and with a run already in the directory: clear errors
/// naming the command or the file, before anything is submitted.
#[test]
fn submitting_without_slurm_or_over_a_run_is_a_clear_error() {
    let work = scratch("slurm-errors");
    let scene = scene("bench/cornell-box.toml");
    let out = path_in(work.path(), "run");
    let empty = work.path().join("no-tools");
    std::fs::create_dir(&empty).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(["slurm", &scene, "--tasks", "4", "--out", &out])
        .env("PATH", &empty)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(stderr.contains("`sbatch --parsable"), "{stderr}");
    assert!(stderr.contains("sbatch is not on PATH"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");

    // The first attempt left its manifest: a second submission into the
    // same directory refuses and says how to follow the run.
    let output = lumis(&["slurm", &scene, "--tasks", "4", "--out", &out]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(stderr.contains("already holds a run"), "{stderr}");
    assert!(stderr.contains("lumis slurm status"), "{stderr}");

    let output = lumis(&["slurm", &scene, "--tasks", "8", "--spp", "4", "--out", &out]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("at most 4 parts"), "{stderr}");
}

#[test]
fn a_job_array_renders_the_image_of_one_process_and_resubmits_a_lost_part() {
    let cluster = match Cluster::start() {
        Ok(cluster) => cluster,
        Err(why) => {
            eprintln!("skipped: Slurm cannot run here:\n{why}");
            return;
        }
    };
    let work = scratch("slurm-runs");
    let single = single_process_render(work.path());

    // sbatch's refusal is an error quoting it.
    let scene = scene("bench/cornell-box.toml");
    let rejected = path_in(work.path(), "rejected");
    let output = cluster.lumis(&[
        "slurm",
        &scene,
        "--tasks",
        "2",
        "--partition",
        "nosuch",
        "--out",
        &rejected,
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(
        stderr.contains("`sbatch --parsable --partition=nosuch render.sbatch` failed"),
        "{stderr}"
    );
    assert!(stderr.contains("invalid partition"), "{stderr}");

    // A whole run: four tasks, then the merge.
    let run = work.path().join("whole");
    submit(&cluster, &run);
    let image = run.join("cornell-box.exr");
    let denoised = run.join("cornell-box.denoised.exr");
    // Written after the image.
    cluster.wait(&run, "the denoised image", || denoised.is_file());
    assert_eq!(
        exr_pixels(&image),
        exr_pixels(&single),
        "the parts merged on Slurm differ from one process's render"
    );
    assert_eq!(
        exr_pixels(&denoised),
        exr_pixels(single.with_extension("denoised.exr")),
        "the merge job's denoised image differs from one process's"
    );

    // A run whose task 2 is cancelled before it starts: the node is
    // drained while submitting, so no task can run before the cancel.
    let node = String::from_utf8(cluster.run("sinfo", &["-h", "-N", "-o", "%N"]).stdout).unwrap();
    let node = format!("NodeName={}", node.trim());
    cluster.run("scontrol", &["update", &node, "State=DRAIN", "Reason=test"]);
    let run = work.path().join("lost");
    let first = submit(&cluster, &run);
    let (array, merge) = (&first.render_jobs[0].id, &first.merge_jobs[0].id);
    cluster.run("scancel", &[&format!("{array}_2")]);
    cluster.run("scontrol", &["update", &node, "State=RESUME"]);
    let part = |k: u32| run.join(format!("part-{k}.exr"));
    cluster.wait(&run, "parts 0, 1 and 3", || {
        [0, 1, 3].iter().all(|&k| part(k).is_file())
    });
    // afterok: the merge waits for a part that will never come.
    cluster.wait(&run, "the merge job held for good", || {
        let reason = cluster
            .run("squeue", &["-h", "-j", merge, "-o", "%r"])
            .stdout;
        String::from_utf8_lossy(&reason).trim() == "DependencyNeverSatisfied"
    });
    let image = run.join("cornell-box.exr");
    assert!(!image.exists(), "a merge ran without part 2");
    assert!(!part(2).exists(), "the cancelled task wrote its part");

    // Merging what is there by hand refuses, naming the gap.
    let present: Vec<String> = [0, 1, 3]
        .iter()
        .map(|&k| part(k).display().to_string())
        .collect();
    let partial_merge = path_in(work.path(), "partial-merge.exr");
    let mut args = vec!["merge"];
    args.extend(present.iter().map(String::as_str));
    args.extend(["-o", &partial_merge]);
    let output = lumis(&args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(
        stderr.contains("samples 8..12 of 16 are in no part"),
        "{stderr}"
    );
    assert!(
        stderr.contains("part-1.exr") && stderr.contains("part-3.exr"),
        "{stderr}"
    );

    // Status names the lost part; --resubmit renders exactly it again,
    // replaces the held merge, and the image completes.
    let run_arg = run.display().to_string();
    let output = cluster.lumis(&["slurm", "status", &run_arg]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    assert!(stdout.contains("done:    0-1,3"), "{stdout}");
    assert!(stdout.contains("part 2:  missing"), "{stdout}");
    let output = cluster.lumis(&["slurm", "status", &run_arg, "--resubmit"]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{output:?}");
    let after = manifest(&run);
    let again = after.render_jobs.last().unwrap();
    assert_eq!(after.render_jobs.len(), 2, "{stdout}");
    assert_eq!(again.parts, vec![2], "{stdout}");
    assert!(
        stdout.contains(&format!("resubmitted parts 2 as array job {}", again.id)),
        "{stdout}"
    );
    assert!(
        stdout.contains(&format!("cancelled merge job {merge}")),
        "{stdout}"
    );
    cluster.wait(&run, "the merged image after resubmission", || {
        image.is_file()
    });
    assert_eq!(
        exr_pixels(&image),
        exr_pixels(&single),
        "the image completed by a resubmitted part differs from one process's render"
    );
    let output = cluster.lumis(&["slurm", "status", &run_arg]);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("done:    0-3"), "{stdout}");
    assert!(stdout.contains("image:"), "{stdout}");
}
