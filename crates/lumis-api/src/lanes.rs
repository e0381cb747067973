//! The structure-of-arrays form in which a packet integrator hands the
//! queries of [`LANES`] paths to a plugin at once (the lane methods
//! `Bsdf::sample_f_lanes`, `Bsdf::eval_lanes`, `Light::sample_li_lanes`).
//!
//! Each component of a vector is an array of lanes, so that a plugin loads
//! it into a SIMD register with one instruction and writes its answers the
//! same way: nothing is transposed on either side of the call (OSPRay's
//! `varying` values and Mitsuba 3's JIT arrays are laid out alike). Which
//! lanes hold a query is a [`LaneMask`]; a lane method reads only those
//! and writes only those, so that the calls for a packet's other
//! materials or lights fill the same answer.

use std::ops::{BitAnd, BitOr, Not};

use glam::{Vec2, Vec3};

use crate::spectrum::Rgb;

/// Paths per packet: eight, the width of an AVX register of `f32` and of
/// Embree's `rtcIntersect8`.
pub const LANES: usize = 8;

/// One `f32` per lane.
pub type Floats = [f32; LANES];

/// Which lanes of a packet hold a query: bit `i` for lane `i`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub struct LaneMask(u32);

impl LaneMask {
    pub const NONE: Self = Self(0);
    pub const ALL: Self = Self((1 << LANES) - 1);

    /// The mask of bits `bits` (those past [`LANES`] dropped).
    #[inline]
    pub const fn from_bits(bits: u32) -> Self {
        Self(bits & Self::ALL.0)
    }

    #[inline]
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// Lanes `0..n`.
    #[inline]
    pub const fn first(n: usize) -> Self {
        Self::from_bits(if n >= LANES { u32::MAX } else { (1 << n) - 1 })
    }

    /// Lane `i` alone.
    #[inline]
    pub const fn lane(i: usize) -> Self {
        Self::from_bits(1 << i)
    }

    #[inline]
    pub const fn contains(self, i: usize) -> bool {
        i < LANES && self.0 & (1 << i) != 0
    }

    #[inline]
    pub fn set(&mut self, i: usize, on: bool) {
        if on {
            self.0 |= 1 << i;
        } else {
            self.0 &= !(1 << i);
        }
    }

    #[inline]
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    #[inline]
    pub const fn count(self) -> u32 {
        self.0.count_ones()
    }

    /// The lanes held, in increasing order.
    #[inline]
    pub fn iter(self) -> impl Iterator<Item = usize> {
        let mut bits = self.0;
        std::iter::from_fn(move || {
            (bits != 0).then(|| {
                let i = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                i
            })
        })
    }
}

impl BitAnd for LaneMask {
    type Output = Self;
    #[inline]
    fn bitand(self, o: Self) -> Self {
        Self(self.0 & o.0)
    }
}

impl BitOr for LaneMask {
    type Output = Self;
    #[inline]
    fn bitor(self, o: Self) -> Self {
        Self(self.0 | o.0)
    }
}

impl Not for LaneMask {
    type Output = Self;
    #[inline]
    fn not(self) -> Self {
        Self(!self.0 & Self::ALL.0)
    }
}

/// A 2-vector per lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vec2Lanes {
    pub x: Floats,
    pub y: Floats,
}

impl Vec2Lanes {
    #[inline]
    pub fn get(&self, i: usize) -> Vec2 {
        Vec2::new(self.x[i], self.y[i])
    }

    #[inline]
    pub fn set(&mut self, i: usize, v: Vec2) {
        (self.x[i], self.y[i]) = (v.x, v.y);
    }
}

/// A 3-vector per lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Vec3Lanes {
    pub x: Floats,
    pub y: Floats,
    pub z: Floats,
}

impl Vec3Lanes {
    #[inline]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    #[inline]
    pub fn set(&mut self, i: usize, v: Vec3) {
        (self.x[i], self.y[i], self.z[i]) = (v.x, v.y, v.z);
    }
}

/// An RGB value per lane.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RgbLanes {
    pub r: Floats,
    pub g: Floats,
    pub b: Floats,
}

impl RgbLanes {
    #[inline]
    pub fn get(&self, i: usize) -> Rgb {
        Rgb::new(self.r[i], self.g[i], self.b[i])
    }

    #[inline]
    pub fn set(&mut self, i: usize, v: Rgb) {
        (self.r[i], self.g[i], self.b[i]) = (v.r, v.g, v.b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_iterate_their_lanes_in_order() {
        let m = LaneMask::from_bits(0b1010_0101);
        assert_eq!(m.iter().collect::<Vec<_>>(), [0, 2, 5, 7]);
        assert_eq!(m.count(), 4);
        assert_eq!((!m).iter().collect::<Vec<_>>(), [1, 3, 4, 6]);
        assert_eq!(LaneMask::first(3).bits(), 0b111);
        assert_eq!(LaneMask::first(LANES), LaneMask::ALL);
        assert_eq!(LaneMask::first(0), LaneMask::NONE);
        assert!(LaneMask::lane(7).contains(7) && !LaneMask::ALL.contains(LANES));
        assert_eq!(LaneMask::from_bits(u32::MAX), LaneMask::ALL);
    }
}
