//! Faults of loaded plugins contained on the plugin's side of the boundary.
//!
//! A plugin library carries its own copy of the Rust standard library, and
//! a panic unwinding out of it into lumis is a foreign exception, which
//! aborts the process: the host cannot catch it. So the catching is done
//! where the plugin's code runs. [`lumis_plugin!`](crate::lumis_plugin)
//! wraps `register`, and while a library registers, the registry wraps
//! every factory it is given, and every plugin those factories make, in
//! the guards below. All of that is this module, compiled into the
//! plugin's own copy of lumis-core, so its `catch_unwind` is the plugin's.
//!
//! A caught panic becomes an [`Error`] naming the plugin, its library, the
//! method and the parameters, kept in the registry's [`FaultSink`]; the
//! call returns a neutral value (no sample, zero radiance) and the host
//! stops at its next check of the sink. Built-in plugins are not wrapped:
//! their panics are the host's own, and unwind normally.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use crate::audit::{Answer, Defects, Tally};
use crate::error::{Error, Result};
use crate::registry::Registry;
use crate::wrap::{CallHook, Fault, Wrapped};

/// The faults of guarded plugins; shared by a registry and every guard it
/// made.
#[derive(Default)]
pub struct FaultSink {
    faulted: AtomicBool,
    /// The first fault of each plugin (by label), in the order they came.
    faults: Mutex<Vec<(Arc<str>, Error)>>,
    /// What each plugin's answers held that no correct plugin gives, by
    /// the plugin's name with its library ([`crate::audit`]).
    tallies: Mutex<Vec<(Arc<str>, Arc<Tally>)>>,
}

impl std::fmt::Debug for FaultSink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FaultSink")
            .field("faulted", &self.has_fault())
            .finish_non_exhaustive()
    }
}

impl FaultSink {
    /// Keeps `error` if it is the first of `plugin`'s.
    fn record(&self, plugin: &str, error: Error) {
        let mut faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        if !faults.iter().any(|(p, _)| **p == *plugin) {
            faults.push((Arc::from(plugin), error));
        }
        self.faulted.store(true, Ordering::Release);
    }

    /// Whether any guarded call has panicked: cheap, for polling.
    pub fn has_fault(&self) -> bool {
        self.faulted.load(Ordering::Acquire)
    }

    /// The first fault as an error, if there was one.
    pub fn check(&self) -> Result<()> {
        if !self.has_fault() {
            return Ok(());
        }
        let faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        Err(faults
            .first()
            .map(|(_, e)| e.clone())
            .unwrap_or_else(|| Error::msg("a plugin panicked")))
    }

    /// The tally of the plugin named `name`, shared by every object made
    /// under that name.
    fn tally(&self, name: &str) -> Arc<Tally> {
        let mut tallies = self.tallies.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, tally)) = tallies.iter().find(|(n, _)| **n == *name) {
            return tally.clone();
        }
        let tally = Arc::new(Tally::default());
        tallies.push((Arc::from(name), tally.clone()));
        tally
    }

    /// The loaded plugins whose answers held defects so far (NaN or
    /// infinite, negative, energy created), each named with its library.
    pub fn defects(&self) -> Vec<(Arc<str>, Defects)> {
        let tallies = self.tallies.lock().unwrap_or_else(|e| e.into_inner());
        tallies
            .iter()
            .map(|(name, tally)| (name.clone(), tally.defects()))
            .filter(|(_, defects)| defects.any())
            .collect()
    }

    /// The faults of the plugins whose label starts with `owner` (the
    /// owner they were created with), for telling apart the cases of a
    /// check that made each its own plugin.
    pub fn faults_of(&self, owner: &str) -> Vec<Error> {
        let faults = self.faults.lock().unwrap_or_else(|e| e.into_inner());
        faults
            .iter()
            .filter(|(plugin, _)| plugin.starts_with(owner))
            .map(|(_, e)| e.clone())
            .collect()
    }
}

/// Runs a library's `register` under the library's `catch_unwind`: what
/// [`lumis_plugin!`](crate::lumis_plugin) exports.
pub fn register_guarded(
    registry: &mut Registry,
    register: fn(&mut Registry) -> Result<()>,
) -> Result<()> {
    // The library's panics report through its own copy of the standard
    // library's hook, once per call that panics: a faulty BSDF would print
    // one per pixel. Its first is printed (with its file and line); the
    // rest are in the error that stops the host.
    static QUIET_AFTER_FIRST: std::sync::Once = std::sync::Once::new();
    QUIET_AFTER_FIRST.call_once(|| {
        let report = std::panic::take_hook();
        let printed = AtomicBool::new(false);
        std::panic::set_hook(Box::new(move |info| {
            if !printed.swap(true, Ordering::Relaxed) {
                report(info);
            }
        }));
    });
    catch_unwind(AssertUnwindSafe(|| register(registry))).unwrap_or_else(|payload| {
        Err(Error::msg(format!(
            "panicked in register: {}",
            panic_message(payload.as_ref())
        )))
    })
}

/// The text of a panic's payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic without a message".into()
    }
}

/// Where guarded calls report: the library's path and the sink.
#[derive(Clone, Debug)]
pub struct PluginGuard {
    library: Arc<str>,
    faults: Arc<FaultSink>,
}

impl PluginGuard {
    pub fn new(library: &str, faults: Arc<FaultSink>) -> Self {
        Self {
            library: Arc::from(library),
            faults,
        }
    }

