//! Traversal answers recorded once and played back instead of traversing
//! (feature `replay`). A render that replays them does everything the
//! renderer does except Embree's own work, on the same queries: its time is
//! the renderer's time outside Embree, measured directly rather than as the
//! difference of two timings (the `embree_overhead` bench).
//!
//! Replay hands out the answers in the order they were recorded, which is
//! the order a single-threaded render of the same scene, seed and spp asks
//! for them. A query past the end of the recording traverses the scene.

use std::sync::atomic::{AtomicU8, AtomicUsize, Ordering::Relaxed};
use std::sync::Mutex;

use crate::Hit;

const OFF: u8 = 0;
const RECORDING: u8 = 1;
const REPLAYING: u8 = 2;

/// The answers of one render's queries, in order.
#[derive(Debug, Default)]
struct Answers {
    hits: Vec<Option<Hit>>,
    occluded: Vec<bool>,
}

#[derive(Debug, Default)]
pub(crate) struct Tape {
    mode: AtomicU8,
    /// Filled while recording (a lock per query, off the timed run).
    recording: Mutex<Answers>,
    /// Played back; only replaced through `&mut`, so reads need no lock.
    played: Answers,
    /// Where playback is: a relaxed load and store each, no read-modify-
    /// write, because one thread replays.
    next_hit: AtomicUsize,
    next_occluded: AtomicUsize,
}

impl Tape {
    /// Forgets any answers and records the next queries' answers.
    pub(crate) fn record(&mut self) {
        *self.recording.get_mut().unwrap_or_else(|e| e.into_inner()) = Answers::default();
        self.played = Answers::default();
        *self.mode.get_mut() = RECORDING;
    }

    /// Plays the recorded answers back from the first; returns how many
    /// closest-hit and shadow answers there are.
    pub(crate) fn replay(&mut self) -> (usize, usize) {
        let recording = self.recording.get_mut().unwrap_or_else(|e| e.into_inner());
        if !recording.hits.is_empty() || !recording.occluded.is_empty() {
            self.played = std::mem::take(recording);
        }
        *self.next_hit.get_mut() = 0;
        *self.next_occluded.get_mut() = 0;
        *self.mode.get_mut() = REPLAYING;
        (self.played.hits.len(), self.played.occluded.len())
    }

    /// Back to traversing every query (the answers are kept for `replay`).
    pub(crate) fn stop(&mut self) {
        *self.mode.get_mut() = OFF;
    }

    /// How many closest-hit and shadow answers playback has handed out.
    pub(crate) fn played(&self) -> (usize, usize) {
        (
            self.next_hit.load(Relaxed),
            self.next_occluded.load(Relaxed),
        )
    }

    #[inline(always)]
    pub(crate) fn next_hit(&self) -> Option<Option<Hit>> {
        if self.mode.load(Relaxed) != REPLAYING {
            return None;
        }
        let i = self.next_hit.load(Relaxed);
        let answer = *self.played.hits.get(i)?;
        self.next_hit.store(i + 1, Relaxed);
        Some(answer)
    }

    #[inline(always)]
    pub(crate) fn next_occluded(&self) -> Option<bool> {
        if self.mode.load(Relaxed) != REPLAYING {
            return None;
        }
        let i = self.next_occluded.load(Relaxed);
        let answer = *self.played.occluded.get(i)?;
        self.next_occluded.store(i + 1, Relaxed);
        Some(answer)
    }

    #[inline(always)]
    pub(crate) fn keep_hit(&self, hit: Option<Hit>) {
        if self.mode.load(Relaxed) == RECORDING {
            self.lock().hits.push(hit);
        }
    }

    #[inline(always)]
    pub(crate) fn keep_occluded(&self, occluded: bool) {
        if self.mode.load(Relaxed) == RECORDING {
            self.lock().occluded.push(occluded);
        }
    }

    #[cold]
    fn lock(&self) -> std::sync::MutexGuard<'_, Answers> {
        self.recording.lock().unwrap_or_else(|e| e.into_inner())
    }
}
