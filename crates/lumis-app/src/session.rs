//! What a render asks of its caller: the plugins, a flag that stops it,
//! and where its notes and its progress go.

use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use lumis_core::Registry;
use lumis_render::{ProgressFn, RenderPool, RenderProgress, ThreadHost};

/// The caller's side of a render. The library prints nothing itself: the
/// command line passes `eprintln!` as [`Session::notes`] and
/// [`Progress::Stderr`]; another caller passes its own.
pub struct Session<'a> {
    pub registry: &'a Registry,
    /// Once set (by Ctrl-C, a signal, a notebook's interrupt), the pass in
    /// flight is abandoned and the passes done are written.
    pub stop: &'a AtomicBool,
    /// A line of the start-up report, a resume, a warning: one call per
    /// line, in the order a user should read them.
    pub notes: &'a (dyn Fn(&str) + Sync),
    pub progress: Progress,
    /// What runs each render thread, for a host that prepares its threads
    /// once (Python); `None` runs them as they are.
    pub thread_host: Option<ThreadHost>,
}

impl<'a> Session<'a> {
    /// A session that says nothing and shows no progress.
    pub fn silent(registry: &'a Registry, stop: &'a AtomicBool) -> Self {
        Self {
            registry,
            stop,
            notes: &|_| {},
            progress: Progress::Hidden,
            thread_host: None,
        }
    }

    pub(crate) fn note(&self, line: &str) {
        (self.notes)(line)
    }

    /// The worker threads of a render of `threads` (0: one per core).
    pub(crate) fn pool(&self, threads: usize) -> lumis_core::Result<RenderPool> {
        RenderPool::hosted(threads, self.thread_host.clone())
    }
}

/// How a render shows how far it is.
#[derive(Clone)]
pub enum Progress {
    Hidden,
    /// A bar on stderr where it is a terminal, else a line every few
    /// seconds (a log, a pipe, a CI job).
    Stderr,
    /// The caller's function, called with the units done and their total
    /// (one unit is a tile's samples of one pass) from the render's
    /// threads.
    Reported(Arc<ProgressFn>),
}

impl Progress {
    /// The display of a render of `total` units.
    pub(crate) fn over(&self, total: u64) -> RenderProgress {
        match self {
            Progress::Hidden => RenderProgress::new(false, total),
            Progress::Stderr => RenderProgress::new(true, total),
            Progress::Reported(report) => RenderProgress::reported(total, report.clone()),
        }
    }
}
