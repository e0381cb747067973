//! Where a render's time goes, by statistical profiling (pbrt-v4's
//! `--stats` profiler, without signals): every worker thread publishes the
//! stage it is in (traversal, BSDF, light sampling...) in an atomic slot,
//! and a sampling thread reads every slot once a millisecond. A stage's
//! share of the samples is its share of the workers' time.
//!
//! Stages are entered by wrappers around the plugins and the scene
//! ([`ProfiledBsdf`], [`ProfiledLight`], [`ProfiledLightSampler`],
//! [`ProfiledSampler`], [`ProfiledScene`]), which a profiled render puts in
//! place of the originals: the integrators stay as they are. The wrappers
//! are the plugin traits' own ([`lumis_core::wrap`]) with a hook that
//! enters the stage, so they forward every method, declarations included.
//! A wrapper costs two relaxed stores and one more virtual call, so a profiled
//! render is a few percent slower than a plain one, and the profiled
//! scene takes the integrators' loop over `dyn Scene`.

use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering::Relaxed};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use lumis_core::audit::Answer;
use lumis_core::wrap::{CallHook, Fault, Wrapped};
use lumis_core::{Bsdf, Light, LightSampler, Sampler, Scene};

/// A stage of the render, as the profile reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Stage {
    /// Not rendering (waiting for work, or outside the render).
    Idle = 0,
    /// The integrator's own work: the path loop, MIS weights, throughput.
    Integrator,
    /// Closest-hit queries, Embree's traversal and the hit's interaction.
    Traversal,
    /// Occlusion queries of shadow rays.
    ShadowRays,
    /// BSDF sampling and evaluation.
    Bsdf,
    /// Choosing a light and sampling, evaluating or weighting it.
    LightSampling,
    /// The sampler's random numbers.
    Sampler,
    /// Camera rays and the film.
    CameraAndFilm,
}

impl Stage {
    const ALL: [Stage; 8] = [
        Stage::Idle,
        Stage::Integrator,
        Stage::Traversal,
        Stage::ShadowRays,
        Stage::Bsdf,
        Stage::LightSampling,
        Stage::Sampler,
        Stage::CameraAndFilm,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Stage::Idle => "idle",
            Stage::Integrator => "integrator (path loop, MIS, throughput)",
            Stage::Traversal => "traversal (closest hit and its interaction)",
            Stage::ShadowRays => "shadow rays (occlusion)",
            Stage::Bsdf => "BSDF sampling and evaluation",
            Stage::LightSampling => "light sampling (choice, sample, pdf, emission)",
            Stage::Sampler => "sampler",
            Stage::CameraAndFilm => "camera rays and film",
        }
    }
}

/// Every worker's slot, for the sampling thread to read.
static SLOTS: Mutex<Vec<Arc<AtomicU8>>> = Mutex::new(Vec::new());

thread_local! {
    /// This thread's slot, registered on first use.
    static SLOT: Arc<AtomicU8> = {
        let slot = Arc::new(AtomicU8::new(Stage::Idle as u8));
        SLOTS
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(Arc::clone(&slot));
        slot
    };
    /// Whether this thread's stage changes are recorded: off unless a
    /// profile is running, so that unprofiled renders touch no slot.
    static ACTIVE: Cell<bool> = const { Cell::new(false) };
}

/// Whether any profile is running (read by workers as they start a tile).
static RUNNING: AtomicBool = AtomicBool::new(false);

/// Runs `f` in `stage`, then returns to the stage it was called from.
#[inline]
pub fn in_stage<R>(stage: Stage, f: impl FnOnce() -> R) -> R {
    if !ACTIVE.with(Cell::get) {
        return f();
    }
    SLOT.with(|slot| {
        // Only this thread writes its slot: a load and a store, no
        // read-modify-write.
        let previous = slot.load(Relaxed);
        slot.store(stage as u8, Relaxed);
        let result = f();
        slot.store(previous, Relaxed);
        result
    })
}

/// Marks the calling (worker) thread as profiled while a profile runs; the
/// driver calls it as each tile starts.
pub fn enter_worker() {
    ACTIVE.with(|a| a.set(RUNNING.load(Relaxed)));
}

