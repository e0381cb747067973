//! The BSDF plugin interface (pbrt-v4 `BxDF`), in the local shading frame.

use glam::{Vec2, Vec3};
use lumis_derive::plugin_interface;

use crate::lanes::{Floats, LaneMask, RgbLanes, Vec2Lanes, Vec3Lanes, LANES};
use crate::spectrum::Rgb;
use crate::texture::TextureQuery;

/// Which quantity is transported; refraction scales radiance by 1/eta^2 but
/// not importance (Veach 1997, section 5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TransportMode {
    #[default]
    Radiance,
    Importance,
}

/// Per-hit information a BSDF may read, so evaluation needs no allocation.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BsdfContext {
    /// Where the hit's textured parameters are looked up (its uv and, with
    /// ray differentials, its footprint).
    pub texture: TextureQuery,
    pub mode: TransportMode,
}

/// Lobe classification: what a BSDF (or one sample of it) is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct BsdfFlags(u8);

impl BsdfFlags {
    pub const NONE: Self = Self(0);
    pub const REFLECTION: Self = Self(1);
    pub const TRANSMISSION: Self = Self(1 << 1);
    pub const DIFFUSE: Self = Self(1 << 2);
    pub const GLOSSY: Self = Self(1 << 3);
    /// A Dirac delta lobe: `f` and `pdf` are zero for every direction, only
    /// `sample_f` can produce it and MIS must not weight it.
    pub const SPECULAR: Self = Self(1 << 4);
    pub const DIFFUSE_REFLECTION: Self = Self(Self::DIFFUSE.0 | Self::REFLECTION.0);

    #[inline]
    pub const fn union(self, o: Self) -> Self {
        Self(self.0 | o.0)
    }

    #[inline]
    pub const fn contains(self, o: Self) -> bool {
        self.0 & o.0 == o.0
    }

    #[inline]
    pub const fn is_specular(self) -> bool {
        self.0 & Self::SPECULAR.0 != 0
    }

    /// Whether any lobe has a finite density, i.e. can be evaluated with `f`.
    #[inline]
    pub const fn is_non_specular(self) -> bool {
        self.0 & (Self::DIFFUSE.0 | Self::GLOSSY.0) != 0
    }
}

impl std::ops::BitOr for BsdfFlags {
    type Output = Self;
    fn bitor(self, o: Self) -> Self {
        self.union(o)
    }
}

/// A sampled direction with the BSDF value and density for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// `f(wo, wi)`, without the cosine.
    pub f: Rgb,
    /// Sampled incident direction, local frame, unit length.
    pub wi: Vec3,
    /// Density w.r.t. solid angle (for specular samples: the discrete probability).
    pub pdf: f32,
    pub flags: BsdfFlags,
    /// Relative index of refraction along `wi` (1 for reflection).
    pub eta: f32,
}

impl BsdfSample {
    /// The sample of a non-delta reflection lobe at `wi`, with the density
    /// and value that the BSDF's own `pdf` and `f` give there, so that
    /// `sample_f` agrees with them to the last bit; `None` below the
    /// horizon or where the density is not positive and finite, since such
    /// a sample could not be weighted.
    #[inline]
    pub fn reflection(
        wi: Vec3,
        flags: BsdfFlags,
        pdf: impl FnOnce(Vec3) -> f32,
        f: impl FnOnce(Vec3) -> Rgb,
    ) -> Option<Self> {
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = pdf(wi);
        if !(pdf > 0.0 && pdf.is_finite()) {
            return None;
        }
        Some(Self {
            f: f(wi),
            wi,
            pdf,
            flags,
            eta: 1.0,
        })
    }
}

/// What `Bsdf::sample_f_lanes` answers: lane `i` holds a sample where
/// `valid` holds lane `i`, as `sample_f` answers `Some`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BsdfSampleLanes {
    pub f: RgbLanes,
    pub wi: Vec3Lanes,
    pub pdf: Floats,
    pub eta: Floats,
    pub flags: [BsdfFlags; LANES],
    pub valid: LaneMask,
}

impl BsdfSampleLanes {
    /// Lane `i`'s sample.
    #[inline]
    pub fn get(&self, i: usize) -> Option<BsdfSample> {
        self.valid.contains(i).then(|| BsdfSample {
            f: self.f.get(i),
            wi: self.wi.get(i),
            pdf: self.pdf[i],
            flags: self.flags[i],
            eta: self.eta[i],
        })
    }

    /// No sample in the lanes of `lanes`: the answer of a call that
    /// faulted, the other lanes left as they are.
    #[inline]
    pub fn set_neutral(&mut self, lanes: LaneMask) {
        self.valid = self.valid & !lanes;
    }

    /// Sets lane `i` to `sample`.
    #[inline]
    pub fn set(&mut self, i: usize, sample: Option<BsdfSample>) {
        self.valid.set(i, sample.is_some());
        if let Some(s) = sample {
            self.f.set(i, s.f);
            self.wi.set(i, s.wi);
            self.pdf[i] = s.pdf;
            self.flags[i] = s.flags;
            self.eta[i] = s.eta;
        }
    }
}

