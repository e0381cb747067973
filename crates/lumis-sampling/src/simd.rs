//! The instruction set the SIMD kernels run with, chosen once per process
//! from the running CPU, as ISPC's multi-target builds (which OSPRay and
//! Embree ship) pick their SSE, AVX2 or AVX-512 code at start-up.
//!
//! A kernel passed to [`dispatch`] is compiled once per [`Isa`] and runs
//! with the chosen one, so one binary stays portable across x86-64
//! machines and still uses the wider registers where the CPU has them.
//! Every [`Isa`] executes the same IEEE operations in the same order (Rust
//! never fuses a multiply and an add behind the program's back), so the
//! choice changes the speed and never a bit of the image.
//!
//! What the wider sets change is the encoding: three-operand VEX and EVEX
//! forms instead of SSE's two-operand ones. The registers stay four lanes
//! wide, because `wide` fixes the layout of [`crate::real::F32x8`] (two
//! SSE2 halves) when it is compiled, not when it runs; the book's
//! performance chapter measures what each choice buys. The packet width
//! stays eight lanes whatever the instruction set: it is part of the
//! plugin interface (`lumis_api::lanes::LANES`).

use std::fmt;
use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction set the kernels are compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// What every CPU of the build's target runs: SSE2 on x86-64, the
    /// target's own baseline elsewhere.
    Baseline,
    /// AVX2 with FMA (x86-64-v3): 8 f32 per register.
    Avx2,
    /// AVX-512 F, BW, DQ and VL (x86-64-v4): 16 f32 per register.
    Avx512,
}

