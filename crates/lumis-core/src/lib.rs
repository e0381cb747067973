//! lumis core: the host's side of the plugin boundary.
//!
//! Everything a plugin sees is [`lumis_api`], re-exported here whole so the
//! host's crates speak one vocabulary. What only the host needs lives here:
//! the scene document's parser and `--set` overrides ([`doc`]), the
//! [`Registry`] plugins register with, the [`PluginEntity`] it creates
//! plugins from, and the [`FaultSink`](faults::FaultSink) where loaded
//! plugins' guards report. None of it is part of the plugin interface, so
//! none of it is in the fingerprint a library is checked against.

pub use lumis_api::*;

pub mod doc;
pub mod entity;
pub mod faults;
pub mod registry;

pub use entity::PluginEntity;
pub use registry::{PluginInterface, Registry};