/// What `Bsdf::eval_lanes` answers: the value and the density of lane
/// `i`'s direction pair, for the lanes in `valid` (every lane asked).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BsdfEvalLanes {
    pub f: RgbLanes,
    pub pdf: Floats,
    pub valid: LaneMask,
}

impl BsdfEvalLanes {
    #[inline]
    pub fn get(&self, i: usize) -> (Rgb, f32) {
        (self.f.get(i), self.pdf[i])
    }

    /// Zero value and density in the lanes of `lanes`: the answer of a
    /// call that faulted, the other lanes left as they are.
    #[inline]
    pub fn set_neutral(&mut self, lanes: LaneMask) {
        for i in lanes.iter() {
            self.set(i, (Rgb::BLACK, 0.0));
        }
    }

    #[inline]
    pub fn set(&mut self, i: usize, (f, pdf): (Rgb, f32)) {
        self.valid.set(i, true);
        self.f.set(i, f);
        self.pdf[i] = pdf;
    }
}

/// A BSDF in its local shading frame (`z` = shading normal).
///
/// Directions point away from the surface. `f` excludes the cosine factor;
/// `pdf` is a density w.r.t. solid angle and must describe exactly the
/// distribution `sample_f` draws from (the chi-square tests check this).
#[plugin_interface]
pub trait Bsdf: Send + Sync {
    fn flags(&self) -> BsdfFlags;

    fn f(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> Rgb;

    /// Samples `wi` given `wo`. `u1` picks a lobe, `u2` the direction.
    fn sample_f(&self, ctx: &BsdfContext, wo: Vec3, u1: f32, u2: Vec2) -> Option<BsdfSample>;

    fn pdf(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> f32;

    /// `(f, pdf)` of one pair of directions in one call (Mitsuba 3's
    /// `eval_pdf`): light sampling needs both, and a model that overrides
    /// this shares their work (orientation tests, half vector, `D`). Must
    /// return exactly what `f` and `pdf` return; the check kit compares.
    #[inline]
    fn eval(&self, ctx: &BsdfContext, wo: Vec3, wi: Vec3) -> (Rgb, f32) {
        (self.f(ctx, wo, wi), self.pdf(ctx, wo, wi))
    }

    /// Whether the model reads directions against the surface's texture
    /// tangents (an anisotropic lobe, a normal map). Its hits then get the
    /// frame of [`crate::Frame::from_tangents`], `x` along `dp/du` and `y`
    /// toward the image's up, which costs a little per hit; otherwise the
    /// frame turns about the normal arbitrarily.
    fn uses_tangent_frame(&self) -> bool {
        false
    }

    /// [`Bsdf::sample_f`] for each lane `i` of a batch: `out[i]` is
    /// `sample_f(&ctx[i], wo[i], u1[i], u2[i])`. The wavefront integrator
    /// calls it once per material and wave. The default loops over
    /// `sample_f`; an override computes the lanes together (SIMD) and must
    /// return what `sample_f` returns up to rounding (the check kit
    /// compares). All slices have the length of `out`.
    #[on_fault(out.fill(None))]
    fn sample_f_batch(
        &self,
        ctx: &[BsdfContext],
        wo: &[Vec3],
        u1: &[f32],
        u2: &[Vec2],
        out: &mut [Option<BsdfSample>],
    ) {
        sample_f_each(self, ctx, wo, u1, u2, out)
    }

    /// [`Bsdf::eval`] for each lane of a batch: `out[i]` is
    /// `eval(&ctx[i], wo[i], wi[i])`. Same contract as
    /// [`Bsdf::sample_f_batch`].
    #[on_fault(out.fill((Rgb::BLACK, 0.0)))]
    fn eval_batch(&self, ctx: &[BsdfContext], wo: &[Vec3], wi: &[Vec3], out: &mut [(Rgb, f32)]) {
        eval_each(self, ctx, wo, wi, out)
    }

    /// [`Bsdf::sample_f`] for the lanes of `active` of a packet: lane `i`
    /// with `ctx[i]`, `wo` lane `i`, `u1[i]` and `u2` lane `i`, its sample
    /// into lane `i` of `out` and its bit of `out.valid` (set where it has
    /// one); the lanes outside `active` are left as they are, so that the
    /// calls for the packet's other BSDFs fill the same `out`. A packet
    /// integrator calls it with the lanes whose hit has this BSDF.
    /// The default loops over `sample_f`; a plugin overrides it to compute
    /// the lanes with SIMD, giving `sample_f`'s answer (`lumis
    /// check-plugin` compares the two).
    #[on_fault(out.set_neutral(active))]
    fn sample_f_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        u1: &Floats,
        u2: &Vec2Lanes,
        active: LaneMask,
        out: &mut BsdfSampleLanes,
    ) {
        sample_f_each_lane(self, ctx, wo, u1, u2, active, out)
    }

    /// [`Bsdf::eval`] for the lanes of `active` of a packet, as
    /// [`Bsdf::sample_f_lanes`] is `sample_f`: it sets the bits of
    /// `active` in `out.valid`, and leaves the other lanes as they are.
    #[on_fault(out.set_neutral(active))]
    fn eval_lanes(
        &self,
        ctx: &[BsdfContext; LANES],
        wo: &Vec3Lanes,
        wi: &Vec3Lanes,
        active: LaneMask,
        out: &mut BsdfEvalLanes,
    ) {
        eval_each_lane(self, ctx, wo, wi, active, out)
    }
}

/// [`Bsdf::sample_f_batch`] lane by lane through `sample_f`: the trait's
/// default, and an override's answer for the settings it has no SIMD
/// code for.
pub fn sample_f_each<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext],
    wo: &[Vec3],
    u1: &[f32],
    u2: &[Vec2],
    out: &mut [Option<BsdfSample>],
) {
    for (i, out) in out.iter_mut().enumerate() {
        *out = bsdf.sample_f(&ctx[i], wo[i], u1[i], u2[i]);
    }
}

