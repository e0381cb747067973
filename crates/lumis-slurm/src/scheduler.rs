//! The Slurm commands `lumis slurm` runs: `sbatch` to submit, `sacct` (or,
//! where accounting is off, `squeue`) to ask what became of the jobs,
//! `scancel` to drop a merge that can no longer run. A command that is
//! missing or fails is an error naming it and quoting its stderr.

use std::collections::HashMap;
use std::path::Path;
use std::process::Command;

use lumis_core::{Error, Result};

/// Runs `program args` in `dir`; its stdout, or an error naming the command.
fn run(program: &str, args: &[String], dir: &Path) -> Result<String> {
    let shown = || format!("`{program} {}`", args.join(" "));
    let output = Command::new(program)
        .args(args)
        .current_dir(dir)
        .output()
        .map_err(|e| {
            let why = if e.kind() == std::io::ErrorKind::NotFound {
                format!("{program} is not on PATH (is this a Slurm login node?)")
            } else {
                e.to_string()
            };
            Error::msg(format!("{} could not run: {why}", shown()))
        })?;
    if !output.status.success() {
        return Err(Error::msg(format!(
            "{} failed ({}): {}",
            shown(),
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        )));
    }
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// Submits `script` from `dir` (so the script's relative `--output` lands
/// there); the job id `sbatch --parsable` prints.
pub fn sbatch(dir: &Path, options: &[String], script: &str) -> Result<String> {
    let mut args = vec!["--parsable".to_owned()];
    args.extend(options.iter().cloned());
    args.push(script.to_owned());
    let stdout = run("sbatch", &args, dir)?;
    // `--parsable` prints `ID` or, on a federation, `ID;CLUSTER`.
    let id = stdout.trim().split(';').next().unwrap_or("").to_owned();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(Error::msg(format!(
            "`sbatch {}` printed {:?}, expected a job id",
            args.join(" "),
            stdout.trim()
        )));
    }
    Ok(id)
}

pub fn scancel(dir: &Path, id: &str) -> Result<()> {
    run("scancel", &[id.to_owned()], dir).map(|_| ())
}

/// What Slurm knows of the jobs `ids` and of their array tasks: state by
/// `ID` or `ID_TASK` (e.g. `PENDING`, `FAILED`, `CANCELLED`). `sacct`
/// answers for as long as accounting keeps the jobs; without accounting,
/// `squeue -t all` answers for the jobs the controller still holds
/// (`MinJobAge` after they end). A job neither knows is absent.
pub fn job_states(dir: &Path, ids: &[String]) -> Result<HashMap<String, String>> {
    if ids.is_empty() {
        return Ok(HashMap::new());
    }
    let list = ids.join(",");
    let sacct = [
        "--noheader",
        "--parsable2",
        "--allocations",
        "--format=JobID,State",
        "--jobs",
        &list,
    ]
    .map(str::to_owned);
    let listing = match run("sacct", &sacct, dir) {
        Ok(listing) => listing,
        // Accounting is off (or sacct is absent): the controller's memory.
        Err(_) => {
            let squeue = [
                "--noheader",
                "--array",
                "--states=all",
                "--format=%i|%T",
                "--jobs",
                &list,
            ]
            .map(str::to_owned);
            run("squeue", &squeue, dir)?
        }
    };
    Ok(parse_states(&listing))
}

/// `ID|STATE` lines into a map; `ID_[2-3,5]` (a pending array not yet
/// split into tasks) gives one entry per task, and `CANCELLED by 0` is
/// `CANCELLED`.
fn parse_states(listing: &str) -> HashMap<String, String> {
    let mut states = HashMap::new();
    for line in listing.lines() {
        let Some((id, state)) = line.trim().split_once('|') else {
            continue;
        };
        let state = state.split_whitespace().next().unwrap_or("").to_owned();
        match id.split_once("_[") {
            Some((job, tasks)) => {
                let tasks = tasks.trim_end_matches(']');
                // `%4` limits how many run at once; it names no task.
                let tasks = tasks.split('%').next().unwrap_or("");
                for range in tasks.split(',') {
                    let (first, last) = range.split_once('-').unwrap_or((range, range));
                    if let (Ok(first), Ok(last)) = (first.parse::<u32>(), last.parse::<u32>()) {
                        for task in first..=last {
                            states.insert(format!("{job}_{task}"), state.clone());
                        }
                    }
                }
            }
            None => {
                states.insert(id.to_owned(), state);
            }
        }
    }
    states
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_are_read_per_task() {
        let states =
            parse_states("12_0|COMPLETED\n12_1|CANCELLED by 0\n12_[2-3,5%2]|PENDING\n13|PENDING\n");
        assert_eq!(states["12_0"], "COMPLETED");
        assert_eq!(states["12_1"], "CANCELLED");
        for task in [2, 3, 5] {
            assert_eq!(states[&format!("12_{task}")], "PENDING");
        }
        assert!(!states.contains_key("12_4"));
        assert_eq!(states["13"], "PENDING");
    }

    #[test]
    fn a_missing_command_is_an_error_naming_it() {
        let error = run("lumis-no-such-command", &["--x".into()], Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("`lumis-no-such-command --x` could not run"),
            "{error}"
        );
    }

    #[test]
    fn a_failing_command_is_an_error_quoting_its_stderr() {
        let args = ["-c".into(), "echo rejected >&2; exit 1".into()];
        let error = run("sh", &args, Path::new(".")).unwrap_err().to_string();
        assert!(error.contains("`sh -c"), "{error}");
        assert!(error.contains("rejected"), "{error}");
    }
}
