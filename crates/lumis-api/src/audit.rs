//! What a render counts of a loaded plugin's answers that no correct
//! plugin gives: NaN or infinite numbers, negative radiance, densities or
//! probabilities, and BSDF samples that carry more energy than they
//! receive.
//!
//! Every answer a guarded plugin returns (and every lane a batched method
//! fills) passes [`Answer::audit`] on its way to the host; a [`Tally`] per
//! plugin keeps the counts, and the host that keeps the tallies
//! ([`crate::registrar::FaultReport`]) lists them when the render ends, for the
//! command line to warn about (or, with `--strict`, refuse).
//!
//! Energy: a BSDF sample's weight `f |cos θi| / pdf` has the BSDF's
//! directional albedo as its expectation (the sampled directions cover the
//! lobe), and a physical BSDF reflects no more than it receives, so the
//! mean weight of its reflection samples is at most 1. A single weight
//! has no such bound (a sampler whose density misses the lobe's shape
//! draws large weights, legitimately), so the test is on the mean: it
//! fails where the mean exceeds 1 by more than five standard errors and
//! a relative 1e-3 of rounding, over at least a thousand samples.
//! Transmission is left out: radiance crossing into a thinner medium is
//! scaled up by η² (Veach 1997, section 5.2).

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering::Relaxed};

use glam::{Vec2, Vec3};

use crate::bsdf::{BsdfEvalLanes, BsdfFlags, BsdfSample, BsdfSampleLanes};
use crate::light::{EmissionSample, LightKind, LightSample, LightSampleLanes};
use crate::light_bounds::LightBounds;
use crate::light_sampler::SampledLight;
use crate::sampler::PixelPattern;
use crate::spectrum::Rgb;

/// A value a plugin method returns, as the audit reads it; most answers
/// have nothing to count.
pub trait Answer {
    #[inline]
    fn audit(&self, _tally: &Tally) {}
}

macro_rules! nothing_to_count {
    ($($ty:ty),* $(,)?) => {
        $(impl Answer for $ty {})*
    };
}

nothing_to_count!(
    (),
    bool,
    u32,
    usize,
    BsdfFlags,
    LightKind,
    LightBounds,
    PixelPattern,
    crate::interaction::SurfaceInteraction<'_>,
);

impl<T: ?Sized> Answer for &T {}
impl<T: ?Sized> Answer for Box<T> {}
impl<T, E> Answer for Result<T, E> {}

/// The lanes a batched method filled.
impl<T: Answer> Answer for [T] {
    #[inline]
    fn audit(&self, tally: &Tally) {
        for answer in self {
            answer.audit(tally)
        }
    }
}

/// The lanes of a packet that a lane method answered.
macro_rules! lanes_answer {
    ($($ty:ty),* $(,)?) => {
        $(impl Answer for $ty {
            #[inline]
            fn audit(&self, tally: &Tally) {
                for i in self.valid.iter() {
                    self.get(i).audit(tally)
                }
            }
        })*
    };
}

lanes_answer!(BsdfSampleLanes, BsdfEvalLanes, LightSampleLanes);

impl<T: Answer> Answer for Option<T> {
    #[inline]
    fn audit(&self, tally: &Tally) {
        if let Some(value) = self {
            value.audit(tally)
        }
    }
}

impl<A: Answer, B: Answer> Answer for (A, B) {
    #[inline]
    fn audit(&self, tally: &Tally) {
        self.0.audit(tally);
        self.1.audit(tally);
    }
}

/// A density, a probability, a texture value, a random number: finite and
/// not negative.
impl Answer for f32 {
    #[inline]
    fn audit(&self, tally: &Tally) {
        tally.number(*self)
    }
}

impl Answer for Rgb {
    #[inline]
    fn audit(&self, tally: &Tally) {
        tally.number(self.r);
        tally.number(self.g);
        tally.number(self.b);
    }
}

impl Answer for Vec2 {
    #[inline]
    fn audit(&self, tally: &Tally) {
        tally.number(self.x);
        tally.number(self.y);
    }
}

/// A direction may point anywhere, but not nowhere.
fn audit_direction(w: Vec3, tally: &Tally) {
    if !w.is_finite() {
        tally.nonfinite.fetch_add(1, Relaxed);
    }
}

impl Answer for BsdfSample {
    #[inline]
    fn audit(&self, tally: &Tally) {
        self.f.audit(tally);
        self.pdf.audit(tally);
        audit_direction(self.wi, tally);
        let reflected = !self.flags.contains(BsdfFlags::TRANSMISSION);
        if reflected && self.pdf > 0.0 {
            let weight = self.f.max_component() * self.wi.z.abs() / self.pdf;
            if weight.is_finite() {
                tally.weight(weight as f64);
            }
        }
    }
}

impl Answer for LightSample {
    #[inline]
    fn audit(&self, tally: &Tally) {
        self.l.audit(tally);
        self.pdf.audit(tally);
        audit_direction(self.wi, tally);
    }
}

impl Answer for EmissionSample {
    #[inline]
    fn audit(&self, tally: &Tally) {
        self.l.audit(tally);
        self.pdf_pos.audit(tally);
        self.pdf_dir.audit(tally);
        audit_direction(self.d, tally);
    }
}

impl Answer for SampledLight {
    #[inline]
    fn audit(&self, tally: &Tally) {
        self.pmf.audit(tally)
    }
}

/// Per-thread slots of the weight sums, so that threads add without
/// sharing a cache line.
const SLOTS: usize = 8;

