//! The texture plugin interface: a colour that varies over a surface's
//! (u, v) parameterization (pbrt-v4 `SpectrumTexture`, Mitsuba 3 `Texture`).
//!
//! BSDFs do not look textures up themselves: a parameter declared as
//! [`Textured`](crate::params::Textured) holds either a constant or a
//! texture, and the BSDF evaluates it with the hit's [`TextureQuery`].

use lumis_derive::plugin_interface;
use std::collections::BTreeMap;
use std::sync::Arc;

use glam::Vec2;

use crate::footprint::PackedFootprint;
use crate::spectrum::Rgb;

/// Where a texture is looked up: the hit's texture coordinates and, when the
/// scene knows the camera, how they change from one pixel to the next
/// (pbrt-v4 `TextureEvalContext`: `uv`, `dudx`, `dudy`, `dvdx`, `dvdy`;
/// [`crate::footprint`] says where they come from). No footprint means a
/// filtered texture does a bilinear lookup.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TextureQuery {
    pub uv: Vec2,
    /// The derivatives, packed; [`TextureQuery::derivatives`] unpacks them.
    pub footprint: PackedFootprint,
}

impl TextureQuery {
    /// A lookup at `uv` without a footprint.
    #[inline]
    pub const fn at(uv: Vec2) -> Self {
        Self {
            uv,
            footprint: PackedFootprint::NONE,
        }
    }

    /// A lookup at `uv` whose coordinates change by `duv_dx` one pixel to
    /// the right and by `duv_dy` one pixel down.
    #[inline]
    pub fn new(uv: Vec2, duv_dx: Vec2, duv_dy: Vec2) -> Self {
        Self {
            uv,
            footprint: PackedFootprint::new(duv_dx, duv_dy),
        }
    }

    /// `(du/dx, dv/dx)` and `(du/dy, dv/dy)`.
    #[inline]
    pub fn derivatives(&self) -> (Vec2, Vec2) {
        self.footprint.unpack()
    }

    /// Whether the query has a footprint to filter over.
    #[inline]
    pub fn has_footprint(&self) -> bool {
        self.footprint != PackedFootprint::NONE
    }
}

/// A texture: an RGB value at every point of uv space.
///
/// Must be cheap to evaluate, deterministic, and finite everywhere; a
/// texture used as a reflectance should stay in [0, 1] (a constant is
/// checked by the BSDF that reads it, a texture's values cannot be).
#[plugin_interface]
pub trait Texture: Send + Sync {
    /// The value at `query`, linear RGB.
    fn eval(&self, query: &TextureQuery) -> Rgb;

    /// The value as one number, for a float parameter (a roughness, a
    /// weight): the mean of the channels, so a grey texture gives its grey
    /// value exactly. A texture that stores one channel may override this.
    #[inline]
    fn eval_float(&self, query: &TextureQuery) -> f32 {
        self.eval(query).average()
    }

    /// Whether lookups read the query's footprint (an image filtered over
    /// it). A scene computes the pixel footprint at its hits only if one
    /// of its textures does: the work is not free.
    fn uses_footprint(&self) -> bool {
        false
    }

    /// Bytes the texture holds (an image's texels and mip levels), added to
    /// the memory a render reports and checks before it starts; 0 for a
    /// procedural texture, the default.
    fn memory_bytes(&self) -> usize {
        0
    }
}

/// Plugins of a scene by the name its tables give them: the `[[texture]]`s
/// that a BSDF's `{ texture = "name" }` parameters refer to, the
/// `[[bsdf]]`s that an adapter (`twosided`) wraps.
pub struct Named<T: ?Sized> {
    by_name: BTreeMap<String, Arc<T>>,
}

/// The textures of a scene, by name.
pub type Textures = Named<dyn Texture>;

impl<T: ?Sized> Clone for Named<T> {
    fn clone(&self) -> Self {
        Self {
            by_name: self.by_name.clone(),
        }
    }
}

impl<T: ?Sized> Default for Named<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: ?Sized> Named<T> {
    pub const fn new() -> Self {
        Self {
            by_name: BTreeMap::new(),
        }
    }

    /// Adds `texture` under `name`; `false` (and no change) if the name is
    /// taken.
    pub fn insert(&mut self, name: impl Into<String>, plugin: Arc<T>) -> bool {
        match self.by_name.entry(name.into()) {
            std::collections::btree_map::Entry::Occupied(_) => false,
            std::collections::btree_map::Entry::Vacant(slot) => {
                slot.insert(plugin);
                true
            }
        }
    }

    pub fn get(&self, name: &str) -> Option<&Arc<T>> {
        self.by_name.get(name)
    }

    /// The plugins, in the order of their names.
    pub fn values(&self) -> impl Iterator<Item = &Arc<T>> {
        self.by_name.values()
    }

    /// The names, sorted, for messages.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.by_name.keys().map(String::as_str)
    }

    pub fn len(&self) -> usize {
        self.by_name.len()
    }

    pub fn is_empty(&self) -> bool {
        self.by_name.is_empty()
    }
}

