//! Which dimensions of a pixel sample's vector each request takes.

use lumis_api::PixelPattern;

/// The first dimension the next request takes. Dimensions 0 and 1 are the
/// position in the pixel (`Sampler::get_pixel_2d`); every other request
/// takes the next unused ones in order, as pbrt-v4's samplers count them,
/// so a 1D, a 2D and a combined request each consume what they return.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct DimensionCursor(u32);

impl DimensionCursor {
    /// At the start of a pixel sample: past the pixel's two dimensions.
    pub const START: Self = Self(2);

    /// The first of the `n` dimensions the request takes.
    #[inline]
    pub fn take(&mut self, n: u32) -> u32 {
        let d = self.0;
        self.0 = d.wrapping_add(n);
        d
    }
}

/// A sampler whose pixel's first power-of-two points form a (0, 2)-net:
/// a net at a power-of-two spp, else no known pattern.
pub(crate) fn net_at_powers_of_two(spp: u32) -> PixelPattern {
    if spp.is_power_of_two() {
        PixelPattern::Net02
    } else {
        PixelPattern::Random
    }
}
