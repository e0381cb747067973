//! A scene document before it is loaded: the parsed TOML of a file, or a
//! table built in code (Python's `lumis.load_dict`), with the `--set`
//! overrides to apply on top. A render loads it, and hashes it to record
//! which scene an image is of.

use std::path::Path;
use std::sync::Arc;

use lumis_core::doc::{self, Table};
use lumis_core::{Error, Location, Registry, Result};
use lumis_files::read_text_bounded;

use crate::load::{load_document, LoadedScene, SCENE_FILE};
use crate::scene_hash::{hash_document, Unreadable};

/// A scene as written, and the overrides a render applies to it.
#[derive(Debug, Clone)]
pub struct SceneDocument {
    /// What names the scene's outputs: a file's stem, e.g. `cornell-box`.
    pub name: String,
    /// Where the document's root is: its file, or the root of a mapping.
    pub origin: Location,
    /// The document as written, without the overrides.
    pub root: Table,
    /// `--set` assignments, applied in order (`integrator.max_depth=3`).
    pub overrides: Vec<String>,
}

impl SceneDocument {
    /// The scene file at `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let text = read_text_bounded(path, SCENE_FILE).map_err(Error::msg)?;
        Self::parse(&text, path)
    }

    /// TOML text, as if it were the file at `path` (which need not exist):
    /// `path` names it in error locations, its directory resolves the
    /// relative paths the text writes, and its stem names the scene.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let label = path.display().to_string();
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into());
        Ok(Self {
            name,
            root: doc::parse(text, &label)?,
            origin: Location::File {
                path: Arc::from(label.as_str()),
                line: 1,
                column: 1,
            },
            overrides: Vec::new(),
        })
    }

    /// A document built in code, each value located by the caller
    /// ([`Location::Key`] for a mapping's); `origin` locates the root.
    pub fn from_table(name: impl Into<String>, root: Table, origin: Location) -> Self {
        Self {
            name: name.into(),
            origin,
            root,
            overrides: Vec::new(),
        }
    }

    /// The document with `overrides` applied after its own.
    pub fn with_overrides(mut self, overrides: impl IntoIterator<Item = String>) -> Self {
        self.overrides.extend(overrides);
        self
    }

    /// The document with its overrides, and `extra` after them, applied:
    /// the table a render loads.
    pub fn resolved(&self, extra: &[String]) -> Result<Table> {
        let mut root = self.root.clone();
        for assignment in self.overrides.iter().chain(extra) {
            doc::apply_override(&mut root, assignment)?;
        }
        Ok(root)
    }

    /// Loads the scene, with `extra` overrides after the document's own
    /// (the command line's `--spp` and `--seed`).
    pub fn load(&self, extra: &[String], registry: &Registry) -> Result<LoadedScene> {
        load_document(self.resolved(extra)?, &self.origin, &self.name, registry)
    }

    /// What the scene renders, as [`crate::scene_hash`] describes: the
    /// document with its overrides. A file it names that cannot be read
    /// is an error: the render would fail on it too.
    pub fn hash(&self) -> Result<u64> {
        hash_document(&self.resolved(&[])?, Unreadable::Fails)
    }

    /// Which scene a render came from, whatever was set on top: the
    /// document as written. A file it names that cannot be read counts by
    /// its name, since an override may have put another in its place.
    pub fn file_hash(&self) -> Result<u64> {
        hash_document(&self.root, Unreadable::CountsByName)
    }
}
