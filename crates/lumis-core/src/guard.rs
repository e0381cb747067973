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

use glam::{UVec2, Vec2, Vec3};

use crate::bsdf::{Bsdf, BsdfContext, BsdfFlags, BsdfSample};
use crate::denoiser::{DenoiseInput, Denoiser};
use crate::error::{Error, Result};
use crate::integrator::Integrator;
use crate::interaction::LightSampleContext;
use crate::light::{Light, LightKind, LightSample};
use crate::light_sampler::{LightSampler, SampledLight};
use crate::ray::Ray;
use crate::registry::Registry;
use crate::sampler::{Sampler, SamplerLanes};
use crate::scene::Scene;
use crate::spectrum::Rgb;
use crate::stats::RenderStats;
use crate::texture::{Texture, TextureQuery};

/// The faults of guarded plugins; shared by a registry and every guard it
/// made.
#[derive(Debug, Default)]
pub struct FaultSink {
    faulted: AtomicBool,
    /// The first fault of each plugin (by label), in the order they came.
    faults: Mutex<Vec<(Arc<str>, Error)>>,
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

/// A guarded plugin: its guard and how messages name it. Once it has
/// panicked it is not called again: its state may be broken, and each
/// further panic would cost as much as the work it interrupts.
pub struct Guarded<P> {
    inner: P,
    guard: PluginGuard,
    label: Arc<str>,
    tripped: AtomicBool,
}

impl<P> Guarded<P> {
    /// `label` names the plugin in messages, with its parameters.
    pub fn new(inner: P, guard: PluginGuard, label: Arc<str>) -> Self {
        Self {
            inner,
            guard,
            label,
            tripped: AtomicBool::new(false),
        }
    }

    fn value<T>(&self, method: &str, neutral: T, f: impl FnOnce(&P) -> T) -> T {
        if self.tripped.load(Ordering::Relaxed) {
            return neutral;
        }
        let inner = &self.inner;
        self.guard
            .call(&self.label, method, || f(inner))
            .unwrap_or_else(|_| {
                self.tripped.store(true, Ordering::Relaxed);
                neutral
            })
    }

    fn value_mut<T>(&mut self, method: &str, neutral: T, f: impl FnOnce(&mut P) -> T) -> T {
        if *self.tripped.get_mut() {
            return neutral;
        }
        let inner = &mut self.inner;
        match self.guard.call(&self.label, method, || f(inner)) {
            Ok(value) => value,
            Err(_) => {
                *self.tripped.get_mut() = true;
                neutral
            }
        }
    }
}

impl Bsdf for Guarded<Arc<dyn Bsdf>> {
    fn flags(&self) -> BsdfFlags {
        self.value("Bsdf::flags", BsdfFlags::NONE, |b| b.flags())
    }
    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb {
        self.value("Bsdf::f", Rgb::BLACK, |b| b.f(ctx, wo, wi))
    }
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample> {
        self.value("Bsdf::sample_f", None, |b| b.sample_f(ctx, wo, u1, u2))
    }
    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32 {
        self.value("Bsdf::pdf", 0.0, |b| b.pdf(ctx, wo, wi))
    }
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        self.value("Bsdf::eval", (Rgb::BLACK, 0.0), |b| b.eval(ctx, wo, wi))
    }
    fn sample_f_batch(
        &self,
        ctx: &[BsdfContext],
        wo: &[Vec3],
        u1: &[f32],
        u2: &[Vec2],
        out: &mut [Option<BsdfSample>],
    ) {
        let out_of_call = &mut *out;
        let done = self.value("Bsdf::sample_f_batch", false, |b| {
            b.sample_f_batch(ctx, wo, u1, u2, out_of_call);
            true
        });
        if !done {
            out.fill(None);
        }
    }
    fn eval_batch(&self, ctx: &[BsdfContext], wo: &[Vec3], wi: &[Vec3], out: &mut [(Rgb, f32)]) {
        let out_of_call = &mut *out;
        let done = self.value("Bsdf::eval_batch", false, |b| {
            b.eval_batch(ctx, wo, wi, out_of_call);
            true
        });
        if !done {
            out.fill((Rgb::BLACK, 0.0));
        }
    }
}

impl Texture for Guarded<Arc<dyn Texture>> {
    fn eval(&self, query: &TextureQuery) -> Rgb {
        self.value("Texture::eval", Rgb::BLACK, |t| t.eval(query))
    }
    fn eval_float(&self, query: &TextureQuery) -> f32 {
        self.value("Texture::eval_float", 0.0, |t| t.eval_float(query))
    }
    fn uses_footprint(&self) -> bool {
        self.value("Texture::uses_footprint", false, |t| t.uses_footprint())
    }
}