/// A running profile: a thread sampling every worker slot each
/// [`Profile::INTERVAL`].
pub struct Profile {
    stop: Arc<AtomicBool>,
    /// Returns the ticks taken and the samples per stage.
    sampler: JoinHandle<(u64, [u64; 8])>,
    start: Instant,
}

/// What a profile measured.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileReport {
    /// Samples per stage, indexed by `Stage as usize`.
    pub counts: [u64; 8],
    /// Wall seconds the profile ran.
    pub seconds: f64,
    /// Sampling ticks taken.
    pub ticks: u64,
}

impl Profile {
    pub const INTERVAL: Duration = Duration::from_millis(1);

    /// Starts sampling. One profile runs at a time in a process; the
    /// slots of threads that never render stay idle and are not counted.
    pub fn start() -> Self {
        RUNNING.store(true, Relaxed);
        let stop = Arc::new(AtomicBool::new(false));
        let stop_flag = Arc::clone(&stop);
        let sampler = std::thread::spawn(move || {
            let (mut ticks, mut counts) = (0u64, [0u64; 8]);
            while !stop_flag.load(Relaxed) {
                std::thread::sleep(Self::INTERVAL);
                let slots = SLOTS.lock().unwrap_or_else(|e| e.into_inner());
                ticks += 1;
                for slot in slots.iter() {
                    let stage = slot.load(Relaxed) as usize;
                    if stage != Stage::Idle as usize && stage < counts.len() {
                        counts[stage] += 1;
                    }
                }
            }
            (ticks, counts)
        });
        Self {
            stop,
            sampler,
            start: Instant::now(),
        }
    }

    /// Stops sampling and returns the counts.
    pub fn finish(self) -> ProfileReport {
        RUNNING.store(false, Relaxed);
        self.stop.store(true, Relaxed);
        let seconds = self.start.elapsed().as_secs_f64();
        let (ticks, counts) = self.sampler.join().unwrap_or((0, [0; 8]));
        ProfileReport {
            counts,
            seconds,
            ticks,
        }
    }
}

impl ProfileReport {
    /// `(stage, share of the workers' busy time, seconds of worker time)`
    /// for every stage seen, largest first.
    pub fn stages(&self) -> Vec<(Stage, f64, f64)> {
        let busy: u64 = self.counts.iter().sum();
        let seconds_per_sample = if self.ticks > 0 {
            self.seconds / self.ticks as f64
        } else {
            0.0
        };
        let mut rows: Vec<(Stage, f64, f64)> = Stage::ALL
            .iter()
            .filter(|&&s| s != Stage::Idle && self.counts[s as usize] > 0)
            .map(|&s| {
                let n = self.counts[s as usize];
                (
                    s,
                    n as f64 / busy.max(1) as f64,
                    n as f64 * seconds_per_sample,
                )
            })
            .collect();
        rows.sort_by(|a, b| b.1.total_cmp(&a.1));
        rows
    }

    /// The report as lines of text.
    pub fn lines(&self) -> Vec<String> {
        let busy: u64 = self.counts.iter().sum();
        let mut lines = vec![format!(
            "time by stage ({busy} samples of the worker threads, about one per {} ms over {:.2} s; the profiled render is a few percent slower than a plain one):",
            Self::interval_ms(),
            self.seconds
        )];
        for (stage, share, seconds) in self.stages() {
            lines.push(format!(
                "  {:<50} {:>5.1}%  {:>7.3} s",
                stage.label(),
                100.0 * share,
                seconds
            ));
        }
        lines
    }

    fn interval_ms() -> u128 {
        Profile::INTERVAL.as_millis()
    }
}

/// The profiler's hook: every call of the wrapped object counts as its
/// stage. Never faults.
#[derive(Debug, Clone, Copy)]
pub struct InStage(pub Stage);

impl CallHook for InStage {
    #[inline]
    fn call<T: Answer>(&self, _: &'static str, call: impl FnOnce() -> T) -> Result<T, Fault> {
        Ok(in_stage(self.0, call))
    }
    fn child(&self) -> Self {
        *self
    }
}

/// The scene's hook: closest-hit queries count as [`Stage::Traversal`],
/// occlusion queries as [`Stage::ShadowRays`], and the rest (the lights)
/// as the stage of whoever asks.
#[derive(Debug, Clone, Copy)]
pub struct SceneStages;

