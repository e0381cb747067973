//! What an integrator knows about a surface hit.

use std::num::NonZeroU32;

use glam::Vec3;

use crate::bsdf::{Bsdf, BsdfFlags};
use crate::math::Frame;
use crate::ray::{Ray, SurfacePoint};
use crate::texture::TextureQuery;

/// A ray-surface intersection, ready for shading.
#[derive(Clone, Copy)]
pub struct SurfaceInteraction<'a> {
    /// The hit point, its error bound and the unit geometric normal (on the
    /// front side of the surface as the shape defines it).
    pub point: SurfacePoint,
    /// Shading frame; `z` is the shading normal, on the same side as `point.n`.
    pub shading: Frame,
    /// The texture coordinates and, when the scene knows the camera, how
    /// they change from pixel to pixel ([`crate::footprint`]).
    pub texture: TextureQuery,
    pub bsdf: &'a dyn Bsdf,
    /// `bsdf.flags()`, read once when the scene was built: every path vertex
    /// asks whether it may sample lights, and the answer never changes.
    pub bsdf_flags: BsdfFlags,
    /// The area light attached to the surface, as an index into
    /// [`crate::Scene::lights`] (the light sampler's pmf needs the index). An
    /// index rather than a reference, and one with a niche, keeps the
    /// interaction within 128 bytes, which the compiler copies inline
    /// instead of calling `memcpy` on every hit.
    pub light: Option<LightIndex>,
}

/// An index into [`crate::Scene::lights`], stored plus one so that
/// `Option<LightIndex>` takes 4 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightIndex(NonZeroU32);

impl LightIndex {
    /// `index`, or `None` for `u32::MAX` (which has no successor).
    #[inline]
    pub const fn new(index: u32) -> Option<Self> {
        match NonZeroU32::new(index.wrapping_add(1)) {
            Some(plus_one) => Some(Self(plus_one)),
            None => None,
        }
    }

    #[inline]
    pub fn get(self) -> u32 {
        self.0.get() - 1
    }
}

impl SurfaceInteraction<'_> {
    #[inline]
    pub fn p(&self) -> Vec3 {
        self.point.p
    }

    #[inline]
    pub fn n(&self) -> Vec3 {
        self.point.n
    }

    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        self.point.spawn_ray(d)
    }

    /// Where light sampling starts from this hit.
    #[inline]
    pub fn light_context(&self) -> LightSampleContext {
        LightSampleContext {
            point: self.point,
            ns: self.shading.normal(),
        }
    }
}

/// The reference point for light sampling: a surface point (or, with a zero
/// normal, a point in space) and its shading normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSampleContext {
    pub point: SurfacePoint,
    pub ns: Vec3,
}

impl LightSampleContext {
    /// A context at a point in free space (no surface), as the tests use.
    pub fn at(p: Vec3) -> Self {
        Self {
            point: SurfacePoint::isolated(p),
            ns: Vec3::ZERO,
        }
    }

    #[inline]
    pub fn p(&self) -> Vec3 {
        self.point.p
    }
}

// The integrators copy interactions by value on every hit: above 128 bytes
// that copy becomes a call to `memcpy`.
const _: () = assert!(std::mem::size_of::<Option<SurfaceInteraction>>() <= 128);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn light_indices_round_trip() {
        for index in [0, 1, 7, u32::MAX - 1] {
            assert_eq!(LightIndex::new(index).map(LightIndex::get), Some(index));
        }
        assert_eq!(LightIndex::new(u32::MAX), None);
    }
}
