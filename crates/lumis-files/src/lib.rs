//! The files a user names: read with a size bound fit for their kind, and
//! replaced only where they are regular files.
//!
//! A user's file can be anything: a directory, a device such as
//! `/dev/zero` that never ends, a FIFO that never opens, or a regular file
//! far larger than any file of its kind. Each is refused with a message
//! instead of being read until memory runs out, or, as an output, instead
//! of being replaced by a rename (which would put an image where a device
//! node was).

use std::fs::File;
use std::io::Read;
use std::path::Path;

/// One mebibyte, for writing the bounds.
pub const MIB: u64 = 1 << 20;
/// One gibibyte.
pub const GIB: u64 = 1 << 30;

/// A texture image (PNG, JPEG, EXR), a file of its own or inside an
/// asset: far above any a renderer can hold (a 16k x 16k float EXR is
/// 3 GiB).
pub const IMAGE_FILE: FileKind = FileKind::new("image", 4 * GIB);

/// What kind of file is read, named in messages, with its size bound.
#[derive(Debug, Clone, Copy)]
pub struct FileKind {
    /// "scene", "OBJ mesh", ...
    pub name: &'static str,
    /// The largest file of this kind that is read.
    pub max_bytes: u64,
}

impl FileKind {
    pub const fn new(name: &'static str, max_bytes: u64) -> Self {
        Self { name, max_bytes }
    }
}

/// Reads all of `path`, a regular file of at most `kind.max_bytes`.
///
/// The checks run on the opened handle, so the file checked is the file
/// read, and the read itself stops one byte past the bound in case the
/// size the system reports is not the size that reads return (`/proc`).
/// Opening does not block on a FIFO: its type is checked first.
pub fn read_bounded(path: &Path, kind: FileKind) -> Result<Vec<u8>, String> {
    let (file, size) = open_bounded(path, kind)?;
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(kind.max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {} '{}': {e}", kind.name, path.display()))?;
    if bytes.len() as u64 > kind.max_bytes {
        return Err(too_large(path, bytes.len() as u64, kind));
    }
    Ok(bytes)
}

/// Opens `path`, a regular file of at most `kind.max_bytes`, for reading
/// it in pieces; with its size. A reader should still stop at the bound.
pub fn open_bounded(path: &Path, kind: FileKind) -> Result<(File, u64), String> {
    let file = open_regular(path, kind)?;
    let size = file
        .metadata()
        .map_err(|e| format!("cannot read {} '{}': {e}", kind.name, path.display()))?
        .len();
    if size > kind.max_bytes {
        return Err(too_large(path, size, kind));
    }
    Ok((file, size))
}

fn too_large(path: &Path, size: u64, kind: FileKind) -> String {
    format!(
        "'{}' is {size} bytes, more than the {} bytes lumis reads as a {}",
        path.display(),
        kind.max_bytes,
        kind.name
    )
}

/// The first `len` bytes of `path` (fewer if the file is shorter), for
/// formats that declare how much of a file they use, such as a glTF
/// buffer's `byteLength`: anything past it is padding, and is not read.
pub fn read_prefix(path: &Path, len: u64, kind: FileKind) -> Result<Vec<u8>, String> {
    if len > kind.max_bytes {
        return Err(format!(
            "'{}' is declared {len} bytes long, more than the {} bytes lumis reads as a {}",
            path.display(),
            kind.max_bytes,
            kind.name
        ));
    }
    let mut bytes = Vec::new();
    open_regular(path, kind)?
        .take(len)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {} '{}': {e}", kind.name, path.display()))?;
    Ok(bytes)
}

/// Opens `path` if it is a regular file. The type is checked before
/// opening, since opening a FIFO blocks until a writer comes.
pub fn open_regular(path: &Path, kind: FileKind) -> Result<File, String> {
    let (shown, what) = (path.display(), kind.name);
    let metadata =
        std::fs::metadata(path).map_err(|e| format!("cannot read {what} '{shown}': {e}"))?;
    if metadata.is_dir() {
        return Err(format!("'{shown}' is a directory, not a {what} file"));
    }
    if !metadata.is_file() {
        return Err(format!(
            "'{shown}' is not a regular file (a device, FIFO or socket); a {what} must be a file"
        ));
    }
    File::open(path).map_err(|e| format!("cannot read {what} '{shown}': {e}"))
}

/// Refuses an output path that exists and is not a regular file (through
/// symbolic links): an output is written beside its target and renamed
/// over it, which would replace a device node, a FIFO or a socket with
/// the file. An absent path, or one that cannot be inspected (the write
/// then reports why), is left to the writer.
pub fn check_replaceable(path: &Path) -> Result<(), String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(format!(
            "'{}' is a directory; an output must be a file",
            path.display()
        )),
        Ok(m) if !m.is_file() => Err(format!(
            "'{}' is not a regular file (a device, FIFO or socket); lumis replaces only \
             regular files with its outputs",
            path.display()
        )),
        _ => Ok(()),
    }
}

