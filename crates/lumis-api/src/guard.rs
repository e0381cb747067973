//! Faults of loaded plugins contained on the plugin's side of the boundary.
//!
//! A plugin library carries its own copy of the Rust standard library, and
//! a panic unwinding out of it into lumis is a foreign exception, which
//! aborts the process: the host cannot catch it. So the catching is done
//! where the plugin's code runs. [`lumis_plugin!`](crate::lumis_plugin)
//! wraps `register`, and hands it a registrar ([`Guarding`]) that wraps
//! every factory it is given, and every plugin those factories make, in
//! the guards below. All of that is this module, compiled into the
//! plugin's own copy of lumis-api, so its `catch_unwind` is the plugin's.
//!
//! A caught panic becomes an [`Error`] naming the plugin, its library, the
//! method and the parameters, kept by the host's [`FaultReport`]; the
//! call returns a neutral value (no sample, zero radiance) and the host
//! stops at its next check of its record. Built-in plugins are not wrapped:
//! their panics are the host's own, and unwind normally.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use crate::audit::{Answer, Tally};
use crate::error::{Error, Result};
use crate::registrar::{Factory, FaultReport, PluginSpec, Registrar};
use crate::wrap::{CallHook, Fault, Wrapped};

/// Runs a library's `register` under the library's `catch_unwind`, with
/// every factory it registers guarded ([`Guarding`]): what
/// [`lumis_plugin!`](crate::lumis_plugin) exports.
pub fn register_guarded(
    registrar: &mut dyn Registrar,
    register: fn(&mut dyn Registrar) -> Result<()>,
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
    let guard = PluginGuard::new(registrar.source(), registrar.faults());
    let mut guarding = Guarding {
        host: registrar,
        guard,
    };
    catch_unwind(AssertUnwindSafe(|| register(&mut guarding))).unwrap_or_else(|payload| {
        Err(Error::msg(format!(
            "panicked in register: {}",
            panic_message(payload.as_ref())
        )))
    })
}

/// The registrar a library's `register` is given: the host's, with every
/// factory guarded on its way in. Runs in the library's copy of this code,
/// so the closures it makes, and their `catch_unwind`, are the library's.
pub struct Guarding<'h> {
    host: &'h mut dyn Registrar,
    guard: PluginGuard,
}

impl Registrar for Guarding<'_> {
    fn add(&mut self, spec: PluginSpec, factory: Factory) -> Result<()> {
        self.host.add(spec, guarded_factory(&self.guard, factory))
    }

    fn source(&self) -> &str {
        self.host.source()
    }

    fn faults(&self) -> Arc<dyn FaultReport> {
        self.host.faults()
    }
}

/// `factory`, called under `guard`, and what it makes guarded.
fn guarded_factory(guard: &PluginGuard, factory: Factory) -> Factory {
    /// The guarded closure for one kind: `$boxed` boxes what is made.
    macro_rules! guarded {
        ($make:ident, $boxed:path, |$params:ident $(, $input:ident: $ty:ty)?|) => {{
            let guard = guard.clone();
            Arc::new(move |$params: &crate::params::Params $(, $input: $ty)?| {
                let label: Arc<str> =
                    Arc::from(format!("{} {{ {} }}", $params.owner(), $params.written()));
                let made = guard.call(&label, "its factory", || $make($params $(, $input)?))??;
                Ok($boxed(Guarded::new(made, Guard::new(guard.clone(), label))))
            })
        }};
    }
    use crate::light::{Light, LightShape};
    match factory {
        Factory::Sampler(make) => Factory::Sampler(guarded!(make, Box::new, |params|)),
        Factory::Texture(make) => Factory::Texture(guarded!(make, Arc::new, |params|)),
        Factory::Bsdf(make) => Factory::Bsdf(guarded!(make, Arc::new, |params|)),
        Factory::Light(make) => {
            Factory::Light(guarded!(make, Box::new, |params, shape: &LightShape|))
        }
        Factory::LightSampler(make) => Factory::LightSampler(guarded!(
            make,
            Box::new,
            |params, lights: &[Box<dyn Light>]|
        )),
        Factory::Integrator(make) => Factory::Integrator(guarded!(make, Box::new, |params|)),
        Factory::Denoiser(make) => Factory::Denoiser(guarded!(make, Box::new, |params|)),
    }
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
    faults: Arc<dyn FaultReport>,
}

impl std::fmt::Debug for dyn FaultReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("FaultReport")
    }
}

impl PluginGuard {
    pub fn new(library: &str, faults: Arc<dyn FaultReport>) -> Self {
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
/// go to the plugin's tally, which the host keeps ([`FaultReport`]).
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
    fn seen<A: Answer + ?Sized>(&self, out: &A) {
        out.audit(&self.tally);
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
    use std::sync::Mutex;

    use glam::{Vec2, Vec3};

    use super::*;
    use crate::bsdf::{Bsdf, BsdfContext, BsdfFlags, BsdfSample};
    use crate::denoiser::{DenoiseInput, Denoiser};
    use crate::spectrum::Rgb;

    /// The faults and tallies of the plugins a test guards.
    #[derive(Default)]
    struct Recorded {
        faults: Mutex<Vec<Error>>,
    }

    impl FaultReport for Recorded {
        fn record(&self, _plugin: &str, error: Error) {
            self.faults.lock().unwrap().push(error);
        }
        fn tally(&self, _name: &str) -> Arc<Tally> {
            Arc::default()
        }
    }

    impl Recorded {
        fn check(&self) -> Result<()> {
            match self.faults.lock().unwrap().first() {
                Some(e) => Err(e.clone()),
                None => Ok(()),
            }
        }
    }

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
        let faults = Arc::new(Recorded::default());
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
        let faults = Arc::new(Recorded::default());
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
