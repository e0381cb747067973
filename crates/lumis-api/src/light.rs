//! The light plugin interface.

use glam::{Vec2, Vec3};
use lumis_derive::plugin_interface;

use crate::interaction::LightSampleContext;
use crate::lanes::{Floats, LaneMask, RgbLanes, Vec2Lanes, Vec3Lanes, LANES};
use crate::light_bounds::LightBounds;
use crate::ray::SurfacePoint;
use crate::spectrum::Rgb;

/// How a light must be treated by integrators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightKind {
    /// A single point: sampled only, never hit; MIS weight 1.
    DeltaPosition,
    /// Emission from a surface that BSDF rays can hit.
    Area,
    /// Radiance arriving from infinitely far away, seen by escaping rays.
    Infinite,
}

/// A light sample toward the reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Radiance arriving at the reference point along `-wi` (unoccluded).
    pub l: Rgb,
    /// Unit direction from the reference point toward the light.
    pub wi: Vec3,
    /// Density w.r.t. solid angle at the reference point (1 for delta lights).
    pub pdf: f32,
    /// The sampled point on the light, for the shadow ray.
    pub p: SurfacePoint,
}

/// A ray of emitted light ([`Light::sample_le`]), where a path traced
/// from the lights starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmissionSample {
    /// The ray's origin, with its error bound and the light's normal there
    /// (zero for a point light; the ray's direction on the disk an
    /// infinite light shines through).
    pub p: SurfacePoint,
    /// Unit direction of the emitted light.
    pub d: Vec3,
    /// Radiance along the ray (intensity, W/sr, for a point light).
    pub l: Rgb,
    /// Density of the origin w.r.t. area (1 for a point light).
    pub pdf_pos: f32,
    /// Density of the direction w.r.t. solid angle.
    pub pdf_dir: f32,
}

impl EmissionSample {
    /// The power the ray carries: `L |cos theta| / (pdf_pos pdf_dir)`, with
    /// the cosine at the origin's normal (1 for a point light), as the
    /// weight of a path from the light (pbrt-v4 `LightTracer`).
    pub fn beta(&self) -> Rgb {
        let cos = if self.p.n == Vec3::ZERO {
            1.0
        } else {
            self.p.n.dot(self.d).abs()
        };
        self.l * (cos / (self.pdf_pos * self.pdf_dir))
    }
}

/// The geometry an area light is attached to, handed to its factory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightShape {
    /// Not attached to geometry (`[[light]]` tables: point lights, environments).
    None,
    /// A parallelogram `corner + s edge_u + t edge_v`, `s, t` in `[0, 1]`;
    /// its front side faces `normalize(edge_u x edge_v)`.
    Quad {
        corner: Vec3,
        edge_u: Vec3,
        edge_v: Vec3,
    },
    /// A triangle; the front side faces `normalize((p1 - p0) x (p2 - p0))`.
    /// `uv` are its vertices' texture coordinates, which a textured
    /// radiance is looked up by ([`LightShape::BARYCENTRIC_UVS`] where the
    /// mesh has none, as its hits see them).
    Triangle { p: [Vec3; 3], uv: [Vec2; 3] },
    /// A sphere; the front side faces outward unless `inward`.
    Sphere {
        center: Vec3,
        radius: f32,
        inward: bool,
    },
}

impl LightShape {
    /// The texture coordinates of a triangle's vertices where its mesh has
    /// none: the barycentric coordinates `(b1, b2)` of each point.
    pub const BARYCENTRIC_UVS: [Vec2; 3] = [Vec2::ZERO, Vec2::X, Vec2::Y];
}

/// What a light is made with: the geometry it is attached to, and the
/// scene's textures, which its parameters may name (a textured radiance).
#[derive(Clone, Copy)]
pub struct LightInput<'a> {
    pub shape: &'a LightShape,
    pub textures: &'a crate::texture::Textures,
}

impl<'a> LightInput<'a> {
    /// A light on `shape` that can name no texture (made outside a scene).
    pub fn untextured(shape: &'a LightShape) -> Self {
        Self {
            shape,
            textures: &crate::texture::NO_TEXTURES,
        }
    }
}

/// What `Light::sample_li_lanes` answers: lane `i` holds a sample where
/// `valid` holds lane `i`, as `sample_li` answers `Some`. The sampled
/// points stay whole: each spawns its lane's shadow ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSampleLanes {
    pub l: RgbLanes,
    pub wi: Vec3Lanes,
    pub pdf: Floats,
    pub p: [SurfacePoint; LANES],
    pub valid: LaneMask,
}

impl Default for LightSampleLanes {
    fn default() -> Self {
        Self {
            l: RgbLanes::default(),
            wi: Vec3Lanes::default(),
            pdf: [0.0; LANES],
            p: [SurfacePoint::isolated(Vec3::ZERO); LANES],
            valid: LaneMask::NONE,
        }
    }
}

impl LightSampleLanes {
    #[inline]
    pub fn get(&self, i: usize) -> Option<LightSample> {
        self.valid.contains(i).then(|| LightSample {
            l: self.l.get(i),
            wi: self.wi.get(i),
            pdf: self.pdf[i],
            p: self.p[i],
        })
    }

    /// No sample in the lanes of `lanes`: the answer of a call that
    /// faulted, the other lanes left as they are.
    #[inline]
    pub fn set_neutral(&mut self, lanes: LaneMask) {
        self.valid = self.valid & !lanes;
    }