impl CallHook for SceneStages {
    #[inline]
    fn call<T: Answer>(&self, method: &'static str, call: impl FnOnce() -> T) -> Result<T, Fault> {
        Ok(if method.starts_with("Scene::intersect") {
            in_stage(Stage::Traversal, call)
        } else if method.starts_with("Scene::occluded") {
            in_stage(Stage::ShadowRays, call)
        } else {
            call()
        })
    }
    fn child(&self) -> Self {
        *self
    }
}

/// A BSDF whose calls count as [`Stage::Bsdf`].
pub type ProfiledBsdf = Wrapped<Arc<dyn Bsdf>, InStage>;
/// A light whose calls count as [`Stage::LightSampling`].
pub type ProfiledLight = Wrapped<Box<dyn Light>, InStage>;
/// A light sampler whose calls count as [`Stage::LightSampling`].
pub type ProfiledLightSampler = Wrapped<Box<dyn LightSampler>, InStage>;
/// A sampler whose requests count as [`Stage::Sampler`].
pub type ProfiledSampler = Wrapped<Box<dyn Sampler>, InStage>;
/// A scene whose queries count as [`Stage::Traversal`] and
/// [`Stage::ShadowRays`].
pub type ProfiledScene<'a> = Wrapped<&'a dyn Scene, SceneStages>;

/// `bsdf`, its calls counted as [`Stage::Bsdf`].
pub fn profiled_bsdf(bsdf: Arc<dyn Bsdf>) -> ProfiledBsdf {
    Wrapped::new(bsdf, InStage(Stage::Bsdf))
}

/// `light`, its calls counted as [`Stage::LightSampling`].
pub fn profiled_light(light: Box<dyn Light>) -> ProfiledLight {
    Wrapped::new(light, InStage(Stage::LightSampling))
}

/// `sampler`, its calls counted as [`Stage::LightSampling`].
pub fn profiled_light_sampler(sampler: Box<dyn LightSampler>) -> ProfiledLightSampler {
    Wrapped::new(sampler, InStage(Stage::LightSampling))
}

/// `sampler`, its requests counted as [`Stage::Sampler`].
pub fn profiled_sampler(sampler: Box<dyn Sampler>) -> ProfiledSampler {
    Wrapped::new(sampler, InStage(Stage::Sampler))
}

/// `scene`, its queries counted by kind.
pub fn profiled_scene(scene: &dyn Scene) -> ProfiledScene<'_> {
    Wrapped::new(scene, SceneStages)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One test: a profile is process-wide, so two at once in parallel
    /// tests would share it.
    #[test]
    fn busy_stages_are_sampled_nested_and_restored() {
        let profile = Profile::start();
        let worker = std::thread::spawn(|| {
            enter_worker();
            in_stage(Stage::Bsdf, || {
                let start = Instant::now();
                while start.elapsed() < Duration::from_millis(60) {
                    std::hint::spin_loop();
                }
            });
            // Back to idle: not counted.
            std::thread::sleep(Duration::from_millis(30));
        });
        worker.join().unwrap();
        enter_worker();
        SLOT.with(|slot| {
            in_stage(Stage::Integrator, || {
                in_stage(Stage::Traversal, || {
                    assert_eq!(slot.load(Relaxed), Stage::Traversal as u8)
                });
                assert_eq!(slot.load(Relaxed), Stage::Integrator as u8);
            });
            assert_eq!(slot.load(Relaxed), Stage::Idle as u8);
        });
        let report = profile.finish();
        let stages = report.stages();
        assert_eq!(stages[0].0, Stage::Bsdf, "{report:?}");
        assert!(report.counts[Stage::Bsdf as usize] >= 10, "{report:?}");
        assert_eq!(report.counts[Stage::Idle as usize], 0);
        assert!(report.ticks >= report.counts[Stage::Bsdf as usize]);
        assert!(report.lines()[1].contains("BSDF"), "{:?}", report.lines());
        // Outside a profile, stages are not recorded.
        enter_worker();
        SLOT.with(|slot| {
            in_stage(Stage::Bsdf, || {
                assert_eq!(slot.load(Relaxed), Stage::Idle as u8)
            })
        });
    }
}
