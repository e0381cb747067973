//! One forwarding rule for everything that wraps a plugin object.
//!
//! A wrapper (the panic guard around a loaded plugin, which also audits
//! its answers, and the profiler's stages) must forward every method of its
//! trait, the declarations with a default included: a wrapper that names
//! only some of them lets the trait's defaults answer for the rest, and a
//! loaded plugin then behaves unlike the same plugin linked in. So no
//! wrapper is written by hand. Each plugin trait is declared with
//! [`plugin_interface`](crate::plugin_interface), which implements it for
//! [`Wrapped<C, H>`] by running each method of the wrapped object through
//! a [`CallHook`]; a wrapper is a hook.

use std::ops::{Deref, DerefMut};

use glam::{Vec2, Vec3};

use crate::audit::Answer;
use crate::bsdf::BsdfFlags;
use crate::error::Error;
use crate::spectrum::Rgb;

/// What a wrapper does around each call of the wrapped object's methods.
pub trait CallHook: Send + Sync + Sized + 'static {
    /// Runs `call`, one call of the method `method` (`"Bsdf::f"`), or
    /// answers with the fault that kept it from completing.
    fn call<T: Answer>(&self, method: &'static str, call: impl FnOnce() -> T) -> Result<T, Fault>;

    /// What a batched method wrote into its `out` lanes, after the call
    /// completed: each lane is an answer too.
    #[inline]
    fn seen<A: Answer + ?Sized>(&self, _out: &A) {}

    /// The hook for a plugin object the wrapped one made (a sampler's
    /// clone, its lanes): wrapped the same way, with state of its own.
    fn child(&self) -> Self;
}

/// A plugin object `C` (`Arc<dyn Bsdf>`, `Box<dyn Sampler>`) whose every
/// call goes through the hook `H`.
pub struct Wrapped<C, H> {
    inner: C,
    hook: H,
}

impl<C, H> Wrapped<C, H> {
    pub fn new(inner: C, hook: H) -> Self {
        Self { inner, hook }
    }
}

impl<C: Deref, H> Wrapped<C, H> {
    /// The wrapped object and the hook, borrowed apart.
    #[inline]
    pub fn parts(&self) -> (&C::Target, &H) {
        (&*self.inner, &self.hook)
    }
}

impl<C: DerefMut, H> Wrapped<C, H> {
    /// The wrapped object, mutably, and the hook.
    #[inline]
    pub fn parts_mut(&mut self) -> (&mut C::Target, &H) {
        (&mut *self.inner, &self.hook)
    }
}

/// Why a wrapped call did not complete.
#[derive(Debug, Clone)]
pub enum Fault {
    /// It panicked; the error names the plugin, its library and the method.
    Panicked(Error),
    /// The plugin panicked in an earlier call and is not called again.
    Tripped,
}

impl Fault {
    /// The fault as an error, for methods that return a `Result`.
    pub fn into_error(self) -> Error {
        match self {
            Fault::Panicked(error) => error,
            Fault::Tripped => Error::msg("the plugin panicked in an earlier call"),
        }
    }
}

/// The answer of a call that faulted: no sample, zero radiance, zero
/// density. The host stops at its next check of the faults, so the value
/// only has to be harmless until then.
pub trait Neutral {
    fn neutral() -> Self;
}

macro_rules! neutral {
    ($($ty:ty => $value:expr),* $(,)?) => {
        $(impl Neutral for $ty {
            #[inline]
            fn neutral() -> Self {
                $value
            }
        })*
    };
}

neutral! {
    () => (),
    bool => false,
    f32 => 0.0,
    u32 => 0,
    usize => 0,
    Rgb => Rgb::BLACK,
    Vec2 => Vec2::ZERO,
    Vec3 => Vec3::ZERO,
    BsdfFlags => BsdfFlags::NONE,
}

impl<T> Neutral for Option<T> {
    #[inline]
    fn neutral() -> Self {
        None
    }
}

impl<T> Neutral for &[T] {
    #[inline]
    fn neutral() -> Self {
        &[]
    }
}

impl<A: Neutral, B: Neutral> Neutral for (A, B) {
    #[inline]
    fn neutral() -> Self {
        (A::neutral(), B::neutral())
    }
}
