//! The sampling baselines every glossy BSDF offers besides its own, so
//! that a scene can measure what importance sampling buys (`sampling =
//! "cosine"` or `"uniform"` on the same material).

use lumis_api::{ParamChoice, Vec2, Vec3};
use lumis_sampling::warp;

use crate::microfacet::NormalSampling;

/// How a glossy reflection lobe draws `wi`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LobeSampling {
    /// The model's own importance sampling (of its half vectors).
    Model(NormalSampling),
    /// Cosine-weighted hemisphere: ignores the lobe's shape.
    Cosine,
    /// Uniform hemisphere: ignores both the lobe and the cosine.
    Uniform,
}

/// The `sampling` choice of a BSDF whose lobe samples microfacet normals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
pub enum MicrofacetLobeSampling {
    Visible,
    Full,
    Cosine,
    Uniform,
}

impl From<MicrofacetLobeSampling> for LobeSampling {
    fn from(sampling: MicrofacetLobeSampling) -> Self {
        match sampling {
            MicrofacetLobeSampling::Visible => Self::Model(NormalSampling::Visible),
            MicrofacetLobeSampling::Full => Self::Model(NormalSampling::Full),
            MicrofacetLobeSampling::Cosine => Self::Cosine,
            MicrofacetLobeSampling::Uniform => Self::Uniform,
        }
    }
}

impl LobeSampling {
    /// For the two baselines: a direction in the upper hemisphere, or
    /// `None` on the horizon (where reflection is zero).
    #[inline]
    pub fn sample_baseline(self, u: Vec2) -> Option<Vec3> {
        let wi = match self {
            Self::Uniform => warp::square_to_uniform_hemisphere(u),
            _ => warp::square_to_cosine_hemisphere(u),
        };
        (wi.z > 0.0).then_some(wi)
    }

    /// Density of a baseline at `cos_theta > 0`.
    #[inline]
    pub fn baseline_pdf(self, cos_theta: f32) -> f32 {
        match self {
            Self::Uniform => warp::uniform_hemisphere_pdf(cos_theta),
            _ => warp::cosine_hemisphere_pdf(cos_theta),
        }
    }
}
