//! An advisory lock on an output, so that two processes writing the same
//! image refuse instead of mixing their files.
//!
//! The lock is a file `PATH.lock` created exclusively and holding the
//! owner's process id. A lock whose owner no longer runs (killed before it
//! could remove it) is stale and taken over.

use std::path::{Path, PathBuf};

use crate::atomic::remove_stale_temporaries;
use crate::process::process_is_running;
use crate::ImageError;

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
    /// names the running owner where another process holds it.
    pub fn acquire(output: &Path) -> Result<Self, ImageError> {
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
        std::fs::write(&claim, format!("{}\n", std::process::id())).map_err(io_err)?;
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
                    let owner = match std::fs::read_to_string(path) {
                        Ok(owner) => owner,
                        // Its owner just released it: try again.
                        Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
                        Err(e) => return Err(io_err(e)),
                    };
                    match owner.trim().parse::<u32>() {
                        Ok(pid) if process_is_running(pid) => {
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
                        _ => match std::fs::remove_file(path) {
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
        assert_eq!(held.trim(), std::process::id().to_string());
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
        assert_eq!(held.trim(), std::process::id().to_string());
        drop(lock);
    }
}
