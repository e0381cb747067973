//! A render's progress: a bar on a terminal; a plain line every few
//! seconds where stderr is a log, a pipe or a CI job, which a bar would
//! leave silent; or nothing.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Seconds between two plain progress lines.
const LINE_PERIOD: f64 = 5.0;

pub(crate) enum Progress {
    Bar(ProgressBar),
    Lines(Lines),
    Hidden,
}

impl Progress {
    /// Progress over `tiles` tiles, shown if `enabled`.
    pub(crate) fn new(enabled: bool, tiles: u64) -> Self {
        if !enabled {
            return Self::Hidden;
        }
        if !std::io::stderr().is_terminal() {
            return Self::Lines(Lines::new(tiles));
        }
        let bar = ProgressBar::with_draw_target(Some(tiles), ProgressDrawTarget::stderr());
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {wide_bar} {pos}/{len} tiles, eta {eta}",
            )
            .expect("static template is valid"),
        );
        Self::Bar(bar)
    }

    pub(crate) fn tile_done(&self) {
        match self {
            Self::Bar(bar) => bar.inc(1),
            Self::Lines(lines) => {
                if let Some(line) = lines.tile_done() {
                    eprintln!("{line}");
                }
            }
            Self::Hidden => {}
        }
    }

    pub(crate) fn finish(&self) {
        if let Self::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}

/// The plain-line progress: counts tiles, and says how far the render is
/// when a period has passed since the last line.
pub(crate) struct Lines {
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

    fn tile_done(&self) -> Option<String> {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let elapsed = self.start.elapsed().as_secs_f64();
        let mut next = self.next_line.lock().unwrap_or_else(|e| e.into_inner());
        line_if_due(done, self.total, elapsed, &mut next)
    }
}

/// The progress line for `done` of `total` tiles after `elapsed` seconds,
/// if `*next_line` has come (and then the time of the one after).
fn line_if_due(done: u64, total: u64, elapsed: f64, next_line: &mut f64) -> Option<String> {
    if elapsed < *next_line || done >= total {
        return None;
    }
    *next_line = elapsed + LINE_PERIOD;
    let eta = elapsed * (total - done) as f64 / done as f64;
    Some(format!(
        "rendering: {done}/{total} tiles ({:.0}%), {elapsed:.0} s, eta {eta:.0} s",
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
        assert_eq!(line, "rendering: 25/100 tiles (25%), 6 s, eta 16 s");
        assert_eq!(next, 10.5);
        assert_eq!(line_if_due(26, 100, 7.0, &mut next), None);
        assert!(line_if_due(60, 100, 11.0, &mut next).is_some());
        assert_eq!(line_if_due(100, 100, 30.0, &mut next), None);
    }
}