/// No textures: what a BSDF made outside a scene (a tool, a test) sees.
pub static NO_TEXTURES: Textures = Textures::new();

/// What a BSDF's parameters may name: the scene's textures and the BSDFs
/// declared before it.
#[derive(Clone, Copy)]
pub struct BsdfScope<'a> {
    pub textures: &'a Textures,
    pub bsdfs: &'a Named<dyn crate::Bsdf>,
}

/// No BSDFs: what a BSDF made outside a scene sees.
pub static NO_BSDFS: Named<dyn crate::Bsdf> = Named::new();

impl BsdfScope<'static> {
    /// Nothing to refer to: a BSDF made outside a scene (a tool, a test).
    pub const EMPTY: Self = Self {
        textures: &NO_TEXTURES,
        bsdfs: &NO_BSDFS,
    };
}

impl<'a> BsdfScope<'a> {
    /// The scene's textures, no BSDFs.
    pub fn textures(textures: &'a Textures) -> Self {
        Self {
            textures,
            bsdfs: &NO_BSDFS,
        }
    }
}

/// A transform of texture coordinates that any texture can apply before its
/// lookup: scale, then rotate counter-clockwise, then offset (the order of
/// glTF's `KHR_texture_transform`; pbrt-v4's `UVMapping` has the scale and
/// offset). Flatten it into a texture's parameters.
#[derive(Debug, Clone, Copy, PartialEq, crate::PluginParams)]
pub struct UvTransform {
    /// scale of (u, v) before the lookup: [2, 2] repeats the texture twice
    /// as often
    #[param(default = [1.0, 1.0])]
    pub uv_scale: Vec2,
    /// rotation of the scaled (u, v) about the origin, in degrees
    /// counter-clockwise
    #[param(default = 0.0)]
    pub uv_rotation: f32,
    /// added to (u, v) after scaling and rotating
    #[param(default = [0.0, 0.0])]
    pub uv_offset: Vec2,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self {
            uv_scale: Vec2::ONE,
            uv_rotation: 0.0,
            uv_offset: Vec2::ZERO,
        }
    }
}

impl UvTransform {
    /// The linear part as columns: `uv' = M uv + offset`.
    fn matrix(&self) -> glam::Mat2 {
        let (sin, cos) = self.uv_rotation.to_radians().sin_cos();
        glam::Mat2::from_cols(Vec2::new(cos, sin), Vec2::new(-sin, cos))
            * glam::Mat2::from_diagonal(self.uv_scale)
    }

    /// Whether it changes nothing (then lookups skip it, bit for bit).
    pub fn is_identity(&self) -> bool {
        *self == Self::default()
    }

    /// The query in transformed coordinates; the footprint goes through
    /// the linear part (the chain rule: `d(M uv)/dx = M duv/dx`).
    #[inline]
    pub fn apply(&self, query: &TextureQuery) -> TextureQuery {
        if self.is_identity() {
            return *query;
        }
        let m = self.matrix();
        let uv = m * query.uv + self.uv_offset;
        if !query.has_footprint() {
            return TextureQuery::at(uv);
        }
        let (dx, dy) = query.derivatives();
        TextureQuery::new(uv, m * dx, m * dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_without_derivatives_has_no_footprint() {
        assert!(!TextureQuery::new(Vec2::ZERO, Vec2::ZERO, Vec2::ZERO).has_footprint());
        assert!(TextureQuery::new(Vec2::ZERO, Vec2::X, Vec2::ZERO).has_footprint());
        assert!(!TextureQuery::at(Vec2::ONE).has_footprint());
    }

    #[test]
    fn uv_transform_scales_rotates_then_offsets() {
        let t = UvTransform {
            uv_scale: Vec2::new(2.0, 3.0),
            uv_rotation: 90.0,
            uv_offset: Vec2::new(0.5, 0.25),
        };
        let q = TextureQuery::new(Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::ZERO);
        let out = t.apply(&q);
        // (2, 3) rotated by 90 degrees is (-3, 2); then offset.
        assert!(
            (out.uv - Vec2::new(-2.5, 2.25)).abs().max_element() < 1e-6,
            "{out:?}"
        );
        // The footprint is scaled and rotated, not offset.
        assert!(
            (out.derivatives().0 - Vec2::new(0.0, 2.0))
                .abs()
                .max_element()
                < 1e-6,
            "{out:?}"
        );
        assert_eq!(UvTransform::default().apply(&q), q);
    }

    #[test]
    fn names_are_unique() {
        struct One;
        impl Texture for One {
            fn eval(&self, _: &TextureQuery) -> Rgb {
                Rgb::splat(0.25)
            }
        }
        let mut textures = Textures::new();
        assert!(textures.insert("a", Arc::new(One)));
        assert!(!textures.insert("a", Arc::new(One)));
        assert_eq!(
            textures
                .get("a")
                .unwrap()
                .eval_float(&TextureQuery::default()),
            0.25
        );
        assert_eq!(textures.names().collect::<Vec<_>>(), ["a"]);
    }
}
