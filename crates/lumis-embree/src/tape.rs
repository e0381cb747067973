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
//!
//! A packet query records its lanes' answers in lane order, into the same
//! track as single rays of its kind, and replays them the same way: the
//! tape holds the answers the recorded render saw, whichever way it traced,
//! and a batch replays whether it was recorded as packets or ray by ray.

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

    #[inline(always)]
    pub(crate) fn hits(
        &self,
        out: &mut [Option<Hit>],
        traverse: impl FnOnce(usize, &mut [Option<Hit>]),
    ) {
        traverse(0, out)
    }

    #[inline(always)]
    pub(crate) fn occlusions(&self, out: &mut [bool], traverse: impl FnOnce(usize, &mut [bool])) {
        traverse(0, out)
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

        /// Plays back into `out` as many answers as are left, at most its
        /// length; returns how many.
        #[inline(always)]
        fn next_batch(&self, out: &mut [T]) -> usize {
            let i = self.next.load(Relaxed);
            let left = self.played.get(i..).unwrap_or_default();
            let n = left.len().min(out.len());
            out[..n].copy_from_slice(&left[..n]);
            self.next.store(i + n, Relaxed);
            n
        }

        #[cold]
        fn keep_batch(&self, answers: &[T]) {
            self.recording
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .extend_from_slice(answers);
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

        /// Answers into `out` for a batch of closest-hit queries;
        /// `traverse(start, out)` traces the batch's rays from `start` on
        /// into `out` (the rest of the batch).
        #[inline(always)]
        pub(crate) fn hits(
            &self,
            out: &mut [Option<Hit>],
            traverse: impl FnOnce(usize, &mut [Option<Hit>]),
        ) {
            self.answer_batch(&self.hits, out, traverse)
        }

        /// As [`Tape::hits`], for shadow queries.
        #[inline(always)]
        pub(crate) fn occlusions(
            &self,
            out: &mut [bool],
            traverse: impl FnOnce(usize, &mut [bool]),
        ) {
            self.answer_batch(&self.occluded, out, traverse)
        }

        #[inline(always)]
        fn answer_batch<T: Copy>(
            &self,
            track: &Track<T>,
            out: &mut [T],
            traverse: impl FnOnce(usize, &mut [T]),
        ) {
            match self.mode.load(Relaxed) {
                REPLAYING => {
                    // Past the recording's end, the rest traverses.
                    let n = track.next_batch(out);
                    if n < out.len() {
                        traverse(n, &mut out[n..]);
                    }
                }
                RECORDING => {
                    traverse(0, out);
                    track.keep_batch(out);
                }
                _ => traverse(0, out),
            }
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
