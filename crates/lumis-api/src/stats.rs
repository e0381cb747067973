//! Counters an integrator keeps while rendering.

use std::ops::AddAssign;

/// Per-thread counters, summed at the end of a render.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RenderStats {
    /// Closest-hit queries (camera rays and bounces).
    pub rays: u64,
    /// Occlusion queries (shadow rays).
    pub shadow_rays: u64,
    /// Camera samples taken.
    pub samples: u64,
    /// Samples whose radiance was NaN or infinite, counted and dropped.
    pub nonfinite: u64,
    /// Emission contributions found by BSDF sampling (an emitter hit by a
    /// bounce with a non-zero MIS weight), strategy f.
    pub bsdf_light_hits: u64,
    /// Emission contributions found by light sampling (unoccluded shadow
    /// rays toward a non-black light sample), strategy g.
    pub light_samples: u64,
}

impl RenderStats {
    pub fn total_rays(&self) -> u64 {
        self.rays + self.shadow_rays
    }
}

impl AddAssign for RenderStats {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.samples += o.samples;
        self.nonfinite += o.nonfinite;
        self.bsdf_light_hits += o.bsdf_light_hits;
        self.light_samples += o.light_samples;
    }
}
