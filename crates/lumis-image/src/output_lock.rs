//! An advisory lock on an output, so that two processes writing the same
//! image refuse instead of mixing their files.
//!
//! The lock is a file `PATH.lock` created exclusively and holding the
//! owner's process id and start time (a pid alone is reused once its
//! process ends). A lock whose owner no longer runs (killed before it
//! could remove it), or that names no process as lumis writes it, is stale
//! and taken over.

use std::path::{Path, PathBuf};

use lumis_files::FileKind;

use crate::atomic::remove_stale_temporaries;
use crate::process::{process_is_running, process_start};
use crate::ImageError;

/// A lock file: one short line.
const LOCK_FILE: FileKind = FileKind::new("lock", 256);

/// What this process writes in its locks: `PID START`.
fn owner_line() -> String {
    let pid = std::process::id();
    match process_start(pid) {
        Some(start) => format!("{pid} {start}\n"),
        None => format!("{pid}\n"),
    }
}

/// The process a lock's text names, if it still runs: the same pid
/// started at the same time. Without `/proc` to say when a process
/// started, a running pid is trusted.
fn running_owner(text: &str) -> Option<u32> {
    let mut words = text.split_whitespace();
    let pid: u32 = words.next()?.parse().ok()?;
    let start: Option<u64> = words.next().and_then(|w| w.parse().ok());
    let started = process_start(pid);
    let same = match (start, started) {
        (Some(start), Some(started)) => start == started,
        (_, None) => process_is_running(pid) && !std::path::Path::new("/proc/self").exists(),
        // A pid without its start time: not a lock lumis wrote.
        (None, Some(_)) => false,
    };
    same.then_some(pid)
}

/// Held while a process writes an output; removes its lock file when dropped.
#[derive(Debug)]
pub struct OutputLock {
    path: PathBuf,
}

/// `PATH.lock` for `path`.
pub fn lock_path(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".lock");
    PathBuf::from(name)
}

impl OutputLock {
    /// Locks `output` for this process, taking over a stale lock; an error
    /// names the running owner where another process holds it. An output
    /// that exists and is not a regular file is refused first: it would
    /// never be replaced, so nothing is rendered for it.
    pub fn acquire(output: &Path) -> Result<Self, ImageError> {
        lumis_files::check_replaceable(output).map_err(|message| ImageError::Format {
            path: output.to_path_buf(),
            message,
        })?;
        let path = lock_path(output);
        let io_err = |source| ImageError::Io {
            path: path.clone(),
            source,
        };
        // The pid is written first and the lock made by linking that file
        // to its name, which fails if the name exists: no process ever sees
        // a lock without its owner. The claim is named like a temporary
        // file of `write_atomically`, so that one left by a killed process
        // is removed like those.
        remove_stale_temporaries(&path);
        let claim = path.with_file_name(format!(
            ".{}.tmp-{}",
            path.file_name().unwrap_or_default().to_string_lossy(),
            std::process::id()
        ));
        std::fs::write(&claim, owner_line()).map_err(io_err)?;
        let result = Self::link(&claim, &path, output);
        let _ = std::fs::remove_file(&claim);
        result
    }

    fn link(claim: &Path, path: &Path, output: &Path) -> Result<Self, ImageError> {
        let io_err = |source| ImageError::Io {
            path: path.to_path_buf(),
            source,
        };
        // Twice at most: once more after removing a stale lock.
        for _ in 0..2 {
            match std::fs::hard_link(claim, path) {
                Ok(()) => {
                    return Ok(Self {
                        path: path.to_path_buf(),
                    })
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let owner = match lumis_files::read_text_bounded(path, LOCK_FILE) {
                        Ok(owner) => owner,
                        // Its owner just released it: try again.
                        Err(_) if !path.exists() => continue,
                        Err(message) => {
                            return Err(ImageError::Format {
                                path: output.to_path_buf(),
                                message,
                            })
                        }
                    };
                    match running_owner(&owner) {
                        Some(pid) => {
                            return Err(ImageError::Format {
                                path: output.to_path_buf(),
                                message: format!(
                                    "another lumis (process {pid}) is writing this output; \
                                     wait for it, or remove '{}' if that process is not lumis",
                                    path.display()
                                ),
                            })
                        }
                        // A dead owner's lock, or one naming no process: stale.
                        None => match std::fs::remove_file(path) {
                            Ok(()) => {}
                            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                            Err(e) => return Err(io_err(e)),
                        },
                    }
                }
                Err(e) => return Err(io_err(e)),
            }
        }
        Err(ImageError::Format {
            path: output.to_path_buf(),
            message: format!("another process keeps taking the lock '{}'", path.display()),
        })
    }
}

impl Drop for OutputLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lock_refuses_and_a_stale_one_is_taken_over() {
        let tmp = tempfile::tempdir().unwrap();
        let output = tmp.path().join("out.exr");
        let lock = OutputLock::acquire(&output).unwrap();
        let held = std::fs::read_to_string(lock_path(&output)).unwrap();
        assert_eq!(held, owner_line());
        let err = OutputLock::acquire(&output).unwrap_err().to_string();
        assert!(
            err.contains("another lumis") && err.contains("out.exr.lock"),
            "{err}"
        );
        drop(lock);
        assert!(!lock_path(&output).exists());

        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        std::fs::write(lock_path(&output), format!("{dead}\n")).unwrap();
        let lock = OutputLock::acquire(&output).unwrap();
        let held = std::fs::read_to_string(lock_path(&output)).unwrap();
        assert_eq!(held, owner_line());
        drop(lock);
    }

    /// A live process that did not write the lock does not hold it: pid 1
    /// without a start time, or with another one.
    #[test]
    fn a_lock_naming_another_live_process_is_stale() {
        if process_start(1).is_none() {
            return;
        }
        let tmp = tempfile::tempdir().unwrap();
        let output = tmp.path().join("out.exr");
        let start = process_start(1).unwrap();
        for text in ["1\n".to_string(), format!("1 {}\n", start + 1)] {
            std::fs::write(lock_path(&output), &text).unwrap();
            let lock = OutputLock::acquire(&output).unwrap();
            drop(lock);
        }
        std::fs::write(lock_path(&output), format!("1 {start}\n")).unwrap();
        assert!(OutputLock::acquire(&output).is_err());
    }

    #[test]
    fn a_lock_that_is_not_a_regular_file_is_an_error_not_a_wait() {
        let tmp = tempfile::tempdir().unwrap();
        let output = tmp.path().join("out.exr");
        let made = std::process::Command::new("mkfifo")
            .arg(lock_path(&output))
            .status();
        if !made.is_ok_and(|s| s.success()) {
            return;
        }
        let err = OutputLock::acquire(&output).unwrap_err().to_string();
        assert!(err.contains("not a regular file"), "{err}");
    }
}