impl Isa {
    /// Every instruction set this build has kernels for, narrowest first.
    pub const BUILT: &'static [Isa] = if cfg!(target_arch = "x86_64") {
        &[Isa::Baseline, Isa::Avx2, Isa::Avx512]
    } else {
        &[Isa::Baseline]
    };

    /// The name `LUMIS_SIMD` takes and the start-up report prints.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline if cfg!(target_arch = "x86_64") => "sse2",
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// The CPU features the kernels are compiled with.
    pub fn features(self) -> &'static str {
        match self {
            Isa::Baseline if cfg!(target_arch = "x86_64") => "the x86-64 baseline",
            Isa::Baseline => "the target's baseline",
            Isa::Avx2 => "AVX2 and FMA",
            Isa::Avx512 => "AVX-512 F, BW, DQ and VL",
        }
    }

    /// Whether the running CPU executes this instruction set.
    pub fn is_supported(self) -> bool {
        match self {
            Isa::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                Isa::Avx2.is_supported()
                    && std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("avx512bw")
                    && std::arch::is_x86_feature_detected!("avx512dq")
                    && std::arch::is_x86_feature_detected!("avx512vl")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// The widest instruction set built that the running CPU executes.
    pub fn best_supported() -> Isa {
        Isa::BUILT
            .iter()
            .copied()
            .rfind(|isa| isa.is_supported())
            .unwrap_or(Isa::Baseline)
    }

    /// The instruction set named `name`, if this CPU runs it.
    pub fn parse(name: &str) -> Result<Isa, String> {
        let built = || {
            let names: Vec<_> = Isa::BUILT.iter().map(|isa| isa.name()).collect();
            names.join(", ")
        };
        let isa = Isa::BUILT
            .iter()
            .copied()
            .find(|isa| isa.name().eq_ignore_ascii_case(name.trim()))
            .ok_or_else(|| {
                format!(
                    "'{name}' is not an instruction set; expected one of {}",
                    built()
                )
            })?;
        if !isa.is_supported() {
            return Err(format!(
                "this CPU does not run '{}'; it runs {}",
                isa.name(),
                Isa::BUILT
                    .iter()
                    .filter(|isa| isa.is_supported())
                    .map(|isa| isa.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
        Ok(isa)
    }

    fn from_code(code: u8) -> Option<Isa> {
        Isa::BUILT
            .iter()
            .copied()
            .find(|isa| *isa as u8 + 1 == code)
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.name(), self.features())
    }
}

/// The chosen [`Isa`] as `isa as u8 + 1`; 0 until the first [`chosen`].
static CHOSEN: AtomicU8 = AtomicU8::new(0);

/// The environment variable that overrides the choice
/// ([`choose_from_env`]).
pub const ENV: &str = "LUMIS_SIMD";

/// The instruction set [`dispatch`] runs kernels with: the one set by
/// [`choose`], else the one [`ENV`] names, else the widest the CPU runs.
///
/// A plugin library holds its own copy of this choice; it reads the same
/// [`ENV`], which the host has checked at start-up
/// ([`choose_from_env`]), so the host and its plugins agree.
pub fn chosen() -> Isa {
    if let Some(isa) = Isa::from_code(CHOSEN.load(Ordering::Relaxed)) {
        return isa;
    }
    let from_env = std::env::var(ENV)
        .ok()
        .and_then(|name| Isa::parse(&name).ok());
    let isa = from_env.unwrap_or_else(Isa::best_supported);
    CHOSEN.store(isa as u8 + 1, Ordering::Relaxed);
    isa
}

/// Runs later kernels with `isa`, which the CPU must run ([`Isa::parse`]
/// checks). Any choice gives the same results; this only changes speed.
pub fn choose(isa: Isa) {
    assert!(isa.is_supported(), "{} is not supported here", isa.name());
    CHOSEN.store(isa as u8 + 1, Ordering::Relaxed);
}

/// Applies [`ENV`] when it is set: an error names the variable, its value
/// and what it may be.
pub fn choose_from_env() -> Result<Isa, String> {
    match std::env::var(ENV) {
        Ok(name) => {
            let isa = Isa::parse(&name).map_err(|why| format!("{ENV}={name}: {why}"))?;
            choose(isa);
            Ok(isa)
        }
        Err(std::env::VarError::NotPresent) => Ok(chosen()),
        Err(std::env::VarError::NotUnicode(_)) => Err(format!(
            "{ENV} is not valid Unicode; expected one of the instruction set names"
        )),
    }
}

/// Runs `kernel` compiled for the [`chosen`] instruction set.
///
/// `kernel` and what it inlines (the [`crate::real::Real`] operations, the
/// lane arithmetic of `wide`) are compiled into each instruction set's
/// copy; functions it calls without inlining run as built.
#[inline(always)]
pub fn dispatch<R>(kernel: impl FnOnce() -> R) -> R {
    match chosen() {
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => x86::avx512(kernel),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => x86::avx2(kernel),
        _ => kernel(),
    }
}

#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
mod x86 {
    use super::Isa;

    #[inline(always)]
    pub fn avx2<R>(kernel: impl FnOnce() -> R) -> R {
        debug_assert!(Isa::Avx2.is_supported());
        // SAFETY: `chosen` returns `Avx2` only where `Isa::is_supported`
        // found AVX2 and FMA on this CPU.
        unsafe { with_avx2(kernel) }
    }

    #[inline(always)]
    pub fn avx512<R>(kernel: impl FnOnce() -> R) -> R {
        debug_assert!(Isa::Avx512.is_supported());
        // SAFETY: `chosen` returns `Avx512` only where `Isa::is_supported`
        // found AVX2, FMA and AVX-512 F, BW, DQ and VL on this CPU.
        unsafe { with_avx512(kernel) }
    }

    #[target_feature(enable = "avx2,fma")]
    fn with_avx2<R>(kernel: impl FnOnce() -> R) -> R {
        kernel()
    }

    #[target_feature(enable = "avx2,fma,avx512f,avx512bw,avx512dq,avx512vl")]
    fn with_avx512<R>(kernel: impl FnOnce() -> R) -> R {
        kernel()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::real::{F32x8, Real};

    #[test]
    fn names_parse_back_and_unknown_ones_are_refused() {
        for &isa in Isa::BUILT.iter().filter(|isa| isa.is_supported()) {
            assert_eq!(Isa::parse(isa.name()), Ok(isa));
        }
        let err = Isa::parse("mmx").unwrap_err();
        assert!(
            err.contains("'mmx'") && err.contains(Isa::Baseline.name()),
            "{err}"
        );
        assert!(Isa::best_supported().is_supported());
    }

    /// A kernel of lane arithmetic gives the same bits under every
    /// instruction set the CPU runs.
    #[test]
    fn every_instruction_set_computes_the_same_bits() {
        let kernel = || {
            let x = F32x8::from_fn(|i| 0.1 + i as f32 * 0.37);
            let y = (x * x + F32x8::splat(1.0)).sqrt() / (x - F32x8::splat(3.0));
            crate::special::erf(y).to_array()
        };
        let reference = kernel();
        for &isa in Isa::BUILT.iter().filter(|isa| isa.is_supported()) {
            choose(isa);
            assert_eq!(chosen(), isa);
            let got = dispatch(kernel);
            assert_eq!(got.map(f32::to_bits), reference.map(f32::to_bits), "{isa}");
        }
        choose(Isa::best_supported());
    }
}
