//! Long work run from Python so that Ctrl-C stops it.
//!
//! The work runs on a thread of its own with the GIL released; the calling
//! thread wakes every [`POLL`] to run Python's signal handlers (so Ctrl-C,
//! or a notebook's interrupt, raises there) and the caller's `tick` (a
//! progress bar). The first exception either raises sets the work's stop
//! flag. Every Python call is made on the calling thread.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use lumis_core::Error;
use pyo3::prelude::*;

use crate::errors::lumis_error;

/// How often the calling thread looks at signals and progress.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` until it returns, setting `stop` at the first exception of
/// the signal handlers or of `tick`; returns what the work returned and
/// that exception.
pub fn run_stoppable<T: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> T + Send,
    mut tick: impl FnMut(Python<'_>) -> PyResult<()> + Send,
) -> PyResult<(T, Option<PyErr>)> {
    let (done, stopped_by) = py.detach(|| {
        std::thread::scope(|threads| {
            let worker = threads.spawn(work);
            let mut stopped_by: Option<PyErr> = None;
            while !worker.is_finished() {
                std::thread::park_timeout(POLL);
                Python::attach(|py| {
                    let looked = py.check_signals().and_then(|()| tick(py));
                    if let (Err(e), None) = (looked, &stopped_by) {
                        stop.store(true, Ordering::Relaxed);
                        stopped_by = Some(e);
                    }
                });
            }
            (worker.join(), stopped_by)
        })
    });
    let done = done.map_err(|_| lumis_error(py, &Error::msg("the work panicked")))?;
    Ok((done, stopped_by))
}