impl Light for Guarded<Box<dyn Light>> {
    fn kind(&self) -> LightKind {
        self.inner.kind()
    }
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample> {
        self.value("Light::sample_li", None, |l| l.sample_li(ctx, u))
    }
    fn sample_li_batch(
        &self,
        ctx: &[LightSampleContext],
        u: &[Vec2],
        out: &mut [Option<LightSample>],
    ) {
        let out_of_call = &mut *out;
        let done = self.value("Light::sample_li_batch", false, |l| {
            l.sample_li_batch(ctx, u, out_of_call);
            true
        });
        if !done {
            out.fill(None);
        }
    }
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32 {
        self.value("Light::pdf_li", 0.0, |l| l.pdf_li(ctx, wi))
    }
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        self.value("Light::l", Rgb::BLACK, |l| l.l(p, n, uv, w))
    }
    fn power(&self) -> Rgb {
        self.value("Light::power", Rgb::BLACK, |l| l.power())
    }
    fn preprocess(&mut self, scene_center: Vec3, scene_radius: f32) {
        self.value_mut("Light::preprocess", (), |l| {
            l.preprocess(scene_center, scene_radius)
        })
    }
}

impl LightSampler for Guarded<Box<dyn LightSampler>> {
    fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        self.value("LightSampler::sample", None, |s| s.sample(ctx, u))
    }
    fn pmf(&self, ctx: &LightSampleContext, index: u32) -> f32 {
        self.value("LightSampler::pmf", 0.0, |s| s.pmf(ctx, index))
    }
}

impl Sampler for Guarded<Box<dyn Sampler>> {
    fn samples_per_pixel(&self) -> u32 {
        self.value("Sampler::samples_per_pixel", 1, |s| s.samples_per_pixel())
    }
    fn start_pixel_sample(&mut self, pixel: UVec2, index: u32, seed: u64) {
        self.value_mut("Sampler::start_pixel_sample", (), |s| {
            s.start_pixel_sample(pixel, index, seed)
        })
    }
    fn get_1d(&mut self) -> f32 {
        self.value_mut("Sampler::get_1d", 0.5, |s| s.get_1d())
    }
    fn get_2d(&mut self) -> Vec2 {
        self.value_mut("Sampler::get_2d", Vec2::splat(0.5), |s| s.get_2d())
    }
    fn get_1d_2d(&mut self) -> (f32, Vec2) {
        self.value_mut("Sampler::get_1d_2d", (0.5, Vec2::splat(0.5)), |s| {
            s.get_1d_2d()
        })
    }
    fn get_pixel_2d(&mut self) -> Vec2 {
        self.value_mut("Sampler::get_pixel_2d", Vec2::splat(0.5), |s| {
            s.get_pixel_2d()
        })
    }
    fn clone_sampler(&self) -> Box<dyn Sampler> {
        // A clone that panicked is replaced by this sampler's own clone
        // under the same guard; the fault is recorded either way.
        let clone = self.guard.call(&self.label, "Sampler::clone_sampler", || {
            self.inner.clone_sampler()
        });
        match clone {
            Ok(inner) => Box::new(Guarded::new(inner, self.guard.clone(), self.label.clone())),
            Err(_) => Box::new(FaultedSampler(self.samples_per_pixel())),
        }
    }
}

/// What a sampler whose clone panicked draws: the centre of every
/// dimension, until the host stops at the recorded fault.
struct FaultedSampler(u32);

impl Sampler for FaultedSampler {
    fn samples_per_pixel(&self) -> u32 {
        self.0
    }
    fn start_pixel_sample(&mut self, _: UVec2, _: u32, _: u64) {}
    fn get_1d(&mut self) -> f32 {
        0.5
    }
    fn get_2d(&mut self) -> Vec2 {
        Vec2::splat(0.5)
    }
    fn get_pixel_2d(&mut self) -> Vec2 {
        Vec2::splat(0.5)
    }
    fn clone_sampler(&self) -> Box<dyn Sampler> {
        Box::new(FaultedSampler(self.0))
    }
}

/// A panicking denoiser is an error: the host still has the raw render.
impl Denoiser for Guarded<Box<dyn Denoiser>> {
    fn denoise(&self, input: &DenoiseInput<'_>) -> Result<Vec<[f32; 3]>> {
        self.guard.call(&self.label, "Denoiser::denoise", || {
            self.inner.denoise(input)
        })?
    }
}

impl Integrator for Guarded<Box<dyn Integrator>> {
    fn li(
        &self,
        ray: &Ray,
        scene: &dyn Scene,
        sampler: &mut dyn Sampler,
        stats: &mut RenderStats,
    ) -> Rgb {
        self.value("Integrator::li", Rgb::BLACK, |i| {
            i.li(ray, scene, sampler, stats)
        })
    }
    fn batch_size(&self) -> usize {
        self.value("Integrator::batch_size", 1, |i| i.batch_size())
            .max(1)
    }
    fn li_batch(
        &self,
        rays: &[Ray],
        scene: &dyn Scene,
        samplers: &mut dyn SamplerLanes,
        stats: &mut RenderStats,
        out: &mut [Rgb],
    ) {
        let out_of_call = &mut *out;
        let done = self.value("Integrator::li_batch", false, |i| {
            i.li_batch(rays, scene, samplers, stats, out_of_call);
            true
        });
        if !done {
            out.fill(Rgb::BLACK);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        let guarded = Guarded::new(bsdf, guard, Arc::from("bsdf 'faulty' (sigma = 0.65)"));
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
        let guarded = Guarded::new(denoiser, guard, Arc::from("denoiser (type = \"x\")"));
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
