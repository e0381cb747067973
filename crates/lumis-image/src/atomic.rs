//! Write to a temporary file beside the target, then rename it into place:
//! readers see the old file or the complete new one, never a partial one.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::ImageError;

/// Calls `write` on a temporary file in the target's directory and renames
/// it to `path` only if `write` succeeded; on any error the temporary file
/// is removed and `path` is left untouched.
pub fn write_atomically<F>(path: &Path, write: F) -> Result<(), ImageError>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), String>,
{
    let io_err = |source| ImageError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path.file_name().ok_or_else(|| ImageError::Format {
        path: path.to_path_buf(),
        message: "output path has no file name".into(),
    })?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let file = File::create(&tmp).map_err(io_err)?;
        let mut writer = BufWriter::new(file);
        write(&mut writer).map_err(|message| ImageError::Format {
            path: path.to_path_buf(),
            message,
        })?;
        let file = writer.into_inner().map_err(|e| io_err(e.into_error()))?;
        file.sync_all().map_err(io_err)?;
        std::fs::rename(&tmp, path).map_err(io_err)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
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
    fn missing_directory_is_an_error_naming_the_path() {
        let target = std::env::temp_dir().join("lumis-no-such-dir-xyz/out.exr");
        let err = write_atomically(&target, |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(err.contains("lumis-no-such-dir-xyz"), "{err}");
    }
}