    #[inline]
    pub fn set(&mut self, i: usize, sample: Option<LightSample>) {
        self.valid.set(i, sample.is_some());
        if let Some(s) = sample {
            self.l.set(i, s.l);
            self.wi.set(i, s.wi);
            self.pdf[i] = s.pdf;
            self.p[i] = s.p;
        }
    }
}

/// A light source. Each shape brings its own sampling and density.
#[plugin_interface]
pub trait Light: Send + Sync {
    #[on_fault(LightKind::Area)]
    fn kind(&self) -> LightKind;

    /// Samples a direction toward the light from `ctx`.
    fn sample_li(&self, ctx: &LightSampleContext, u: Vec2) -> Option<LightSample>;

    /// [`Light::sample_li`] for each lane of a batch: `out[i]` is
    /// `sample_li(&ctx[i], u[i])`. The default loops; an override (SIMD)
    /// must return what `sample_li` returns up to rounding.
    #[on_fault(out.fill(None))]
    fn sample_li_batch(
        &self,
        ctx: &[LightSampleContext],
        u: &[Vec2],
        out: &mut [Option<LightSample>],
    ) {
        sample_li_each(self, ctx, u, out)
    }

    /// [`Light::sample_li`] for the lanes of `active` of a packet: lane `i`
    /// from `ctx[i]` with `u` lane `i`, its sample into lane `i` of `out`
    /// and its bit of `out.valid` (set where it has one); the lanes outside
    /// `active` are left as they are. The default loops over
    /// `sample_li`; a plugin overrides it to compute the lanes with SIMD,
    /// giving `sample_li`'s answer.
    #[on_fault(out.set_neutral(active))]
    fn sample_li_lanes(
        &self,
        ctx: &[LightSampleContext; LANES],
        u: &Vec2Lanes,
        active: LaneMask,
        out: &mut LightSampleLanes,
    ) {
        sample_li_each_lane(self, ctx, u, active, out)
    }

    /// A ray of light leaving the light, for paths traced from the lights
    /// (pbrt-v4 `Light::SampleLe`): its origin from `u_pos`, its direction
    /// from `u_dir`. `None` where `u` gives no ray (zero emission there).
    /// A light that cannot start such paths keeps the default, `None`
    /// always, and integrators that trace from the lights refuse a scene
    /// holding it.
    #[on_fault(None)]
    fn sample_le(&self, u_pos: Vec2, u_dir: Vec2) -> Option<EmissionSample> {
        let _ = (u_pos, u_dir);
        None
    }

    /// Density w.r.t. solid angle with which `sample_li` from `ctx` returns
    /// the direction `wi`; zero for delta lights.
    fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> f32;

    /// Emitted radiance leaving the light's surface at `p` (normal `n`) in
    /// direction `w`; for infinite lights, radiance arriving along `-w`.
    fn l(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb;

    /// Total emitted power (flux), for power-proportional light selection.
    fn power(&self) -> Rgb;

    /// Where the light is and which way it emits, for light samplers that
    /// weigh lights by their place (`bvh`). `None` (infinite lights, and
    /// the default) leaves the light out of the tree: it is then picked
    /// alongside, as an environment is, without regard to position.
    fn bounds(&self) -> Option<LightBounds> {
        None
    }

    /// Bytes the light holds (an environment map's image and sampling
    /// tables), added to the memory a render reports and checks before it
    /// starts; 0, the default, for a light of a few numbers.
    fn memory_bytes(&self) -> usize {
        0
    }

    /// Lets infinite lights learn the scene's bounding sphere after loading.
    fn preprocess(&mut self, _scene_center: Vec3, _scene_radius: f32) {}
}

/// [`Light::sample_li_batch`] lane by lane through `sample_li`: the
/// trait's default, and an override's answer for the settings it has no
/// SIMD code for.
pub fn sample_li_each<L: Light + ?Sized>(
    light: &L,
    ctx: &[LightSampleContext],
    u: &[Vec2],
    out: &mut [Option<LightSample>],
) {
    for (i, out) in out.iter_mut().enumerate() {
        *out = light.sample_li(&ctx[i], u[i]);
    }
}

/// [`Light::sample_li_lanes`] lane by lane through `sample_li`: the
/// trait's default, and an override's answer for the settings it has no
/// SIMD code for.
pub fn sample_li_each_lane<L: Light + ?Sized>(
    light: &L,
    ctx: &[LightSampleContext; LANES],
    u: &Vec2Lanes,
    active: LaneMask,
    out: &mut LightSampleLanes,
) {
    for i in active.iter() {
        out.set(i, light.sample_li(&ctx[i], u.get(i)));
    }
}

/// Answers [`Light::sample_li_lanes`] through `light`'s
/// [`Light::sample_li_batch`], for a plugin whose SIMD code reads its
/// lanes from slices: the lanes of `active` gathered in order, and each
/// answer put back in its lane.
pub fn sample_li_lanes_by_batch<L: Light + ?Sized>(
    light: &L,
    ctx: &[LightSampleContext; LANES],
    u: &Vec2Lanes,
    active: LaneMask,
    out: &mut LightSampleLanes,
) {
    let n = active.count() as usize;
    let mut args = (
        [LightSampleContext::at(Vec3::ZERO); LANES],
        [Vec2::ZERO; LANES],
    );
    for (k, i) in active.iter().enumerate() {
        (args.0[k], args.1[k]) = (ctx[i], u.get(i));
    }
    let mut samples = [None; LANES];
    light.sample_li_batch(&args.0[..n], &args.1[..n], &mut samples[..n]);
    for (k, i) in active.iter().enumerate() {
        out.set(i, samples[k]);
    }
}