#[derive(Default)]
#[repr(align(64))]
struct WeightSlot {
    count: AtomicU64,
    /// `f64` bits of the sums of weights and of their squares.
    sum: AtomicU64,
    sum_sq: AtomicU64,
}

thread_local! {
    static SLOT: usize = {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        NEXT.fetch_add(1, Relaxed) % SLOTS
    };
}

/// What one plugin's answers held that no correct plugin gives.
#[derive(Default)]
pub struct Tally {
    nonfinite: AtomicU64,
    negative: AtomicU64,
    weights: [WeightSlot; SLOTS],
}

impl Tally {
    #[inline]
    fn number(&self, v: f32) {
        if !v.is_finite() {
            self.nonfinite.fetch_add(1, Relaxed);
        } else if v < 0.0 {
            self.negative.fetch_add(1, Relaxed);
        }
    }

    #[inline]
    fn weight(&self, w: f64) {
        let slot = &self.weights[SLOT.with(|s| *s)];
        // A slot is one thread's unless more threads than slots run, so the
        // exchange almost never retries; it keeps the sums exact when it must.
        let add = |sum: &AtomicU64, v: f64| {
            let _ = sum.fetch_update(Relaxed, Relaxed, |bits| {
                Some((f64::from_bits(bits) + v).to_bits())
            });
        };
        add(&slot.sum, w);
        add(&slot.sum_sq, w * w);
        slot.count.fetch_add(1, Relaxed);
    }

    /// The counts so far.
    pub fn defects(&self) -> Defects {
        let (mut n, mut sum, mut sum_sq) = (0u64, 0.0, 0.0);
        for slot in &self.weights {
            n += slot.count.load(Relaxed);
            sum += f64::from_bits(slot.sum.load(Relaxed));
            sum_sq += f64::from_bits(slot.sum_sq.load(Relaxed));
        }
        Defects {
            nonfinite: self.nonfinite.load(Relaxed),
            negative: self.negative.load(Relaxed),
            samples: n,
            mean_weight: if n > 0 { sum / n as f64 } else { 0.0 },
            weight_error: if n > 1 {
                ((sum_sq / n as f64 - (sum / n as f64).powi(2)).max(0.0) / n as f64).sqrt()
            } else {
                0.0
            },
        }
    }
}

/// One plugin's defects, as a render reports them.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Defects {
    /// Answers holding a NaN or an infinity.
    pub nonfinite: u64,
    /// Negative radiance, densities, probabilities or numbers.
    pub negative: u64,
    /// BSDF reflection samples, and their mean weight `f |cos| / pdf` with
    /// its standard error.
    pub samples: u64,
    pub mean_weight: f64,
    pub weight_error: f64,
}

impl Defects {
    /// Samples below this many say too little about the mean.
    pub const MIN_SAMPLES: u64 = 1000;

    /// Whether the reflection samples carry more energy than they
    /// receive, beyond their noise (see the module's documentation).
    pub fn creates_energy(&self) -> bool {
        self.samples >= Self::MIN_SAMPLES && self.mean_weight > 1.0 + 1e-3 + 5.0 * self.weight_error
    }

    pub fn any(&self) -> bool {
        self.nonfinite > 0 || self.negative > 0 || self.creates_energy()
    }

    /// What was found, in words (empty where nothing was).
    pub fn describe(&self) -> Vec<String> {
        let mut found = Vec::new();
        if self.nonfinite > 0 {
            found.push(format!(
                "{} answers with NaN or infinite values",
                self.nonfinite
            ));
        }
        if self.negative > 0 {
            found.push(format!("{} answers with negative values", self.negative));
        }
        if self.creates_energy() {
            found.push(format!(
                "its reflection samples return {:.4} ± {:.4} of the energy they receive over {} samples, more than any physical BSDF (weight f |cos| / pdf above 1 on average)",
                self.mean_weight, self.weight_error, self.samples
            ));
        }
        found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(f: f32, cos: f32, pdf: f32) -> BsdfSample {
        BsdfSample {
            f: Rgb::splat(f),
            wi: Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos),
            pdf,
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        }
    }

    #[test]
    fn bad_numbers_are_counted() {
        let tally = Tally::default();
        Rgb::new(f32::NAN, 0.5, -1.0).audit(&tally);
        Some((Rgb::BLACK, f32::INFINITY)).audit(&tally);
        (-0.0f32).audit(&tally);
        0.25f32.audit(&tally);
        let d = tally.defects();
        assert_eq!((d.nonfinite, d.negative), (2, 1));
        assert!(d.any());
        assert_eq!(d.describe().len(), 2, "{:?}", d.describe());
    }

    /// A white Lambertian BSDF sampled by the cosine returns exactly what
    /// it receives (weight 1, up to rounding); 3% more is energy created.
    #[test]
    fn a_mean_weight_above_one_creates_energy() {
        let exact = Tally::default();
        let gaining = Tally::default();
        let pi = std::f32::consts::PI;
        for i in 0..2000 {
            let cos = (i as f32 + 0.5) / 2000.0;
            sample(1.0 / pi, cos, cos / pi).audit(&exact);
            sample(1.03 / pi, cos, cos / pi).audit(&gaining);
        }
        assert!(!exact.defects().any(), "{:?}", exact.defects());
        let d = gaining.defects();
        assert!(d.creates_energy(), "{d:?}");
        assert!((d.mean_weight - 1.03).abs() < 1e-4, "{d:?}");
        // Too few samples say nothing.
        let few = Tally::default();
        for _ in 0..10 {
            sample(2.0, 1.0, 1.0).audit(&few);
        }
        assert!(!few.defects().any());
    }
}