/// [`read_bounded`] for a text file, with the first invalid UTF-8 byte's
/// line in the message.
pub fn read_text_bounded(path: &Path, kind: FileKind) -> Result<String, String> {
    let bytes = read_bounded(path, kind)?;
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..at].iter().filter(|&&b| b == b'\n').count();
        format!(
            "'{}' line {line}: not UTF-8 text (byte {at}); a {} is UTF-8 text",
            path.display(),
            kind.name
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: FileKind = FileKind::new("test file", 8);

    #[test]
    fn reads_a_file_within_its_bound() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, b"12345678").unwrap();
        assert_eq!(read_bounded(&path, SMALL).unwrap(), b"12345678");
    }

    #[test]
    fn refuses_a_file_past_its_bound() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, b"123456789").unwrap();
        let err = read_bounded(&path, SMALL).unwrap_err();
        assert!(err.contains("9 bytes, more than the 8"), "{err}");
    }

    #[test]
    fn reads_a_declared_prefix() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, b"1234567890").unwrap();
        assert_eq!(read_prefix(&path, 4, SMALL).unwrap(), b"1234");
        assert_eq!(read_prefix(&path, 8, SMALL).unwrap(), b"12345678");
        let err = read_prefix(&path, 9, SMALL).unwrap_err();
        assert!(err.contains("declared 9 bytes"), "{err}");
    }

    #[test]
    fn refuses_directories_and_devices() {
        let dir = tempfile::tempdir().unwrap();
        let err = read_bounded(dir.path(), SMALL).unwrap_err();
        assert!(err.contains("is a directory"), "{err}");
        let err = read_bounded(Path::new("/dev/zero"), SMALL).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let err = read_prefix(Path::new("/dev/zero"), 4, SMALL).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
    }

    #[test]
    fn only_regular_files_are_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("f.exr");
        assert!(check_replaceable(&file).is_ok());
        std::fs::write(&file, b"x").unwrap();
        assert!(check_replaceable(&file).is_ok());
        let err = check_replaceable(Path::new("/dev/null")).unwrap_err();
        assert!(err.contains("'/dev/null' is not a regular file"), "{err}");
        let err = check_replaceable(dir.path()).unwrap_err();
        assert!(err.contains("is a directory"), "{err}");
    }

    #[test]
    fn names_the_os_reason_and_the_line_of_bad_text() {
        let err = read_bounded(Path::new("no-such-file"), SMALL).unwrap_err();
        assert!(err.contains("test file 'no-such-file'"), "{err}");
        assert!(err.contains("No such file"), "{err}");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        std::fs::write(&path, b"ok\nb\xffd").unwrap();
        let err = read_text_bounded(&path, SMALL).unwrap_err();
        assert!(err.contains("line 2: not UTF-8"), "{err}");
    }
}