/// [`Bsdf::eval_batch`] lane by lane through `eval`, as [`sample_f_each`].
pub fn eval_each<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext],
    wo: &[Vec3],
    wi: &[Vec3],
    out: &mut [(Rgb, f32)],
) {
    for (i, out) in out.iter_mut().enumerate() {
        *out = bsdf.eval(&ctx[i], wo[i], wi[i]);
    }
}

/// [`Bsdf::sample_f_lanes`] lane by lane through `sample_f`: the trait's
/// default, and an override's answer for the settings it has no SIMD
/// code for.
pub fn sample_f_each_lane<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext; LANES],
    wo: &Vec3Lanes,
    u1: &Floats,
    u2: &Vec2Lanes,
    active: LaneMask,
    out: &mut BsdfSampleLanes,
) {
    for i in active.iter() {
        out.set(i, bsdf.sample_f(&ctx[i], wo.get(i), u1[i], u2.get(i)));
    }
}

/// [`Bsdf::eval_lanes`] lane by lane through `eval`, as
/// [`sample_f_each_lane`].
pub fn eval_each_lane<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext; LANES],
    wo: &Vec3Lanes,
    wi: &Vec3Lanes,
    active: LaneMask,
    out: &mut BsdfEvalLanes,
) {
    for i in active.iter() {
        out.set(i, bsdf.eval(&ctx[i], wo.get(i), wi.get(i)));
    }
}

/// Answers [`Bsdf::sample_f_lanes`] through `bsdf`'s
/// [`Bsdf::sample_f_batch`], for a plugin whose SIMD code reads its lanes
/// from slices: the lanes of `active` gathered in order, and each answer
/// put back in its lane.
pub fn sample_f_lanes_by_batch<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext; LANES],
    wo: &Vec3Lanes,
    u1: &Floats,
    u2: &Vec2Lanes,
    active: LaneMask,
    out: &mut BsdfSampleLanes,
) {
    let n = active.count() as usize;
    let mut args = ([BsdfContext::default(); LANES], [Vec3::ZERO; LANES]);
    let mut u = ([0.0; LANES], [Vec2::ZERO; LANES]);
    for (k, i) in active.iter().enumerate() {
        (args.0[k], args.1[k], u.0[k], u.1[k]) = (ctx[i], wo.get(i), u1[i], u2.get(i));
    }
    let mut samples = [None; LANES];
    bsdf.sample_f_batch(
        &args.0[..n],
        &args.1[..n],
        &u.0[..n],
        &u.1[..n],
        &mut samples[..n],
    );
    for (k, i) in active.iter().enumerate() {
        out.set(i, samples[k]);
    }
}

/// Answers [`Bsdf::eval_lanes`] through `bsdf`'s [`Bsdf::eval_batch`], as
/// [`sample_f_lanes_by_batch`] does.
pub fn eval_lanes_by_batch<B: Bsdf + ?Sized>(
    bsdf: &B,
    ctx: &[BsdfContext; LANES],
    wo: &Vec3Lanes,
    wi: &Vec3Lanes,
    active: LaneMask,
    out: &mut BsdfEvalLanes,
) {
    let n = active.count() as usize;
    let mut args = (
        [BsdfContext::default(); LANES],
        [Vec3::ZERO; LANES],
        [Vec3::ZERO; LANES],
    );
    for (k, i) in active.iter().enumerate() {
        (args.0[k], args.1[k], args.2[k]) = (ctx[i], wo.get(i), wi.get(i));
    }
    let mut evals = [(Rgb::BLACK, 0.0); LANES];
    bsdf.eval_batch(&args.0[..n], &args.1[..n], &args.2[..n], &mut evals[..n]);
    for (k, i) in active.iter().enumerate() {
        out.set(i, evals[k]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lane_holds_what_was_set() {
        let s = BsdfSample {
            f: Rgb::new(0.1, 0.2, 0.3),
            wi: Vec3::new(0.0, 0.6, 0.8),
            pdf: 0.5,
            flags: BsdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
        };
        let mut lanes = BsdfSampleLanes::default();
        lanes.set(3, Some(s));
        assert_eq!(lanes.get(3), Some(s));
        assert_eq!(lanes.get(2), None);
        lanes.set(3, None);
        assert_eq!(lanes.get(3), None);
    }
}
