//! The scene's BSDFs, indexed as shading looks them up, and found by the
//! names shapes refer to them by.

use std::sync::Arc;

use lumis_core::{Bsdf, Error, Result};

use crate::bsdf_ref::BsdfRef;

/// The `[[bsdf]]`s first (in file order, by name), then those of imported
/// materials (unnamed: only their importer refers to them).
pub(crate) struct BsdfTable {
    names: Vec<String>,
    bsdfs: Vec<Arc<dyn Bsdf>>,
}

impl BsdfTable {
    /// The table of the scene's named BSDFs.
    pub fn named(named: Vec<(String, Arc<dyn Bsdf>)>) -> Self {
        let (names, bsdfs) = named.into_iter().unzip();
        Self { names, bsdfs }
    }

    /// The index of the `[[bsdf]]` `reference` names; `owner` (the shape)
    /// opens the error.
    pub fn index_of(&self, reference: &BsdfRef, owner: &str) -> Result<u32> {
        match self.names.iter().position(|n| *n == reference.name) {
            Some(i) => Ok(i as u32),
            None => Err(Error::at(
                &reference.location,
                format!(
                    "{owner}: no [[bsdf]] named \"{}\"; defined: {}",
                    reference.name,
                    if self.names.is_empty() {
                        "none".into()
                    } else {
                        self.names.join(", ")
                    }
                ),
            )),
        }
    }

    /// Adds an imported material's BSDF; returns its index.
    pub fn push_unnamed(&mut self, bsdf: Arc<dyn Bsdf>) -> u32 {
        self.bsdfs.push(bsdf);
        self.bsdfs.len() as u32 - 1
    }

    pub fn into_bsdfs(self) -> Vec<Arc<dyn Bsdf>> {
        self.bsdfs
    }
}
