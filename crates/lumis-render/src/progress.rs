//! A render's progress, over all its passes: a bar on a terminal; a plain line every few
//! seconds where stderr is a log, a pipe or a CI job, which a bar would
//! leave silent; a caller's own function; or nothing.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Seconds between two plain progress lines.
const LINE_PERIOD: f64 = 5.0;

/// Progress over units of work (a tile's samples of one pass), shown as a
/// bar, as lines or not at all.
pub enum RenderProgress {
    Bar(ProgressBar),
    Lines(Lines),
    /// `report(done, total)` after each unit of work, from the thread
    /// that did it.
    Reported {
        total: u64,
        done: AtomicU64,
        report: Arc<ProgressFn>,
    },
    Hidden,
}

/// A caller's progress display: called with the units done and the total.
pub type ProgressFn = dyn Fn(u64, u64) + Send + Sync;

impl RenderProgress {
    /// Progress over `total` units, shown if `enabled`.
    pub fn new(enabled: bool, total: u64) -> Self {
        if !enabled {
            return Self::Hidden;
        }
        if !std::io::stderr().is_terminal() {
            return Self::Lines(Lines::new(total));
        }
        let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {percent}%, eta {eta}",
            )
            .expect("static template is valid"),
        );
        Self::Bar(bar)
    }

    /// Progress over `total` units, reported to `report`.
    pub fn reported(total: u64, report: Arc<ProgressFn>) -> Self {
        Self::Reported {
            total,
            done: AtomicU64::new(0),
            report,
        }
    }

    /// Counts `units` more done.
    pub fn advance(&self, units: u64) {
        match self {
            Self::Bar(bar) => bar.inc(units),
            Self::Lines(lines) => {
                if let Some(line) = lines.advance(units) {
                    eprintln!("{line}");
                }
            }
            Self::Reported {
                total,
                done,
                report,
            } => report(done.fetch_add(units, Ordering::Relaxed) + units, *total),
            Self::Hidden => {}
        }
    }

    /// Clears the bar.
    pub fn finish(&self) {
        if let Self::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}

/// The plain-line progress: counts units, and says how far the render is
/// when a period has passed since the last line.
pub struct Lines {
    total: u64,
    done: AtomicU64,
    start: Instant,
    /// Seconds after `start` when the next line is due.
    next_line: Mutex<f64>,
}

impl Lines {
    fn new(total: u64) -> Self {
        Self {
            total,
            done: AtomicU64::new(0),
            start: Instant::now(),
            next_line: Mutex::new(LINE_PERIOD),
        }
    }

    fn advance(&self, units: u64) -> Option<String> {
        let done = self.done.fetch_add(units, Ordering::Relaxed) + units;
        let elapsed = self.start.elapsed().as_secs_f64();
        let mut next = self.next_line.lock().unwrap_or_else(|e| e.into_inner());
        line_if_due(done, self.total, elapsed, &mut next)
    }
}

/// The progress line for `done` of `total` units after `elapsed` seconds,
/// if `*next_line` has come (and then the time of the one after).
fn line_if_due(done: u64, total: u64, elapsed: f64, next_line: &mut f64) -> Option<String> {
    if elapsed < *next_line || done >= total {
        return None;
    }
    *next_line = elapsed + LINE_PERIOD;
    let eta = elapsed * (total - done) as f64 / done as f64;
    Some(format!(
        "rendering: {:.0}%, {elapsed:.0} s, eta {eta:.0} s",
        100.0 * done as f64 / total as f64
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line once per period, none before the first or after the last
    /// tile, with the share done and the time left at the current pace.
    #[test]
    fn lines_come_once_per_period() {
        let mut next = LINE_PERIOD;
        assert_eq!(line_if_due(3, 100, 1.0, &mut next), None);
        let line = line_if_due(25, 100, 5.5, &mut next).unwrap();
        assert_eq!(line, "rendering: 25%, 6 s, eta 16 s");
        assert_eq!(next, 10.5);
        assert_eq!(line_if_due(26, 100, 7.0, &mut next), None);
        assert!(line_if_due(60, 100, 11.0, &mut next).is_some());
        assert_eq!(line_if_due(100, 100, 30.0, &mut next), None);
    }
}
