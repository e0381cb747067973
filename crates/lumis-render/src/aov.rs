//! Arbitrary output variables: images beside the colour that describe the
//! render (its noise, its sample counts) or the scene's first visible
//! surface (the guides a denoiser reads).

use std::fmt;

/// One output a scene may ask for with `[film] aovs = [...]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Aov {
    /// The hemispherical reflectance of the first non-specular surface
    /// (after perfect mirrors and glass), as Open Image Denoise expects.
    Albedo,
    /// The world-space shading normal of that surface, in `[-1, 1]`.
    Normal,
    /// The distance along the camera ray to the first surface it hits; 0
    /// where it hits nothing (as Mitsuba 3's `aov` integrator).
    Depth,
    /// The variance of each pixel's mean (the sample variance over the
    /// sample count): the noise left in the colour.
    Variance,
    /// The samples each pixel took.
    Spp,
}

impl Aov {
    pub const ALL: [Aov; 5] = [
        Aov::Albedo,
        Aov::Normal,
        Aov::Depth,
        Aov::Variance,
        Aov::Spp,
    ];

    /// The name a scene file and an EXR layer use.
    pub const fn name(self) -> &'static str {
        match self {
            Aov::Albedo => "albedo",
            Aov::Normal => "normal",
            Aov::Depth => "depth",
            Aov::Variance => "variance",
            Aov::Spp => "spp",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// The EXR channels of the layer, each one component of its
    /// [`lumis_image::Image`] in order.
    pub const fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Albedo | Aov::Variance => &["R", "G", "B"],
            Aov::Normal => &["X", "Y", "Z"],
            Aov::Depth => &["Z"],
            Aov::Spp => &["Y"],
        }
    }

    /// Whether the output needs the separate first-hit pass over the
    /// camera rays.
    pub const fn needs_first_hit(self) -> bool {
        matches!(self, Aov::Albedo | Aov::Normal | Aov::Depth)
    }

    /// The bit of this output in a set stored as a mask (checkpoints).
    pub const fn bit(self) -> u32 {
        1 << self as u32
    }
}

impl fmt::Display for Aov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_bits_are_distinct() {
        let mut mask = 0;
        for aov in Aov::ALL {
            assert_eq!(Aov::from_name(aov.name()), Some(aov));
            assert_eq!(mask & aov.bit(), 0);
            mask |= aov.bit();
        }
        assert_eq!(Aov::from_name("colour"), None);
    }
}
