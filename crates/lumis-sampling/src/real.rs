//! One statement of a formula for a single value and for SIMD lanes.
//!
//! The special functions and the microfacet terms are written once, generic
//! over [`Real`], and run on `f32` in the scalar plugin methods and on
//! [`F32x4`] (four lanes, SSE2 on x86-64, from the `wide` crate) in the
//! batched ones. Both execute the same IEEE operations in the same order,
//! so a lane's result is bit for bit the scalar one: special cases are
//! selected lane by lane (and returned early only where they cover every
//! lane, which for `f32` is the scalar branch), and nothing is fused into
//! an `fma`.

use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

use wide::{f32x4, i32x4};

/// Four f32 lanes.
pub type F32x4 = f32x4;

/// A floating-point value or a vector of lanes, with the operations the
/// generic formulas use. Comparisons give a mask; [`Real::select`] picks
/// lane by lane.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    type Mask: Copy
        + BitAnd<Output = Self::Mask>
        + BitOr<Output = Self::Mask>
        + Not<Output = Self::Mask>;

    fn splat(v: f32) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn lt(self, o: Self) -> Self::Mask;
    fn le(self, o: Self) -> Self::Mask;
    fn gt(self, o: Self) -> Self::Mask;
    fn ge(self, o: Self) -> Self::Mask;
    fn eq(self, o: Self) -> Self::Mask;
    /// Lanes that are NaN.
    fn is_nan(self) -> Self::Mask;
    /// `if_true` where `mask` holds, else `if_false`.
    fn select(mask: Self::Mask, if_true: Self, if_false: Self) -> Self;
    /// Whether `mask` holds in every lane: where a special case covers all
    /// lanes, the formula returns it early, as scalar code branches.
    fn all(mask: Self::Mask) -> bool;
    /// `self * 2^k` for integral `k` in `[-254, 254]`, in two steps of
    /// `2^(k/2)` so that a subnormal result needs no branch.
    fn mul_pow2(self, k: Self) -> Self;
    /// `max(self, o)` for non-NaN `o`; NaN lanes of `self` stay NaN.
    fn max(self, o: Self) -> Self {
        Self::select(self.lt(o), o, self)
    }
    /// `min(self, o)` for non-NaN `o`; NaN lanes of `self` stay NaN.
    fn min(self, o: Self) -> Self {
        Self::select(self.gt(o), o, self)
    }
}

/// `2^k` for integer `k` in `[-126, 127]`, from its exponent bits.
#[inline(always)]
fn pow2i(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

impl Real for f32 {
    type Mask = bool;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32::abs(self)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: Self) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: Self) -> bool {
        self == o
    }
    #[inline(always)]
    fn is_nan(self) -> bool {
        f32::is_nan(self)
    }
    #[inline(always)]
    fn select(mask: bool, if_true: Self, if_false: Self) -> Self {
        if mask {
            if_true
        } else {
            if_false
        }
    }
    #[inline(always)]
    fn all(mask: bool) -> bool {
        mask
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        let k = k as i32;
        let half = k >> 1;
        self * pow2i(half) * pow2i(k - half)
    }
}

impl Real for F32x4 {
    type Mask = F32x4;

    #[inline(always)]
    fn splat(v: f32) -> Self {
        f32x4::splat(v)
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f32x4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f32x4::abs(self)
    }
    #[inline(always)]
    fn lt(self, o: Self) -> Self {
        self.simd_lt(o)
    }
    #[inline(always)]
    fn le(self, o: Self) -> Self {
        self.simd_le(o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> Self {
        self.simd_gt(o)
    }
    #[inline(always)]
    fn ge(self, o: Self) -> Self {
        self.simd_ge(o)
    }
    #[inline(always)]
    fn eq(self, o: Self) -> Self {
        self.simd_eq(o)
    }
    #[inline(always)]
    fn is_nan(self) -> Self {
        f32x4::is_nan(self)
    }
    #[inline(always)]
    fn select(mask: Self, if_true: Self, if_false: Self) -> Self {
        mask.select(if_true, if_false)
    }
    #[inline(always)]
    fn all(mask: Self) -> bool {
        mask.all()
    }
    #[inline(always)]
    fn mul_pow2(self, k: Self) -> Self {
        // `round_int` of an integral value is exact, as `as i32` is.
        let k = k.round_int();
        let half = k >> 1;
        let pow2 = |e: i32x4| -> f32x4 { wide::bytemuck::cast((e + i32x4::splat(127)) << 23) };
        self * pow2(half) * pow2(k - half)
    }
}

/// Loads up to four lanes from `f(i)`, padding with `pad`.
#[inline(always)]
pub fn gather4(n: usize, pad: f32, f: impl Fn(usize) -> f32) -> F32x4 {
    f32x4::new(std::array::from_fn(|i| if i < n { f(i) } else { pad }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_scale_by_powers_of_two_as_the_scalar_does() {
        let x = F32x4::new([1.5, -3.0, 1e-20, 7.0]);
        for k in [-254.0, -150.0, -1.0, 0.0, 1.0, 100.0, 254.0] {
            let lanes = x.mul_pow2(F32x4::splat(k)).to_array();
            for (lane, &v) in lanes.iter().zip(&x.to_array()) {
                assert_eq!(lane.to_bits(), v.mul_pow2(k).to_bits(), "{v} 2^{k}");
            }
        }
    }

    #[test]
    fn select_and_comparisons_agree_lane_by_lane() {
        let a = F32x4::new([1.0, f32::NAN, -2.0, 0.0]);
        let b = F32x4::splat(0.0);
        let picked = F32x4::select(a.gt(b) | a.is_nan(), F32x4::splat(1.0), F32x4::splat(2.0));
        assert_eq!(picked.to_array(), [1.0, 1.0, 2.0, 2.0]);
        assert_eq!(Real::max(a, b).to_array()[2], 0.0);
        assert!(Real::max(a, b).to_array()[1].is_nan());
    }
}
