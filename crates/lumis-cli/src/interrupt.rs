//! Ctrl-C, SIGTERM and SIGHUP: the first asks the command to stop at the
//! next safe point and keep its work; a second one exits at once.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use lumis_core::{Error, Result};

/// The exit status of a command stopped by a signal (128 + SIGINT), as
/// shells report an interrupted program.
pub const INTERRUPTED_EXIT_CODE: u8 = 130;

/// Installs the handler; the flag it returns is set by the first signal.
/// Call once per process.
pub fn stop_on_interrupt() -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    let signals = AtomicUsize::new(0);
    ctrlc::set_handler(move || {
        if signals.fetch_add(1, Ordering::SeqCst) == 0 {
            flag.store(true, Ordering::SeqCst);
            eprintln!("\ninterrupted: stopping and saving the work done (again to quit at once)");
        } else {
            eprintln!("\ninterrupted again: quitting");
            std::process::exit(INTERRUPTED_EXIT_CODE.into());
        }
    })
    .map_err(|e| Error::msg(format!("cannot install the Ctrl-C handler: {e}")))?;
    Ok(stop)
}
