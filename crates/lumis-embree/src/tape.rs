//! Traversal answers recorded once and played back instead of traversing
//! (feature `replay`). A render that replays them does everything the
//! renderer does except Embree's own work, on the same queries: its time is
//! the renderer's time outside Embree, measured directly rather than as the
//! difference of two timings (the `embree_overhead` bench).
//!
//! Replay hands out the answers in the order they were recorded, which is
//! the order a single-threaded render of the same scene, seed and spp asks
//! for them. A query past the end of the recording traverses the scene.
//! Without the feature the tape is empty and every query traverses.

use crate::Hit;

#[cfg(feature = "replay")]
pub(crate) use recorder::Tape;

/// Without the `replay` feature: nothing to record, every query traverses.
#[cfg(not(feature = "replay"))]
#[derive(Debug, Default)]
pub(crate) struct Tape {}

#[cfg(not(feature = "replay"))]
impl Tape {
    #[inline(always)]
    pub(crate) fn hit(&self, traverse: impl FnOnce() -> Option<Hit>) -> Option<Hit> {
        traverse()
    }

    #[inline(always)]
    pub(crate) fn occluded(&self, traverse: impl FnOnce() -> bool) -> bool {
        traverse()
    }

    /// Whether queries are being recorded or replayed: never.
    #[inline(always)]
    pub(crate) fn active(&self) -> bool {
        false
    }
}

#[cfg(feature = "replay")]
mod recorder {
    use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering::Relaxed};
    use std::sync::Mutex;

    use super::Hit;

    const OFF: u8 = 0;
    const RECORDING: u8 = 1;
    const REPLAYING: u8 = 2;

    /// The answers of one kind of query, in order.
    #[derive(Debug, Default)]
    struct Track<T> {
        /// Filled while recording (a lock per query, off the timed run).
        recording: Mutex<Vec<T>>,
        /// Played back; only replaced through `&mut`, so reads need no lock.
        played: Vec<T>,
        /// Where playback is: a relaxed load and store, no read-modify-
        /// write, because one thread replays.
        next: AtomicUsize,
    }

    impl<T: Copy> Track<T> {
        fn clear(&mut self) {
            self.recording
                .get_mut()
                .unwrap_or_else(|e| e.into_inner())
                .clear();
            self.played.clear();
        }

        /// Rewinds, taking over what was recorded since the last rewind, if
        /// anything; returns how many answers it plays.
        fn rewind(&mut self) -> usize {
            let recording = self.recording.get_mut().unwrap_or_else(|e| e.into_inner());
            if !recording.is_empty() {
                self.played = std::mem::take(recording);
            }
            *self.next.get_mut() = 0;
            self.played.len()
        }

        #[inline(always)]
        fn next(&self) -> Option<T> {
            let i = self.next.load(Relaxed);
            let answer = *self.played.get(i)?;
            self.next.store(i + 1, Relaxed);
            Some(answer)
        }

        #[cold]
        fn keep(&self, answer: T) {
            self.recording
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(answer);
        }
    }

    #[derive(Debug, Default)]
    pub(crate) struct Tape {
        mode: AtomicU8,
        hits: Track<Option<Hit>>,
        occluded: Track<bool>,
    }

    impl Tape {
        /// Forgets any answers and records the next queries' answers.
        pub(crate) fn record(&mut self) {
            self.hits.clear();
            self.occluded.clear();
            *self.mode.get_mut() = RECORDING;
        }

        /// Plays the recorded answers back from the first; returns how many
        /// closest-hit and shadow answers there are.
        pub(crate) fn replay(&mut self) -> (usize, usize) {
            *self.mode.get_mut() = REPLAYING;
            (self.hits.rewind(), self.occluded.rewind())
        }

        /// Back to traversing every query (the answers are kept for
        /// `replay`).
        pub(crate) fn stop(&mut self) {
            *self.mode.get_mut() = OFF;
        }

        /// How many closest-hit and shadow answers playback has handed out.
        pub(crate) fn played(&self) -> (usize, usize) {
            (
                self.hits.next.load(Relaxed),
                self.occluded.next.load(Relaxed),
            )
        }

        #[inline(always)]
        pub(crate) fn hit(&self, traverse: impl FnOnce() -> Option<Hit>) -> Option<Hit> {
            self.answer(&self.hits, traverse)
        }

        #[inline(always)]
        pub(crate) fn occluded(&self, traverse: impl FnOnce() -> bool) -> bool {
            self.answer(&self.occluded, traverse)
        }

        /// Whether queries are being recorded or replayed, which the
        /// tape does one query at a time.
        #[inline(always)]
        pub(crate) fn active(&self) -> bool {
            self.mode.load(Relaxed) != OFF
        }

        #[inline(always)]
        fn answer<T: Copy>(&self, track: &Track<T>, traverse: impl FnOnce() -> T) -> T {
            match self.mode.load(Relaxed) {
                REPLAYING => track.next().unwrap_or_else(traverse),
                RECORDING => {
                    let answer = traverse();
                    track.keep(answer);
                    answer
                }
                _ => traverse(),
            }
        }
    }
}
