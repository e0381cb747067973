//! The host's record of what loaded plugins did wrong: their panics and
//! the defects of their answers, reported by the plugin-side guards
//! ([`lumis_api::guard`]) through [`FaultReport`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use lumis_api::audit::{Defects, Tally};
use lumis_api::registrar::FaultReport;

use crate::error::{Error, Result};

/// The faults of guarded plugins; shared by a registry and every guard
/// its libraries made.
#[derive(Default)]
pub struct FaultSink {
    faulted: AtomicBool,
    /// The first fault of each plugin (by label), in the order they came.
    faults: Mutex<Vec<(Arc<str>, Error)>>,
    /// What each plugin's answers held that no correct plugin gives, by
    /// the plugin's name with its library ([`lumis_api::audit`]).
    tallies: Mutex<Vec<(Arc<str>, Arc<Tally>)>>,
}

impl std::fmt::Debug for FaultSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FaultSink")
            .field("faulted", &self.has_fault())
            .finish_non_exhaustive()
    }
}

impl FaultReport for FaultSink {
    fn record(&self, plugin: &str, error: Error) {
        let mut faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        if !faults.iter().any(|(p, _)| **p == *plugin) {
            faults.push((Arc::from(plugin), error));
        }
        self.faulted.store(true, Ordering::Release);
    }

    fn tally(&self, name: &str) -> Arc<Tally> {
        let mut tallies = self.tallies.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, tally)) = tallies.iter().find(|(n, _)| **n == *name) {
            return tally.clone();
        }
        let tally = Arc::new(Tally::default());
        tallies.push((Arc::from(name), tally.clone()));
        tally
    }
}

impl FaultSink {
    /// Whether any guarded call has panicked: cheap, for polling.
    pub fn has_fault(&self) -> bool {
        self.faulted.load(Ordering::Acquire)
    }

    /// The first fault as an error, if there was one.
    pub fn check(&self) -> Result<()> {
        if !self.has_fault() {
            return Ok(());
        }
        let faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        Err(faults
            .first()
            .map(|(_, e)| e.clone())
            .unwrap_or_else(|| Error::msg("a plugin panicked")))
    }

    /// The loaded plugins whose answers held defects so far (NaN or
    /// infinite, negative, energy created), each named with its library.
    pub fn defects(&self) -> Vec<(Arc<str>, Defects)> {
        let tallies = self.tallies.lock().unwrap_or_else(|e| e.into_inner());
        tallies
            .iter()
            .map(|(name, tally)| (name.clone(), tally.defects()))
            .filter(|(_, defects)| defects.any())
            .collect()
    }

    /// The faults of the plugins whose label starts with `owner` (the
    /// owner they were created with), for telling apart the cases of a
    /// check that made each its own plugin.
    pub fn faults_of(&self, owner: &str) -> Vec<Error> {
        let faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        faults
            .iter()
            .filter(|(plugin, _)| plugin.starts_with(owner))
            .map(|(_, e)| e.clone())
            .collect()
    }
}
