//! Write to a temporary file beside the target, then rename it into place:
//! readers see the old file or the complete new one, never a partial one.
//! Only a regular file (or nothing) is replaced: a rename over a device
//! node, a FIFO or a socket would put the file where it was.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use crate::process::process_is_running;
use crate::ImageError;

/// The hidden temporary name `write_atomically` uses for `path` in this
/// process: `.NAME.tmp-PID` beside it.
fn temporary_path(path: &Path) -> Result<PathBuf, ImageError> {
    let name = path.file_name().ok_or_else(|| ImageError::Format {
        path: path.to_path_buf(),
        message: "output path has no file name".into(),
    })?;
    Ok(directory_of(path).join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    )))
}

fn directory_of(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// A complete file written under a temporary name, waiting to be renamed
/// into place. Staging every output first and renaming them one after the
/// other keeps the window in which some are new and some old down to the
/// renames. Dropped uncommitted, the temporary file is removed.
#[derive(Debug)]
pub struct StagedFile {
    temporary: PathBuf,
    target: PathBuf,
    committed: bool,
}

impl StagedFile {
    /// The file it will replace.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// Renames the staged file to its target, if the target is a regular
    /// file or absent.
    pub fn commit(mut self) -> Result<(), ImageError> {
        replaceable(&self.target)?;
        std::fs::rename(&self.temporary, &self.target).map_err(|source| ImageError::Io {
            path: self.target.clone(),
            source,
        })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}

/// Refuses a target that exists and is not a regular file.
fn replaceable(path: &Path) -> Result<(), ImageError> {
    lumis_files::check_replaceable(path).map_err(|message| ImageError::Format {
        path: path.to_path_buf(),
        message,
    })
}

/// Calls `write` on a temporary file in the target's directory, synced to
/// disk; on any error the temporary file is removed. A target that is not
/// a regular file is refused before anything is written.
pub fn stage<F>(path: &Path, write: F) -> Result<StagedFile, ImageError>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), String>,
{
    replaceable(path)?;
    let io_err = |source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    };
    let staged = StagedFile {
        temporary: temporary_path(path)?,
        target: path.to_path_buf(),
        committed: false,
    };
    let file = File::create(&staged.temporary).map_err(io_err)?;
    let mut writer = BufWriter::new(file);
    write(&mut writer).map_err(|message| ImageError::Format {
        path: path.to_path_buf(),
        message,
    })?;
    let file = writer.into_inner().map_err(|e| io_err(e.into_error()))?;
    file.sync_all().map_err(io_err)?;
    Ok(staged)
}

/// Calls `write` on a temporary file in the target's directory and renames
/// it to `path` only if `write` succeeded; on any error the temporary file
/// is removed and `path` is left untouched.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<(), ImageError>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), String>,
{
    stage(path, write)?.commit()
}

/// Removes the temporary files that processes no longer running left
/// beside `path` (`.NAME.tmp-PID`, from a write they did not finish);
/// returns how many. Those of running processes are theirs and stay.
pub fn remove_stale_temporaries(path: &Path) -> usize {
    let Some(name) = path.file_name() else {
        return 0;
    };
    let prefix = format!(".{}.tmp-", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(directory_of(path)) else {
        return 0;
    };
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let file_name = file_name.to_string_lossy();
        let Some(pid) = file_name
            .strip_prefix(&prefix)
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if !process_is_running(pid) && std::fs::remove_file(entry.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// Adapts `std::io::Write` errors for closures given to [`write_atomically`].
pub(crate) fn flush(w: &mut impl Write) -> Result<(), String> {
    w.flush().map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh directory for one test's files, removed when the test ends.
    fn scratch(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("lumis-atomic-{name}-"))
            .tempdir()
            .unwrap()
    }

    #[test]
    fn failure_leaves_nothing_behind() {
        let tmp = scratch("fail");
        let dir = tmp.path();
        let target = dir.join("out.exr");
        let err = write_atomically(&target, |w| {
            w.write_all(b"partial").map_err(|e| e.to_string())?;
            Err("render interrupted".into())
        });
        assert!(err.unwrap_err().to_string().contains("render interrupted"));
        assert!(!target.exists());
        assert_eq!(
            std::fs::read_dir(dir).unwrap().count(),
            0,
            "temporary file removed"
        );
    }

    #[test]
    fn failure_keeps_the_previous_file() {
        let tmp = scratch("keep");
        let dir = tmp.path();
        let target = dir.join("out.png");
        std::fs::write(&target, b"old").unwrap();
        let _ = write_atomically(&target, |_| Err("boom".into()));
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        write_atomically(&target, |w| w.write_all(b"new").map_err(|e| e.to_string())).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
    }

    #[test]
    fn staged_files_wait_for_commit_and_vanish_when_dropped() {
        let tmp = scratch("stage");
        let dir = tmp.path();
        let target = dir.join("out.png");
        std::fs::write(&target, b"old").unwrap();
        let staged = stage(&target, |w| w.write_all(b"new").map_err(|e| e.to_string())).unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        drop(staged);
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
        let staged = stage(&target, |w| w.write_all(b"new").map_err(|e| e.to_string())).unwrap();
        staged.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
    }

    #[test]
    fn stale_temporaries_of_dead_processes_are_removed() {
        let tmp = scratch("stale");
        let dir = tmp.path();
        let target = dir.join("out.exr");
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let dead = child.id();
        child.wait().unwrap();
        let stale = dir.join(format!(".out.exr.tmp-{dead}"));
        let live = dir.join(format!(".out.exr.tmp-{}", std::process::id()));
        let other = dir.join(format!(".other.exr.tmp-{dead}"));
        for p in [&stale, &live, &other] {
            std::fs::write(p, b"x").unwrap();
        }
        assert_eq!(remove_stale_temporaries(&target), 1);
        assert!(!stale.exists() && live.exists() && other.exists());
    }

    #[test]
    fn special_files_are_never_replaced() {
        for device in ["/dev/null", "/dev/full"] {
            let target = Path::new(device);
            let err = write_atomically(target, |w| w.write_all(b"x").map_err(|e| e.to_string()))
                .unwrap_err()
                .to_string();
            assert!(err.contains("not a regular file"), "{err}");
            let metadata = std::fs::metadata(target).unwrap();
            assert!(!metadata.is_file(), "{device} is still a device");
        }
        let tmp = scratch("fifo");
        let fifo = tmp.path().join("out.png");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let err = write_atomically(&fifo, |_| Ok(())).unwrap_err().to_string();
            assert!(err.contains("not a regular file"), "{err}");
            assert!(!std::fs::metadata(&fifo).unwrap().is_file());
        }
    }

    #[test]
    fn missing_directory_is_an_error_naming_the_path() {
        let target = std::env::temp_dir().join("lumis-no-such-dir-xyz/out.exr");
        let err = write_atomically(&target, |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(err.contains("lumis-no-such-dir-xyz"), "{err}");
    }
}
