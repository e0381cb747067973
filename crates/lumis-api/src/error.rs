//! Errors that point at the scene file, line and key that caused them.

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a value came from: a line of a scene file, a command-line
/// override, or a key of a scene given as a mapping.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Location {
    File {
        path: Arc<str>,
        line: u32,
        column: u32,
    },
    Override(Arc<str>),
    /// A value of a scene given as nested mappings rather than text
    /// (Python's `lumis.load_dict`), named by its subscripts from the
    /// root, as the caller wrote them: `scene['bsdf'][0]['reflectance']`.
    Key(Arc<str>),
    /// Built into lumis (a parameter default, a programmatic table).
    Builtin,
}

impl Location {
    /// A file path written here, resolved. A relative path is resolved
    /// against the directory of the scene file that wrote it, so a scene and
    /// its assets move together; given with `--set`, in a mapping (or built
    /// in), it is relative to the working directory, as a path typed in a
    /// shell is.
    pub fn resolve(&self, path: impl AsRef<Path>) -> PathBuf {
        let path = path.as_ref();
        match self {
            Location::File { path: scene, .. } if path.is_relative() => Path::new(&**scene)
                .parent()
                .map_or(path.to_path_buf(), |dir| dir.join(path)),
            _ => path.to_path_buf(),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::File { path, line, column } => write!(f, "{path}:{line}:{column}"),
            Location::Override(text) => write!(f, "--set {text}"),
            Location::Key(path) => f.write_str(path),
            Location::Builtin => write!(f, "<built-in>"),
        }
    }
}

/// A lumis error: a message, and where in the input it was found if known.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct Error {
    pub location: Option<Location>,
    pub message: String,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            Some(location) => write!(f, "{location}: {}", self.message),
            None => f.write_str(&self.message),
        }
    }
}

impl Error {
    pub fn msg(message: impl Into<String>) -> Self {
        Self {
            location: None,
            message: message.into(),
        }
    }

    pub fn at(location: &Location, message: impl Into<String>) -> Self {
        Self {
            location: Some(location.clone()),
            message: message.into(),
        }
    }

    /// Prefixes the message with context, keeping the location.
    pub fn context(mut self, context: impl fmt::Display) -> Self {
        self.message = format!("{context}: {}", self.message);
        self
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
