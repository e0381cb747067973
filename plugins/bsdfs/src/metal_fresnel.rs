//! A metal's Fresnel term (Born and Wolf's complex-index reflectance,
//! `fresnel::conductor`), the same everywhere or read from textures at each
//! hit: what `conductor` and the metal parameters share.

use lumis_api::{Rgb, TextureQuery, TexturedRgb};
use lumis_sampling::real::Real;

use crate::fresnel;

/// The metal's reflectance at each angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConductorFresnel {
    /// Reflects everything at every angle (Fresnel = 1).
    Perfect,
    Complex {
        eta: Rgb,
        k: Rgb,
    },
}

impl ConductorFresnel {
    #[inline]
    pub fn eval(&self, cos_theta: f32) -> Rgb {
        match *self {
            Self::Perfect => Rgb::WHITE,
            Self::Complex { eta, k } => fresnel::conductor(cos_theta, eta, k),
        }
    }

    /// [`Self::eval`] of each lane of `cos_theta`, the same bits per lane.
    #[inline]
    pub(crate) fn eval_lanes<F: Real>(&self, cos_theta: F) -> [F; 3] {
        match *self {
            Self::Perfect => [F::splat(1.0); 3],
            Self::Complex { eta, k } => [(eta.r, k.r), (eta.g, k.g), (eta.b, k.b)]
                .map(|(eta, k)| fresnel::conductor_channel_lanes(cos_theta, eta, k)),
        }
    }
}

/// A metal's Fresnel term: the same everywhere, or from `eta` and `k`
/// textures at each hit (pbrt-v4's `ConductorMaterial` reads its
/// spectrum textures per hit the same way).
#[derive(Debug, Clone)]
pub enum MetalFresnel {
    Fixed(ConductorFresnel),
    Textured { eta: TexturedRgb, k: TexturedRgb },
}

impl From<ConductorFresnel> for MetalFresnel {
    fn from(fresnel: ConductorFresnel) -> Self {
        Self::Fixed(fresnel)
    }
}

impl MetalFresnel {
    /// The Fresnel term at the hit `query` looks up.
    #[inline]
    pub fn at(&self, query: &TextureQuery) -> ConductorFresnel {
        match self {
            Self::Fixed(fresnel) => *fresnel,
            // A texel out of the physical range (eta <= 0, k < 0) is held
            // at its edge, as the constants are checked to be.
            Self::Textured { eta, k } => ConductorFresnel::Complex {
                eta: eta.eval(query).map(|c| c.max(1e-3)),
                k: k.eval(query).map(|c| c.max(0.0)),
            },
        }
    }

    /// The Fresnel term if it is the same everywhere: what the batched
    /// methods work on lanes with.
    #[inline]
    pub fn fixed(&self) -> Option<ConductorFresnel> {
        match self {
            Self::Fixed(fresnel) => Some(*fresnel),
            Self::Textured { .. } => None,
        }
    }
}