    /// Runs `f` for `plugin` (`bsdf 'name' (params)`), turning a panic in
    /// `method` into a recorded error.
    pub fn call<T>(&self, plugin: &str, method: &str, f: impl FnOnce() -> T) -> Result<T> {
        catch_unwind(AssertUnwindSafe(f)).map_err(|payload| {
            let error = Error::msg(format!(
                "{plugin} from '{}' panicked in {method}: {}",
                self.library,
                panic_message(payload.as_ref())
            ));
            self.faults.record(plugin, error.clone());
            error
        })
    }
}

/// The hook of a guarded plugin: its guard and how messages name it. Once
/// the plugin has panicked it is not called again: its state may be
/// broken, and each further panic would cost as much as the work it
/// interrupts.
///
/// Every answer that comes back is audited ([`crate::audit`]): the counts
/// go to the plugin's tally in the registry's [`FaultSink`].
pub struct Guard {
    guard: PluginGuard,
    label: Arc<str>,
    tripped: AtomicBool,
    tally: Arc<Tally>,
}

impl Guard {
    /// `label` names the plugin in messages, with its parameters.
    pub fn new(guard: PluginGuard, label: Arc<str>) -> Self {
        let tally = guard
            .faults
            .tally(&format!("{label} from '{}'", guard.library));
        Self {
            guard,
            label,
            tripped: AtomicBool::new(false),
            tally,
        }
    }
}

impl CallHook for Guard {
    #[inline]
    fn call<T: Answer>(&self, method: &'static str, call: impl FnOnce() -> T) -> Result<T, Fault> {
        if self.tripped.load(Ordering::Relaxed) {
            return Err(Fault::Tripped);
        }
        match self.guard.call(&self.label, method, call) {
            Ok(answer) => {
                answer.audit(&self.tally);
                Ok(answer)
            }
            Err(error) => {
                self.tripped.store(true, Ordering::Relaxed);
                Err(Fault::Panicked(error))
            }
        }
    }

    #[inline]
    fn seen<T: Answer>(&self, out: &[T]) {
        for answer in out {
            answer.audit(&self.tally);
        }
    }

    fn child(&self) -> Self {
        Self {
            guard: self.guard.clone(),
            label: self.label.clone(),
            tripped: AtomicBool::new(false),
            tally: self.tally.clone(),
        }
    }
}

/// A loaded plugin object, every call of it guarded: `Guarded<Arc<dyn
/// Bsdf>>` is a `Bsdf` (see [`crate::wrap`]).
pub type Guarded<C> = Wrapped<C, Guard>;

#[cfg(test)]
mod tests {
    use glam::{Vec2, Vec3};

    use super::*;
    use crate::bsdf::{Bsdf, BsdfContext, BsdfFlags, BsdfSample};
    use crate::denoiser::{DenoiseInput, Denoiser};
    use crate::spectrum::Rgb;

    struct Faulty;

    impl Bsdf for Faulty {
        fn flags(&self) -> BsdfFlags {
            BsdfFlags::DIFFUSE_REFLECTION
        }
        fn f(&self, _: &BsdfContext, _: Vec3, wi: Vec3) -> Rgb {
            assert!(wi.z > 0.5, "wi.z = {} is too low", wi.z);
            Rgb::splat(0.25)
        }
        fn sample_f(&self, _: &BsdfContext, _: Vec3, _: f32, _: Vec2) -> Option<BsdfSample> {
            panic!("no sampling")
        }
        fn pdf(&self, _: &BsdfContext, _: Vec3, _: Vec3) -> f32 {
            1.0
        }
    }

    #[test]
    fn a_panic_is_a_recorded_error_and_a_neutral_value() {
        let faults = Arc::new(FaultSink::default());
        let guard = PluginGuard::new("libfaulty.so", faults.clone());
        let bsdf: Arc<dyn Bsdf> = Arc::new(Faulty);
        let guarded = Guarded::new(
            bsdf,
            Guard::new(guard, Arc::from("bsdf 'faulty' (sigma = 0.65)")),
        );
        let ctx = BsdfContext::default();
        assert_eq!(guarded.f(&ctx, Vec3::Z, Vec3::Z), Rgb::splat(0.25));
        assert!(faults.check().is_ok());
        assert_eq!(guarded.f(&ctx, Vec3::Z, Vec3::X), Rgb::BLACK);
        assert!(guarded.sample_f(&ctx, Vec3::Z, 0.5, Vec2::ZERO).is_none());
        let err = faults.check().unwrap_err().to_string();
        assert!(
            err.contains("bsdf 'faulty' (sigma = 0.65) from 'libfaulty.so' panicked in Bsdf::f: wi.z = 0 is too low"),
            "{err}"
        );
    }

    struct Panicking;

    impl Denoiser for Panicking {
        fn denoise(&self, input: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>> {
            Ok(vec![input.color[input.width * input.height]])
        }
    }

    #[test]
    fn a_panicking_denoiser_is_an_error() {
        let faults = Arc::new(FaultSink::default());
        let guard = PluginGuard::new("libdenoise.so", faults.clone());
        let denoiser: Box<dyn Denoiser> = Box::new(Panicking);
        let guarded = Guarded::new(
            denoiser,
            Guard::new(guard, Arc::from("denoiser (type = \"x\")")),
        );
        let input = DenoiseInput {
            width: 1,
            height: 1,
            color: &[[1.0; 3]],
            albedo: None,
            normal: None,
        };
        let err = guarded.denoise(&input).unwrap_err().to_string();
        assert!(
            err.contains(
                "denoiser (type = \"x\") from 'libdenoise.so' panicked in Denoiser::denoise"
            ),
            "{err}"
        );
        assert!(faults.check().is_err());
    }
}
