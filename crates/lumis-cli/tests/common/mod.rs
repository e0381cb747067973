//! Helpers for the tests that run the `lumis` binary, signal it and kill it.

#![allow(dead_code)]

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};

/// Runs `lumis` to completion.
pub fn lumis(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(args)
        .output()
        .expect("lumis runs")
}

/// The standard output of a `lumis` run that must have succeeded; fails
/// showing both outputs if it did not.
pub fn stdout_of_success(run: &Output) -> String {
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    stdout
}

/// Starts `lumis` without waiting, its output captured.
pub fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_lumis"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("lumis starts")
}

pub fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
        .display()
        .to_string()
}

/// A fresh directory for one test's files, removed when the test ends.
pub fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("lumis-cli-{name}-"))
        .tempdir()
        .unwrap()
}

/// Sends `signal` (`INT`, `TERM`, `KILL`...) to process `pid`.
pub fn signal(pid: u32, signal: &str) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &pid.to_string()])
        .status()
        .expect("kill runs");
    assert!(status.success(), "kill -{signal} {pid} failed");
}

/// Waits until `path` exists; panics, with the child's output, if the
/// child ends first.
pub fn wait_for(child: &mut Child, path: &Path) {
    while !path.exists() {
        if let Some(status) = child.try_wait().unwrap() {
            let mut stderr = String::new();
            if let Some(mut e) = child.stderr.take() {
                std::io::Read::read_to_string(&mut e, &mut stderr).unwrap();
            }
            panic!(
                "lumis ended ({status}) before {} appeared: {stderr}",
                path.display()
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

/// Runs `args` once per moment of [`kill_moments`]`(count, max_ms)` and
/// SIGKILLs each run once `progress` exists (its first checkpoint, or the
/// one it resumes from) plus that moment; the first moment is zero, so at
/// least one kill lands mid-render however fast the machine is. Returns
/// how many runs were still going when their kill came.
pub fn kill_after_progress(args: &[&str], progress: &Path, count: usize, max_ms: u64) -> usize {
    let mut moments = kill_moments(count, max_ms.max(1));
    moments[0] = 0;
    let mut killed = 0;
    for ms in moments {
        let mut child = spawn(args);
        wait_for(&mut child, progress);
        std::thread::sleep(std::time::Duration::from_millis(ms));
        // It may have finished already: then there is nothing to kill.
        if child.try_wait().unwrap().is_none() {
            signal(child.id(), "KILL");
            killed += 1;
        }
        child.wait().unwrap();
    }
    killed
}

/// The value of `lumis.KEY` in the header of the EXR at `path`.
pub fn header(path: &Path, key: &str) -> String {
    let name = format!("lumis.{key}");
    lumis_image::read_exr_metadata(path)
        .unwrap()
        .into_iter()
        .find(|(n, _)| *n == name)
        .unwrap_or_else(|| panic!("{} has no {name}", path.display()))
        .1
}

/// The files in `dir`, sorted by name.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// `dir/name` as a string argument.
pub fn path_in(dir: &Path, name: &str) -> String {
    dir.join(name).display().to_string()
}

/// The process id of a process that has ended.
pub fn dead_pid() -> u32 {
    let mut child = Command::new("true").spawn().unwrap();
    let pid = child.id();
    child.wait().unwrap();
    pid
}

/// The bits of every pixel of an EXR, for comparisons that must be exact.
pub fn exr_pixels(path: impl AsRef<Path>) -> Vec<[u32; 3]> {
    lumis_image::read_exr(path.as_ref())
        .unwrap()
        .pixels
        .iter()
        .map(|p| p.map(f32::to_bits))
        .collect()
}

/// `lumis render` arguments for a small, quick render of the glossy plates
/// (a scene naming no files) to `out`.
pub fn small_render<'a>(out: &'a str, spp: &'a str) -> Vec<&'a str> {
    vec![
        "render",
        SMALL_SCENE.with(|s| *s),
        "--set",
        "film.resolution=[32, 32]",
        "--threads",
        "2",
        "--spp",
        spp,
        "-o",
        out,
        "-q",
    ]
}

thread_local! {
    static SMALL_SCENE: &'static str = Box::leak(scene("glossy-plates.toml").into_boxed_str());
}

/// Moments to kill at, in milliseconds after a start: a small linear
/// congruential generator seeded from the clock, printed so a failure can
/// be replayed by its seed (`LUMIS_KILL_SEED`).
pub fn kill_moments(count: usize, max_ms: u64) -> Vec<u64> {
    let seed = std::env::var("LUMIS_KILL_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .unwrap()
                .as_nanos() as u64
        });
    eprintln!("kill moments from LUMIS_KILL_SEED={seed}");
    let mut state = seed;
    (0..count)
        .map(|_| {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) % max_ms
        })
        .collect()
}
